"""A small application with a sensor table (tests/autocode/sensors,
tests/link, tests/ground): a state vector with a barometer's and an
accelerometer's elements, a machine that reads the pressure, and the
parts given as `.sns` text, written as p.sv, p.sm, p.sns and p.app."""

from __future__ import annotations

from pathlib import Path

from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics

SV = """\
[Data]
U64 time
U32 state
F32 baroP
F64 baroT
bool baroFault
U8 baroHealth
F32 accelZ
F32 accelY
bool high
"""
SM = """\
[state_vector]
U64 time @alias G
U32 state @alias S
F32 baroP @read_only
bool high

[Run]
.step
    high = baroP > 100000
"""
APP = """\
[application]
board {board}
rate 100
{baud}
[configs]
state_vector p.sv
machine p.sm
{io}
[tasks]
sense inputs rate=100
control machine p rate=100
{telemetry}"""
TELEMETRY = """\
down telemetry rate=50

[telemetry]
Data rate=10
"""
# a barometer on I2C with its fault flag, an accelerometer on SPI
SNS = "bmp280 i2c:0x76 pressure=baroP fault=baroFault\nadxl345 spi:7 -z=accelZ\n"


def write_project(folder: Path, sns: str | None = SNS, *, board: str = "native", baud: int | None = None,
                  telemetry: bool = False) -> Path:
    """Writes the project into `folder` and returns its p.app: without a
    p.sns when `sns` is None, with `baud` in [application] when given, and
    with a telemetry task sending the [Data] group when `telemetry`."""
    (folder / "p.sv").write_text(SV)
    (folder / "p.sm").write_text(SM)
    if sns is not None:
        (folder / "p.sns").write_text(sns)
    app = folder / "p.app"
    app.write_text(APP.format(board=board, baud="" if baud is None else f"baud {baud}\n",
                              io="" if sns is None else "io p.sns",
                              telemetry=TELEMETRY if telemetry else ""))
    return app


def load(path: Path):
    """The application at `path`, which must check without errors."""
    d = Diagnostics()
    app = load_app(str(path), d)
    assert app is not None, d.render()
    return app
