"""A machine as a bytecode image (docs/bytecode.md) for the runtime's VM
(firmware/src/fsw_vm.cpp): the same step as the C++ that emit/machine.py
generates, evaluated in R over the same runtime helpers.

Conditions compile to tests that jump, and the C++ emitter's integer
compares and adds, binary32 threshold tests and constant stores have typed
instructions of their own (JINT, JKEY, IADD, SETK): each is bit-identical
to plain R evaluation (the differential tests hold both to that), and saves
the VM the conversions to and from R. A local the machine never
writes (and that is no parameter) is a constant in the code, as in the
C++; `scriptable` keeps every local a variable, for a state script that
writes them (as the C++ emitter's own flag does). Compilation is a pure
function: the same machine gives the same bytes."""

from __future__ import annotations

import struct

from .. import model as M
from ..evaluate import NotConstant, compare, evaluate, local_values
from ..numeric import Real, to_type
from ..thresholds import tests
from .. import vmverify as V
from .common import value_bytes
from .fastpaths import (add_operands, exact_int, exact_sum_limit, folded_compare, folded_locals, known, no_reads,
                        orient)


class BytecodeError(Exception):
    """A machine the format cannot carry (yet), located at `line`:`col`."""

    def __init__(self, message: str, line: int = 0, col: int = 0):
        super().__init__(message)
        self.line, self.col = line, col


def local_order(m: M.Machine) -> list[M.Var]:
    """The image's locals: every local (parameters included), in
    declaration order, packed little-endian in the VM's locals buffer."""
    return [v for v in m.vars if v.kind == M.LOCAL]


def local_offsets(m: M.Machine) -> dict[int, int]:
    offs, at = {}, 0
    for v in local_order(m):
        offs[v.index] = at
        at += v.type.size
    return offs


def window_ram(m: M.Machine, real: Real, idx_bytes: int = 4, align: int = 8) -> int:
    """An upper bound of the VM's RAM for `m` (fsw_vm.cpp's window_size with
    indices of `idx_bytes` and parts aligned to `align`, plus the locals)."""
    def up(x: int) -> int:
        return (x + align - 1) // align * align
    r = real.bits // 8
    ext = lambda n: up(4 * idx_bytes) + up(n * r) + up(n * idx_bytes)  # noqa: E731
    size = 0
    for w in m.windows:
        n = w.size
        size += {"avg": up(2 * r + 4 * idx_bytes) + up(n * r), "min": ext(n), "max": ext(n),
                 "range": 2 * ext(n), "median": up(2 * idx_bytes) + 2 * up(n * r)}[w.func]
    return size + sum(v.type.size for v in local_order(m))


def stack_depth(e: M.Expr) -> int:
    """Operand-stack entries the code of `e` needs (the compiler's shapes:
    a binary operator holds its left value while its right one is built;
    `and`/`or` pop the left value before the right one)."""
    t = type(e)
    if t in (M.Neg, M.Not):
        return stack_depth(e.operand)
    if t in (M.Arith, M.Cmp):
        return max(stack_depth(e.left), 1 + stack_depth(e.right))
    if t is M.ChainCmp:
        return max(max(stack_depth(a), 1 + stack_depth(b)) for a, b in zip(e.operands, e.operands[1:]))
    if t is M.Logic:
        return max(stack_depth(e.left), stack_depth(e.right))
    return 1


class _Code:
    """Code of one machine: bytes, with forward jumps patched once their
    target is known."""

    def __init__(self, m: M.Machine, real: Real, elem_index: dict[str, int], loc_index: dict[int, int],
                 consts: dict[int, float]):
        self.m, self.real = m, real
        self.consts = consts  # locals read as constants: their R values
        self.b = bytearray()
        self.starts: list[tuple[int, int, int]] = []  # (code offset, line, col) of each statement, in order
        self.elem_index, self.loc_index = elem_index, loc_index
        self.loc_offset = local_offsets(m)
        self.fmt = "<f" if real.bits == 32 else "<d"

    def op(self, *bs: int) -> None:
        self.b += bytes(bs)

    def jump(self, op: int) -> int:
        self.b += bytes((op, 0, 0))
        return len(self.b)

    def land(self, after: int) -> None:
        d = len(self.b) - after
        if d > 0xFFFF:
            raise BytecodeError("a jump longer than 65535 bytes: not supported yet")
        self.b[after - 2:after] = struct.pack("<H", d)

    # -- expressions: each leaves one R on the stack -----------------------------
    def top(self, e: M.Expr) -> None:
        """A whole expression (a statement's or a window's)."""
        self.check_depth(e)
        self.value(e)

    @staticmethod
    def check_depth(e: M.Expr) -> None:
        """Refuses an expression that needs more of the operand stack than
        the VM has."""
        need = stack_depth(e)
        if need > V.VM_STACK:
            raise BytecodeError(f"this expression needs an operand stack of {need} values; the VM has "
                                f"{V.VM_STACK} (FSW_VM_STACK): split it over locals (not supported yet)",
                                e.line, e.col)

    def value(self, e: M.Expr) -> None:
        t = type(e)
        if t is M.Const:
            self.op(V.CONST)
            self.b += struct.pack(self.fmt, self.real.literal(e.text))
        elif t is M.Ref and e.var in self.consts:
            self.op(V.CONST)
            self.b += struct.pack(self.fmt, self.consts[e.var])
        elif t is M.Ref:
            v = self.m.vars[e.var]
            if v.kind == M.TIME_IN_STATE:
                self.op(V.LDT)
            elif v.kind == M.ELEMENT:
                self.op(V.LDE, *struct.pack("<HB", self.elem_index[v.name], V.TYPE_CODES[v.type.name]))
            else:
                self.op(V.LDL, *struct.pack("<H", self.loc_index[v.index]))
        elif t is M.Neg:
            self.value(e.operand)
            self.op(V.NEG)
        elif t is M.Arith:
            self.value(e.left)
            self.value(e.right)
            self.op(V.ARITH[e.op])
        elif t is M.Roll:
            self.op(V.ROLL, e.window)
        elif t is M.Cmp:
            self.value(e.left)
            self.value(e.right)
            self.op(V.COMPARE[e.op])
        elif t is M.ChainCmp:
            # Pair by pair with `and`: an operand has no side effect, so a middle
            # one read twice is the value the C++ reads once.
            ends = []
            for k, op in enumerate(e.ops):
                self.value(M.Cmp(op, e.operands[k], e.operands[k + 1], e.line, e.col))
                if k < len(e.ops) - 1:
                    ends.append(self.jump(V.AND))
            for after in ends:
                self.land(after)
        elif t is M.Logic:
            self.value(e.left)
            after = self.jump(V.AND if e.op == "and" else V.OR)
            self.truth(e.right)
            self.land(after)
        elif t is M.Not:
            self.value(e.operand)
            self.op(V.NOT)
        else:  # pragma: no cover - the model has no other expression
            raise BytecodeError(f"{t.__name__}: not supported yet", e.line, e.col)

    # -- conditions: a tree of tests, compiled to jumps ---------------------------
    # ("const", b) | ("key", ref, size, key, inclusive) | ("int", ref, cmp, c bytes)
    # | ("cmp", op, left, right) | ("value", e) | ("not", n) | ("and"|"or", a, b)
    def ref(self, i: int) -> bytes | None:
        """A typed instruction's variable `i` (where, u16, and type, u8:
        the element's byte offset in the state vector, or the local's in the
        locals plus REF_LOCAL), or None (T, an element of a locked state
        vector, an offset past the encoding)."""
        v = self.m.vars[i]
        if v.kind == M.ELEMENT:
            at = self.m.sv.elements[self.elem_index[v.name]].offset
            if at >= V.REF_LOCAL or self.m.sv.lock:
                return None
        elif v.kind == M.LOCAL:
            at = V.REF_LOCAL + self.loc_offset[v.index]
            if at >= V.REF_T:
                return None
        else:
            return None
        return struct.pack("<HB", at, V.TYPE_CODES[v.type.name])

    def known(self, e: M.Expr):
        """The R value of a literal or of a local read as a constant."""
        return known(e, self.real, self.consts)

    def exact_int_const(self, e: M.Expr):
        """A known integer of magnitude below 2^p (p = R's precision)."""
        return exact_int(self.known(e), self.real)

    def int_var(self, e: M.Expr):
        """The integer or bool variable (or T) `e` reads, or None."""
        if type(e) is not M.Ref:
            return None
        v = self.m.vars[e.var]
        if v.kind == M.TIME_IN_STATE:
            return v
        if v.type.kind == "float" or e.var in self.consts or self.ref(e.var) is None:
            return None
        return v

    def int_test(self, left: M.Expr, op: str, right: M.Expr):
        """`x op c` on the integer itself, as the C++ emitter's int_compare:
        a node, or None."""
        got = orient(left, op, right, self.int_var, self.exact_int_const)
        if got is None:
            return None
        _, v, c, op = got
        t = v.type
        lo, hi = (0, 1) if t.kind == "bool" else (t.lo, t.hi)
        folded = folded_compare(op, c, lo, hi)
        if folded is not None:
            return ("const", folded)
        if v.kind == M.TIME_IN_STATE:
            if not 0 <= c < 0xFFFFFFFF:
                return None
            return ("int", V.T_VAR, V.CMP_CODES[op], struct.pack("<I", c))
        cb = bytes((c,)) if t.kind == "bool" else c.to_bytes(t.size, "little", signed=t.signed)
        return ("int", self.ref(v.index), V.CMP_CODES[op], cb)

    def key_test(self, left: M.Expr, op: str, right: M.Expr):
        """binary32 R: `R(x) op c` for a float variable x as threshold tests
        on x's stored bytes (autocode/thresholds.py), as the C++ emitter's
        float_key_test: a node, or None."""
        if self.real.bits != 32:
            return None
        got = orient(left, op, right, lambda e: e if type(e) is M.Ref and e.var not in self.consts else None,
                     self.known)
        if got is None:
            return None
        x, _, cv, op = got
        v = self.m.vars[x.var]
        if v.kind == M.TIME_IN_STATE or v.type.kind != "float" or self.ref(x.var) is None:
            return None
        negate = op == "!="
        terms = tests("==" if negate else op, cv, v.type.size)
        if terms is None:
            return None
        node = None
        for neg, t in terms:
            term = ("const", t) if isinstance(t, bool) else ("key", self.ref(x.var), v.type.size, *t)
            term = ("not", term) if neg else term
            node = term if node is None else ("and", node, term)
        node = ("not", node) if negate else node
        folded = _simplify(node)
        # A NaN reads as +0 (its key is +0's): one key read covers both.
        assert folded[0] != "const" or folded[1] == compare(op, 0.0, cv)
        return folded

    def tree(self, e: M.Expr):
        t = type(e)
        if t is M.Cmp:
            node = self.int_test(e.left, e.op, e.right)
            if node is None:
                node = self.key_test(e.left, e.op, e.right)
            return node if node is not None else ("cmp", e.op, e.left, e.right)
        if t is M.ChainCmp:
            node = None
            for k, op in enumerate(e.ops):
                pair = self.tree(M.Cmp(op, e.operands[k], e.operands[k + 1], e.line, e.col))
                node = pair if node is None else ("and", node, pair)
            return node
        if t is M.Logic:
            return (e.op, self.tree(e.left), self.tree(e.right))
        if t is M.Not:
            return ("not", self.tree(e.operand))
        return ("value", e)

    def jumps(self, n, sense: bool) -> list[int]:
        """Code that jumps when `n` is `sense` and falls through otherwise:
        the jumps to land (a simplified tree: no constant inside)."""
        kind = n[0]
        if kind == "not":
            return self.jumps(n[1], not sense)
        if kind in ("and", "or"):
            if (kind == "and") != sense:  # a and b false / a or b true: either does
                return self.jumps(n[1], sense) + self.jumps(n[2], sense)
            skip = self.jumps(n[1], not sense)
            out = self.jumps(n[2], sense)
            for after in skip:
                self.land(after)
            return out
        if kind == "key":
            _, ref, size, key, inclusive = n
            flags = (V.KEY_INCLUSIVE if inclusive else 0) | (V.KEY_JUMP_IF if sense else 0)
            self.op(V.JKEY, *ref, flags)
            self.b += key.to_bytes(size, "little")
            return [self.jump_offset()]
        if kind == "int":
            _, ref, cmp, cb = n
            self.op(V.JINT, *ref, cmp | (V.JUMP_IF if sense else 0))
            self.b += cb
            return [self.jump_offset()]
        if kind == "cmp":
            _, op, left, right = n
            self.check_depth(M.Cmp(op, left, right, left.line, left.col))
            self.value(left)
            self.value(right)
            self.op(V.JCMP, V.CMP_CODES[op] | (V.JUMP_IF if sense else 0))
            return [self.jump_offset()]
        assert kind == "value", n
        self.top(n[1])
        if sense:
            self.op(V.NOT)
        return [self.jump(V.JF)]

    def jump_offset(self) -> int:
        self.b += bytes(2)
        return len(self.b)

    # -- stores with typed instructions ---------------------------------------------
    def fast_assign(self, var: int, e: M.Expr) -> bool:
        """`x = <literals>` (SETK) and `x = a + k` / `x = a - k` on integers
        (IADD), as the C++ emitter's constant_store and int_add; False when
        neither applies."""
        target = self.m.vars[var]
        ref = self.ref(var)
        if ref is None:
            return False
        try:
            x = evaluate(e, self.real, no_reads)
        except NotConstant:
            x = None
        if x is not None:
            self.op(V.SETK, *ref)
            self.b += value_bytes(target.type, to_type(target.type, x))
            return True
        if type(e) is not M.Arith or e.op not in ("+", "-") or target.type.kind != "int":
            return False
        got = add_operands(e, self.int_var, self.exact_int_const)
        if got is None or got[0].kind == M.TIME_IN_STATE or got[0].type.kind != "int":
            return False
        a, k = got
        if not -(1 << 31) <= k < (1 << 31) or exact_sum_limit(k, self.real) < 0:
            return False
        self.op(V.IADD, *ref, *self.ref(a.index), *struct.pack("<i", k))
        return True

    def truth(self, e: M.Expr) -> None:
        """`e` as a truth value, 1 or 0 (what `and`/`or` leave)."""
        self.value(e)
        if type(e) not in (M.Cmp, M.ChainCmp, M.Logic, M.Not):
            self.op(V.TRUTH)

    # -- statements ---------------------------------------------------------------
    def block(self, stmts) -> bool:
        """The statements; True when every path ends in a goto (what follows
        is never reached, and is not emitted, as in the C++)."""
        for st in stmts:
            self.starts.append((len(self.b), st.line, st.col))
            t = type(st)
            if t is M.Assign:
                if self.fast_assign(st.var, st.expr):
                    continue
                self.top(st.expr)
                v = self.m.vars[st.var]
                if v.kind == M.ELEMENT:
                    self.op(V.STE, *struct.pack("<HB", self.elem_index[v.name], V.TYPE_CODES[v.type.name]))
                elif v.kind == M.LOCAL:
                    self.op(V.STL, *struct.pack("<H", self.loc_index[v.index]))
                else:
                    raise BytecodeError("an assignment to T", st.line, st.col)
            elif t is M.Goto:
                self.op(V.GOTO, st.state)
                return True
            else:
                node = _simplify(self.tree(st.cond))
                if node[0] == "const":  # the C++ compiler drops the branch never taken too
                    if self.block(st.then if node[1] else st.orelse):
                        return True
                    continue
                to_else = self.jumps(node, False)
                then_ends = self.block(st.then)
                if not st.orelse:
                    for after in to_else:
                        self.land(after)
                    continue
                to_end = None if then_ends else self.jump(V.JMP)
                for after in to_else:
                    self.land(after)
                else_ends = self.block(st.orelse)
                if to_end is not None:
                    self.land(to_end)
                elif else_ends:
                    return True
        return False


def _simplify(n):
    """A condition tree with its constants folded away (or one constant):
    operands have no side effects, so `a and false` is false."""
    kind = n[0]
    if kind == "not":
        x = _simplify(n[1])
        return ("const", not x[1]) if x[0] == "const" else ("not", x)
    if kind in ("and", "or"):
        a, b = _simplify(n[1]), _simplify(n[2])
        absorbing = kind == "or"  # the value that decides: true for or, false for and
        for x, other in ((a, b), (b, a)):
            if x[0] == "const":
                return x if x[1] == absorbing else other
        return (kind, a, b)
    return n


def compile_machine(m: M.Machine, real: Real, scriptable: bool = False) -> bytes:
    """The image of `m` for a runtime whose R is `real`. BytecodeError for
    what the format cannot carry; the result passes vmverify.verify.
    `scriptable`: for a runner that may write the locals between steps (a
    state script), so none is read as a constant."""
    if len(m.states) > 255:
        raise BytecodeError(f"{len(m.states)} states: an image holds at most 255 (not supported yet)",
                            m.states[255].line)
    if len(m.windows) > 255:
        raise BytecodeError(f"{len(m.windows)} roll_* windows: an image holds at most 255 (not supported yet)",
                            m.windows[255].line, m.windows[255].col)
    for k, w in enumerate(m.windows):
        if w.size > 0xFFFF:
            raise BytecodeError(f"roll_{w.func} over {w.size} samples: an image holds windows of at most "
                                f"65535 (not supported yet)", w.line, w.col)
        assert w.index == k, "windows are listed in index order"
    if len(m.sv.elements) > 0xFFFF:
        raise BytecodeError("a state vector of more than 65535 elements: not supported yet")
    elem_index = {e.name: k for k, e in enumerate(m.sv.elements)}
    locs = local_order(m)
    loc_index = {v.index: k for k, v in enumerate(locs)}
    offs = local_offsets(m)
    values = local_values(m, real)
    init = b"".join(value_bytes(v.type, values[v.index]) for v in locs)
    if len(init) > 0xFFFF or len(locs) > 0xFFFF:
        raise BytecodeError("more than 65535 bytes of locals: not supported yet")
    code = _Code(m, real, elem_index, loc_index, folded_locals(m, real, scriptable))
    offsets = []
    for st in m.states:
        row = []
        for label in ("entry", "step", "exit"):
            stmts = getattr(st, label)
            if not stmts:
                row.append(V.NONE)
                continue
            row.append(len(code.b))
            if not code.block(stmts):
                code.op(V.END)
        offsets.append(row)
    prelude = len(code.b)
    for w in m.windows:
        code.top(w.arg)
        code.op(V.WPUSH, w.index)
    code.op(V.END)
    if len(code.b) > 0xFFFF:  # located at the first statement past the limit (the windows' prelude: the last)
        past = [(ln, c) for at, ln, c in code.starts if at > 0xFFFF] or [(ln, c) for _at, ln, c in code.starts[-1:]]
        line, col = past[0] if past else (0, 0)
        raise BytecodeError(f"{len(code.b)} bytes of code: an image holds at most 65535 (not supported yet)",
                            line, col)
    from ..schema import schema_hash
    g, s = m.vars[m.g], m.vars[m.s]
    head = bytearray(V.MAGIC + bytes((V.VERSION, real.bits // 8, V.FLAG_LOCK if m.sv.lock else 0, 0)))
    head += struct.pack("<IHHHBBHHHH", schema_hash(m.sv), len(m.sv.elements),
                        m.sv.elements[elem_index[g.name]].offset, m.sv.elements[elem_index[s.name]].offset,
                        len(m.states), len(m.windows), len(locs), len(init), prelude, len(code.b))
    assert len(head) == V.HEADER
    body = b"".join(struct.pack("<HHH", *row) for row in offsets)
    body += b"".join(struct.pack("<BH", V.TYPE_CODES[v.type.name], offs[v.index]) for v in locs)
    body += b"".join(struct.pack("<BBH", V.WINDOW_FUNCS[w.func], 0, w.size) for w in m.windows)
    image = bytearray(head + body + init + bytes(code.b))
    if len(image) > 0xFFFF:
        raise BytecodeError(f"an image of {len(image)} bytes: at most 65535 (not supported yet)")
    layout = V.layout_of(m.sv)
    reason, deepest = V.code_depth(bytes(image), layout)
    assert deepest <= V.VM_STACK, "stack_depth() bounds every expression"
    image[7] = deepest
    if V.verify(bytes(image), layout, real.bits // 8) == V.TOO_NESTED:
        off = V.too_nested_at(bytes(image), layout)  # the jump too many: in the last statement begun before it
        before = [(ln, c) for at, ln, c in code.starts if off is not None and at <= off]
        line, col = before[-1] if before else (0, 0)
        raise BytecodeError(f"conditions nested deeper than the verifier tracks ({V.VM_PENDING} forward jumps "
                            f"pending at once, FSW_VM_PENDING): not supported yet", line, col)
    return bytes(image)
