"""What a simulated flight's recorder kept (docs/recorder.md): the record is
read from the board's store after the flight, decoded as `fsw dump`
decodes it, and compared with the telemetry of the same run (value for
value where both have a sample) and with the plant's truth."""

from __future__ import annotations

import numpy as np

from fswkit.autocode.recorder import Flight, RecordError, decode, plan


def newest_flight(app, run):
    """(plan, the newest flight, every flight, empty records) of the store a
    run read after its flight: the whole EEPROM (`run.eeprom`), or the
    written part of an SPI NOR chip from address 0 (`run.flash`, the rest
    blank); the flight is None when there is none of this `[log]`'s."""
    p = plan(app)
    if p is None:
        return p, None, [], 0
    if p.store == "spi_nor":
        image = getattr(run, "flash", None)
        if image is not None:
            image = image[:p.size] + b"\xff" * max(0, p.size - len(image))
    else:
        image = run.eeprom[p.base:p.base + p.size] if run.eeprom is not None else None
    if image is None:
        return p, None, [], 0
    flights, empty = decode(p, image)
    own = [f for f in flights if f.foreign is None]  # a kept store (`-E FILE`) may hold flights of an earlier [log]
    return p, (own[-1] if own else None), flights, empty


def flight_report(app, run, check_cls, *, truth=None, alt_element: str | None = None, offset: float = 0.0):
    """The recorder's part of a simulated flight's report: (summary lines,
    checks, (plan, flight) to write as record.log or None). The launch and
    the end of the flight are the telemetry's transitions into the trigger
    state and then into a state that records nothing; `offset` turns the
    run's seconds into the firmware's (a tape replay's run counts tape
    seconds)."""
    log = app.log
    names = {st.id: st.name for st in app.machines[log.machine].states}
    launch = next((t for t, _, n in run.transitions if n == names[log.trigger]), None)
    end = None
    if launch is not None:
        stop = {names[i] for i, r in enumerate(log.rates) if i and r == 0}
        end = next((t for t, _, n in run.transitions if t > launch and n in stop), None)
    fw = (lambda t: None if t is None else t + offset)  # noqa: E731
    return recorder_report(app, run, check_cls, launch_s=fw(launch), landed_s=fw(end), truth=truth,
                           alt_element=alt_element)


def agrees(recorded: float, telemetered: float, half_step: float) -> bool:
    """Whether a recorded value is the telemetered one as the encoding kept
    it: equal (half_step 0), or within half a step, plus the rounding of the
    firmware's value x (1 / step) to binary32 before it is rounded to a
    count, which can put a value a hair under half a step from one count on
    the count above (306.14999 -> 306.2 with step 0.1)."""
    slack = abs(telemetered) * 2.0 ** -23 if half_step else 0.0
    return abs(recorded - telemetered) <= half_step + slack


def recorder_report(app, run, check_cls, *, launch_s: float | None, landed_s: float | None,
                    truth=None, alt_element: str | None = None):
    """(summary lines, checks, (plan, flight) or None) for a flight's record.
    `launch_s`, `landed_s`: when the firmware entered its trigger state and
    the state that ends a flight, in the firmware's seconds; `truth`: (times
    in the firmware's seconds, true altitudes) to compare the recorded
    `alt_element` with."""
    try:
        p, flight, flights, empty = newest_flight(app, run)
    except RecordError as e:
        return [f"flight recorder: {e}"], [check_cls("the flight record decodes", False, str(e))], None
    where = (f"EEPROM {p.base}–{p.base + p.size - 1}" if p.store == "eeprom"
             else f"an SPI NOR flash of {p.size:,} B")
    lines = [f"flight recorder: {len(flights)} flight(s) in {p.slots - empty} of {p.slots} records of "
             f"{p.record} B ({where})"]
    if flight is None:
        if launch_s is None:  # the vehicle never launched: there is nothing to keep
            return lines, [check_cls("the recorder kept no flight: the trigger state never came", True,
                                     "no flight in the record")], None
        return lines, [check_cls("the recorder kept the flight", False, "no flight in the record")], None
    s = flight.samples
    used = len(flight.records) + (flight.start is not None)
    if not s:  # begun, but the run ended before its first sample was stored (a flight cut short)
        lines.append(f"  flight {flight.number}: no sample stored yet ({used} record{'s' if used != 1 else ''} begun)")
        return lines, [check_cls("the recorder stored the flight's samples", False,
                                 f"flight {flight.number} holds no sample: the run ended before the first was "
                                 "written")], (p, flight)
    span = (s[-1][0] - s[0][0]) / 1000
    per_record = len(s) / max(1, len(flight.records))
    capacity = (p.slots - 1) * per_record * span / max(1, len(s) - 1) if len(s) > 1 else 0.0
    lines.append(f"  flight {flight.number}: {len(s)} samples in {used} records ({used * p.record} B), "
                 f"{s[0][0] / 1000:.3f}–{s[-1][0] / 1000:.3f} s; {per_record:.1f} samples and "
                 f"{p.record / per_record:.2f} B a sample; the store holds about {capacity:.0f} s of such flight")
    checks = []
    rates = app.log.rates

    def allowed(v) -> float:  # the sample period of the state a sample was taken in
        st = v.get(p.state_element)
        r = rates[st] if st is not None and 0 < st < len(rates) and rates[st] else max(rates)
        return 1000 / float(r)
    # a sample's time is G as a machine task stored it, up to one executor cycle after the cycle began (the
    # tasks before it take their time: examples/hpr_digital's inputs task crosses a millisecond now and then), so
    # the period plus a cycle; a missing sample makes a gap of two periods
    cycle_ms = 1000 / float(app.rate)
    late = [(b[0] - a[0], a[0]) for a, b in zip(s, s[1:])
            if b[0] - a[0] > max(allowed(a[1]), allowed(b[1])) + cycle_ms + 1e-9]
    before = (launch_s * 1000 - s[0][0]) / 1000 if launch_s is not None else float("nan")
    full = not p.newest and bool(flight.records) and flight.records[-1].slot == p.slots - 1  # `full stop`: no room
    # the last sample within a sample period (its state's) of the end, as telemetry saw it (its own samples come up to a
    # stream period after the transition: 50 ms covers every stream the kit's links carry at 20 Hz or more)
    end_ok = landed_s is None or s[-1][0] >= landed_s * 1000 - allowed(s[-1][1]) - 50 or full
    ok = launch_s is not None and before >= float(app.log.before) - 1e-9 and not late and end_ok
    rate_text = "/".join(f"{float(r):g}" for r in sorted(set(r for r in rates[1:] if r), reverse=True))
    checks.append(check_cls(
        f"the record covers {float(app.log.before):g} s before launch to landing at the log's rates ({rate_text} Hz)",
        ok, f"from {before:.2f} s before launch to {s[-1][0] / 1000:.2f} s"
            + (f" (landing {landed_s:.2f} s)" if landed_s is not None else "")
            + (", the store full" if full else "")
            + (f", {len(late)} gaps longer than the state's period, the first {late[0][0]} ms at "
               f"{late[0][1] / 1000:.2f} s" if late else ", no sample missing")))
    # value for value against the telemetry of the same run
    tele = {}
    for _, row in run.samples:
        if "time" in row:
            tele[int(row["time"]) & 0xFFFFFFFF] = row
    steps = {f.name: (float(f.step) / 2 + 1e-6 if f.step is not None else 0.0) for f in p.fields}
    both = bad = 0
    first_bad = ""
    for t, v in s:
        row = tele.get(t)
        if row is None:
            continue
        both += 1
        for name, x in v.items():
            if name not in row:
                continue
            y = row[name]
            if not agrees(float(x), float(y), steps[name]):
                bad += 1
                if not first_bad:
                    first_bad = f"; first at {t} ms: {name} recorded {x}, telemetered {y}"
    checks.append(check_cls("the record matches the telemetry value for value where both have a sample "
                            "(within half a step where the encoding quantises)",
                            both > 0 and bad == 0, f"{both} common samples, {bad} differ{first_bad}"))
    if truth is not None and len(truth[0]) and alt_element in {f.name for f in p.fields}:
        tt = np.array([t / 1000 for t, _ in s])
        rec = np.array([v[alt_element] for _, v in s], dtype=float)
        true_t, true_h = np.asarray(truth[0], dtype=float), np.asarray(truth[1], dtype=float)
        err = rec - np.interp(tt, true_t, true_h)
        peak_rec, peak_true = float(rec.max()), float(np.nanmax(true_h))
        # what the firmware estimated, against the truth: a fault (a stuck barometer) shows here as it does
        # in the telemetry, so it is reported, and the checks above hold the record to the telemetry
        lines.append(f"  {alt_element} against the truth: RMS {float(np.sqrt(np.mean(err ** 2))):.2f} m, "
                     f"largest {float(np.abs(err).max()):.2f} m; apogee recorded {peak_rec:.1f} m, true "
                     f"{peak_true:.1f} m")
    return lines, checks, (p, flight)
