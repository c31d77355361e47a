"""An application with pyro channels keeps its flight across a reset in
spans of RAM (docs/safety.md), counted in a byte: the state vector, each
machine's state, locals and windows, the pyro gates, the modes of each run
of tasks without a `mode=` element, .... An application of over 255 such
parts (first found as the rocket with 240 more `inputs` tasks, each mode a
part of its own then; since a run of such tasks is one part, here the
rocket with 90 more machines of three parts each) passed `fsw check` and
then failed to compile (the count narrowed into its byte). `fsw check` now
refuses it at its first pyro channel, saying how many parts it has and how
to need fewer."""

from __future__ import annotations

from conftest import run_fsw
from support.configs import edit, example_copy

N_MACHINES = 90  # a state, locals and a window each: 270 parts with the rocket's


def test_too_many_kept_parts_is_a_check_error(tmp_path):
    proj = example_copy("rocket", tmp_path)
    edit(proj / "rocket.sv", "[Nav]\n", "[Extra]\n" + "".join(f"U32  x{i:03d}State\n" for i in range(N_MACHINES))
         + "\n[Nav]\n")
    for i in range(N_MACHINES):
        (proj / f"x{i:03d}.sm").write_text(
            "[state_vector]\nU64  time  @alias G\n"
            f"U32  x{i:03d}State  @alias S\nF32  pressure  @read_only\n\n"
            "[local]\nF32 v = 0\n\n[Run]\n.step\n    v = roll_avg(pressure, 2)\n")
    edit(proj / "rocket.app", "machine      mission.sm\n",
         "machine      mission.sm\n" + "".join(f"machine      x{i:03d}.sm\n" for i in range(N_MACHINES)))
    edit(proj / "rocket.app", "sense    inputs            rate=100\n", "sense    inputs            rate=100\n"
         + "".join(f"x{i:03d}     machine x{i:03d}      rate=100\n" for i in range(N_MACHINES)))
    line = next(n for n, l in enumerate((proj / "rocket.app").read_text().splitlines(), 1) if l.startswith("drogue "))
    r = run_fsw("check", str(proj))
    out = r.out + r.err
    assert r.code == 1, out
    assert f"rocket.app:{line}:1:" in out and "at most 255" in out and "mode=" in out, out


def test_many_tasks_without_a_mode_element_are_few_parts(tmp_path):
    """The 240 more `inputs` tasks that were 247 parts: one run, one part."""
    proj = example_copy("rocket", tmp_path)
    extra = "".join(f"in{i:03d}    inputs            rate=100\n" for i in range(240))
    edit(proj / "rocket.app", "sense    inputs            rate=100\n", "sense    inputs            rate=100\n" + extra)
    r = run_fsw("check", str(proj))
    assert "parts of RAM" not in r.out + r.err, r.out + r.err


def test_the_rocket_as_it_is_keeps_few_parts(tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.emit.resume import resume_spans
    from fswkit.target.build import load

    app = load(str(example_copy("rocket", tmp_path)), Diagnostics(), None)
    spans = resume_spans(app)
    assert 5 <= len(spans) <= 20, spans
