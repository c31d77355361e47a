"""A machine task asked before each step whether the clock had ticked since
its machine's last step (fsw::machine_same_tick: G's 8 bytes compared with
the last G, a call of memcmp), and the step's machine_begin then compared
them again: on the rocket's nav and mission about 4 us a cycle on the
simulated Uno for a question whose answer is almost always no.

Now a machine task without an uploaded image steps first, and asks only
when the step refused its G (kErrTime): machine_begin refuses a G that is
not above the last before it changes anything, so a refused step in the
same tick is left for the next run as before (kOk), and a G that went back
is still the step's error. (The task of a machine that can be replaced at
run time still asks first: reload_step may switch images before it
steps.) tests/firmware/test_machine.cpp holds the runtime to what this
relies on: a refused machine_begin leaves the Machine and S as they were."""

from __future__ import annotations

import re

from conftest import run_fsw
from support.configs import example_copy


def _task(cpp: str, name: str) -> str:
    start = cpp.index(f"fsw::Result task_{name}(void*) {{")
    return cpp[start:cpp.index("\n}\n", start)]


def test_the_rockets_machine_tasks_step_before_they_ask_about_the_tick(tmp_path):
    proj = example_copy("rocket", tmp_path)
    r = run_fsw("gen", str(proj), "--out", str(tmp_path / "gen"))
    assert r.code == 0, r.out + r.err
    cpp = (tmp_path / "gen" / "app.gen.cpp").read_text()
    for task, machine in (("nav", "nav"), ("mission", "mission")):
        body = _task(cpp, task)
        step = body.index(f"{machine}::step()")
        same = body.index(f"fsw::machine_same_tick({machine}::machine")
        assert step < same, body  # before: the same-tick test first, on every run
        assert re.search(r"r == fsw::kErrTime && fsw::machine_same_tick\(", body), body
        assert body.count("machine_same_tick") == 1, body


def test_a_reloadable_machines_task_still_asks_first(tmp_path):
    proj = example_copy("rocket", tmp_path)
    app = proj / "rocket.app"
    text = re.sub(r"(?m)^board\s+\w+", "board mega2560", app.read_text(), count=1)
    text = re.sub(r"(?m)^\[budget\][^\[]*", "", text)  # the Uno's budget
    app.write_text(text + "\n[reload]\nmachine  mission\nsize     1024\nram      192\nactivate Safe\n")
    r = run_fsw("gen", str(proj), "--out", str(tmp_path / "gen"))
    assert r.code == 0, r.out + r.err
    body = _task((tmp_path / "gen" / "app.gen.cpp").read_text(), "mission")
    # reload_step may switch images before it steps: the tick is asked about first
    assert body.index("fsw::machine_same_tick(mission::machine") < body.index("fsw::reload_step(reload)"), body
    nav = _task((tmp_path / "gen" / "app.gen.cpp").read_text(), "nav")
    assert nav.index("nav::step()") < nav.index("fsw::machine_same_tick(nav::machine"), nav
