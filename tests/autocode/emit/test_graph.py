"""`fsw graph`: a machine as Graphviz DOT and as Mermaid stateDiagram-v2."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from conftest import EXAMPLES
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.project import load_machine
from fswkit.autocode.emit.graph import dot_string, mermaid_text, to_dot, to_mermaid, transitions

TANK = EXAMPLES / "tank"
MACHINES = Path(__file__).resolve().parent / "machines"
DOT = shutil.which("dot")

TANK_DOT = r'''// state machine tank.sm: `fsw graph` output for Graphviz (dot -Tsvg) (digest 7d3f510e7cc8)
digraph "tank" {
    node [shape=box, style=rounded];
    "(start)" [shape=point, label=""];
    "TankVentControl";
    "Abort";
    "Idle";
    "(start)" -> "TankVentControl";
    "TankVentControl" -> "Abort" [label="not (500 < tankPressure < P_AbortThreshold)"];
    "TankVentControl" -> "Idle" [label="counter > 1000 and T > 4000"];
}
'''

TANK_MERMAID = '''stateDiagram-v2
    %% state machine tank.sm: `fsw graph --format mermaid` output (digest c8d058477da6)
    state "TankVentControl" as s1
    state "Abort" as s2
    state "Idle" as s3
    [*] --> s1
    s1 --> s2 : not (500 #lt; tankPressure #lt; P_AbortThreshold)
    s1 --> s3 : counter #gt; 1000 and T #gt; 4000
'''


def machine(path):
    diags = Diagnostics()
    m = load_machine(str(path), diags)
    assert m is not None, diags.render()
    return m


def write_machine(tmp_path: Path, body: str) -> Path:
    (tmp_path / "m.sv").write_text("[R]\nU64 time\nU32 state\nF64 a\nF64 b\nbool c\n")
    path = tmp_path / "m.sm"
    path.write_text("[state_vector]\nU64 time @alias G\nU32 state @alias S\n"
                    "F64 a\nF64 b\nbool c\n" + body)
    return path


def dot_edges(text: str) -> list[tuple[str, str, str | None]]:
    out = []
    for line in text.splitlines():
        mt = re.fullmatch(r'    "([^"]+)" -> "([^"]+)"(?: \[label="((?:[^"\\]|\\.)*)"\])?;', line)
        if mt:
            out.append(mt.groups())
    return out


# ---- golden output --------------------------------------------------------------

def test_tank_dot_golden(fsw):
    r = fsw("graph", str(TANK / "tank.sm"))
    assert r.code == 0 and r.err == ""
    assert r.out == TANK_DOT


def test_tank_mermaid_golden(fsw):
    r = fsw("graph", str(TANK / "tank.sm"), "--format", "mermaid")
    assert r.code == 0 and r.err == ""
    assert r.out == TANK_MERMAID


def test_output_is_byte_reproducible(fsw, tmp_path):
    for fmt in ("dot", "mermaid"):
        a = fsw("graph", str(MACHINES / "gates.sm"), "--format", fmt)
        b = fsw("graph", str(MACHINES / "gates.sm"), "--format", fmt)
        assert a.code == b.code == 0
        assert a.out == b.out
        out = tmp_path / f"g.{fmt}"
        assert fsw("graph", str(MACHINES / "gates.sm"), "--format", fmt, "-o", str(out)).code == 0
        assert out.read_text() == a.out


# ---- edges and their guards ----------------------------------------------------------

def test_guards_nest_and_else_negates(fsw):
    r = fsw("graph", str(MACHINES / "rocket.sm"))
    assert r.code == 0
    assert dot_edges(r.out) == [
        ("(start)", "Idle", None),
        ("Idle", "Ready", "armed and T >= 200"),
        ("Ready", "Idle", "not armed"),
        # else of `if not armed`: `armed`, not `not not armed`
        ("Ready", "Ascent", "armed and 100 < altitude <= 3000"),
        ("Ready", "Ready", "T > 500"),  # a self-transition is an edge too
        ("Ascent", "Apogee", "altitude > 3000"),
        ("Ascent", "Ready", "not (altitude > 3000) and altitude < floor"),
        ("Apogee", "Landed", "roll_avg(altitude, 4) < 1000"),
    ]


def test_entry_transitions_say_so_and_unconditional_ones_have_no_label(fsw):
    r = fsw("graph", str(MACHINES / "gates.sm"))
    assert r.code == 0
    edges = dot_edges(r.out)
    assert ("Start", "Early", "entry: door") in edges
    assert ("Start", "Open", "door") in edges
    assert ("Early", "Start", None) in edges
    assert ("Open", "Full", "not (b >= 300) and level == 255") in edges
    # every transition the checker sees, dead ones included
    assert edges.count(("Full", "Start", None)) == 1
    assert ("Full", "Start", "false") in edges  # `if false`
    assert len(edges) == 1 + len(transitions(machine(MACHINES / "gates.sm")))
    # the state no transition reaches is still a node
    assert '    "Orphan";\n' in r.out
    m = fsw("graph", str(MACHINES / "gates.sm"), "--format", "mermaid").out
    assert "    s1 --> s2 : entry#58; door\n" in m
    assert "    s2 --> s1\n" in m


def test_conjunction_keeps_or_together(fsw, tmp_path):
    sm = write_machine(tmp_path, (
        "[A]\n.entry\n    if a > 1 or c {\n        b < 2: -> B\n    }\n"
        ".step\n    if a > 1 and c: -> A\n    else if not (b == 3): -> B\n    else: -> A\n"
        "[B]\n"))
    r = fsw("graph", str(sm))
    assert r.code == 0, r.err
    assert dot_edges(r.out)[1:] == [
        ("A", "B", "entry: (a > 1 or c) and b < 2"),
        ("A", "A", "a > 1 and c"),
        ("A", "B", "not (a > 1 and c) and not (b == 3)"),
        ("A", "A", "not (a > 1 and c) and b == 3"),
    ]


def test_initial_state_has_the_start_arrow(fsw, tmp_path):
    sm = write_machine(tmp_path, "[Second]\n[First]\n.step\n    -> Second\n")
    dot = fsw("graph", str(sm)).out
    assert '    "(start)" -> "Second";\n' in dot
    mer = fsw("graph", str(sm), "--format", "mermaid").out
    assert "    [*] --> s1\n" in mer and 'state "Second" as s1' in mer


# ---- escaping ------------------------------------------------------------------------------

def test_dot_string_escapes():
    assert dot_string('a "b" \\ c') == r'"a \"b\" \\ c"'
    assert dot_string("x\ny") == r'"x\ny"'
    assert dot_string("a < b > c { | }") == '"a < b > c { | }"'  # literal in a quoted label


def test_mermaid_text_escapes():
    assert mermaid_text('a:b;c#d"e&f<g>h') == "a#58;b#59;c#35;d#quot;e#amp;f#lt;g#gt;h"
    assert "\n" not in mermaid_text("a\nb")


# What Mermaid's stateDiagram lexer accepts after `:` in a transition:
# `[^:\n;]+`, with `#...;` entity codes replaced before lexing.
MERMAID_EDGE = re.compile(r"    s\d+ --> s\d+(?: : ([^:\n;]+))?")
MERMAID_STATE = re.compile(r'    state "([^"\n]*)" as s\d+')


def mermaid_lines_ok(text: str) -> None:
    lines = text.splitlines()
    assert lines[0] == "stateDiagram-v2"
    for line in lines[1:]:
        if line.startswith("    %%"):
            assert not line.startswith("    %%{")  # not a directive
            continue
        if line.startswith("    [*] --> "):
            continue
        plain = re.sub(r"#\w+;", "E", line)
        assert MERMAID_STATE.fullmatch(plain) or MERMAID_EDGE.fullmatch(plain), line
        assert not re.search(r'[<>"&]', plain.split(" : ", 1)[1] if " : " in plain else ""), line


@pytest.mark.parametrize("path", [TANK / "tank.sm", MACHINES / "rocket.sm", MACHINES / "gates.sm"])
def test_mermaid_lines_follow_the_grammar(path):
    mermaid_lines_ok(to_mermaid(machine(path)))


def test_state_names_that_are_mermaid_or_dot_keywords(fsw, tmp_path):
    sm = write_machine(tmp_path, (
        "[note]\n.step\n    c: -> state\n[state]\n.step\n    -> end\n[end]\n.step\n    -> node\n"
        "[node]\n.step\n    -> digraph\n[digraph]\n"))
    mer = fsw("graph", str(sm), "--format", "mermaid").out
    mermaid_lines_ok(mer)
    assert 'state "note" as s1' in mer and "    s1 --> s2 : c\n" in mer
    dot = fsw("graph", str(sm)).out
    assert '    "end" -> "node";\n' in dot
    if DOT:
        subprocess.run([DOT, "-Tsvg"], input=dot, text=True, check=True, capture_output=True)


# ---- the DOT is valid: Graphviz renders it ----------------------------------------------------

@pytest.mark.skipif(DOT is None, reason="graphviz `dot` not installed")
@pytest.mark.parametrize("path", [TANK / "tank.sm", MACHINES / "rocket.sm", MACHINES / "gates.sm"])
def test_dot_renders(path):
    r = subprocess.run([DOT, "-Tsvg"], input=to_dot(machine(path)), text=True,
                       capture_output=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""
    assert "<svg" in r.stdout


@pytest.mark.skipif(DOT is None, reason="graphviz `dot` not installed")
def test_dot_labels_render_literally():
    """`<` stays a character (not an HTML label); quotes and backslashes
    survive the escaping."""
    svg = subprocess.run([DOT, "-Tsvg"], input=to_dot(machine(TANK / "tank.sm")), text=True,
                         capture_output=True, check=True).stdout
    assert ">not (500 &lt; tankPressure &lt; P_AbortThreshold)</text>" in svg
    assert ">counter &gt; 1000 and T &gt; 4000</text>" in svg
    odd = 'say "hi" \\ <b>'
    src = f"digraph x {{ a -> b [label={dot_string(odd)}]; }}\n"
    svg = subprocess.run([DOT, "-Tsvg"], input=src, text=True, capture_output=True, check=True).stdout
    assert ">say &quot;hi&quot; \\ &lt;b&gt;</text>" in svg


# ---- the command line ------------------------------------------------------------------------

@pytest.mark.parametrize("fmt", ["dot", "mermaid"])
def test_broken_machine_gives_located_error_and_exit_2(fsw, fmt):
    r = fsw("graph", "tank_typo.sm", "--format", fmt, cwd=TANK)
    assert r.code == 2
    assert r.out == ""
    assert r.err.startswith("state machine config error @ tank_typo.sm:18:9:\n"
                            "  |         valve0pe = true\n"
                            "  |         ^ unknown element `valve0pe`\n")


def test_machine_without_state_vector(fsw, tmp_path):
    (tmp_path / "lonely.sm").write_text("[A]\n")
    r = fsw("graph", str(tmp_path / "lonely.sm"))
    assert r.code == 2
    assert "no state vector config (.sv) found" in r.err
    assert "Traceback" not in r.err


def test_unwritable_output(fsw, tmp_path):
    target = tmp_path / "missing" / "tank.dot"
    r = fsw("graph", str(TANK / "tank.sm"), "-o", str(target))
    assert r.code == 1
    assert r.out == ""
    assert r.err.startswith(f"fsw graph: cannot write {target}: ")
    assert "Traceback" not in r.err


def test_output_dash_is_stdout(fsw):
    r = fsw("graph", str(TANK / "tank.sm"), "-o", "-")
    assert r.code == 0 and r.out == TANK_DOT


def test_unknown_format_is_a_usage_error(fsw):
    r = fsw("graph", str(TANK / "tank.sm"), "--format", "png")
    assert r.code == 2
    assert "invalid choice" in r.err
