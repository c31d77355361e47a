"""`fsw gen PROJECT --sketch DIR`: an Arduino sketch folder arduino-cli
builds with the fswkit library installed. The compile test runs only where
arduino-cli is on PATH; FSW_ARDUINO_CLI_FLAGS adds arguments to its command
line (a --config-file, --build-property for Debian's core)."""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess

import pytest

from conftest import EXAMPLES, ROOT

TANK = EXAMPLES / "tank"


def test_sketch_folder_holds_the_generated_code_an_ino_and_the_fqbn(fsw, tmp_path):
    sketch = tmp_path / "tank_rig"
    r = fsw("gen", str(TANK), "--sketch", str(sketch))
    assert r.code == 0, r.err
    assert "arduino-cli compile -b arduino:avr:uno" in r.err
    names = sorted(p.name for p in sketch.iterdir())
    assert names == ["app.gen.cpp", "sketch.yaml", "sv.gen.cpp", "sv.gen.h", "tank.gen.cpp", "tank.gen.h",
                     "tank_rig.ino"]
    ino = (sketch / "tank_rig.ino").read_text()
    assert "#include <fswkit.h>" in ino and '#include "tank.gen.h"' in ino
    assert "void setup" not in ino  # app.gen.cpp holds setup() and loop()
    assert "void setup() {" in (sketch / "app.gen.cpp").read_text()
    assert (sketch / "sketch.yaml").read_text().endswith("default_fqbn: arduino:avr:uno\n")
    ref = tmp_path / "ref"
    assert fsw("gen", str(TANK), "--out", str(ref)).code == 0
    for p in ref.iterdir():
        assert (sketch / p.name).read_bytes() == p.read_bytes()


def test_sketch_for_another_board_names_its_fqbn(fsw, tmp_path):
    r = fsw("gen", str(TANK), "--board", "mega2560", "--sketch", str(tmp_path / "tank"))
    assert r.code == 0, r.err
    assert "default_fqbn: arduino:avr:mega:cpu=atmega2560" in (tmp_path / "tank" / "sketch.yaml").read_text()


def test_sketch_errors(fsw, tmp_path):
    r = fsw("gen", str(TANK), "--board", "native", "--sketch", str(tmp_path / "tank"))
    assert r.code == 2 and "board `native` is not an Arduino board" in r.err
    r = fsw("gen", str(TANK), "--sketch", str(tmp_path / "-tank"))
    assert r.code == 2 and "`-tank` cannot name an Arduino sketch" in r.err
    r = fsw("gen", str(TANK), "--sketch", str(tmp_path / "a"), "--out", str(tmp_path / "b"))
    assert r.code == 2 and "not allowed with argument" in r.err


@pytest.mark.skipif(shutil.which("arduino-cli") is None, reason="arduino-cli not installed")
def test_arduino_cli_compiles_the_exported_sketch(fsw, tmp_path):
    sketch = tmp_path / "tank"
    assert fsw("gen", str(TANK), "--sketch", str(sketch)).code == 0
    cmd = ["arduino-cli", "compile", "-b", "arduino:avr:uno", "--library", str(ROOT / "firmware"),
           "--output-dir", str(tmp_path / "out")] + shlex.split(os.environ.get("FSW_ARDUINO_CLI_FLAGS", ""))
    r = subprocess.run(cmd + [str(sketch)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "Sketch uses" in r.stdout
    assert (tmp_path / "out" / "tank.ino.hex").is_file()
