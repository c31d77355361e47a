"""An error in a parameters file (plant.toml, a dispersion file) names the
line of the key at fault, also where TOML lets a key be written dotted
(`vehicle.mass_sd = 0.1`, at the top or inside another table), and an
array of tables (`[[barometer]]`) is one error that says what to write,
not an unknown key followed by a second message."""

from __future__ import annotations

import pytest
from conftest import EXAMPLES, run_fsw

from fswkit.plant import dispersion
from fswkit.plant.params import ParamsError


def _errors(tmp_path, text: str) -> list[str]:
    p = tmp_path / "d.toml"
    p.write_text(text)
    with pytest.raises(ParamsError) as e:
        dispersion.load(str(p))
    return [m.replace(f"{p}:", "d.toml:") for m in e.value.errors]


@pytest.mark.parametrize("text,expect", [
    # a dotted key inside another table: its own line, not the table's header
    ("# a study\n\n[motor]\nimpulse_sd = 0.03\n\n[wind]\nvehicle.mass_sd = \"x\"\n",
     "d.toml:7: [wind] unknown key `vehicle`"),
    ("[motor]\nimpulse_sd = 0.03\nvehicle.mass_sd = 0.1\n", "d.toml:3: [motor] unknown key `vehicle`"),
    ("[motor]\nimpulse_sd = 0.03\n\n\nvehicle.mass_sd = 0.1\n", "d.toml:5: [motor] unknown key `vehicle`"),
    # dotted at the top: a table's key written on one line
    ("# a study\nvehicle.mass_sd = \"x\"\n", "d.toml:2: [vehicle] mass_sd: expected a number"),
    ("vehicle . drag_sd = 0.1\nvehicle.mass_sd = -1\n", "d.toml:2: [vehicle] mass_sd: -1 is out of range"),
    ("wind.gust.sd = 1\n", "d.toml:1: [wind] unknown key `gust`"),
])
def test_dotted_keys_are_located_on_their_own_line(tmp_path, text, expect):
    errs = _errors(tmp_path, text)
    assert len(errs) == 1 and errs[0].startswith(expect), errs


def test_an_array_of_tables_is_one_error_that_says_what_to_write(tmp_path):
    errs = _errors(tmp_path, "[motor]\nimpulse_sd = 0.03\n\n[[barometer]]\nbias_sd = 4\n")
    assert errs == ["d.toml:4: `barometer` must be a table [barometer], not an array of tables [[barometer]]"], errs


def test_the_command_line_says_so(tmp_path):
    p = tmp_path / "d.toml"
    p.write_text("[motor]\nimpulse_sd = 0.03\n[vehicle]\nmass_sd = 0.03\n[wind]\nvehicle.drag_sd = \"x\"\n")
    r = run_fsw("sim", str(EXAMPLES / "rocket"), "--plant", "rocket", "--runs", "2", "--dispersion", str(p),
                "--out", str(tmp_path / "out"))
    assert r.code == 2, r.err
    assert f"{p}:6: [wind] unknown key `vehicle`" in r.err, r.err
    assert "Traceback" not in r.err
