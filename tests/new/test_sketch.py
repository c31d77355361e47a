"""`fsw gen PROJECT --sketch DIR`: an Arduino sketch folder arduino-cli
builds with the fswkit library installed. The compile tests run only where
arduino-cli is on PATH. FSW_ARDUINO_CLI_FLAGS gives the arguments that
choose the core (a --config-file, --build-property...); without it they
compile offline against Debian's Arduino core, the way
integrations/arduino-cli/README.md describes (a config whose sketchbook links
the core and whose indexes are empty, Debian's arduino-ctags, DECIMAL_DIG)."""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess

import pytest

from conftest import EXAMPLES, ROOT
from fswkit.new.sketch import BUILD_PROPERTIES

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
    yaml = (sketch / "sketch.yaml").read_text()
    assert yaml.endswith("default_fqbn: arduino:avr:uno\n")
    # fsw build's flags, named for the command line (the folder cannot carry them)
    assert "#   --build-property 'compiler.c.elf.extra_flags=-Wl,--relax -ffunction-sections -fdata-sections -fno-toplevel-reorder'\n" \
        in yaml
    assert "#   --build-property 'compiler.cpp.extra_flags=-mcall-prologues -mstrict-X -fno-move-loop-invariants -fno-tree-vrp -fira-algorithm=priority'\n" \
        in yaml
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


DEBIAN_CORE = "/usr/share/arduino/hardware/arduino/avr"

needs_arduino_cli = pytest.mark.skipif(shutil.which("arduino-cli") is None, reason="arduino-cli not installed")


def arduino_cli(sketch, out, tmp_path, kit_flags=False):
    """`arduino-cli compile` of the sketch for the Uno; the process."""
    props = dict(BUILD_PROPERTIES) if kit_flags else {}
    if "FSW_ARDUINO_CLI_FLAGS" in os.environ:
        choose = shlex.split(os.environ["FSW_ARDUINO_CLI_FLAGS"])
    else:
        if not os.path.isfile(os.path.join(DEBIAN_CORE, "platform.txt")) or shutil.which("arduino-ctags") is None:
            pytest.skip("Debian's arduino-core-avr or arduino-ctags not installed, and no FSW_ARDUINO_CLI_FLAGS")
        cfg = tmp_path / "arduino-cli"
        (cfg / "user" / "hardware" / "arduino").mkdir(parents=True, exist_ok=True)
        (cfg / "data").mkdir(exist_ok=True)
        link = cfg / "user" / "hardware" / "arduino" / "avr"
        if not link.is_symlink():
            link.symlink_to(DEBIAN_CORE)
        (cfg / "data" / "package_index.json").write_text('{"packages": []}\n')
        (cfg / "data" / "library_index.json").write_text('{"libraries": []}\n')
        (cfg / "cli.yaml").write_text(f"directories:\n  user: {cfg / 'user'}\n  data: {cfg / 'data'}\n"
                                      f"  downloads: {cfg / 'downloads'}\n")
        choose = ["--config-file", str(cfg / "cli.yaml"), "--build-property", "tools.ctags.path=/usr/bin",
                  "--build-property", "tools.ctags.cmd.path={path}/arduino-ctags"]
        props["compiler.cpp.extra_flags"] = ("-DDECIMAL_DIG=__DECIMAL_DIG__ "
                                             + props.get("compiler.cpp.extra_flags", "")).strip()
    cmd = ["arduino-cli", "compile", "-b", "arduino:avr:uno", "--library", str(ROOT / "firmware"),
           "--output-dir", str(out), "--build-path", str(out) + "-build"] + choose
    for k, v in props.items():
        cmd += ["--build-property", f"{k}={v}"]
    r = subprocess.run(cmd + [str(sketch)], capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stdout + r.stderr
    return r


def sections(elf) -> dict[str, int]:
    r = subprocess.run(["avr-size", "-A", str(elf)], capture_output=True, text=True, check=True)
    return {p[0]: int(p[1]) for p in (ln.split() for ln in r.stdout.splitlines()) if len(p) == 3 and p[1].isdigit()}


@needs_arduino_cli
def test_arduino_cli_compiles_the_exported_sketch(fsw, tmp_path):
    sketch = tmp_path / "tank"
    assert fsw("gen", str(TANK), "--sketch", str(sketch)).code == 0
    r = arduino_cli(sketch, tmp_path / "out", tmp_path)
    assert "Sketch uses" in r.stdout
    assert (tmp_path / "out" / "tank.ino.hex").is_file()


@needs_arduino_cli
def test_with_the_kits_flags_arduino_cli_builds_fsw_builds_firmware(fsw, tmp_path):
    """The Arduino IDE's flags lack -mcall-prologues and -Wl,--relax: about
    5 % more flash. With them as build properties (the ones sketch.yaml
    names), arduino-cli's firmware is
    `fsw build`'s to within the few bytes LTO places differently because
    arduino-cli archives the core's objects in another order (measured: 12 B
    of 10,436 for the tank on the Uno); RAM is the same."""
    sketch = tmp_path / "tank"
    assert fsw("gen", str(TANK), "--sketch", str(sketch)).code == 0
    assert fsw("build", str(TANK), "--board", "uno", "--out", str(tmp_path / "fsw")).code == 0
    kit = sections(tmp_path / "fsw" / "tank.elf")
    arduino_cli(sketch, tmp_path / "plain", tmp_path)
    arduino_cli(sketch, tmp_path / "flags", tmp_path, kit_flags=True)
    plain, flags = sections(tmp_path / "plain" / "tank.ino.elf"), sections(tmp_path / "flags" / "tank.ino.elf")

    def flash(s):
        return s[".text"] + s[".data"]

    assert abs(flash(flags) - flash(kit)) <= 32, (flash(flags), flash(kit))
    assert flash(plain) > flash(kit) * 1.03, (flash(plain), flash(kit))
    for ram in (".data", ".bss", ".noinit"):
        assert flags.get(ram, 0) == kit.get(ram, 0) == plain.get(ram, 0), ram


def test_the_sketchs_size_flags_are_fsw_builds():
    """The build properties sketch.yaml names carry mk/build.mk's SIZE_OPT
    whole (two of its four were missing once: 2.6 % more flash)."""
    import re

    from fswkit.new.sketch import SIZE_FLAGS

    opt = re.search(r"^SIZE_OPT\s*:=\s*(.+)$", (ROOT / "mk" / "build.mk").read_text(), re.M).group(1).split()
    assert SIZE_FLAGS.split() == opt
    assert BUILD_PROPERTIES["compiler.c.extra_flags"] == BUILD_PROPERTIES["compiler.cpp.extra_flags"] == SIZE_FLAGS
