"""The run-time pyro gate through generated firmware (docs/safety.md,
"checked at run time"): a small project built for the host, its outputs
task's pin watched cycle by cycle while the key, the machine and the
element change; and the rocket's pyro pins generated through the gate."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT, run_fsw
from support import cxx
from support.caches import native_runtime

needs_cxx = pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")

SV = """[Flight]
U64 time
U32 state
bool armSwitch
bool go
bool leave
bool charge
"""

# Safe -> Armed on the key; Armed -> Fire on `go`; in Fire the element
# follows `go` (a fall and a rise re-fire); `leave` goes to Hold with the
# element still true.
SM = """[state_vector]
U64 time         @alias G
U32 state        @alias S
bool armSwitch   @read_only
bool go          @read_only
bool leave       @read_only
bool charge

[Safe]
.step
    armSwitch: -> Armed
[Armed]
.step
    go: -> Fire
[Fire]
.entry
    charge = true
.step
    charge = go
    leave: -> Hold
[Hold]
"""

DIO = """# dir  pin  element
i      2    armSwitch
i      3    go
i      4    leave
o      5    charge
"""

APP = """[application]
board native
rate  100

[configs]
state_vector gate.sv
machine      gate.sm
io           gate.dio

[time]
source cycle
unit   ms

[tasks]
sense    inputs        rate=100
fly      machine gate  rate=100
act      outputs       rate=100

[pyro]
charge   arm=armSwitch  pulse=0.05  machine=gate  armed=Armed  fire=Fire
"""

# Args: dP=V sets a digital input; a number N runs N cycles, printing the
# pyro pin (5) after each, then a space.
MAIN = r"""#include <stdio.h>
#include <stdlib.h>
#include "fswkit.h"
#include "psl_native.h"
namespace fsw_gen { bool begin(); void run_cycle(); }
int main(int argc, char** argv) {
    if (!fsw_gen::begin()) return 3;
    for (int i = 1; i < argc; ++i) {
        unsigned pin = 0, value = 0;
        if (sscanf(argv[i], "d%u=%u", &pin, &value) == 2) {
            fsw::native::sim_set_digital(static_cast<uint8_t>(pin), value != 0);
        } else {
            for (long n = strtol(argv[i], 0, 10); n > 0; --n) {
                fsw_gen::run_cycle();
                putchar(fsw::native::sim_digital(5) ? '1' : '0');
            }
            putchar(' ');
        }
    }
    putchar('\n');
    return 0;
}
"""


@pytest.fixture(scope="module")
def firmware(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("pyro_gate")
    proj = d / "proj"
    proj.mkdir()
    for name, text in (("gate.sv", SV), ("gate.sm", SM), ("gate.dio", DIO), ("gate.app", APP)):
        (proj / name).write_text(text)
    r = run_fsw("gen", str(proj), "--out", str(d / "gen"))
    assert r.code == 0, r.err
    (d / "main.cpp").write_text(MAIN)
    exe = d / "fw"  # linked with the runtime's objects as a native build links them
    r = cxx.program(["-std=c++11", "-O1", "-fno-exceptions", "-fno-rtti", "-DFSW_NO_MAIN",
                     f"-I{ROOT / 'firmware' / 'src'}", "-Igen"], [d / "main.cpp", *sorted((d / "gen").glob("*.cpp"))],
                    exe, d, native_runtime())
    assert r.returncode == 0, r.stderr[-3000:]
    return exe


def pins(exe: Path, *script: str) -> list[str]:
    return subprocess.run([str(exe), *script], capture_output=True, text=True, check=True).stdout.split()


ARMED_AND_FIRED = ("d2=1", "2", "d3=1", "1")  # armed, then Fire entered (the element rises next cycle)


@needs_cxx
def test_pulse_ends_after_its_runs_while_the_element_stays_true(firmware):
    # pulse=0.05 at 100 Hz: 5 runs of the outputs task, then low
    assert pins(firmware, *ARMED_AND_FIRED, "20")[-1] == "1" * 5 + "0" * 15


@needs_cxx
def test_no_fire_without_the_key(firmware):
    # key off: the machine never arms, and nothing fires
    assert pins(firmware, "d3=1", "20") == ["0" * 20]


@needs_cxx
def test_refires_only_after_the_element_falls_and_rises(firmware):
    out = pins(firmware, *ARMED_AND_FIRED, "10", "d3=0", "2", "d3=1", "10")
    assert out[-3:] == ["1" * 5 + "0" * 5, "00", "1" * 5 + "0" * 5]


@needs_cxx
def test_the_key_dropping_mid_pulse_ends_it_for_good(firmware):
    # the machine stays in Fire with the element true: the key alone ends it
    out = pins(firmware, *ARMED_AND_FIRED, "2", "d2=0", "3", "d2=1", "10")
    assert out[-3:] == ["11", "000", "0" * 10]


@needs_cxx
def test_out_of_its_fire_state_the_pin_drops(firmware):
    # Hold is not a fire state; the element is still true there
    out = pins(firmware, *ARMED_AND_FIRED, "2", "d4=1", "5")
    assert out[-2:] == ["11", "00000"]


def test_the_rocket_drives_its_pyro_pins_through_the_gate(tmp_path):
    r = run_fsw("gen", str(EXAMPLES / "rocket"), "--out", str(tmp_path))
    assert r.code == 0, r.err
    app = (tmp_path / "app.gen.cpp").read_text()
    # continuity: the reading >= 1.0 as a test of its key (above that of 1.0's predecessor), as the
    # machines test a float against a literal: the value read_F32 reads, tested on its bits
    assert ("const bool pyro0 = fsw::pyro_gate(Pyro[0], sv[E_drogue] != 0, fsw::io_pin_read(FSW_PIN(2, D, 2)), "
            "mission::machine.state == mission::S_Apogee, 100u, "
            "((fsw::f32_key_gt(fsw::read_F32(sv + E_drogueSense), 0xbf7fffffUL)) ? fsw::kPyroContinuity : 0));") in app
    assert ("const bool pyro1 = fsw::pyro_gate(Pyro[1], sv[E_main] != 0, fsw::io_pin_read(FSW_PIN(2, D, 2)), "
            "mission::machine.state == mission::S_Main, 100u, "
            "((fsw::f32_key_gt(fsw::read_F32(sv + E_mainSense), 0xbf7fffffUL)) ? fsw::kPyroContinuity : 0));") in app
    # the flight's state kept before a pulse's first high, then the pins
    save = app.index("if (((Pyro[0].status | Pyro[1].status) & fsw::kPyroRose) != 0) fsw::resume_save(resume);")
    assert app.index("const bool pyro1") < save < app.index("fsw::io_pin_write(FSW_PIN(5, D, 5), pyro0);") \
        < app.index("fsw::io_pin_write(FSW_PIN(6, D, 6), pyro1);")
    assert "sv + E_drogue)" not in app and "sv + E_main)" not in app  # not a plain output any more
    assert "fsw::io_digital_out(FSW_PIN(8, B, 0), sv + E_buzzer);" in app
