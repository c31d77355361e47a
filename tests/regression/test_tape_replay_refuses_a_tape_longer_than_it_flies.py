"""`fsw sim PROJECT --tape` took a tape of any span: one whose last row
lay at 1e300 s (a valid tape: times increasing) crashed the replay with an
internal error (`Maximum allowed size exceeded`, after a numpy cast
warning: the rows' simulated cycles overflowed), and one whose last row
lay at 1e6 s ran the firmware for an hour, to the wall-clock limit. A
replay now flies at most MAX_SPAN_S (3,600 s, as a plant run's `max_s`) of
tape, and a longer tape is refused before the build with a located message
at the first row beyond it. (A row at 1e300 s or 1e6 s is now beyond the
range of any tape's times, -3,600 to 3,600 s, and refused by the tape
reader at its line: test_tape_cells_beyond_what_a_flight_records_are_refused.)"""

from __future__ import annotations

import pytest

from conftest import EXAMPLES, run_fsw

HPR = EXAMPLES / "hpr"


def tape(tmp_path, last: str, first: float = -1.0):
    rows = [f"{i / 10 + first:g},{100000 - 50 * max(i - 10, 0)},1" for i in range(50)]
    t = 50 / 10 + first  # then a row every 30 s (rows lie at most 60 s apart) to the last
    while float(last) <= 3600 and t + 30 < float(last):
        t += 30
        rows.append(f"{t:g},90000,")
    p = tmp_path / "long.csv"
    p.write_text("# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n" + "\n".join(rows) + f"\n{last},90000,\n")
    (tmp_path / "long.truth.toml").write_text('name = "long"\napogee_s = 3.0\nburnout_s = 1.0\n')
    return p


@pytest.mark.parametrize("first, last, line", [(-1.0, "1e300", 53), (-1.0, "1e6", 53), (-1.0, "3600", 172),
                                               (-1200.0, "2500", 172)])
def test_a_tape_beyond_the_replays_span_is_refused_where_it_goes_beyond(tmp_path, first, last, line):
    p = tape(tmp_path, last, first)
    r = run_fsw("sim", str(HPR), "--tape", str(p), "--out", str(tmp_path / "out"))
    assert r.code == 2, r.err
    assert f"{p}:{line}:" in r.err and "3,600 s" in r.err, r.err
    assert "internal error" not in r.err and "Warning" not in r.err
    assert not (tmp_path / "out").exists()


def test_a_tape_within_the_span_is_loaded(tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.plant import tape_replay as tr
    from fswkit.target.build import load

    assert tr.MAX_SPAN_S == 3600.0
    app = load(str(HPR), Diagnostics(), None)
    cfg = tr.load_config(app, from_app(app), None)
    t, _truth = tr.load_tape(str(tape(tmp_path, "3598.9")), cfg)  # 3,599.9 s after the first row
    assert t.span == pytest.approx(3599.9)
