"""An application with pyro channels keeps its flight across a reset in
spans of RAM (docs/safety.md), counted in a byte: the state vector, each
machine's state, locals and windows, the pyro gates, each task's mode
without a `mode=` element, .... An application of over 255 such parts
(here the rocket with 240 more `inputs` tasks, which may repeat) passed
`fsw check` and then failed to compile (the count narrowed into its
byte). `fsw check` now refuses it at its first pyro channel, saying how
many parts it has and how to need fewer."""

from __future__ import annotations

from conftest import run_fsw
from support.configs import edit, example_copy


def test_too_many_kept_parts_is_a_check_error(tmp_path):
    proj = example_copy("rocket", tmp_path)
    extra = "".join(f"in{i:03d}    inputs            rate=100\n" for i in range(240))
    edit(proj / "rocket.app", "sense    inputs            rate=100\n", "sense    inputs            rate=100\n" + extra)
    line = next(n for n, l in enumerate((proj / "rocket.app").read_text().splitlines(), 1) if l.startswith("drogue "))
    r = run_fsw("check", str(proj))
    out = r.out + r.err
    assert r.code == 1, out
    assert f"rocket.app:{line}:1:" in out and "at most 255" in out and "mode=" in out, out


def test_the_rocket_as_it_is_keeps_few_parts(tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.emit.resume import resume_spans
    from fswkit.target.build import load

    app = load(str(example_copy("rocket", tmp_path)), Diagnostics(), None)
    spans = resume_spans(app)
    assert 10 <= len(spans) <= 20, spans
