"""`fsw gen PROJECT --sketch DIR` ended with `build it with: arduino-cli
compile -b arduino:avr:uno DIR`: pasted by someone who has not linked the
runtime into their sketchbook (step 1 of integrations/arduino-cli/README.md)
it fails on `#include <fswkit.h>`, and a DIR under a folder with a space
in its name split into two arguments. The command printed now names the
kit's runtime library (`--library KIT/firmware`, a folder arduino-cli
takes as a library: its library.properties) and quotes what needs it, so
it works pasted as it is."""

from __future__ import annotations

import os
import shlex

from conftest import EXAMPLES, ROOT, run_fsw


def _command(err: str) -> list[str]:
    line = err.split("build it with: ", 1)[1].splitlines()[0]
    return shlex.split(line)


def test_the_command_names_the_runtime_library(tmp_path):
    sketch = tmp_path / "my sketches" / "tank"
    r = run_fsw("gen", str(EXAMPLES / "tank"), "--sketch", str(sketch))
    assert r.code == 0, r.err
    argv = _command(r.err)
    assert argv[:4] == ["arduino-cli", "compile", "-b", "arduino:avr:uno"], argv
    assert argv[-1] == str(sketch), argv  # one argument, the space and all
    library = argv[argv.index("--library") + 1]
    assert os.path.samefile(library, ROOT / "firmware")
    assert os.path.isfile(os.path.join(library, "library.properties"))
    assert (sketch / "tank.ino").is_file()
