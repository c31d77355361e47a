"""On AVR the firmware had two routines for one job in three places: an F32
store (`write_F32`) and the same store returning what it stored
(`write_F32_read`), 38 and 42 B; an analog count's conversion to a float
(`real_from_count`, 74 B) and the float library's integer conversion
(`__floatunsisf`/`__floatsisf`, 122 B), which T as a real, a window's
count and a U32 variable pulled in; and a threshold test's key read
(`f32_read_key`, 70 B), which tested the bytes for a NaN apart from
`read_F32`'s test. The store took its place first, so each call moved a
computed value out of the registers the float routines leave it in.

Now a store is one routine taking the value first (`f32_write_back`, the
value back in the same registers: `write_F32` and `write_F32_read` are
calls of it), every integer becomes a float through one routine in
assembly (`fsw_f32_from_u16/u32/i32`: the library's is not linked), and
a threshold test of an F32 that no local holds reads it with read_F32 and
tests the value's bits (f32_key_gt/f32_key_ge, as for one a local holds):
no key routine is linked. The values are the same bits
(tests/firmware/test_convert.cpp tests the conversions against the cast on
the simulated board, and the held value's tests against its key)."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest

from support.core_rocket import build_core

pytestmark = pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")


@pytest.fixture(scope="module")
def symbols(tmp_path_factory) -> dict[str, int]:
    _, out = build_core(tmp_path_factory)
    nm = subprocess.run(["avr-nm", "-S", "-C", str(out / "rocket.elf")], capture_output=True, text=True,
                        check=True).stdout
    sizes: dict[str, int] = {}
    for m in re.finditer(r"^[0-9a-f]+ ([0-9a-f]+) [tT] (.+)$", nm, re.M):
        name = re.sub(r" \[clone [^\]]*\]", "", m.group(2))
        sizes[name] = sizes.get(name, 0) + int(m.group(1), 16)
    return sizes


def test_an_f32_store_is_one_routine_with_the_value_first(symbols):
    assert "fsw::f32_write_back(float, unsigned char*)" in symbols, sorted(symbols)
    assert not [n for n in symbols if n.startswith(("fsw::write_F32(", "fsw::write_F32_read("))], sorted(symbols)


def test_integers_become_floats_through_one_routine(symbols):
    assert not [n for n in symbols if n in ("__floatunsisf", "__floatsisf")], sorted(symbols)
    assert not [n for n in symbols if n.startswith("fsw::real_from_count(")], sorted(symbols)
    assert "fsw_f32_from_u16" in symbols and "fsw_f32_from_u32" in symbols, sorted(symbols)


def test_a_threshold_test_reads_the_value_as_read_F32_does(symbols, tmp_path_factory):
    # `x > c` of an F32 no local holds: read_F32 and the value's bits tested, no key routine
    _, out = build_core(tmp_path_factory)
    mission = (out / "gen" / "mission.gen.cpp").read_text()
    assert "f32_read_key" not in mission, mission
    assert "fsw::f32_key_gt(fsw::read_F32(svp + E_drogueSense), 0xbf7fffffUL)" in mission, mission
    assert not [n for n in symbols if n.startswith("fsw::f32_read_key(")], sorted(symbols)
