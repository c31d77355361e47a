"""The flight's save (docs/safety.md, "A reset in flight") copied the mode
of each task without a `mode=` element as a span of its own: one byte of
each task's TaskStats, about 40 AVR cycles a span every cycle, where the
byte itself takes 9 (the rocket's seven tasks: 280 cycles a save). Now a
run of such tasks is one strided span (`fsw::resume_strided`: a byte of
each record), the same bytes in the same order in the bank; a task with a
`mode=` element (its mode in the state vector) ends a run. That the
firmware keeps and restores those bytes: tests/firmware/test_resume.cpp
and tests/regression/test_a_resume_keeps_the_tasks_modes.py."""

from __future__ import annotations

import re

from support.configs import edit, example_copy


def _spans(proj):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.emit.resume import resume_spans
    from fswkit.target.build import load

    diags = Diagnostics()
    app = load(str(proj), diags, None)
    assert app is not None and not diags.errors, diags.render()
    return [(p, n) for p, n, _ in resume_spans(app)]


def test_the_rockets_seven_task_modes_are_one_span(tmp_path):
    spans = _spans(example_copy("rocket", tmp_path))
    modes = [(p, n) for p, n in spans if "stats[" in p]
    assert modes == [("&stats[0].mode", "fsw::resume_strided(7, sizeof(fsw::TaskStats))")], spans


def test_a_task_with_a_mode_element_ends_a_run(tmp_path):
    proj = example_copy("rocket", tmp_path)
    edit(proj / "rocket.sv", "[Nav]\n", "[Nav]\nU8   navMode\n")
    edit(proj / "rocket.app", "nav      machine nav       rate=100", "nav      machine nav       rate=100  mode=navMode")
    modes = [(p, n) for p, n in _spans(proj) if "stats[" in p]
    assert modes == [("&stats[0].mode", "fsw::resume_strided(2, sizeof(fsw::TaskStats))"),
                     ("&stats[3].mode", "fsw::resume_strided(4, sizeof(fsw::TaskStats))")], modes


def test_the_generated_size_counts_a_strided_span_by_its_bytes(tmp_path):
    from conftest import run_fsw

    proj = example_copy("rocket", tmp_path)
    r = run_fsw("gen", str(proj), "--out", str(tmp_path / "gen"))
    assert r.code == 0, r.out + r.err
    cpp = (tmp_path / "gen" / "app.gen.cpp").read_text()
    [size] = re.findall(r"const uint16_t kResumeSize = (.*);", cpp)
    # the rocket's 307 B: the state vector, two machines' bookkeeping, locals and windows, the pyro
    # gates, then the 7 modes' bytes (not the strided span's encoded size) and the recorder's 2
    assert size.endswith(" + static_cast<uint16_t>(sizeof Pyro) + static_cast<uint16_t>(7) + "
                         "static_cast<uint16_t>(2)"), size
