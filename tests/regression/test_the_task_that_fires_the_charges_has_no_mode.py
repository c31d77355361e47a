"""The outputs task that drives the pyro pins could take `mode=`: with
`act outputs rate=100 mode=actMode start=disabled`, `fsw check` passed,
and the firmware booted with the charges' task stopped: no charge could
fire until the ground enabled it (and, until the target locked that
task's mode, the ground's `fsw cmd
mode act disabled` in a pulse left the pin high:
test_the_ground_cannot_stop_a_pulse.py). That task runs always.

Now `fsw check` refuses a `mode=` (and so a `start=`) on the outputs task
that drives the pyro channels, at its `mode=`; another outputs task may
still have one."""

from __future__ import annotations

import shutil

from conftest import EXAMPLES


def rocket(tmp_path, tasks: str):
    shutil.copytree(EXAMPLES / "rocket", tmp_path / "rocket")
    sv = tmp_path / "rocket" / "rocket.sv"
    sv.write_text(sv.read_text().replace("[Nav]\n", "[Nav]\nU8   actMode\nU8   slowMode\n"))
    app = tmp_path / "rocket" / "rocket.app"
    text = app.read_text()
    old = "act      outputs           rate=100\n"
    assert old in text
    app.write_text(text.replace(old, tasks))
    return app


def test_a_mode_on_the_pyro_outputs_task_is_refused(fsw, tmp_path):
    app = rocket(tmp_path, "act      outputs           rate=100  mode=actMode  start=enabled\n")
    r = fsw("check", str(app))
    assert r.code == 1, r.err
    assert "rocket.app:28:38:" in r.err
    assert ("task `act` drives the pyro channels (drogue, main) and counts their pulses down: it cannot have a "
            "mode (it runs always: `fsw cmd mode act disabled` in a pulse would leave the charge's pin high, and "
            "the target refuses it); drop its `mode=`") in r.err
    assert "Traceback" not in r.err


def test_another_outputs_task_may_have_one(fsw, tmp_path):
    app = rocket(tmp_path, "act      outputs           rate=100\nslow     outputs           rate=10  mode=slowMode\n")
    r = fsw("check", str(app))
    assert r.code == 0, r.err
