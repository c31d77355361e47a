"""What a closed-loop run found and what it writes: the checks (each PASS
or FAIL), the summary, the truth-and-telemetry CSV and the plot."""

from __future__ import annotations

import csv
import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from fswkit.link.session import reset_words

from .cosim import Run


@dataclass(frozen=True)
class Check:
    name: str
    passed: bool
    detail: str


@dataclass
class Report:
    lines: list[str]
    checks: list[Check]
    facts: dict = field(default_factory=dict)  # the numbers, for tools (bench_flights)

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def text(self) -> str:
        out = list(self.lines)
        out.append("checks:")
        out += [f"  {'PASS' if c.passed else 'FAIL'}  {c.name}: {c.detail}" for c in self.checks]
        n = sum(c.passed for c in self.checks)
        out.append(f"{n} of {len(self.checks)} checks passed")
        return "\n".join(out) + "\n"


def _rising(run: Run, role: str):
    return [e for e in run.pin_events if e.role == role and e.level]


def _column(run: Run, name: str) -> np.ndarray:
    i = run.columns.index(name)
    return np.array([r[i] for r in run.rows], dtype=float)


def _telemetry(run: Run, name: str) -> tuple[np.ndarray, np.ndarray]:
    pts = [(t, float(row[name])) for t, row in run.samples if name in row]
    if not pts:
        return np.zeros(0), np.zeros(0)
    a = np.array(pts, dtype=float)
    return a[:, 0], a[:, 1]


def _interp(run: Run, name: str, t: float) -> float:
    return float(np.interp(t, _column(run, "time_s"), _column(run, name)))


def _run_lines(run: Run, sc, what: str) -> list[str]:
    fault = f"fault {sc.fault}" if sc.fault else "no fault"
    if not sc.fault and getattr(sc, "part_fail_plan", None):  # plant.toml's [scenario] part_fail
        from fswkit.sim.sensors import part_name

        fault = ", ".join(f"part {part_name(part)} {mode} at {t:g} s" for t, part, mode in sc.part_fail_plan)
    speed = run.sim_s / run.wall_s if run.wall_s else float("inf")
    return [f"{what}: seed {sc.seed}, {fault}; {run.sim_s:.3f} s simulated in {run.wall_s:.1f} s wall "
            f"({run.steps:,} plant steps at {sc.rate} Hz, {run.round_trips:,} round trips, {speed:.2f}× real time)"]


def _tail_lines(run: Run) -> list[str]:
    out = []
    for ev in run.reset_events:
        why = "reset_at" if ev.trigger == "time" else "reset_state"
        out.append(f"reset: {ev.cause} at {ev.t:.3f} s ({why}; telemetry showed state {ev.state or 'none yet'})")
    s = run.session
    if s.hello is not None and run.reset_events:
        out.append(f"target after the reset: {reset_words(s.hello['reset_cause'])} (its last hello)")
    st, ws = s.stats, s.deframer.stats
    h = s.health or {}
    out.append(f"link: {st.frames:,} frames, {st.samples:,} samples, {st.lost} lost, {ws.crc_errors} CRC errors, "
               f"{ws.framing_errors} framing errors; target dropped {h.get('dropped', '?')}, "
               f"late cycles {h.get('late', '?')}")
    for p in h.get("pyro", ()):  # what the last health frame said of each charge
        out.append(f"pyro {p['name']} (last health frame): {p['words']}")
    for t, name, mode in getattr(run, "part_failures", ()):  # what the plant did to a digital part
        what = {"nack": "stops answering (nack)", "stuck": "results stuck",
                "noisy": "results noisy (the plant adds its NOISY_PA / NOISY_G)"}.get(mode, mode)
        out.append(f"sensor {name}: failed at {t:.3f} s simulated: {what}")
    for p in h.get("sensors", ()):  # what the last health frame said of each digital part, and the others
        line = f"sensor {p['name']} (last health frame): {p['words']}"
        frames, faulty, first = run.part_health.get(p["name"], (0, 0, None))
        if faulty:
            line += f"; a fault in {faulty} of {frames} health frames, the first arriving at {first:.3f} s"
        out.append(line)
    if h.get("tasks"):
        worst = max(h["tasks"], key=lambda x: x["worst_us"])
        out.append(f"executor: overruns {sum(x['overruns'] for x in h['tasks'])}, "
                   f"worst task step {worst['worst_us']} µs ({worst['name']})")
    if run.ram:
        out.append("RAM (measured on the board): " + "; ".join(_ram(v) for v in run.ram.values()))
    else:
        out.append("RAM: not measured (this SimBoard has no RAM probe)")
    return out


def _baro_lost(sc, run: Run) -> bool:
    """Whether the barometer part failed (nack, stuck or noisy) before the true
    apogee: the flight is then checked as with a stuck barometer (the drogue
    by the backup timer)."""
    part = getattr(sc, "baro_part", None)
    if part is None:
        return False
    from fswkit.sim.sensors import part_name

    apogee = sc.rocket.apogee_t
    return any(name == part_name(part) and (apogee is None or t <= apogee)
               for t, name, _mode in getattr(run, "part_failures", ()))


def _ram(v) -> str:
    """A RAM probe's answer: bytes, or a record of them (static, stack, ...)."""
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, int):
        return f"{v:,} B"
    if dataclasses.is_dataclass(v):
        v = dataclasses.asdict(v)
    if isinstance(v, dict):
        return ", ".join(f"{k} {_ram(x)}" for k, x in v.items())
    return str(v)


def _transition_lines(run: Run, alt_name: str | None, truth: str, unit: str) -> list[str]:
    out = ["transitions (telemetry):"]
    tt, tv = _telemetry(run, alt_name) if alt_name else (np.zeros(0), np.zeros(0))
    for t, _sid, name in run.transitions:
        true = _interp(run, truth, t)
        est = ""
        if len(tt):
            i = np.searchsorted(tt, t, side="right") - 1
            if i >= 0:
                est = f", telemetry {tv[i]:.1f} {unit}"
        out.append(f"  {t:8.3f} s  {name:<16} true {true:7.1f} {unit}{est}")
    return out


# ---- the rocket ----------------------------------------------------------------------------

def rocket(run: Run, sc) -> Report:
    r = sc.rocket
    p = sc.p
    fw, ck = p["firmware"], p["checks"]
    lines = _run_lines(run, sc, "flight")
    facts: dict = {"seed": sc.seed, "fault": sc.fault, "sim_s": run.sim_s, "wall_s": run.wall_s}
    checks: list[Check] = []
    names = [n for _, _, n in run.transitions]
    drogue = _rising(run, "drogue")
    main = _rising(run, "main")
    t_alt, v_alt = _telemetry(run, sc.altitude_element)
    lines.append(f"motor: {sc.motor.total:.1f} N·s ({100 * (sc.motor_factor - 1):+.1f} % from the nominal "
                 f"{sc.nominal_impulse:.1f} N·s)" + ("" if sc.ignition_s is not None else ", never lit"))
    if r.liftoff is not None:
        lines.append(f"liftoff: {r.liftoff:.3f} s (ignition {sc.ignition_s:.3f} s)")
    if r.apogee_t is not None:
        lines.append(f"apogee, true: {r.apogee_h:.1f} m at {r.apogee_t:.3f} s")
    facts.update(true_apogee_m=r.apogee_h if r.apogee_t is not None else None, true_apogee_s=r.apogee_t)
    detect_t = drogue[0].t if drogue else next((t for t, _, n in run.transitions if n == fw["apogee_state"]), None)
    if detect_t is not None and r.apogee_t is not None:
        before = v_alt[t_alt <= detect_t]
        det_h = float(before.max()) if len(before) else float("nan")
        lines.append(f"apogee, detected: {det_h:.1f} m (highest telemetered altitude) at {detect_t:.3f} s "
                     f"({'drogue pin' if drogue else 'state ' + fw['apogee_state']}): "
                     f"error {det_h - r.apogee_h:+.1f} m, "
                     f"{detect_t - r.apogee_t:+.3f} s")
        facts.update(detected_apogee_m=det_h, detected_apogee_s=detect_t, apogee_error_m=det_h - r.apogee_h,
                     apogee_error_s=detect_t - r.apogee_t)
    lines += _transition_lines(run, sc.altitude_element, "altitude_m", "m")
    lines.append("pyro channels (pin edges, exact; true altitude at the edge):")
    if not drogue and not main:
        lines.append("  none fired")
    for role, evs in (("drogue", drogue), ("main", main)):
        for e in evs:
            fired = r.deployed.get(role)
            extra = f", charge fired {fired:.3f} s" if fired is not None and fired >= e.t else ""
            below = f", {r.apogee_h - e.truth['altitude']:.1f} m below apogee" if role == "drogue" else \
                f", configured {sc.main_alt:g} m: {e.truth['altitude'] - sc.main_alt:+.1f} m" \
                if sc.main_alt is not None else ""
            lines.append(f"  {role:<6} {e.t:8.3f} s at {e.truth['altitude']:.1f} m, {e.truth['velocity']:+.1f} m/s"
                         f"{below}{extra}")
    if drogue:
        facts.update(drogue_alt_m=drogue[0].truth["altitude"], drogue_drop_m=r.apogee_h - drogue[0].truth["altitude"])
    if main:
        facts.update(main_alt_m=main[0].truth["altitude"], main_config_m=sc.main_alt)
    # accelerations and descent
    t = _column(run, "time_s")
    sf = _column(run, "specific_force_g")
    vel = _column(run, "velocity_m_s")
    if r.ignition is not None:
        boost = (t >= r.ignition) & (t <= r.ignition + sc.motor.burn_time)
        _, va = _telemetry(run, sc.accel_element) if sc.accel_element else (None, np.zeros(0))
        tel = f", telemetry {va.max():.1f} g" if len(va) else ""
        lines.append(f"peak acceleration: {sf[boost].max():.1f} g in boost (true){tel}; "
                     f"{sf.max():.1f} g over the flight (chute openings)")
        facts["peak_g"] = float(sf[boost].max())
    descents = []
    if r.deployed.get("drogue") is not None:
        start = r.deployed["drogue"] + p["drogue"]["inflate_s"] + 1.0
        end = main[0].t - 0.1 if main else (r.touchdown or t[-1]) - 0.1
        descents.append(("drogue", start, end))
    if r.deployed.get("main") is not None:
        start = r.deployed["main"] + p["main"]["inflate_s"] + 2.0
        end = (r.touchdown if r.touchdown is not None else t[-1]) - 0.2
        descents.append(("main", start, end))
    for name, a, b in descents:
        w = (t >= a) & (t <= b)
        tw = (t_alt >= a) & (t_alt <= b)
        if w.sum() < 2:
            continue
        true_rate = -float(vel[w].mean())
        est = ""
        if tw.sum() >= 3:
            est = f", telemetry {-np.polyfit(t_alt[tw], v_alt[tw], 1)[0]:.1f} m/s"
        lines.append(f"descent under the {name}: {true_rate:.1f} m/s (true, {a:.1f}–{b:.1f} s){est}")
        facts[f"{name}_descent_m_s"] = true_rate
    if r.touchdown is not None:
        lines.append(f"touchdown: {r.touchdown:.3f} s")
    lines += _tail_lines(run)

    landed = fw["landed_state"] in names
    facts["landed"] = landed
    if sc.fault in ("pinned-accel", "pinned-baro", "open-igniter"):
        fired = [e for e in run.pin_events if e.level]
        checks.append(Check("no pyro channel fired", not fired,
                            "none" if not fired else ", ".join(f"{e.role} at {e.t:.3f} s" for e in fired)))
        off = [n for n in names if n not in fw["pad_states"]]
        checks.append(Check(f"the vehicle stayed in its pad states ({', '.join(fw['pad_states'])})", not off,
                            f"states seen: {', '.join(dict.fromkeys(names)) or 'none'}"))
        armed = fw["armed_state"] in names
        when = next((f"at {t:.3f} s" for t, _, n in run.transitions if n == fw["armed_state"]), "never")
        if sc.fault == "open-igniter":  # the key is on, but an open igniter must keep the vehicle from arming
            checks.append(Check(f"the vehicle refused to arm with the drogue's igniter open (never in state "
                                f"{fw['armed_state']})", not armed, f"armed {when}" if armed else "never armed"))
        else:
            checks.append(Check(f"the vehicle was armed (state {fw['armed_state']})", armed, when))
    elif sc.fault == "stuck-baro" or _baro_lost(sc, run):
        if not drogue or r.liftoff is None or sc.backup_s is None:
            checks.append(Check("drogue fired by the backup timer", False,
                                "the drogue never fired" if not drogue else "no liftoff"))
        else:
            after = drogue[0].t - r.liftoff
            tol = ck["backup_tolerance_s"]
            ok = sc.backup_s <= after <= sc.backup_s + tol
            checks.append(Check(f"drogue fired by the backup timer ({fw['apogee_backup']} = {sc.backup_s:g} s "
                                f"after launch, within {tol:g} s)", ok,
                                f"drogue pin {after:.3f} s after liftoff, at {drogue[0].truth['altitude']:.1f} m"))
        early = [e for e in run.pin_events if e.level and (r.liftoff is None or e.t < r.liftoff)]
        checks.append(Check("no pyro channel fired on the pad", not early,
                            "none" if not early else ", ".join(f"{e.role} at {e.t:.3f} s" for e in early)))
    else:
        if r.apogee_t is None:
            checks.append(Check("apogee detected", False, "the vehicle never left the pad"))
        elif detect_t is None:
            checks.append(Check("apogee detected", False, "the drogue never fired and the apogee state never came"))
        else:
            dt = detect_t - r.apogee_t
            win = ck["apogee_window_s"]
            checks.append(Check(f"apogee detected within {win:g} s after the true apogee, not before", 0 <= dt <= win,
                                f"{'drogue pin' if drogue else fw['apogee_state']} at {detect_t:.3f} s, "
                                f"{dt:+.3f} s from the true apogee at {r.apogee_t:.3f} s"))
        if drogue and r.apogee_t is not None:
            drop = r.apogee_h - drogue[0].truth["altitude"]
            lim = ck["drogue_max_drop_m"]
            checks.append(Check(f"drogue fired before falling {lim:g} m below apogee", drop <= lim,
                                f"{drop:.1f} m below apogee ({drogue[0].truth['altitude']:.1f} m)"))
        else:
            checks.append(Check(f"drogue fired before falling {ck['drogue_max_drop_m']:g} m below apogee", False,
                                "the drogue never fired"))
        if main and sc.main_alt is not None:
            err = main[0].truth["altitude"] - sc.main_alt
            tol = ck["main_tolerance_m"]
            checks.append(Check(f"main fired within ±{tol:g} m of {fw['main_altitude']} = {sc.main_alt:g} m",
                                abs(err) <= tol, f"at {main[0].truth['altitude']:.1f} m ({err:+.1f} m)"))
        else:
            checks.append(Check(f"main fired within ±{ck['main_tolerance_m']:g} m of {fw['main_altitude']}", False,
                                "the main never fired"))
        checks.append(Check(f"landing detected (state {fw['landed_state']})", landed,
                            next((f"at {t:.3f} s" + (f", {t - r.touchdown:.2f} s after touchdown"
                                                     if r.touchdown is not None else "")
                                  for t, _, n in run.transitions if n == fw["landed_state"]), "never")))
        checks.append(Check("the states came in the nominal order", names == list(ck["sequence"]),
                            " → ".join(names) if names else "no telemetry"))
    facts["passed"] = all(c.passed for c in checks)
    return Report(lines, checks, facts)


# ---- the tank ------------------------------------------------------------------------------

def tank(run: Run, sc) -> Report:
    p = sc.p
    fw, ck = p["firmware"], p["checks"]
    lines = _run_lines(run, sc, "tank run")
    t = _column(run, "time_s")
    psi = _column(run, "pressure_psi")
    tr = p["transducer"]
    lsb = tr["psi_per_volt"] * sc.vref / 1023  # one ADC count
    margin = 4 * tr["noise_psi"] + lsb
    fail = p["scenario"]["failure_s"]
    opens = _rising(run, "valve")
    closes = [e for e in run.pin_events if e.role == "valve" and not e.level]
    before = t < fail
    lines.append(f"start {p['tank']['initial_psi']:g} psi; vent above {sc.vent_psi:g} psi, abort above "
                 f"{fw['abort_limit']} = {sc.abort_psi:g} psi; noise {tr['noise_psi']:g} psi, ADC count "
                 f"{lsb:.2f} psi (margin {margin:.1f} psi)")
    first_open = opens[0] if opens else None
    regulating = before & (t >= (first_open.t if first_open else fail))
    if regulating.any():
        lines.append(f"regulation ({first_open.t:.2f}–{fail:.2f} s): {psi[regulating].min():.1f}–"
                     f"{psi[regulating].max():.1f} psi true, valve opened {sum(e.t < fail for e in opens)} times, "
                     f"open {100 * _column(run, 'pin_valve')[regulating].mean():.0f} % of the time")
    lines.append(f"regulator fails open at {fail:.2f} s: inflow {p['supply']['flow_g_s']:g} → "
                 f"{p['supply']['failed_flow_g_s']:g} g/s; peak {psi.max():.1f} psi at {t[psi.argmax()]:.2f} s")
    lines += _transition_lines(run, sc.pressure_element, "pressure_psi", "psi")
    lines += _tail_lines(run)

    checks = []
    cross = t[psi > sc.vent_psi + margin]
    if first_open is None:
        checks.append(Check(f"the valve opens above {sc.vent_psi:g} psi", False, "the valve never opened"))
    else:
        low = [e for e in opens if e.truth["pressure_psi"] < sc.vent_psi - margin]
        late = cross.size and first_open.t > cross[0] + ck["open_within_s"]
        checks.append(Check(f"the valve opens above {sc.vent_psi:g} psi (within {ck['open_within_s']:g} s)",
                            not low and not late,
                            f"first at {first_open.t:.3f} s at {first_open.truth['pressure_psi']:.1f} psi true"
                            + (f"; {len(low)} openings below {sc.vent_psi - margin:.1f} psi" if low else "")
                            + (f"; {first_open.t - cross[0]:.3f} s after {sc.vent_psi + margin:.1f} psi" if late
                               else "")))
    n_before = sum(e.t < fail for e in opens)
    early_abort = [x for x in run.transitions if x[2] == fw["abort_state"] and x[0] < fail]
    checks.append(Check(f"regulation before the failure (valve cycles ≥ {ck['min_cycles']}, below "
                        f"{sc.abort_psi:g} psi, state {fw['control_state']})",
                        n_before >= ck["min_cycles"] and psi[before].max() < sc.abort_psi and not early_abort,
                        f"{n_before} openings, {len([e for e in closes if e.t < fail])} closings, "
                        f"peak {psi[before].max():.1f} psi"))
    aborts = [x for x in run.transitions if x[2] == fw["abort_state"]]
    over = t[psi > sc.abort_psi + margin]
    near = t[psi > sc.abort_psi - margin]
    if not aborts:
        checks.append(Check(f"abort on over-pressure within {ck['abort_within_s']:g} s", False,
                            "the abort state never came" + (f"; over {sc.abort_psi + margin:.0f} psi from "
                                                            f"{over[0]:.3f} s" if over.size else "")))
    else:
        ta = aborts[0][0]
        ok = over.size > 0 and near[0] <= ta <= over[0] + ck["abort_within_s"]
        checks.append(Check(f"abort on over-pressure within {ck['abort_within_s']:g} s", ok,
                            f"state {fw['abort_state']} at {ta:.3f} s at {_interp(run, 'pressure_psi', ta):.1f} psi "
                            f"true" + (f", {ta - over[0]:+.3f} s from {sc.abort_psi + margin:.1f} psi" if over.size
                                       else "")))
    checks.append(Check("the valve is left open after the abort", bool(aborts) and sc.valve,
                        "open" if sc.valve else "closed"))
    facts = {"seed": sc.seed, "sim_s": run.sim_s, "wall_s": run.wall_s, "passed": all(c.passed for c in checks)}
    return Report(lines, checks, facts)


# ---- files ------------------------------------------------------------------------------------

def write_csv(run: Run, layout, state_element: str, path: str) -> int:
    """Truth rows and, beside each, the telemetry as of that instant (the
    latest sample taken at or before it); returns the number of rows."""
    streamed = [n for s in layout.streams for n in s.region.names]
    names = list(dict.fromkeys(streamed))
    states = layout.states.get(state_element, {})
    samples = sorted(run.samples, key=lambda s: s[0])
    known: dict = {}
    last_t = None
    j = 0
    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(list(run.columns) + ["tm_time_s", "tm_state_name"] + [f"tm_{n}" for n in names])
        for row in run.rows:
            while j < len(samples) and samples[j][0] <= row[0] + 1e-9:
                last_t = samples[j][0]
                known.update(samples[j][1])
                j += 1
            st = known.get(state_element)
            w.writerow([_cell(x) for x in row] + [_cell(last_t), states.get(int(st), "") if st is not None else ""]
                       + [_cell(known.get(n)) for n in names])
    return len(run.rows)


def _cell(v) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return f"{v:.6g}" if math.isfinite(v) else str(v)
    return str(v)


DIGEST_KEY = "fswkit-flight-csv-sha256"  # a PNG text chunk: the data the plot shows


def plot(run: Run, sc, path: str, title: str, csv_digest: str | None = None) -> None:
    """The PNG; `csv_digest`, the SHA-256 of the flight's CSV, goes into a
    text chunk, so a copy of the plot can be told current or stale."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = _column(run, "time_s")
    if sc.kind == "rocket":
        panels = [("altitude above the pad (m)", [(t, _column(run, "altitude_m"), "true", "-")]
                   + [(*_telemetry(run, sc.altitude_element), "telemetry", "-")]),
                  ("velocity (m/s)", [(t, _column(run, "velocity_m_s"), "true", "-")])]
        pins = ("drogue", "main")
    else:
        panels = [("pressure (psi)", [(t, _column(run, "pressure_psi"), "true", "-")]
                   + [(*_telemetry(run, sc.pressure_element), "telemetry", "-")]),
                  ("valve", [(t, _column(run, "pin_valve"), "pin (command)", "-"),
                             (t, _column(run, "valve_opening"), "opening", "-")])]
        pins = ()
    fig, axes = plt.subplots(len(panels), 1, sharex=True, figsize=(11, 7), squeeze=False)
    for ax, (label, series) in zip(axes[:, 0], panels):
        for x, y, name, style in series:
            if len(x):
                ax.plot(x, y, style, label=name, linewidth=1.0 if name != "telemetry" else 0.8)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="center right", fontsize=8)
        for tt, _sid, name in run.transitions:
            ax.axvline(tt, color="tab:red", linestyle="--", linewidth=0.7)
        for e in run.pin_events:
            if e.level and e.role in pins:
                ax.axvline(e.t, color="tab:purple", linestyle=":", linewidth=1.0)
    if sc.kind == "tank":
        ax = axes[0, 0]
        ax.axhline(sc.vent_psi, color="grey", linewidth=0.6)
        if sc.abort_psi is not None:
            ax.axhline(sc.abort_psi, color="grey", linewidth=0.6, linestyle="--")
    top = axes[0, 0]
    for tt, _sid, name in run.transitions:
        top.annotate(name, (tt, 0.98), xycoords=("data", "axes fraction"), rotation=90, fontsize=7, va="top",
                     ha="right", color="tab:red")
    for e in run.pin_events:
        if e.level and e.role in pins:
            axes[-1, 0].annotate(f"{e.role} pin", (e.t, 0.02), xycoords=("data", "axes fraction"), rotation=90,
                                 fontsize=7, va="bottom", ha="left", color="tab:purple")
    axes[-1, 0].set_xlabel("simulated time (s)")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110, metadata={DIGEST_KEY: csv_digest} if csv_digest else None)
    plt.close(fig)


def png_text(path: str) -> dict[str, str]:
    """The tEXt chunks of a PNG file."""
    import struct

    out = {}
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG file")
    i = 8
    while i + 8 <= len(data):
        n, kind = struct.unpack(">I4s", data[i:i + 8])
        if kind == b"tEXt":
            key, _, value = data[i + 8:i + 8 + n].partition(b"\0")
            out[key.decode("latin-1")] = value.decode("latin-1")
        i += 12 + n
    return out
