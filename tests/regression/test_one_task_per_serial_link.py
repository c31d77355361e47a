"""Two `telemetry` tasks were accepted: both drove the one serial link, the
streams were sampled twice as often as configured and the ground's
timestamps went backwards. Every task kind that drives a single shared
resource (the serial link: `telemetry`, `uplink`) may appear at most once;
the second is refused where it is written, naming the first."""

from __future__ import annotations

import pytest

SV = """\
[Flight]
U64 time
U32 state
F32 alt
[Cmd]
bool abort
"""

SM = """\
[state_vector]
U64 time @alias G
U32 state @alias S
F32 alt @read_only
bool abort @read_only

[Idle]
"""

APP = """\
[application]
board uno
rate 100

[configs]
state_vector rig.sv
machine rig.sm

[tasks]
up       uplink
control  machine rig
down     telemetry rate=50
{extra}
[telemetry]
Flight rate=10

[uplink]
abort
"""


def project(tmp_path, extra: str):
    for name, text in (("rig.sv", SV), ("rig.sm", SM), ("rig.app", APP.format(extra=extra))):
        (tmp_path / name).write_text(text)
    return tmp_path / "rig.app"


def test_one_of_each_is_accepted(fsw, tmp_path):
    r = fsw("check", str(project(tmp_path, "sense inputs\nsense2 inputs\nact outputs\nact2 outputs\n")))
    assert r.code == 0, r.err


@pytest.mark.parametrize("extra, first, line", [
    ("down2    telemetry\n", "down", 12),
    ("up2      uplink rate=50\n", "up", 10),
])
def test_a_second_link_task_is_refused(fsw, tmp_path, extra, first, line):
    p = project(tmp_path, extra)
    r = fsw("check", str(p))
    assert r.code != 0
    kind = extra.split()[1]
    assert f"application config error @ {p}:13:10:" in r.err, r.err
    assert (f"a second `{kind}` task: task `{first}` on line {line} already drives the serial link "
            f"(at most one `{kind}` task)") in r.err, r.err
    assert "Traceback" not in r.err
