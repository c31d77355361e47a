"""The sensor table (`.sns`; docs/sensor-table.md): rows resolved into the
model's `Sensor` (defaults, the order of the settings, negated quantities,
addresses), what the generated code does with them (the drivers'
arguments, the inputs task's lines, the includes only an application with
parts has), and a native build of a small application with a bmp280 row
run against the native board's scripted TWI responder: the pressure and
temperature reach their elements, and a part that stops answering is a
fault. (tests/autocode/golden/app/sensors_*.app hold every diagnostic.)"""

from __future__ import annotations

import shutil
import subprocess

import pytest

from conftest import EXAMPLES, ROOT, run_fsw
from fswkit.autocode.emit.app import emit_app, sensor_args
from fswkit.autocode.sensors import sensor_name
from support import cxx
from support.caches import native_runtime
from support.sensor_project import load, write_project


# ---- rows into the model ---------------------------------------------------------

def test_defaults_and_the_order_of_the_settings(tmp_path):
    app = load(write_project(tmp_path, "bmp280 i2c:0x77 pressure=baroP   # a comment\n"
                                       "adxl345 spi:7 stuck=0 rate=100 -z=accelZ\n"
                                       "ms5611 i2c:118 timeout=9 pressure=baroT\n"
                                       "mpu6050\ti2c:0x68 dlpf=6 temperature=accelY\n"))
    bmp, adxl, ms, mpu = app.sensors
    assert (bmp.part, bmp.bus, bmp.address, bmp.cs_pin, bmp.where) == ("bmp280", "i2c", 0x77, None, "0x77")
    assert bmp.settings == (("osrs_p", 4), ("osrs_t", 1), ("stuck", 50), ("timeout", 3))
    assert adxl.settings == (("range", 16), ("rate", 100), ("stuck", 0), ("timeout", 3))
    assert (adxl.bus, adxl.address, adxl.cs_pin) == ("spi", None, 7)
    assert [(q, e.name) for q, e in adxl.outputs] == [("-z", "accelZ")]
    assert ms.address == 0x76 and ms.settings == (("osr", 1024), ("stuck", 50), ("timeout", 9))
    assert mpu.settings == (("range", 16), ("dlpf", 6), ("stuck", 50), ("timeout", 3))
    assert [sensor_name(s) for s in app.sensors] == ["bmp280@0x77", "adxl345@spi:7", "ms5611@0x76", "mpu6050@0x68"]
    assert [s.line for s in app.sensors] == [1, 2, 3, 4]
    assert bmp.fault is None and bmp.health is None


def test_the_drivers_arguments_are_the_datasheets_codes(tmp_path):
    app = load(write_project(tmp_path, "bmp280 i2c:0x76 osrs_p=16 osrs_t=2 stuck=7 timeout=4 pressure=baroP\n"
                                       "ms5611 i2c:0x77 osr=256 pressure=baroT\n"
                                       "adxl345 spi:8 range=2 rate=3200 z=accelZ\n"
                                       "adxl345 i2c:0x1D range=4 rate=25 y=accelY\n"))
    assert [sensor_args(s) for s in app.sensors] == [
        "0x76, 2, 5, 7, 4",  # address, osrs_t code, osrs_p code (x16: 5), stuck, timeout
        "0x77, 0, 50, 3",  # OSR 256: 0
        "8, 1, 0, 0xF, 50, 3",  # chip select, on SPI, +-2 g: 0, 3200 Hz: BW_RATE 0xF
        "0x1D, 0, 1, 0x8, 50, 3",
    ]


# ---- the generated code --------------------------------------------------------

def test_the_inputs_task_steps_every_part_then_writes_its_elements(tmp_path):
    app = load(write_project(tmp_path, "bmp280 i2c:0x76 pressure=baroP temperature=baroT fault=baroFault "
                                       "health=baroHealth\nadxl345 spi:7 -z=accelZ\n"))
    cpp = emit_app(app)["app.gen.cpp"]
    assert '#include "fsw_sensor.h"\n#include "fsw_accel.h"\n' in cpp
    assert "fsw::Bmp280 sensor0(0x76, 1, 3, 50, 3);" in cpp and "fsw::Adxl345 sensor1(7, 1, 3, 0xC, 50, 3);" in cpp
    task = cpp[cpp.index("fsw::Result task_sense"):]
    task = task[:task.index("\n}\n")]
    lines = [ln.strip() for ln in task.splitlines()]
    steps = [i for i, ln in enumerate(lines) if ln.startswith("sensor") and ".step();" in ln]
    writes = [i for i, ln in enumerate(lines) if "sv + E_" in ln or "sv[E_" in ln]
    assert len(steps) == 2 and max(steps) < min(writes)  # every part steps before any element is written
    assert "fsw::store<float>(sv + E_baroP, sensor0.pressure_pa());  // pressure" in lines
    assert "fsw::write_F64(sv + E_baroT, sensor0.temp_c());  // temperature" in lines
    assert "fsw::store<float>(sv + E_accelZ, -sensor1.z_g());  // -z" in lines
    assert "fsw::store_bool(sv + E_baroFault, h >= fsw::kSensorNoAnswer);  // fault" in lines
    assert "sv[E_baroHealth] = h;  // health" in lines
    assert "if (sensor0.readings() != 0) {  // before its first reading: the initial values" in lines
    assert "fsw::sensors_begin(1, 1);" in cpp


def test_a_barometer_only_app_includes_no_accelerometer_header(tmp_path):
    cpp = emit_app(load(write_project(tmp_path, "ms5611 i2c:0x77 pressure=baroP\n")))["app.gen.cpp"]
    assert '#include "fsw_sensor.h"' in cpp and "fsw_accel.h" not in cpp
    assert "fsw::sensors_begin(1, 0);" in cpp


@pytest.mark.parametrize("example", ["rocket", "hpr", "tank"])
def test_applications_without_parts_generate_no_sensor_code(example):
    app = load(next((EXAMPLES / example).glob("*.app")))
    assert app.sensors == ()
    cpp = emit_app(app)["app.gen.cpp"]
    for text in ("fsw_sensor.h", "fsw_accel.h", "sensors_begin", "sensor_health", "sensor0"):
        assert text not in cpp


# ---- a native build, run against the scripted TWI responder --------------------

MAIN = r"""
#include <stdio.h>
#include <string.h>
#include "fswkit.h"
#include "psl_native.h"
#include "sv.gen.h"
namespace fsw_gen { bool begin(); void run_cycle(); }
using namespace fsw;
using namespace fsw_gen;
// A BMP280 at 0x76 with the datasheet's worked example (3.12): 100653.25 Pa, 25.08 degC.
static const uint8_t kCal[24] = {0x70, 0x6B, 0x43, 0x67, 0x18, 0xFC, 0x7D, 0x8E, 0x43, 0xD6, 0xD0, 0x0B,
                                 0x27, 0x0B, 0x8C, 0x00, 0xF9, 0xFF, 0x8C, 0x3C, 0xF8, 0xC6, 0x70, 0x17};
static uint8_t reg, data[6];
static bool gone;
static uint8_t bmp(uint8_t addr7, const uint8_t* w, uint8_t nw, uint8_t* r, uint8_t nr) {
    if (addr7 != 0x76 || gone) return kTwiNackAddr;
    if (nw >= 1) reg = w[0];
    for (uint8_t i = 0; i + 1 < nw; i = static_cast<uint8_t>(i + 2)) {
        if (w[i] == 0xF4 && (w[i + 1] & 3u) != 0) {
            const int32_t p = 415148L, t = 519888L;
            const uint8_t d[6] = {static_cast<uint8_t>(p >> 12), static_cast<uint8_t>(p >> 4),
                                  static_cast<uint8_t>(p << 4), static_cast<uint8_t>(t >> 12),
                                  static_cast<uint8_t>(t >> 4), static_cast<uint8_t>(t << 4)};
            memcpy(data, d, 6);
        }
    }
    for (uint8_t i = 0; i < nr; ++i) {
        const uint8_t a = static_cast<uint8_t>(reg + i);
        r[i] = a == 0xD0 ? 0x58 : a >= 0x88 && a < 0x88 + 24 ? kCal[a - 0x88] : a >= 0xF7 && a <= 0xFC ? data[a - 0xF7] : 0;
    }
    return kTwiOk;
}
static void show(const char* when) {
    float p;
    double t;
    memcpy(&p, sv + E_baroP, sizeof p);
    memcpy(&t, sv + E_baroT, sizeof t);
    printf("%s %.9g %.9g %u %u\n", when, p, t, sv[E_baroFault], sv[E_baroHealth]);
}
int main() {
    native::twi_set_responder(bmp);
    if (!begin()) return 3;
    show("boot");
    for (int i = 0; i < 100; ++i) { native::sim_advance_us(10000); run_cycle(); }
    show("answering");
    gone = true;
    for (int i = 0; i < 20; ++i) { native::sim_advance_us(10000); run_cycle(); }
    show("gone");
    return 0;
}
"""


@pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")
def test_a_native_bmp280_app_writes_the_pressure_element(tmp_path):
    app = load(write_project(tmp_path, "bmp280 i2c:0x76 pressure=baroP temperature=baroT fault=baroFault "
                                       "health=baroHealth\n"))
    gen = tmp_path / "gen"
    gen.mkdir()
    for name, text in emit_app(app).items():
        (gen / name).write_text(text)
    (tmp_path / "main.cpp").write_text(MAIN)
    runtime = ROOT / "firmware" / "src"
    exe = tmp_path / "app"  # linked with the runtime's objects as a native build links them
    r = cxx.program(["-std=gnu++11", "-O1", "-fno-exceptions", "-fno-rtti", "-Wall", "-Wextra", "-Werror",
                     "-DFSW_NO_MAIN", f"-I{runtime}", "-Igen"], [*sorted(gen.glob("*.cpp")), tmp_path / "main.cpp"],
                    exe, tmp_path, native_runtime(), ["-pthread"])
    assert r.returncode == 0, r.stderr[-3000:]
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=True, cwd=tmp_path).stdout.splitlines()
    boot, answering, gone = (ln.split() for ln in out)
    assert boot[1:] == ["0", "0", "0", "0"]  # before the first reading: the initial values, health init
    assert answering[1:] == ["100653.25", "25.0799999", "0", "1"]  # 25.08f widened to the F64 element; ok
    assert gone[1:3] == answering[1:3]  # the last reading stays
    assert gone[3:] == ["1", "2"]  # a fault: no answer


# ---- fsw check ------------------------------------------------------------------

def test_fsw_check_a_project_with_a_sensor_table(tmp_path):
    write_project(tmp_path, "bmp280 i2c:0x76 pressure=baroP\n", board="uno")
    r = run_fsw("check", str(tmp_path))
    assert (r.code, r.err) == (0, "fsw check: 3 files, 0 errors, 0 warnings\n")  # p.app, p.sm, p.sv
    (tmp_path / "p.sns").write_text("bmp280 i2c:0x76 pressure=baroP\nadxl345 spi:13 z=accelZ\n")
    r = run_fsw("check", "p.app", cwd=tmp_path)
    assert r.code == 1
    assert r.err.startswith("I/O config error @ p.sns:2:13:\n")
    assert "pin 13 is the SPI bus's SCK on the uno" in r.err


def test_fsw_check_of_a_table_alone_says_what_to_give(tmp_path):
    write_project(tmp_path, "bmp280 i2c:0x76 pressure=baroP\n")
    r = run_fsw("check", "p.sns", cwd=tmp_path)
    assert r.code == 2
    assert r.err == ("fsw check: p.sns: an I/O table (.aio, .dio, .sns) is checked with the application that lists "
                     "it in [configs]: give its .app, or the project's folder\n")
