"""`fsw tape truth` of a tape holding one absurd pressure (a recorder's
glitch row kept by the import, or a hand-edited cell: 1 Pa, 39 km above
the pad) wrote a truth file as if it were flown: the shared Camoes
flight's apogee moved from 24.31 s, 3,015 m, to 28.99 s, 3,655 m, and its
raw maximum to 39,277 m, with exit status 0, and `fsw sim --tape` then
judged the firmware against that. Now a pressure beyond the ISA
troposphere the truth's altitudes are worked in (-1 to 11 km above sea
level) is an error at its line (`TAPE:LINE`), exit status 1, no file
written; the shared tapes work out as before. (1 Pa and 150,000 Pa, beyond
any barometer's range, are now refused by the tape reader itself:
test_tape_cells_beyond_what_a_flight_records_are_refused.)"""

from __future__ import annotations

import shutil

import pytest

from pathlib import Path

from conftest import SHARED, run_fsw
from fswkit.tape import TapeError, read_tape
from fswkit.tape.truth import check_altitudes

FLIGHTS = SHARED / "flights"
CAMOES = FLIGHTS / "camoes_cats.csv"
pytestmark = pytest.mark.skipif(not CAMOES.exists(), reason=f"{FLIGHTS} is not there")


def _with(tmp_path, row: int, pressure: str) -> tuple[Path, int]:
    lines = CAMOES.read_text().splitlines(keepends=True)
    first = next(i for i, x in enumerate(lines) if x.startswith("time_s")) + 1
    i = first + row
    t, _, a = lines[i].rstrip("\n").split(",")
    lines[i] = f"{t},{pressure},{a}\n"
    p = tmp_path / "glitch.csv"
    p.write_text("".join(lines))
    return p, i + 1


@pytest.mark.parametrize("pressure, what", [("5000", "19216 m above the pad, 19323 m ASL"),
                                            ("115000", "-1188 m above the pad, -1081 m ASL")])
def test_a_glitch_row_is_refused_at_its_line(tmp_path, pressure, what):
    p, line = _with(tmp_path, 3000, pressure)
    r = run_fsw("tape", "truth", str(p))
    assert r.code == 1, r.err
    assert "Traceback" not in r.err
    assert r.err.startswith(f"fsw tape truth: {p}:{line}: pressure_pa {pressure} is "), r.err
    assert what in r.err and "beyond the ISA troposphere" in r.err, r.err
    assert not (tmp_path / "glitch.truth.toml").exists()


def test_the_shared_tapes_have_none(tmp_path):
    for tape in sorted(FLIGHTS.glob("*.csv")):
        check_altitudes(read_tape(str(tape)))  # raises nothing
    shutil.copy(CAMOES, tmp_path / "c.csv")
    r = run_fsw("tape", "truth", str(tmp_path / "c.csv"))
    assert r.code == 0, r.err
    assert "apogee_s = 24.31" in (tmp_path / "c.truth.toml").read_text()


def test_a_tape_made_in_memory_is_located_by_row(tmp_path):
    import numpy as np

    from fswkit.tape import Tape

    t = Tape("mem", np.array([-0.1, 0.0, 0.1]), np.array([100000.0, 1.0, 99990.0]), np.full(3, np.nan))
    with pytest.raises(TapeError) as e:
        check_altitudes(t)
    assert str(e.value).startswith("mem: row 2: pressure_pa 1 is "), str(e.value)
