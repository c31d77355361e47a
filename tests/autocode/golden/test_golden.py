"""Golden files for every diagnostic of the .sv, .sm and .ss front end.

tests/autocode/golden/<lang>/ holds one small input per diagnostic (`NAME.sv`,
`NAME.sm` or `NAME.ss`, after the folder) beside `NAME.expected`: exactly
what `fsw check NAME.<lang>` writes to standard error, run from that folder.
Under a `run/` folder the case is a state script run by `fsw test`, and the
expected text is its report on standard output. Files of another language in
a folder are the companions the cases share (the .sv beside the .sm cases,
found by `autocode/project.py find_beside`).

    FSW_UPDATE_GOLDEN=1 pytest tests/autocode/golden/test_golden.py

rewrites every .expected file from the current output; review the diff by
eye before committing: each file is what a user sees.
"""

from __future__ import annotations

import ast
import os
import random
import re
from pathlib import Path

import pytest

from conftest import ROOT, run_fsw

GOLDEN = Path(__file__).resolve().parent
LANGS = ("sv", "sm", "ss")
UPDATE = os.environ.get("FSW_UPDATE_GOLDEN") == "1"


def cases() -> list[Path]:
    out = []
    for lang in LANGS:
        out += sorted((GOLDEN / lang).rglob(f"*.{lang}"))
    return out


def expected_files() -> list[Path]:
    """The expected outputs of the three state languages (app/ holds the
    application language's cases, tests/autocode/golden/app)."""
    return [p for lang in LANGS for p in sorted((GOLDEN / lang).rglob("*.expected"))]


def case_id(p: Path) -> str:
    return p.relative_to(GOLDEN).as_posix()


def run_case(inp: Path):
    """(text the user sees, exit status, the other stream)."""
    if inp.parent.name == "run":
        r = run_fsw("test", inp.name, cwd=inp.parent)
        return r.out, r.code, r.err
    r = run_fsw("check", inp.name, cwd=inp.parent)
    return r.err, r.code, r.out


@pytest.mark.parametrize("inp", cases(), ids=case_id)
def test_golden(inp: Path):
    expected_path = inp.with_suffix(".expected")
    text, code, other = run_case(inp)
    if UPDATE:
        expected_path.write_text(text)
    assert expected_path.exists(), f"no {expected_path.name}: run with FSW_UPDATE_GOLDEN=1, then review it"
    expected = expected_path.read_text()
    assert text == expected
    assert other == ""
    if inp.parent.name == "run":
        assert code == 1  # every run case is a failing script
    else:
        summary = expected.splitlines()[-1]
        assert re.fullmatch(r"fsw check: 1 file, \d+ errors?, \d+ warnings?", summary)
        assert code == (0 if ", 0 errors," in summary else 1)
    assert "Traceback" not in text and "internal error" not in text


def test_every_expected_file_has_its_input():
    inputs = {p.with_suffix(".expected") for p in cases()}
    orphans = [case_id(p) for p in expected_files() if p not in inputs]
    assert orphans == []


# ---- every message the front end can produce has a golden case -------------

SOURCES = [ROOT / "autocode" / n for n in ("lexer.py", "parser.py", "check.py", "project.py")]
SOURCES.append(ROOT / "host-tools" / "fswkit" / "run" / "script.py")
REPORTERS = {"error", "lexical_error", "warning", "warn", "err", "ParseError", "located"}
# Messages that no golden case can hold, and where they are tested instead.
NOT_GOLDEN = {
    "cannot read file: ": "test_unreadable_file_is_located",
    # only where R is binary32 (a board, `fsw test --real f32`), which no golden case names
    "number is outside the representable range of binary": "tests/regression/"
    "test_numbers_beyond_the_float_range_in_configs.py",
    " evaluation type R (at most ": "tests/regression/test_numbers_beyond_the_float_range_in_configs.py",
    # a golden case would be a state vector of 64 KB
    "the state vector would grow past ": "tests/regression/test_table_limits_checked_before_generation.py",
    "` (ending at byte ": "tests/regression/test_table_limits_checked_before_generation.py",
    "): element offsets and sizes are 16-bit": "tests/regression/test_table_limits_checked_before_generation.py",
    " B with `": "tests/regression/test_table_limits_checked_before_generation.py",
    "the machine's locals would grow past ": "tests/regression/test_table_limits_checked_before_generation.py",
    "`: local offsets are 16-bit": "tests/regression/test_table_limits_checked_before_generation.py",
}


def message_fragments() -> dict[str, str]:
    """The literal pieces of every message passed to a reporter in SOURCES,
    each with where it comes from."""
    out = {}
    for path in SOURCES:
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call) or not node.args:
                continue
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else None
            if name not in REPORTERS:
                continue
            msg = node.args[-1]
            pieces = []
            if isinstance(msg, ast.Constant) and isinstance(msg.value, str):
                pieces = [msg.value]
            elif isinstance(msg, ast.JoinedStr):
                pieces = [v.value for v in msg.values if isinstance(v, ast.Constant)]
            for p in pieces:
                if len(p.strip()) >= 4:
                    out[p] = f"{path.name}:{node.lineno}"
    return out


def test_every_message_has_a_golden_case():
    fragments = message_fragments()
    assert len(fragments) > 80  # the scan found the reporters
    seen = "".join(p.read_text() for p in expected_files())
    missing = [f"{where}: {frag!r}" for frag, where in sorted(fragments.items(), key=lambda kv: kv[1])
               if frag not in seen and frag not in NOT_GOLDEN]
    assert missing == []


def test_unreadable_file_is_located(fsw, tmp_path):
    r = fsw("check", "gone.sv", cwd=tmp_path)
    assert r.code == 1
    assert r.err == ("state vector config error @ gone.sv:1:1:\n"
                     "  | \n"
                     "  | ^ cannot read file: No such file or directory\n"
                     "fsw check: 1 file, 1 error, 0 warnings\n")


# ---- several errors of one file: all of them, in file order ------------------

def locations(text: str) -> list[tuple[int, int]]:
    return [(int(a), int(b)) for a, b in re.findall(r" @ [^:\n]+:(\d+):(\d+):\n", text)]


@pytest.mark.parametrize("lang", LANGS)
def test_several_errors_are_all_reported_in_order(lang):
    inp = next(GOLDEN.glob(f"{lang}/several_errors.{lang}"))
    text, code, _ = run_case(inp)
    locs = locations(text)
    assert code == 1
    assert len(locs) >= 5
    assert locs == sorted(locs)
    assert len({line for line, _ in locs}) == len(locs)  # independent errors, one a line here
    assert text.endswith(f"1 file, {len(locs)} errors, 0 warnings\n")


def test_errors_of_several_files_keep_file_order(fsw):
    """Files in the order they were checked, each in line order."""
    r = fsw("check", "sm/several_errors.sm", "sv/several_errors.sv", cwd=GOLDEN)
    files = re.findall(r"^\S.* @ ([^:\n]+):\d+:\d+:$", r.err, re.M)
    n_sm = len(locations(run_case(GOLDEN / "sm" / "several_errors.sm")[0]))
    n_sv = len(locations(run_case(GOLDEN / "sv" / "several_errors.sv")[0]))
    assert files == ["sm/several_errors.sm"] * n_sm + ["sv/several_errors.sv"] * n_sv
    assert r.err.endswith(f"2 files, {n_sm + n_sv} errors, 0 warnings\n")


# ---- no input, however malformed, gives a traceback or a hang ----------------

def mutations(text: str, rng: random.Random, n: int):
    pieces = ["{", "}", "(", ")", ":", "->", "else", "if", "@stop", "@assert", "[", "]", "\t", "\n",
              ".step", ".exit", "=", "-", "not", "1e", "roll_avg(", ",", "\xff", "#", "T", "G"]
    for _ in range(n):
        s = list(text)
        for _ in range(rng.randint(1, 4)):
            i = rng.randrange(len(s) + 1)
            op = rng.random()
            if op < 0.5:
                s.insert(i, rng.choice(pieces))
            elif s and op < 0.8:
                del s[min(i, len(s) - 1)]
            elif s:
                j = rng.randrange(len(s))
                s[i:i] = s[j:j + rng.randint(1, 20)]
        yield "".join(s)


@pytest.mark.parametrize("lang", LANGS)
def test_mutated_golden_inputs_give_only_diagnostics(lang, tmp_path):
    """Golden inputs with random edits: every run ends with diagnostics and
    a summary, never a traceback, an internal error or a hang."""
    rng = random.Random(f"fswkit-{lang}")
    folder = GOLDEN / lang
    for companion in folder.glob("*.s[vm]"):
        if companion.suffix != f".{lang}":
            (tmp_path / companion.name).write_bytes(companion.read_bytes())
    seeds = [p.read_text(errors="surrogateescape") for p in sorted(folder.glob(f"*.{lang}"))]
    target = tmp_path / f"case.{lang}"
    for text in (m for seed in seeds for m in mutations(seed, rng, 4)):
        target.write_bytes(text.encode("utf-8", "surrogateescape"))
        r = run_fsw("check", target.name, cwd=tmp_path)
        assert r.code in (0, 1), (text, r.err)
        assert r.err.endswith("warnings\n") or r.err.endswith("warning\n"), (text, r.err)


def test_every_message_is_in_the_language_reference():
    """docs/languages.md lists each diagnostic, so that a user who searches
    for the message finds it."""
    doc = (ROOT / "docs" / "languages.md").read_text()
    missing = [f"{where}: {frag!r}" for frag, where in sorted(message_fragments().items(), key=lambda kv: kv[1])
               if frag not in doc]
    assert missing == []
