"""`fsw machine upload` checked the uploaded machine alone, against the state
vector: never in the application whose generated machine it replaces. It
took a machine that writes an element an input channel writes (the tank's
pressure, overwritten), a machine with its states in another order (the
ground then names every state by the generated machine's numbers, and the
recorder and the pyro gates hold those numbers too: the rocket's drogue
gate opens in "state 5", Apogee in the generated machine and whatever the
upload made it), and a mission machine that sets its drogue charge in
Coast, which `fsw check` proves the generated one never does. Now the
uploaded machine keeps the generated machine's states at their numbers
(new ones after them), and the application is checked again with it in
place: each refusal located in the uploaded file, before a port is
opened."""

from __future__ import annotations

import re
import shutil

import pytest

from conftest import EXAMPLES

STAND = EXAMPLES / "stand"
NEW = STAND / "tank_700.sm"
PORT = "/dev/ttyNOPE"


def _upload(fsw, project, sm):
    return fsw("machine", str(project), "upload", str(sm), "--port", PORT)


def _accepted(r) -> bool:
    """The host's checks passed: the command went on to the port."""
    assert "Traceback" not in r.err
    return r.code == 1 and PORT in r.err


def _line(path, text: str) -> int:
    return next(i for i, row in enumerate(path.read_text().splitlines(), 1) if row.startswith(text))


def test_states_in_another_order_are_refused_at_the_first_that_moved(fsw, tmp_path):
    sm = tmp_path / "swapped.sm"
    text = NEW.read_text()
    sm.write_text(text[:text.index("[Abort]")] + "[Idle]\n\n[Abort]\n")
    r = _upload(fsw, STAND, sm)
    assert r.code == 2, r.err
    assert f"swapped.sm:{_line(sm, '[Idle]')}:2:" in r.err, r.err
    assert "state 2 is `Idle` here but `Abort` in the generated machine `tank`" in r.err


def test_a_state_of_the_generated_machine_left_out_is_refused(fsw, tmp_path):
    sm = tmp_path / "short.sm"
    text = NEW.read_text()
    sm.write_text(text[:text.index("[Idle]")].replace("-> Idle", "-> Abort"))
    r = _upload(fsw, STAND, sm)
    assert r.code == 2, r.err
    assert "machine `short` has 2 states: the generated machine `tank` has 3 (Idle missing)" in r.err


def test_new_states_after_the_generated_ones_are_taken(fsw, tmp_path):
    sm = tmp_path / "more.sm"
    sm.write_text(NEW.read_text() + "\n[Hold]\n.step\n    T > 100: -> Idle\n")
    assert _accepted(_upload(fsw, STAND, sm))
    assert _accepted(_upload(fsw, STAND, NEW))


def test_an_element_an_input_channel_writes_is_refused_where_it_is_written(fsw, tmp_path):
    sm = tmp_path / "writes_input.sm"
    text = NEW.read_text().replace("F64 tankPressure @read_only", "F64 tankPressure")
    sm.write_text(text.replace(".entry\n    counter = 0\n", ".entry\n    counter = 0\n    tankPressure = 0\n"))
    r = _upload(fsw, STAND, sm)
    assert r.code == 2, r.err
    assert f"writes_input.sm:{_line(sm, '    tankPressure = 0')}:5:" in r.err, r.err
    assert "element `tankPressure` is already written by input channel" in r.err


@pytest.fixture
def rocket(tmp_path):
    """examples/rocket on an ATmega2560 with its mission machine reloadable
    (tools/bench_reload.py's variant)."""
    folder = tmp_path / "rocket"
    shutil.copytree(EXAMPLES / "rocket", folder, ignore=shutil.ignore_patterns("build"))
    app = folder / "rocket.app"
    text = re.sub(r"(?m)^board\s+\w+", "board mega2560", app.read_text(), count=1)
    text = re.sub(r"(?m)^\[budget\][^\[]*", "", text)
    app.write_text(text + "\n[reload]\nmachine  mission\nsize     1024\nram      192\nactivate Safe\n")
    return folder


def test_a_mission_that_fires_its_drogue_outside_its_fire_states_is_refused(fsw, rocket):
    sm = rocket / "early.sm"
    text = (rocket / "mission.sm").read_text()
    sm.write_text(text.replace("[Coast]\n.entry\n", "[Coast]\n.entry\n    drogue = true\n"))
    r = _upload(fsw, rocket, sm)
    assert r.code == 2, r.err
    assert f"early.sm:{_line(sm, '    drogue = true')}:5:" in r.err, r.err
    row = _line(rocket / "rocket.app", "drogue ")
    assert f"pyro channel `drogue` (rocket.app:{row}) can fire here, in state `Coast`, which is not one of its fire " \
           "states (Apogee)" in r.err


def test_a_mission_whose_states_moved_is_refused_and_the_same_one_taken(fsw, rocket):
    sm = rocket / "moved.sm"
    text = (rocket / "mission.sm").read_text()
    sm.write_text(text.replace("[Apogee]\n", "[Hold]\n\n[Apogee]\n", 1))
    r = _upload(fsw, rocket, sm)
    assert r.code == 2, r.err
    assert "state 5 is `Hold` here but `Apogee` in the generated machine `mission`" in r.err
    same = rocket / "mission_2.sm"
    same.write_text(text)
    assert _accepted(_upload(fsw, rocket, same))
