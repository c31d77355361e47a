"""Configurations the checker accepted could produce C++ that did not
compile (names that collide in C++, tables past their C types' range).
Property: any application the checker (`load_app`, what `fsw check` runs)
accepts generates pure-ASCII C++ without an error and that C++ compiles for
the board it names and natively; or the checker refuses it itself, with a
diagnostic. Never a generator exception, never a compiler error.

Hypothesis draws whole projects: a machine from fswkit.testing.strategies (states,
statements, locals, windows) plus machines, elements, locals, states,
regions and tasks named after C++ keywords, the generated code's own
identifiers (taken from the generated code itself), runtime and C library
names and platform macros; state vectors up to past an Uno's RAM; executor,
task and stream rates up to past their tables' 16-bit ranges; 0 to 260
tasks; odd application file names. Hypothesis draws the projects in chunks
of 120, one seed each; the accepted ones are compiled in one -fsyntax-only
run per board and chunk (tests/support/cxx.py). FSW_GEN_CASES (default
120, one chunk) sets how many projects; `make fuzz` runs 20,000."""

from __future__ import annotations

import os
import re
import shutil
from fractions import Fraction

import pytest
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from support import cxx
from conftest import EXAMPLES
from fswkit.autocode.app import load_app
from fswkit.autocode.board import load_board
from fswkit.autocode.cnames import CXX_KEYWORDS, TAKEN
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.app import emit_app
from fswkit.autocode.lexer import KEYWORDS
from fswkit.testing.strategies import RESERVED, programs

CASES = int(os.environ.get("FSW_GEN_CASES", "120"))
CHUNK = 120  # projects per seed and compiler run
BOARDS = ("uno", "nano", "mega2560", "native")
needs_avr = pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")


def _generated_identifiers() -> list[str]:
    """Every identifier of the example tank's generated C++: names a user's
    name must not collide with, whatever the generator comes to use."""
    app = load_app(str(EXAMPLES / "tank" / "tank.app"), Diagnostics(), board_override="native")
    text = "\n".join(emit_app(app).values())
    text = re.sub(r'//.*|"(\\.|[^"\\])*"', "", text)
    return sorted(set(re.findall(r"\b[A-Za-z_][A-Za-z0-9_]*\b", text)))


def _ok(n: str) -> bool:
    return n not in KEYWORDS and n not in RESERVED and n not in ("G", "S", "T")


MACROS = ("PORTB", "F_CPU", "HIGH", "LOW", "A0", "INPUT", "PRIu8", "EOF", "NULL", "SREG", "DDRB", "TCNT0",
          "UDR0", "RAMEND", "ADC_vect", "tmpnam", "ctermid", "cuserid", "SET", "XTND", "INCR", "OK",
          "IFMT", "stdin", "stdout", "sinf", "linux", "unix", "errno", "assert", "min", "max", "abs",
          "round", "bit", "Serial", "String", "setup", "loop", "main", "con", "nul", "com1")
DANGER = tuple(sorted({n for n in (*CXX_KEYWORDS, *TAKEN, *MACROS, *_generated_identifiers()) if _ok(n)}))
names = st.one_of(st.sampled_from(DANGER), st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,8}", fullmatch=True)).filter(_ok)

EXEC_RATES = (1, 2, 4, 5, 8, 10, 16, 20, 25, 50, 100, 125, 200, 250, 500, 1000, 2000, 5000, 62500, 100000)
DIVIDERS = (1, 1, 1, 2, 4, 5, 10, 100, 1000, 64000, 65536)
APP_NAMES = ("a.app", 'q"uote ??= \\.app', "t\tab.app", "caf\u00e9 \u2603.app", "new\nline.app")


def _decimal(q: Fraction) -> str:
    """An exact decimal literal for q (its denominator is 2^a 5^b)."""
    n, d = q.numerator, q.denominator
    k = 0
    while (10 ** k) % d:
        k += 1
    whole = n * (10 ** k // d)
    s = str(whole).rjust(k + 1, "0")
    return s if k == 0 else f"{s[:-k]}.{s[-k:]}"


@st.composite
def projects(draw) -> dict:
    """One project: {file name: text}, the .app's name, its board."""
    prog = draw(programs(max_states=3, max_elements=3, max_locals=3))
    sv_text, sm_text = prog.sv_text, prog.sm_text
    taken = {d.name for r in prog.sv.regions for d in r.elements} | {r.header.name for r in prog.sv.regions}
    g = next(e.name for e in prog.sm.elements if "G" in (e.name, e.alias))

    pool = [n for n in draw(st.lists(names, unique=True, min_size=24, max_size=24)) if n not in taken]
    pool += [f"n{i}" for i in range(40)]
    pool = [n for n in dict.fromkeys(pool) if n not in taken]
    take = iter(pool).__next__

    # Extra elements with drawn names, a mode element, the extra machines' S.
    extra_machines = draw(st.integers(0, 2))
    stems = draw(st.lists(names, unique=True, min_size=extra_machines + 1, max_size=extra_machines + 1))
    s_elems = [take() for _ in range(extra_machines)]
    mode = take()
    plain = [(draw(st.sampled_from(("U8", "I16", "F32", "F64", "bool", "U64"))), take())
             for _ in range(draw(st.integers(0, 4)))]
    bulk = draw(st.sampled_from((0, 0, 0, 10, 240, 260)))  # F64s: 260 pass an Uno's 2 KB
    region = take()
    sv_text += f"[{region}]\nU8 {mode}\n" + "".join(f"U32 {s}\n" for s in s_elems) + \
        "".join(f"{t} {n}\n" for t, n in plain) + "".join(f"F64 {region}_{i}\n" for i in range(bulk))
    files = {"p.sv": sv_text, f"{stems[0]}.sm": sm_text}
    io = []  # channels on elements with drawn names: an analog input, digital ones both ways
    if draw(st.booleans()):
        ain, din, dout = take(), take(), take()
        sv_text += f"F32 {ain}\nbool {din}\nbool {dout}\n"
        files["p.sv"] = sv_text
        io_stem = draw(names)
        files[f"{io_stem}.aio"] = f"i A0 {ain} scale={draw(st.sampled_from(('250', '1e30', '0.001')))} offset=-1\n"
        files[f"{io_stem}.dio"] = f"i 2 {din}\no 13 {dout}\n"
        io = [f"io {io_stem}.aio", f"io {io_stem}.dio"]
        tasks_io = [f"{take()} inputs", f"{take()} outputs"]
    else:
        tasks_io = []
    for k in range(extra_machines):
        local, a, b = take(), take(), take()
        files[f"{stems[k + 1]}.sm"] = (
            f"[state_vector]\nU64 {g}{' @alias G' if g != 'G' else ''}\nU32 {s_elems[k]} @alias S\n\n"
            f"[local]\nF32 {local} = 1\n\n[{a}]\n.step\n    {local} = {local} + 1\n    {local} > 3: -> {b}\n\n"
            f"[{b}]\n.entry\n    {local} = 0\n.step\n    -> {a}\n")

    board = draw(st.sampled_from(BOARDS))
    rate = draw(st.sampled_from(EXEC_RATES))
    unit = draw(st.sampled_from(("ms", "us")))
    source = draw(st.sampled_from(("clock", "clock", "cycle")))

    def task_rate():
        return Fraction(rate) / draw(st.sampled_from(DIVIDERS))

    tasks = []
    for k, stem in enumerate(stems):
        opts = f" mode={mode}" if k == 0 and draw(st.booleans()) else ""
        tasks.append(f"{take()} machine {stem} rate={_decimal(task_rate())}{opts}")
    tele = None
    if draw(st.booleans()):
        tele = task_rate()
        tasks.append(f"{take()} telemetry rate={_decimal(tele)}")
    if draw(st.booleans()):
        tasks.append(f"{take()} uplink rate={_decimal(task_rate())}")
    n_out = draw(st.sampled_from((0, 0, 1, 3, 253, 260)))
    tasks += [f"{take() if i < 3 else f'o{i}'} outputs" for i in range(n_out)] + tasks_io
    tasks = draw(st.permutations(tasks))

    telemetry = []
    if tele is not None:
        for r in draw(st.lists(st.sampled_from([r.header.name for r in prog.sv.regions] + [region]),
                               unique=True, max_size=3)):
            telemetry.append(f"{r} rate={_decimal(tele / draw(st.sampled_from(DIVIDERS)))}")
    uplink = draw(st.lists(st.sampled_from([n for _, n in plain]), unique=True, max_size=3)) if plain else []

    app_name = draw(st.sampled_from(APP_NAMES))
    files[app_name] = (
        f"[application]\nboard {board}\nrate {rate}\n[configs]\nstate_vector p.sv\n"
        + "".join(f"machine {s}.sm\n" for s in stems) + "".join(f"{line}\n" for line in io)
        + f"[time]\nsource {source}\nunit {unit}\n[tasks]\n" + "\n".join(tasks) + "\n"
        + "[telemetry]\n" + "".join(f"{t}\n" for t in telemetry)
        + "[uplink]\n" + "".join(f"{u}\n" for u in uplink))
    return {"files": files, "app": app_name, "board": board}


def _describe(p: dict) -> str:
    return "\n".join(f"--- {name!r}\n{text}" for name, text in sorted(p["files"].items()) if not
                     name.endswith(".sv") or len(text) < 2000)


def _check(p: dict, folder: str, cases: dict) -> None:
    """Writes project `p` into `folder`, loads it for its board and natively;
    each accepted application's generated files go to cases[board]."""
    os.makedirs(folder)
    for name, text in p["files"].items():
        with open(os.path.join(folder, name), "w", encoding="utf-8") as f:
            f.write(text)
    for board in dict.fromkeys((p["board"], "native")):
        diags = Diagnostics()
        app = load_app(os.path.join(folder, p["app"]), diags, board_override=board)
        if app is None:
            assert diags.errors, "refused without a diagnostic"
            continue
        files = emit_app(app)  # never an exception for an accepted application
        bad = [n for n, t in files.items() if not t.isascii()]
        assert not bad, f"non-ASCII C++ in {bad}\n{_describe(p)}"
        cases.setdefault(board, []).append((p, files))


@needs_avr
def test_accepted_configs_compile_for_their_board_and_natively(tmp_path):
    # Hypothesis draws the projects and checks what needs no compiler (the
    # loader's and generator's side); the compiler then sees the accepted
    # ones, one run per board and chunk. Chunks of CHUNK projects, each
    # from its own seed, keep memory and disk flat however many there are.
    accepted = 0
    for chunk, start in enumerate(range(0, CASES, CHUNK)):
        cases: dict[str, list] = {}
        folder = tmp_path / f"chunk{chunk}"
        seen = iter(range(10 ** 9))

        @seed(chunk)
        @settings(max_examples=min(CHUNK, CASES - start), deadline=None, database=None,
                  suppress_health_check=list(HealthCheck))
        @given(projects())
        def load_and_generate(p):
            _check(p, str(folder / f"p{next(seen)}"), cases)

        load_and_generate()
        for board, mine in sorted(cases.items()):
            accepted += len(mine)
            proc = cxx.compile_together(load_board(board), [f for _, f in mine], str(folder / f"gen-{board}"))
            if proc.returncode != 0:
                failing = sorted({int(m) for m in re.findall(r"/c(\d+)/", proc.stderr)}) or [0]
                pytest.fail(f"accepted, generated, did not compile for {board}:\n{proc.stderr[-3000:]}\n"
                            f"{_describe(mine[failing[0]][0])}")
        shutil.rmtree(folder, ignore_errors=True)
    assert accepted >= CASES // 3  # enough accepted to mean something
