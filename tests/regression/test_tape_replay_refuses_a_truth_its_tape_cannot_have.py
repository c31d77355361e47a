"""`fsw sim PROJECT --tape` took any finite times from the truth file: a
truth whose `burnout_s` was -4.48 (before liftoff) made the check "no
pyro pin before liftoff or during boost (before burnout_s -4.48 s)" pass
whatever the firmware did, and one whose `apogee_s` was 500 s on a tape
ending at 142.7 s (another flight's truth, or a typo) failed the firmware
by 475 s. Now an event time the checks use (`liftoff_s`, `burnout_s`,
`apogee_s`, `landing_s`) outside the tape's rows, or out of the flight's
order (liftoff, burnout, apogee, landing), or a `pad_pressure_pa` (which
the truth's altitudes are taken above) beyond the ISA troposphere (a
pressure in hPa: 1000.5), is an error at its line of the truth file, exit status 2, before anything is built; the shared tapes'
truths load as they are."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES, SHARED, run_fsw

HPR = EXAMPLES / "hpr"
FLIGHTS = SHARED / "flights"
CAMOES = FLIGHTS / "camoes_cats.csv"
pytestmark = pytest.mark.skipif(not CAMOES.exists(), reason=f"{FLIGHTS} is not there")


def _flight(tmp_path, old: str, new: str):
    p = tmp_path / "f.csv"
    shutil.copy(CAMOES, p)
    truth = CAMOES.with_name("camoes_cats.truth.toml").read_text()
    assert old in truth
    (tmp_path / "f.truth.toml").write_text(truth.replace(old, new))
    line = next(i for i, x in enumerate(truth.replace(old, new).splitlines(), 1) if x.startswith(new))
    return p, line


@pytest.mark.parametrize("old, new, said", [
    ("burnout_s = 4.48", "burnout_s = -4.48", "burnout_s -4.48 s is not after liftoff_s 0 s"),
    ("apogee_s = 24.31", "apogee_s = 500.0", "apogee_s 500 s is after the tape's last row (142.7 s)"),
    ("apogee_s = 24.31", "apogee_s = 2.0", "apogee_s 2 s is not after burnout_s 4.48 s"),
    ("landing_s = 139.97", "landing_s = 20.0", "landing_s 20 s is not after apogee_s 24.31 s"),
    ("liftoff_s = 0.0", "liftoff_s = -9.0", "liftoff_s -9 s is before the tape's first row (-0.75 s)"),
    ("pad_pressure_pa = 100047.7", "pad_pressure_pa = 1000.5",
     "pad_pressure_pa 1000.5 Pa is 25,917 m ASL: beyond the ISA troposphere"),
])
def test_an_event_the_tape_cannot_have_is_refused_at_its_line(tmp_path, old, new, said):
    p, line = _flight(tmp_path, old, new)
    r = run_fsw("sim", str(HPR), "--tape", str(p), "--out", str(tmp_path / "out"))
    assert r.code == 2, r.err
    assert f"{tmp_path / 'f.truth.toml'}:{line}: {said}" in r.err, r.err
    assert "built" not in r.err and not (tmp_path / "out").exists()


def test_the_shared_truths_load(tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.plant import tape_replay as tr
    from fswkit.target.build import load

    app = load(str(HPR), Diagnostics(), None)
    cfg = tr.load_config(app, from_app(app), None)
    for tape in sorted(FLIGHTS.glob("*.csv")):
        tr.load_tape(str(tape), cfg)
