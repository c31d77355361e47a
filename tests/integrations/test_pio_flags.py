"""PlatformIO's board environments compile with `fsw build`'s flags.

`pio run` itself needs the atmelavr platform, which is on no registry this
machine reaches, so the comparison is made from what can be read here:

- PlatformIO's side: the environment as `pio project config --json-output`
  reads platformio.ini (board_build.*, build_flags, build_unflags), on top of
  the flags the atmelavr platform's Arduino builder always passes
  (PIO_ARDUINO below, copied from platform-atmelavr 5.2.0,
  builder/frameworks/arduino.py) and the link flags the kit's hook adds
  (pio_hook.py's AVR_LINKFLAGS). The board settings are written out in
  platformio.ini, so they do not depend on the platform's board manifests.
- `fsw build`'s side: the commands mk/build.mk runs for the same board, as
  the build service calls it (`make -n` of target.build.make_args).

For each board environment: the MCU, the clock, the variant, -std for C and
C++, the -O level, the preprocessor defines and the flags that decide the
code's size (sections, LTO, call prologues, linker relaxation) must be the
same on both sides. Left out, and why:
- DECIMAL_DIG: the hook defines it when the toolchain lacks it
  (test_pio_hook.py); mk/build.mk always does (Debian's avr-gcc lacks it).
- the value of ARDUINO (the IDE version each claims, 10819 and 10808): no
  code in the core, the runtime or the generated code reads it.
- warnings and debug information (-Wall, -g, -w), -fpermissive, -fno-rtti
  (the firmware has no typeid or dynamic_cast), -fno-fat-lto-objects on C++:
  they change no byte of the firmware.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT
from fswkit.target.build import ARDUINO
from test_pio_config import needs_pio, project_config

# platform-atmelavr 5.2.0, builder/frameworks/arduino.py: what every
# `framework = arduino` build of the platform gets ($BOARD_MCU and
# $BOARD_F_CPU are the board's build.mcu and build.f_cpu; the board
# manifest's build.extra_flags adds the board define).
PIO_ARDUINO = {
    "CFLAGS": ["-std=gnu11", "-fno-fat-lto-objects"],
    "CCFLAGS": ["-mmcu=$BOARD_MCU", "-Os", "-Wall", "-ffunction-sections", "-fdata-sections", "-flto"],
    "CXXFLAGS": ["-fno-exceptions", "-fno-threadsafe-statics", "-fpermissive", "-std=gnu++11"],
    "LINKFLAGS": ["-mmcu=$BOARD_MCU", "-Os", "-Wl,--gc-sections", "-flto", "-fuse-linker-plugin"],
    "CPPDEFINES": ["F_CPU=$BOARD_F_CPU", "ARDUINO_ARCH_AVR", "ARDUINO=10808"],
}

# The flags compared, besides -mmcu, -std, -O and the defines: those that
# decide the code.
CODE_FLAGS = {"-ffunction-sections", "-fdata-sections", "-flto", "-mcall-prologues", "-mstrict-X",
              "-fno-move-loop-invariants", "-fno-tree-vrp", "-fira-algorithm=priority", "-fno-exceptions",
              "-fno-threadsafe-statics"}
LINK_FLAGS = {"-flto", "-fuse-linker-plugin", "-Wl,--gc-sections", "-Wl,--relax", "-mcall-prologues", "-mstrict-X",
              "-ffunction-sections", "-fdata-sections", "-fno-toplevel-reorder"}  # (at the link: LTO's own
#                                                                                  compilation, mk/build.mk)


def hook_linkflags() -> list[str]:
    """What integrations/platformio/pio_hook.py appends to an atmelavr
    build's LINKFLAGS (its AVR_LINKFLAGS), read from the hook's text."""
    import ast

    tree = ast.parse((ROOT / "integrations" / "platformio" / "pio_hook.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and [getattr(t, "id", None) for t in node.targets] == ["AVR_LINKFLAGS"]:
            return list(ast.literal_eval(node.value))
    return []
IGNORED_DEFINES = {"DECIMAL_DIG"}

BOARD_ENVS = {"uno": "uno", "nanoatmega328": "nano", "megaatmega2560": "mega2560"}


def _split(flags) -> list[str]:
    out = []
    for f in flags if isinstance(flags, list) else [flags]:
        out += str(f).split()
    return out


def _defines(flags: list[str]) -> dict[str, str]:
    return {f[2:].split("=", 1)[0]: (f[2:].split("=", 1) + [""])[1] for f in flags if f.startswith("-D")}


def pio_flags(env: dict) -> dict:
    """The compile and link flags of a PlatformIO environment: the platform's
    Arduino flags, the board settings, then build_flags (sorted as SCons's
    ParseFlags sorts them: -D to the defines, -Wl, to the linker, the rest
    to every compile) less build_unflags."""
    mcu, f_cpu = env.get("board_build.mcu", "?"), env.get("board_build.f_cpu", "?")

    def sub(fs):
        return [f.replace("$BOARD_MCU", mcu).replace("$BOARD_F_CPU", f_cpu) for f in fs]

    cc, c, cxx, link = (sub(PIO_ARDUINO[k]) for k in ("CCFLAGS", "CFLAGS", "CXXFLAGS", "LINKFLAGS"))
    link += hook_linkflags()
    defines = ["-D" + d for d in sub(PIO_ARDUINO["CPPDEFINES"])] + _split(env.get("board_build.extra_flags", ""))
    for f in _split(env.get("build_flags", [])):
        if f.startswith("-D"):
            defines.append(f)
        elif f.startswith("-Wl,"):
            link.append(f)
        else:
            cc.append(f)
    # With -flto the code is made at the link, with the target (-m) options
    # the objects were compiled with (GCC's lto-wrapper passes them on).
    link += [f for f in cc if f.startswith("-m") and f not in link]
    unflags = set(_split(env.get("build_unflags", [])))
    keep = [f for f in defines if f not in unflags]
    return {"c": [f for f in cc + c if f not in unflags] + keep,
            "cxx": [f for f in cc + cxx if f not in unflags] + keep,
            "link": [f for f in link if f not in unflags],
            "variant": env.get("board_build.variant", "?")}


def mk_flags(board: str, tmp_path) -> dict:
    """The flags of mk/build.mk's commands for `board`, as `fsw build` runs it."""
    from fswkit.autocode.app import load_app
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import make_args

    diags = Diagnostics()
    app = load_app(str(EXAMPLES / "tank" / "tank.app"), diags, board)
    assert app is not None, diags.render()
    out = tmp_path / board
    (out / "gen").mkdir(parents=True)
    (out / "gen" / "app.gen.cpp").write_text("")
    _, args = make_args(app, str(out))
    r = subprocess.run(args + ["-n", "-B"], capture_output=True, text=True, cwd=out, timeout=120)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()

    def line(pred):
        found = [ln.split() for ln in lines if pred(ln)]
        assert found, r.stdout
        return found[0]

    cxx = line(lambda ln: ln.startswith("avr-g++") and " -c gen/app.gen.cpp" in ln)
    c = line(lambda ln: ln.startswith("avr-gcc") and "/wiring.c " in ln and " -c " in ln)
    link = line(lambda ln: ln.startswith("avr-gcc") and " -o tank.elf" in ln)
    variant = [f for f in cxx if f.startswith("-I") and "/variants/" in f][0].rstrip("/").rsplit("/", 1)[1]
    return {"c": c, "cxx": cxx, "link": link, "variant": variant}


def _one(flags, prefix) -> list[str]:
    return sorted({f for f in flags if f.startswith(prefix)})


def differences(pio: dict, mk: dict) -> list[str]:
    """What differs between the two builds' flags, one line each ([] when none)."""
    diffs = []
    if pio["variant"] != mk["variant"]:
        diffs.append(f"variant: PlatformIO {pio['variant']}, fsw build {mk['variant']}")
    for kind in ("c", "cxx", "link"):
        p, m = pio[kind], mk[kind]
        for prefix in ("-mmcu=", "-std=", "-O"):
            if kind == "link" and prefix == "-std=":
                continue
            if _one(p, prefix) != _one(m, prefix):
                diffs.append(f"{kind} {prefix}: PlatformIO {_one(p, prefix)}, fsw build {_one(m, prefix)}")
        wanted = LINK_FLAGS if kind == "link" else CODE_FLAGS - ({"-fno-exceptions", "-fno-threadsafe-statics"}
                                                                 if kind == "c" else set())
        ps, ms = sorted(set(p) & wanted), sorted(set(m) & wanted)
        if ps != ms:
            diffs.append(f"{kind} flags: PlatformIO {ps}, fsw build {ms}")
        if kind != "link":
            pd, md = _defines(p), _defines(m)
            names = sorted((set(pd) | set(md)) - IGNORED_DEFINES)
            for n in names:
                if n not in pd or n not in md:
                    diffs.append(f"{kind} define {n}: only in {'PlatformIO' if n in pd else 'fsw build'}")
                elif n != "ARDUINO" and pd[n] != md[n]:
                    diffs.append(f"{kind} define {n}: PlatformIO {pd[n]}, fsw build {md[n]}")
    return diffs


needs_avr = pytest.mark.skipif(
    shutil.which("avr-g++") is None or shutil.which("make") is None
    or not (Path(ARDUINO) / "cores" / "arduino" / "Arduino.h").is_file(),
    reason="gcc-avr, make or Debian's Arduino core not installed (make setup)")


@needs_pio
@needs_avr
def test_board_environments_compile_with_fsw_builds_flags(tmp_path):
    cfg = project_config(ROOT, tmp_path)
    seen = []
    for env_name, board in BOARD_ENVS.items():
        env = cfg[f"env:{env_name}"]
        assert env["custom_fsw_board"] == board
        pio, mk = pio_flags(env), mk_flags(board, tmp_path)
        assert differences(pio, mk) == [], f"env:{env_name} against fsw build --board {board}"
        seen.append((env_name, _one(mk["cxx"], "-mmcu="), _defines(mk["cxx"])["F_CPU"]))
    assert seen == [("uno", ["-mmcu=atmega328p"], "16000000L"),
                    ("nanoatmega328", ["-mmcu=atmega328p"], "16000000L"),
                    ("megaatmega2560", ["-mmcu=atmega2560"], "16000000L")]


@needs_pio
@needs_avr
def test_a_mismatch_is_reported(tmp_path):
    ini = (ROOT / "platformio.ini").read_text()
    ini = ini.replace("board_build.f_cpu = 16000000L\nboard_build.variant = standard",
                      "board_build.f_cpu = 8000000L\nboard_build.variant = standard", 1)
    ini = ini.replace("build_flags = -mcall-prologues -mstrict-X -fno-move-loop-invariants -fno-tree-vrp -fira-algorithm=priority -Wl,--relax",
                      "build_flags = -O2 -DEXTRA=1", 1)
    assert "8000000L" in ini and "-O2 -DEXTRA=1" in ini
    project = tmp_path / "project"
    project.mkdir()
    (project / "platformio.ini").write_text(ini)
    env = project_config(project, tmp_path)["env:uno"]
    diffs = differences(pio_flags(env), mk_flags("uno", tmp_path))
    assert "cxx define F_CPU: PlatformIO 8000000L, fsw build 16000000L" in diffs
    assert "cxx -O: PlatformIO ['-O2', '-Os'], fsw build ['-Os']" in diffs
    assert "c define EXTRA: only in PlatformIO" in diffs
    assert "link flags: PlatformIO ['-Wl,--gc-sections', '-fdata-sections', '-ffunction-sections', '-flto', " \
           "'-fno-toplevel-reorder', '-fuse-linker-plugin'], fsw build ['-Wl,--gc-sections', '-Wl,--relax', '-fdata-sections', " \
           "'-ffunction-sections', '-flto', '-fno-toplevel-reorder', '-fuse-linker-plugin', '-mcall-prologues', " \
           "'-mstrict-X']" in diffs


@needs_pio
@needs_avr
@pytest.mark.parametrize("board", ["uno", "nano", "mega2560"])
def test_new_projects_environment_compiles_with_fsw_builds_flags(fsw, tmp_path, board):
    """The platformio.ini `fsw new` writes holds the same flags."""
    assert fsw("new", str(tmp_path / "rocket"), "--board", board).code == 0
    env = project_config(tmp_path / "rocket", tmp_path)[f"env:{board}"]
    assert differences(pio_flags(env), mk_flags(board, tmp_path)) == []
