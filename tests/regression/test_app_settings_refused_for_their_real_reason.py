"""Two `.app` settings were refused for the wrong reason, or passed in
silence: an `[uplink]` list with no `uplink` task was accepted without a
word (the elements can never be written: nothing receives commands); and
an executor `rate` of 125000, 200000 or 500000 was refused as not dividing
1000000, which it does: the real limit is 100000 cycles per second. A
setting that cannot take effect is refused with its real reason, or, when
it is merely idle, a warning that `fsw check --strict` fails on."""

from __future__ import annotations

import pytest

SV = """\
[Flight]
U64 time
U32 state
[Cmd]
bool abort
"""

SM = """\
[state_vector]
U64 time @alias G
U32 state @alias S
bool abort @read_only

[Idle]
"""

APP = """\
[application]
board native
rate {rate}

[configs]
state_vector rig.sv
machine rig.sm

[tasks]
control  machine rig
{tasks}
[uplink]
abort

[time]
unit us
"""


def project(tmp_path, rate="100", tasks="up uplink\n"):
    for name, text in (("rig.sv", SV), ("rig.sm", SM), ("rig.app", APP.format(rate=rate, tasks=tasks))):
        (tmp_path / name).write_text(text)
    return tmp_path / "rig.app"


def test_an_uplink_list_with_its_task_is_accepted(fsw, tmp_path):
    r = fsw("check", str(project(tmp_path)))
    assert r.code == 0, r.err


def test_an_uplink_list_without_an_uplink_task_is_a_warning(fsw, tmp_path):
    p = project(tmp_path, tasks="")
    r = fsw("check", str(p))
    assert r.code == 0
    assert f"application config warning @ {p}:13:1:" in r.err, r.err
    assert "writable elements without an `uplink` task in [tasks]: nothing receives commands" in r.err
    assert r.err.count("writable elements without") == 1
    assert fsw("check", "--strict", str(p)).code == 1


@pytest.mark.parametrize("rate", ["100000", "50000", "1"])
def test_rates_up_to_100000_that_divide_a_million_are_accepted(fsw, tmp_path, rate):
    assert fsw("check", str(project(tmp_path, rate=rate))).code == 0


@pytest.mark.parametrize("rate", ["125000", "200000", "500000", "1000000"])
def test_rates_over_100000_are_refused_as_too_fast(fsw, tmp_path, rate):
    p = project(tmp_path, rate=rate)
    r = fsw("check", str(p))
    assert r.code == 1
    assert f"application config error @ {p}:3:6:" in r.err, r.err
    assert f"`rate` is at most 100000 cycles per second (10 us a cycle), found {rate}" in r.err


@pytest.mark.parametrize("rate", ["300", "99999", "2.5"])
def test_rates_that_do_not_divide_a_million_say_so(fsw, tmp_path, rate):
    r = fsw("check", str(project(tmp_path, rate=rate)))
    assert r.code == 1 and "that divides 1000000" in r.err, r.err
