"""The typed model: one frozen description of a state vector, a state
machine, a state script, a channel table or an application, checked and
resolved. The interpreter, the code
generator and the telemetry schema read only this; nothing downstream
re-parses text."""

from __future__ import annotations

from dataclasses import dataclass, fields
from fractions import Fraction
from typing import Union

from .board import Board
from .types import ElemType


# ---- state vector (spec §3) --------------------------------------------------

@dataclass(frozen=True)
class Element:
    name: str
    type: ElemType
    region: str
    offset: int  # bytes from the start of the state vector
    line: int


@dataclass(frozen=True)
class Region:
    name: str
    offset: int
    size: int
    elements: tuple[Element, ...]
    line: int


@dataclass(frozen=True)
class StateVector:
    path: str
    lock: bool
    regions: tuple[Region, ...]
    elements: tuple[Element, ...]  # layout order
    size: int
    # Names declared with an error (an unknown type): a machine listing one
    # is not told again that the element is missing.
    unreadable: frozenset = frozenset()

    def find(self, name: str) -> Element | None:
        for e in self.elements:
            if e.name == name:
                return e
        return None


# ---- variables a machine knows (spec §4.1, §4.2) -------------------------------

ELEMENT, LOCAL, TIME_IN_STATE = "element", "local", "T"


@dataclass(frozen=True)
class Var:
    index: int  # position in Machine.vars
    kind: str  # ELEMENT, LOCAL or TIME_IN_STATE
    name: str
    alias: str | None
    type: ElemType
    read_only: bool  # for the machine; G, S and T always are
    line: int
    init: "Expr | None" = None  # locals: the initial value
    param: "Param | None" = None  # a parameter (a read-only local the ground may change)

    @property
    def display(self) -> str:
        """The name the report prints: element name or alias, whichever
        sorts first in byte order."""
        if self.alias is not None and self.alias.encode() < self.name.encode():
            return self.alias
        return self.name


@dataclass(frozen=True)
class Param:
    """What makes a local a parameter (docs/parameters.md): its range (values
    of its type, None for a bool), its unit text, and the states in which a
    change is allowed (state ids, 1-based)."""
    min: object
    max: object
    unit: str
    when: tuple[int, ...]


# ---- expressions: every operand converted to R ---------------------------------

@dataclass(frozen=True)
class Const:
    text: str  # the literal as written, `true` and `false` included
    line: int
    col: int


@dataclass(frozen=True)
class Ref:
    var: int
    line: int
    col: int


@dataclass(frozen=True)
class Neg:
    operand: "Expr"
    line: int
    col: int


@dataclass(frozen=True)
class Not:
    operand: "Expr"
    line: int
    col: int


@dataclass(frozen=True)
class Arith:
    op: str  # + - * /
    left: "Expr"
    right: "Expr"
    line: int
    col: int


@dataclass(frozen=True)
class Cmp:
    op: str  # < <= > >= == !=
    left: "Expr"
    right: "Expr"
    line: int
    col: int


@dataclass(frozen=True)
class ChainCmp:
    """`a < b <= c`: each adjacent pair compared, middle operands once."""
    operands: tuple["Expr", ...]
    ops: tuple[str, ...]
    line: int
    col: int


@dataclass(frozen=True)
class Logic:
    op: str  # and, or
    left: "Expr"
    right: "Expr"
    line: int
    col: int


@dataclass(frozen=True)
class Roll:
    func: str  # avg, median, min, max, range
    arg: "Expr"
    size: int
    window: int  # index into the owner's windows
    line: int
    col: int


Expr = Union[Const, Ref, Neg, Not, Arith, Cmp, ChainCmp, Logic, Roll]


# ---- statements ----------------------------------------------------------------

@dataclass(frozen=True)
class Assign:
    var: int
    expr: Expr
    line: int
    col: int


@dataclass(frozen=True)
class Goto:
    state: int  # index into Machine.states
    line: int
    col: int


@dataclass(frozen=True)
class If:
    cond: Expr
    then: tuple["Stmt", ...]
    orelse: tuple["Stmt", ...]
    line: int
    col: int


Stmt = Union[Assign, Goto, If]


@dataclass(frozen=True)
class Window:
    """One rolling window: one per `roll_*` call site."""
    index: int
    func: str
    size: int
    arg: Expr
    line: int
    col: int


@dataclass(frozen=True)
class State:
    index: int
    id: int  # 1, 2, 3, ... in file order
    name: str
    line: int
    entry: tuple[Stmt, ...]
    step: tuple[Stmt, ...]
    exit: tuple[Stmt, ...]


@dataclass(frozen=True)
class Machine:
    path: str
    name: str
    sv: StateVector
    vars: tuple[Var, ...]  # listed elements, then locals, then T
    states: tuple[State, ...]
    windows: tuple[Window, ...]  # update order: inner calls before outer
    g: int  # var index of G
    s: int  # var index of S
    t: int  # var index of T

    def var(self, name: str) -> Var | None:
        for v in self.vars:
            if v.name == name or v.alias == name:
                return v
        return None

    def state(self, name: str) -> State | None:
        for st in self.states:
            if st.name == name:
                return st
        return None


# ---- state scripts (spec §5) -----------------------------------------------------

@dataclass(frozen=True)
class Assert:
    expr: Expr
    line: int
    col: int


@dataclass(frozen=True)
class Stop:
    line: int
    col: int


@dataclass(frozen=True)
class InputGroup:
    guard: Expr
    inputs: tuple[Assign, ...]


@dataclass(frozen=True)
class CheckGroup:
    guard: Expr
    checks: tuple[Union[Assert, Stop], ...]


@dataclass(frozen=True)
class ScriptSection:
    state: int | None  # None: [all_states]
    inputs: tuple[InputGroup, ...]
    checks: tuple[CheckGroup, ...]
    line: int


@dataclass(frozen=True)
class Script:
    path: str
    machine: Machine
    delta_t: int
    init_state: int
    max_steps: int
    sections: tuple[ScriptSection, ...]
    windows: tuple[Window, ...]  # the script's own roll_* windows
    # Guards of blocks with nothing in them: checked like every guard, never
    # evaluated (a guard is evaluated only before an input or a check).
    idle_guards: tuple[Expr, ...] = ()
    delta_t_at: tuple[int, int] = (1, 1)  # (line, column) of `delta_t`'s value: a refused step points there


# ---- channel tables (spec §6) ---------------------------------------------------

@dataclass(frozen=True)
class Channel:
    analog: bool
    direction: str  # "i" or "o"
    pin: str  # as written: "A0", "4"
    pin_number: int  # the board's pin number
    element: Element
    scale: float  # analog inputs: element = volts * scale + offset
    offset: float
    path: str
    line: int


# ---- sensor tables (`.sns`; docs/sensors.md, "The sensor table") -------------------

SENSOR_PARTS = ("bmp280", "ms5611", "adxl345", "mpu6050")


@dataclass(frozen=True)
class Sensor:
    """A digital sensor part: one row of a `.sns` table, resolved."""
    part: str  # one of SENSOR_PARTS
    bus: str  # "i2c" or "spi"
    address: int | None  # i2c: the 7-bit address
    cs_pin: int | None  # spi: the chip select's board pin
    where: str  # as written after the colon: "0x76", "10"
    settings: tuple[tuple[str, int], ...]  # (key, value) resolved for the part, defaults included, in a fixed order
    outputs: tuple[tuple[str, Element], ...]  # (quantity, element): pressure, temperature, x, y, z
    fault: Element | None  # bool: true while the part's health is a fault
    health: Element | None  # U8: the part's health code (fsw_sensor.h kSensor*)
    path: str
    line: int

    def setting(self, key: str) -> int:
        return dict(self.settings)[key]

    # Its hash, the dataclass's own (the same number, so sets of parts keep their order), worked out once:
    # a co-simulation keys its parts' values by the part at every plant step, and the dataclass's hash
    # walks every field (the elements' too) each time. Not pickled: a string's hash is another process's
    # elsewhere.
    def __hash__(self) -> int:
        h = self.__dict__.get("_hash")
        if h is None:
            h = hash(tuple(getattr(self, f.name) for f in fields(self)))
            object.__setattr__(self, "_hash", h)
        return h

    def __getstate__(self) -> dict:
        return {k: v for k, v in self.__dict__.items() if k != "_hash"}



# ---- the application (spec §7) ----------------------------------------------------

TASK_KINDS = ("inputs", "outputs", "machine", "telemetry", "uplink", "recorder")
TASK_MODES = {"disabled": 0, "safed": 1, "enabled": 2}  # values of a task's U8 mode element


@dataclass(frozen=True)
class Task:
    name: str
    kind: str  # one of TASK_KINDS
    machine: int | None  # index into Application.machines for kind "machine"
    rate: Fraction  # Hz
    divider: int  # runs every `divider` executor cycles
    mode: Element | None  # U8: 0 disabled, 1 safed, 2 enabled
    start: str  # the mode at boot
    line: int
    overruns: Element | None = None  # U16: steps longer than the task's period
    worst_us: Element | None = None  # U32: the longest step, microseconds


@dataclass(frozen=True)
class Stream:
    region: Region
    rate: Fraction
    divider: int  # executor cycles between samples
    line: int


@dataclass(frozen=True)
class LogField:
    """An element the flight recorder keeps (docs/recorder.md, "Encodings")."""
    element: Element
    enc: str  # raw, hold, delta, quant
    step: Fraction | None  # delta, quant: the value of one count
    width: int  # bytes of its absolute value in a sample
    line: int


LOG_MIN_SLOTS = 2  # records a flight recorder's store holds at least (fsw_log.h log_config_ok)


@dataclass(frozen=True)
class Log:
    """The `[log]` section: what the flight recorder keeps, when, and where."""
    store: str  # "eeprom"
    record: int  # bytes per record
    newest: bool  # full: overwrite the oldest records (else stop)
    machine: int  # index into Application.machines: whose states the rates name
    trigger: int  # the state id whose entry starts a flight
    before: Fraction  # seconds kept before the trigger
    rates: tuple[Fraction, ...]  # Hz by state id (index 0 unused)
    erase: tuple[int, ...]  # state ids in which an erase is allowed
    fields: tuple[LogField, ...]  # in record order: held, delta, quant, raw
    line: int  # the [log] section's first row
    cs_pin: int | None = None  # store spi_nor: the chip select's board pin
    flash_size: int = 0  # store spi_nor: bytes of the chip


@dataclass(frozen=True)
class Reload:
    """The `[reload]` section (docs/reload.md): a machine task that may run
    a bytecode image uploaded over the link instead of its generated code."""
    machine: int  # index into Application.machines
    size: int  # bytes of a slot: an image and its state mask
    ram: int  # bytes for an image's windows and locals
    activate: tuple[str, ...]  # state names in which another machine may take over
    line: int  # the section's first row
    vm: tuple[str, ...] = ()  # the VM's features beyond the machine's and the state vector's (vmverify), or ("all",)


@dataclass(frozen=True)
class PyroChannel:
    """A pyro channel (docs/safety.md): a `[pyro]` row of the application
    config, resolved. The channel is named by its output element."""
    output: Channel  # the `.dio` row that drives its pin
    arm: tuple[Channel, ...]  # the digital inputs that must all read true (armed)
    continuity: Channel | None  # an analog input reading the igniter, or None
    continuity_min: Fraction | None  # the reading at or above which the igniter is intact
    pulse: Fraction  # seconds the pin stays high once fired
    machine: int  # index into Application.machines: the one machine that writes it
    armed: tuple[int, ...]  # state ids: entered only with the arming inputs reading true
    fire: tuple[int, ...]  # state ids: the only states in which the machine may set it true
    line: int  # its row in the .app

    @property
    def element(self) -> Element:
        return self.output.element


@dataclass(frozen=True)
class Application:
    path: str
    name: str
    board: Board
    rate: int  # executor cycles per second
    baud: int
    sv: StateVector
    machines: tuple[Machine, ...]
    channels: tuple[Channel, ...]
    tasks: tuple[Task, ...]
    time_element: Element
    time_source: str  # "clock" or "cycle"
    time_unit: str  # "ms" or "us"
    telemetry: tuple[Stream, ...]
    writable: tuple[Element, ...]
    reset_cause: Element | None = None  # U8: the MCU's reset cause at boot
    flash_budget: int | None = None  # [budget] flash: bytes of program memory at most
    ram_budget: int | None = None  # [budget] ram: data + bss + the stack's high-water mark
    log: Log | None = None  # [log]: the flight recorder
    pyro: tuple[PyroChannel, ...] = ()  # [pyro]: the channels that fire charges (docs/safety.md)
    sensors: tuple[Sensor, ...] = ()  # `.sns` tables: digital sensor parts (docs/sensors.md)
    reload: Reload | None = None  # [reload]: machines replaced at run time (docs/reload.md)
