"""The kit's main() (a firmware without PWM outputs: docs/runtime.md) never
returns, but the compiler saved the callee-saved registers it used for its
caller all the same, in the stack every path of the firmware pays: 2 bytes
of the whole rocket's (r28, r29 for its frame), 16 once the executor's
cycle, inlined into it, used more registers (the rocket's stack 109 -> 123
B on the demo flight). main() is now OS_main: no register saved, its frame
set up without them (interrupts are still off when it starts); the whole
rocket's stack on the demo flight 107 B, the core's 56 B."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from conftest import EXAMPLES
from support.simfw import project_elf

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")


def test_the_rockets_main_pushes_nothing_for_its_caller():
    elf = Path(project_elf(str(EXAMPLES / "rocket"), "uno"))  # kept between runs (support.simfw)
    gen = (elf.parent / "gen" / "app.gen.cpp").read_text()
    assert "__attribute__((OS_main)) int main() {" in gen
    dis = subprocess.run(["avr-objdump", "-d", str(elf)], capture_output=True,
                         text=True, check=True).stdout
    body = dis[dis.index("<main>:\n"):]
    head = [line.split("\t")[2] for line in body.splitlines()[1:12] if line.count("\t") >= 2]
    # before: `push r28`, `push r29` (or a jump into __prologue_saves__) first
    assert not any(re.match(r"push\s+r(\d+)", h) for h in head), head
    assert "__prologue_saves__" not in "\n".join(body.splitlines()[:12]), body[:800]
