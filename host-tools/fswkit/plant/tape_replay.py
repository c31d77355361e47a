"""Real flights through the real firmware (`fsw sim PROJECT --tape
FLIGHT.csv`, whose command is fswkit.cli.sim): a sensor tape (fswkit.tape)
drives the simulated board's analog inputs OPEN LOOP, at the tape's own
times, while the firmware's pins and telemetry are recorded; then its
events are compared with the tape's truth (`FLIGHT.truth.toml`) and with
the recording altimeter's own, and checked.

Each tape column feeds one analog input of the project: the physical value
becomes the sensor's volts through the inverse of that input's `.aio`
calibration, clipped at the rails and quantised as the MCU's converter
does (fswkit.sim.sensors). Between rows the value is held. An empty cell
holds the last value (`missing = "hold"`) or makes the sensor output
`silent_volts` (`missing = "silent"`).

The board is given every input change at once (`SimBoard.schedule`: it
applies each at its cycle itself; no plant, no lock-step) and runs a
simulated second per `SimBoard.batch`, so a replay runs as fast as simavr
runs the firmware.

Each igniter's continuity input (`[igniters]`; plant.toml's `[drogue]`/
`[main]` `continuity_channel` by default) reads `intact_volts` the whole
replay, quantised as the sensors are: a replay is open loop, and nothing
opens an igniter when its pin fires (the closed-loop plant does that).

Which column feeds which input, the arming switch, the pyro pins, the
igniters, the mission machine's states and the main's configured altitude come from
`tape.toml` beside the project (or `--params FILE`), each key defaulting
from the project's `plant.toml` where it has one (docs/sim.md, "Replaying
real flights").

`--perturb N --seed S` replays the tape N times with seeded sensor noise,
spikes, dropouts and bias (`Perturbation`), in parallel on the available
CPUs, and reports the distribution of the event errors and every failed
check."""

from __future__ import annotations

import concurrent.futures
import csv
import hashlib
import math
import os
import statistics
import time
from dataclasses import dataclass, field

import numpy as np

from fswkit.link.layout import Layout
from fswkit.link.log import LogWriter
from fswkit.progress import progress
from fswkit.sim.board import EdgeOverflow, SimBoard, SimError
from fswkit.tape.truth import smoothed_altitude  # the truth's altitude, by its apogee's rule
from fswkit.autocode.model import SENSOR_PARTS
from fswkit.sim.sensors import (ACCELEROMETERS, AXES, BAROMETERS, AnalogSensor, PartFeed, board_parts, find_part,
                                from_channel, part_name)

from . import atmosphere
from . import report as reports
from .cosim import CosimError, PinEvent, Run, Telemetry, _nor, _one_cpu, nor_image, stop_words
from .params import Field as F
from .params import ParamsError, Table, _at
from .params import load_all
from .params import resolve as resolve_params
from .scenario import ROCKET_SCHEMA, _Binder

TAPE_COLUMNS = ("pressure_pa", "accel_g")  # the sensor columns of tape v1
RECORD_HZ = 100  # CSV rows per second of tape time

_UNSET = ""  # an optional string/pin key not given

TAPE_SCHEMA = {
    "tape": Table("the tape's columns and the replay's timeline", {
        "pressure_pa": F("pin", "the analog input the tape's pressure_pa feeds, as the .aio names it (\"A0\"), "
                         "a barometer part of the sensor tables (\"bmp280@0x76\"), or \"none\"", default=_UNSET),
        "accel_g": F("pin", "the analog input the tape's accel_g feeds, an accelerometer part (\"adxl345@0x53\"), "
                     "or \"none\"", default=_UNSET),
        "accel_axis": F("str", "with an accelerometer part: its axis along the vehicle's (x, y, z, \"-z\")",
                        default="z"),
        "missing": F("str", "an empty cell: \"hold\" the sensor's last value, or \"silent\": it outputs "
                     "silent_volts", default="hold"),
        "silent_volts": F("float", "a silent sensor's output, V", default=0.0, lo=0, hi=100),
        "pad_s": F("float", "simulated seconds from reset to the tape's first row (its first values held "
                   "meanwhile)", default=5.0, lo=0, hi=3600),
        "arm_s": F("float", "the arming switch closes at this simulated second", default=1.0, lo=0, hi=3600),
        "run_on_s": F("float", "after the tape's last row, its last values held this long", default=5.0, lo=0,
                      hi=3600),
    }),
    "pins": Table("the flight computer's digital pins", {
        "arm": F("pin", "the arming switch (a digital input driven high at arm_s), or \"none\"", default=_UNSET),
        "drogue": F("pin", "the drogue's pyro channel (a digital output)", default=_UNSET),
        "main": F("pin", "the main's pyro channel (a digital output)", default=_UNSET),
    }),
    "igniters": Table("the igniters' continuity inputs: each reads intact_volts the whole replay (open loop)", {
        "drogue_channel": F("pin", "the analog input that reads the drogue igniter's continuity (\"A2\"), or "
                            "\"none\"", default=_UNSET),
        "main_channel": F("pin", "the analog input that reads the main igniter's continuity, or \"none\"",
                          default=_UNSET),
        "intact_volts": F("float", "what a continuity input reads with its igniter intact, V (all the replay)",
                          default=2.5, lo=0, hi=100),
        "open_volts": F("float", "what it reads with the igniter open, V (a replay never opens one: kept as "
                        "plant.toml's key, and shown)", default=0.0, lo=0, hi=100),
    }),
    "firmware": Table("where the events are found in the project", {
        "machine": F("str", "the mission machine", default=_UNSET),
        "state_element": F("str", "the telemetry element holding its state", default=_UNSET),
        "altitude_element": F("str", "the telemetry element holding the estimated altitude above the pad",
                              default=_UNSET),
        "main_alt": F("str", "the main's deployment altitude (m above the pad): a machine's local, "
                      "\"MACHINE.LOCAL\"", default=_UNSET),
        "launch_state": F("str", "the state entered at launch", default="Boost"),
        "burnout_state": F("str", "the state entered at burnout", default="Coast"),
        "apogee_state": F("str", "the state entered at apogee", default="Apogee"),
        "landed_state": F("str", "the state entered on landing", default="Landed"),
    }),
    "checks": Table("pass/fail bounds", {
        "drogue_early_s": F("float", "the drogue pin no earlier than this before the barometric apogee",
                            default=0.5, lo=0, hi=60),
        "drogue_late_s": F("float", "... and no later than this after it", default=1.0, lo=0, hi=60),
        "main_tolerance_m": F("float", "the main pin within this of its configured altitude", default=15.0,
                              above=0, hi=10000),
        "landing_early_s": F("float", "landing detected no earlier than this before the tape's landing_s",
                             default=1.0, lo=0, hi=600),
        "landing_late_s": F("float", "... and no later than this after it", default=10.0, lo=0, hi=600),
    }),
}


class ReplayError(Exception):
    """Bad input for a replay (located messages): exit status 2."""


@dataclass(frozen=True)
class Perturbation:
    """What `--perturb` adds to each replay, per sensor column (documented
    in docs/sim.md): a bias drawn once per run (normal, standard deviation
    `bias`), Gaussian noise on every row (`noise`), spikes (each row with
    probability `spike_p` is replaced by the value plus a uniformly drawn
    `spike` magnitude of random sign), and dropouts (each row with
    probability `dropout_p` starts a run of empty cells lasting
    `dropout_s` seconds, uniformly drawn)."""

    bias: float
    noise: float
    spike_p: float
    spike: tuple[float, float]
    dropout_p: float
    dropout_s: tuple[float, float]


PERTURB = {
    "pressure_pa": Perturbation(bias=30.0, noise=8.0, spike_p=0.002, spike=(300.0, 1500.0), dropout_p=0.0005,
                                dropout_s=(0.05, 0.5)),
    "accel_g": Perturbation(bias=0.05, noise=0.1, spike_p=0.002, spike=(1.0, 8.0), dropout_p=0.0005,
                            dropout_s=(0.05, 0.5)),
}


# ---- the configuration ------------------------------------------------------------------

IGNITER_ROLES = ("drogue", "main")


@dataclass(frozen=True)
class TapeIgniter:
    """An igniter's continuity input in a replay: the input's `.aio`
    calibration and the converter (`sensor`), at `volts` (intact_volts) from
    reset to the end. Open loop: nothing opens it when its pyro pin fires.
    Its count and the board's millivolts are the sensors' (AnalogSensor)."""

    role: str
    sensor: AnalogSensor
    volts: float  # intact_volts
    open_volts: float  # never applied in a replay: shown

    @property
    def counts(self) -> int:
        return self.sensor.counts(self.volts)

    @property
    def millivolts(self) -> int:
        return self.sensor.millivolts(self.counts)

    def reading(self) -> float:
        """What the firmware's element holds (the board's arithmetic)."""
        return self.sensor.reading(self.counts)

@dataclass
class Config:
    path: str | None  # tape.toml, if any
    sensors: dict  # column -> AnalogSensor (None: the column feeds nothing)
    missing: str
    silent_volts: float
    pad_s: float
    arm_s: float
    run_on_s: float
    arm_pin: int | None
    drogue_pin: int | None
    main_pin: int | None
    state_element: str
    altitude_element: str | None
    accel_element: str | None
    states: dict  # event -> state name (launch, burnout, apogee, landed)
    main_alt: float | None
    main_alt_name: str
    checks: dict
    notes: list = field(default_factory=list)  # about the configuration: printed with the report's notes
    igniters: dict = field(default_factory=dict)  # role -> TapeIgniter (driven continuity inputs)
    eeprom: bytes | None = None  # the EEPROM programmed before boot (fsw sim --fw-params)
    nor: tuple | None = None  # (recorder plan, SimBoard spi_flash) of a recorder on an SPI NOR flash
    parts: dict = field(default_factory=dict)  # column -> TapePart (a digital part the column feeds)
    app_sensors: tuple = ()  # every part of the project's sensor tables: all are on the simulated board


@dataclass(frozen=True)
class TapePart:
    """A digital part a tape column feeds: the project's sensor part and the
    quantity the column's values become (pressure, or an axis with its sign;
    the other axes read 0 g)."""

    sensor: object  # autocode's Sensor
    quantity: str  # "pressure", "x", "y", "z"
    sign: float = 1.0

    @property
    def name(self) -> str:
        return part_name(self.sensor)

    def values(self, v: float) -> dict:
        """PartFeed.raw's arguments for a tape value: a pressure's
        temperature is the ISA temperature at its pressure altitude."""
        if self.quantity == "pressure":
            h = atmosphere.altitude(max(v, 1.0))  # (a pressure at or below 0: the model's top)
            return {"pressure": v, "temperature": atmosphere.temperature(h) - 273.15}
        return {self.quantity: self.sign * v}


class _Origins(_Binder):
    """The scenario binder, its messages located in whichever file gave the
    key (tape.toml, or plant.toml for a default)."""

    def __init__(self, app, layout, origins):
        super().__init__(None, {}, app, layout)
        self.origins = origins  # (table, key) -> "path:line"

    def err(self, table, key, msg):
        where = self.origins.get((table, key)) or self.origins.get((table, "")) or "tape config"
        self.errors.append(f"{where}: [{table}] {key}: {msg}")


def _plant_defaults(project_dir: str) -> tuple[dict, dict]:
    """Keys of plant.toml a tape replay can take as defaults (read without
    its schema: a tank's file has none of them); (values, origins).
    ReplayError when the file cannot be read (not TOML, a broken `extends`)."""
    path = os.path.join(project_dir, "plant.toml")
    if not os.path.exists(path):
        return {}, {}
    try:
        data, where = resolve_params(path, ROCKET_SCHEMA)  # its `extends` chain merged
    except ParamsError as e:  # never passed over: the replay would say plant.toml's keys are not named
        raise ReplayError("\n".join(e.errors + [
            f"{path}: a tape replay takes its defaults from this file (the sensors' channels, the pyro pins, "
            "the mission machine): mend it, or move it away and give them in tape.toml"])) from None

    def at(table, key):
        line = where.get((table, key), 1)
        return f"{getattr(line, 'path', path)}:{int(line)}"
    vals: dict = {}
    orig: dict = {}

    def take(src_t, src_k, dst_t, dst_k, conv=lambda v: v):
        t = data.get(src_t) if src_t else data
        if isinstance(t, dict) and src_k in t and isinstance(t[src_k], (str, int)) and not isinstance(t[src_k], bool):
            vals.setdefault(dst_t, {})[dst_k] = conv(t[src_k])
            orig[(dst_t, dst_k)] = at(src_t, src_k)

    take("barometer", "channel", "tape", "pressure_pa")
    take("accelerometer", "channel", "tape", "accel_g")
    take("barometer", "part", "tape", "pressure_pa")  # a digital part instead of an analog input
    take("accelerometer", "part", "tape", "accel_g")
    take("accelerometer", "axis", "tape", "accel_axis")
    take("pins", "arm", "pins", "arm")
    take("pins", "drogue", "pins", "drogue")
    take("pins", "main", "pins", "main")
    take("drogue", "pin", "pins", "drogue")  # [drogue]/[main] sections that name their pin win
    take("main", "pin", "pins", "main")
    for k in ("machine", "state_element", "altitude_element", "apogee_state", "landed_state"):
        take("firmware", k, "firmware", k)
    fw = data.get("firmware") if isinstance(data.get("firmware"), dict) else {}
    if isinstance(fw.get("main_altitude"), str) and isinstance(fw.get("machine"), str):
        vals.setdefault("firmware", {})["main_alt"] = f"{fw['machine']}.{fw['main_altitude']}"
        orig[("firmware", "main_alt")] = at("firmware", "main_altitude")
    sc = data.get("scenario")
    if isinstance(sc, dict) and isinstance(sc.get("arm_s"), (int, float)) and not isinstance(sc["arm_s"], bool):
        vals.setdefault("tape", {})["arm_s"] = float(sc["arm_s"])
        orig[("tape", "arm_s")] = at("scenario", "arm_s")
    for role in IGNITER_ROLES:  # the chutes' igniters; their volts each its own (`ROLE:intact_volts`)
        take(role, "continuity_channel", "igniters", f"{role}_channel")
        t = data.get(role)
        for k in ("intact_volts", "open_volts"):
            if isinstance(t, dict) and k in t and isinstance(t[k], (int, float, str)) and not isinstance(t[k], bool):
                vals.setdefault("igniters", {})[f"{role}:{k}"] = t[k]
                orig[("igniters", f"{role}:{k}")] = at(role, k)
    return vals, orig


def load_config(app, layout: Layout, path: str | None = None) -> Config:
    """The replay's configuration: `path` (default PROJECT/tape.toml, if it
    exists) over plant.toml's defaults, checked against the project;
    ReplayError with every located problem, in one run: a value tape.toml
    gives that the schema refuses is reported, and only the checks that need
    it are skipped (it is None in the values, not plant.toml's default)."""
    project_dir = os.path.dirname(app.path) or "."
    if path is None:
        cand = os.path.join(project_dir, "tape.toml")
        path = cand if os.path.exists(cand) else None
    defaults, origins = _plant_defaults(project_dir)
    given: dict = {t: {} for t in TAPE_SCHEMA}
    errors: list[str] = []  # the schema's
    if path is not None:
        try:
            values, where, errors, _bad = load_all(path, TAPE_SCHEMA)
        except ParamsError as e:
            raise ReplayError("\n".join(e.errors)) from None
        raw, _ = resolve_params(path, TAPE_SCHEMA)
        for t in TAPE_SCHEMA:
            origins[(t, "")] = _at(path, where.get((t, ''), 1))
            table = raw.get(t)
            for k in (table if isinstance(table, dict) else {}):
                if k in TAPE_SCHEMA[t].fields:  # (an unknown key: the schema's error)
                    given[t][k] = values[t][k]  # None: refused by the schema
                    origins[(t, k)] = _at(path, where.get((t, k), 1))
    else:
        for t in TAPE_SCHEMA:
            origins.setdefault((t, ""), os.path.join(project_dir, "tape.toml (absent)"))
    v: dict = {}
    for t, table in TAPE_SCHEMA.items():
        v[t] = {}
        for k, f in table.fields.items():
            v[t][k] = given[t].get(k, defaults.get(t, {}).get(k, f.default))
    bind = _Origins(app, layout, origins)
    tp, pins, fw = v["tape"], v["pins"], v["firmware"]
    if tp["missing"] is not None and tp["missing"] not in ("hold", "silent"):
        bind.err("tape", "missing", f"\"{tp['missing']}\": one of \"hold\", \"silent\"")
    if tp["silent_volts"] is not None and not 0 <= tp["silent_volts"] <= app.board.adc_vref:
        bind.err("tape", "silent_volts", f"{tp['silent_volts']:g} V is beyond the converter's 0..{app.board.adc_vref:g} V")
    sensors: dict = {}
    parts: dict = {}
    used: dict = {}
    for col in TAPE_COLUMNS:
        pin = tp[col]
        if pin == _UNSET or pin is None:
            continue  # checked against the tape's columns later (None: refused by the schema)
        if str(pin).lower() == "none":
            sensors[col] = None
            continue
        if isinstance(pin, str) and (pin.split("@")[0].strip().lower() in SENSOR_PARTS or "@" in pin):
            kinds = BAROMETERS if col == "pressure_pa" else ACCELEROMETERS
            part, why = find_part(getattr(app, "sensors", ()) or (), pin, kinds)
            if part is None:
                bind.err("tape", col, why)
                continue
            axis = ("pressure", 1.0)
            if col == "accel_g":
                if tp["accel_axis"] is None:
                    continue  # refused by the schema
                a = str(tp["accel_axis"]).strip().lower()
                if a.lstrip("+-") not in AXES:
                    bind.err("tape", "accel_axis", f"\"{tp['accel_axis']}\": one of x, y, z (\"-z\": the axis "
                             "points down)")
                    continue
                axis = (a.lstrip("+-"), -1.0 if a.startswith("-") else 1.0)
            parts[col] = TapePart(part, *axis)
            continue
        ch = bind.channel("tape", col, pin, True, "i")
        if ch is None:
            continue
        if ch.pin_number in used:
            bind.err("tape", col, f"pin {pin} already takes the tape's {used[ch.pin_number]}")
            continue
        used[ch.pin_number] = col
        try:
            sensors[col] = from_channel(ch, app.board)
        except ValueError as e:
            bind.err("tape", col, str(e))
    igniters = _igniters(app, bind, v["igniters"], given["igniters"], defaults.get("igniters", {}), origins, used)
    pin_no = {}
    for key, direction in (("arm", "i"), ("drogue", "o"), ("main", "o")):
        pin = pins[key]
        if pin is None:  # refused by the schema
            pin_no[key] = None
            continue
        if pin == _UNSET or (key == "arm" and str(pin).lower() == "none"):
            pin_no[key] = None
            if key != "arm":
                bind.err("pins", key, f"the {key}'s pyro pin is not named (set [pins] {key} in tape.toml, or "
                         "[pins] in plant.toml)")
            continue
        ch = bind.channel("pins", key, pin, False, direction)
        pin_no[key] = ch.pin_number if ch is not None else None
    machine = None
    if fw["machine"] is None or fw["state_element"] is None:
        pass  # refused by the schema
    elif fw["machine"] == _UNSET:
        bind.err("firmware", "machine", "the mission machine is not named (set [firmware] machine)")
    elif fw["state_element"] == _UNSET:
        bind.err("firmware", "state_element", "the telemetry element of its state is not named")
    else:
        machine = bind.machine_with_state(fw)
    if fw["altitude_element"] != _UNSET:
        bind.streamed("altitude_element", fw["altitude_element"])
    states = {}
    for ev in ("launch", "burnout", "apogee", "landed"):
        name = fw[f"{ev}_state"]
        if machine is not None and name is not None and machine.state(name) is None:
            bind.err("firmware", f"{ev}_state", f"machine `{machine.name}` has no state `{name}` (its states: "
                     + ", ".join(s.name for s in machine.states) + ")")
        states[ev] = name
    main_alt = None
    main_name = fw["main_alt"]
    if main_name is None:
        pass  # refused by the schema
    elif main_name == _UNSET:
        bind.err("firmware", "main_alt", "the main's configured altitude is not named (\"MACHINE.LOCAL\", e.g. "
                 "\"mission.MAIN_ALT\")")
    else:
        mname, dot, local = main_name.partition(".")
        m = next((x for x in app.machines if x.name == mname), None) if dot else None
        if m is None:
            bind.err("firmware", "main_alt", f"\"{main_name}\": expected \"MACHINE.LOCAL\" with a machine of the "
                     f"project ({', '.join(x.name for x in app.machines)})")
        else:
            main_alt = bind.local(m, "main_alt", local)
    if errors or bind.errors:
        raise ReplayError("\n".join(errors + bind.errors))
    accel = sensors.get("accel_g")
    accel_element = accel.element if accel is not None else None
    if "accel_g" in parts:
        tpart = parts["accel_g"]
        accel_element = next((el.name for q, el in tpart.sensor.outputs if q.lstrip("-") == tpart.quantity), None)
    cfg = Config(path, sensors, tp["missing"], tp["silent_volts"], tp["pad_s"], tp["arm_s"], tp["run_on_s"],
                 pin_no["arm"], pin_no["drogue"], pin_no["main"], fw["state_element"],
                 None if fw["altitude_element"] == _UNSET else fw["altitude_element"],
                 accel_element, states, main_alt, main_name, dict(v["checks"]))
    cfg.parts = parts
    cfg.app_sensors = tuple(getattr(app, "sensors", ()) or ())
    cfg.nor = _nor(app, app.board)  # the flight recorder's SPI NOR chip, when it logs to one
    cfg.igniters = igniters
    cfg.notes += _continuity_notes(app, igniters)
    return cfg


def _igniters(app, bind: _Origins, ig: dict, given: dict, defaults: dict, origins: dict, used: dict) -> dict:
    """The igniters' continuity inputs of `[igniters]` (plant.toml's chutes
    by default), checked: an analog input of the project that no tape
    column and no other igniter drives, volts within the converter's range;
    role -> TapeIgniter."""
    vref = app.board.adc_vref
    out = {}
    for role in IGNITER_ROLES:
        key = f"{role}_channel"
        pin = ig[key]
        if pin is None or pin == _UNSET or str(pin).lower() == "none":  # (None: refused by the schema)
            continue
        ch = bind.channel("igniters", key, pin, True, "i")
        volts = {}
        for k in ("intact_volts", "open_volts"):
            if k in given:  # tape.toml's: both igniters (checked by the schema)
                x, where = given[k], origins.get(("igniters", k))
            elif f"{role}:{k}" in defaults:  # this chute's in plant.toml
                x, where = defaults[f"{role}:{k}"], origins.get(("igniters", f"{role}:{k}"))
            else:
                x, where = TAPE_SCHEMA["igniters"].fields[k].default, None
            if x is None:  # refused by the schema: said
                x = 0.0
            elif isinstance(x, str) or not 0 <= x <= vref:
                msg = f"{where or 'tape config'}: [igniters] {k}: " + (
                    f'expected a number (volts), found a string "{x}"' if isinstance(x, str)
                    else f"{x:g} V is beyond the converter's 0..{vref:g} V")
                if msg not in bind.errors:
                    bind.errors.append(msg)
                x = 0.0
            volts[k] = float(x)
        if ch is None:
            continue
        if ch.pin_number in used:
            who = used[ch.pin_number]
            who = f"the tape's {who}" if who in TAPE_COLUMNS else who
            bind.err("igniters", key, f"pin {pin} is already driven by {who}: each sensor and igniter needs its "
                     "own analog input")
            continue
        used[ch.pin_number] = f"[igniters] {key}"
        try:
            out[role] = TapeIgniter(role, from_channel(ch, app.board), volts["intact_volts"], volts["open_volts"])
        except ValueError as e:
            bind.err("igniters", key, str(e))
    return out


def _continuity_notes(app, igniters: dict) -> list[str]:
    """Notes on the project's `[pyro]` continuity inputs against the
    replay's igniters: one no igniter drives (it reads 0 V on the board),
    one whose intact reading is below the channel's `min=`: firmware that
    checks continuity before arming may refuse to arm."""
    driven = {ig.sensor.pin: ig for ig in igniters.values()}
    notes = []
    for p in getattr(app, "pyro", ()):
        c = p.continuity
        if c is None:
            continue
        least = f", min={float(p.continuity_min):g}" if p.continuity_min is not None else ""
        ig = driven.get(c.pin)
        if ig is None:
            notes.append(f"NOTE  continuity: pyro channel `{p.element.name}` reads its igniter on {c.pin} "
                         f"(`{c.element.name}`{least}), which no igniter of this replay drives (it reads 0 V; "
                         "name it in tape.toml's [igniters], or as continuity_channel in plant.toml's "
                         "[drogue]/[main]): firmware that checks continuity before arming may refuse to arm")
        elif p.continuity_min is not None and ig.reading() < float(p.continuity_min):
            notes.append(f"NOTE  continuity: pyro channel `{p.element.name}`'s igniter on {c.pin} reads "
                         f"{ig.reading():.4g} (intact_volts {ig.volts:g} V), below its "
                         f"min={float(p.continuity_min):g}: firmware that checks continuity before arming may "
                         "refuse to arm")
    return notes


# ---- the tape and its truth -----------------------------------------------------------------

def _column_line(path: str) -> int:
    """The line of a tape's column names (after its `#` header); lines end
    as the tape reader ends them (LF, CRLF or CR alone)."""
    from fswkit.tape.tape import LINE_END_BYTES

    with open(path, "rb") as f:
        lines = LINE_END_BYTES.split(f.read())
    for n, line in enumerate(lines, 1):
        if not line.startswith(b"#"):
            return n
    return max(len(lines), 1)


MAX_SPAN_S = 3600.0  # s of tape a replay flies, from its first row to its last (as a plant run's max_s)


def load_tape(path: str, cfg: Config):
    """(tape, truth) for a replay; ReplayError with located messages: an
    unreadable tape or truth file, a cell beyond its range (the reader's),
    a pressure beyond the ISA troposphere (as `fsw tape truth` refuses
    it), a tape whose rows span more than
    MAX_SPAN_S (its simulated cycles would overflow, or the run last
    hours), a missing truth file, a column with values that the
    configuration feeds to no input."""
    from fswkit.tape import TapeError, read_tape, read_truth, truth_path

    from fswkit.tape.truth import check_altitudes

    try:
        tape = read_tape(path)
        check_altitudes(tape)  # the truth's altitude of a replay is worked out from every pressure, as the truth's
    except TapeError as e:
        raise ReplayError(str(e)) from None
    if tape.span > MAX_SPAN_S:
        i = int(np.argmax(tape.time - tape.start > MAX_SPAN_S))
        raise ReplayError(f"{path}:{_column_line(path) + 1 + i}: time_s {tape.time[i]:g} is more than "
                          f"{MAX_SPAN_S:,.0f} s after the first row's {tape.start:g} s: a replay flies at most "
                          f"{MAX_SPAN_S:,.0f} s of tape (a flight's log, not days of a clock); cut the tape to the "
                          "flight, or check the unit of its times")
    tpath = truth_path(path)
    if not os.path.exists(tpath):
        raise ReplayError(f"{path}: no truth file beside it ({tpath}): a replay compares the firmware's events "
                          "with the truth (docs/tapes.md)")
    try:
        truth = read_truth(tpath)
    except TapeError as e:
        raise ReplayError(str(e)) from None
    errors = []
    line = _column_line(path)
    for col in tape.columns_available():
        if col not in cfg.sensors and col not in cfg.parts:
            errors.append(f"{path}:{line}: column `{col}` has values but feeds no analog input of the project "
                          f"(name one in tape.toml, [tape] {col} = \"A0\", or {col} = \"none\" to leave it out)")
    for key in ("apogee_s", "burnout_s"):
        if getattr(truth, key) is None:
            errors.append(f"{tpath}:1: `{key}` is missing: the checks need it")
    errors += _truth_against(tape, truth)
    if errors:
        raise ReplayError("\n".join(errors))
    return tape, truth


# The truth's events the checks use, in the order a flight has them (liftoff_s absent: the tape's 0 s).
FLIGHT_EVENTS = ("liftoff_s", "burnout_s", "apogee_s", "landing_s")


def _truth_against(tape, truth) -> list[str]:
    """Located errors for a truth its tape cannot have: an event the checks
    use outside the tape's rows, or not after the one before it in a
    flight (a burnout before liftoff passes the boost's check whatever the
    firmware does; another flight's apogee fails it by minutes); a pad
    pressure, which the truth's altitudes are taken above, beyond the ISA
    troposphere."""
    out = []
    prev = None
    for key in FLIGHT_EVENTS:
        v = getattr(truth, key)
        if v is None:
            if key == "liftoff_s":
                prev = (key, 0.0)  # the tape's time base
            continue
        where = f"{truth.path}:{truth.lines.get(key, 1)}"
        if prev is not None and v <= prev[1]:
            out.append(f"{where}: {key} {v:g} s is not after {prev[0]} {prev[1]:g} s: a flight's events come in "
                       f"the order {', '.join(FLIGHT_EVENTS)}")
        elif v < tape.start:
            out.append(f"{where}: {key} {v:g} s is before the tape's first row ({tape.start:g} s): the truth of "
                       "another tape?")
        elif v > tape.end:
            out.append(f"{where}: {key} {v:g} s is after the tape's last row ({tape.end:g} s): the truth of "
                       "another tape?")
        prev = (key, v)
    pad = truth.pad_pressure_pa
    if pad is not None:
        from fswkit.tape import isa_altitude
        from fswkit.tape.truth import ISA_LOW_M, ISA_TOP_M

        h = float(isa_altitude(pad)) if pad > 0 else math.inf
        if not ISA_LOW_M <= h < ISA_TOP_M:
            out.append(f"{truth.path}:{truth.lines.get('pad_pressure_pa', 1)}: pad_pressure_pa {pad:g} Pa is "
                       + (f"{h:,.0f} m ASL" if math.isfinite(h) else "no pressure")
                       + f": beyond the ISA troposphere the truth's altitudes are taken in ({ISA_LOW_M / 1000:g} to "
                       f"{ISA_TOP_M / 1000:g} km ASL): a pressure in Pa (hPa times 100)")
    return out


def _columns(tape) -> dict:
    return {"pressure_pa": tape.pressure, "accel_g": tape.accel}


def missing_spans(t: np.ndarray, values: np.ndarray) -> list[tuple[float, float, int]]:
    """The runs of empty cells: (first row's time, last row's time, rows)."""
    gap = np.isnan(values)
    if not gap.any():
        return []
    d = np.diff(np.concatenate(([0], gap.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
    return [(float(t[a]), float(t[b - 1]), int(b - a)) for a, b in zip(starts, ends)]


def perturb(tape_cols: dict, t: np.ndarray, rng: np.random.Generator) -> dict:
    """The columns with this run's bias, noise, spikes and dropouts
    (PERTURB); empty cells stay empty."""
    out = {}
    for col, x in tape_cols.items():
        p = PERTURB[col]
        n = x.size
        y = x + rng.normal(0.0, p.bias) + rng.normal(0.0, p.noise, n)
        spikes = rng.random(n) < p.spike_p
        k = int(spikes.sum())
        y[spikes] += rng.choice((-1.0, 1.0), k) * rng.uniform(*p.spike, k)
        for i in np.flatnonzero(rng.random(n) < p.dropout_p):
            y[(t >= t[i]) & (t < t[i] + rng.uniform(*p.dropout_s))] = np.nan
        out[col] = y
    return out


def counts_series(values: np.ndarray, sensor: AnalogSensor, missing: str, silent_volts: float) -> np.ndarray:
    """The converter's count at each row: the value through the sensor; an
    empty cell holds the last count ("hold"; before the first value, the
    first value's) or reads `silent_volts` ("silent")."""
    silent = sensor.counts(silent_volts)
    have = ~np.isnan(values)
    first = sensor.count_of(float(values[have][0])) if have.any() else silent
    last = first if missing == "hold" else silent
    hold = missing == "hold"
    # each distinct value's count worked out once (count_of is a pure function of it; a tape's rows repeat
    # a few thousand values), the counts gathered in a list and made an array at the end
    memo: dict[float, int] = {}
    count_of = sensor.count_of
    out = []
    append = out.append
    for v in values.tolist():
        if v != v:
            append(last if hold else silent)
        else:
            c = memo.get(v)
            if c is None:
                c = memo[v] = count_of(v)
            last = c
            append(c)
    return np.array(out, dtype=np.int64)


# ---- the replay ----------------------------------------------------------------------------

@dataclass
class Replay:
    run: Run  # times in tape seconds (from liftoff)
    offset: float  # simulated second = tape second + offset
    counts: dict  # column -> counts per row
    missing: dict  # column -> missing_spans
    truth_t: np.ndarray
    truth_h: np.ndarray


def replay(tape, cfg: Config, elf: str, board, layout: Layout, log_path: str | None = None, *, truth=None,
           columns: dict | None = None, wall_limit: float = 3600.0, log_meta: dict | None = None,
           stop=None) -> Replay:
    """The firmware on the simulated board, its inputs driven from the tape
    (or `columns`, a perturbed copy of its columns); the Replay. The
    truth's altitude is taken above `truth.pad_pressure_pa` (else the
    tape's pad). On a terminal, a bar shows the seconds of the tape replayed.
    `stop`, a threading.Event: once set, CosimError at the next step."""
    with _one_cpu(), progress("tape replay", total=_end_s(tape, cfg), unit="s") as bar:
        return _replay(tape, cfg, elf, board, layout, log_path, columns, wall_limit, log_meta, truth, bar, stop)


def _end_s(tape, cfg: Config) -> float:
    """The simulated second a replay ends at: the tape's length after the
    pad time, and the run-on."""
    offset = cfg.pad_s - float(tape.time[0])
    return float(tape.time[-1]) + offset + cfg.run_on_s


def _replay(tape, cfg, elf, board, layout, log_path, columns, wall_limit, log_meta, truth, bar, stop=None) -> Replay:
    f_cpu = int(board.f_cpu)
    t = tape.time
    cols = columns if columns is not None else _columns(tape)
    offset = cfg.pad_s - float(t[0])
    counts = {c: counts_series(cols[c], s, cfg.missing, cfg.silent_volts) for c, s in cfg.sensors.items()
              if s is not None}
    mv = {cfg.sensors[c].pin: [cfg.sensors[c].millivolts(int(k)) for k in counts[c]] for c in counts}
    end_s = _end_s(tape, cfg)
    # the input changes, by cycle: (cycle, {pin: volts}, {pin: level})
    changes: dict[int, tuple[dict, dict]] = {}
    cyc = np.rint((t + offset) * f_cpu).astype(np.int64).tolist()
    for pin, series in mv.items():
        last = series[0]
        for i in range(1, len(series)):
            if series[i] != last:
                last = series[i]
                changes.setdefault(cyc[i], ({}, {}))[0][pin] = last / 1000.0
    if cfg.arm_pin is not None:
        changes.setdefault(int(round(cfg.arm_s * f_cpu)), ({}, {}))[1][cfg.arm_pin] = True
    end_cycle = int(round(end_s * f_cpu))
    chunk = f_cpu  # a simulated second per batch: telemetry decoded as it comes
    stops = sorted(c for c in changes if 0 < c < end_cycle)
    run = Run(columns=())
    roles = {p: r for r, p in (("drogue", cfg.drogue_pin), ("main", cfg.main_pin)) if p is not None}
    log = LogWriter(log_path, layout, **(log_meta or {})) if log_path else None
    if log:
        log.commit()
    telemetry = Telemetry(run, layout, cfg.state_element, log, offset)
    initial = {pin: series[0] / 1000.0 for pin, series in mv.items()}
    for ig in cfg.igniters.values():  # open loop: intact from reset to the end, never scheduled
        initial[ig.sensor.pin] = ig.millivolts / 1000.0
    sensors = cfg.app_sensors or tuple(tp.sensor for tp in cfg.parts.values())
    where = dict(zip(sensors, (w for _k, w in board_parts(sensors, board))))
    try:
        b = SimBoard(elf, board, uart="control", sim_limit=end_s + 1.0, wall_limit=wall_limit, analog=initial,
                     eeprom=cfg.eeprom, spi_flash=cfg.nor[1] if cfg.nor else None,
                     parts=[(x.part, where[x]) for x in sensors] or None)
    except SimError as e:
        if log:
            log.close()
        raise CosimError(str(e)) from None
    wall0 = time.perf_counter()
    try:
        for pin in roles:
            b.watch(pin)
        # every analog input change goes to the board at once: it applies each
        # at its cycle itself, and the replay runs a simulated second per round
        # trip; the digital parts' raw counts go in a `batch` at each change
        b.schedule([(c, *changes[c]) for c in stops])
        part_changes = _part_changes(b, cfg, cols, cyc, end_cycle, where, counts)
        part_stops = sorted(c for c in part_changes if 0 < c < end_cycle)
        pending = part_changes.get(0, {})
        first = changes.get(0, ({}, {}))
        now = 0
        j = 0
        while now < end_cycle:
            if stop is not None and stop.is_set():
                raise CosimError("stopped")
            until = min(end_cycle, now + chunk)
            if j < len(part_stops) and part_stops[j] < until:
                until = part_stops[j]
            try:
                step = b.batch(until, first[0], first[1], pending)
            except EdgeOverflow:
                raise CosimError("the board recorded more pin edges than it keeps") from None
            first = ({}, {})
            pending = {}
            if j < len(part_stops) and part_stops[j] == until:
                pending = part_changes[until]
                j += 1
            run.round_trips += 1
            if step.run.stop != "target":
                raise CosimError(f"{stop_words(step.run.stop, wall_limit)} at {now / f_cpu - offset:.3f} s tape time")
            now = until
            for e in step.edges:
                te = e.cycle / f_cpu - offset
                run.pin_events.append(PinEvent(te, e.pin, roles.get(e.pin, str(e.pin)), e.level, {}))
            if step.uart:
                telemetry.feed(step.uart, now / f_cpu)
            bar.update(now / f_cpu)
        run.steps = len(stops) + 1
        run.sim_s = end_s
        run.wall_s = time.perf_counter() - wall0
        if getattr(board, "eeprom", 0):
            run.eeprom = b.eeprom_read(0, board.eeprom)  # the flight recorder's store
        if cfg.nor:
            run.flash = nor_image(b, cfg.nor[0])
        try:
            run.ram["ram_usage"] = b.ram_usage()
        except (SimError, TypeError, ValueError) as e:
            run.ram["ram_usage"] = f"unavailable ({e})"
    except SimError as e:
        raise CosimError(str(e)) from None
    finally:
        b.close()
        if log:
            log.close()
    th = smoothed_altitude(tape, _pad(tape, truth))
    return Replay(run, offset, counts, {c: missing_spans(t, v) for c, v in _columns(tape).items()}, *th)


PART_DITHER_S = 0.005  # a fed part's lowest count is redrawn this often (see _part_changes)


def _part_changes(b: SimBoard, cfg: Config, cols: dict, cyc: list, end_cycle: int, where: dict,
                  counts: dict) -> dict:
    """The parts' raw counts by cycle, {cycle: {harness id: {name: counts}}},
    only those that change; each column's main count per row (adc_P, D1, or
    the axis's count) goes to `counts`. Each row's value is held until the
    next row; an empty cell holds the last value (before the first value,
    the first value's) whatever `missing` says: a part has no output volts
    to go silent with.

    A held value is not frozen: every PART_DITHER_S of simulated time the
    main count's lowest bit is redrawn (a seeded draw, the same every
    replay), as a real part's noise keeps its lowest bits moving, so that
    the driver's stuck check (`stuck=N` identical conversions in a row) is
    not set off by the tape's sample-and-hold, its pad time or its run-on."""
    out: dict = {}
    f_cpu = int(b.f_cpu)
    step = max(1, int(round(PART_DITHER_S * f_cpu)))
    grid = np.arange(0, end_cycle, step, dtype=np.int64)
    rows = np.asarray(cyc, dtype=np.int64)
    rng = np.random.Generator(np.random.PCG64(0x5EED))
    for col, tp in cfg.parts.items():
        w = where[tp.sensor]
        feed = PartFeed(tp.sensor, w, b.part_calibration(w))
        values = np.asarray(cols[col], dtype=float)
        have = ~np.isnan(values)
        if not have.any():
            continue
        main = {"bmp280": "adc_P", "ms5611": "D1"}.get(tp.sensor.part) or (
            tp.quantity if tp.sensor.part == "adxl345" else "a" + tp.quantity)
        per_row = []
        last_v = float(values[have][0])
        for v in values.tolist():
            if v == v:
                last_v = v
            per_row.append(feed.raw(**tp.values(last_v)))
        counts[col] = np.array([r[main] for r in per_row], dtype=np.int64)
        # the instants a value is set: each row's (the first from reset) and the dither's grid
        points = np.union1d(grid, rows[1:][(rows[1:] > 0) & (rows[1:] < end_cycle)])
        row_at = np.clip(np.searchsorted(rows, points, side="right") - 1, 0, len(per_row) - 1)
        bits = rng.integers(0, 2, points.size).tolist()
        last: dict = {}
        for c, r, bit in zip(points.tolist(), row_at.tolist(), bits):
            raw = dict(per_row[r])
            raw[main] ^= bit
            changed = {n: x for n, x in raw.items() if last.get(n) != x}
            if changed:
                last = raw
                out.setdefault(c, {}).setdefault(w, {}).update(changed)
    return out


def _pad(tape, truth) -> float:
    pad = truth.pad_pressure_pa if truth is not None and truth.pad_pressure_pa is not None else None
    return pad if pad is not None else tape.pad_pressure()


# ---- events, checks, the report -----------------------------------------------------------

RECORDER = {  # event -> the recorder_*_s keys that hold the recording altimeter's own, in preference order
    "launch": ("recorder_liftoff_event_s", "recorder_boost_event_s", "recorder_launch_event_s"),
    "burnout": ("recorder_coast_event_s", "recorder_burnout_flag_s", "recorder_burnout_event_s"),
    "apogee": ("recorder_apogee_event_s", "recorder_drogue_event_s", "recorder_drogue_state_s",
               "recorder_drogue_state_inferred_s"),
    "main": ("recorder_main_event_s", "recorder_main_state_s", "recorder_main_flag_s"),
    "landing": ("recorder_landed_event_s", "recorder_landed_state_s", "recorder_landing_event_s"),
}


def recorder_event(truth, event: str) -> tuple[str, float] | None:
    """The recording altimeter's own time of an event: (key, s), or None."""
    rec = truth.recorder_events
    for key in RECORDER[event]:
        v = rec.get(key)
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            return key, float(v)
    return None


def firmware_events(rp: Replay, cfg: Config) -> dict:
    """event -> (tape s, how it was seen) for the firmware's events."""
    run = rp.run

    def state(name):
        return next((t for t, _, n in run.transitions if n == name), None)

    def pin(role):
        return next((e.t for e in run.pin_events if e.role == role and e.level), None)

    out = {}
    for ev, how in (("launch", "launch"), ("burnout", "burnout")):
        t = state(cfg.states[how])
        if t is not None:
            out[ev] = (t, f"state {cfg.states[how]}")
    t = pin("drogue")
    out["apogee"] = (t, "drogue pin") if t is not None else None
    if out["apogee"] is None:
        t = state(cfg.states["apogee"])
        out["apogee"] = (t, f"state {cfg.states['apogee']}") if t is not None else None
    t = pin("main")
    out["main"] = (t, "main pin") if t is not None else None
    t = state(cfg.states["landed"])
    out["landing"] = (t, f"state {cfg.states['landed']}") if t is not None else None
    return {k: v for k, v in out.items() if v is not None}


def altitude_at(rp: Replay, t: float) -> float:
    """The truth's (smoothed) altitude above the pad at tape second t."""
    if rp.truth_t.size == 0:
        return math.nan
    return float(np.interp(t, rp.truth_t, rp.truth_h))


def evaluate(rp: Replay, cfg: Config, truth, tape) -> tuple[dict, list, list]:
    """(errors: the numbers, checks: [reports.Check], notes: checks skipped)."""
    ck = cfg.checks
    ev = firmware_events(rp, cfg)
    run = rp.run
    checks, notes = [], []
    nums: dict = {}
    burnout = truth.burnout_s
    early = [e for e in run.pin_events if e.level and e.role in ("drogue", "main") and e.t < burnout]
    checks.append(reports.Check(f"no pyro pin before liftoff or during boost (before burnout_s {burnout:g} s)",
                                not early, "none" if not early else
                                ", ".join(f"{e.role} at {e.t:.3f} s" for e in early)))
    nums["boost_pyro"] = len(early)
    lo, hi = ck["drogue_early_s"], ck["drogue_late_s"]
    name = f"drogue pin within -{lo:g}/+{hi:g} s of the barometric apogee ({truth.apogee_s:g} s)"
    d = next((e for e in run.pin_events if e.role == "drogue" and e.level), None)
    if d is None:
        checks.append(reports.Check(name, False, "the drogue pin never went high"))
    else:
        err = d.t - truth.apogee_s
        nums["apogee_err_s"] = err
        checks.append(reports.Check(name, -lo <= err <= hi, f"at {d.t:.3f} s ({err:+.3f} s), "
                                    f"{altitude_at(rp, d.t):.1f} m"))
    tol = ck["main_tolerance_m"]
    m = next((e for e in run.pin_events if e.role == "main" and e.level), None)
    name = f"main pin within ±{tol:g} m of {cfg.main_alt_name} = {cfg.main_alt:g} m (truth altitude at the pin)"
    after = rp.truth_h[rp.truth_t > truth.apogee_s]
    if m is None and (after.size == 0 or after.min() > cfg.main_alt):
        low = float(after.min()) if after.size else math.nan
        notes.append(f"SKIP  main: the tape never comes down to {cfg.main_alt_name} = {cfg.main_alt:g} m (its lowest "
                     f"after apogee: {low:.0f} m), and the main pin never went high: main not checked")
    elif m is None:
        checks.append(reports.Check(name, False, "the main pin never went high"))
    else:
        h = altitude_at(rp, m.t)
        nums["main_err_m"] = h - cfg.main_alt
        checks.append(reports.Check(name, abs(h - cfg.main_alt) <= tol,
                                    f"at {m.t:.3f} s at {h:.1f} m ({h - cfg.main_alt:+.1f} m)"))
    if truth.landing_s is None:
        end_h = altitude_at(rp, float(tape.end))
        notes.append(f"SKIP  landing: the tape ends in the air ({end_h:.0f} m above the pad at {tape.end:g} s): "
                     "landing not checked")
    else:
        lo, hi = ck["landing_early_s"], ck["landing_late_s"]
        name = f"landing detected within -{lo:g}/+{hi:g} s of the tape's landing ({truth.landing_s:g} s)"
        got = ev.get("landing")
        if got is None:
            checks.append(reports.Check(name, False, f"state {cfg.states['landed']} never came"))
        else:
            err = got[0] - truth.landing_s
            nums["landing_err_s"] = err
            checks.append(reports.Check(name, -lo <= err <= hi, f"at {got[0]:.3f} s ({err:+.3f} s)"))
    for k, key in (("launch", "launch_err_s"), ("burnout", "burnout_err_s")):
        ref = truth.liftoff_s if k == "launch" else truth.burnout_s
        if k in ev and ref is not None:
            nums[key] = ev[k][0] - ref
    return nums, checks, notes


def _fmt(x, unit="s", sign=False) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    return f"{x:+.2f} {unit}" if sign else f"{x:.2f} {unit}"


def event_table(rp: Replay, cfg: Config, truth, end: float | None = None) -> list[str]:
    """The firmware's events beside the truth and the recorder's own; an
    event after `end` (the tape's last row) is marked: the inputs were
    held then."""
    ev = firmware_events(rp, cfg)
    if end is not None:
        ev = {k: (t, how + (" (after the tape's end)" if t > end else "")) for k, (t, how) in ev.items()}
    rec_name = truth.recorder or "the recorder"
    rows = [("event", "firmware", "how", "truth", "fw − truth", "recorder", "rec − truth", "fw − rec")]
    truths = {"launch": ("liftoff_s", truth.liftoff_s), "burnout": ("burnout_s", truth.burnout_s),
              "apogee": ("apogee_s", truth.apogee_s), "main": (None, None),
              "landing": ("landing_s", truth.landing_s)}
    for name in ("launch", "burnout", "apogee", "main", "landing"):
        fw = ev.get(name)
        tkey, tv = truths[name]
        rec = recorder_event(truth, name)
        fw_t = fw[0] if fw else None
        rec_t = rec[1] if rec else None
        if name == "main":  # compared by altitude: the truth is the configured altitude
            h = altitude_at(rp, fw_t) if fw_t is not None else None
            rec_h = altitude_at(rp, rec_t) if rec_t is not None else None
            rows.append((name, _fmt(fw_t), fw[1] if fw else "never",
                         f"{cfg.main_alt:g} m ({cfg.main_alt_name})",
                         _fmt(None if h is None else h - cfg.main_alt, "m", True),
                         _fmt(rec_t) + (f" at {rec_h:.0f} m" if rec_h is not None else ""),
                         "—",  # the recorder's own configured altitude is not in the truth
                         _fmt(None if fw_t is None or rec_t is None else fw_t - rec_t, "s", True)))
            continue
        rows.append((name, _fmt(fw_t), fw[1] if fw else "never",
                     _fmt(tv) if tv is not None else "— (not in the truth)",
                     _fmt(None if fw_t is None or tv is None else fw_t - tv, "s", True),
                     _fmt(rec_t), _fmt(None if rec_t is None or tv is None else rec_t - tv, "s", True),
                     _fmt(None if fw_t is None or rec_t is None else fw_t - rec_t, "s", True)))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    out = [f"events (tape time, s from liftoff; recorder: {rec_name}; main compared by the truth's altitude):"]
    for r in rows:
        out.append("  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
    return out


def summary(rp: Replay, cfg: Config, tape, truth, checks, notes, label: str) -> reports.Report:
    run = rp.run
    speed = run.sim_s / run.wall_s if run.wall_s else float("inf")
    lines = [f"{label}: {tape.path} ({tape.rows:,} rows, {tape.start:g} to {tape.end:g} s; {truth.recorder or ''})",
             f"replay: {run.sim_s:.3f} s simulated in {run.wall_s:.1f} s wall ({speed:.2f}× real time, "
             f"{run.round_trips:,} round trips); the tape's first row at {cfg.pad_s:g} s simulated, "
             f"arm at {cfg.arm_s:g} s" + ("" if cfg.arm_pin is not None else " (no arming pin)")]
    for col in TAPE_COLUMNS:
        s = cfg.sensors.get(col)
        tp = cfg.parts.get(col)
        if tp is not None:
            q = tp.quantity if tp.quantity == "pressure" else ("-" if tp.sign < 0 else "") + tp.quantity
            lines.append(f"sensor {col} → part {tp.name} ({q}): raw counts through the datasheet's inverse with "
                         "the part's calibration")
            continue
        if s is None:
            lines.append(f"sensor {col}: feeds no input")
            continue
        k = rp.counts[col]
        lo, hi = s.range()
        sat = int(np.count_nonzero((k == 0) | (k == s.full)))
        lines.append(f"sensor {col} → {s.pin} (`{s.element}` = V × {s.scale:g} + {s.offset:g}): {lo:g} to {hi:g} "
                     f"between the rails, one count {s.lsb:.4g}"
                     + (f"; {sat:,} rows at a rail (saturated)" if sat else ""))
    lines += igniter_lines(cfg)
    for col, spans in rp.missing.items():
        if not spans:
            continue
        how = ("held at the last value" if cfg.missing == "hold" or col in cfg.parts
               else f"sensor silent at {cfg.silent_volts:g} V")
        shown = ", ".join(f"{a:g}–{b:g} s ({n:,} rows)" for a, b, n in spans[:5])
        more = f" and {len(spans) - 5} more runs" if len(spans) > 5 else ""
        fed = "" if cfg.sensors.get(col) is not None or col in cfg.parts else " (not fed)"
        lines.append(f"missing {col}{fed}: {shown}{more}; {how}")
    lines += event_table(rp, cfg, truth, tape.end)
    lines += reports._transition_lines(_Shim(run, rp), cfg.altitude_element, "altitude_m", "m")
    lines += reports._tail_lines(run)
    lines += cfg.notes + notes
    return reports.Report(lines, checks)


def igniter_lines(cfg: Config) -> list[str]:
    """One line per driven continuity input: what it reads, all the replay."""
    out = []
    for role, ig in cfg.igniters.items():
        s = ig.sensor
        out.append(f"igniter {role} → {s.pin} (`{s.element}` = V × {s.scale:g} + {s.offset:g}): intact, "
                   f"{ig.volts:g} V (count {ig.counts}, read as {ig.reading():.6g}) from reset to the end; open "
                   f"loop, it never opens ({ig.open_volts:g} V) when its charge fires")
    return out


class _Shim:
    """A Run seen by report._transition_lines: the truth's altitude as a column."""

    def __init__(self, run, rp):
        self.transitions, self.samples = run.transitions, run.samples
        self.columns = ("time_s", "altitude_m")
        self.rows = list(zip(rp.truth_t.tolist(), rp.truth_h.tolist())) or [(0.0, math.nan)]


# ---- files ------------------------------------------------------------------------------

CSV_COLUMNS = ("time_s", "sim_s", "pressure_pa", "accel_g", "altitude_m_agl", "pressure_counts", "accel_counts",
               "pin_drogue", "pin_main")


def truth_rows(rp: Replay, tape) -> list[tuple]:
    """RECORD_HZ rows: the tape (held), the truth's altitude, the counts the
    firmware read, the pyro pins' levels."""
    t = tape.time
    grid = np.arange(math.ceil(t[0] * RECORD_HZ), math.floor((t[-1]) * RECORD_HZ) + 1) / RECORD_HZ
    idx = np.clip(np.searchsorted(t, grid + 1e-9, side="right") - 1, 0, t.size - 1)
    alt = np.interp(grid, rp.truth_t, rp.truth_h) if rp.truth_t.size else np.full(grid.size, np.nan)
    cols = _columns(tape)
    pins = {"drogue": np.zeros(grid.size, dtype=int), "main": np.zeros(grid.size, dtype=int)}
    for e in rp.run.pin_events:
        if e.role in pins:
            pins[e.role][grid >= e.t] = int(e.level)
    rows = []
    pk = rp.counts.get("pressure_pa")
    ak = rp.counts.get("accel_g")
    for j, g in enumerate(grid.tolist()):
        i = int(idx[j])
        p, a = float(cols["pressure_pa"][i]), float(cols["accel_g"][i])
        rows.append((round(g, 6), round(g + rp.offset, 6), None if p != p else p, None if a != a else a,
                     float(alt[j]), None if pk is None else int(pk[i]), None if ak is None else int(ak[i]),
                     int(pins["drogue"][j]), int(pins["main"][j])))
    return rows


def plot(rp: Replay, cfg: Config, tape, path: str, title: str, digest: str | None = None) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    run = rp.run
    tel_t, tel_h = reports._telemetry(run, cfg.altitude_element) if cfg.altitude_element else (np.zeros(0),) * 2
    acc_t, acc_v = reports._telemetry(run, cfg.accel_element) if cfg.accel_element else (np.zeros(0),) * 2
    fig, axes = plt.subplots(2, 1, sharex=True, figsize=(11, 7))
    axes[0].plot(rp.truth_t, rp.truth_h, "-", linewidth=1.0, label="tape (ISA, 0.5 s average)")
    if len(tel_t):
        axes[0].plot(tel_t, tel_h, "-", linewidth=0.8, label="telemetry")
    axes[0].set_ylabel("altitude above the pad (m)")
    have = tape.available("accel_g")
    axes[1].plot(tape.time[have], tape.accel[have], "-", linewidth=0.8, label="tape")
    if len(acc_t):
        axes[1].plot(acc_t, acc_v, "-", linewidth=0.8, label="telemetry")
    axes[1].set_ylabel("axial acceleration (g)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="center right", fontsize=8)
        for tt, _sid, _name in run.transitions:
            ax.axvline(tt, color="tab:red", linestyle="--", linewidth=0.7)
        for e in run.pin_events:
            if e.level and e.role in ("drogue", "main"):
                ax.axvline(e.t, color="tab:purple", linestyle=":", linewidth=1.0)
    for tt, _sid, name in run.transitions:
        axes[0].annotate(name, (tt, 0.98), xycoords=("data", "axes fraction"), rotation=90, fontsize=7, va="top",
                         ha="right", color="tab:red")
    for e in run.pin_events:
        if e.level and e.role in ("drogue", "main"):
            axes[1].annotate(f"{e.role} pin", (e.t, 0.02), xycoords=("data", "axes fraction"), rotation=90,
                             fontsize=7, va="bottom", ha="left", color="tab:purple")
    axes[1].set_xlabel("tape time (s from liftoff)")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110, metadata={reports.DIGEST_KEY: digest} if digest else None)
    plt.close(fig)


@dataclass
class Outcome:
    replay: Replay
    report: reports.Report
    numbers: dict
    files: dict


def execute(tape, truth, cfg: Config, app, elf: str, board, layout: Layout, out: str | None) -> Outcome:
    """One replay, its files written into `out` as one set (as closed-loop
    runs: fswkit.plant.run's staging, the summary last)."""
    from fswkit.outputs import stopped_by_signals
    from .run import _install, _set_aside
    import tempfile

    if out is None:
        return _execute(tape, truth, cfg, app, elf, board, layout, None)
    os.makedirs(out, exist_ok=True)
    stage = tempfile.mkdtemp(prefix=".run-", dir=out)
    with stopped_by_signals():
        try:
            o = _execute(tape, truth, cfg, app, elf, board, layout, stage)
        except BaseException as e:
            _set_aside(stage, out, e)
            raise
        o.files = _install(stage, out)
    return o


def _execute(tape, truth, cfg, app, elf, board, layout, folder) -> Outcome:
    from .run import FILES, budget_checks

    files = {k: os.path.join(folder, v) for k, v in FILES.items()} if folder is not None else {}
    meta = {"source": f"fsw sim --tape {os.path.basename(tape.path)}", "clock": "simulated",
            "tape": tape.path, "tape_offset_s": cfg.pad_s - tape.start}
    rp = replay(tape, cfg, elf, board, layout, files.get("log"), truth=truth, log_meta=meta)
    nums, checks, notes = evaluate(rp, cfg, truth, tape)
    record_lines, flight_record = [], None
    if app.log is not None:
        record_lines, flight_record = _recorder(app, rp, checks)
    checks += budget_checks(app, elf, rp.run)
    rep = summary(rp, cfg, tape, truth, checks, notes, f"{layout.name}: tape replay")
    rep.lines += record_lines
    nums["speed"] = rp.run.sim_s / rp.run.wall_s if rp.run.wall_s else float("inf")
    if folder is not None:
        with open(files["csv"], "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            streamed = list(dict.fromkeys(n for s in layout.streams for n in s.region.names))
            w.writerow(list(CSV_COLUMNS) + ["tm_time_s", "tm_state_name"] + [f"tm_{n}" for n in streamed])
            states = layout.states.get(cfg.state_element, {})
            samples = rp.run.samples
            known: dict = {}
            last_t = None
            j = 0
            for row in truth_rows(rp, tape):
                while j < len(samples) and samples[j][0] <= row[0] + 1e-9:
                    last_t = samples[j][0]
                    known.update(samples[j][1])
                    j += 1
                st = known.get(cfg.state_element)
                w.writerow([reports._cell(x) for x in row]
                           + [reports._cell(last_t), states.get(int(st), "") if st is not None else ""]
                           + [reports._cell(known.get(n)) for n in streamed])
        with open(files["csv"], "rb") as f:
            digest = hashlib.sha256(f.read()).hexdigest()
        title = (f"{layout.name}: tape {os.path.basename(tape.path)}"
                 + (" — all checks pass" if rep.passed else " — CHECKS FAIL"))
        plot(rp, cfg, tape, files["png"], title, digest)
        if flight_record is not None:
            from fswkit.recorder.dump import write_flight

            write_flight(files["record"], app, *flight_record)
        with open(files["summary"], "w") as f:
            f.write(rep.text())
    return Outcome(rp, rep, nums, files)


def _recorder(app, rp, checks) -> tuple[list[str], tuple | None]:
    """The flight recorder after a replay (docs/recorder.md): the record
    against the telemetry and the tape's truth; (lines, (plan, flight))."""
    from fswkit.recorder.check import flight_report

    truth = (rp.truth_t + rp.offset, rp.truth_h) if rp.truth_t.size else None
    alt = next((f.element.name for f in app.log.fields if f.element.name == "altitude"), None)
    lines, more, record = flight_report(app, rp.run, reports.Check, truth=truth, alt_element=alt, offset=rp.offset)
    checks += more
    return lines, record


# ---- robustness runs -------------------------------------------------------------------

@dataclass
class PerturbResult:
    index: int
    numbers: dict
    checks: list
    error: str | None = None
    notes: list = field(default_factory=list)  # the configuration's (Config.notes)


def _one_perturbed(i, seq, tape, truth, cfg, elf, board, layout, stop=None) -> PerturbResult:
    rng = np.random.Generator(np.random.PCG64(seq))
    cols = perturb(_columns(tape), tape.time, rng)
    try:
        rp = replay(tape, cfg, elf, board, layout, truth=truth, columns=cols, stop=stop)
    except CosimError as e:
        return PerturbResult(i, {}, [], str(e), list(cfg.notes))
    nums, checks, _notes = evaluate(rp, cfg, truth, tape)
    nums["speed"] = rp.run.sim_s / rp.run.wall_s if rp.run.wall_s else float("inf")
    return PerturbResult(i, nums, checks, notes=list(cfg.notes))


# The replays of one `--perturb N` (as a study's runs, fswkit.cli.sim_study.MAX_RUNS): each is drawn and
# queued only when a worker is free, its result held in memory to the table.
MAX_PERTURB = 1_000_000


class StoppedRuns(Exception):
    """Ctrl-C or a stopping signal (fswkit.outputs.Stopped) ended the
    replays early: `results`, those that had finished, in run order."""

    def __init__(self, results: list):
        super().__init__(f"stopped after {len(results)} runs")
        self.results = results


def robustness(tape, truth, cfg: Config, elf: str, board, layout: Layout, n: int, seed: int,
               workers: int | None = None) -> list[PerturbResult]:
    """N perturbed replays (run i from the i-th child of SeedSequence(seed):
    the same seed gives the same runs, whatever the number of workers).
    StoppedRuns on Ctrl-C or a stopping signal: the replays still flying
    stop at their next step, those not started never start.

    In the main thread, SIGINT, SIGTERM and SIGHUP (those not ignored) only
    set the stop while the replays fly, and the loop sees it within
    STOP_POLL_S: an exception raised wherever the main thread happened to
    be could strike inside concurrent.futures' waiting, between the locks
    of the futures it takes one by one, and leave one held, so that the
    replay finishing it and the pool's join waited for ever."""
    import signal
    import threading

    from fswkit import outputs
    from fswkit.outputs import Stopped

    if workers is None:
        try:
            workers = len(os.sched_getaffinity(0))
        except (AttributeError, OSError):
            workers = os.cpu_count() or 1
    workers = max(1, min(workers, n))
    stop = threading.Event()
    signalled: list[int] = []

    def on_signal(signum, _frame):
        signalled.append(signum)
        stop.set()

    saved = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            if signal.getsignal(sig) not in (signal.SIG_IGN, None):  # None: a handler not set from Python
                saved[sig] = signal.signal(sig, on_signal)
    done: list[PerturbResult] = []
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=workers)
    try:
        with progress("perturbed replays", total=n, unit="runs") as bar:
            queued: set = set()
            nxt = failed = 0
            while (nxt < n or queued) and not stop.is_set():
                while nxt < n and len(queued) < workers:  # the i-th child of SeedSequence(seed), as spawn(n)[i]
                    seq = np.random.SeedSequence(seed, spawn_key=(nxt,))
                    queued.add(pool.submit(_one_perturbed, nxt, seq, tape, truth, cfg, elf, board, layout, stop))
                    nxt += 1
                ended, queued = concurrent.futures.wait(queued, timeout=STOP_POLL_S,
                                                        return_when=concurrent.futures.FIRST_COMPLETED)
                for f in ended:
                    r = f.result()
                    done.append(r)
                    failed += r.error is not None or not all(c.passed for c in r.checks)
                bar.update(len(done), failed=failed)
    except (KeyboardInterrupt, Stopped):  # not in the main thread, or before the handlers were in place
        stop.set()
    finally:
        for sig, handler in saved.items():
            signal.signal(sig, handler)
    if stop.is_set():
        pool.shutdown(wait=True, cancel_futures=True)
        if signalled and signalled[0] != signal.SIGINT:
            outputs.stopped_by = signalled[0]  # the exit status names it (128 + N), as Stopped's does
        raise StoppedRuns(sorted(done, key=lambda r: r.index))
    pool.shutdown(wait=True)
    return sorted(done, key=lambda r: r.index)


STOP_POLL_S = 0.2  # how soon the replays' loop sees a stop


ERROR_KEYS = (("launch_err_s", "launch − liftoff", "s"), ("burnout_err_s", "burnout − burnout_s", "s"),
              ("apogee_err_s", "drogue pin − apogee_s", "s"), ("main_err_m", "main altitude − configured", "m"),
              ("landing_err_s", "landing − landing_s", "s"), ("boost_pyro", "pyro pins during boost", ""))


def robustness_text(results: list[PerturbResult], tape, n: int, seed: int, wall: float,
                    complete: bool = True) -> tuple[str, bool]:
    """The distribution of the event errors and every failed check; (text, all passed)."""
    runs = f"{n} perturbed replays" if complete else \
        f"{len(results)} of {n} perturbed replays (stopped early: the table covers the runs that finished)"
    lines = [f"robustness: {tape.path}, {runs}, seed {seed}, {wall:.1f} s wall",
             "perturbation per run (docs/sim.md): " + "; ".join(
                 f"{c}: bias sd {p.bias:g}, noise sd {p.noise:g}, spikes p={p.spike_p:g} of {p.spike[0]:g}–"
                 f"{p.spike[1]:g}, dropouts p={p.dropout_p:g} of {p.dropout_s[0]:g}–{p.dropout_s[1]:g} s"
                 for c, p in PERTURB.items())]
    lines += list(dict.fromkeys(n for r in results for n in r.notes))  # the configuration's, once
    ok_runs = [r for r in results if r.error is None]
    speeds = [r.numbers["speed"] for r in ok_runs if "speed" in r.numbers]
    if speeds:
        lines.append(f"speed: {statistics.median(speeds):.2f}× real time per replay (median)")
    lines.append("event errors (min / median / max over the runs that had the event):")
    for key, label, unit in ERROR_KEYS:
        xs = [r.numbers[key] for r in ok_runs if key in r.numbers]
        if xs:
            lines.append(f"  {label:<30} {min(xs):+9.3f} / {statistics.median(xs):+9.3f} / {max(xs):+9.3f} {unit}"
                         f"  ({len(xs)} of {len(results)} runs)")
        else:
            lines.append(f"  {label:<30} never seen")
    names: dict = {}
    for r in ok_runs:
        for c in r.checks:
            names.setdefault(c.name, []).append(c.passed)
    lines.append("checks (share of runs meeting each):")
    for name, got in names.items():
        lines.append(f"  {sum(got):4d} of {len(results)}  {name}")
    failed = [(r.index, c) for r in ok_runs for c in r.checks if not c.passed]
    broken = [r for r in results if r.error is not None]
    if failed or broken:
        lines.append("failed:")
        lines += [f"  FAIL  run {i}: {c.name}: {c.detail}" for i, c in failed]
        lines += [f"  FAIL  run {r.index}: {r.error}" for r in broken]
    ok = not failed and not broken
    lines.append(f"{len(results) - len({i for i, _ in failed} | {r.index for r in broken})} of {len(results)} "
                 "runs passed every check")
    return "\n".join(lines) + "\n", ok


def robustness_csv(results: list[PerturbResult]) -> str:
    keys = [k for k, _, _ in ERROR_KEYS] + ["speed"]
    out = ["run," + ",".join(keys) + ",passed,error"]
    for r in results:
        cells = [reports._cell(r.numbers.get(k)) for k in keys]
        passed = r.error is None and all(c.passed for c in r.checks)
        out.append(f"{r.index}," + ",".join(cells) + f",{int(passed)},{(r.error or '').replace(',', ';')}")
    return "\n".join(out) + "\n"
