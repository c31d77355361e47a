"""Golden files for every diagnostic of the application languages: the
`.app` config and the `.aio`/`.dio` channel tables and `.sns` sensor tables
it names.

tests/autocode/golden/app/ holds one small application per diagnostic,
`NAME.app`, beside `NAME.expected`: exactly what `fsw check NAME.app` writes
to standard error, run from this folder. A case about a channel table names
its own `NAME.aio` or `NAME.dio`, a sensor case (`sensors_*`) its
`NAME.sns` (writing the elements of rig.sv's [Parts] group),
changing `sensors_valid.app`; the other files (rig.sv, rig.sm, rig.aio,
rig.dio, ...) are the companions the cases share. Each case is the same
valid application (`valid.app`) with one thing changed, so its diagnostics
are those of that change.

    FSW_UPDATE_GOLDEN=1 pytest tests/autocode/golden/app/test_golden_app.py

rewrites every .expected file from the current output; review the diff by
eye before committing: each file is what a user sees.
"""

from __future__ import annotations

import ast
import os
import re
from pathlib import Path

import pytest

from conftest import ROOT, run_fsw

GOLDEN = Path(__file__).resolve().parent
UPDATE = os.environ.get("FSW_UPDATE_GOLDEN") == "1"


def cases() -> list[Path]:
    return sorted(GOLDEN.glob("*.app"))


@pytest.mark.parametrize("inp", cases(), ids=lambda p: p.name)
def test_golden_app(inp: Path):
    expected_path = inp.with_suffix(".expected")
    r = run_fsw("check", inp.name, cwd=GOLDEN)
    if UPDATE:
        expected_path.write_text(r.err)
    assert expected_path.exists(), f"no {expected_path.name}: run with FSW_UPDATE_GOLDEN=1, then review it"
    expected = expected_path.read_text()
    assert r.err == expected
    assert r.out == ""
    summary = expected.splitlines()[-1]
    assert re.fullmatch(r"fsw check: 1 file, \d+ errors?, \d+ warnings?", summary)
    assert r.code == (0 if ", 0 errors," in summary else 1)
    assert "Traceback" not in r.err and "internal error" not in r.err


def test_the_base_case_is_valid():
    r = run_fsw("check", "valid.app", cwd=GOLDEN)
    assert (r.code, r.err) == (0, "fsw check: 1 file, 0 errors, 0 warnings\n")


def test_every_expected_file_has_its_input():
    inputs = {p.with_suffix(".expected") for p in cases()}
    assert [p.name for p in GOLDEN.glob("*.expected") if p not in inputs] == []


# ---- every message the application checker can produce has a golden case ------------

SOURCES = [ROOT / "autocode" / n for n in ("appsyntax.py", "appcheck.py", "iotables.py", "logcheck.py", "pyrocheck.py",
                                           "reloadcheck.py", "sensors.py")]
REPORTERS = {"error", "warning", "err", "at", "Problem", "_Refused"}
# Messages that no golden case here can hold, and where they are tested instead.
NOT_GOLDEN = {
    # the flight recorder on an SPI NOR flash: projects of their own (the rig's pins and sizes)
    "`record` on spi_nor is a power of two from 32 to 128 (records never straddle a ":
        "tests/recorder/test_log_spi_check.py",
    "-byte sector or a 256-byte page): found ": "tests/recorder/test_log_spi_check.py",
    "`full newest` is not available on spi_nor: a flash sector is erased whole, so overwriting the oldest records "
    "would drop a whole sector of them at a time, and boot finds the end of the log by a binary search that needs "
    "the records written from the chip's start; use `full stop` and `fsw dump --erase`":
        "tests/recorder/test_log_spi_check.py",
    "`store spi_nor` takes the chip select's pin, then the chip's size (default 8 MiB): bytes, or a number and K or "
    "M, e.g. `spi_nor 10 1 M`": "tests/recorder/test_log_spi_check.py",
    " is reserved on the ": "tests/recorder/test_log_spi_check.py",
    " is the SPI bus's ": "tests/recorder/test_log_spi_check.py",
    ": the chip select must be another pin": "tests/recorder/test_log_spi_check.py",
    "the flash's size is a power of two from 64 K to 16 M (bytes, or a number and K or M), found `":
        "tests/recorder/test_log_spi_check.py",
    " is already the channel of `": "tests/recorder/test_log_spi_check.py",
    " on the ": "tests/recorder/test_log_spi_check.py",
    # a board without EEPROM (none in boards/), 33 logged elements
    " has no EEPROM": "tests/recorder/test_log_check.py",
    "at most 32 elements are logged": "tests/recorder/test_log_check.py",
    "the logged elements take ": "tests/recorder/test_log_check.py",
    " bytes a sample: at most 253 (log fewer, or encode F32 ones with delta= or quant=)":
        "tests/recorder/test_log_check.py",
    # [reload] on a board without EEPROM; `activate` with no state (tests/reload/test_reload_check.py)
    " has no EEPROM to keep uploaded machines in": "tests/reload/test_reload_check.py",
    "`activate` takes states of machine `": "tests/reload/test_reload_check.py",
    # a machine of 256 states
    " states: an uploaded machine keeps them at their numbers and an image holds at most ":
        "tests/reload/test_reload_check.py",
    ", so no machine could ever replace it": "tests/reload/test_reload_check.py",
    # two machine files whose names differ only in case: one file on some file systems
    "machines `": "tests/regression/test_names_reach_cpp_safely.py",
    "` would generate the same C++ files (`": "tests/regression/test_names_reach_cpp_safely.py",
    ".gen.h`; file names that differ only in case are one file on some file systems): rename one":
        "tests/regression/test_names_reach_cpp_safely.py",
    # a state vector of 256 writable elements
    "` is writable element ": "tests/regression/test_table_limits_checked_before_generation.py",
    ": the uplink writes at most ": "tests/regression/test_table_limits_checked_before_generation.py",
    # a board whose executor keeps no timer of its own (every board in boards/ has one)
    "` and `": "tests/regression/test_names_reach_cpp_safely.py",
    "` steps every ": "tests/regression/test_clock_too_coarse_for_the_machine_rate.py",
    " us, but with `source clock` and `unit ms` the ": "tests/regression/test_clock_too_coarse_for_the_machine_rate.py",
    "'s millis() moves on only every ": "tests/regression/test_clock_too_coarse_for_the_machine_rate.py",
    " us: `G` would sometimes not increase between its steps (use `unit us`, `source cycle`, or a rate of at most ":
        "tests/regression/test_clock_too_coarse_for_the_machine_rate.py",
    # a board of another clock than those in boards/
    "; `baud` is not set, so it is the default: set `baud` in [application]":
        "tests/regression/test_baud_rate_the_uart_can_make.py",
}


def _literals(node) -> list[str]:
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node.value]
    if isinstance(node, ast.JoinedStr):
        return [v.value for v in node.values if isinstance(v, ast.Constant)]
    if isinstance(node, ast.BinOp):
        return _literals(node.left) + _literals(node.right)
    return []


def message_fragments() -> dict[str, str]:
    """The literal pieces of every message the sources report: the last
    argument of a reporter, a `problem = ...` a reporter is given later, and
    what a `*_problem` function returns."""
    out = {}
    for path in SOURCES:
        tree = ast.parse(path.read_text())
        found = []
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and node.args:
                f = node.func
                name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else None
                if name in REPORTERS:
                    found.append((node.lineno, node.args[-1]))
            elif isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "problem"
                                                      for t in node.targets):
                found.append((node.lineno, node.value))
            elif isinstance(node, ast.FunctionDef) and node.name.endswith("_problem"):
                found += [(r.lineno, r.value) for r in ast.walk(node) if isinstance(r, ast.Return) and r.value]
        for line, msg in found:
            for p in _literals(msg):
                if len(p.strip()) >= 4:
                    out[p] = f"{path.name}:{line}"
    return out


def test_every_message_has_a_golden_case():
    fragments = message_fragments()
    assert len(fragments) > 80  # the scan found the reporters
    seen = "".join(p.read_text() for p in GOLDEN.glob("*.expected"))
    missing = [f"{where}: {frag!r}" for frag, where in sorted(fragments.items(), key=lambda kv: kv[1])
               if frag not in seen and frag not in NOT_GOLDEN]
    assert missing == []
    assert [frag for frag in NOT_GOLDEN if frag not in fragments] == []  # each exception still a message
