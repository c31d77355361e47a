"""What the generated tables can hold, checked before generation.

Every number the generator writes into a typed C++ table or constant has a
range: a task's divider and a stream's sampling interval are `uint16_t`,
the counts of tasks and writable elements `uint8_t`, the stream count 128
(a sample frame's type carries the stream's number in 7 bits), the link's
transmit buffer is sized in a `uint16_t`, and on an AVR board no static
object may exceed the board's RAM (nor avr-gcc's 32,767 B object limit).
`check_limits` reports each value out of range at the configuration line
that asks for it; the state vector's and a machine's locals' 16-bit sizes
are checked where they are declared (autocode/check.py)."""

from __future__ import annotations

from decimal import Decimal, localcontext
from fractions import Fraction

from . import model as M
from .diagnostics import APP, Diagnostics, Source
from .protocol import CRC, HEADER, HELLO_PAYLOAD, encoded_max
from .schema import link_plan

U8_COUNT = 255  # tables counted in a uint8_t (0xFF marks "none" for the uplink task)
U16_MAX = 65535
MAX_STREAMS = 128  # a sample frame's type is 0x80 | the stream's number

# Bytes a rolling window of size N holds per sample (firmware/src/fsw_window.h):
# values of R, plus the 16-bit sample indices of the extremum windows on AVR.
_WINDOW_BYTES_AVR = {"avg": 4, "median": 8, "min": 6, "max": 6, "range": 12}


def hz(q) -> str:
    """A rate as the config spells one: `100`, `0.0015625`; one beyond
    what a float shows (`1e-400`) or of more than 16 digits in a few
    significant digits (`1e+402`)."""
    if q.denominator == 1 and q.numerator < 10 ** 16:
        return str(q.numerator)
    f = float(q) if abs(q) < 10 ** 16 else 0.0
    return repr(f) if f != 0 else _sci(q)


def count(n: int) -> str:
    """A whole number with thousands separators, or in a few significant
    digits when it has more than 16 (`1e+402`)."""
    return f"{n:,}" if n < 10 ** 16 else _sci(Fraction(n))


def _sci(q) -> str:
    with localcontext() as ctx:
        ctx.prec = 6
        return format((Decimal(q.numerator) / Decimal(q.denominator)).normalize(), "g")


def window_bytes_avr(w: M.Window) -> int:
    return _WINDOW_BYTES_AVR[w.func] * w.size


def encoded_health(plan) -> int:
    """The bytes of a health frame on the wire: payload, header, CRC, the
    COBS code byte and the delimiter."""
    return plan.health_payload + HEADER + CRC + 2


def link_load(app) -> tuple[float, float]:
    """(bytes per second the link must carry, bytes per second it can)."""
    plan = link_plan(app)
    load = 0.0
    for s in plan.streams:
        frame = encoded_max(s.batch * s.region.size + HEADER + CRC)
        load += float(s.rate) / s.batch * frame
    if plan.telemetry_task is not None and plan.health_every:
        hz = float(app.tasks[plan.telemetry_task].rate / plan.health_every)
        load += hz * encoded_health(plan) + hz / max(plan.hello_every, 1) * (HELLO_PAYLOAD.size + HEADER + CRC)
    return load, app.baud / 10


def check_limits(app, src: Source, diags: Diagnostics, sv_tok, machine_toks: dict) -> bool:
    """Reports every generated value of `app` out of its C type's range;
    True when there is none. `sv_tok` is the `state_vector` line's file
    token, `machine_toks` maps a machine's name to its `machine` line's."""
    before = diags.error_count
    at = lambda line, col, msg: diags.error(src, APP, line, col, msg)  # noqa: E731

    if len(app.tasks) > U8_COUNT:
        t = app.tasks[U8_COUNT]
        at(t.line, 1, f"task `{t.name}` is task {U8_COUNT + 1}: an application runs at most {U8_COUNT} tasks")
    for t in app.tasks:
        if t.divider > U16_MAX:
            at(t.line, 1, f"task `{t.name}` runs every {count(t.divider)} executor cycles: at most every "
                          f"{U16_MAX:,} (a task's rate must be at least the executor rate {app.rate} Hz / {U16_MAX:,})")
        if t.kind == "telemetry" and t.rate > U16_MAX:
            at(t.line, 1, f"telemetry task `{t.name}` runs at {hz(t.rate)} Hz: at most {U16_MAX:,} Hz "
                          "(its once-a-second health frame is counted in its runs, a 16-bit count)")
    if len(app.telemetry) > MAX_STREAMS:
        s = app.telemetry[MAX_STREAMS]
        at(s.line, 1, f"stream `{s.region.name}` is stream {MAX_STREAMS + 1}: the link carries at most {MAX_STREAMS} "
                      "streams (a sample frame's type holds the stream's number in 7 bits)")
    tele = next((t for t in app.tasks if t.kind == "telemetry"), None)
    for s in app.telemetry:
        every = tele.rate / s.rate if tele is not None else 1
        if every > U16_MAX:
            at(s.line, 1, f"stream `{s.region.name}` at {hz(s.rate)} Hz samples every {hz(every)} telemetry runs: "
                          f"at most every {U16_MAX:,} (a stream's rate must be at least the telemetry task's "
                          f"{hz(tele.rate)} Hz / {U16_MAX:,})")
    if diags.error_count != before:
        return False  # the link plan below assumes the counts fit

    plan = link_plan(app)
    if plan.tx_cap > U16_MAX:
        s = max(plan.streams, key=lambda x: x.batch * x.region.size)
        line = next(x.line for x in app.telemetry if x.region is s.region)
        at(line, 1, f"stream `{s.region.name}` makes frames of up to {plan.tx_cap:,} B on the wire: at most "
                    f"{U16_MAX:,} B (the link's buffer is sized in 16 bits); stream a smaller region")
    if tele is not None:
        load, capacity = link_load(app)
        if load > capacity:
            at(tele.line, 1, f"the telemetry streams need about {round(load):,} B/s but the link carries "
                             f"{round(capacity):,} B/s at {app.baud} baud: lower the stream rates or raise `baud`")

    if app.pyro:  # the flight kept across a reset, in spans the runtime counts in a byte
        from .emit.resume import MAX_RESUME_SPANS, resume_spans

        n = len(resume_spans(app))
        if n > MAX_RESUME_SPANS:
            at(app.pyro[0].line, 1, f"keeping the flight across a reset (docs/safety.md) takes {n} parts of RAM here: "
                                    f"at most {MAX_RESUME_SPANS} (the state vector, the pyro gates, each machine's "
                                    "state, locals and windows, and the modes of each run of tasks without a `mode=` "
                                    "element, one part a run): run fewer machines, or list the tasks without a `mode=` "
                                    "element next to each other")
    b = app.board
    if b.is_avr and b.ram:
        size = max(app.sv.size, 1)
        if size > b.ram:
            at(sv_tok.line, sv_tok.col, f"the state vector is {size:,} B: more than the {b.name}'s RAM "
                                        f"({b.ram:,} B)")
        for m in app.machines:
            tok = machine_toks.get(m.name)
            line, col = (tok.line, tok.col) if tok is not None else (1, 1)
            local_bytes = sum(v.type.size for v in m.vars if v.kind == M.LOCAL)
            if local_bytes > b.ram:
                at(line, col, f"machine `{m.name}` has {local_bytes:,} B of locals: more than the {b.name}'s "
                              f"RAM ({b.ram:,} B)")
            for w in m.windows:
                need = window_bytes_avr(w)
                if need > b.ram:
                    at(line, col, f"the window roll_{w.func}(..., {w.size}) at {m.path}:{w.line}:{w.col} holds "
                                  f"{need:,} B: more than the {b.name}'s RAM ({b.ram:,} B)")
        if plan.streams and plan.tx_cap > b.ram:
            s = max(plan.streams, key=lambda x: x.batch * x.region.size)
            line = next(x.line for x in app.telemetry if x.region is s.region)
            at(line, 1, f"stream `{s.region.name}` needs a {plan.tx_cap:,} B transmit buffer: more than the "
                        f"{b.name}'s RAM ({b.ram:,} B)")
        if app.log is not None:
            from .recorder import plan as log_plan

            lp = log_plan(app)
            if lp.ram > b.ram:
                at(app.log.line, 1, f"the flight recorder takes {lp.ram:,} B of RAM (a ring of {lp.ring_cap} samples "
                                    f"of {lp.sample_size} B: `before` at the rate of the states before the trigger, "
                                    f"and its other buffers): more than the {b.name}'s RAM ({b.ram:,} B); lower "
                                    "`before` or those rates, or log fewer elements")
    return diags.error_count == before
