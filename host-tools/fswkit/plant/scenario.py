"""Scenarios: a plant model wired to a project's pins, its sensors' volts
and noise, the timeline (arming, ignition, a regulator failure), the
faults, when the run ends, and the parameters file (`plant.toml`) that says
all of it. `load(kind, path, app, layout, seed, fault)` checks the file and
its references into the project — the mission machine's states and locals,
the telemetry elements, the pins of the .dio/.aio — and returns the
scenario; every problem is a located ParamsError.

The cosim loop calls `inputs(t)` (sensor volts by analog pin, levels of the
digital inputs the scenario drives; and `part_values`, the physical values
of the digital parts it feeds: `parts`, failing as `part_fail_plan` says), `advance(t0, t1, edges)` (integrate
the step with the watched pins' edges; returns PinEvents), `record()` (a
truth row) and `done(t, state)`.
"""

from __future__ import annotations

import numpy as np

from fswkit.autocode import model as M
from fswkit.autocode.evaluate import NotConstant, local_values
from fswkit.autocode.numeric import REALS
from fswkit.autocode.numtext import decimal

from fswkit.sim.sensors import ACCELEROMETERS, AXES, BAROMETERS, find_part

from . import atmosphere
from .atmosphere import G0
from .cosim import PinEvent
from .motor import CURVE_MAX_N, CURVE_MAX_S, MAX_MASS_KG
from .params import Field as F
from .params import ParamsError, Table, error_at, load_all
from .rocket import Chute, Motor, Rocket
from .tank import PSI, Tank

PLANTS = ("rocket", "tank")
FAULTS = {
    "stuck-baro": "the barometer's output freezes at its value at ignition; the drogue must still deploy, "
                  "by the backup timer",
    "pinned-accel": "the accelerometer reads full scale (5 V) from boot and the motor is never lit; "
                    "no pyro channel may fire and the vehicle never leaves its pad states",
    "pinned-baro": "the barometer reads full scale (5 V) from boot and the motor is never lit; "
                   "no pyro channel may fire and the vehicle never leaves its pad states",
    "open-igniter": "the drogue's igniter is open from boot (broken or unconnected: its continuity input reads "
                    "open_volts) and the motor is never lit; the vehicle must refuse to arm, no pyro channel may "
                    "fire and it never leaves its pad states",
}
# Faults that keep the vehicle on the pad, armed by its key until hold_s, the motor never lit.
PAD_FAULTS = ("pinned-accel", "pinned-baro", "open-igniter")
# Failures of a digital part (plant.toml's [barometer] / [accelerometer] `part`), written
# `--fault baro-nack@12.5`: at a simulated second, or at ignition without `@T`.
PART_FAULTS = {
    "baro-nack": "the barometer part stops answering on its bus (no ACK; on SPI, MISO reads 0xFF)",
    "baro-stuck": "the barometer part's results stop changing (its conversions still end)",
    "accel-nack": "the accelerometer part stops answering on its bus",
    "accel-stuck": "the accelerometer part's results stop changing",
    "baro-noisy": "the barometer part's results turn noisy: NOISY_PA of Gaussian noise on its pressure",
    "accel-noisy": "the accelerometer part's results turn noisy: NOISY_G of Gaussian noise on its axis",
}
# A `noisy` part (a cracked package, a loose connector, a failing supply): what it reads, on top of its own noise.
# The part still answers and its counts change, so no driver can see it: the navigation must.
NOISY_PA = 1000.0  # about 90 m of altitude at the pad's 1,400 m
NOISY_G = 2.0


def parse_fault(text: str) -> tuple[str, float | None]:
    """(fault, second or None) of a `--fault` value; ValueError with the reason."""
    name, at, when = text.partition("@")
    if name in FAULTS and not at:
        return name, None
    if name not in PART_FAULTS:
        raise ValueError(f"--fault {text}: one of {', '.join(FAULTS)}, or a digital part's failure "
                         f"{', '.join(k + '[@SECONDS]' for k in PART_FAULTS)}")
    if not at:
        return name, None
    t = decimal(when)
    if t is None or not 0 <= t <= 3600:
        raise ValueError(f"--fault {text}: `@{when}` must be a simulated second from 0 to 3600 (baro-nack@12.5)")
    return name, t

# ---- parameter schemas ------------------------------------------------------------------

_TOP = Table("the plant and its rate", {
    "plant": F("str", "which plant model: rocket or tank"),
    "rate_hz": F("int", "plant steps per simulated second (lock-step with the MCU)", default=1000,
                 lo=1000, hi=100000),
})

def _chute(what: str) -> Table:
    return Table(what, {
        "cd_area_m2": F("float", "Cd × area when fully inflated, m²", above=0, hi=1000),
        "fire_ms": F("float", "the pyro pin must stay high this long to fire the charge", lo=0, hi=10000),
        "inflate_s": F("float", "from the charge firing to a full canopy", lo=0, hi=30),
        "continuity_channel": F("pin", "the analog input that reads the igniter's continuity through a sense "
                                "resistor, e.g. \"A2\" (absent: no continuity input, the igniter is not simulated)",
                                required=False),
        "intact_volts": F("float", "what the continuity input reads with the igniter intact, V", default=2.5,
                          lo=0, hi=5),
        "open_volts": F("float", "what it reads with the igniter open (after its charge fired, or broken), V",
                        default=0.0, lo=0, hi=5),
    })


# [scenario] keys of both plants: a reset of the MCU at a phase of the flight (fswkit.plant.cosim).
_RESET = {
    "reset_state": F("str", "the MCU resets once, reset_after_s after telemetry first shows the machine in this "
                     "state (absent: no such reset)", required=False),
    "reset_after_s": F("float", "with reset_state: seconds after telemetry first shows that state", default=0.2,
                       lo=0, hi=3600),
    "reset_cause": F("str", "with reset_state: why the MCU resets: brownout, watchdog, external or power "
                     "(fswkit.sim.board.RESET_CAUSES)", default="brownout"),
}


ROCKET_SCHEMA = {
    "": _TOP,
    "vehicle": Table("the vehicle without its propellant", {
        "dry_mass_kg": F("float", "mass without propellant, kg", lo=0.01, hi=1000),
        "body_cd_area_m2": F("float", "drag coefficient × reference area of the body, m²", lo=0, hi=10),
    }),
    "motor": Table("the motor: a thrust curve written here, or a RASP motor file", {
        "file": F("str", "a RASP .eng motor file (relative to this file): its motor's thrust curve, and its "
                  "propellant mass unless propellant_kg says otherwise", required=False),
        "name": F("str", "with file: the designation of the motor to fly (\"H128W\"), needed when the file holds "
                  "more than one", required=False),
        "propellant_kg": F("float", "propellant mass, burnt in proportion to the impulse delivered", lo=0,
                           hi=MAX_MASS_KG, required=False),
        "thrust_curve": F("curve", "[[seconds from ignition, newtons], ...], linearly interpolated",
                          x_hi=CURVE_MAX_S, hi=CURVE_MAX_N, required=False),
        "impulse_sd": F("float", "motor-to-motor spread: each seed's motor has its thrust scaled by 1 + "
                        "impulse_sd × a standard normal draw (0: every motor is nominal)", default=0.0, lo=0, hi=0.2),
    }, alternatives=(("file", "name"), ("thrust_curve",)), follows=(("propellant_kg", "thrust_curve"),)),
    "drogue": _chute("the drogue parachute"),
    "main": _chute("the main parachute"),
    "atmosphere": Table("the standard atmosphere", {
        "pad_altitude_m": F("float", "the pad's altitude above sea level, m", lo=-400, hi=8000),
    }),
    "barometer": Table("the barometer: an analog sensor on an input (channel) or a digital part (part)", {
        "channel": F("pin", "the analog input it drives, e.g. \"A0\"", required=False),
        "pa_per_volt": F("float", "with channel: its slope, Pa per volt", lo=1, hi=1e7, required=False),
        "pa_at_0v": F("float", "with channel: the pressure that would read 0 V, Pa", lo=-1e7, hi=1e7,
                      required=False),
        "part": F("str", "a barometer of the project's sensor tables whose raw counts the plant sets: "
                  "\"bmp280@0x76\", or \"bmp280\" when the project has one", required=False),
        "noise_pa": F("float", "Gaussian noise, standard deviation in Pa", lo=0, hi=1e5),
    }, alternatives=(("channel", "pa_per_volt", "pa_at_0v"), ("part",))),
    "accelerometer": Table("the accelerometer on the vehicle's axis: analog (channel) or a digital part (part)", {
        "channel": F("pin", "the analog input it drives, e.g. \"A1\"", required=False),
        "volts_per_g": F("float", "with channel: its slope, V per g", lo=1e-4, hi=100, required=False),
        "zero_g_volts": F("float", "with channel: its output at 0 g, V", lo=0, hi=5, required=False),
        "part": F("str", "an accelerometer of the project's sensor tables whose raw counts the plant sets: "
                  "\"adxl345@0x53\", \"adxl345@spi:7\", or \"adxl345\" when the project has one",
                  required=False),
        "axis": F("str", "with part: the part's axis along the vehicle's (x, y, z; \"-z\" when it points down); "
                  "the other two read 0 g", required=False),
        "noise_g": F("float", "Gaussian noise, standard deviation in g", lo=0, hi=100),
    }, alternatives=(("channel", "volts_per_g", "zero_g_volts"), ("part", "axis"))),
    "pins": Table("the flight computer's digital pins the plant uses", {
        "arm": F("int", "the arming switch (a digital input the scenario drives: high = armed)", lo=0, hi=255),
        "drogue": F("int", "the drogue's pyro channel (a digital output)", lo=0, hi=255),
        "main": F("int", "the main's pyro channel (a digital output)", lo=0, hi=255),
    }),
    "scenario": Table("the timeline", {
        "arm_s": F("float", "the arming switch closes at this simulated second", lo=0, hi=3600),
        "ignition_s": F("float", "the motor is lit at this simulated second", lo=0, hi=3600),
        "max_s": F("float", "the run stops here whatever happens", above=0, hi=3600),
        "linger_s": F("float", "simulated seconds run on after the landed state", default=1.0, lo=0, hi=600),
        "landed_timeout_s": F("float", "after touchdown, give up waiting for the landed state", default=10.0,
                              lo=0, hi=600),
        "hold_s": F("float", "pinned-sensor and open-igniter faults: the vehicle sits on the pad with its arming "
                    "key on until this second", default=20.0, above=0, hi=3600),
        "part_fail": F("str", "a digital part that fails mid-flight: \"bmp280@0x76\" (one of the project's "
                       "sensor tables'; absent: none)", required=False),
        "part_fail_s": F("float", "with part_fail: the simulated second it fails at", lo=0, hi=3600, required=False),
        "part_fail_mode": F("str", "with part_fail: \"nack\" (it stops answering), \"stuck\" (its results stop "
                            "changing) or \"noisy\" (the plant adds NOISY_PA / NOISY_G of noise)", default="nack"),
        **_RESET,
    }),
    "firmware": Table("where the plant and the checks find things in the project", {
        "machine": F("str", "the mission machine"),
        "state_element": F("str", "the telemetry element holding the mission machine's state"),
        "altitude_element": F("str", "the telemetry element holding the estimated altitude, m above the pad"),
        "main_altitude": F("str", "the mission machine's local: the main's deployment altitude, m above the pad"),
        "apogee_backup": F("str", "the mission machine's local: time after launch that fires the drogue anyway"),
        "apogee_state": F("str", "the state entered at apogee"),
        "armed_state": F("str", "the state of an armed vehicle on the pad"),
        "landed_state": F("str", "the state entered on landing"),
        "pad_states": F("names", "the states of a vehicle on the pad"),
    }),
    "checks": Table("pass/fail bounds", {
        "apogee_window_s": F("float", "apogee detected no later than this after the true apogee", default=1.0,
                             above=0, hi=60),
        "drogue_max_drop_m": F("float", "the drogue fires before the vehicle falls this far below apogee",
                               default=30.0, above=0, hi=10000),
        "main_tolerance_m": F("float", "the main fires within this of its configured altitude", default=15.0,
                              above=0, hi=10000),
        "backup_tolerance_s": F("float", "stuck barometer: the drogue fires within this after the backup time",
                                default=0.2, above=0, hi=60),
        "sequence": F("names", "the states of a nominal flight, in order"),
    }),
}

TANK_SCHEMA = {
    "": _TOP,
    "tank": Table("the tank and its gas", {
        "volume_l": F("float", "litres", lo=0.001, hi=1e6),
        "temperature_k": F("float", "the gas's temperature (held constant), K", lo=20, hi=2000),
        "gas_constant_j_kg_k": F("float", "specific gas constant, J/(kg·K) (nitrogen 296.8)", lo=1, hi=1e5),
        "gamma": F("float", "ratio of specific heats (nitrogen 1.4)", above=1, hi=2),
        "initial_psi": F("float", "gauge pressure at the start, psi", lo=0, hi=1e5),
    }),
    "supply": Table("the pressurant supply through the regulator", {
        "flow_g_s": F("float", "inflow while the regulator works, g/s", lo=0, hi=1e6),
        "failed_flow_g_s": F("float", "inflow once it has failed, g/s", lo=0, hi=1e6),
    }),
    "vent": Table("the vent valve", {
        "cd_area_mm2": F("float", "discharge coefficient × orifice area, mm²", above=0, hi=1e6),
        "response_ms": F("float", "the valve's time constant opening and closing, ms", lo=0, hi=10000),
    }),
    "transducer": Table("the pressure transducer (gauge)", {
        "channel": F("pin", "the analog input it drives, e.g. \"A0\""),
        "psi_per_volt": F("float", "its slope, psi per volt", lo=1e-3, hi=1e6),
        "psi_at_0v": F("float", "the pressure that would read 0 V, psi", lo=-1e6, hi=1e6),
        "noise_psi": F("float", "Gaussian noise, standard deviation in psi", lo=0, hi=1e5),
    }),
    "pins": Table("the rig's digital pins the plant uses", {
        "valve": F("int", "the vent valve's driver (a digital output: high = open)", lo=0, hi=255),
    }),
    "scenario": Table("the timeline", {
        "failure_s": F("float", "the regulator fails at this simulated second", lo=0, hi=3600),
        "max_s": F("float", "the run stops here whatever happens", above=0, hi=3600),
        "linger_s": F("float", "simulated seconds run on after the abort state", default=1.0, lo=0, hi=600),
        **_RESET,
    }),
    "firmware": Table("where the plant and the checks find things in the project", {
        "machine": F("str", "the vent controller's machine"),
        "state_element": F("str", "the telemetry element holding the machine's state"),
        "pressure_element": F("str", "the telemetry element holding the measured pressure"),
        "vent_psi": F("float", "the pressure above which the machine opens the valve (a literal in the machine)",
                      lo=-1e6, hi=1e6),
        "abort_limit": F("str", "the machine's local: the pressure above which it aborts"),
        "control_state": F("str", "the state that regulates"),
        "abort_state": F("str", "the state entered on over-pressure"),
    }),
    "checks": Table("pass/fail bounds", {
        "open_within_s": F("float", "the valve opens no later than this after the pressure passes vent_psi",
                           default=0.05, above=0, hi=60),
        "abort_within_s": F("float", "the abort state is reached no later than this after the pressure "
                            "passes the abort limit", default=0.1, above=0, hi=60),
        "min_cycles": F("int", "the valve opens at least this many times before the failure", default=2,
                        lo=0, hi=1000000),
    }),
}

SCHEMAS = {"rocket": ROCKET_SCHEMA, "tank": TANK_SCHEMA}


class Noise:
    """Gaussian noise of one sensor from its own generator, drawn in blocks."""

    def __init__(self, rng: np.random.Generator, sigma: float, block: int = 4096):
        self.rng, self.sigma, self.block = rng, sigma, block
        self.buf: list[float] = []
        self.i = 0
        # the generator's state since the last block was drawn (None: not read yet): it only changes when a
        # block is drawn, and reading it (a new dict) at every save cost more than the steps between saves
        self._state: dict | None = None

    def save(self) -> tuple:
        if self._state is None:
            self._state = self.rng.bit_generator.state
        return self.buf, self.i, self._state  # buf is replaced, never changed in place

    def restore(self, saved: tuple) -> None:
        self.buf, self.i, state = saved
        if state is not self._state:  # a block was drawn since: the generator goes back to before it
            self.rng.bit_generator.state = state
            self._state = state

    def __call__(self) -> float:
        if not self.sigma:
            return 0.0
        if self.i == len(self.buf):
            self.buf = (self.rng.standard_normal(self.block) * self.sigma).tolist()
            self.i = 0
            self._state = None
        self.i += 1
        return self.buf[self.i - 1]


class Pyro:
    """A pyro channel: the charge fires once its pin has been high for `fire_s`."""

    def __init__(self, fire_s: float):
        self.fire_s = fire_s
        self.high_since: float | None = None
        self.fired_at: float | None = None

    def edge(self, t: float, level: bool) -> None:
        self.high_since = (self.high_since if self.high_since is not None else t) if level else None

    def poll(self, t: float) -> float | None:
        """The time the charge fired, the first time it has by `t`."""
        if self.fired_at is None and self.high_since is not None and t - self.high_since >= self.fire_s:
            self.fired_at = self.high_since + self.fire_s
            return self.fired_at
        return None


class Igniter:
    """A pyro channel's igniter as its continuity input sees it: through a
    sense resistor, `intact_volts` while the igniter conducts, `open_volts`
    once its charge has fired (the bridge wire is gone) or from boot when it
    is broken or unconnected (`broken`)."""

    def __init__(self, channel: str, pyro: Pyro, intact_volts: float, open_volts: float, broken: bool = False):
        self.channel, self.pyro = channel, pyro
        self.intact_volts, self.open_volts, self.broken = intact_volts, open_volts, broken

    def volts(self, t: float) -> float:
        fired = self.pyro.fired_at
        if self.broken or (fired is not None and fired <= t):
            return self.open_volts
        return self.intact_volts


# ---- binding a parameters file to the project --------------------------------------------

class _Binder:
    """Checks names and pins of the parameters against the project. `bad`:
    the (table, key) of values the schema refused (None in the values): a
    check that needs one is skipped, its error already said; a name or pin
    of None is not checked."""

    def __init__(self, path, where, app, layout, bad=frozenset()):
        self.path, self.where, self.app, self.layout = path, where, app, layout
        self.bad = set(bad)
        self.errors: list[str] = []

    def good(self, table, *keys) -> bool:
        """Whether none of these keys of `table` holds a value the schema refused."""
        return not any((table, k) in self.bad for k in keys)

    def err(self, table, key, msg):
        self.errors.append(error_at(self.path, self.where, table, key, msg))

    def machine(self, name):
        if name is None:
            return None
        m = next((m for m in self.app.machines if m.name == name), None)
        if m is None:
            self.err("firmware", "machine", f"the project has no machine `{name}` (it has "
                     + ", ".join(m.name for m in self.app.machines) + ")")
        return m

    def machine_with_state(self, fw):
        """The `[firmware]` machine, its state element checked: streamed, and
        that machine's `S`."""
        m = self.machine(fw["machine"])
        self.streamed("state_element", fw["state_element"])
        name = fw["state_element"]
        if m is not None and name is not None and self.layout.element(name) is not None \
                and m.vars[m.s].name != name:
            self.err("firmware", "state_element", f"`{fw['state_element']}` is not machine `{m.name}`'s state "
                     f"(that is `{m.vars[m.s].name}`)")
        return m

    def streamed(self, key, name):
        if name is None:
            return
        streamed = {n for s in self.layout.streams for n in s.region.names}
        if self.layout.element(name) is None:
            self.err("firmware", key, f"the project has no element `{name}`")
        elif name not in streamed:
            self.err("firmware", key, f"`{name}` is not in any telemetry stream (the ground never sees it)")

    def state(self, m, key, name, table="firmware"):
        if m is not None and name is not None and m.state(name) is None:
            self.err(table, key, f"machine `{m.name}` has no state `{name}` (its states: "
                     + ", ".join(s.name for s in m.states) + ")")

    def local(self, m, key, name):
        if m is None or name is None:
            return None
        v = m.var(name)
        if v is None or v.kind != M.LOCAL:
            self.err("firmware", key, f"machine `{m.name}` has no local `{name}`")
            return None
        try:
            values = local_values(m, REALS[self.app.board.real])
        except NotConstant:
            self.err("firmware", key, f"the locals of `{m.name}` have no constant initial values")
            return None
        value = values[v.index]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.err("firmware", key, f"local `{name}` of `{m.name}` is not a number")
            return None
        return float(value)

    def channel(self, table, key, pin, analog, direction):
        """The project's channel on `pin`, named as the I/O tables name pins
        (`"A0"`) or by the board's pin number (14, "14"), or None after an
        error (None for a pin of None: a value the schema refused)."""
        if pin is None:
            return None
        what = ("an analog input" if analog else "a digital input" if direction == "i" else "a digital output")
        pin_text = str(pin)
        board = self.app.board
        number = board.pin(pin_text)
        if number is None:
            forms = ", ".join(f'"{n}" or {p}' for n, p in board.analog_pins.items())
            self.err(table, key, f"board `{board.name}` has no pin {pin_text}: name a pin as the I/O tables do, "
                     f"or by its number ({'analog inputs: ' + forms if analog else 'digital pins: numbers'})")
            return None
        for c in self.app.channels:
            if c.pin_number == number:
                if c.analog != analog or c.direction != direction:
                    self.err(table, key, f"pin {pin_text} is not {what} of the project ({c.path}:{c.line} "
                             f"makes it {'an analog' if c.analog else 'a digital'} "
                             f"{'input' if c.direction == 'i' else 'output'} for `{c.element.name}`)")
                return c
        self.err(table, key, f"pin {pin_text} is not {what} of the project (its I/O tables have no such pin)")
        return None


def _bind_reset(sc, bind: _Binder, m, sc_table: dict) -> None:
    """[scenario]'s reset at a phase of the flight, checked: a state of the
    machine, a cause the board can simulate, no reset_after_s or
    reset_cause without a reset_state."""
    from fswkit.sim.board import RESET_CAUSES

    sc.reset_state = sc_table["reset_state"]
    sc.reset_after_s = sc_table["reset_after_s"]
    sc.reset_cause = sc_table["reset_cause"]
    if sc.reset_state is not None:
        bind.state(m, "reset_state", sc.reset_state, table="scenario")
    elif bind.good("scenario", "reset_state"):
        for key in ("reset_after_s", "reset_cause"):
            if ("scenario", key) in bind.where:
                bind.err("scenario", key, "needs reset_state (the state whose first sighting starts the count)")
    if sc.reset_cause is not None and sc.reset_cause not in RESET_CAUSES:
        bind.err("scenario", "reset_cause", f"`{sc.reset_cause}` is not a reset cause (one of "
                 + ", ".join(RESET_CAUSES) + ")")


SENSOR_KINDS = BAROMETERS + ACCELEROMETERS


def _sensor(bind: _Binder, t: dict, role: str, transfer: tuple[str, str], kinds: tuple[str, ...]):
    """[barometer] / [accelerometer]: (the project's analog channel, None)
    or (None, the project's digital part), checked: one of channel and
    part, an analog sensor's transfer function, a part of the project's
    sensor tables of a kind that measures this. `t`: the table's values.
    With `channel` or `part` refused by the schema, which of the two the
    sensor is is unknown: only the other, if given, is checked."""
    if not bind.good(role, "channel", "part"):
        if t["part"] is not None:
            part, why = find_part(getattr(bind.app, "sensors", ()) or (), t["part"], kinds)
            if part is None:
                bind.err(role, "part", why)
            return None, part
        return bind.channel(role, "channel", t["channel"], True, "i"), None
    if t["channel"] is not None and t["part"] is not None:
        bind.err(role, "part", "an analog `channel` or a digital `part`, not both")
        return None, None
    if t["part"] is not None:
        for key in transfer:
            if t[key] is not None:
                bind.err(role, key, "belongs to an analog `channel`; this sensor is a digital `part`")
        part, why = find_part(getattr(bind.app, "sensors", ()) or (), t["part"], kinds)
        if part is None:
            bind.err(role, "part", why)
        return None, part
    if t["channel"] is None:
        bind.err(role, "", f"missing: channel (the analog input it drives, with {' and '.join(transfer)}) or part "
                 f"(a digital {role} of the project's sensor tables, \"{kinds[0]}@...\")")
        return None, None
    for key in transfer:
        if t[key] is None and bind.good(role, key):
            bind.err(role, key, f"missing (with channel: {_transfer_doc(role, key)})")
    return bind.channel(role, "channel", t["channel"], True, "i"), None


def _transfer_doc(role: str, key: str) -> str:
    return ROCKET_SCHEMA[role].fields[key].doc.removeprefix("with channel: ")


def _axis(bind: _Binder, t: dict, part) -> tuple[str, float]:
    """[accelerometer] axis: (x|y|z, +1 or -1); "z" by default."""
    axis = t["axis"]
    if axis is None:
        return "z", 1.0
    if part is None and t["channel"] is not None and bind.good("accelerometer", "part"):
        bind.err("accelerometer", "axis", "belongs to a digital `part`; an analog accelerometer has one axis")
    a = axis.strip().lower()
    sign = -1.0 if a.startswith("-") else 1.0
    a = a.lstrip("+-")
    if a not in AXES:
        bind.err("accelerometer", "axis", f"\"{axis}\": one of x, y, z (\"-z\": the axis points down)")
        return "z", 1.0
    return a, sign


def _output(part, quantity: str) -> str | None:
    """The element a part's quantity goes to (`z=accel` or `-z=accel`), or None."""
    if part is None:
        return None
    for q, el in part.outputs:
        if q.lstrip("-") == quantity:
            return el.name
    return None


def load(kind: str, path: str, app, layout, seed: int, fault: str | None):
    """The scenario of a parameters file, checked against the project:
    every error of the file in one ParamsError. A value the schema refuses
    is reported and skips only the checks that need it; the names and pins
    of the rest are still checked against the project."""
    if kind not in SCHEMAS:
        raise ValueError(kind)
    values, where, errors, bad = load_all(path, SCHEMAS[kind])
    plant = values[""]["plant"]
    if plant is not None and plant != kind:  # the file's names and pins are another plant's: not checked
        raise ParamsError([error_at(path, where, "", "plant", f"this file describes a `{plant}` plant, not a "
                                    f"`{kind}`")] + errors)
    rate = values[""]["rate_hz"]
    bind = _Binder(path, where, app, layout, bad)
    if rate is not None and app.board.f_cpu % rate:
        bind.err("", "rate_hz", f"{rate} Hz does not divide the {app.board.name}'s clock ({app.board.f_cpu} Hz): "
                 "every plant step must end on a whole CPU cycle")
    cls = RocketScenario if kind == "rocket" else TankScenario
    sc = cls(values, bind, seed, fault)
    if errors or bind.errors:
        raise ParamsError(errors + bind.errors)
    sc.app = app  # its [budget] is checked after the run
    return sc


def _time_unit_s(app) -> float:
    return 1e-3 if app.time_unit == "ms" else 1e-6


# ---- the rocket -----------------------------------------------------------------------------

_NO_CURVE = ((0.0, 0.0), (1.0, 100.0), (1.1, 0.0))  # _motor's curve after an error: no check is made of it


# The plant steps a motor's burn lasts at the least: the plant samples the thrust at each step's ends and
# middle (fswkit.plant.rocket, RK4), and a burn within a step or two is not the curve's impulse (all of it
# missed, the vehicle left on the pad).
MIN_BURN_STEPS = 10


def _burn_s(curve) -> float:
    """How long a thrust curve's thrust lasts: from the last point without
    thrust before its first with (the first point, when it has thrust) to
    the point after its last with (the curve's end)."""
    thrust = [i for i, (_, f) in enumerate(curve) if f > 0]
    if not thrust:
        return 0.0
    first, last = thrust[0], thrust[-1]
    return curve[min(last + 1, len(curve) - 1)][0] - curve[max(first - 1, 0)][0]


def _motor(bind: _Binder, mot: dict) -> tuple[tuple, float]:
    """[motor]'s thrust curve and propellant mass: written in the table, or
    from the RASP file it names (fswkit.plant.motor). A propellant mass
    written here is held to the curve's impulse as a motor file's is (a
    specific impulse of a rocket motor: fswkit.plant.motor.impulse_problem);
    0 is a motor whose mass does not change."""
    import os

    from .motor import EngError, _clip, impulse_problem
    from .motor import load as load_eng

    fallback = (_NO_CURVE, mot["propellant_kg"] or 0.0)  # after an error
    if not bind.good("motor", "file", "name", "thrust_curve"):  # which motor it is depends on the value refused
        return fallback
    if mot["file"] is not None and mot["thrust_curve"] is not None:
        bind.err("motor", "file", "a motor file or a thrust_curve, not both")
        return fallback
    if mot["file"] is None:
        if mot["name"] is not None:
            bind.err("motor", "name", "names a motor of the motor file (`file`), and there is none")
            return fallback
        if mot["thrust_curve"] is None:
            bind.err("motor", "", "missing: a thrust_curve, or a RASP motor file (file = \"motors/G80T.eng\")")
            return fallback
        if mot["propellant_kg"] is None:
            if not bind.good("motor", "propellant_kg"):
                return fallback
            bind.err("motor", "", "propellant_kg: missing (a thrust_curve written here needs its propellant mass)")
            return fallback
        curve = mot["thrust_curve"]
    else:
        from .params import key_file

        path = os.path.join(os.path.dirname(key_file(bind.path, bind.where, "motor", "file")), mot["file"])
        try:
            motors = load_eng(path)
        except EngError as e:
            bind.err("motor", "file", f"the motor file {path} cannot be flown:")
            bind.errors += e.errors
            return fallback
        eng = _named_motor(bind, path, motors, mot["name"])
        if eng is None:
            return fallback
        if mot["propellant_kg"] is None:
            if not bind.good("motor", "propellant_kg"):
                return fallback
            return eng.curve(), eng.propellant_kg  # held to the curve when the file was read
        if mot["propellant_kg"] > eng.total_kg:
            bind.err("motor", "propellant_kg", f"{mot['propellant_kg']:g} kg of propellant weighs more than the whole "
                     f"motor {_clip(eng.name)} ({eng.path}:{eng.line}: {eng.total_kg:g} kg)")
        curve = eng.curve()
    impulse = Motor(curve).total
    if mot["propellant_kg"] > 0:
        problem = impulse_problem(impulse, mot["propellant_kg"])
        if problem:
            bind.err("motor", "propellant_kg", problem)
    return curve, mot["propellant_kg"]


def _named_motor(bind: _Binder, path: str, motors: list, name: str | None):
    """The motor of a motor file that [motor] `name` names, or its only one;
    None after a located error (several and no name, a name the file does
    not hold, or holds more than once)."""
    from .motor import _clip

    names = list(dict.fromkeys(_clip(m.name) for m in motors))
    if name is None:
        if len(motors) == 1:
            return motors[0]
        listed = ", ".join(f"{_clip(m.name)} at line {m.line}" for m in motors[:8]) + (", ..." if len(motors) > 8
                                                                                          else "")
        bind.err("motor", "file", f"{path} holds {len(motors)} motors ({listed}): name the one to fly, "
                 f"[motor] name = \"{_clip(motors[0].name)}\"")
        return None
    same = [m for m in motors if m.name == name]
    if not same:
        listed = ", ".join(names[:20]) + (", ..." if len(names) > 20 else "")
        bind.err("motor", "name", f"{path} holds no motor named {_clip(name)} (it holds {listed})")
        return None
    if len(same) > 1:
        lines = ", ".join(str(m.line) for m in same[:-1]) + f" and {same[-1].line}"
        bind.err("motor", "name", f"{path} holds {len(same)} motors named {_clip(name)} (at lines {lines}): keep "
                 "the one to fly")
        return None
    return same[0]


class RocketScenario:
    kind = "rocket"
    columns = ("time_s", "altitude_m", "velocity_m_s", "accel_m_s2", "specific_force_g", "pressure_pa",
               "mass_kg", "thrust_n", "cd_area_m2", "drogue_inflation", "main_inflation",
               "pin_arm", "pin_drogue", "pin_main", "baro_v", "accel_v")

    def __init__(self, p: dict, bind: _Binder, seed: int, fault: str | None):
        self.p, self.seed, self.fault = p, seed, fault
        self.rate = p[""]["rate_hz"]
        fw, sc, pins = p["firmware"], p["scenario"], p["pins"]
        self.state_element = fw["state_element"]
        self.altitude_element = fw["altitude_element"]
        m = bind.machine_with_state(fw)
        bind.streamed("altitude_element", fw["altitude_element"])
        for key in ("armed_state", "apogee_state", "landed_state"):
            bind.state(m, key, fw[key])
        for name in fw["pad_states"] or ():
            bind.state(m, "pad_states", name)
        for name in p["checks"]["sequence"] or ():
            bind.state(m, "sequence", name, table="checks")
        _bind_reset(self, bind, m, sc)
        self.main_alt = bind.local(m, "main_altitude", fw["main_altitude"])
        backup = bind.local(m, "apogee_backup", fw["apogee_backup"])
        self.backup_s = None if backup is None else backup * _time_unit_s(bind.app)
        baro, self.baro_part = _sensor(bind, p["barometer"], "barometer", ("pa_per_volt", "pa_at_0v"), BAROMETERS)
        accel, self.accel_part = _sensor(bind, p["accelerometer"], "accelerometer", ("volts_per_g", "zero_g_volts"),
                                         ACCELEROMETERS)
        self.accel_axis = _axis(bind, p["accelerometer"], self.accel_part)
        self.accel_element = accel.element.name if accel is not None else _output(self.accel_part,
                                                                                  self.accel_axis[0])
        self.baro_element = baro.element.name if baro is not None else _output(self.baro_part, "pressure")
        self._part_faults(bind, fault, sc)
        if baro is not None and accel is not None and baro.pin_number == accel.pin_number:
            bind.err("accelerometer", "channel", "the barometer and the accelerometer must drive two different "
                     f"analog inputs (both name pin {baro.pin})")
        bind.channel("pins", "arm", pins["arm"], False, "i")
        bind.channel("pins", "drogue", pins["drogue"], False, "o")
        bind.channel("pins", "main", pins["main"], False, "o")
        if None not in (pins["arm"], pins["drogue"], pins["main"]) \
                and len({pins["arm"], pins["drogue"], pins["main"]}) < 3:
            bind.err("pins", "main", "the arm, drogue and main pins must be three different pins")
        self.vref = float(bind.app.board.adc_vref)
        veh, mot = p["vehicle"], p["motor"]
        baro_rng, accel_rng, motor_rng = (np.random.Generator(np.random.PCG64(s))
                                          for s in np.random.SeedSequence(seed).spawn(3))
        curve, propellant = _motor(bind, mot)
        nominal = Motor(curve)
        liftoff_weight = None if veh["dry_mass_kg"] is None else (veh["dry_mass_kg"] + propellant) * G0
        if curve is not _NO_CURVE and liftoff_weight is not None and nominal.peak <= liftoff_weight:
            bind.err("motor", "file" if mot["file"] else "thrust_curve", f"the peak thrust ({nominal.peak:g} N) never exceeds the "
                     f"vehicle's weight ({liftoff_weight:.1f} N): it would never leave the pad")
        burn = _burn_s(curve)
        if curve is not _NO_CURVE and self.rate is not None and burn * self.rate < MIN_BURN_STEPS:
            bind.err("motor", "file" if mot["file"] else "thrust_curve", f"the motor burns {burn:g} s: under "
                     f"{MIN_BURN_STEPS} plant steps ({MIN_BURN_STEPS / self.rate:g} s at {self.rate} Hz), which "
                     "sample its thrust at their ends and middles, so it would not be flown as its curve says (a "
                     "rocket motor burns a tenth of a second and more: times in seconds?)")
        # this seed's motor: the nominal curve scaled (the clamp only matters for a draw beyond 2.5 sigma
        # with the largest impulse_sd allowed)
        self.motor_factor = max(0.5, 1.0 + (mot["impulse_sd"] or 0.0) * float(motor_rng.standard_normal()))
        self.nominal_impulse = nominal.total
        self.curve, self.propellant_kg = curve, propellant
        self.motor = Motor([(t, f * self.motor_factor) for t, f in curve])
        if curve is not _NO_CURVE and sc["ignition_s"] is not None and sc["max_s"] is not None \
                and sc["ignition_s"] + self.motor.burn_time >= sc["max_s"]:
            bind.err("scenario", "max_s", "the run must outlast the motor's burn")
        # a file with an error is never flown: its vehicle is not built from the values the schema refused
        self.rocket = None if bind.bad else Rocket(
            dry_mass=veh["dry_mass_kg"], propellant_mass=propellant, motor=self.motor,
            body_cd_area=veh["body_cd_area_m2"],
            drogue=Chute(p["drogue"]["cd_area_m2"], p["drogue"]["inflate_s"]),
            main=Chute(p["main"]["cd_area_m2"], p["main"]["inflate_s"]),
            pad_altitude=p["atmosphere"]["pad_altitude_m"])
        self.pins = {pins["drogue"]: "drogue", pins["main"]: "main"}
        self.outputs = tuple(self.pins)
        self.arm_pin = pins["arm"]
        self.pyros = {pins["drogue"]: Pyro((p["drogue"]["fire_ms"] or 0.0) / 1000),  # (or: refused, never flown)
                      pins["main"]: Pyro((p["main"]["fire_ms"] or 0.0) / 1000)}
        self.levels = {pin: False for pin in self.pins}
        self.igniters = self._igniters(bind, fault, (baro, accel))
        # each continuity input's volts in the truth rows, only when there are any (columns as before otherwise)
        self.columns = RocketScenario.columns + tuple(f"{role}_cont_v" for role in self.igniters)
        self.cont_v = {role: ig.volts(0.0) for role, ig in self.igniters.items()}
        self.baro_noise = Noise(baro_rng, p["barometer"]["noise_pa"])
        self.accel_noise = Noise(accel_rng, p["accelerometer"]["noise_g"])
        # the parts that have turned noisy (part_fail_plan's "noisy", set by the co-simulation when due), and
        # their noise's own generator, so that a noisy run's other draws are its nominal run's
        self.noisy_parts: set = set()
        self.noisy_noise = Noise(np.random.default_rng([seed, 0x4E4F4953]), 1.0)
        # the ADC channels by the names the I/O tables give them, whatever form plant.toml used
        # (None: that sensor is a digital part)
        self.channels = (baro.pin if baro is not None else p["barometer"]["channel"],
                         accel.pin if accel is not None else p["accelerometer"]["channel"])
        self.parts = tuple(x for x in (self.baro_part, self.accel_part) if x is not None)
        if self.baro_part is not None or self.accel_part is not None:  # what the parts were fed, physical units
            self.columns = tuple({"baro_v": "baro_pa" if self.baro_part is not None else "baro_v",
                                  "accel_v": "accel_g" if self.accel_part is not None else "accel_v"}.get(c, c)
                                 for c in self.columns)
        self.part_values: dict = {}  # part -> {quantity: value} of the last inputs(t)
        self.ignition_s = None if fault in PAD_FAULTS else sc["ignition_s"]
        self.max_s = sc["hold_s"] if self.ignition_s is None else sc["max_s"]
        self.frozen_baro: float | None = None
        self.dropout_held: dict = {}  # a dispersion's dropouts: part -> its values when the dropout started
        self.landed_seen: float | None = None
        self.t = 0.0
        self.baro_v = self.accel_v = 0.0
        self.arm = False

    def _igniters(self, bind: _Binder, fault: str | None, sensors) -> dict[str, Igniter]:
        """The igniters of the chutes whose table names a continuity input,
        by role; open-igniter breaks the drogue's (which must then have one)."""
        p = self.p
        used = {c.pin_number: f"[{t}] channel" for c, t in zip(sensors, ("barometer", "accelerometer"))
                if c is not None}
        out = {}
        for role in ("drogue", "main"):
            chute = p[role]
            pin = chute["continuity_channel"]
            if pin is None and not bind.good(role, "continuity_channel"):
                continue  # refused by the schema: said
            if pin is None:
                for key in ("intact_volts", "open_volts"):
                    if (role, key) in bind.where:
                        bind.err(role, key, "needs continuity_channel (the analog input the igniter drives)")
                if role == "drogue" and fault == "open-igniter":
                    bind.err(role, "continuity_channel", "missing: --fault open-igniter opens the drogue's igniter, "
                             "which the firmware can only see through a continuity input: name the analog input "
                             "that reads it (continuity_channel = \"A2\")")
                continue
            c = bind.channel(role, "continuity_channel", pin, True, "i")
            if c is None:
                continue
            if c.pin_number in used:
                bind.err(role, "continuity_channel", f"pin {pin} is already driven by {used[c.pin_number]}: each "
                         "sensor and igniter needs its own analog input")
                continue
            used[c.pin_number] = f"[{role}] continuity_channel"
            out[role] = Igniter(c.pin, self.pyros[p["pins"][role]], chute["intact_volts"], chute["open_volts"],
                                broken=role == "drogue" and fault == "open-igniter")
        return out

    # -- sensors --
    def _part_faults(self, bind: _Binder, fault: str | None, sc: dict) -> None:
        """`part_fail_plan`: [(simulated second, part, "nack" | "stuck")] from
        --fault (baro-nack@T ...; stuck-baro on a barometer part: stuck at
        ignition) and [scenario] part_fail; errors for faults of an analog
        sensor asked of a part and the reverse."""
        self.part_fail_plan: list = []
        try:
            name, at = (None, None) if fault is None else parse_fault(fault)
        except ValueError as e:
            raise ParamsError([str(e)]) from None
        parts = {"barometer": self.baro_part, "accelerometer": self.accel_part}
        if name in ("pinned-baro", "pinned-accel"):
            role = "barometer" if name == "pinned-baro" else "accelerometer"
            if parts[role] is not None:
                own = [k for k in PART_FAULTS if k.startswith(name.split("-")[1] + "-")]  # baro-nack, ...
                bind.err(role, "part", f"--fault {name} pins an analog sensor's output at full scale; this "
                         f"{role} is a digital part: its failures are {', '.join(own[:-1])} and {own[-1]}")
        if name in PART_FAULTS:
            role = "barometer" if name.startswith("baro") else "accelerometer"
            if parts[role] is None:
                if bind.good(role, "channel", "part"):  # (else whether it is analog depends on a refused value)
                    bind.err(role, "channel", f"--fault {fault} fails a digital part; this {role} is analog "
                             f"(set [{role}] part to one of the project's sensor tables' parts)")
            else:
                when = at if at is not None else sc["ignition_s"]
                if when is not None:
                    self.part_fail_plan.append((when, parts[role], name.split("-")[1]))
        if name == "stuck-baro" and self.baro_part is not None and sc["ignition_s"] is not None:
            self.part_fail_plan.append((sc["ignition_s"], self.baro_part, "stuck"))
        if sc["part_fail"] is not None:
            part, why = find_part(getattr(bind.app, "sensors", ()) or (), sc["part_fail"], SENSOR_KINDS)
            if part is None:
                bind.err("scenario", "part_fail", why)
            if sc["part_fail_s"] is None and bind.good("scenario", "part_fail_s"):
                bind.err("scenario", "part_fail_s", "missing: the simulated second the part fails at")
            if sc["part_fail_mode"] is None:
                pass  # refused by the schema
            elif sc["part_fail_mode"] not in ("nack", "stuck", "noisy"):
                bind.err("scenario", "part_fail_mode",
                         f"\"{sc['part_fail_mode']}\": one of \"nack\", \"stuck\", \"noisy\"")
            elif part is not None and sc["part_fail_s"] is not None:
                self.part_fail_plan.append((sc["part_fail_s"], part, sc["part_fail_mode"]))
        elif bind.good("scenario", "part_fail"):
            for key in ("part_fail_s", "part_fail_mode"):
                if ("scenario", key) in bind.where:
                    bind.err("scenario", key, "needs part_fail (the part that fails)")
        self.part_fail_plan.sort(key=lambda f: f[0])

    def inputs(self, t: float):
        pa = self.rocket.static_pressure() + self.baro_noise()
        g = self.rocket.specific_force() / G0 + self.accel_noise()
        noisy = self.noisy_parts  # (empty but for a `noisy` part failure: no part hashed then)
        if noisy and self.baro_part is not None and self.baro_part in noisy:
            pa += self.noisy_noise() * NOISY_PA
        if noisy and self.accel_part is not None and self.accel_part in noisy:
            g += self.noisy_noise() * NOISY_G
        self.part_values = {}
        if self.baro_part is not None:
            h = self.rocket.pad_altitude + self.rocket.h
            self.part_values[self.baro_part] = {"pressure": pa, "temperature": atmosphere.temperature(h) - 273.15}
            self.baro_v = pa
            baro = None
        else:
            b = self.p["barometer"]
            baro = (pa - b["pa_at_0v"]) / b["pa_per_volt"]
        if self.accel_part is not None:
            axis, sign = self.accel_axis
            self.part_values[self.accel_part] = {axis: sign * g}
            self.accel_v = g
            accel = None
        else:
            a = self.p["accelerometer"]
            accel = a["zero_g_volts"] + g * a["volts_per_g"]
        if self.fault == "pinned-baro":
            baro = self.vref
        elif self.fault == "pinned-accel":
            accel = self.vref
        elif (self.fault == "stuck-baro" and baro is not None and self.ignition_s is not None
              and t >= self.ignition_s):
            if self.frozen_baro is None:
                self.frozen_baro = baro
            baro = self.frozen_baro
        analog = {}
        if baro is not None:
            self.baro_v = analog[self.channels[0]] = min(max(baro, 0.0), self.vref)
        if accel is not None:
            self.accel_v = analog[self.channels[1]] = min(max(accel, 0.0), self.vref)
        self.arm = t >= self.p["scenario"]["arm_s"]
        for role, ig in self.igniters.items():
            v = self.cont_v[role] = min(max(ig.volts(t), 0.0), self.vref)
            analog[ig.channel] = v
        return analog, {self.arm_pin: self.arm}

    # -- time --
    def advance(self, t0: float, t1: float, edges) -> list[PinEvent]:
        r = self.rocket
        if self.ignition_s is not None and t1 > self.ignition_s:
            r.ignite(self.ignition_s)
        for te, pin, level in edges:
            if pin in self.pyros:
                self.levels[pin] = level
                self.pyros[pin].edge(te, level)
        for pin, pyro in self.pyros.items():
            fired = pyro.poll(t1)
            if fired is not None:
                r.deploy(self.pins[pin], fired)
        h0, v0 = r.h, r.v
        r.t = t0
        r.advance(t1 - t0)
        self.t = t1
        out = []
        for te, pin, level in edges:
            f = (te - t0) / (t1 - t0) if t1 > t0 else 1.0
            out.append(PinEvent(te, pin, self.pins.get(pin, str(pin)), level,
                                {"altitude": h0 + (r.h - h0) * f, "velocity": v0 + (r.v - v0) * f}))
        return out

    # -- speculative steps (fswkit.plant.cosim): what inputs() and advance() change --
    def save(self) -> tuple:
        return (self.rocket.save(), tuple((q.high_since, q.fired_at) for q in self.pyros.values()),
                dict(self.levels), dict(self.cont_v),
                self.baro_noise.save(), self.accel_noise.save(), self.noisy_noise.save(), set(self.noisy_parts),
                self.part_values, self.frozen_baro, self.landed_seen, self.t, self.baro_v, self.accel_v, self.arm,
                dict(self.dropout_held))

    def restore(self, saved: tuple) -> None:
        (rocket, pyros, levels, cont_v, baro_n, accel_n, noisy_n, noisy_parts, self.part_values, self.frozen_baro,
         self.landed_seen, self.t, self.baro_v, self.accel_v, self.arm, held) = saved
        self.rocket.restore(rocket)
        for q, (high_since, fired_at) in zip(self.pyros.values(), pyros):
            q.high_since, q.fired_at = high_since, fired_at
        self.levels, self.cont_v = dict(levels), dict(cont_v)
        self.baro_noise.restore(baro_n)
        self.accel_noise.restore(accel_n)
        self.noisy_noise.restore(noisy_n)
        self.noisy_parts = set(noisy_parts)
        self.dropout_held.clear()
        self.dropout_held.update(held)

    def record(self) -> tuple:
        r, t = self.rocket, self.t
        return (round(t, 6), r.h, r.v, r.a, r.specific_force() / G0, r.static_pressure(), r.mass(t), r.thrust(t),
                r.cd_area(t), r.inflation("drogue", t), r.inflation("main", t), int(self.arm),
                int(self.levels[self.p["pins"]["drogue"]]), int(self.levels[self.p["pins"]["main"]]),
                self.baro_v, self.accel_v) + tuple(self.cont_v.values())

    def done(self, t: float, state: str | None) -> bool:
        if state == self.p["firmware"]["landed_state"] and self.landed_seen is None and self.ignition_s is not None:
            self.landed_seen = t
        return self.would_end(t, state)

    def would_end(self, t: float, state: str | None) -> bool:
        """done(t, state) without its side effect: whether the run ends at
        `t` with telemetry showing `state`."""
        if t >= self.max_s:
            return True
        if self.ignition_s is None:
            return False
        if state == self.p["firmware"]["landed_state"]:
            seen = t if self.landed_seen is None else self.landed_seen
            return t >= seen + self.p["scenario"]["linger_s"]
        td = self.rocket.touchdown
        return td is not None and t >= td + self.p["scenario"]["landed_timeout_s"]


# ---- the tank --------------------------------------------------------------------------------

class TankScenario:
    kind = "tank"
    columns = ("time_s", "pressure_psi", "pressure_pa_abs", "gas_kg", "inflow_g_s", "outflow_g_s",
               "regulator_failed", "pin_valve", "valve_opening", "transducer_v")

    def __init__(self, p: dict, bind: _Binder, seed: int, fault: str | None):
        if fault is not None:
            raise ParamsError([f"--fault {fault} is a fault of the rocket plant; the tank's scenario has its "
                               "regulator failure built in"])
        self.p, self.seed, self.fault = p, seed, fault
        self.rate = p[""]["rate_hz"]
        fw, sc = p["firmware"], p["scenario"]
        self.state_element = fw["state_element"]
        self.pressure_element = fw["pressure_element"]
        m = bind.machine_with_state(fw)
        _bind_reset(self, bind, m, sc)
        bind.streamed("pressure_element", fw["pressure_element"])
        for key in ("control_state", "abort_state"):
            bind.state(m, key, fw[key])
        self.abort_psi = bind.local(m, "abort_limit", fw["abort_limit"])
        self.vent_psi = fw["vent_psi"]
        transducer = bind.channel("transducer", "channel", p["transducer"]["channel"], True, "i")
        bind.channel("pins", "valve", p["pins"]["valve"], False, "o")
        if sc["failure_s"] is not None and sc["max_s"] is not None and sc["failure_s"] >= sc["max_s"]:
            bind.err("scenario", "failure_s", "the regulator must fail before the run's end (max_s)")
        tk = p["tank"]
        # a file with an error is never flown: its tank is not built from the values the schema refused
        self.tank = None if bind.bad else Tank(volume=tk["volume_l"] / 1000, temperature=tk["temperature_k"],
                         gas_constant=tk["gas_constant_j_kg_k"], gamma=tk["gamma"],
                         initial_pa=tk["initial_psi"] * PSI + 101325.0,
                         vent_cd_area=p["vent"]["cd_area_mm2"] * 1e-6, valve_time=p["vent"]["response_ms"] / 1000)
        self.valve_pin = p["pins"]["valve"]
        self.outputs = (self.valve_pin,)
        self.vref = float(bind.app.board.adc_vref)
        (rng,) = (np.random.Generator(np.random.PCG64(s)) for s in np.random.SeedSequence(seed).spawn(1))
        self.noise = Noise(rng, p["transducer"]["noise_psi"])
        self.channel = transducer.pin if transducer is not None else p["transducer"]["channel"]
        self.max_s = sc["max_s"]
        self.valve = False
        self.abort_seen: float | None = None
        self.t = 0.0
        self.volts = 0.0

    def inputs(self, t: float):
        tr = self.p["transducer"]
        v = (self.tank.gauge_psi + self.noise() - tr["psi_at_0v"]) / tr["psi_per_volt"]
        self.volts = min(max(v, 0.0), self.vref)
        return {self.channel: self.volts}, {}

    def inflow(self, t: float) -> float:
        s = self.p["supply"]
        return (s["failed_flow_g_s"] if t >= self.p["scenario"]["failure_s"] else s["flow_g_s"]) / 1000

    def advance(self, t0: float, t1: float, edges) -> list[PinEvent]:
        tank = self.tank
        out = []
        at = t0
        for te, pin, level in edges:  # integrate up to each edge, then on with the new level
            if te > at:
                tank.advance(te - at, self.inflow(at), self.valve)
                at = te
            if pin == self.valve_pin:
                self.valve = level
            out.append(PinEvent(te, pin, "valve", level, {"pressure_psi": tank.gauge_psi}))
        if t1 > at:
            tank.advance(t1 - at, self.inflow(at), self.valve)
        self.t = t1
        return out

    # -- speculative steps (fswkit.plant.cosim): what inputs() and advance() change --
    def save(self) -> tuple:
        return self.tank.save(), self.noise.save(), self.valve, self.abort_seen, self.t, self.volts

    def restore(self, saved: tuple) -> None:
        tank, noise, self.valve, self.abort_seen, self.t, self.volts = saved
        self.tank.restore(tank)
        self.noise.restore(noise)

    def record(self) -> tuple:
        tk, t = self.tank, self.t
        return (round(t, 6), tk.gauge_psi, tk.pressure, tk.mass, tk.inflow * 1000, tk.outflow * 1000,
                int(t >= self.p["scenario"]["failure_s"]), int(self.valve), tk.valve, self.volts)

    def done(self, t: float, state: str | None) -> bool:
        if state == self.p["firmware"]["abort_state"] and self.abort_seen is None:
            self.abort_seen = t
        return self.would_end(t, state)

    def would_end(self, t: float, state: str | None) -> bool:
        """done(t, state) without its side effect."""
        if t >= self.max_s:
            return True
        if state == self.p["firmware"]["abort_state"]:
            seen = t if self.abort_seen is None else self.abort_seen
            return t >= seen + self.p["scenario"]["linger_s"]
        return False
