"""Names the languages accept could break the generated C++: a machine file
named after a C++ keyword (`int.sm`), after something the generated code or
the runtime defines (`sv`, `app`, `fsw`, `begin`, `poll`, `link`, `ex`),
after a platform macro (`PORTB`, `F_CPU`, `stdin`) or spelling one behind
a prefix (a local `tmpnam` became `L_tmpnam`, a macro of stdio.h); `fsw new
int` made a project that did not build; `"` or a line break in a file name
reached comments and string literals raw; a script with no `@assert` made
`kAssertText[] = {, 0}`. Every name that reaches C++ is mangled by one
scheme (autocode/cnames.py, docs/codegen.md) and compiles for a board and
natively; two machines whose C++ names would be one (or one but for case)
are refused where the second is listed."""

from __future__ import annotations

import os

import pytest

from support import cxx
from conftest import run_fsw
from fswkit.autocode.app import load_app
from fswkit.autocode.board import load_board
from fswkit.autocode.cnames import machine_ident
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.app import emit_app
from fswkit.autocode.numeric import REALS
from fswkit.autocode.project import load_script
from fswkit.autocode.emit.script import script_files

# Machine file stems: keywords, the generated code's and the runtime's own
# names, C library names, platform macros, mixed case, the mangled form of
# another name's neighbour.
STEMS = ["int", "class", "and_eq", "typeof", "sv", "app", "fsw", "fsw_gen", "std", "begin", "poll", "link", "ex",
         "stats", "main", "setup", "loop", "run_cycle", "memcpy", "uint8_t", "time", "stdin", "sinf", "linux",
         "PORTB", "F_CPU", "HIGH", "PRIu8", "Tank", "tank", "task_x", "w0", "s1_step", "con", "_x", "a__b"]
# Locals and states whose prefixed C++ names are macros of system headers.
LOCALS = ["tmpnam", "ctermid", "cuserid", "SET", "XTND", "INCR"]


def _project(folder, stems: list[str], app_name: str = "rig.app") -> str:
    os.makedirs(folder, exist_ok=True)
    sv = ["[Main]", "U64 time", "F32 x"] + [f"U32 st{k}" for k in range(len(stems))] + ["[Status]", "U8 mode0"]
    with open(os.path.join(folder, "rig.sv"), "w") as f:
        f.write("\n".join(sv) + "\n")
    for k, stem in enumerate(stems):
        locs = "\n".join(f"F32 {n} = {i}" for i, n in enumerate(LOCALS))
        bump = "\n".join(f"    {n} = {n} + x" for n in LOCALS)
        with open(os.path.join(folder, stem + ".sm"), "w") as f:
            f.write(f"[state_vector]\nU64 time @alias G\nU32 st{k} @alias S\nF32 x\n\n[local]\n{locs}\n\n"
                    f"[OK]\n.step\n{bump}\n    x > tmpnam: -> ERROR\n\n[ERROR]\n.step\n    x < SET: -> OK\n")
    tasks = "\n".join(f"t{k} machine {stem} rate=10" + (" mode=mode0" if k == 0 else "")
                      for k, stem in enumerate(stems))
    configs = "\n".join(f"machine {stem}.sm" for stem in stems)
    app = (f"[application]\nboard uno\nrate 100\n[configs]\nstate_vector rig.sv\n{configs}\n"
           f"[tasks]\n{tasks}\ndown telemetry rate=10\nup uplink rate=10\n[telemetry]\nMain rate=1\nStatus rate=1\n"
           f"[uplink]\nx\n")
    path = os.path.join(folder, app_name)
    with open(path, "w") as f:
        f.write(app)
    return path


def _load(path: str, board: str):
    diags = Diagnostics()
    app = load_app(path, diags, board_override=board)
    return app, "\n".join(d.render() for d in diags.errors)


@pytest.fixture(scope="module")
def projects(tmp_path_factory):
    """The applications under test, each generated for the Uno, the Mega
    and natively: {board: [files, ...]}."""
    root = tmp_path_factory.mktemp("names")
    paths = [_project(root / "many", STEMS),
             _project(root / "quote", ["rig"], 'q"uote ??= ??( \t.app'),
             _project(root / "newline", ["rig"], "new\nline\\.app"),
             _project(root / "bytes", ["rig"], os.fsdecode(b"caf\xe9 \xff.app"))]
    for name in ("int", "sv", "ex", "fsw", "link", "PORTB"):
        r = run_fsw("new", str(root / name), "--board", "uno")
        assert r.code == 0, r.err
        paths.append(str(root / name / f"{name}.app"))
    out = {}
    for board in ("uno", "mega2560", "native"):
        out[board] = []
        for p in paths:
            app, errors = _load(p, board)
            assert app is not None, errors
            out[board].append(emit_app(app))
    return root, out


@pytest.mark.parametrize("board", ["uno", "mega2560", "native"])
def test_every_name_compiles(projects, board):
    root, generated = projects
    cpp = []
    for k, files in enumerate(generated[board]):
        assert all(t.isascii() for t in files.values())
        cpp += cxx.write(files, str(root / "gen" / board / f"c{k}"))
    proc = cxx.compile_each(load_board(board), cpp)
    assert proc.returncode == 0, proc.stderr[-4000:]


def test_machine_names_are_mangled_by_the_documented_scheme():
    assert machine_ident("tank") == "tank"
    for stem in ("int", "sv", "app", "fsw", "begin", "poll", "link", "PORTB", "Tank", "we\"ird", "task_x"):
        assert machine_ident(stem) == "sm_" + "".join(c if c.isalnum() or c == "_" else "_" for c in stem)


@pytest.mark.parametrize("first, second", [("Tank", "TANK"), ("sm_int", "int")])
def test_machines_with_one_cpp_name_are_refused(tmp_path, first, second):
    path = _project(tmp_path, [first, second])
    app, errors = _load(path, "uno")
    assert app is None
    assert "rig.app:7:9:" in errors, errors
    assert f"machines `{first}` and `{second}` would generate the same C++ files" in errors


@pytest.mark.parametrize("stem", ["a-b", "a.b", "a+b", "t ank"])
def test_a_machine_file_whose_name_tasks_cannot_name_is_refused_where_it_is_listed(tmp_path, stem):
    # A machine is named after its file, and [tasks] names it: a stem that
    # is not a name was refused only later, at the task, as an unknown
    # machine `a` (from `a-b`), or reached the generator when no task named it.
    path = _project(tmp_path, [stem])
    app, errors = _load(path, "uno")
    assert app is None
    assert "rig.app:6:9:" in errors, errors
    assert (f"the machine in `{stem}.sm` is named `{stem}` after its file, and [tasks] can only name a machine "
            "whose name is letters, digits and `_`") in errors, errors


def test_tank_beside_Tank_builds(tmp_path):
    app, errors = _load(_project(tmp_path, ["tank", "Tank"]), "uno")
    assert app is not None, errors
    assert {"tank.gen.h", "sm_Tank.gen.h"} <= set(emit_app(app))


def test_odd_script_and_machine_names_run_natively(tmp_path):
    """`fsw test --native` on a machine and script whose file names hold a
    quote, a trigraph, a tab and a byte that is not UTF-8; the script has no
    `@assert` at all."""
    stem = os.fsdecode(b'we"ird ??= \t\xff')
    folder = tmp_path
    (folder / "rig.sv").write_text("[Main]\nU64 time\nU32 st\nF32 x\n")
    (folder / f"{stem}.sm").write_bytes("[state_vector]\nU64 time @alias G\nU32 st @alias S\nF32 x\n\n"
                                       "[local]\nF32 tmpnam = 2\n\n[A]\n.step\n    tmpnam = tmpnam + 1\n".encode())
    ss = folder / f"{stem}.ss"
    ss.write_bytes(b"[options]\ndelta_t 10\n\n[all_states]\nG == 30: @stop\n")
    r = run_fsw("test", "--native", str(ss))
    assert r.code == 0, r.out + r.err
    assert "0 asserts passed" in r.out
    diags = Diagnostics()
    script = load_script(str(ss), diags)
    files = script_files(script, REALS["f64"], lambda path, line: "")
    assert "kAssertText[] = {0};" in files["script_main.cpp"]


def test_sketch_of_an_application_with_odd_names_compiles(tmp_path):
    """The sketch's .ino names the application's file in a comment and
    includes every machine's header after Arduino.h (as the Arduino
    builder compiles it)."""
    from fswkit.new.sketch import sketch_files

    app, errors = _load(_project(tmp_path / "p", ["int", "PORTB", "HIGH", "tank"], "new\nline.app"), "uno")
    assert app is not None, errors
    files = sketch_files(app, emit_app(app), "rig")
    ino = files.pop("rig.ino")
    assert all(line.startswith(("//", "#include")) for line in ino.splitlines()), ino
    files["rig_ino.cpp"] = "#include <Arduino.h>\n" + ino
    del files["sketch.yaml"]
    proc = cxx.compile_each(load_board("uno"), cxx.write(files, str(tmp_path / "sketch")))
    assert proc.returncode == 0, proc.stderr[-3000:]
