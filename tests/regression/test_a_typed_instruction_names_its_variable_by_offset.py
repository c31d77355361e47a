"""A typed instruction (JKEY, JINT, SETK, IADD) named its variable by its
index: an element's in the layout, a local's in the image's table. The VM
then read the element's offset and type from the layout's table in flash
(or the local's from the image) on every instruction, and a tank step took
4.1 times the generated code's cycles on an AVR. Typed instructions could
also run with values on the operand stack, which made the VM's block loop
test after every instruction whether it ran one for the stack interpreter.

Now (format version 3) the variable is its byte offset and its type: an
element's offset in the state vector, a local's in the locals plus 0x8000,
T 0xFFFF with U64's type. Both verifiers check the pair (an element of the
layout at that offset, of that type; a local's bytes within the locals'),
and refuse a typed instruction with values on the stack (BAD_STACK)."""

from __future__ import annotations

import os
import struct

from fswkit.autocode import vmverify as V
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.bytecode import compile_machine, local_offsets, local_order
from fswkit.autocode.numeric import F32MODE
from fswkit.autocode.project import load_machine

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def tank():
    m = load_machine(os.path.join(ROOT, "examples", "tank", "tank.sm"), Diagnostics())
    assert m is not None
    return m, compile_machine(m, F32MODE)


def typed_vars(im: bytes, layout: V.Layout) -> list[tuple[int, int, int]]:
    """(opcode, where, type) of every typed instruction's variable."""
    p = V.parts(im)
    code = im[p.code:p.code + p.code_size]
    out, pc = [], 0
    for op in V.opcodes(im, layout):
        if op in (V.JKEY, V.JINT, V.SETK, V.IADD):
            out.append((op, *struct.unpack_from("<HB", code, pc + 1)))
            if op == V.IADD:
                out.append((op, *struct.unpack_from("<HB", code, pc + 4)))
        n = V.operand_bytes(op, im[5])
        if op in (V.JKEY, V.JINT, V.SETK, V.IADD):
            n += V._typed_operands(op, V.TYPE_T if code[pc + 1:pc + 3] == b"\xff\xff" else code[pc + 3])
        pc += 1 + n
    return out


def test_the_tanks_typed_instructions_name_offsets_and_types():
    m, im = tank()
    layout = V.layout_of(m.sv)
    assert im[4] == V.VERSION == 3
    assert V.verify(im, layout, 4) == V.OK
    elems = {e.offset: V.TYPE_CODES[e.type.name] for e in m.sv.elements}
    locs = {V.REF_LOCAL + local_offsets(m)[v.index]: V.TYPE_CODES[v.type.name] for v in local_order(m)}
    locs[V.REF_T] = V.TYPE_CODES["U64"]  # T
    got = typed_vars(im, layout)
    ops = {op for op, _w, _t in got}
    assert ops == {V.JKEY, V.JINT, V.SETK, V.IADD}
    pressure = next(e for e in m.sv.elements if e.name == "tankPressure")
    counter = V.REF_LOCAL + local_offsets(m)[next(v.index for v in local_order(m) if v.name == "counter")]
    assert (V.JKEY, pressure.offset, V.TYPE_CODES["F64"]) in got
    assert (V.IADD, counter, V.TYPE_CODES["U64"]) in got
    for _op, where, t in got:
        assert elems.get(where, locs.get(where)) == t


def test_an_index_where_an_offset_belongs_is_refused():
    m, im = tank()
    layout = V.layout_of(m.sv)
    p = V.parts(im)
    code = im[p.code:p.code + p.code_size]
    pressure = next(k for k, e in enumerate(m.sv.elements) if e.name == "tankPressure")
    at = code.index(bytes((V.JKEY,)) + struct.pack("<HB", m.sv.elements[pressure].offset, V.TYPE_CODES["F64"]))
    bad = bytearray(im)
    struct.pack_into("<H", bad, p.code + at + 1, pressure)  # the version 2 operand: the element's index
    assert V.verify(bytes(bad), layout, 4) == V.BAD_ELEMENT
    old = bytearray(im)
    old[4] = 2
    assert V.verify(bytes(old), layout, 4) == V.BAD_VERSION


def test_a_typed_instruction_with_values_on_the_stack_is_refused():
    m, im = tank()
    layout = V.layout_of(m.sv)
    p = V.parts(im)
    code = bytearray(im[p.code:p.code + p.code_size])
    entry = struct.unpack_from("<H", im, V.HEADER)[0]
    assert code[entry] == V.SETK  # .entry: counter = 0
    setk = bytes(code[entry:entry + 12])
    # LDT; SETK ...; TRUTH; JF +0: the SETK at depth 1, the stack empty at the END
    block = bytes((V.LDT,)) + setk + bytes((V.TRUTH, V.JF, 0, 0))
    code[entry:entry + 12] = block[:12]
    patched = bytearray(im[:p.code]) + code[:entry] + block + code[entry + 12:]
    struct.pack_into("<H", patched, 26, len(code) + len(block) - 12)
    for k in range(3 * p.states):  # the blocks after .entry moved on
        off = struct.unpack_from("<H", patched, V.HEADER + 2 * k)[0]
        if off != V.NONE and off > entry:
            struct.pack_into("<H", patched, V.HEADER + 2 * k, off + len(block) - 12)
    prelude = struct.unpack_from("<H", patched, 24)[0]
    struct.pack_into("<H", patched, 24, prelude + len(block) - 12)
    patched[7] = 1
    assert V.verify(bytes(patched), layout, 4) == V.BAD_STACK
    # the same block with the SETK before the LDT is accepted
    block = setk + bytes((V.LDT, V.TRUTH, V.JF, 0, 0))
    patched[p.code + entry:p.code + entry + len(block)] = block
    assert V.verify(bytes(patched), layout, 4) == V.OK
