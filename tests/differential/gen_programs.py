"""Random machines + state scripts aimed at the code generator.

`case(seed, k)` draws project number `k` of a seeded run: a state vector
(`.sv`), a machine over it (`.sm`) and a state script (`.ss`), as text. The
draw is a plain `random.Random` seeded by (seed, k), so every case is
reproducible on its own and a run of 1,000 costs milliseconds.

The programs are valid by construction and aim at the emitter's fast paths
and at the edges of the evaluation type R (spec §4.5):

- every element type, locals that are `@read_only`, never assigned or
  assigned (folded into the code when the script writes no local: the
  firmware form; kept in memory when it does: the "scriptable" form);
- integer comparisons with constants at the type bounds and next to 2^24
  and 2^53, both ways round and through folded locals (`int_compare`);
- `x = a + k` / `x = a - k` / `x = k + a` with `a` swept towards 2^24 − |k|,
  2^53, the type's bounds and 2^64 (`int_add` and its binary32 slow path);
- stores of constant expressions, NaN, ±inf and −0 included
  (`constant_store`);
- F32/F64 compared with constants at, and one binary64 ulp beside, binary32
  values and the midpoints between them (`float_threshold`);
- chained comparisons of plain and of complex operands, parenthesised
  comparisons, `and`/`or`/`not` over NaN, nested if/else, transitions from
  `.entry` and `.step`, self-transitions, `roll_*` windows of size 1..5
  (sizes also through locals), guards on `T`;
- scripts that sweep inputs (`x = x + 0.37`, `c = c + 1`), write special
  values, carry asserts that hold by construction (and now and then one
  that may fail), and stop at a fixed `G`; now and then `G` grows by a huge
  `delta_t` (so `G` and `T` leave R's exact integers, or wrap: a step
  error), or `max_steps` ends the run first.

`machine_case(seed, k)` draws a machine driven instead by raw element
bytes, for the values no script can store (see the section at the end).
"""

from __future__ import annotations

import math
import random
import re
import struct
from dataclasses import dataclass
from decimal import Decimal

# name: (kind, signed, bits)
TYPES = {
    "I8": ("int", True, 8), "I16": ("int", True, 16), "I32": ("int", True, 32), "I64": ("int", True, 64),
    "U8": ("int", False, 8), "U16": ("int", False, 16), "U32": ("int", False, 32), "U64": ("int", False, 64),
    "F32": ("float", True, 32), "F64": ("float", True, 64), "bool": ("bool", False, 1),
}
INT_TYPES = [t for t, (k, _, _) in TYPES.items() if k == "int"]
FLOAT_TYPES = ["F32", "F64"]


def bounds(t: str) -> tuple[int, int]:
    kind, signed, bits = TYPES[t]
    if kind == "bool":
        return 0, 1
    if signed:
        return -(1 << (bits - 1)), (1 << (bits - 1)) - 1
    return 0, (1 << bits) - 1


# ---- interesting numbers --------------------------------------------------------

def f32_of(x: float) -> float:
    return struct.unpack("<f", struct.pack("<f", x))[0]


def f32_next(x: float, up: bool) -> float:
    """The binary32 neighbour of binary32 value x (finite)."""
    if x == 0:
        tiny = struct.unpack("<f", struct.pack("<I", 1))[0]
        return tiny if up else -tiny
    b = struct.unpack("<I", struct.pack("<f", x))[0]
    b += 1 if (x > 0) == up else -1
    return struct.unpack("<f", struct.pack("<I", b))[0]


def exact_text(x: float) -> str:
    """A literal whose exact decimal value is the binary64 value x."""
    if x == int(x) and abs(x) < 1e30:
        return str(int(x))
    d = Decimal(x)
    s = format(d, "E") if abs(x) < 1e-6 or abs(x) >= 1e30 else format(d, "f")
    return s.lstrip("-")


F32_BASES = (1.0, 0.1, 0.37, 775.0, 1e-3, 8388608.0, 16777216.0, 3.4028234663852886e38,
             1.401298464324817e-45, 1.1754943508222875e-38, 2.5, 1e10, 33554432.0, 0.5)


def float_constants(rng: random.Random) -> tuple[str, float]:
    """A literal (text, binary64 value) near a binary32 value: the value, a
    neighbour, the midpoint between them, or one binary64 ulp beside the
    midpoint; or a short decimal spelling."""
    base = rng.choice(F32_BASES)
    scaled = base * rng.choice((1, 1, 1, 2, 0.5, 3))
    v = f32_of(scaled if scaled < 3.4e38 else base)
    if rng.random() < 0.3:
        v = f32_of(rng.uniform(-1000, 1000))
    up = rng.random() < 0.5
    n = f32_next(v, up) if math.isfinite(f32_next(v, up)) else v
    mid = (v + n) / 2
    pick = rng.randrange(7)
    if pick == 0:
        x = v
    elif pick == 1:
        x = n
    elif pick in (2, 3):
        x = mid
    elif pick == 4:
        x = math.nextafter(mid, math.inf)
    elif pick == 5:
        x = math.nextafter(mid, -math.inf)
    else:
        return repr(v).replace("e+", "e"), v
    return exact_text(abs(x)), abs(x)


def int_constants(rng: random.Random, t: str) -> int:
    """An integer near a bound of type t, of binary32's or binary64's exact
    integers, or small."""
    lo, hi = bounds(t)
    pts = [0, 1, 2, 100, lo, hi, (1 << 24), (1 << 53), (1 << 23), (1 << 31), (1 << 32), (1 << 63), (1 << 64),
           -(1 << 24), -(1 << 53)]
    base = rng.choice(pts)
    return base + rng.choice((0, 0, 0, 1, -1, 2, -2, 3, -3))


def int_text(n: int) -> str:
    """Non-negative literals only (a `-` is an operator: `-5` is Neg(5))."""
    return str(n) if n >= 0 else f"-{-n}"


# ---- the program model --------------------------------------------------------------

@dataclass
class Var:
    name: str
    type: str
    elem: bool
    machine_writes: bool  # the machine may assign it (not read-only, not G/S)
    role: str = ""  # "G", "S" or ""
    alias: str = ""  # another name the machine gives it
    init: str = "0"  # locals: the initial value's text

    @property
    def kind(self) -> str:
        return TYPES[self.type][0]


@dataclass
class Case:
    """One generated project."""
    seed: int
    index: int
    name: str  # the machine's file stem
    sv: str
    sm: str
    ss: str

    def repro(self) -> str:
        return (f"# case {self.index} of seed {self.seed}\n"
                f"# ---- {self.name}.sv\n{self.sv}"
                f"# ---- {self.name}.sm\n{self.sm}"
                f"# ---- {self.name}.ss\n{self.ss}")


class Gen:
    def __init__(self, rng: random.Random):
        self.r = rng
        self.vars: list[Var] = []
        self.states: list[str] = []
        self.nwin = 0

    # -- helpers --
    def chance(self, p: float) -> bool:
        return self.r.random() < p

    def pick(self, seq):
        return self.r.choice(seq)

    def readable(self) -> list[str]:
        return [self.ref(v) for v in self.vars] + ["T"]

    def ref(self, v: Var) -> str:
        """A name of v: its role, else its alias now and then, else its name."""
        if v.role:
            return v.role
        return v.alias if v.alias and self.chance(0.5) else v.name

    def of_kind(self, *kinds: str, writable: bool | None = None) -> list[Var]:
        return [v for v in self.vars if v.kind in kinds and v.role == ""
                and (writable is None or v.machine_writes == writable)]

    def size_arg(self) -> str:
        small = [v for v in self.vars if not v.elem and v.kind == "int" and v.init.isdigit()
                 and 1 <= int(v.init) <= 5 and not v.machine_writes]
        if small and self.chance(0.3):
            return self.pick(small).name
        return str(self.r.randint(1, 5))

    # -- expressions (text, fully parenthesised where it matters) --
    def literal(self, kind: str = "") -> str:
        r = self.r.random()
        if kind == "float" or (kind == "" and r < 0.35):
            return float_constants(self.r)[0]
        if kind == "int" or r < 0.8:
            return int_text(abs(int_constants(self.r, self.pick(INT_TYPES))))
        return self.pick(("0.37", "1.5", "2.5E-3", ".5", "5.", "1e3", "true", "false", "1e39", "1e-45"))

    def operand(self, depth: int) -> str:
        """A numeric expression."""
        r = self.r.random()
        if depth <= 0 or r < 0.35:
            return self.pick(self.readable())
        if r < 0.5:
            return self.literal()
        if r < 0.75:
            op = self.pick(("+", "-", "*", "/"))
            return f"({self.operand(depth - 1)} {op} {self.operand(depth - 1)})"
        if r < 0.82:
            return f"-{self.operand(depth - 1)}"
        if r < 0.92:
            self.nwin += 1
            f = self.pick(("avg", "median", "min", "max", "range"))
            return f"roll_{f}({self.operand(depth - 1)}, {self.size_arg()})"
        return f"({self.cond(depth - 1)})"

    def plain(self) -> str:
        """A literal or a name: chains of these are split pair by pair."""
        return self.pick(self.readable()) if self.chance(0.6) else self.literal()

    def int_cmp(self) -> str:
        ints = self.of_kind("int", "bool") + [v for v in self.vars if v.role in ("G", "S")]
        if not ints or self.chance(0.15):
            name, t = "T", "U64"
        else:
            v = self.pick(ints)
            name, t = self.ref(v), v.type
        consts = [v for v in self.vars if not v.elem and v.kind == "int" and not v.machine_writes]
        if consts and self.chance(0.2):
            c = self.pick(consts).name
        else:
            c = int_text(int_constants(self.r, t if t != "bool" else "U8"))
        op = self.pick(("<", "<=", ">", ">=", "==", "!="))
        return f"{name} {op} {c}" if self.chance(0.7) else f"{c} {op} {name}"

    def float_cmp(self) -> str:
        fl = self.of_kind("float")
        if not fl:
            return self.int_cmp()
        v = self.pick(fl)
        c = float_constants(self.r)[0]
        consts = [x for x in self.vars if not x.elem and not x.machine_writes and x.kind == "float"]
        if consts and self.chance(0.25):
            c = self.pick(consts).name  # folded: a known constant, -0 or ±inf too
        elif self.chance(0.2):
            c = f"-{c}"  # not a known constant: the general path
        op = self.pick(("<", "<=", ">", ">=", "==", "!="))
        name = self.ref(v)
        return f"{name} {op} {c}" if self.chance(0.7) else f"{c} {op} {name}"

    def chain(self, depth: int) -> str:
        n = self.r.randint(3, 4)
        complex_ = self.chance(0.4)
        ops = [self.pick(("<", "<=", ">", ">=")) for _ in range(n - 1)]
        parts = []
        for i in range(n):
            parts.append(f"({self.operand(depth)})" if complex_ and self.chance(0.6) else self.plain())
        text = parts[0]
        for op, p in zip(ops, parts[1:]):
            text += f" {op} {p}"
        return text

    def cond(self, depth: int = 2) -> str:
        r = self.r.random()
        if r < 0.25:
            return self.int_cmp()
        if r < 0.45:
            return self.float_cmp()
        if r < 0.55:
            return self.chain(depth - 1)
        if depth > 0 and r < 0.7:
            op = self.pick(("and", "or"))
            return f"({self.cond(depth - 1)}) {op} ({self.cond(depth - 1)})"
        if depth > 0 and r < 0.78:
            return f"{self.pick(('not ', '!'))}({self.cond(depth - 1)})"
        if r < 0.82:
            return f"({self.plain()} < {self.plain()}) {self.pick(('<', '>=', '=='))} {self.plain()}"
        if r < 0.88:
            return f"T {self.pick(('>', '>=', '==', '<'))} {self.r.choice((0, 10, 20, 35, 50, 100))}"
        if r < 0.94:
            return self.operand(depth)  # a bare value: true when non-zero and not NaN
        return f"{self.operand(depth)} {self.pick(('<', '<=', '>', '>=', '==', '!='))} {self.operand(depth)}"

    # -- assignments --
    def special_value(self) -> str:
        # `1e308 * 10`: a literal beyond binary64 (`1e400`) is an error. (`1e39` is one too where R is
        # binary32, when a board or `--real f32` is named; these cases go to the checker directly.)
        return self.pick(("0/0", "1/0", "-1/0", "-0", "0 * -1", "-(0/0)", "1e39", "-1e39", "3.4028235e38 * 2",
                          "18446744073709551615", "18446744073709551616", "9007199254740993",
                          "16777217", "-9223372036854775809", "1e308 * 10", "1e-400", "-1e-46", "2.5", "-2.9",
                          "300", "-129", "65535.9", "4294967295.5"))

    def assignment(self, target: Var, depth: int) -> str:
        r = self.r.random()
        if target.kind == "int" and r < 0.35:
            srcs = self.of_kind("int") + [v for v in self.vars if v.role in ("G", "S")]
            a = "T" if not srcs or self.chance(0.15) else self.ref(self.pick(srcs))
            if self.chance(0.5):
                a = self.ref(target)
            k = self.pick((1, 1, 3, 7, 100, 4095, (1 << 23) - 1, (1 << 23), (1 << 23) + 1, (1 << 24) - 1, 1 << 24,
                           (1 << 53) - 1, 1 << 53, 65535))
            form = self.r.randrange(3)
            if form == 0:
                return f"{target.name} = {a} + {k}"
            if form == 1:
                return f"{target.name} = {a} - {k}"
            return f"{target.name} = {k} + {a}"
        if r < 0.5:
            if self.chance(0.5):
                return f"{target.name} = {self.special_value()}"
            return f"{target.name} = {self.literal()}"
        if r < 0.6 and target.kind == "float":
            if self.chance(0.4):  # -0 samples (elements start at 0): windows store them as +0
                f = self.pick(("avg", "median", "min", "max", "range"))
                return f"{target.name} = roll_{f}(-{self.pick(self.readable())}, {self.size_arg()})"
            return f"{target.name} = {target.name} {self.pick(('+', '-', '*', '/'))} {self.literal()}"
        if r < 0.7:
            return f"{target.name} = {self.cond(depth)}"
        return f"{target.name} = {self.operand(depth)}"


# ---- machine ---------------------------------------------------------------------------

def gen_sv(g: Gen) -> tuple[str, list[Var]]:
    r = g.r
    lines = []
    if r.random() < 0.1:
        lines += ["[options]", "lock", ""]
    n = r.randint(3, 8)
    types = [r.choice(list(TYPES)) for _ in range(n)]
    if r.random() < 0.5:
        types.append(r.choice(FLOAT_TYPES))
    elems = []
    g_named = r.random() < 0.2
    elems.append(Var("G" if g_named else "time", "U64", True, False, role="G"))
    elems.append(Var("state", "U32", True, False, role="S"))
    for i, t in enumerate(types):
        elems.append(Var(f"{t.lower()}_{i}", t, True, True))
    r.shuffle(elems)
    nreg = r.randint(1, 3)
    cuts = sorted(r.sample(range(1, len(elems)), nreg - 1))
    regions, last = [], 0
    for c in cuts + [len(elems)]:
        regions.append(elems[last:c])
        last = c
    for k, reg in enumerate(regions):
        lines.append(f"[Region{k}]")
        lines += [f"{v.type} {v.name}" for v in reg]
    return "\n".join(lines) + "\n", elems


def gen_sm(g: Gen, elems: list[Var], read_only_share: float = 0.3, probes: bool = False) -> str:
    r = g.r
    lines = ["[state_vector]"]
    listed = []
    for v in elems:
        if v.role == "" and r.random() < 0.08:
            continue  # an element the machine does not list
        ann = ""
        if v.role == "G":
            ann = "" if v.name == "G" else " @alias G"
        elif v.role == "S":
            ann = " @alias S"
        elif r.random() < read_only_share:
            v.machine_writes = False
            ann = " @read_only"
        if v.role == "" and r.random() < 0.1:
            v.alias = f"{'Z' if r.random() < 0.5 else 'a'}{v.name}"  # sorts before or after the name
            ann += f" @alias {v.alias}"
        lines.append(f"{v.type} {v.name}{ann}")
        listed.append(v)
    g.vars = listed
    # locals
    nloc = r.randint(0, 5)
    if nloc:
        lines += ["", "[local]"]
    for i in range(nloc):
        t = r.choice(list(TYPES))
        name = f"l_{t.lower()}_{i}"
        earlier = [v for v in g.vars if not v.elem]
        pick = r.random()
        if t in FLOAT_TYPES and pick < 0.3:  # zeros of both signs, infinities, NaN (stored as 0)
            init = r.choice(("-0", "0 * -1", "0", "1/0", "-1/0", "0/0"))
        elif pick < 0.25:
            init = str(r.randint(1, 5))
        elif pick < 0.5 and t in INT_TYPES:
            n = int_constants(r, t)
            init = int_text(n)
        elif pick < 0.7:
            init = g.literal()
        elif earlier and pick < 0.85:
            init = f"{r.choice(earlier).name} {r.choice(('+', '-', '*'))} {g.literal('int')}"
        else:
            init = g.special_value()
        ro = r.random() < 0.3
        mode = "ro" if ro else ("never" if r.random() < 0.4 else "assigned")
        v = Var(name, t, False, mode == "assigned", init=init)
        g.vars.append(v)
        lines.append(f"{t} {name} = {init}{' @read_only' if ro else ''}")
    nst = r.randint(1, 4)
    g.states = [f"St{k}" for k in range(nst)]
    for st in g.states:
        lines += ["", f"[{st}]"]
        blocks = ["entry", "step", "exit"]
        r.shuffle(blocks)
        for b in blocks:
            if r.random() < 0.35 and not (probes and b == "step"):
                continue
            lines.append(f".{b}")
            body: list[str] = []
            if probes and b == "step":
                body += probe_lines(g)
            gen_block(g, b != "exit", 2, "    ", body)
            lines += body
    return "\n".join(lines) + "\n"


def probe_lines(g: Gen) -> list[str]:
    """Copies of read-only elements into writable ones through R (`w = x`,
    `w = x * 1`): every conversion of an input shows in the trace."""
    r = g.r
    ins = [v for v in g.vars if v.elem and v.role == "" and not v.machine_writes]
    outs = g.of_kind("int", "float", "bool", writable=True)
    floats = [v for v in outs if v.kind == "float"]
    lines = []
    for _ in range(r.randint(1, 3) if ins and outs else 0):
        w = r.choice(floats) if floats and r.random() < 0.6 else r.choice(outs)
        lines.append(f"    {w.name} = {g.ref(r.choice(ins))}{r.choice(('', ' * 1', ' + 0'))}")
    return lines


def gen_block(g: Gen, can_goto: bool, depth: int, ind: str, out: list[str]) -> None:
    r = g.r
    targets = g.of_kind("int", "float", "bool", writable=True)
    for _ in range(r.randint(1, 3) if depth == 2 else r.randint(1, 2)):
        x = r.random()
        if x < 0.45 and targets:
            out.append(ind + g.assignment(r.choice(targets), 2))
        elif x < 0.6 and can_goto:
            out.append(f"{ind}{g.cond()}: -> {r.choice(g.states)}")
        elif x < 0.7 and targets:
            out.append(f"{ind}{g.cond()}: {g.assignment(r.choice(targets), 1)}")
        elif depth > 0:
            out.append(f"{ind}if {g.cond()} {{")
            inner: list[str] = []
            gen_block(g, can_goto, depth - 1, ind + "    ", inner)
            out += inner
            if r.random() < 0.5:
                out.append(f"{ind}}}")
            elif r.random() < 0.5:
                inner = []
                gen_block(g, can_goto, depth - 1, ind + "    ", inner)
                if inner:  # `else { }` is an error ("expected logic after else")
                    out.append(f"{ind}}} else {{")
                    out += inner
                out.append(f"{ind}}}")
            else:
                out.append(f"{ind}}}")
                out.append(f"{ind}else if {g.cond()} {{")
                inner = []
                gen_block(g, can_goto, depth - 1, ind + "    ", inner)
                out += inner
                out.append(f"{ind}}}")
    if can_goto and r.random() < 0.15:
        out.append(f"{ind}-> {r.choice(g.states)}")  # unconditional (self-transitions too)


# ---- script ---------------------------------------------------------------------------

def start_value(g: Gen, v: Var, delta: int) -> str:
    """A value a sweep starts from: close enough to an edge to cross it."""
    r = g.r
    if v.kind == "bool":
        return r.choice(("true", "false"))
    if v.kind == "float":
        if r.random() < 0.3:
            return g.special_value()
        return float_constants(r)[0]
    lo, hi = bounds(v.type)
    edges = [lo, hi, (1 << 24), -(1 << 24), (1 << 53), 0, 1 << 23]
    e = r.choice([x for x in edges if lo <= x <= hi] or [0])
    n = e - r.randint(-3, 12) * delta
    return int_text(max(lo, min(hi, n)))


def gen_ss(g: Gen, stop_steps: int) -> str:
    r = g.r
    writable = [v for v in g.vars if v.role == ""]
    writes_locals = r.random() < 0.5
    if not writes_locals:
        writable = [v for v in writable if v.elem]
    opts = ["[options]"]
    huge = r.random() < 0.06
    if huge:
        delta_t = r.choice(((1 << 23) + 1, (1 << 52) + 1, (1 << 62) + 3, 3 << 61))
    else:
        delta_t = r.choice((1, 7, 10, 10, 100, 250))
    opts.append(f"delta_t {delta_t}")
    if len(g.states) > 1 and r.random() < 0.4:
        opts.append(f"init_state {r.choice(g.states)}")
    stop_g = stop_steps * delta_t
    if stop_g >= 1 << 64:
        stop_g = 3 * delta_t  # G wraps before that: `G == stop_g` still means something
    if r.random() < 0.05:
        opts.append(f"max_steps {r.randint(5, stop_steps)}")
    lines = opts + ["", "[all_states]"]
    # initial values, then per-step sweeps
    inits = [v for v in writable if r.random() < 0.7]
    if inits:
        lines.append("G == 0 {")
        for v in inits:
            lines.append(f"    {v.name} = {start_value(g, v, r.choice((1, 3, 7)))}")
        lines.append("}")
    for v in writable:
        x = r.random()
        if x < 0.4:
            if v.kind == "float":
                step = r.choice(("0.37", "1", "0.001", "1e30", "2.5E-3", exact_text(2.0 ** -20)))
                op = r.choice(("+", "-", "+", "*"))
                if op == "*":
                    step = r.choice(("1.5", "-2", "0.5"))
                lines.append(f"true: {v.name} = {v.name} {op} {step}")
            elif v.kind == "int":
                k = r.choice((1, 1, 3, 7, 1000))
                lines.append(f"true: {v.name} = {v.name} {r.choice(('+', '-'))} {k}")
            else:
                lines.append(f"true: {v.name} = not {v.name}")
        elif x < 0.55:
            at = r.randrange(stop_steps) * delta_t
            lines.append(f"G == {at}: {v.name} = {g.special_value()}")
        elif x < 0.65:
            lines.append(f"{g.cond(1)}: {v.name} = {g.operand(1)}")
    # asserts that hold whatever the values
    for _ in range(r.randint(1, 4)):
        lines.append(f"{tautology_guard(g)}: @assert {tautology(g)}")
    if r.random() < 0.07:
        lines.append(f"G > {r.randrange(stop_steps) * delta_t}: @assert {g.cond(1)}")  # may fail
    stop_line = f"G == {stop_g}: @stop"
    if r.random() < 0.15:
        stop_line = f"G >= {stop_g} {{\n    @assert {tautology(g)}\n    @stop\n}}"
    lines.append(stop_line)
    # sections of single states
    for st in r.sample(g.states, r.randint(0, len(g.states))):
        lines += ["", f"[{st}]"]
        if writable and r.random() < 0.7:
            v = r.choice(writable)
            lines.append(f"true: {v.name} = {g.operand(1)}")
        lines.append(f"true: @assert S == {g.states.index(st) + 1}")
    return "\n".join(lines) + "\n"


def tautology_guard(g: Gen) -> str:
    return g.pick(("true", "true", g.cond(1), f"T {g.pick(('>', '=='))} 0"))


def tautology(g: Gen) -> str:
    """An assertion that holds for every value of every variable."""
    r = g.r
    v = r.choice([x for x in g.vars if x.role == ""] or g.vars)
    name = g.ref(v)
    lo, hi = bounds(v.type) if v.kind != "float" else (0, 0)
    x = r.random()
    if x < 0.25 and v.kind == "int":
        return f"{int_text(lo)} <= {name} <= {int_text(hi)}"
    if x < 0.25 and v.kind == "bool":
        return f"{name} == 0 or {name} == 1"
    if x < 0.4:
        return f"{name} == {name}"  # NaN reads as 0
    if x < 0.55:
        n = g.size_arg()
        e = g.operand(1)
        return f"roll_min({e}, {n}) <= roll_max({e}, {n})"
    if x < 0.7:
        return f"1 <= S <= {len(g.states)}"
    if x < 0.8:
        return "T >= 0 and G >= T"
    if x < 0.9:
        return f"not ({name} != {name})"
    return f"{name} * 0 == 0 or {name} * 0 != 0"  # x * 0 is NaN for x = ±inf


def case(seed: int, k: int) -> Case:
    """Project `k` of the run seeded by `seed`."""
    rng = random.Random(seed * 1_000_003 + k)
    g = Gen(rng)
    name = f"m{k}"
    sv, elems = gen_sv(g)
    sm = gen_sm(g, elems)
    ss = gen_ss(g, rng.randint(15, 60))
    return Case(seed, k, name, sv, sm, ss)


def cases(seed: int, n: int, start: int = 0) -> list[Case]:
    return [case(seed, k) for k in range(start, start + n)]


# ---- machines driven by raw element values ------------------------------------------------
#
# A state script can only store what R computes: in binary32 an F64 element
# only ever holds binary32 values, no element ever holds a NaN, and integers
# above 2^24 come only from `G`/`T`. On a board, element values also come
# from I/O, the uplink and other tasks, as raw bytes. These cases write raw
# bytes into the machine's read-only elements before every step: binary64
# values between binary32 neighbours and exactly on their midpoints, NaNs
# with payloads, -0, subnormals, and arbitrary 64-bit integers.

@dataclass
class MachineCase:
    seed: int
    index: int
    name: str
    sv: str
    sm: str
    delta_t: int
    init_state: int  # index
    input_types: list[tuple[str, str]]  # (name, type) of each input element
    steps: list[list[bytes]]  # per step, each input's raw little-endian bytes

    def repro(self) -> str:
        rows = []
        for n, row in enumerate(self.steps, 1):
            rows.append(f"#   step {n} (G = {(n - 1) * self.delta_t}): " + ", ".join(
                f"{name} = {describe(t, raw)}" for (name, t), raw in zip(self.input_types, row)))
        return (f"# raw-input case {self.index} of seed {self.seed}, delta_t {self.delta_t}, "
                f"initial state #{self.init_state + 1}\n# ---- {self.name}.sv\n{self.sv}"
                f"# ---- {self.name}.sm\n{self.sm}# ---- inputs before each step\n" + "\n".join(rows) + "\n")


def describe(t: str, raw: bytes) -> str:
    kind, signed, bits = TYPES[t]
    if kind == "float":
        x = struct.unpack("<f" if bits == 32 else "<d", raw)[0]
        return f"{x!r} (0x{int.from_bytes(raw, 'little'):0{len(raw) * 2}x})"
    return str(int.from_bytes(raw, "little", signed=signed))


def near_literal(r: random.Random, literals: list[str]) -> float:
    """A binary64 value at or beside a literal of the machine as binary32
    reads it: the binary32 value c, a neighbour's midpoint with c (where
    rounding a binary64 element to binary32 ties), or one binary64 ulp
    beside that midpoint; sometimes negated."""
    from fractions import Fraction
    from fswkit.autocode.numeric import f32_from_fraction

    c = f32_from_fraction(Fraction(r.choice(literals)))
    if math.isinf(c):
        c = 3.4028234663852886e38
    n = f32_next(c, r.random() < 0.5)
    if math.isinf(n):
        n = c
    mid = (c + n) / 2
    v = r.choice((c, n, mid, mid, mid, math.nextafter(mid, math.inf), math.nextafter(mid, -math.inf)))
    return -v if r.random() < 0.3 else v


def rounding_tie(r: random.Random, bits: int, p: int) -> int:
    """A positive integer of at most `bits` bits exactly halfway between two
    neighbours with p significant bits (so rounding it to binary32, p = 24,
    or binary64, p = 53, is a tie), or one more (just past the tie), or
    with the low bits set (a tie in the top bits only: rounding must look
    at every bit, not just the first 32)."""
    length = r.randint(p + 1, bits)
    m = (1 << (p - 1)) | r.getrandbits(p - 1)
    shift = length - p
    n = (m << shift) | (1 << (shift - 1))
    return n + r.choice((0, 0, 1, -1, r.getrandbits(max(shift - 1, 1)) if shift > 2 else 0))


def raw_value(r: random.Random, t: str, literals: list[str]) -> bytes:
    kind, signed, bits = TYPES[t]
    if kind == "bool":
        return bytes([r.random() < 0.5])
    if kind == "int":
        lo, hi = bounds(t)
        x = r.random()
        if x < 0.25 and literals:
            n = int(float(r.choice(literals))) + r.randint(-2, 2)
        elif x < 0.45 and bits >= 32:
            magnitude = bits - (1 if signed else 0)
            n = rounding_tie(r, magnitude, r.choice((24, 53)) if magnitude > 54 else 24)
            n = -n if signed and r.random() < 0.5 else n
        elif x < 0.6:
            n = int_constants(r, t)
        elif x < 0.8:
            n = r.randint(lo, hi)
        else:
            n = r.choice((0, 1, 7, 100, 1000)) * r.choice((1, -1))
        n = max(lo, min(hi, n))
        return n.to_bytes(bits // 8, "little", signed=signed)
    x = r.random()
    if x < 0.12:  # NaNs: quiet, signalling, negative, with payloads
        if bits == 32:
            pattern = r.choice((0x7FC00000, 0x7F800001, 0xFFC00000, 0x7FFFFFFF, 0x7FA00000 | r.getrandbits(20)))
        else:
            pattern = r.choice((0x7FF8000000000000, 0x7FF0000000000001, 0xFFF8000000000000,
                                0x7FF0000020000000, 0x7FF0000000000000 | r.getrandbits(51) | 1))
        return pattern.to_bytes(bits // 8, "little")
    if x < 0.2:  # zeros, infinities, binary64 subnormals, the edges of binary32's range
        v = r.choice((0.0, -0.0, math.inf, -math.inf, 1e-310, -5e-324, 1e300, -1e300,
                      3.4028235677973366e38, 3.4028235677973362e38, 3.402823466385289e38,
                      1.401298464324817e-45, 7.006492321624085e-46, 7.006492321624087e-46, 1e-46,
                      1.1754942106924411e-38))
    elif x < 0.65 and literals:
        v = near_literal(r, literals)
    elif x < 0.85:
        v = float_constants(r)[1]
        if r.random() < 0.3:
            v = -v
    else:
        v = r.uniform(-1000, 1000) if r.random() < 0.5 else struct.unpack("<d", r.getrandbits(64).to_bytes(8, "little"))[0]
        if v != v:
            v = 0.5
    if bits == 32:
        return struct.pack("<f", f32_of(v) if abs(v) <= 3.4e38 or math.isinf(v) else math.copysign(math.inf, v))
    return struct.pack("<d", v)


def machine_case(seed: int, k: int, steps: int = 24) -> MachineCase:
    """Machine `k` of the raw-input run seeded by `seed`, with its inputs."""
    rng = random.Random(seed * 1_000_033 + k + 7)
    g = Gen(rng)
    name = f"r{k}"
    sv, elems = gen_sv(g)
    sm = gen_sm(g, elems, read_only_share=0.55, probes=True)
    inputs = [v for v in g.vars if v.elem and v.role == "" and not v.machine_writes]
    delta_t = rng.choice((1, 10, 250, (1 << 23) + 1, (1 << 52) + 1))
    # The machine's numeric literals: inputs land on and beside them, above
    # all on those an input is compared with.
    num = r"(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
    literals = [x for x in re.findall(rf"(?<![\w.]){num}", sm) if 0 < abs(float(x)) < 1e38]
    compared = {}
    for v in inputs:
        names = "|".join(re.escape(n) for n in (v.name, v.alias) if n)
        found = re.findall(rf"\b(?:{names})\s*[<>=!]=?\s*-?({num})", sm) + \
            re.findall(rf"(?<![\w.])({num})\s*[<>=!]=?\s*(?:{names})\b", sm)
        compared[v.name] = [x for x in found if 0 < abs(float(x)) < 1e38]
    rows = [[raw_value(rng, v.type, compared[v.name] if compared[v.name] and rng.random() < 0.7 else literals)
             for v in inputs] for _ in range(steps)]
    return MachineCase(seed, k, name, sv, sm, delta_t, rng.randrange(len(g.states)),
                       [(v.name, v.type) for v in inputs], rows)
