"""A sensor tape through a project's machines in the reference interpreter
(binary32): the tape replay of `fsw sim --tape` (fswkit.plant.tape_replay)
without the simulated board, for tests that fly every real-flight tape in
seconds. The inputs are the board's: each column through the inverse of
the `.aio` calibration and the 10-bit converter (counts_series), read back
through the calibration in binary32 as the firmware's analog task does,
held between rows; the machines step every 1000 / rate ms in the order of
the application's tasks, sharing the state vector's elements; the arming
switch closes at arm_s, the tape's first row comes at pad_s (tape.toml's
defaults). The events agree with the board's within a step or two (the
board's clock is millis(); tools/bench_tapes.py prints the board's)."""

from __future__ import annotations

import numpy as np

from fswkit.autocode.numeric import F32MODE, f32
from fswkit.plant.tape_replay import counts_series, smoothed_altitude
from fswkit.run.interp import MachineRun
from fswkit.sim.sensors import from_channel


def replay(app, tape, columns: dict, *, mission: str = "mission", arm: str = "armSwitch",
           pins=("drogue", "main"), pad_s: float = 5.0, arm_s: float = 1.0, run_on_s: float = 5.0):
    """[(tape second, event)]: every state the mission machine enters
    (its name) and every rising edge of the `pins` elements ("drogue pin").
    `columns` maps an analog input's element to the tape's values (NaN:
    hold the last)."""
    sensors = {c.element.name: from_channel(c, app.board) for c in app.channels
               if c.analog and c.direction == "i"}
    t = tape.time
    offset = pad_s - float(t[0])
    values = {}
    for name, s in sensors.items():
        counts = counts_series(np.asarray(columns[name], dtype=float), s, "hold", 0.0)
        full, vref, scale, off = f32(float(s.full)), f32(s.vref), f32(s.scale), f32(s.offset)
        values[name] = [f32(f32(f32(f32(float(k)) * vref) / full) * scale + off) for k in counts.tolist()]
    runs = [MachineRun(m, F32MODE, 0) for m in app.machines]
    shared = [[(v.name, v.index) for v in m.vars if v.kind == "element"] for m in app.machines]
    sv = {e.name: (0.0 if e.type.kind == "float" else 0) for e in app.sv.elements}
    k_mission = [m.name for m in app.machines].index(mission)
    names = [s.name for s in app.machines[k_mission].states]
    step_ms = 1000 // app.rate
    ends = t + offset
    steps = int((float(t[-1]) + offset + run_on_s) * 1000) // step_ms
    row, prev, events = -1, None, []
    high = dict.fromkeys(pins, False)
    for k in range(1, steps):
        g = k * step_ms
        now = g / 1000.0
        while row + 1 < len(t) and ends[row + 1] <= now:
            row += 1
        for name in values:
            sv[name] = values[name][max(row, 0)]
        sv[arm] = now >= arm_s
        sv["time"] = g
        for run, elements in zip(runs, shared):
            for name, i in elements:
                run.v[i] = sv[name]
            run.step()
            for name, i in elements:
                sv[name] = run.v[i]
        at = now - offset
        state = names[runs[k_mission].state]
        if state != prev:
            events.append((at, state))
            prev = state
        for p in pins:
            if sv[p] and not high[p]:
                events.append((at, f"{p} pin"))
            high[p] = bool(sv[p])
    return events


def first(events, what: str):
    return next((t for t, e in events if e == what), None)


def truth_altitude(tape, truth, t: float) -> float:
    """The tape's smoothed altitude above the pad at tape second t (as the replay's checks)."""
    tt, h = smoothed_altitude(tape, truth.pad_pressure_pa if truth.pad_pressure_pa is not None
                              else tape.pad_pressure())
    return float(np.interp(t, tt, h))
