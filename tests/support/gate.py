"""A small pyro project on the simulated Uno for the regression tests of the
gate and the resume (the machine `gate` fires `charge` on pin 5 after the
key on pin 2 and `go` on pin 3): its .app, and its firmware built."""

from __future__ import annotations

from pathlib import Path


def gate_app(*, extra: str = "", telemetry_rate: int = 10, sections: str = "") -> str:
    """The .app: [application] (with `extra` lines), [configs] gate.sv,
    gate.sm, gate.dio, the clock in ms, uplink, inputs, the machine, outputs
    and telemetry at 100 Hz, Flight streamed at `telemetry_rate`; then
    `sections` ([pyro], [reload], ...)."""
    return f"""[application]
board uno
rate  100
{extra}
[configs]
state_vector gate.sv
machine      gate.sm
io           gate.dio

[time]
source clock
unit   ms

[tasks]
uplink   uplink        rate=100
sense    inputs        rate=100
fly      machine gate  rate=100
act      outputs       rate=100
down     telemetry     rate=100

[telemetry]
Flight   rate={telemetry_rate}

{sections}"""


def gate_firmware(folder: Path, files: dict[str, str]):
    """Writes `files` (name -> text: gate.sv, gate.sm, gate.dio, gate.app)
    into `folder` and builds the firmware: (the application, its ELF)."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import firmware, load

    for name, text in files.items():
        (folder / name).write_text(text)
    diags = Diagnostics()
    app = load(str(folder / "gate.app"), diags)
    assert app is not None, diags.render()
    built = firmware(app, str(folder / "build"))
    assert built.fits, built.report
    return app, built.artifact
