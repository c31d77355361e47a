"""The outputs task that drives the pyro pins could take `mode=`: with
`act outputs rate=100 mode=actMode`, `fsw check` passed, and the ground's
`fsw cmd mode act disabled` (or `safed`, or `start=disabled`) in the
middle of a drogue's pulse stopped the only code that ends it: a disabled
or safed task runs no step, so the pin stayed high with the firing
current on for as long as the ground liked (docs/safety.md said so under
"What the gate does not do"). The pulse's bound, the gate's promise, was
the ground's to break.

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
            "mode (`fsw cmd mode act disabled` in a pulse would leave the charge's pin high)") in r.err
    assert "Traceback" not in r.err


def test_another_outputs_task_may_have_one(fsw, tmp_path):
    app = rocket(tmp_path, "act      outputs           rate=100\nslow     outputs           rate=10  mode=slowMode\n")
    r = fsw("check", str(app))
    assert r.code == 0, r.err
