"""docs/sim.md's `SimBoard` example set A0 to 800 psi, ran 1 ms and
asserted the tank's vent valve open: the tank's tasks run at 100 Hz, so
the valve opens up to 10 ms after a change of A0 and the example failed
its own assert (12 ms after it, here). It now runs 20 ms, two of the
tasks' cycles. Its "Stack and RAM" example printed, it said,
`RamUsage(static=528, stack=208, total=736, ...)`: the tank's firmware of
today gives 505, 112 and 617. A doc claim is a test: the examples run as
written, on the tank's firmware as `fsw sim` builds it, and print what the
doc shows (its byte counts, measured figures, updated by hand)."""

from __future__ import annotations

import os
import re
import shutil

import pytest

from conftest import EXAMPLES, ROOT
from support.simfw import kept_sim

pytestmark = pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                reason="gcc-avr and libsimavr-dev are needed (make setup)")

DOC_ELF = "examples/tank/build/uno/tank.elf"


def test_the_python_example_of_docs_sim_md_runs_as_written(capsys):
    text = (ROOT / "docs" / "sim.md").read_text()
    m = re.search(r"^## Python: `SimBoard`\n\n```python\n(.*?)^```", text, re.M | re.S)
    assert m, "docs/sim.md has no SimBoard example"
    code = m.group(1)
    assert f'SimBoard("{DOC_ELF}", "uno",' in code and "assert b.digital(4)" in code
    elf, _board = kept_sim(EXAMPLES / "tank")  # the doc's ELF, built where tests keep their builds
    exec(compile(code.replace(DOC_ELF, str(elf)), "docs/sim.md", "exec"), {})
    cycle, t, edges = capsys.readouterr().out.split(" ", 2)
    assert 0.069 < float(t) < 0.071 and "pin=4" in edges and "level=True" in edges


def test_the_stack_and_ram_example_prints_what_docs_sim_md_says(capsys):
    text = (ROOT / "docs" / "sim.md").read_text()
    m = re.search(r"^## Stack and RAM\n.*?```python\n(.*?)^```", text, re.M | re.S)
    assert m, "docs/sim.md has no Stack and RAM example"
    code = m.group(1)
    shown = re.search(r"print\(b\.ram_usage\(\)\)\s+# (RamUsage\(.*\))", code)
    assert shown and DOC_ELF in code
    elf, _board = kept_sim(EXAMPLES / "tank")
    exec(compile(code.replace(DOC_ELF, str(elf)), "docs/sim.md", "exec"), {"SimBoard": __import__(
        "fswkit.sim.board", fromlist=["SimBoard"]).SimBoard})
    field = re.compile(r"RamUsage\(static=(\d+), stack=(\d+), total=(\d+), ram=(\d+)\)")
    printed = field.fullmatch(capsys.readouterr().out.strip())
    said = field.fullmatch(shown.group(1))
    assert printed and said  # the example prints what the doc shows, of the same form
    for static, stack, total, ram in (map(int, printed.groups()), map(int, said.groups())):
        assert static + stack == total and ram == 2048 and 0 < stack < 512
    # the figures themselves are the firmware's sizes, which the docs quote as measured (sim.md was 528/208
    # in a tree whose tank had 505 B static and 112 B stack): kept by hand, not held here
