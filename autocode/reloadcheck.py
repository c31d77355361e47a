"""The `[reload]` section of the application config (docs/reload.md): the
machine task whose machine the ground may replace over the link with a
bytecode image (`fsw machine upload`), without reflashing.

    [reload]
    machine  tank                 # the machine (a `machine` task runs it)
    size     384                  # bytes of a slot: the image and its state mask (32..4096)
    ram      64                   # bytes for an image's windows and locals (0..4096)
    activate TankVentControl Idle # the states in which another machine may take over
                                  # (default: the machine's first state)
    vm       roll_median F32      # what an upload may use beyond what the machine and the
                                  # state vector use (default: nothing more; `all`: everything)

The two slots live in the EEPROM after the parameters' banks and before
the flight recorder's records. Every problem is reported where it is
written."""

from __future__ import annotations

from . import model as M
from .appsyntax import Setting
from .lexer import NUM

KEYS = ("machine", "size", "ram", "activate", "vm")
SLOT_HEADER = 9  # firmware/src/fsw_reload.h kReloadHeader
SIZE_RANGE = (32, 4096)
RAM_RANGE = (0, 4096)
DEFAULT_SIZE = 256
DEFAULT_RAM = 64
IMAGE_STATES = 255  # an image's states are counted in a byte (autocode/emit/bytecode.py)


def eeprom_bytes(size: int) -> int:
    """EEPROM bytes the two slots take."""
    return 2 * (SLOT_HEADER + size)


def check_reload(rows: tuple[Setting, ...], tasks: list[M.Task], machines: list[M.Machine], board,
                 log: M.Log | None, r) -> M.Reload | None:
    """The checked `[reload]` section, None when it is absent or has errors
    (reported through `r`, appcheck's Report)."""
    if not rows:
        return None
    first = rows[0].key
    before = r.diags.error_count
    once: dict[str, Setting] = {}
    for s in rows:
        k = s.key.text
        if k not in KEYS:
            r.err(s.key, f"unknown [reload] setting `{k}`: expected one of {', '.join(KEYS)}")
        elif k in once:
            r.err(s.key, f"`{k}` given twice (first on line {once[k].key.line})")
        else:
            once[k] = s
    machine = None
    if "machine" not in once:
        r.err(first, "[reload] needs `machine NAME`: the machine the ground may replace")
    else:
        s = once["machine"]
        names = [m.name for m in machines]
        if len(s.values) > 1:
            r.err(s.values[1], "`machine` takes one value: the reloadable machine is one")
        elif not s.values or s.values[0].text not in names:
            r.err(s.values[0] if s.values else s.key,
                  f"`machine` takes the name of a machine from [configs] ({', '.join(names) or 'none'})")
        else:  # a task runs it: every machine has one (appcheck)
            machine = names.index(s.values[0].text)
            n = len(machines[machine].states)
            if n > IMAGE_STATES:
                r.err(s.values[0], f"machine `{names[machine]}` has {n} states: an uploaded machine keeps them at "
                                   f"their numbers and an image holds at most {IMAGE_STATES}, so no machine could "
                                   "ever replace it")
    size = _number(once.get("size"), DEFAULT_SIZE, SIZE_RANGE, "the bytes of a slot (an image and its state mask)", r)
    ram = _number(once.get("ram"), DEFAULT_RAM, RAM_RANGE, "the bytes for an image's windows and locals", r)
    activate: tuple[str, ...] = ()
    if machine is not None:
        m = machines[machine]
        s = once.get("activate")
        if s is None:
            activate = (m.states[0].name,)
        elif not s.values:
            r.err(s.key, f"`activate` takes states of machine `{m.name}`")
        else:
            by_name = [st.name for st in m.states]
            seen = []
            for t in s.values:
                if t.text not in by_name:
                    r.err(t, f"machine `{m.name}` has no state `{t.text}` (states: {', '.join(by_name)})")
                elif t.text in seen:
                    r.err(t, f"state `{t.text}` named twice")
                else:
                    seen.append(t.text)
            activate = tuple(seen)
    vm = _vm(once.get("vm"), r)
    if not any(t.kind == "uplink" for t in tasks):
        r.err(first, "[reload] takes its images over the link: add an `uplink` task to [tasks] "
                     "(e.g. `uplink uplink rate=100`)")
    if board is not None and r.diags.error_count == before:
        at = once["size"].values[0] if "size" in once and once["size"].values else first
        _eeprom_room(machines, board, log, size, at, r)
        if board.is_avr and board.ram and size + ram > board.ram:  # static buffers: the build could never fit
            at = next((once[k].values[0] for k in ("ram", "size") if k in once and once[k].values), first)
            r.err(at, f"the image's copy (size {size:,} B) and its windows and locals (ram {ram:,} B) take "
                      f"{size + ram:,} B: more than the {board.name}'s RAM ({board.ram:,} B); lower `ram` or `size`")
    if r.diags.error_count != before or machine is None:
        return None
    return M.Reload(machine, size, ram, activate, first.line, vm)


def _vm(s: Setting | None, r) -> tuple[str, ...]:
    """`vm`'s features, each known and named once; `all` alone."""
    from .vmverify import FEATURE_BITS

    if s is None:
        return ()
    if not s.values:
        r.err(s.key, "`vm` takes the VM's features beyond the machine's and the state vector's: `all`, or some of "
                     + ", ".join(FEATURE_BITS))
        return ()
    seen: list[str] = []
    for t in s.values:
        if t.text != "all" and t.text not in FEATURE_BITS:
            r.err(t, f"unknown VM feature `{t.text}`: expected `all` or some of " + ", ".join(FEATURE_BITS))
        elif t.text in seen:
            r.err(t, f"`{t.text}` named twice")
        else:
            seen.append(t.text)
    beside = [t for t in s.values if t.text != "all"]
    if "all" in seen and beside:
        r.err(beside[0], "`all` is every feature: name nothing beside it")
    return tuple(seen)


def _number(s: Setting | None, default: int, span: tuple[int, int], what: str, r) -> int:
    if s is None:
        return default
    signed = len(s.values) == 2 and s.values[0].text in ("-", "+") and s.values[1].kind == NUM  # out of range
    if len(s.values) > 1 and not signed:
        r.err(s.values[1], f"`{s.key.text}` takes one value")
        return default
    t = s.values[0] if s.values else s.key
    if len(s.values) != 1 or t.kind != NUM or not t.text.isdigit() or not span[0] <= int(t.text) <= span[1]:
        r.err(t, f"`{s.key.text}` takes {what}: a whole number from {span[0]} to {span[1]}")
        return default
    return int(t.text)


def _eeprom_room(machines: list[M.Machine], board, log: M.Log | None, size: int, tok, r) -> None:
    """The slots after the parameters' banks, and two records or more of
    the recorder's after them when it keeps its log in the EEPROM."""
    from .params import HEADER as PHEADER

    if board.eeprom == 0:
        r.err(tok, f"the {board.name} has no EEPROM to keep uploaded machines in")
        return
    psize = sum(v.type.size for m in machines for v in m.vars if v.param is not None)
    params = 2 * (PHEADER + psize) if psize else 0
    need = params + eeprom_bytes(size)
    record = log.record if log is not None and log.store == "eeprom" else 0
    if need + M.LOG_MIN_SLOTS * record > board.eeprom:
        parts = [f"the two slots take {eeprom_bytes(size):,} B (2 x ({SLOT_HEADER} + {size}))"]
        if params:
            parts.append(f"the parameters' banks {params:,} B")
        if record:
            parts.append(f"the recorder at least {M.LOG_MIN_SLOTS} records of {record} B")
        r.err(tok, f"{', '.join(parts)}: more than the {board.name}'s {board.eeprom:,} B of EEPROM; "
                   "lower `size`")
