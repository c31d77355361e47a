"""A machine as a bytecode image (docs/bytecode.md) for the runtime's VM
(firmware/src/fsw_vm.cpp): the same step as the C++ that emit/machine.py
generates, evaluated in R over the same runtime helpers.

The C++ emitter's fast paths (integer compares and adds, binary32 threshold
tests, folded locals, x * 2^-k for x / 2^k) are bit-identical to plain R
evaluation (the differential tests hold them to that), so the image
carries the plain R form of every expression. Compilation is a pure
function: the same machine gives the same bytes."""

from __future__ import annotations

import struct

from .. import model as M
from ..evaluate import local_values
from ..numeric import Real
from .. import vmverify as V
from .common import value_bytes


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
        size += {"avg": up(2 * r + 2 * idx_bytes) + up(n * r), "min": ext(n), "max": ext(n),
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

    def __init__(self, m: M.Machine, real: Real, elem_index: dict[str, int], loc_index: dict[int, int]):
        self.m, self.real = m, real
        self.b = bytearray()
        self.elem_index, self.loc_index = elem_index, loc_index
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
        """A whole expression (a statement's or a window's), refused where
        it needs more of the operand stack than the VM has."""
        need = stack_depth(e)
        if need > V.VM_STACK:
            raise BytecodeError(f"this expression needs an operand stack of {need} values; the VM has "
                                f"{V.VM_STACK} (FSW_VM_STACK): split it over locals (not supported yet)",
                                e.line, e.col)
        self.value(e)

    def value(self, e: M.Expr) -> None:
        t = type(e)
        if t is M.Const:
            self.op(V.CONST)
            self.b += struct.pack(self.fmt, self.real.literal(e.text))
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
            t = type(st)
            if t is M.Assign:
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
                self.top(st.cond)
                to_else = self.jump(V.JF)
                then_ends = self.block(st.then)
                if not st.orelse:
                    self.land(to_else)
                    continue
                to_end = None if then_ends else self.jump(V.JMP)
                self.land(to_else)
                else_ends = self.block(st.orelse)
                if to_end is not None:
                    self.land(to_end)
                elif else_ends:
                    return True
        return False


def compile_machine(m: M.Machine, real: Real) -> bytes:
    """The image of `m` for a runtime whose R is `real`. BytecodeError for
    what the format cannot carry; the result passes vmverify.verify."""
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
    code = _Code(m, real, elem_index, loc_index)
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
    if len(code.b) > 0xFFFF:
        raise BytecodeError(f"{len(code.b)} bytes of code: an image holds at most 65535 (not supported yet)")
    from ..schema import schema_hash
    g, s = m.vars[m.g], m.vars[m.s]
    head = bytearray(V.MAGIC + bytes((V.VERSION, real.bits // 8, V.FLAG_LOCK if m.sv.lock else 0, 0)))
    head += struct.pack("<IHHHBBHHHH", schema_hash(m.sv), len(m.sv.elements), elem_index[g.name],
                        elem_index[s.name], len(m.states), len(m.windows), len(locs), len(init), prelude,
                        len(code.b))
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
        raise BytecodeError(f"conditions nested deeper than the verifier tracks ({V.VM_PENDING} forward jumps "
                            f"pending at once, FSW_VM_PENDING): not supported yet")
    return bytes(image)
