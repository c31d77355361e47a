"""A sensor tape through a project's machines in the reference interpreter
(binary32) instead of the simulated board: the same open-loop replay as
fswkit.plant.tape_replay, its events checked by the same `evaluate`, in a
fraction of a second per flight instead of minutes. Tests fly every
real-flight tape with it; tools/bench_tapes.py runs `--perturb`'s
hundreds of perturbed replays per tape with it, beside a few on the board.

What it shares with the board's replay: the inputs (each tape column
through the inverse of the `.aio` calibration and the converter,
`counts_series`, an empty cell holding the last count), read back through
the calibration in binary32 as the firmware computes it (count * gain +
offset, iotables.analog_value), held between rows, and each igniter's
continuity input (`Config.igniters`) at its intact count from boot to the
end, read back the same way (`analog_inputs`); one step late as
the firmware's inputs are (its ADC scan converts them in the background
for the next run of the inputs task: step k reads the pins as they were at
step k - 1, the first step at boot); the timeline
(the tape's first row at `pad_s`, the arming switch at `arm_s`, `run_on_s`
after the last row); the machines stepped every 1000 / rate ms in the
order the application lists them, sharing the state vector's elements;
each pyro pin through the firmware's run-time gate (`_Gate`, the same rule
as fsw::pyro_gate). What it leaves out: the executor's clock (G is the step's time here,
millis() on the board), the UART and the telemetry (an event is seen at
its step, not in the next frame), the other tasks. On the eight shared
tapes its events agree with the board's within a step or two
(docs/sim.md, "Replaying real flights")."""

from __future__ import annotations

import numpy as np

from fswkit.autocode.emit.app import pyro_pulse_runs, pyro_task
from fswkit.autocode.iotables import analog_gain, analog_value
from fswkit.autocode.numeric import F32MODE
from fswkit.run.interp import MachineRun

from .cosim import PinEvent, Run
from .tape_replay import Replay, _columns, _pad, counts_series, missing_spans, smoothed_altitude


class InterpError(Exception):
    """The project cannot be replayed in the interpreter (say why)."""


def _element_of(app, pin: int | None, analog: bool = False) -> str | None:
    if pin is None:
        return None
    ch = next((c for c in app.channels if c.pin_number == pin and c.analog == analog), None)
    return ch.element.name if ch is not None else None


class _Gate:
    """The firmware's pyro gate (fsw::pyro_gate, docs/safety.md), the same
    rule: the pin high only while the element is true, every arming input
    reads armed, the machine is in a fire state, and for at most the pulse
    from the element's rise; low until the element falls and rises again.
    The pulse in steps: the outputs task's runs times its divider."""

    def __init__(self, app, channel):
        task = pyro_task(app)
        self.ch = channel
        self.arm = [c.element.name for c in channel.arm]
        self.fire = set(channel.fire)
        self.pulse = pyro_pulse_runs(channel, task) * task.divider
        self.machine = channel.machine
        self.left, self.last = 0, False

    def level(self, sv, state_id: int) -> bool:
        element = bool(sv[self.ch.element.name])
        if element and not self.last:
            self.left = self.pulse
        self.last = element
        if not element or not all(sv[a] for a in self.arm) or state_id not in self.fire or self.left == 0:
            self.left = 0
            return False
        self.left -= 1
        return True


def _reading(sensor, counts: int) -> float:
    """The element's value for a count, as the firmware computes it (binary32)."""
    return _readings(sensor, [counts])[0]


def _readings(sensor, counts: list[int]) -> list[float]:
    """_reading of each count: each distinct count's value worked out once
    (exact rational arithmetic, and a tape's rows repeat a few hundred
    counts)."""
    gain = analog_gain(sensor.scale, sensor.vref, sensor.bits, F32MODE)
    offset = F32MODE.literal(repr(float(sensor.offset)))
    memo: dict[int, float] = {}
    out = []
    for k in counts:
        v = memo.get(k)
        if v is None:
            v = memo[k] = analog_value(k, gain, offset, F32MODE)
        out.append(v)
    return out


def analog_inputs(cfg, columns: dict) -> tuple[dict, dict]:
    """What the machines read from the analog inputs the replay drives:
    (element -> value at each tape row, for the columns' sensors; element ->
    value all the replay, for the igniters' continuity inputs), each the
    board's count (the same counts and millivolts as tape_replay gives the
    board) through the calibration in binary32."""
    series, constant, _counts = _analog_inputs(cfg, columns)
    return series, constant


def _analog_inputs(cfg, columns: dict) -> tuple[dict, dict, dict]:
    """analog_inputs' (series, constant), and the counts they were read
    from (column -> counts_series; the replay's `counts`)."""
    series, counts = {}, {}
    for col, s in cfg.sensors.items():
        if s is None:
            continue
        counts[col] = counts_series(columns[col], s, cfg.missing, cfg.silent_volts)
        series[s.element] = _readings(s, counts[col].tolist())
    constant = {ig.sensor.element: _reading(ig.sensor, ig.counts) for ig in getattr(cfg, "igniters", {}).values()}
    series.update(part_inputs(cfg, columns))
    return series, constant, counts


def part_inputs(cfg, columns: dict) -> dict:
    """What the machines read from the digital parts the replay feeds
    (`Config.parts`): element -> value at each tape row, each the part's
    counts for the row (PartFeed, with the calibration the simulated part
    starts with: the datasheet's example) through the driver's conversion
    in binary32 — pressure (Pa), temperature (°C), an axis (g), negated for
    a `-z=` output. The board's replay also redraws a held value's lowest
    bit (tape_replay._part_changes); that dither is left out here."""
    from fswkit.sim import parts as P
    from fswkit.sim.sensors import PartFeed

    f32 = _f32
    out: dict = {}
    for col, tp in getattr(cfg, "parts", {}).items():
        sensor = tp.sensor
        cal = {"bmp280": P.bmp280_calib_bytes(P.BMP280_EXAMPLE[0]),
               "ms5611": b"".join(w.to_bytes(2, "big") for w in P.ms5611_prom_words(P.MS5611_EXAMPLE[0]))
               }.get(sensor.part, b"\0" * 4)
        feed = PartFeed(sensor, 0, cal)
        values = np.asarray(columns[col], dtype=float)
        have = ~np.isnan(values)
        if not have.any():
            continue
        rows: dict = {}
        last = float(values[have][0])
        for v in values.tolist():
            last = v if v == v else last
            raw = feed.raw(**tp.values(last))
            if sensor.part == "bmp280":
                t_centi, t_fine = P.bmp280_compensate_T(feed.calib, raw["adc_T"])
                got = {"pressure": P.bmp280_compensate_P64(feed.calib, raw["adc_P"], t_fine) / 256.0,
                       "temperature": t_centi / 100.0}
            elif sensor.part == "ms5611":
                r = P.ms5611_compensate(feed.calib, raw["D1"], raw["D2"], True)
                got = {"pressure": float(r.P), "temperature": r.TEMP / 100.0}
            elif sensor.part == "adxl345":
                per = P.adxl345_g_per_count(feed.data_format)
                got = {q: raw[q] * per for q in "xyz"}
            else:
                per = P.mpu6050_g_per_count({2: 0, 4: 1, 8: 2, 16: 3}[feed.settings.get("range", 16)])
                got = {q: raw["a" + q] * per for q in "xyz"}
            for q, el in sensor.outputs:
                x = got.get(q.lstrip("-"))
                if x is not None:
                    rows.setdefault(el.name, []).append(f32(-x if q.startswith("-") else x))
        out.update(rows)
    return out


def _f32(x: float) -> float:
    return float(np.float32(x))


def _mission(app, cfg):
    names = set(cfg.states.values())
    m = next((m for m in app.machines if names <= {s.name for s in m.states}), None)
    if m is None:
        raise InterpError("no machine of the project has the states " + ", ".join(sorted(names)))
    return m


def replay(app, cfg, tape, *, truth=None, columns: dict | None = None) -> Replay:
    """The Replay of `tape` (or `columns`, a perturbed copy of its columns)
    through the project's machines, as tape_replay.replay gives the board's:
    `run.transitions` of the mission machine and `run.pin_events` of the
    pyro pins, at tape seconds."""
    if not app.rate or 1000 % int(app.rate):
        raise InterpError(f"an executor rate of {app.rate} Hz is not a whole number of milliseconds a step")
    step_ms = 1000 // int(app.rate)
    t = tape.time
    cols = columns if columns is not None else _columns(tape)
    offset = cfg.pad_s - float(t[0])
    values, constant, counts = _analog_inputs(cfg, cols)
    arm = _element_of(app, cfg.arm_pin)
    pins = [(role, _element_of(app, p), p) for role, p in (("drogue", cfg.drogue_pin), ("main", cfg.main_pin))
            if p is not None]
    mission = _mission(app, cfg)
    runs = [MachineRun(m, F32MODE, 0) for m in app.machines]
    shared = [[(v.name, v.index) for v in m.vars if v.kind == "element"] for m in app.machines]
    sv = {e.name: (0.0 if e.type.kind == "float" else 0) for e in app.sv.elements}
    k_mission = app.machines.index(mission)
    states = mission.states
    at_row = (t + offset).tolist()  # (each step compares with a row's time: Python floats, the same values)
    n_rows = len(at_row)
    inputs = list(values.items())
    end_s = float(t[-1]) + offset + cfg.run_on_s
    steps = int(end_s * 1000) // step_ms
    run = Run(columns=())
    row, prev = -1, None
    high = {role: False for role, _, _ in pins}
    gates = {role: _Gate(app, p) for role, _, pin in pins for p in app.pyro if p.output.pin_number == pin}
    for k in range(1, steps + 1):
        g = k * step_ms
        now = g / 1000.0
        sampled = (k - 1) * step_ms / 1000.0  # the previous step's scan (the first step's: at boot)
        while row + 1 < n_rows and at_row[row + 1] <= sampled:
            row += 1
        r0 = max(row, 0)
        for name, series in inputs:
            sv[name] = series[r0]
        sv.update(constant)  # the igniters: intact all the replay (open loop)
        if arm is not None:
            sv[arm] = now >= cfg.arm_s
        sv["time"] = g
        for mr, elements in zip(runs, shared):
            v = mr.v
            for name, i in elements:
                v[i] = sv[name]
            mr.step()
            for name, i in elements:
                sv[name] = v[i]
        tt = now - offset
        st = runs[k_mission].state
        if st != prev:
            run.transitions.append((tt, states[st].id, states[st].name))
            prev = st
        for role, element, pin in pins:
            gate = gates.get(role)
            level = (gate.level(sv, app.machines[gate.machine].states[runs[gate.machine].state].id)
                     if gate is not None else bool(sv[element]))
            if level != high[role]:
                run.pin_events.append(PinEvent(tt, pin, role, level, {}))
                high[role] = level
    run.steps = steps
    run.sim_s = end_s
    th = smoothed_altitude(tape, _pad(tape, truth))
    return Replay(run, offset, counts, {c: missing_spans(t, v) for c, v in _columns(tape).items()}, *th)


def perturbed(app, cfg, tape, truth, n: int, seed: int) -> list:
    """N perturbed replays in the interpreter, run i from the i-th child of
    SeedSequence(seed) as `fsw sim --perturb` draws them (the same
    perturbations as the board's runs of that seed): [(numbers, checks)]
    from tape_replay.evaluate."""
    from .tape_replay import evaluate, perturb

    out = []
    for seq in np.random.SeedSequence(seed).spawn(n):
        rng = np.random.Generator(np.random.PCG64(seq))
        cols = perturb(_columns(tape), tape.time, rng)
        rp = replay(app, cfg, tape, truth=truth, columns=cols)
        nums, checks, _notes = evaluate(rp, cfg, truth, tape)
        out.append((nums, checks))
    return out
