"""C++ for the model's expressions, shared by the machine and the script
runner: R arithmetic over the runtime, with integer and binary32 fast paths
that are bit-identical to it (the differential tests hold them to that)."""

from __future__ import annotations

import math

import struct

from .. import model as M
from ..cnames import enumerator
from ..evaluate import NotConstant, compare, evaluate
from ..numeric import Real, to_type
from ..thresholds import tests
from .common import real_literal
from .fastpaths import (add_operands, exact_int, exact_sum_limit, folded_compare, folded_locals, known, no_reads,
                        orient)




class ExprEmitter:
    """C++ for model expressions of one machine (or of a script over it)."""

    def __init__(self, m: M.Machine, real: Real, scriptable: bool, prefix: str = "",
                 windows: str = "w", ns: str = "fsw_gen"):
        self.m = m
        self.ns = ns  # the state vector's namespace (qualifies elements from outside)
        self.real = real
        self.scriptable = scriptable
        self.prefix = prefix  # qualifies the machine's names from outside (scripts)
        self.windows = windows
        # window -> how it reads, after `windows`, where it is not its own
        # `<index>.value()` (a window kept in another's ring: shared_extremes)
        self.window_reads: dict[int, str] = {}
        self.consts = folded_locals(m, real, scriptable)
        self.sv_lock = m.sv.lock
        # Variables whose value a C++ local holds at the statement being
        # emitted (var index -> its name): read there instead of the
        # variable's bytes (autocode/emit/machine.py keeps it).
        self.held: dict[int, str] = {}
        # `x + c` / `x - c` / `c - x` kept in a slot of their own, worked out
        # where x is written (sum_key -> the slot's read; machine.py's
        # cached_sums), and the slots to work out again at a write of x
        # (var index -> [(slot name, the expression)]).
        self.cached: dict[tuple, str] = {}
        self.sum_writes: dict[int, list[tuple[str, M.Arith]]] = {}

    def holdable(self, i: int) -> bool:
        """Whether a C++ local may hold variable i's value between its
        statements: an F32 variable read and written in binary32 R (the
        local holds what read_F32 returns, bit for bit), not folded to a
        constant, and not an element that interrupts may write (`lock`)."""
        v = self.m.vars[i]
        if v.kind == M.TIME_IN_STATE or i in self.consts or self.real.bits != 32:
            return False
        if v.type.kind != "float" or v.type.size != 4:
            return False
        return not (self.sv_lock and v.kind == M.ELEMENT)

    def ptr(self, v: M.Var) -> str:
        if v.kind == M.ELEMENT:
            return f"{self.ns}::sv + {self.ns}::E_{v.name}" if self.prefix else f"sv + E_{v.name}"
        if v.param is not None and not self.scriptable:  # the parameter block the ground writes
            return f"{self.prefix}prm + {self.prefix}{enumerator('P_', v.name)}"
        return f"{self.prefix}loc + {self.prefix}{enumerator('L_', v.name)}"

    def read(self, i: int) -> str:
        v = self.m.vars[i]
        if v.kind == M.TIME_IN_STATE:
            return f"fsw::machine_T_real({self.prefix}machine)"
        if i in self.consts:
            return real_literal(self.consts[i], self.real)
        if i in self.held:
            return self.held[i]
        text = f"fsw::read_{v.type.name}({self.ptr(v)})"
        if self.sv_lock and v.kind == M.ELEMENT:
            return f"(fsw::SvGuard<true>(), {text})"
        return text

    def write(self, i: int, value: str) -> str:
        v = self.m.vars[i]
        text = f"fsw::write_{v.type.name}({self.ptr(v)}, {value});"
        if self.sv_lock and v.kind == M.ELEMENT:
            return "{ fsw::SvGuard<true> lock; " + text + " }"
        return text

    def value(self, e: M.Expr) -> str:
        t = type(e)
        if t is M.Const:
            return real_literal(self.real.literal(e.text), self.real)
        if t is M.Ref:
            return self.read(e.var)
        if t is M.Neg:
            return f"(-{self.value(e.operand)})"
        if t is M.Arith:
            if self.cached:
                slot = self.cached.get(sum_key(e, self.known))
                if slot is not None:
                    return slot
            inv = self.exact_reciprocal(e.right) if e.op == "/" else None
            if inv is not None:  # x / 2^k is x * 2^-k, bit for bit: no division on the MCU
                return f"({self.value(e.left)} * {real_literal(inv, self.real)})"
            return f"({self.value(e.left)} {e.op} {self.value(e.right)})"
        if t is M.Roll:
            return f"{self.windows}{self.window_reads.get(e.window, f'{e.window}.value()')}"
        return f"fsw::real_from_truth({self.cond(e)})"

    def exact_reciprocal(self, e: M.Expr) -> float | None:
        """1/c when `e` is a constant c = ±2^k whose reciprocal R holds as a
        normal number: dividing by c and multiplying by 1/c then round the
        same exact quotient, so they give the same bits (NaN, infinities and
        signed zeros included). None otherwise."""
        if type(e) is M.Neg:
            inv = self.exact_reciprocal(e.operand)
            return None if inv is None else -inv
        if type(e) is M.Const:
            c = self.real.literal(e.text)
        elif type(e) is M.Ref and e.var in self.consts:  # a local the machine never writes
            c = self.consts[e.var]
        else:
            return None
        if c == 0 or c != c or math.isinf(c) or abs(math.frexp(c)[0]) != 0.5:
            return None
        inv = 1.0 / c
        tiny = 2.0 ** (-126 if self.real.bits == 32 else -1022)
        big = 2.0 ** (127 if self.real.bits == 32 else 1023)
        return inv if tiny <= abs(inv) <= big else None

    def cond(self, e: M.Expr) -> str:
        t = type(e)
        if t is M.Cmp:
            fast = self.int_compare(e.left, e.op, e.right)
            if fast is None and self.real.bits == 32:
                fast = self.float_threshold(e.left, e.op, e.right)
            if fast is not None:
                return fast
            return f"({self.value(e.left)} {e.op} {self.value(e.right)})"
        if t is M.ChainCmp:
            if all(type(o) in (M.Const, M.Ref) or self.known(o) is not None for o in e.operands):
                # Literals, variables and constant expressions (`-GATE`) read
                # the same twice: test pair by pair, each on its fast path.
                pairs = [self.cond(M.Cmp(op, e.operands[k], e.operands[k + 1], e.line, e.col))
                         for k, op in enumerate(e.ops)]
                return "(" + " && ".join(pairs) + ")"
            # Each middle operand is evaluated once: a lambda holds them.
            names = [f"c{k}" for k in range(len(e.operands))]
            decl = " ".join(f"const fsw::Real {n} = {self.value(o)};" for n, o in zip(names, e.operands))
            test = " && ".join(f"{names[k]} {op} {names[k + 1]}" for k, op in enumerate(e.ops))
            return f"([&]() -> bool {{ {decl} return {test}; }}())"
        if t is M.Logic:
            op = "&&" if e.op == "and" else "||"
            return f"({self.cond(e.left)} {op} {self.cond(e.right)})"
        if t is M.Not:
            return f"(!{self.cond(e.operand)})"
        return f"fsw::truthy({self.value(e)})"

    def float_threshold(self, left: M.Expr, op: str, right: M.Expr):
        """binary32 R: `R(x) op c` for a float variable x and a literal c as
        integer threshold tests on x's stored bytes (autocode/thresholds.py)."""
        got = orient(left, op, right, self.threshold_var, self.known)
        if got is None:
            return None
        x, _, cv, op = got
        v = self.m.vars[x.var]
        if v.kind == M.TIME_IN_STATE or v.type.kind != "float":
            return None
        if self.sv_lock and v.kind == M.ELEMENT:
            return None
        if x.var in self.held:  # (never a NaN: what read_F32 returned)
            return float_key_test(op, cv, v.type.size, self.ptr(v), self.held[x.var])
        return float_key_test(op, cv, v.type.size, self.ptr(v))

    def threshold_var(self, e: M.Expr):
        """`e` when it reads a variable that is no folded constant."""
        return e if type(e) is M.Ref and e.var not in self.consts else None

    # -- integer fast paths, bit-identical to the R semantics ------------------
    def assign(self, var: int, e: M.Expr) -> str:
        """An assignment statement: `x = a + k` / `x = a - k` on integers take
        an integer path when a range check proves R would be exact."""
        const = self.constant_store(var, e)
        if const is not None:
            return const
        fast = self.int_add(var, e)
        if fast is None:
            fast = self.time_store(var, e)
        return fast if fast is not None else self.write(var, self.value(e))

    def time_store(self, var: int, e: M.Expr):
        """`x = T` for an integer x of at most 32 bits: R(T) converted to x's
        type is T saturated at x's maximum, rounded to R's precision first
        (fsw::machine_T_int, integer code only)."""
        target = self.m.vars[var]
        t = target.type
        if type(e) is not M.Ref or self.m.vars[e.var].kind != M.TIME_IN_STATE:
            return None
        if t.kind != "int" or t.size > 4 or (self.sv_lock and target.kind == M.ELEMENT):
            return None
        ctype = self._ctype(t)
        return (f"fsw::store<{ctype}>({self.ptr(target)}, static_cast<{ctype}>("
                f"fsw::machine_T_int({self.prefix}machine, {t.hi}UL)));")

    def constant_store(self, var: int, e: M.Expr):
        """`x = <literals only>`: the converted value is known now; store it."""
        if self.sv_lock and self.m.vars[var].kind == M.ELEMENT:
            return None
        try:
            x = evaluate(e, self.real, no_reads)
        except NotConstant:
            return None
        t = self.m.vars[var].type
        value = to_type(t, x)
        ptr = self.ptr(self.m.vars[var])
        if t.kind == "bool":
            return f"fsw::store_bool({ptr}, {'true' if value else 'false'});"
        if t.kind == "int":
            ctype = ("int" if t.signed else "uint") + f"{t.size * 8}_t"
            if t.signed and value == t.lo:
                literal = f"({t.lo + 1}LL - 1)"  # the minimum has no literal of its own
            else:
                literal = f"{value}{'LL' if t.signed else 'ULL'}"
            return f"fsw::store<{ctype}>({ptr}, static_cast<{ctype}>({literal}));"
        bits = struct.unpack("<I", struct.pack("<f", value))[0] if t.size == 4 else \
            struct.unpack("<Q", struct.pack("<d", value))[0]
        ctype = "uint32_t" if t.size == 4 else "uint64_t"
        return f"fsw::store<{ctype}>({ptr}, 0x{bits:0{t.size * 2}x}ULL);  // {value!r}"

    def int_add(self, var: int, e: M.Expr):
        target = self.m.vars[var]
        if type(e) is not M.Arith or e.op not in ("+", "-") or target.type.kind != "int":
            return None
        if self.sv_lock and target.kind == M.ELEMENT:
            return None
        got = add_operands(e, self.int_operand, self.exact_int_const)
        if got is None or got[0][1].kind != "int":
            return None
        (text, ta), k = got
        limit = exact_sum_limit(k, self.real)
        if limit < 0:
            return None
        # |a| <= limit: a, a + k and the result are all exact in R, so the
        # assignment is the integer a + k clamped to the target's range.
        tt = target.type
        ctype = ("int" if tt.signed else "uint") + f"{tt.size * 8}_t"
        guard = []
        if ta.signed and -limit > ta.lo:
            guard.append(f"a >= -{limit}LL")
        if limit < ta.hi:
            guard.append(f"a <= {limit}{'LL' if ta.signed else 'ULL'}")
        lo_r = max(ta.lo, -limit) + k
        hi_r = min(ta.hi, limit) + k
        # The sum in the narrowest signed type that holds every value it can
        # take (on an 8-bit MCU a 64-bit sum and compare are library calls
        # or long runs of instructions; the value is the same).
        if -(1 << 15) <= min(lo_r, tt.lo) and max(hi_r, tt.hi) < (1 << 15):
            rtype, sfx = "int16_t", ""
        elif -(1 << 31) <= min(lo_r, tt.lo) and max(hi_r, tt.hi) < (1 << 31):
            rtype, sfx = "int32_t", "L"
        else:
            rtype, sfx = "int64_t", "LL"
        r = f"static_cast<{rtype}>(a) + ({k}{sfx})"
        sum_ = f"const {rtype} r = static_cast<{rtype}>(static_cast<{rtype}>(a) + ({k}{sfx})); "
        if lo_r < tt.lo:
            r = f"(r < {tt.lo}{sfx} ? {tt.lo}{sfx} : r)" if hi_r <= tt.hi else \
                f"(r < {tt.lo}{sfx} ? {tt.lo}{sfx} : r > {tt.hi}{sfx} ? {tt.hi}{sfx} : r)"
            pre = sum_
        elif hi_r > tt.hi:
            r = f"(r > {tt.hi}{sfx} ? {tt.hi}{sfx} : r)"
            pre = sum_
        else:
            pre = ""
        ptr = self.ptr(target)
        fast = f"{pre}fsw::store<{ctype}>({ptr}, static_cast<{ctype}>({r}));"
        if self.real.bits == 32 and not ta.signed and abs(k) < (1 << 23):
            # Past the fast range binary32 still only rounds integers: round a
            # to 24 bits, add k, round again, saturate - with no float code.
            sat = "over" if tt.hi == (1 << 64) - 1 else f"(over || s > {tt.hi}ULL)"
            step = f"s += {k}ULL; s = fsw::round_to_f32_precision(s, over);" if k >= 0 else \
                f"s -= {-k}ULL; s = fsw::round_to_f32_precision(s, over);"
            slow = (f"bool over = false; uint64_t s = fsw::round_to_f32_precision(a, over); "
                    f"if (!over) {{ {step} }} "
                    f"fsw::store<{ctype}>({ptr}, {sat} ? static_cast<{ctype}>({tt.hi}{'LL' if tt.signed else 'ULL'}) "
                    f": static_cast<{ctype}>(s));")
        else:
            slow = self.write(var, f"({self.read_int(text, ta)} {'+' if k >= 0 else '-'} "
                                   f"{real_literal(float(abs(k)), self.real)})")
        if not guard:
            return f"{{ const {self._ctype(ta)} a = {text}; {fast} }}"
        return (f"{{ const {self._ctype(ta)} a = {text}; if ({' && '.join(guard)}) {{ {fast} }} "
                f"else {{ {slow} }} }}")

    @staticmethod
    def _ctype(t) -> str:
        return ("int" if t.signed else "uint") + f"{t.size * 8}_t"

    def read_int(self, text: str, t) -> str:
        """`a` (an integer local copy) as an R."""
        return f"fsw::real_from_{t.name}(a)"

    def int_operand(self, e: M.Expr):
        """(C++ integer expression, type) when `e` reads an integer or bool
        variable (or T) without conversion, else None."""
        if type(e) is not M.Ref or (self.sv_lock and self.m.vars[e.var].kind == M.ELEMENT):
            return None
        v = self.m.vars[e.var]
        if v.kind == M.TIME_IN_STATE:
            return f"fsw::machine_T({self.prefix}machine)", v.type
        if e.var in self.consts or v.type.kind == "float":
            return None
        if v.type.kind == "bool":
            return f"fsw::load_bool({self.ptr(v)})", v.type
        ctype = ("int" if v.type.signed else "uint") + f"{v.type.size * 8}_t"
        return f"fsw::load<{ctype}>({self.ptr(v)})", v.type

    def known(self, e: M.Expr):
        """The R value of a literal or of a local folded to a constant."""
        return known(e, self.real, self.consts)

    def exact_int_const(self, e: M.Expr):
        """The value of a known operand that is an integer of magnitude below
        2^p (p = 24 or 53), so that every integer near it is exact in R."""
        return exact_int(self.known(e), self.real)

    def int_compare(self, left: M.Expr, op: str, right: M.Expr):
        """`x op c` on the integer itself. Converting an integer to R is
        monotonic and exact near c, so `R(x) op c` equals `x op c`."""
        got = orient(left, op, right, self.int_operand, self.exact_int_const)
        if got is None:
            return None
        x, (text, t), c, op = got
        lo, hi = (0, 1) if t.kind == "bool" else (t.lo, t.hi)
        folded = folded_compare(op, c, lo, hi)
        if folded is not None:
            return "true" if folded else "false"
        if t.kind == "bool":
            return f"(static_cast<int>({text}) {op} {c})"
        if self.m.vars[x.var].kind == M.TIME_IN_STATE and 0 <= c < 0xFFFFFFFF:
            # T saturated to 32 bits tests the same against such a c (fsw_machine.h).
            return f"(fsw::machine_T32({self.prefix}machine) {op} {c}UL)"
        return f"({text} {op} {c}{'LL' if t.signed else 'ULL'})"


def sum_key(e: M.Arith, known) -> tuple | None:
    """What `x + c`, `x - c` or `c - x` (x a variable, c a known finite
    constant: `known` gives it) computes, as a key equal for every copy of
    it: (op, x, which side x is on, c's bits); None for any other
    arithmetic. A finite c: the sum of x's stored value (never a NaN) and c
    is never a NaN, so an F32 slot keeps it exactly."""
    if e.op not in ("+", "-"):
        return None
    for x, other, side in ((e.left, e.right, 0), (e.right, e.left, 1)):
        if type(x) is M.Ref:
            c = known(other)
            if c is not None and math.isfinite(c):
                return e.op, x.var, side, struct.pack("<d", c)
    return None


def float_key_test(op: str, cv: float, size: int, ptr: str, held: str | None = None):
    """binary32 R: `R(x) op c` for the float element or local x of `size`
    bytes at `ptr` and a literal c, as integer threshold tests on x's
    stored bytes (autocode/thresholds.py), or None when not expressible.
    `held`: a C++ local holding x's value (an F32's, never a NaN), tested
    instead of the bytes (fsw::f32_key_gt, f32_key_ge). An F32 no local
    holds is read by fsw::read_F32 (a NaN reads as +0) and its value tested
    so: the same result as its bytes' key (f32_read_key), with no routine of
    its own for the key (54 B of the core rocket's flash)."""
    if held is None and size == 4:
        read = f"fsw::read_F32({ptr})"
        test = _float_key_test(op, cv, size, ptr, read)
        if test is None or test.count(read) <= 1:
            return test
        body = _float_key_test(op, cv, size, ptr, "v")  # more than one term: the value read once
        return f"([&]() -> bool {{ const fsw::Real v = {read}; return {body}; }}())"
    return _float_key_test(op, cv, size, ptr, held)


def _float_key_test(op: str, cv: float, size: int, ptr: str, held: str | None):
    negate = op == "!="
    terms = tests("==" if negate else op, cv, size)
    if terms is None:
        return None
    nan_result = compare(op, 0.0, cv)  # a NaN element reads as 0
    bits = 64 if size == 8 else 32
    if all(isinstance(t, bool) for _, t in terms):
        # The same for every value (`x > 1e39` in binary32: never), so
        # also for 0, which is what a NaN reads as: a constant.
        value = all(t != neg for neg, t in terms) != negate
        assert value == nan_result
        return "true" if value else "false"
    parts = []
    for neg, t in terms:
        if isinstance(t, bool):
            test = "true" if t else "false"
        else:
            key, inclusive = t
            if held is not None:
                test = f"fsw::f32_key_{'ge' if inclusive else 'gt'}({held}, 0x{key:08x}UL)"
            else:
                test = f"k {'>=' if inclusive else '>'} 0x{key:0{bits // 4}x}{'UL' if bits == 32 else 'ULL'}"
        parts.append(f"!({test})" if neg else f"({test})")
    body = " && ".join(parts)
    if negate:
        body = f"!({body})"
    # A NaN reads as +0, and the key of +0 passes the terms exactly when
    # `0 op c` holds (nan_result): one key read covers both.
    zero = 1 << (bits - 1)
    at_zero = all((t if isinstance(t, bool) else (zero >= t[0] if t[1] else zero > t[0])) != neg
                  for neg, t in terms)
    assert (at_zero != negate) == nan_result, "threshold terms disagree with R at +0"
    if held is not None:
        return body if len(parts) == 1 and not negate else f"({body})"
    if len(parts) == 1 and not negate:
        return parts[0].replace("k ", f"fsw::f{bits}_read_key({ptr}) ", 1)
    return (f"([&]() -> bool {{ const uint{bits}_t k = fsw::f{bits}_read_key({ptr}); "
            f"return {body}; }}())")
