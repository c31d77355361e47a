"""`fsw build P --out X` then `fsw build P --board mega2560 --out X` linked
the Uno's objects into "Mega" firmware: the object rules did not depend on
the MCU, the clock, the variant, the flags or the compiler, nor on the
headers of the Arduino core. Every input of a build now decides a rebuild
(mk/build.mk: a stamp of the whole configuration, and the compiler's
dependency files for headers), and nothing else does."""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT

TANK = EXAMPLES / "tank"
BUILD_MK = ROOT / "mk" / "build.mk"
ARDUINO = Path("/usr/share/arduino/hardware/arduino/avr")

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None or not ARDUINO.is_dir(),
                                reason="gcc-avr or the Arduino core not installed")

SKETCH = """\
#include <Arduino.h>
#include "sketch.h"
void setup() { Serial.begin(SKETCH_BAUD); pinMode(LED_BUILTIN, OUTPUT); }
void loop() { digitalWrite(LED_BUILTIN, (millis() / 500) & 1); }
"""

UNO = {"MCU": "atmega328p", "F_CPU": "16000000", "VARIANT": "standard", "BOARD_DEFINE": "ARDUINO_AVR_UNO"}


def _avr_arch(path: Path) -> int:
    """The AVR architecture an ELF file (object or firmware) was built for:
    5 for the Uno's ATmega328P, 6 for the Mega's ATmega2560 (e_flags)."""
    return struct.unpack_from("<I", path.read_bytes(), 36)[0] & 0x7F


def test_a_mega_build_into_an_uno_build_folder_is_the_megas_firmware(fsw, tmp_path):
    shared = tmp_path / "shared"
    assert fsw("build", str(TANK), "--out", str(shared)).code == 0
    assert {_avr_arch(p) for p in shared.rglob("*.o")} == {5}
    r = fsw("build", str(TANK), "--board", "mega2560", "--out", str(shared))
    assert r.code == 0, r.err
    built = [shared / "tank.elf"] + sorted(shared.rglob("*.o"))
    assert {p.name: _avr_arch(p) for p in built} == {p.name: 6 for p in built}
    # the interrupt handlers the firmware defines: the Mega's USART0 receive
    # vector is __vector_25, and none of the Uno's numbers for Timer0's
    # overflow, USART0's data register empty and the ADC (16, 19, 21) is there
    nm = subprocess.run(["avr-nm", str(shared / "tank.elf")], capture_output=True, text=True, check=True).stdout
    handlers = {line.split()[-1] for line in nm.splitlines() if " T __vector_" in line}
    assert "__vector_25" in handlers and not {"__vector_16", "__vector_19", "__vector_21"} & handlers, handlers


# A few objects of each kind (generated, runtime, the core's C, C++ and
# assembler) stand for all: building only them keeps the test quick.
OBJECTS = ["gen/sketch.o", "rt/fsw_crc.o", "core/wiring.c.o", "core/wiring_digital.c.o", "core/WMath.cpp.o",
           "core/HardwareSerial0.cpp.o", "core/wiring_pulse.S.o"]


def _make(out: Path, gen: Path, arduino: Path, **config) -> None:
    args = [f"{k}={v}" for k, v in config.items()] + [str(out / o) for o in OBJECTS]
    r = subprocess.run(["make", "--no-print-directory", "-j2", "-f", str(BUILD_MK), f"GEN={gen}", f"OUT={out}",
                        "NAME=sketch", f"ARDUINO={arduino}"] + args, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-3000:]


def _stamps(out: Path) -> dict[str, int]:
    """Every object of a build folder: {path: mtime in ns}."""
    return {str(p.relative_to(out)): p.stat().st_mtime_ns for p in out.rglob("*")
            if p.suffix == ".o"}


@pytest.fixture(scope="module")
def sketch():
    """A sketch and a private copy of the Arduino core (whose headers the
    tests change), made afresh in each run at one place in build/sim-tests/
    (held while the module runs): the objects are compiled from sources at
    the same paths in every run, which ccache, where the build uses it,
    then serves (from a new temporary folder each run, every one of them
    was compiled again)."""
    from support.simfw import OUT

    from support.held import fresh_folder

    with fresh_folder(OUT / "rebuild-on-board-change") as root:
        yield _sketch(root)


def _sketch(root: Path):
    arduino = root / "arduino"
    shutil.copytree(ARDUINO / "cores", arduino / "cores")
    for v in ("standard", "eightanaloginputs", "mega"):
        shutil.copytree(ARDUINO / "variants" / v, arduino / "variants" / v)
    gen = root / "gen"
    gen.mkdir()
    (gen / "sketch.cpp").write_text(SKETCH)
    (gen / "sketch.h").write_text("#define SKETCH_BAUD 9600\n")
    wrapper = root / "bin" / "avr-g++"
    wrapper.parent.mkdir()
    wrapper.write_text("#!/bin/sh\nexec avr-g++ \"$@\"\n")
    wrapper.chmod(0o755)
    return root, gen, arduino, wrapper


def test_every_build_input_decides_a_rebuild(sketch):
    root, gen, arduino, wrapper = sketch
    out = root / "out-config"
    config = dict(UNO)
    _make(out, gen, arduino, **config)
    built = _stamps(out)
    _make(out, gen, arduino, **config)
    assert _stamps(out) == built, "an unchanged build rebuilt something"
    for change in ({"F_CPU": "8000000"}, {"BOARD_DEFINE": "ARDUINO_AVR_NANO"}, {"VARIANT": "eightanaloginputs"},
                   {"AVR_CXX": str(wrapper)}, {"MCU": "atmega168"}):
        config.update(change)
        _make(out, gen, arduino, **config)
        now = _stamps(out)
        stale = sorted(p for p in built if now.get(p) == built[p])
        assert stale == [], f"after {change}: not rebuilt: {stale}"
        built = now


def test_another_tools_key_rebuilds(sketch):
    """AVR_TOOLS_KEY, the tools' identity `fsw build` passes in place of
    make asking the tools (fswkit.target.libcache.avr_tools_key), is part
    of the configuration: another key rebuilds, the same one nothing."""
    root, gen, arduino, _ = sketch
    out = root / "out-tools-key"
    built = {}
    for key in ("a" * 20, "b" * 20, "b" * 20):
        r = subprocess.run(["make", "--no-print-directory", "-f", str(BUILD_MK), f"GEN={gen}", f"OUT={out}",
                            "NAME=sketch", f"ARDUINO={arduino}", f"AVR_TOOLS_KEY={key}", str(out / "gen/sketch.o")]
                           + [f"{k}={v}" for k, v in UNO.items()], capture_output=True, text=True)
        assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-3000:]
        assert f"tools={key}" in (out / ".config-avr").read_text()
        built.setdefault(key, []).append((out / "gen" / "sketch.o").stat().st_mtime_ns)
    assert built["b" * 20][0] != built["a" * 20][0], "another tools key did not rebuild"
    assert built["b" * 20][1] == built["b" * 20][0], "the same tools key rebuilt"


def test_a_changed_header_rebuilds_the_objects_that_include_it(sketch):
    root, gen, arduino, _ = sketch
    out = root / "out-headers"
    _make(out, gen, arduino, **UNO)
    later = 1_000_000_000 + int(max(p.stat().st_mtime for p in out.rglob("*.o")))
    for header, users in ((arduino / "variants" / "standard" / "pins_arduino.h", ["core/wiring_digital.c.o",
                                                                                 "gen/sketch.o"]),
                          (arduino / "cores" / "arduino" / "HardwareSerial.h", ["core/HardwareSerial0.cpp.o",
                                                                               "gen/sketch.o"]),
                          (gen / "sketch.h", ["gen/sketch.o"])):
        before = _stamps(out)
        os.utime(header, (later, later))
        later += 10
        _make(out, gen, arduino, **UNO)
        after = _stamps(out)
        for user in users:
            assert after[user] != before[user], f"{header.name} changed, {user} not rebuilt"
        assert after["core/WMath.cpp.o"] == before["core/WMath.cpp.o"], f"{header.name} does not concern WMath.cpp"


@pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")
def test_another_host_compiler_is_another_native_build(fsw, tmp_path, monkeypatch):
    """`fsw test --native` caches its compiled runners: the compiler's
    identity is part of the cache key, so an upgraded compiler at the
    same path compiles anew. (The runtime's objects, keyed the same way,
    are put in each identity's entry from the run's own cache: the
    wrapper runs that same g++ with the same flags, so they are the ones
    it would compile, and the runners are what this test watches.)"""
    from fswkit.autocode.numeric import F64MODE
    from fswkit.run import native

    compiled = os.path.dirname(native.runtime_objects(F64MODE)[0])  # the run's cache: compiled there once
    cxx = tmp_path / "bin" / "g++"
    cxx.parent.mkdir()
    monkeypatch.setenv("FSW_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(native, "CXX", str(cxx))
    script = str(TANK / "tank.ss")
    runners = []
    for version in ("12.1", "12.2.0"):
        cxx.write_text(f'#!/bin/sh\n[ "$1" = --version ] && {{ echo "g++ {version}"; exit 0; }}\nexec g++ "$@"\n')
        cxx.chmod(0o755)
        key = native._key({"(the runtime alone)": ""}, F64MODE)  # this identity's entry for the runtime
        shutil.copytree(compiled, tmp_path / "cache" / "native" / key)
        r = fsw("test", "--native", script)
        assert r.code == 0, r.err
        runners.append(sorted(p.parent.name for p in (tmp_path / "cache").rglob("runner")))
    assert len(runners[0]) == 1 and len(runners[1]) == 2
