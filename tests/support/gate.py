"""A small pyro project on the simulated Uno for the regression tests of the
gate and the resume (the machine `gate` fires `charge` on pin 5 after the
key on pin 2 and `go` on pin 3): its machine and table, its .app, and
its firmware built."""

from __future__ import annotations

from pathlib import Path

# The machine: Safe -> Armed on the key, Armed -> Fire on `go`; Fire sets
# the charge for a second, then Done.
GATE_SM = """[state_vector]
U64 time         @alias G
U32 state        @alias S
bool armSwitch   @read_only
bool go          @read_only
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
    T >= 1000: -> Done
.exit
    charge = false
[Done]
"""

GATE_DIO = """# dir  pin  element
i      2    armSwitch
i      3    go
o      5    charge
"""


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


class GateBoard:
    """The firmware on the simulated Uno with a link session: `b` the
    board, `session`, `t` the transport (0.3 s run, the hello seen);
    `mode(task, mode)` the ground's MODE command, its acknowledgement."""

    def __init__(self, app, elf, sim_limit: float = 60):
        from fswkit.link.client import Numbers
        from fswkit.link.layout import from_app
        from fswkit.link.session import Session
        from fswkit.param.client import SimTransport
        from fswkit.sim.board import SimBoard

        self.b = SimBoard(elf, "uno", uart="control", sim_limit=sim_limit)
        self.session = Session(from_app(app))
        self.t = SimTransport(self.b, self.session)
        self.numbers = Numbers(self.session)
        self.t.events(0.3)
        assert self.session.hello is not None

    def _send_and_wait(self, seq, frame):
        self.t.send(frame)
        end = self.b.time + 0.3
        while self.b.time < end:
            for ev in self.t.events(0.01):
                if ev.kind == "ack" and ev.info["cmd_seq"] == seq:
                    return ev.info
        return None

    def mode(self, task: int, mode: int):
        from fswkit.link import wire
        from fswkit.link.client import exchange

        return exchange(self.numbers, wire.OP_MODE, bytes([task, mode]), 3, self._send_and_wait)

    def close(self) -> None:
        self.b.close()
