"""The front end's mutation fuzzer: its corpus, mutators, invariants and
worker pool. tools/fuzz_frontend.py is its command line (`make fuzz`);
the tests run it in small (tests/fuzz, tests/autocode/lexer).

Each case takes a project (a `.sv`, a `.sm` and a `.ss`) from the corpus —
the examples, the state languages' golden cases (tests/autocode/golden) in
a source tree, and programs drawn from fswkit.testing.strategies — mutates one or more of its files (token deletions,
duplications and swaps, byte flips, truncation, inserted brackets,
operators, keywords, huge numbers, deep nesting, long lines, tabs, CR, NUL,
non-UTF-8, random bytes), and runs it through every loader in-process:
`load_sv`, `load_machine` (with `fsw check`'s warnings), `load_script`, a
bounded run of a script that compiles (in binary64 or binary32), and every
100th case `fsw check` / `fsw test` themselves. The invariants (spec §8):
nothing raises, nothing hangs (a case has 10 s), every diagnostic is
located inside its file and its caret line renders, a loader returns a
model exactly when it reported no error, and the commands exit 0, 1 or 2.

Cases are numbered; case i is a pure function of (seed, i), so any case can
be rebuilt from its number. Failing inputs go to the folder `fuzz` is
given (the command line's default: build/fuzz/crashes/).
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import io
import multiprocessing as mp
import os
import random
import re
import shutil
import signal
import sys
import tempfile
import time
import traceback
from pathlib import Path

from fswkit.autocode.kit import ROOT as KIT_ROOT

# The source tree's examples/ and tests/ (autocode.kit knows where the tree
# is): an installed kit has neither, and its corpus is the generated programs.
ROOT = Path(KIT_ROOT)
NAMES = ("p.sv", "p.sm", "p.ss")
RUN_STEPS = 50  # steps of a bounded script run
CLI_TEST_MAX_STEPS = 2000  # `fsw test` only runs scripts bounded this tightly


@dataclasses.dataclass(frozen=True)
class Project:
    name: str
    files: tuple[bytes, bytes, bytes]  # .sv, .sm, .ss
    valid: bool = False  # all three check without errors


# ---- the corpus ------------------------------------------------------------------

def _projects_in(folder: Path) -> list[Project]:
    """Every (.sv, .sm, .ss) triple a folder's configs form, as `fsw` pairs
    them; a machine without a script gets a one-line script."""
    from fswkit.autocode.project import find_beside

    out: list[Project] = []
    for dirpath, dirnames, filenames in os.walk(folder):
        dirnames.sort()
        d = Path(dirpath)
        used_sm = set()
        for ss in sorted(n for n in filenames if n.endswith(".ss")):
            sm = find_beside(str(d / ss), ".sm")
            sv = find_beside(sm, ".sv") if sm else None
            if sm and sv:
                used_sm.add(os.path.basename(sm))
                out.append(Project(str(d / ss), (Path(sv).read_bytes(), Path(sm).read_bytes(),
                                                 (d / ss).read_bytes())))
        for sm in sorted(n for n in filenames if n.endswith(".sm") and n not in used_sm):
            sv = find_beside(str(d / sm), ".sv")
            if sv:
                out.append(Project(str(d / sm), (Path(sv).read_bytes(), (d / sm).read_bytes(),
                                                 b"[options]\ndelta_t 1\n[all_states]\nG >= 5: @stop\n")))
    return out


def generated_projects(n: int) -> list[Project]:
    """`n` programs drawn (deterministically) from fswkit.testing.strategies."""
    if n <= 0:
        return []
    try:
        from hypothesis import HealthCheck, Phase, given, settings
    except ImportError:  # the test extra is not installed: examples only
        return []
    from fswkit.testing import strategies

    out: list[Project] = []

    @settings(max_examples=n, database=None, derandomize=True, phases=[Phase.generate],
              suppress_health_check=list(HealthCheck), deadline=None)
    @given(strategies.programs(), strategies.st.booleans(), strategies.st.randoms(use_true_random=False))
    def collect(p, spelled, r):
        if spelled:  # canonical text or other spellings
            texts = (strategies.spell_sv(p.sv, r), strategies.spell_sm(p.sm, r), strategies.spell_ss(p.ss, r))
        else:
            texts = (p.sv_text, p.sm_text, p.ss_text)
        out.append(Project(f"generated-{len(out)}", tuple(t.encode() for t in texts)))

    with _without_local_constants():
        collect()
    return out


@contextlib.contextmanager
def _without_local_constants():
    """Hypothesis (6.131 on) mixes into its draws constants it finds in the
    source of every local module imported so far, so a derandomized draw
    depends on what the process imported before it. Drawing with that pool
    empty makes the generated programs, and so every case, a function of
    (seed, index) alone."""
    try:
        from hypothesis.internal.conjecture import providers
        empty = providers.Constants()
        cache = providers.CONSTANTS_CACHE.cache
        real = providers._get_local_constants
    except (ImportError, AttributeError):  # another Hypothesis: nothing to hold still
        yield
        return
    cache.clear()
    providers._get_local_constants = lambda: empty
    try:
        yield
    finally:
        providers._get_local_constants = real
        cache.clear()


def _checked(p: Project, d: str) -> Project:
    """`p` marked valid or not, its files written into the folder `d` (one
    folder for a whole corpus: a folder made and removed for each of its
    projects was half of the corpus's time)."""
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.project import load_script

    paths = [os.path.join(d, n) for n in NAMES]
    for path, data in zip(paths, p.files):
        with open(path, "wb") as f:
            f.write(data)
    diags = Diagnostics()
    ok = load_script(paths[2], diags, paths[1], paths[0]) is not None and not diags.errors
    return dataclasses.replace(p, valid=ok)


def corpus(generated: int = 60) -> list[Project]:
    """The examples, the state languages' golden cases (configs with errors,
    mostly) and generated valid programs, each marked valid or not."""
    projects = _projects_in(ROOT / "examples")
    for lang in ("sm", "ss", "sv"):  # the order a walk of golden/ gives
        projects += _projects_in(ROOT / "tests" / "autocode" / "golden" / lang)
    with tempfile.TemporaryDirectory() as d:
        return [_checked(p, d) for p in projects + generated_projects(generated)]


# ---- mutations -------------------------------------------------------------------------

_TOKEN = re.compile(rb"[A-Za-z_][A-Za-z0-9_]*|[0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?|@\w+|\.\w+"
                    rb"|->|[<>=!]=|[ \t]+|\r?\n|.", re.S)
_NUMBER = re.compile(rb"[0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?")
_IDENT = re.compile(rb"[A-Za-z_][A-Za-z0-9_]*")

DICTIONARY = [s.encode() for s in (
    "[", "]", "{", "}", "(", ")", ":", ",", "->", "=", "==", "!=", "<", "<=", ">", ">=", "+", "-",
    "*", "/", "!", "and", "or", "not", "if", "else", "else if", "else:", "true", "false", "@stop",
    "@assert", "@alias", "@read_only", "@alias G", "@alias S", "@bogus", ".entry", ".step", ".exit",
    ".other", "[all_states]", "[local]", "[state_vector]", "[options]", "[X]", "[]", "T", "G", "S",
    "delta_t", "init_state", "max_steps", "lock", "I8", "I16", "I32", "I64", "U8", "U16", "U32",
    "U64", "F32", "F64", "bool", "roll_avg(", "roll_median(", "roll_min(x, 3)", "roll_max",
    "roll_range(1, 100001)", "roll_avg(1, 0)", "roll_avg(1, 2.5)", "foo(", "#", "# comment",
    "\n", "\n\n", " ", "\t", "\r", "\r\n", "\x00", "\x0b", "\x0c", "\x7f", "\u2028", "\x85",
    "\ufeff", "\u00e9", "\U0001f680", "0", "-1", "1e309", ".5", "5.", "1e", "1.2.3", "0x10",
    "9" * 40, "1e-400", "18446744073709551616", "1e4001",
)] + [b"\xff", b"\xfe\xff", b"\xc3", b"\xed\xa0\x80", b"\x80"]

SPECIALS = [
    lambda r: b"(" * r.choice((3, 63, 64, 65, 200, 2000)) + b"1" + b")" * r.choice((0, 3, 64, 2000)),
    lambda r: b"-" * r.choice((2, 64, 65, 500, 5000)) + b"1",
    lambda r: b"not " * r.choice((2, 64, 65, 300)) + b"x",
    lambda r: b"!" * r.choice((2, 65, 1000)) + b"x",
    lambda r: b"{\n" * r.choice((2, 65, 300)) + b"x = 1\n" + b"}\n" * r.choice((0, 2, 300)),
    lambda r: b"a: " * r.choice((2, 65, 300)) + b"x = 1",
    lambda r: b"if a {\n} else " * r.choice((2, 70)) + b"{ }",
    lambda r: b" + ".join([b"x"] * r.choice((10, 199, 200, 201, 2000))),
    lambda r: b" < ".join([b"1"] * r.choice((3, 300))),
    lambda r: b"roll_avg(" * r.choice((2, 65)) + b"1" + b", 2)" * r.choice((2, 65)),
    lambda r: b"x" * r.choice((1000, 30000)),
    lambda r: b" " * r.choice((100, 5000)) + b"\t" * r.choice((1, 50)) + b"x",
    lambda r: b"9" * r.choice((20, 400, 5000)),
    lambda r: b"1e" + str(r.choice((38, 39, 308, 309, 4000, 4001, 99999999))).encode(),
    lambda r: b"0." + b"0" * r.choice((50, 400, 3000)) + b"1",
    lambda r: b"\n" * r.choice((100, 3000)),
    lambda r: bytes(r.randrange(256) for _ in range(r.randrange(1, 40))),
    lambda r: b"[" + b"A" * r.choice((1, 300)) + b"]\n.entry\n",
    lambda r: b"\t" + b"a + " * r.choice((100, 10000)),  # many tokens after a tab
    lambda r: b"1a " * r.choice((10, 500)),  # many diagnostics on one line
    lambda r: b"x = roll_avg(zz, 3)\n" * r.choice((10, 2000)),  # many windows with errors
]

EDGE_NUMBERS = [s.encode() for s in (
    "0", "1", "-1", "0.5", "255", "256", "65536", "2147483648", "4294967296", "16777217",
    "9007199254740993", "18446744073709551615", "18446744073709551616", "1e19", "3.4028236e38",
    "1e39", "1e308", "1e309", "1e-46", "5e-324", "1e-400", "100000", "100001", "0.0", "1e4001")]


def _tokens(data: bytes) -> list[bytes]:
    return _TOKEN.findall(data)


def mutate_once(data: bytes, r: random.Random, others: list[bytes]) -> bytes:
    k = r.randrange(20)
    n = len(data)
    if k == 0 and n:  # flip a bit
        i = r.randrange(n)
        return data[:i] + bytes([data[i] ^ (1 << r.randrange(8))]) + data[i + 1:]
    if k == 1:  # insert, replace or delete a random byte
        i = r.randrange(n + 1)
        b = bytes([r.randrange(256)])
        return r.choice((data[:i] + b + data[i:], data[:i] + b + data[i + 1:], data[:i] + data[i + 1:]))
    if k == 2:  # truncate, or split a token / join two
        i = r.randrange(n + 1)
        op = r.randrange(3)
        if op == 0:
            return data[:i]
        if op == 1:
            return data[:i] + r.choice((b" ", b"\t", b"\n")) + data[i:]
        spaces = [m.start() for m in re.finditer(rb"[ \t]", data)]
        if spaces:
            j = r.choice(spaces)
            return data[:j] + data[j + 1:]
        return data
    if k in (3, 4, 5, 6, 7):  # token deletion, duplication, swap, replacement, insertion
        toks = _tokens(data)
        if not toks:
            return r.choice(DICTIONARY)
        i = r.randrange(len(toks))
        if k == 3:
            del toks[i]
        elif k == 4:
            toks.insert(i, toks[i])
        elif k == 5:
            j = r.randrange(len(toks))
            toks[i], toks[j] = toks[j], toks[i]
        elif k == 6:
            toks[i] = r.choice(DICTIONARY + toks)
        else:
            toks.insert(i, r.choice(DICTIONARY) + r.choice((b"", b" ")))
        return b"".join(toks)
    if k in (8, 9):  # a special: huge numbers, deep nesting, long lines, control bytes
        i = r.randrange(n + 1)
        return data[:i] + r.choice(SPECIALS)(r) + data[i:]
    if k in (10, 11, 12, 13):  # line operations
        lines = data.split(b"\n")
        i, j = r.randrange(len(lines)), r.randrange(len(lines))
        op = r.randrange(5)
        if op == 0:
            del lines[i]
        elif op == 1:
            lines.insert(j, lines[i])
        elif op == 2:
            lines[i], lines[j] = lines[j], lines[i]
        elif op == 3:  # crossover from another file
            src = r.choice(others).split(b"\n") if others else lines
            a = r.randrange(len(src))
            lines[i:i] = src[a:a + r.randrange(1, 6)]
        else:
            lines[i] = r.choice((b"\t", b"    ", b"")) + lines[i] + r.choice((b"\r", b" \t", b"#", b"\x00"))
        return b"\n".join(lines)
    if k in (14, 15):  # a number for an edge number
        nums = list(_NUMBER.finditer(data))
        if nums:
            m = r.choice(nums)
            return data[:m.start()] + r.choice(EDGE_NUMBERS) + data[m.end():]
    if k in (16, 17):  # an identifier for another of the project's
        ids = list(_IDENT.finditer(data))
        if ids:
            m = r.choice(ids)
            pool = [x.group() for x in ids] + [b"G", b"S", b"T", b"if", b"else", b"roll_avg"]
            return data[:m.start()] + r.choice(pool) + data[m.end():]
    if k == 18:  # line endings and indentation
        return r.choice((data.replace(b"\n", b"\r\n"), data.replace(b"    ", b"\t"),
                         data.replace(b"\n", b"\r"), data.replace(b" ", b"\t")))
    i = r.randrange(n + 1)  # a dictionary entry anywhere
    return data[:i] + r.choice(DICTIONARY) + data[i:]


def mutate(data: bytes, r: random.Random, others: list[bytes]) -> bytes:
    n = 1
    while n < 9 and r.random() < 0.5:  # 1 mutation half the time, 2 a quarter, ...
        n += 1
    for _ in range(n):
        data = mutate_once(data, r, others)
    return data


def make_case(projects: list[Project], seed: int, index: int) -> tuple[tuple[bytes, bytes, bytes], frozenset]:
    """Case `index`, a pure function of (seed, index): the three files and
    the indices (0 .sv, 1 .sm, 2 .ss) of those that were changed."""
    r = random.Random(seed * 0x9E3779B97F4A7C15 + index)
    valid = [p for p in projects if p.valid] if r.random() < 0.6 else None
    files = list(r.choice(valid or projects).files)  # valid ones more often: they reach the checker
    others = [f for p in (r.choice(projects), r.choice(projects)) for f in p.files]
    which = r.random()
    targets = [r.choice((0, 1, 1, 2, 2, 2))]
    if which < 0.04:  # random bytes
        files[targets[0]] = bytes(r.randrange(256) for _ in range(r.randrange(200)))
    elif which < 0.06:  # random bytes drawn from the language's alphabet
        alphabet = b"[]{}():,=<>!-+*/.@#_ \t\n\r\x00aGSTxy019eE"
        files[targets[0]] = bytes(r.choice(alphabet) for _ in range(r.randrange(300)))
    else:
        if r.random() < 0.15:
            targets.append(r.randrange(3))
        for t in targets:
            files[t] = mutate(files[t], r, others)
    return tuple(files), frozenset(targets)


# ---- one case: the invariants -----------------------------------------------------------

class Hang(BaseException):
    """A case ran past its time limit (BaseException: no handler in the
    front end may swallow it)."""


def check_diagnostics(diags, sources: dict[str, str]) -> None:
    """Every diagnostic names one of the files, a line inside it and a
    column inside that line (or just past its end), shows the line as
    written and renders with its caret under that column."""
    from fswkit.autocode.diagnostics import SHOWN, Source, display_line

    split: dict[str, tuple[str, ...]] = {}
    for d in diags.items:
        assert d.path in sources, f"diagnostic names an unknown file {d.path!r}"
        if d.path not in split:
            split[d.path] = Source.from_text(d.path, sources[d.path]).lines
        lines = split[d.path]
        assert 1 <= d.line <= len(lines), f"line {d.line} outside {d.path} ({len(lines)} lines): {d.message}"
        assert d.source_line == lines[d.line - 1], f"diagnostic shows the wrong line: {d.message}"
        shown = display_line(d.source_line)
        assert 1 <= d.col <= len(shown) + 1, f"column {d.col} outside line {d.line} ({len(shown)} columns): {d.message}"
        assert d.message and d.severity in ("error", "warning")
        text = d.render().split("\n")
        assert len(text) == 3 + d.message.count("\n"), "rendered diagnostic has the wrong shape"
        assert text[0].endswith(f" @ {d.path}:{d.line}:{d.col}:"), text[0]
        if len(shown) <= SHOWN:
            assert text[1] == "  | " + shown
            assert text[2].startswith("  | " + " " * (d.col - 1) + "^ "), "caret not under the column"
        else:  # a long line is cut around the caret: the caret still points at its character
            cut, caret = text[1][4:], text[2].index("^") - 4
            assert len(cut) <= SHOWN + 6 and (cut.startswith("...") or cut.startswith(shown[:SHOWN]))
            assert cut[caret:caret + 1] == shown[d.col - 1:d.col], "caret not under the column"


def run_case(files: tuple[bytes, bytes, bytes], workdir: str, cli: bool = False,
             changed: frozenset = frozenset((0, 1, 2))) -> None:
    """Runs one case; raises (AssertionError or the front end's own
    exception) when an invariant breaks. Loaders whose inputs did not
    change (`changed`: 0 .sv, 1 .sm, 2 .ss) are not run again on their own:
    `load_script` still reads all three. The collector runs as seldom as
    in the loaders (fswkit.autocode.collect) for the whole case."""
    from fswkit.autocode.collect import fewer_collections

    with fewer_collections():
        _run_case(files, workdir, cli, changed)


def _run_case(files: tuple[bytes, bytes, bytes], workdir: str, cli: bool, changed: frozenset) -> None:
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.numeric import F32MODE, F64MODE
    from fswkit.autocode.project import load_machine, load_script, load_sv
    from fswkit.run.script import run

    paths = [os.path.join(workdir, n) for n in NAMES]
    sources = {}
    for p, data in zip(paths, files):
        with open(p, "wb") as f:
            f.write(data)
        sources[p] = _decode(data)
    sv, sm, ss = paths

    if 0 in changed:
        d = Diagnostics()
        load_sv(sv, d)
        check_diagnostics(d, sources)
    if 0 in changed or 1 in changed:
        d = Diagnostics()
        m = load_machine(sm, d, sv, warnings=True)
        check_diagnostics(d, sources)
        assert (m is None) == bool(d.errors), "a machine with errors was returned, or none without"
    d = Diagnostics()
    script = load_script(ss, d, sm, sv)
    check_diagnostics(d, sources)
    assert (script is None) == bool(d.errors), "a script with errors was returned, or none without"
    if script is not None:
        bounded = dataclasses.replace(script, max_steps=min(script.max_steps, RUN_STEPS))
        real = F32MODE if len(files[2]) % 2 else F64MODE  # one of the two, by the case
        res = run(bounded, real, source_line=lambda path, n: sources[path].split("\n")[n - 1]
                  if 0 < n <= sources[path].count("\n") + 1 else "")
        assert res.report().startswith("state script ran for ")
    if cli:
        from fswkit.cli import main

        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            codes = [main(["check", workdir])]
            if script is None or script.max_steps <= CLI_TEST_MAX_STEPS:
                codes.append(main(["test", ss, "--real", "f32" if len(files[2]) % 2 else "f64"]))
        for code in codes:
            assert code in (0, 1, 2), f"fsw exited {code}: {err.getvalue()[-2000:]}"
        assert "Traceback" not in err.getvalue() and "internal error" not in err.getvalue()


def _decode(data: bytes) -> str:
    """A file's text as the loaders see it."""
    from fswkit.autocode.diagnostics import decode

    return decode(data)


# ---- workers ----------------------------------------------------------------------------

def _on_alarm(signum, frame):
    raise Hang()


def record(out: Path, index: int, files, kind: str, detail: str, limit: int = 200) -> None:
    out.mkdir(parents=True, exist_ok=True)
    if sum(1 for _ in out.iterdir()) >= limit:
        return
    digest = hashlib.sha1(b"\0".join(files)).hexdigest()[:12]
    case = out / f"{kind}-{index}-{digest}"
    case.mkdir(exist_ok=True)
    for name, data in zip(NAMES, files):
        (case / name).write_bytes(data)
    (case / "error.txt").write_text(detail)


def _signature(exc: BaseException) -> str:
    tb = traceback.extract_tb(exc.__traceback__)
    where = f"{os.path.basename(tb[-1].filename)}:{tb[-1].lineno}" if tb else "?"
    return f"{type(exc).__name__} at {where}: {str(exc)[:200]}"


def _worker(wid, nworkers, first, total, seed, projects, timeout, cli_every, out, counts, current, sigs):
    """Runs cases first, first + nworkers, ... below total."""
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 1000))
    signal.signal(signal.SIGALRM, _on_alarm)
    shm = "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) else None
    workdir = tempfile.mkdtemp(prefix=f"fswfuzz{wid}-", dir=shm)
    out = Path(out)
    os.environ["FSW_DEBUG"] = "1"  # `fsw` raises instead of printing "internal error"
    passed = failed = 0
    reported: set[str] = set()

    def report(sig: str) -> None:
        if sig not in reported and len(reported) < 50:
            reported.add(sig)
            sigs.put(sig)
    try:
        for i in range(first, total, nworkers):
            current[wid] = i
            files, changed = make_case(projects, seed, i)
            try:
                signal.setitimer(signal.ITIMER_REAL, timeout)
                try:
                    run_case(files, workdir, cli=cli_every > 0 and i % cli_every == 0, changed=changed)
                finally:
                    signal.setitimer(signal.ITIMER_REAL, 0)
                passed += 1
            except Hang:
                failed += 1
                record(out, i, files, "hang", f"seed {seed} case {i}: no result within {timeout} s\n")
                report("hang")
            except BaseException as e:  # noqa: BLE001 - every failure is the finding
                if isinstance(e, KeyboardInterrupt):
                    raise
                failed += 1
                detail = f"seed {seed} case {i}\n" + "".join(traceback.format_exception(e))
                record(out, i, files, "crash", detail)
                report(_signature(e))
            counts[2 * wid], counts[2 * wid + 1] = passed, failed  # a killed worker's count stays
    finally:
        counts[2 * wid], counts[2 * wid + 1] = passed, failed
        current[wid] = -1
        shutil.rmtree(workdir, ignore_errors=True)


@dataclasses.dataclass
class Outcome:
    cases: int
    passed: int
    failed: int
    seconds: float
    signatures: dict[str, int]


def fuzz(cases: int, seed: int = 1, workers: int = 2, timeout: float = 10.0, out: str | Path | None = None,
         cli_every: int = 100, generated: int = 60, projects: list[Project] | None = None,
         progress=None, stall: float | None = None) -> Outcome:
    """Runs `cases` cases over `workers` processes (fork) and returns the
    counts. A worker that makes no progress for `stall` seconds (default
    3 x timeout + 5: a hang the alarm cannot interrupt, in C code or with
    the signal blocked) is killed, its case recorded, and restarted."""
    stall = stall if stall is not None else 3 * timeout + 5
    out = Path(out or ROOT / "build" / "fuzz" / "crashes")
    projects = projects if projects is not None else corpus(generated)
    ctx = mp.get_context("fork")
    counts = ctx.Array("q", 2 * workers, lock=False)
    current = ctx.Array("q", workers, lock=False)
    sigs = ctx.SimpleQueue()
    base = [0] * (2 * workers)  # counts of killed workers' earlier runs
    start = time.monotonic()

    def spawn(wid, first):
        counts[2 * wid] = counts[2 * wid + 1] = 0
        current[wid] = first
        p = ctx.Process(target=_worker, args=(wid, workers, first, cases, seed, projects, timeout,
                                              cli_every, str(out), counts, current, sigs), daemon=True)
        p.start()
        return p

    procs = [spawn(w, w) for w in range(workers)]
    seen = [(-2, time.monotonic())] * workers
    signatures: dict[str, int] = {}
    last_report = time.monotonic()

    def drain():
        while not sigs.empty():
            s = sigs.get()
            signatures[s] = signatures.get(s, 0) + 1

    try:
        while any(p.is_alive() for p in procs):
            time.sleep(0.2)
            drain()
            now = time.monotonic()
            for w, p in enumerate(procs):
                if not p.is_alive():
                    continue
                cur = current[w]
                if cur != seen[w][0]:
                    seen[w] = (cur, now)
                elif now - seen[w][1] > stall:  # stuck where the alarm cannot reach
                    p.kill()
                    p.join()
                    base[2 * w] += counts[2 * w]
                    base[2 * w + 1] += counts[2 * w + 1] + 1
                    record(out, cur, make_case(projects, seed, cur)[0], "hang",
                            f"seed {seed} case {cur}: worker stuck for {now - seen[w][1]:.0f} s\n")
                    signatures[f"hang (worker killed): case {cur}"] = 1
                    procs[w] = spawn(w, cur + workers)
                    seen[w] = (-2, now)
            if progress and now - last_report >= 15:
                last_report = now
                done = sum(counts) + sum(base)
                progress(f"fuzz: {done}/{cases} cases, {sum(counts[1::2]) + sum(base[1::2])} failed, "
                         f"{now - start:.0f} s")
    finally:  # interrupted or terminated: no worker outlives the run
        for p in procs:
            if p.is_alive():
                p.kill()
    for p in procs:
        p.join()
    drain()
    passed = sum(counts[0::2]) + sum(base[0::2])
    failed = sum(counts[1::2]) + sum(base[1::2])
    return Outcome(passed + failed, passed, failed, time.monotonic() - start, signatures)
