"""The `[log]` section of the application config (docs/recorder.md): what
the flight recorder keeps, at which rate in which states, and where.

    [log]
    store   eeprom                # where records go: eeprom, or spi_nor PIN [SIZE]
                                  # (an SPI NOR flash chip, chip select on board pin PIN,
                                  # SIZE bytes, or a number and K or M: 64 K..16 M,
                                  # default 8 M)
    record  64                    # bytes per record, 32..255
    full    stop                  # stop | newest: what happens when the store is full
    machine mission               # the machine whose states the lines below name
    trigger Boost                 # entering this state starts a flight
    before  0.5                   # seconds kept in RAM before the trigger, committed with it
    rate    10                    # Hz in the states no other `rate` line names
    rate    0 Landed Abort        # Hz in these states; 0 records nothing (and ends a flight)
    erase   Safe                  # the states in which the ground may erase the log
    element altitude delta=0.1    # an element and its encoding: raw, hold, delta=STEP, quant=STEP
    element state                 # (a machine's state number: held, one byte)

Every problem is reported where it is written."""

from __future__ import annotations

import struct
from fractions import Fraction
from os.path import basename

from . import model as M
from .appsyntax import Setting
from .buses import i2c_bus, spi_bus, spi_channel_problem
from .lexer import ID, NUM, OP, Tok
from .limits import hz
from .numeric import exact_literal

KEYS = ("store", "record", "full", "machine", "trigger", "before", "rate", "erase", "element")
ONCE = ("store", "record", "full", "machine", "trigger", "before", "erase")
ENCODINGS = ("raw", "hold", "delta", "quant")
MAX_BEFORE = 60
STORES = ("eeprom", "spi_nor")
NOR_SECTOR = 4096  # bytes a sector erase clears: records never straddle one
NOR_SIZES = (64 << 10, 16 << 20)  # a power of two between these
NOR_DEFAULT = 8 << 20  # the W25Q64JV
UNITS = {"K": 1 << 10, "KiB": 1 << 10, "M": 1 << 20, "MiB": 1 << 20}
MAX_SLOTS = 65535  # record indexes are u16
MIN_RECORDS = M.LOG_MIN_SLOTS
MAX_STEP = 10**6  # delta= and quant= at most
MIN_STEP = "2.94e-39"  # about 1 / FLT_MAX: smaller, and 1/STEP is no binary32 number



def check_log(rows: tuple[Setting, ...], sv: M.StateVector, tasks: list[M.Task], machines: list[M.Machine],
              board, r, channels: list[M.Channel] | None = None, sensors=(), written: bool = False) -> M.Log | None:
    """The checked `[log]` section, None when it is absent or has errors
    (reported through `r`, appcheck's Report). `channels`: the I/O channels,
    whose pins an SPI flash's chip select must not take; `sensors`: the
    sensor tables' parts, whose chip selects and I2C pins it must not take
    either. `written`: the section's header is there (empty: the parser
    said so, once)."""
    rec_task = next((t for t in tasks if t.kind == "recorder"), None)
    if not rows:
        if rec_task is not None and not written:
            r.at(rec_task.line, 1, f"task `{rec_task.name}` is a `recorder` but the application has no [log] section")
        return None
    first = rows[0].key
    before_errors = r.diags.error_count
    once: dict[str, Setting] = {}
    rates: list[Setting] = []
    elements: list[Setting] = []
    for s in rows:
        k = s.key.text
        if k not in KEYS:
            r.err(s.key, f"unknown [log] setting `{k}`: expected one of {', '.join(KEYS)}")
        elif k in ONCE:
            if k in once:
                r.err(s.key, f"`{k}` given twice (first on line {once[k].key.line})")
            else:
                once[k] = s
        elif k == "rate":
            rates.append(s)
        else:
            elements.append(s)
    if rec_task is None:
        r.err(first, "[log] needs a `recorder` task in [tasks] (e.g. `log recorder rate=100`)")
    for k in ("store", "machine", "trigger"):
        if k not in once:
            r.err(first, f"[log] needs `{k}`")
    if not elements:
        r.err(first, "[log] needs at least one `element`")

    store, cs_pin, flash_size = _store(once.get("store"), board, channels, r, sensors)
    if store == "eeprom" and "store" in once and board is not None and board.eeprom == 0:  # none: said above
        r.err(once["store"].values[0], f"the {board.name} has no EEPROM")
    record = _record(once.get("record"), r)
    if store == "eeprom" and board is not None and board.eeprom:
        at = once.get("record") or once.get("store")
        _eeprom_room(board, machines, record, at.values[0] if at is not None and at.values else first, r)
    if store == "spi_nor" and "record" in once and (record & (record - 1) or record > 128):
        r.err(once["record"].values[0], f"`record` on spi_nor is a power of two from 32 to 128 "
                                        f"(records never straddle a {NOR_SECTOR}-byte sector or a 256-byte page): "
                                        f"found {record}")
    full = _one_word(once.get("full"), ("stop", "newest"), "stop", r)
    if store == "spi_nor" and full == "newest":
        r.err(once["full"].values[0], "`full newest` is not available on spi_nor: a flash sector is erased whole, so "
                                      "overwriting the oldest records would drop a whole sector of them at a time, "
                                      "and boot finds the end of the log by a binary search that needs the records "
                                      "written from the chip's start; use `full stop` and `fsw dump --erase`")
    machine = _machine(once.get("machine"), machines, r)
    m = machines[machine] if machine is not None else None
    trigger = _states(once.get("trigger"), m, r, one=True)
    before = _before(once.get("before"), r)
    erase = _states(once.get("erase"), m, r) if "erase" in once else ((m.states[0].id,) if m else ())
    state_rates = _rates(rates, m, rec_task, r)
    if trigger and state_rates is not None and state_rates[trigger[0]] == 0:
        r.err(once["trigger"].values[0], f"the trigger state `{once['trigger'].values[0].text}` records nothing "
                                         "(rate 0): a flight would end as it starts")
    fields = _fields(elements, sv, machines, r)
    if r.diags.error_count != before_errors or m is None or not trigger or state_rates is None or fields is None:
        return None
    _trigger_entered(m, trigger[0], once["trigger"].values[0], r)
    if before and once["before"].values:
        _before_recorded(m, trigger[0], state_rates, once["before"].values[0], r)
    if store == "spi_nor" and flash_size // record > MAX_SLOTS + 1:  # one record short (8 M of 128 B) is no news
        vals = once["store"].values
        at = vals[2] if len(vals) > 2 else vals[0]
        used = MAX_SLOTS * record
        r.warn(at, f"the recorder uses {used:,} B of the {flash_size:,} B chip: records are numbered in 16 bits "
                   f"(at most {MAX_SLOTS:,} of {record} B); a larger `record` (up to 128) uses more of it")
    order = {"hold": 0, "delta": 1, "quant": 2, "raw": 3}
    fields = tuple(sorted(fields, key=lambda f: order[f.enc]))  # stable: as written within a kind
    log = M.Log(store, record, full == "newest", machine, trigger[0], before, state_rates, erase, fields, first.line,
                cs_pin, flash_size)
    if not _sizes(log, m, once, elements, r):
        return None
    if store == "eeprom" and board is not None and board.is_avr:
        _eeprom_rate(log, rates, r)
    return log


def _eeprom_rate(log: M.Log, rows: list[Setting], r) -> None:
    """A warning when the log needs more bytes a second at its fastest rate
    than an AVR's EEPROM writes (a byte in 3.4 ms): the RAM ring would
    overflow and samples be dropped on the board (the simulator's EEPROM
    writes at once and would not show it). A record's samples are counted
    at their usual size (no held change), with its opening, tail and kind."""
    from .recorder import EEPROM_WRITE_S, TAIL, encoded_size, record_sizes

    _ss, n_hold, _esc, opening, _worst = record_sizes(log.fields)
    usual = sum(encoded_size(f.enc, f.width) for f in log.fields[n_hold:])
    fastest = max(log.rates)
    room = log.record - TAIL - opening
    per_record = 1 + (room // usual if usual else 0)
    written = opening + (per_record - 1) * usual + TAIL + 2  # the kind cleared first and written last
    need = float(fastest) / per_record * written
    can = 1 / EEPROM_WRITE_S
    if need <= can:
        return
    row = next((s for s in rows if s.values and exact_literal(s.values[0].text) == fastest), None)
    if row is None:
        return
    r.warn(row.values[0], f"at {row.values[0].text} Hz the log needs about {need:,.0f} B/s ({per_record} samples "
                          f"a {log.record}-byte record), and an AVR's EEPROM writes {can:.0f} B/s: samples would be "
                          "dropped on the board (`fsw sim` writes its EEPROM at once and would not show it); lower "
                          "the rate, encode F32 elements with delta=, or `store spi_nor`")


def _sizes(log: M.Log, m: M.Machine, once: dict[str, Setting], elements: list[Setting], r) -> bool:
    """What the generated tables count in bytes (recorder.plan's sizes): a
    sample within 255 bytes, a record that holds its header, a first sample
    and one more with its tail, a RAM ring of at most 255 samples."""
    from .recorder import TAIL, record_sizes, ring_capacity

    sample_size, _n_hold, _escape, opening, worst = record_sizes(log.fields)
    if sample_size > 255:
        r.err(elements[-1].key, f"the logged elements take {sample_size - 2} bytes a sample: at most 253 "
                                "(log fewer, or encode F32 ones with delta= or quant=)")
        return False
    if opening + worst + TAIL > log.record:
        at = once["record"].values[0] if "record" in once and once["record"].values else elements[-1].key
        r.err(at, f"a record of {log.record} B cannot hold its header and first sample ({opening} B), one more "
                  f"sample ({worst} B) and its tail ({TAIL} B): `record {opening + worst + TAIL}` at least, or "
                  "fewer elements")
        return False
    ring = ring_capacity(log, m)
    if ring > 255:
        msg = (f"the RAM ring would keep {ring:,} samples (`before` at the rate of the states before the "
               "trigger, and room while the store is busy): at most 255; lower `before` or those rates")
        if "before" in once and once["before"].values:
            r.err(once["before"].values[0], msg)
        else:
            r.at(log.line, 1, msg)
        return False
    return True


def _store(s: Setting | None, board, channels: list[M.Channel] | None, r,
           sensors=()) -> tuple[str | None, int | None, int]:
    """(store, chip-select pin, flash bytes) of `store eeprom` / `store spi_nor PIN [SIZE]`."""
    if s is None:
        return "eeprom", None, 0
    if not s.values or s.values[0].text not in STORES or (s.values[0].text == "eeprom" and len(s.values) != 1):
        at = s.values[1] if len(s.values) > 1 and s.values[0].text == "eeprom" else (s.values[0] if s.values else s.key)
        r.err(at, "`store` takes one of: eeprom, spi_nor PIN [SIZE]")
        return None, None, 0
    if s.values[0].text == "eeprom":
        return "eeprom", None, 0
    rest = s.values[1:]
    if not rest or len(rest) > 3 or (len(rest) == 3 and rest[2].text not in UNITS):
        r.err(rest[-1] if len(rest) > 2 else s.values[0],
              "`store spi_nor` takes the chip select's pin, then the chip's size (default 8 MiB): bytes, or a "
              "number and K or M, e.g. `spi_nor 10 1 M`")
        return None, None, 0
    ok = True
    pin = _cs_pin(rest[0], board, channels, r, sensors)
    if pin is None:
        ok = False
    if board is not None and not any(p.bus == "spi" for p in sensors):  # an SPI part reported these itself
        hit = spi_channel_problem(board, channels or ())
        if hit is not None:
            c, why = hit
            r.err(s.values[0], f"the flash is on the SPI bus, and pin {c.pin} is {why}: the "
                               f"{'input' if c.direction == 'i' else 'output'} channel of `{c.element.name}` "
                               f"({basename(c.path)}:{c.line}) cannot have it; move the channel to another pin")
            ok = False
    size = NOR_DEFAULT
    if len(rest) >= 2:
        size = _size(rest[1], rest[2] if len(rest) == 3 else None, r)
        if size is None:
            ok = False
    return ("spi_nor", pin, size) if ok else (None, None, 0)


def _cs_pin(t: Tok, board, channels: list[M.Channel] | None, r, sensors=()) -> int | None:
    if board is None:
        return None
    # named as the I/O tables name pins (`A0` or `14`; board.pin), as a sensor part's `spi:PIN` is
    pin = board.pin(t.text) if t.kind in (NUM, ID) and t.text.isascii() else None
    if pin is None or pin not in board.digital_pins:
        pins = sorted(board.digital_pins)
        r.err(t, f"the {board.name} has no digital pin `{t.text}` for the flash's chip select "
                 f"(digital pins: {pins[0]}..{pins[-1]})" if pins else f"the {board.name} has no digital pins")
        return None
    if pin in board.reserved:
        r.err(t, f"pin {pin} is reserved on the {board.name}: {board.reserved[pin]}")
        return None
    bus = spi_bus(board)
    if pin in bus:
        r.err(t, f"pin {pin} is the SPI bus's {bus[pin]} on the {board.name}: the chip select must be another pin")
        return None
    for c in channels or ():
        if c.pin_number == pin:
            r.err(t, f"pin {pin} is already the channel of `{c.element.name}` ({basename(c.path)}:{c.line})")
            return None
    for p in sensors:
        if p.cs_pin == pin:
            r.err(t, f"pin {pin} is already the chip select of the {p.part} ({basename(p.path)}:{p.line})")
            return None
    if any(p.bus == "i2c" for p in sensors):
        twi = i2c_bus(board)
        if pin in twi:
            r.err(t, f"pin {pin} is the I2C bus's {twi[pin]} on the {board.name} (the sensor parts' bus): the chip "
                     "select must be another pin")
            return None
    return pin


def _size(t: Tok, unit: Tok | None, r) -> int | None:
    """Bytes from `1048576`, `1024 K`, `1 M` (a power of two, 64K..16M). The
    lexer takes `1M` for a malformed number: the unit is a word of its own."""
    mult = UNITS[unit.text] if unit is not None else 1
    n = int(t.text) * mult if t.kind == NUM and t.text.isdigit() and t.text.isascii() and len(t.text) <= 9 else None
    if n is None or n & (n - 1) or not NOR_SIZES[0] <= n <= NOR_SIZES[1]:
        shown = t.text + (" " + unit.text if unit is not None else "")
        r.err(t, f"the flash's size is a power of two from 64 K to 16 M (bytes, or a number and K or M), "
                 f"found `{shown}`")
        return None
    return n


def _one_word(s: Setting | None, words: tuple[str, ...], default: str, r) -> str | None:
    if s is None:
        return default
    if len(s.values) != 1 or s.values[0].text not in words:
        at = s.values[0] if s.values else s.key
        r.err(at, f"`{s.key.text}` takes one of: {', '.join(words)}")
        return None
    return s.values[0].text


def _record(s: Setting | None, r) -> int:
    if s is None:
        return 64
    t = s.values[0] if s.values else s.key
    if len(s.values) != 1 or t.kind != NUM or not t.text.isdigit() or not 32 <= int(t.text) <= 255:
        r.err(t, "`record` takes the bytes of a record: a whole number from 32 to 255")
        return 64
    return int(t.text)


def _machine(s: Setting | None, machines: list[M.Machine], r) -> int | None:
    if s is None:
        return None
    names = [m.name for m in machines]
    if len(s.values) != 1 or s.values[0].text not in names:
        r.err(s.values[0] if s.values else s.key,
              f"`machine` takes the name of a machine from [configs] ({', '.join(names) or 'none'})")
        return None
    return names.index(s.values[0].text)


def _states(s: Setting | None, m: M.Machine | None, r, one: bool = False) -> tuple[int, ...]:
    if s is None or m is None:
        return ()
    if not s.values or (one and len(s.values) != 1):
        r.err(s.values[1] if len(s.values) > 1 else s.key,
              f"`{s.key.text}` takes {'one state' if one else 'states'} of machine `{m.name}`")
        return ()
    by_name = {st.name: st.id for st in m.states}
    out = []
    for t in s.values:
        if t.text not in by_name:
            r.err(t, f"machine `{m.name}` has no state `{t.text}` (states: {', '.join(by_name)})")
        else:
            out.append(by_name[t.text])
    return tuple(out)


def _before(s: Setting | None, r) -> Fraction:
    if s is None:
        return Fraction(0)
    t = s.values[0] if s.values else s.key
    q = exact_literal(t.text) if t.kind == NUM and len(s.values) == 1 else None
    if q is None or not 0 <= q <= MAX_BEFORE:
        r.err(t, f"`before` takes the seconds kept before the trigger: a number from 0 to {MAX_BEFORE}")
        return Fraction(0)
    return q


def _rates(rows: list[Setting], m: M.Machine | None, task: M.Task | None, r) -> tuple[Fraction, ...] | None:
    """Hz by state id (index 0 unused); None on an error."""
    if m is None:
        return None
    default: Fraction | None = None
    default_line = 0
    named: dict[int, tuple[Fraction, int]] = {}
    ok = True
    by_name = {st.name: st.id for st in m.states}
    for s in rows:
        if not s.values:
            r.err(s.key, "`rate` takes Hz, then the states it applies to (none: every other state)")
            ok = False
            continue
        t = s.values[0]
        q = exact_literal(t.text) if t.kind == NUM else None
        if q is None or q < 0:
            shown = t.text + (s.values[1].text if t.text == "-" and len(s.values) > 1 else "")
            r.err(t, f"`rate` takes Hz (0 or a positive number), found `{shown}`")
            ok = False
            continue
        if q != 0 and task is not None and (task.rate / q).denominator != 1:
            r.err(t, f"log rate {t.text} Hz must divide the recorder task's rate {hz(task.rate)} Hz")
            ok = False
            continue
        if q != 0 and task is not None and task.rate / q > 255:
            r.err(t, f"log rate {t.text} Hz is below 1/255 of the recorder task's rate {hz(task.rate)} Hz")
            ok = False
            continue
        if len(s.values) == 1:
            if default is not None:
                r.err(s.key, f"a second `rate` for every other state (the first is on line {default_line})")
                ok = False
            default, default_line = q, s.key.line
            continue
        for st in s.values[1:]:
            if st.text not in by_name:
                r.err(st, f"machine `{m.name}` has no state `{st.text}` (states: {', '.join(by_name)})")
                ok = False
            elif by_name[st.text] in named:
                r.err(st, f"state `{st.text}` already has a rate on line {named[by_name[st.text]][1]}")
                ok = False
            else:
                named[by_name[st.text]] = (q, st.line)
    if not ok:
        return None
    base = default if default is not None else Fraction(0)
    return (Fraction(0),) + tuple(named.get(st.id, (base, 0))[0] for st in m.states)


def _fields(rows: list[Setting], sv: M.StateVector, machines: list[M.Machine], r) -> list[M.LogField] | None:
    by_name = {e.name: e for e in sv.elements}
    states = {m.vars[m.s].name: len(m.states) for m in machines}  # state elements: their machine's state count
    out: list[M.LogField] = []
    seen: dict[str, int] = {}
    ok = True
    for s in rows:
        if not s.values or s.values[0].kind != ID:
            r.err(s.values[0] if s.values else s.key, "`element` takes an element of the state vector, then its "
                                                      "encoding: raw, hold, delta=STEP or quant=STEP")
            ok = False
            continue
        et = s.values[0]
        e = by_name.get(et.text)
        if e is None:
            r.err(et, f"unknown element `{et.text}`")
            ok = False
            continue
        if et.text in seen:
            r.err(et, f"element `{et.text}` is logged twice (first on line {seen[et.text]})")
            ok = False
            continue
        seen[et.text] = et.line
        f = _encoding(s, e, states.get(e.name), r)
        if f is None:
            ok = False
        else:
            out.append(f)
    if len(out) > 32:
        r.err(rows[32].key, "at most 32 elements are logged")
        ok = False
    return out if ok else None


def _trigger_entered(m: M.Machine, trigger: int, at: Tok, r) -> None:
    """A warning when no transition that can run from the machine's first
    state leads into the trigger (a state id): the firmware starts a flight
    on entering it (at boot the first state is not entered, it is where the
    machine starts), so the recorder would never record."""
    from .pyrocheck import machine_graph, search

    g = machine_graph(m)
    t = trigger - 1  # the index
    if any(e.dst == t for s in search(g) for e in g.edges[s]):
        return
    first = m.states[0].name
    why = (f"it is the machine's first state, where it starts at boot, and no transition leads back to it"
           if t == 0 else f"no transition that can run from the machine's first state (`{first}`) leads to it")
    r.warn(at, f"the trigger state `{at.text}` is never entered: {why}, so the recorder never starts a flight")


def _before_recorded(m: M.Machine, trigger: int, rates, at: Tok, r) -> None:
    """A warning when `before` can keep nothing: every state with a
    transition into the trigger records nothing (rate 0), so no sample is
    ever taken before a flight starts."""
    from .recorder import _predecessors

    preds = sorted(s for s in _predecessors(m, trigger) if s != trigger)
    if preds and all(rates[s] == 0 for s in preds):
        names = ", ".join(m.states[s - 1].name for s in preds)
        r.warn(at, f"`before {at.text}` keeps nothing: the states that lead to the trigger ({names}) record nothing "
                   "(rate 0), so no sample is taken before a flight starts; give them a rate, or drop `before`")


def _eeprom_room(board, machines: list[M.Machine], record: int, at: Tok, r) -> None:
    """The EEPROM after the parameters' banks holds two records at least:
    the recorder writes one while the last is still whole."""
    from .params import HEADER as PHEADER

    psize = sum(v.type.size for m in machines for v in m.vars if v.param is not None)
    params = 2 * (PHEADER + psize) if psize else 0
    n = (board.eeprom - params) // record
    if params <= board.eeprom and n < MIN_RECORDS:
        r.err(at, f"the parameters' banks take {params:,} B of the {board.name}'s {board.eeprom:,} B of EEPROM, which "
                  f"leaves {board.eeprom - params:,} B: room for {n} record{'' if n == 1 else 's'} of {record} B, "
                  f"and the recorder needs {MIN_RECORDS} at least; a smaller `record`, fewer parameters, or "
                  "`store spi_nor`")


def _binary32_finite(x: float) -> bool:
    """Whether x, a C++ `float` literal, is a finite binary32 number."""
    try:
        struct.pack("<f", x)
    except OverflowError:
        return False
    return True


def _encoding(s: Setting, e: M.Element, n_states: int | None, r) -> M.LogField | None:
    rest = s.values[1:]
    narrow = 1 if n_states is not None and n_states < 256 else e.type.size  # a state number fits a byte
    if not rest:
        return M.LogField(e, "hold" if n_states is not None else "raw", None, narrow, s.key.line)
    w = rest[0]
    if w.kind == ID and w.text in ("raw", "hold") and len(rest) == 1:
        return M.LogField(e, w.text, None, narrow, s.key.line)
    if w.kind == ID and w.text in ("delta", "quant") and len(rest) == 3 and rest[1].kind == OP \
            and rest[1].text == "=" and rest[2].kind == NUM:
        if e.type.name != "F32":
            r.err(w, f"`{w.text}=STEP` encodes F32 elements; `{e.name}` is {e.type.name} (log it `raw`)")
            return None
        q = exact_literal(rest[2].text)
        if q is None or q <= 0 or q > MAX_STEP:
            r.err(rest[2], f"`{w.text}=` takes the value of one count: a positive number up to {MAX_STEP:,}, "
                           f"found `{rest[2].text}`")
            return None
        if not _binary32_finite(float(1 / q)):
            # the firmware multiplies by 1/STEP in binary32: an infinite factor saturates every sample
            r.err(rest[2], f"`{w.text}={rest[2].text}` is too small a count: the firmware multiplies by 1/STEP in "
                           f"binary32, which must be finite (STEP at least about {MIN_STEP})")
            return None
        return M.LogField(e, w.text, q, 4 if w.text == "delta" else 2, s.key.line)
    r.err(w, f"unknown encoding `{' '.join(t.text for t in rest)}`: expected raw, hold, delta=STEP or quant=STEP")
    return None
