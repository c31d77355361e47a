"""`fsw tape truth`: a tape's truth worked out from the tape by the shared
flights' rules (docs/tapes.md, "Truth files"), so that a team's own flight,
imported with `fsw tape import`, can be replayed with `fsw sim --tape`.

The yardstick: for each of the eight real flights of ../shared/flights/,
every value worked out equals its `.truth.toml`'s, to the digits the file
writes (recomputed from the tape; the recorder's own events are the log's and
not compared). Then the command: where it writes, what it never replaces, a
tape that cannot give every value, and a replay taking what it wrote."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES, SHARED, run_fsw
from fswkit.tape import read_tape, read_truth, truth_path
from fswkit.tape.truth import compute

FLIGHTS = SHARED / "flights"
NAMES = ("prometheus_telemega", "prometheus_telemetrum", "hedy_cats", "ndrt2020_raven", "camoes_cats",
         "genesis_cats", "lince_cats", "halcyon_cats")
shared = pytest.mark.skipif(not FLIGHTS.is_dir(), reason=f"{FLIGHTS} is absent (the shared flight tapes sit "
                            "beside the repository, not in it): nothing to compare with")


@shared
@pytest.mark.parametrize("name", NAMES)
def test_the_truth_worked_out_is_the_shared_files(name):
    path = str(FLIGHTS / f"{name}.csv")
    ref = read_truth(truth_path(path))
    got = {k: v for k, v, _rule in compute(read_tape(path))}
    for key, v in got.items():
        want = getattr(ref, key)
        if v is None or want is None:
            assert v is None and want is None, (key, v, want)
            continue
        tol = 0.06 if key.endswith(("_pa", "_m_agl")) else 0.006  # the file's digits: 0.1 Pa/m, 0.01 s/g
        assert v == pytest.approx(want, abs=tol), key
    compared = {k for k in got if got[k] is not None}
    assert {"burnout_s", "apogee_s", "pad_pressure_pa", "apogee_band5m_to_s", "log_end_s"} <= compared
    assert ("landing_s" in compared) == (ref.landing_s is not None)


def _tape(tmp_path, accel: bool = True):
    """A tape of a flight of our own: 1 g on the pad, 6 g for 2 s (25 m/s^2 up), a coast to an apogee of
    2,140 m at 22.4 s, down at 20 m/s to the ground at 129.4 s, 10 s on it; 100 Hz to 3 s, 10 Hz after."""
    times = [i / 100 for i in range(-50, 300)] + [3 + i / 10 for i in range(1, 1370)]
    rows = []
    for t in times:
        if t < 0:
            h = 0.0
        elif t < 2:
            h = 25 * t * t
        elif t < 22.4:
            h = 100 + 200 * (t - 2) - 4.9 * (t - 2) ** 2
        else:
            h = max(2139.8 - 20 * (t - 22.4), 0.0)
        p = 101325 * (1 - h / 44330.77) ** (1 / 0.190263)
        a = 1.0 if t < 0 else (6.0 if t < 2 else -0.3)
        rows.append(f"{t:.2f},{p:.1f}," + (f"{a:g}" if accel else ""))
    path = tmp_path / "mine.csv"
    path.write_text("# fswkit sensor tape v1\n# source: a test's own\n# derived: written by a test\n"
                    "time_s,pressure_pa,accel_g\n" + "\n".join(rows) + "\n")
    return path


def test_the_truth_goes_beside_the_tape_and_is_read_back(tmp_path):
    tape = _tape(tmp_path)
    r = run_fsw("tape", "truth", str(tape))
    assert r.code == 0, r.err
    out = tmp_path / "mine.truth.toml"
    truth = read_truth(str(out))
    assert truth.name == "mine"
    assert truth.burnout_s == pytest.approx(2.0, abs=0.011)
    assert truth.apogee_s == pytest.approx(22.4, abs=0.2) and truth.apogee_m_agl == pytest.approx(2139.8, abs=1)
    assert truth.accel_over_2g_s == 0.0 and truth.landing_s == pytest.approx(129.4, abs=0.5)
    assert f"{out}: burnout_s 2.00 s, apogee_s" in r.err, r.err
    assert "# apogee_s" not in out.read_text() and "apogee_s = " in out.read_text()


def test_a_truth_file_there_is_replaced_only_when_asked(tmp_path):
    tape = _tape(tmp_path)
    out = tmp_path / "mine.truth.toml"
    out.write_text("# my own notes\nname = \"mine\"\napogee_s = 1.0\n")
    r = run_fsw("tape", "truth", str(tape))
    assert r.code == 1 and "exists: it is replaced only when asked (--force)" in r.err, r.err
    assert out.read_text().startswith("# my own notes")
    r = run_fsw("tape", "truth", str(tape), "--force")
    assert r.code == 0 and read_truth(str(out)).apogee_s > 22.0, r.err
    r = run_fsw("tape", "truth", str(tape), "-o", str(tape), "--force")  # never its own input
    assert r.code == 1 and tape.read_text().startswith("# fswkit sensor tape v1"), r.err
    r = run_fsw("tape", "truth", str(tape), "-o", "-", "--force")
    assert r.code == 2 and "--force" in r.err, r.err
    r = run_fsw("tape", "truth", str(tape), "-o", "-")
    assert r.code == 0 and 'name = "mine"' in r.out and "burnout_s = 2.0" in r.out, r.err


def test_a_tape_without_accel_gives_no_burnout_and_says_what_to_add(tmp_path):
    tape = _tape(tmp_path, accel=False)
    r = run_fsw("tape", "truth", str(tape))
    assert r.code == 0, r.err
    assert "gives no burnout_s" in r.err and "by hand" in r.err, r.err
    text = (tmp_path / "mine.truth.toml").read_text()
    assert "# no burnout_s: no accel_g" in text and "apogee_s = " in text
    assert read_truth(str(tmp_path / "mine.truth.toml")).burnout_s is None


def test_a_replay_takes_the_truth_written(tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.plant import tape_replay as tr
    from fswkit.target.build import load

    tape = _tape(tmp_path)
    app = load(str(EXAMPLES / "hpr"), Diagnostics(), None)
    cfg = tr.load_config(app, from_app(app), None)
    with pytest.raises(tr.ReplayError, match="no truth file beside it"):
        tr.load_tape(str(tape), cfg)
    assert run_fsw("tape", "truth", str(tape)).code == 0
    _t, truth = tr.load_tape(str(tape), cfg)
    assert truth.burnout_s is not None and truth.apogee_s is not None


@shared
def test_an_imported_shared_tape_copy_gets_its_truth(tmp_path):
    src = FLIGHTS / "ndrt2020_raven.csv"
    tape = tmp_path / "ndrt.csv"
    shutil.copy(src, tape)
    r = run_fsw("tape", "truth", str(tape))
    assert r.code == 0, r.err
    assert read_truth(str(tmp_path / "ndrt.truth.toml")).apogee_s == pytest.approx(
        read_truth(truth_path(str(src))).apogee_s, abs=0.006)


@shared
def test_a_flight_imported_from_its_recorders_export_gets_the_shared_truth(tmp_path):
    """The team's path: the recorder's export, `fsw tape import`, `fsw tape truth`. The TeleMega's flight
    written back as an AltOS export (m/s^2 with the rest's 1 g removed, as AltOS writes) comes back with
    every value of its shared truth file."""
    import math

    src = str(FLIGHTS / "prometheus_telemega.csv")
    t = read_tape(src)
    rows = ["#version,serial,flight,call,time,state,state_name,acceleration,pressure,altitude,height,speed,"
            "temperature,connected"]
    for tt, p, a in zip(t.time.tolist(), t.pressure.tolist(), t.accel.tolist()):
        acc = "NaN" if math.isnan(a) else f"{(a - 1) * 9.80665:.4f}"
        rows.append(f"6, 6583, 3,N0CALL,{tt:.3f}, 3, boost,{acc},{'NaN' if math.isnan(p) else f'{p:.2f}'}, 0, 0, 0, "
                    "20, 1")
    (tmp_path / "export.csv").write_text("\n".join(rows) + "\n")
    assert run_fsw("tape", "import", "altos", str(tmp_path / "export.csv"), "-o", str(tmp_path / "mine.csv")).code == 0
    r = run_fsw("tape", "truth", str(tmp_path / "mine.csv"))
    assert r.code == 0, r.err
    got, ref = read_truth(str(tmp_path / "mine.truth.toml")), read_truth(truth_path(src))
    for key in ("burnout_s", "max_boost_accel_g", "pad_pressure_pa", "apogee_s", "apogee_m_agl", "landing_s",
                "log_end_s"):
        assert getattr(got, key) == pytest.approx(getattr(ref, key), abs=0.06), key
    assert got.recorder == "AltOS serial 6583 flight 3"
