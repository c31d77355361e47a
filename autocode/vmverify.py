"""The bytecode image's format constants and its verifier, the host's copy
of firmware/src/fsw_vm.cpp's vm_verify: the same rules in the same order,
returning the same reason codes (docs/bytecode.md, "The verifier").
`fsw compile` runs it before it writes an image."""

from __future__ import annotations

import struct
from dataclasses import dataclass

from . import model as M

MAGIC = b"FSMB"
VERSION = 3
HEADER = 28
NONE = 0xFFFF  # a state without this block
FLAG_LOCK = 1
VM_STACK = 12  # FSW_VM_STACK's default
VM_PENDING = 16  # FSW_VM_PENDING's default

# Opcodes (docs/bytecode.md, "Instructions").
END, GOTO, JMP, JF, AND, OR = 0x00, 0x01, 0x02, 0x03, 0x04, 0x05
CONST, LDE, STE, LDL, STL, LDT, ROLL, WPUSH = 0x06, 0x07, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D
NEG, ADD, SUB, MUL, DIV = 0x10, 0x11, 0x12, 0x13, 0x14
LT, LE, GT, GE, EQ, NE, NOT, TRUTH = 0x18, 0x19, 0x1A, 0x1B, 0x1C, 0x1D, 0x1E, 0x1F
ARITH = {"+": ADD, "-": SUB, "*": MUL, "/": DIV}
COMPARE = {"<": LT, "<=": LE, ">": GT, ">=": GE, "==": EQ, "!=": NE}
# Typed tests and stores (version 2): the generated code's fast paths.
JKEY, JINT, SETK, IADD, JCMP = 0x20, 0x21, 0x22, 0x23, 0x24
# A typed instruction's variable (version 3): where, u16, and type, u8: an
# element's byte offset in the state vector, a local's byte offset in the
# locals plus REF_LOCAL, or REF_T (T, JINT only; U64's type code).
REF_LOCAL = 0x8000
REF_T = 0xFFFF
VAR_BYTES = 3
T_VAR = bytes((0xFF, 0xFF, 7))  # T as a typed instruction's variable
TYPE_T = 0xFE
JUMP_IF = 0x80  # JINT/JCMP: jump when the test holds (else when it fails)
KEY_INCLUSIVE, KEY_JUMP_IF = 1, 2  # JKEY's flags
CMP_CODES = {"<": 0, "<=": 1, ">": 2, ">=": 3, "==": 4, "!=": 5}

WINDOW_FUNCS = {"avg": 0, "min": 1, "max": 2, "range": 3, "median": 4}
# Element types as the runtime numbers them (fsw_types.h ElemType).
TYPE_CODES = {n: k for k, n in enumerate(("I8", "I16", "I32", "I64", "U8", "U16", "U32", "U64",
                                          "F32", "F64", "bool"))}
TYPE_SIZES = (1, 2, 4, 8, 1, 2, 4, 8, 4, 8, 1)

# Reason codes (fsw_vm.h VmReason), with what each means.
REASONS = {
    0: "ok",
    1: "bad magic (not a state-machine image)",
    2: "a format version or flags this runtime does not read",
    3: "compiled for the other evaluation type (f32/f64)",
    4: "bound to another state vector (schema hash or element count)",
    5: "the lengths in the header do not add up to the image",
    6: "an element index or offset not the layout's, or its type not the layout's",
    7: "a local index out of range, or a local outside the locals",
    8: "no states, a state index out of range, or a code offset out of range",
    9: "a window index, function or size out of range, or pushed out of order",
    10: "a jump backward, out of its block, or into an instruction",
    11: "stack underflow, deeper than the VM's stack or than declared, or not empty at the end",
    12: "an unknown opcode, or an operand past the code",
    13: "a block that does not end, unreachable code, or an offset not at a block's start",
    14: "goto outside .entry/.step, or a window push outside the prelude",
    15: "more pending forward jumps than the verifier tracks",
    16: "the RAM buffer is smaller than the image needs",
    17: "the state mask after the image is not a bit per state of it, or no state in it allows a switch",
    18: "a window function, value type or lock the board's VM was built without",
}
(OK, BAD_MAGIC, BAD_VERSION, BAD_REAL, BAD_SCHEMA, BAD_SIZE, BAD_ELEMENT, BAD_LOCAL, BAD_STATE,
 BAD_WINDOW, BAD_JUMP, BAD_STACK, BAD_OPCODE, BAD_END, BAD_PLACE, TOO_NESTED, NO_RAM, BAD_MASK,
 NO_FEATURE) = range(19)


# What a VM runs beyond what every image may use (fsw_vm.h VmFeature): a
# window function (bit 1 << its WINDOW_FUNCS code), values of a type other
# than U32, U64 and bool, a locked state vector. A board's VM has those of
# its application (features_of); libfswsm's has every one.
FEAT_F32, FEAT_F64, FEAT_LOCK = 0x20, 0x40, 0x80
ALL_FEATURES = 0x3FFF
# the bit of each type's values (0: always taken)
TYPE_FEATURES = {"I8": 0x100, "I16": 0x200, "I32": 0x400, "I64": 0x800, "U8": 0x1000, "U16": 0x2000,
                 "U32": 0, "U64": 0, "F32": FEAT_F32, "F64": FEAT_F64, "bool": 0}
_TYPE_BIT = tuple(TYPE_FEATURES[name] for name in TYPE_CODES)  # by type code


def takes(type_code: int, features: int) -> bool:
    """Whether a VM of `features` takes values of this type (fsw_vm.cpp takes())."""
    if type_code >= len(TYPE_SIZES):
        return True  # (an unknown type is refused by its own rule)
    bit = _TYPE_BIT[type_code]
    return bit == 0 or bool(features & bit)


def features_of(sv: M.StateVector, m: M.Machine) -> int:
    """The features of the VM built into an application whose state vector
    is `sv` and whose replaceable machine is `m`: the types of the vector's
    elements and of the machine's locals, the machine's window functions,
    the vector's lock option (autocode/emit/app.py writes them as
    fsw::vm_features)."""
    types = {e.type.name for e in sv.elements} | {v.type.name for v in m.vars if v.kind == M.LOCAL}
    f = FEAT_LOCK if sv.lock else 0
    for t in types:
        f |= TYPE_FEATURES[t]
    for w in m.windows:
        f |= 1 << WINDOW_FUNCS[w.func]
    return f


# Every feature by the name `[reload] vm` takes (feature_names' words).
FEATURE_BITS = {**{f"roll_{name}": 1 << code for name, code in WINDOW_FUNCS.items()},
                **{t: bit for t, bit in TYPE_FEATURES.items() if bit}}


def board_features(app) -> int:
    """The features of an application's VM: those of its state vector and
    replaceable machine (features_of) and those its `[reload] vm` names
    (`all`: every one, as libfswsm's VM)."""
    rl = app.reload
    if "all" in rl.vm:
        return ALL_FEATURES
    f = features_of(app.sv, app.machines[rl.machine])
    for name in rl.vm:
        f |= FEATURE_BITS[name]
    return f


def feature_names(features: int) -> list[str]:
    """What `features` holds, in the words of a machine: `roll_avg`...,
    the types beyond U32, U64 and bool, lock."""
    return [name for name, bit in FEATURE_BITS.items() if features & bit] + (["lock"] if features & FEAT_LOCK else [])


@dataclass(frozen=True)
class Layout:
    """The state vector an image is bound to: (offset, type code) per
    element in layout order, and its schema hash."""
    elems: tuple[tuple[int, int], ...]
    schema: int


def layout_of(sv: M.StateVector) -> Layout:
    from .schema import schema_hash
    return Layout(tuple((e.offset, TYPE_CODES[e.type.name]) for e in sv.elements), schema_hash(sv))


def operand_bytes(op: int, real: int) -> int | None:
    if op in (END, LDT, NEG, ADD, SUB, MUL, DIV, LT, LE, GT, GE, EQ, NE, NOT, TRUTH):
        return 0
    if op in (GOTO, ROLL, WPUSH):
        return 1
    if op in (JMP, JF, AND, OR, LDL, STL):
        return 2
    if op in (LDE, STE):
        return 3
    if op == CONST:
        return real
    if op in (JKEY, JINT, SETK, IADD):
        return VAR_BYTES  # the variable; the rest is its type's
    if op == JCMP:
        return 3
    return None


def _typed_operands(op: int, t: int) -> int:
    """Bytes of a typed instruction's operands after its variable of type `t`
    (TYPE_T: T): a test's flags or comparison, its constant and its jump
    offset; SETK's value; IADD's source and constant."""
    if op == IADD:
        return VAR_BYTES + 4
    size = 4 if t == TYPE_T else TYPE_SIZES[t]
    return size if op == SETK else 1 + size + 2


def _wrong_type(ref: int) -> int:
    return BAD_LOCAL if REF_LOCAL <= ref != REF_T else BAD_ELEMENT


def _ref_type(code: bytes, a: int, p: "Parts", layout: Layout, lock: bool, features: int) -> tuple[int, int]:
    """(reason, type code) of the typed instruction's variable at code
    offset `a` (TYPE_T: T): T's type is U64's; an element's offset and type
    an element's of the layout (the first at that offset); a local's type
    one the VM takes, its bytes within the locals'."""
    ref, t = _u16(code, a), code[a + 2]
    if ref == REF_T:
        return (OK, TYPE_T) if t == TYPE_CODES["U64"] else (BAD_ELEMENT, 0)
    if ref >= REF_LOCAL:
        if t >= len(TYPE_SIZES) or ref - REF_LOCAL > p.loc_size - TYPE_SIZES[t]:
            return BAD_LOCAL, 0
        if not takes(t, features):
            return NO_FEATURE, 0
        return OK, t
    if lock:
        return BAD_ELEMENT, 0
    at = next((e for e in layout.elems if e[0] == ref), None)
    if at is None or at[1] != t:
        return BAD_ELEMENT, 0
    return OK, t


@dataclass
class Parts:
    states: int
    windows: int
    locals: int
    loc_size: int
    prelude: int
    code_size: int
    st: int  # byte offsets in the image
    loc: int
    win: int
    init: int
    code: int
    total: int


def parts(im: bytes) -> Parts:
    states, windows = im[18], im[19]
    nloc, loc_size, prelude, code_size = struct.unpack_from("<HHHH", im, 20)
    st = HEADER
    loc = st + 6 * states
    win = loc + 3 * nloc
    init = win + 4 * windows
    code = init + loc_size
    return Parts(states, windows, nloc, loc_size, prelude, code_size, st, loc, win, init, code, code + code_size)


def _u16(im: bytes, at: int) -> int:
    return im[at] | (im[at + 1] << 8)


def _verify_code(im: bytes, p: Parts, layout: Layout, stack: int, pending: int,
                 nested: list | None = None, features: int = ALL_FEATURES) -> tuple[int, int]:
    """(reason, deepest stack) of the code pass. `nested`: gets the code
    offset of the jump that made too many pending (TOO_NESTED)."""
    real = im[5]
    offsets = [_u16(im, p.st + 2 * k) for k in range(3 * p.states)]
    declared = 1 if p.prelude != NONE else 0
    for off in offsets:
        if off == NONE:
            continue
        if off >= p.code_size:
            return BAD_STATE, 0
        declared += 1
    if p.prelude == NONE or p.prelude >= p.code_size:
        return BAD_END, 0
    moving_offs = [off for k, off in enumerate(offsets) if k % 3 != 2]
    still_offs = [off for k, off in enumerate(offsets) if k % 3 == 2]
    pend: list[list[int]] = []
    depth = deepest = pushed = 0
    reachable, at_start, may_move, prelude = True, True, False, False
    matched = pc = 0
    code = im[p.code:p.code + p.code_size]
    while pc < p.code_size:
        if at_start:
            moving = moving_offs.count(pc)
            still = still_offs.count(pc) + (p.prelude == pc)
            if moving and still:
                return BAD_PLACE, deepest
            matched += moving + still
            may_move = moving != 0
            prelude = p.prelude == pc
            pushed = 0
            at_start = False
            reachable = True
        k = 0
        while k < len(pend):  # the same order as the C loop (swap-remove)
            target, d = pend[k]
            if target < pc:
                return BAD_JUMP, deepest
            if target == pc:
                if pc in moving_offs or pc in still_offs or pc == p.prelude:
                    return BAD_JUMP, deepest  # into another block
                if reachable and depth != d:
                    return BAD_STACK, deepest
                depth = d
                reachable = True
                pend[k] = pend[-1]
                pend.pop()
            else:
                k += 1
        if not reachable:
            return BAD_END, deepest
        op = code[pc]
        n = operand_bytes(op, real)
        if n is None or pc + 1 + n > p.code_size:
            return BAD_OPCODE, deepest
        a = pc + 1
        pc += 1 + n
        pops = pushes = 0
        ends = False
        if op == END:
            ends = True
        elif op == GOTO:
            if not may_move:
                return BAD_PLACE, deepest
            if code[a] >= p.states:
                return BAD_STATE, deepest
            ends = True
        elif op in (JMP, JF, AND, OR):
            pops = 0 if op == JMP else 1
            if depth < pops:
                return BAD_STACK, deepest
            target = pc + _u16(code, a)
            if target >= p.code_size:
                return BAD_JUMP, deepest
            if len(pend) == pending:
                if nested is not None:
                    nested.append(a - 1)
                return TOO_NESTED, deepest
            pend.append([target, depth - 1 if op == JF else depth])
            if op == JMP:
                reachable = False
        elif op in (JKEY, JINT, SETK, IADD):
            if depth != 0:
                return BAD_STACK, deepest  # (the VM runs them outside the stack's code)
            ref = _u16(code, a)
            lock = bool(im[6] & FLAG_LOCK)
            why, t = _ref_type(code, a, p, layout, lock, features)
            if why != OK:
                return why, deepest
            b = a + VAR_BYTES
            if op == JKEY:
                fits = t in (TYPE_CODES["F32"], TYPE_CODES["F64"])
            elif op == JINT:
                fits = t == TYPE_T or t <= TYPE_CODES["U64"] or t == TYPE_CODES["bool"]
            elif op == SETK:
                fits = t != TYPE_T
            else:
                fits = t <= TYPE_CODES["U64"]
            if not fits:
                return _wrong_type(ref), deepest
            more = _typed_operands(op, t)
            at = more - 2  # a test's jump offset, last
            if pc + more > p.code_size:
                return BAD_OPCODE, deepest
            pc += more
            if op == SETK:
                if t == TYPE_CODES["bool"] and code[b] > 1:
                    return BAD_OPCODE, deepest
            elif op == IADD:
                why, ts = _ref_type(code, b, p, layout, lock, features)
                if why != OK:
                    return why, deepest
                if ts > TYPE_CODES["U64"]:
                    return _wrong_type(_u16(code, b)), deepest
                k = struct.unpack_from("<i", code, b + VAR_BYTES)[0]
                if real == 4 and not -16777215 <= k <= 16777215:
                    return BAD_OPCODE, deepest
            else:
                if (code[b] & ~(KEY_INCLUSIVE | KEY_JUMP_IF)) if op == JKEY else (code[b] & ~JUMP_IF) > 5:
                    return BAD_OPCODE, deepest
                target = pc + _u16(code, b + at)
                if target >= p.code_size:
                    return BAD_JUMP, deepest
                if len(pend) == pending:
                    if nested is not None:
                        nested.append(a - 1)
                    return TOO_NESTED, deepest
                pend.append([target, depth])
        elif op == JCMP:
            if (code[a] & ~JUMP_IF) > 5:
                return BAD_OPCODE, deepest
            pops = 2
            if depth < pops:
                return BAD_STACK, deepest
            target = pc + _u16(code, a + 1)
            if target >= p.code_size:
                return BAD_JUMP, deepest
            if len(pend) == pending:
                if nested is not None:
                    nested.append(a - 1)
                return TOO_NESTED, deepest
            pend.append([target, depth - 2])
        elif op in (CONST, LDT):
            pushes = 1
        elif op in (LDE, STE):
            e = _u16(code, a)
            if e >= len(layout.elems) or layout.elems[e][1] != code[a + 2]:
                return BAD_ELEMENT, deepest
            pushes, pops = (1, 0) if op == LDE else (0, 1)
        elif op in (LDL, STL):
            if _u16(code, a) >= p.locals:
                return BAD_LOCAL, deepest
            pushes, pops = (1, 0) if op == LDL else (0, 1)
        elif op == ROLL:
            if code[a] >= p.windows or (prelude and code[a] >= pushed):
                return BAD_WINDOW, deepest
            pushes = 1
        elif op == WPUSH:
            if not prelude:
                return BAD_PLACE, deepest
            if code[a] != pushed:
                return BAD_WINDOW, deepest
            pushed += 1
            pops = 1
        elif op in (NEG, NOT, TRUTH):
            pops = pushes = 1
        else:
            pops, pushes = 2, 1
        if depth < pops:
            return BAD_STACK, deepest
        depth = depth - pops + pushes
        deepest = max(deepest, depth)
        if deepest > stack:
            return BAD_STACK, deepest
        if ends:
            if depth != 0:
                return BAD_STACK, deepest
            reachable = False
            if not pend:
                if prelude and pushed != p.windows:
                    return BAD_WINDOW, deepest
                at_start = True
    if pend:
        return BAD_JUMP, deepest
    if not at_start or matched != declared:
        return BAD_END, deepest
    if deepest != im[7]:
        return BAD_STACK, deepest
    return OK, deepest


def too_nested_at(im: bytes, layout: Layout, pending: int = VM_PENDING) -> int | None:
    """The code offset of the jump that has more than `pending` forward
    jumps pending at once (TOO_NESTED), or None: where the compiler says a
    machine's conditions nest too deep."""
    at: list = []
    _verify_code(im, parts(im), layout, 255, pending, at)
    return at[0] if at else None


def code_depth(im: bytes, layout: Layout, stack: int = 255) -> tuple[int, int]:
    """The code pass alone: (reason, deepest stack). The compiler takes the
    deepest figure for the header (whose own figure may differ: BAD_STACK
    then says only that)."""
    return _verify_code(im, parts(im), layout, stack, VM_PENDING)


def verify(im: bytes, layout: Layout, real_bytes: int, stack: int = VM_STACK, pending: int = VM_PENDING,
           features: int = ALL_FEATURES) -> int:
    """vm_verify on the host: the reason code (0: the image may run).
    `real_bytes` is the runtime's sizeof(Real); RAM is not checked here
    (the board's buffer is the board's); `features` are the VM's (fsw::vm_features)."""
    if len(im) > 0xFFFF or len(im) < HEADER:
        return BAD_SIZE
    if im[:4] != MAGIC:
        return BAD_MAGIC
    if im[4] != VERSION:
        return BAD_VERSION
    if im[5] != real_bytes:
        return BAD_REAL
    if im[6] & ~FLAG_LOCK:
        return BAD_VERSION
    schema, count = struct.unpack_from("<IH", im, 8)
    if schema != layout.schema or count != len(layout.elems):
        return BAD_SCHEMA
    if im[6] & FLAG_LOCK and not features & FEAT_LOCK:
        return NO_FEATURE
    if any(not takes(t, features) for _off, t in layout.elems):
        return NO_FEATURE
    p = parts(im)
    if p.total != len(im):
        return BAD_SIZE
    # G and S by their byte offsets (version 3), as a typed instruction's elements
    g, s = (next((e for e in layout.elems if e[0] == off), None) for off in struct.unpack_from("<HH", im, 14))
    if g is None or s is None or g[1] != TYPE_CODES["U64"] or s[1] != TYPE_CODES["U32"]:
        return BAD_ELEMENT
    if p.states == 0:
        return BAD_STATE
    for k in range(p.locals):
        t = im[p.loc + 3 * k]
        off = _u16(im, p.loc + 3 * k + 1)
        if t >= len(TYPE_SIZES) or off + TYPE_SIZES[t] > p.loc_size:
            return BAD_LOCAL
        if not takes(t, features):
            return NO_FEATURE
    for w in range(p.windows):
        n = _u16(im, p.win + 4 * w + 2)
        if im[p.win + 4 * w] > 4 or im[p.win + 4 * w + 1] != 0 or n == 0:
            return BAD_WINDOW
        if not features & (1 << im[p.win + 4 * w]):
            return NO_FEATURE
    return _verify_code(im, p, layout, stack, pending, features=features)[0]


def opcodes(im: bytes, layout: Layout) -> list[int]:
    """The opcode of each instruction of a verified image, in code order
    (what a listing or a test of the compiler's output walks)."""
    p = parts(im)
    code = im[p.code:p.code + p.code_size]
    lock = bool(im[6] & FLAG_LOCK)
    out, pc = [], 0
    while pc < p.code_size:
        op = code[pc]
        n = operand_bytes(op, im[5])
        if op in (JKEY, JINT, SETK, IADD):
            n += _typed_operands(op, _ref_type(code, pc + 1, p, layout, lock, ALL_FEATURES)[1])
        out.append(op)
        pc += 1 + n
    return out
