"""The front-end fuzzer (fswkit.testing.fuzz; tools/fuzz_frontend.py is its
command line): a short clean run, and proof that it finds what it is for — a
planted crash and a planted hang are reported, counted and saved. `make fuzz`
runs it for a million cases."""

from __future__ import annotations

import os
import time

import pytest

from fswkit.testing import fuzz

pytestmark = pytest.mark.costly(12)

CASES = int(os.environ.get("FSW_FUZZ_SMOKE", "500"))


@pytest.fixture(scope="module")
def projects():
    return fuzz.corpus(generated=4)


def test_cases_are_reproducible(projects):
    assert fuzz.make_case(projects, 7, 123) == fuzz.make_case(projects, 7, 123)
    assert fuzz.make_case(projects, 7, 123) != fuzz.make_case(projects, 7, 124)


def test_mutations_reach_every_file(projects):
    changed = set()
    for i in range(300):
        files, which = fuzz.make_case(projects, 1, i)
        changed |= which
    assert changed == {0, 1, 2}


def test_a_short_run_is_clean(projects, tmp_path):
    o = fuzz.fuzz(CASES, seed=11, workers=2, timeout=20, out=tmp_path, cli_every=50, projects=projects)
    assert o.cases == CASES
    assert (o.passed, o.failed) == (CASES, 0), o.signatures
    assert not any(tmp_path.iterdir())


def test_a_planted_crash_is_found_and_saved(projects, tmp_path, monkeypatch):
    from fswkit.autocode import parser

    real = parser.Parser.primary

    def primary(self):
        t = self.peek()
        if t.kind == "num" and len(t.text) > 12:  # a bug that only huge literals reach
            raise ZeroDivisionError("planted")
        return real(self)

    monkeypatch.setattr(parser.Parser, "primary", primary)
    # about one case in 18 reaches it: 11 of these 200 (38 of 600, the first at case 20)
    o = fuzz.fuzz(200, seed=3, workers=2, timeout=20, out=tmp_path, cli_every=0, projects=projects)
    assert o.failed > 0 and o.passed + o.failed == 200
    assert any("ZeroDivisionError" in s and "planted" in s for s in o.signatures)
    saved = [p for p in tmp_path.iterdir() if p.name.startswith("crash-")]
    assert saved and (saved[0] / "error.txt").read_text().count("planted")
    assert {p.name for p in saved[0].iterdir()} == {"p.sv", "p.sm", "p.ss", "error.txt"}


def test_a_planted_hang_is_found(projects, tmp_path, monkeypatch):
    from fswkit.autocode import lexer

    real = lexer.lex_line

    def lex_line(src, n, text, diags, lang):
        if "\t" in text and "{" in text:  # a hang that only tabs next to braces reach
            while True:  # (asleep: a hang need not keep a CPU busy while the test waits for it)
                time.sleep(60)
        return real(src, n, text, diags, lang)

    monkeypatch.setattr(lexer, "lex_line", lex_line)
    o = fuzz.fuzz(40, seed=5, workers=2, timeout=0.5, out=tmp_path, cli_every=0, projects=projects)
    assert o.failed > 0 and o.passed + o.failed == 40
    assert "hang" in o.signatures
    assert any(p.name.startswith("hang-") for p in tmp_path.iterdir())


def test_a_worker_stuck_beyond_the_alarm_is_killed_and_replaced(projects, tmp_path, monkeypatch):
    """A hang the alarm cannot end (here the signal is blocked) is found by
    the watchdog: the worker is killed, the case saved, the run completed."""
    import signal

    from fswkit.autocode import lexer

    real = lexer.lex_line

    def lex_line(src, n, text, diags, lang):
        if "\t" in text and "{" in text:
            signal.pthread_sigmask(signal.SIG_BLOCK, [signal.SIGALRM])
            while True:
                time.sleep(60)
        return real(src, n, text, diags, lang)

    monkeypatch.setattr(lexer, "lex_line", lex_line)
    # the cases of test_a_planted_hang_is_found, where tabs next to braces come up
    o = fuzz.fuzz(40, seed=5, workers=2, timeout=0.3, stall=1.0, out=tmp_path, cli_every=0, projects=projects)
    assert o.passed + o.failed == 40 and o.failed > 0
    assert any(s.startswith("hang (worker killed)") for s in o.signatures)
    assert any(p.name.startswith("hang-") for p in tmp_path.iterdir())


def test_generated_projects_do_not_depend_on_what_was_imported_before():
    """Hypothesis draws constants from every local module imported so far;
    the corpus's generated programs are drawn without them, so a case
    number means the same input in any process."""
    import subprocess
    import sys

    draw = ("from fswkit.testing import fuzz; import hashlib; "
            "print(hashlib.sha256(repr([p.files for p in fuzz.generated_projects(6)]).encode()).hexdigest())")
    more = "import fswkit.plant.run, fswkit.link.session, fswkit.new.project, fswkit.ground.monitor; "
    a, b = (subprocess.run([sys.executable, "-c", pre + draw], capture_output=True, text=True, timeout=120)
            for pre in ("", more))
    assert a.returncode == b.returncode == 0, a.stderr + b.stderr
    assert a.stdout == b.stdout
