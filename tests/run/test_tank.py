"""The thesis's tank example: the exact reports of ../shared/examples/tank/expected.md."""

from __future__ import annotations

import re

import pytest

from conftest import EXAMPLES, SHARED

TANK = EXAMPLES / "tank"


def expected_blocks() -> list[str]:
    """The indented report blocks of expected.md, dedented."""
    text = (SHARED / "examples" / "tank" / "expected.md").read_text()
    blocks, cur = [], []
    for line in text.splitlines() + ["<end>"]:
        if line.startswith("    "):
            cur.append(line)
        elif cur and line.strip() == "":
            cur.append("")
        elif cur:
            while cur and cur[-1] == "":
                cur.pop()
            indent = min(len(l) - len(l.lstrip()) for l in cur if l)
            blocks.append("\n".join(l[indent:] for l in cur) + "\n")
            cur = []
    return blocks


TANK_REPORT = """\
state script ran for 101 steps
100 asserts passed
final state vector:
  G = 1000
  P_AbortThreshold = 825
  P_WarnThreshold = 800
  S = 1
  T = 1000
  counter = 0
  pi = 3.141590
  tankPressure = 701.000000
  valveOpen = false
"""


@pytest.mark.parametrize("real", ["f64", "f32"])
def test_tank_report_is_exact(fsw, real):
    r = fsw("test", str(TANK / "tank.ss"), "--real", real)
    assert r.code == 0
    assert r.out == TANK_REPORT


@pytest.mark.skipif(not (SHARED / "examples").exists(), reason="shared/ not beside the project")
def test_expected_md_blocks_match(fsw):
    blocks = expected_blocks()
    assert blocks[0] == TANK_REPORT
    counter = next(b for b in blocks if "assertion failure" in b)
    r = fsw("test", "tank_counter.ss", cwd=TANK)
    assert r.code == 1
    assert r.out == counter
    typo = next(b for b in blocks if "valve0pe" in b)
    r = fsw("check", "tank_typo.sm", cwd=TANK)
    assert r.code == 1
    assert r.err.startswith(typo)


@pytest.mark.parametrize("real", ["f64", "f32"])
def test_tank_770(fsw, real):
    r = fsw("test", str(TANK / "tank_770.ss"), "--real", real)
    assert r.code == 0
    assert r.out.startswith("state script ran for 101 steps\n100 asserts passed\n")
    assert "  counter = 48\n" in r.out
    assert "  tankPressure = 775.000000\n" in r.out


@pytest.mark.parametrize("real", ["f64", "f32"])
def test_tank_counter_fails_at_the_assert(fsw, real):
    r = fsw("test", "tank_counter.ss", "--real", real, cwd=TANK)
    assert r.code == 1
    assert r.out.startswith("state script ran for 24 steps\n23 asserts passed\n"
                            "assertion failure @ tank_counter.ss:15:7:\n")
    assert "  counter = 10\n" in r.out


def test_tank_typo_is_located(fsw):
    r = fsw("check", "tank_typo.sm", cwd=TANK)
    assert r.code == 1
    assert r.err.startswith("state machine config error @ tank_typo.sm:18:9:\n"
                            "  |         valve0pe = true\n"
                            "  |         ^ unknown element `valve0pe`\n")


def test_trace_has_a_row_per_step(fsw, tmp_path):
    trace = tmp_path / "t.csv"
    r = fsw("test", str(TANK / "tank.ss"), "--trace", str(trace))
    assert r.code == 0
    rows = trace.read_text().splitlines()
    assert rows[0] == "step,G,P_AbortThreshold,P_WarnThreshold,S,T,counter,pi,tankPressure,valveOpen"
    assert len(rows) == 1 + 101
    assert re.match(r"^101,1000,825,800,1,1000,0,3\.14159,701\.0,false$", rows[-1])
