"""Firmware that did not fit answered with the linker's own words (`region
'text' overflowed by 617672 bytes`, `.bss is not within region 'data'`),
and anything else the compiler refused on a checked configuration with
pages of raw compiler output. Now firmware that does not fit says which
memory, by how much, and what uses it, largest first, named by the config
lines it comes from (the size table); any other build failure is an
internal error to report, with the build log's path."""

from __future__ import annotations

import re
import shutil

import pytest

from conftest import EXAMPLES

TANK = EXAMPLES / "tank"
needs_avr = pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")
RAW = ("overflowed by", "not within region", "will not fit in region", "collect2", "ld returned", "make: ***")

APP = """\
[application]
board uno
rate 100
[configs]
state_vector big.sv
machine big.sm
[time]
source clock
unit ms
[tasks]
control machine big rate=100
"""


def _over(err: str, what: str, budget: int) -> tuple[int, int]:
    m = re.search(rf"{what} ([\d,]+) B of {budget:,} B, ([\d,]+) B over", err)
    assert m, err
    used, over = (int(g.replace(",", "")) for g in m.groups())
    return used, over


def _rows(err: str, what: str) -> list[tuple[int, str]]:
    """The rows of the report's `what uses WHAT` table: (bytes, label)."""
    block = err.split(f"what uses {what}, largest first:\n", 1)[1]
    rows = []
    for line in block.splitlines():
        m = re.match(r"  \s*([\d,]+) B  (\S.*)", line)
        if not m or line.startswith(" " * 13):
            if not m:
                break
            continue
        rows.append((int(m.group(1).replace(",", "")), m.group(2)))
    return rows


@needs_avr
def test_a_state_vector_too_big_for_the_ram_is_reported_line_by_line(fsw, tmp_path):
    project = tmp_path / "tank"
    shutil.copytree(TANK, project, ignore=shutil.ignore_patterns("build"))
    with open(project / "tank.sv", "a") as f:  # 1,800 B more: the Uno's 2 KB no longer hold it all
        f.write("[Log]\n" + "".join(f"F64 sample{i}\n" for i in range(225)))
    r = fsw("build", str(project), "--out", str(tmp_path / "out"))
    assert r.code == 1
    assert not any(raw in r.err for raw in RAW), r.err
    used, over = _over(r.err, "RAM", 2048)
    assert over == used - 2048 > 0
    rows = _rows(r.err, "RAM")
    assert rows[0] == (1821, "the state vector, tank.sv (229 elements)")  # 21 B of the tank + 1,800 B
    assert "1,800 B  region Log, tank.sv:7 (225 elements)" in r.err
    assert rows[-1][1].startswith("the fswkit runtime, the Arduino core and the C library")
    assert [n for n, _ in rows[:-1]] == sorted((n for n, _ in rows[:-1]), reverse=True)
    assert sum(n for n, _ in rows) == used


@needs_avr
def test_machine_code_too_big_for_the_flash_is_reported_by_machine(fsw, tmp_path):
    (tmp_path / "big.app").write_text(APP)
    (tmp_path / "big.sv").write_text("[Flight]\nU64 time\nU32 state\nF64 x\nF64 y\n")
    sm = ["[state_vector]", "U64 time @alias G", "U32 state @alias S", "F64 x", "F64 y", ""]
    n = 200  # well past the Uno's 32 KB whatever the generator saves
    for i in range(1, n + 1):
        sm += [f"[S{i}]", ".step", f"    x = x * {1 + i / 1000} + y / {i}.5 - {i}",
               f"    y = (y + x * {i}) / (x - {i}.25)", f"    x > {i * 10} and y < {i}: -> S{i % n + 1}", ""]
    (tmp_path / "big.sm").write_text("\n".join(sm))
    r = fsw("build", str(tmp_path), "--out", str(tmp_path / "out"))
    assert r.code == 1
    assert not any(raw in r.err for raw in RAW), r.err
    used, over = _over(r.err, "flash", 32256)
    assert over == used - 32256 > 0
    rows = _rows(r.err, "flash")
    assert rows[0][1].startswith("machine big, big.sm: its states' code") and rows[0][0] > over
    costliest = re.findall(r"^ {13,}([\d,]+) B  big\.sm:(\d+)  (.*)$", r.err, re.M)
    assert len(costliest) == 5
    sm_lines = (tmp_path / "big.sm").read_text().splitlines()
    for size, line, text in costliest:  # a statement of big.sm, shown as written
        assert int(size.replace(",", "")) > 0 and sm_lines[int(line) - 1].strip() == text
    assert sum(n for n, _ in rows) == used
    assert not (tmp_path / "out" / "big.overflow.elf").exists()


def _broken(monkeypatch, text: str) -> None:
    """Generation that appends `text` to the application's C++: a defect
    of the generator, as the user would meet one."""
    import fswkit.autocode.emit.app as emit

    real = emit.emit_app

    def emit_app(app):
        files = real(app)
        files["app.gen.cpp"] += text
        return files

    monkeypatch.setattr(emit, "emit_app", emit_app)


@pytest.mark.parametrize("board", [pytest.param("uno", marks=needs_avr), "native"])
@pytest.mark.parametrize("text, shown", [
    ('static_assert(sizeof(int) == 0, "tank.app:3: a table the checker let through");\n',
     "tank.app:3: a table the checker let through"),
    ("int broken = ;\n", "expected primary-expression"),
])
def test_a_compiler_failure_on_a_checked_configuration_is_an_internal_error(fsw, tmp_path, monkeypatch,
                                                                             board, text, shown):
    if board == "native" and shutil.which("g++") is None:
        pytest.skip("no host C++ compiler")
    _broken(monkeypatch, text)
    out = tmp_path / "out"
    r = fsw("build", str(TANK), "--board", board, "--out", str(out))
    assert r.code == 3
    log = out / "build.log"
    assert "fsw build: internal error:" in r.err and "please report it with " + str(log) in r.err
    assert shown in r.err
    assert len(r.err.splitlines()) <= 10, r.err
    assert shown in log.read_text() and "app.gen.cpp" in log.read_text()
