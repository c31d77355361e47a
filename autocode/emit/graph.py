"""`fsw graph`: a state machine as a Graphviz DOT or a Mermaid
`stateDiagram-v2` picture. One node per state, a start arrow into the
initial state, one edge per transition (`-> State` in `.entry` or `.step`,
however deeply nested), labelled with the conditions that lead to it."""

from __future__ import annotations

import os
from dataclasses import dataclass

from .. import model as M
from .. import unparse


@dataclass(frozen=True)
class Arrow:
    """One `-> State` of a machine (a transition, drawn as an arrow) and the
    path of conditions to it."""
    index: int  # position in transitions(m): states in order, entry before step
    source: int  # state index
    target: int  # state index
    block: str  # "entry" or "step"
    path: tuple[tuple[M.Expr, bool], ...]  # (condition, must be true) outermost first
    goto: M.Goto


def transitions(m: M.Machine) -> list[Arrow]:
    """Every transition of the machine, in file order per state, `.entry`
    before `.step` (`.exit` cannot transition)."""
    out: list[Arrow] = []

    def walk(stmts, st: M.State, block: str, path: tuple) -> None:
        for s in stmts:
            if isinstance(s, M.Goto):
                out.append(Arrow(len(out), st.index, s.state, block, path, s))
            elif isinstance(s, M.If):
                walk(s.then, st, block, path + ((s.cond, True),))
                walk(s.orelse, st, block, path + ((s.cond, False),))

    for st in m.states:
        walk(st.entry, st, "entry", ())
        walk(st.step, st, "step", ())
    return out


def guard_expr(t: Arrow) -> M.Expr | None:
    """The conjunction of the conditions along the path (an `else` branch
    contributes `not (cond)`), or None for an unconditional transition."""
    out = None
    for cond, want in t.path:
        if want:
            term = cond
        elif isinstance(cond, M.Not):
            term = cond.operand  # `else` of `if not x`: x, not `not not x`
        else:
            term = M.Not(cond, cond.line, cond.col)
        out = term if out is None else M.Logic("and", out, term, cond.line, cond.col)
    return out


def guard_text(t: Arrow, m: M.Machine) -> str:
    """`counter > 1000 and T > 4000`; empty for an unconditional transition."""
    g = guard_expr(t)
    return "" if g is None else unparse.model_expr(g, m)


def label(t: Arrow, m: M.Machine) -> str:
    """The edge label: the guard, prefixed `entry: ` for a transition of the
    `.entry` block (it can fire only on the first step in the state)."""
    g = guard_text(t, m)
    if t.block == "entry":
        return f"entry: {g}" if g else "entry"
    return g


def describe(t: Arrow, m: M.Machine) -> str:
    """`A -> B when guard` (with the label's `entry: ` prefix), or
    `A -> B (unconditional)`: for comments in generated scripts."""
    text = label(t, m)
    src, dst = m.states[t.source].name, m.states[t.target].name
    return f"{src} -> {dst} when {text}" if text else f"{src} -> {dst} (unconditional)"


def _source_name(m: M.Machine) -> str:
    """The machine's file name, for a one-line comment."""
    name = os.path.basename(m.path.replace("\\", "/"))
    return "".join(c if c.isprintable() else "?" for c in name)


# ---- Graphviz DOT ------------------------------------------------------------------

def dot_string(text: str) -> str:
    """A DOT double-quoted string. Inside one, `\\` starts an escape (`\\n`,
    `\\l`, `\\N`, ...) and `"` ends it, so both are escaped; a newline becomes
    `\\n`. `<`, `>`, `{`, `}` and `|` are literal in a quoted (non-HTML,
    non-record) label and need nothing."""
    text = text.replace("\\", "\\\\").replace('"', '\\"')
    text = text.replace("\r\n", "\n").replace("\r", "\n").replace("\n", "\\n")
    return f'"{text}"'


# A node id that no state can have: state names are identifiers.
_START = '"(start)"'


def to_dot(m: M.Machine) -> str:
    lines = [
        f"// state machine {_source_name(m)}: `fsw graph` output for Graphviz (dot -Tsvg)",
        f"digraph {dot_string(m.name)} {{",
        "    node [shape=box, style=rounded];",
        f'    {_START} [shape=point, label=""];',
    ]
    for st in m.states:
        lines.append(f"    {dot_string(st.name)};")
    lines.append(f"    {_START} -> {dot_string(m.states[0].name)};")
    for t in transitions(m):
        edge = f"    {dot_string(m.states[t.source].name)} -> {dot_string(m.states[t.target].name)}"
        text = label(t, m)
        lines.append(f"{edge} [label={dot_string(text)}];" if text else f"{edge};")
    lines.append("}")
    return "\n".join(lines) + "\n"


# ---- Mermaid -------------------------------------------------------------------------

# Characters with a meaning in a Mermaid transition label (`A --> B : label`):
# the label is lexed as `:[^:\n;]+`, so a second `:` or a `;` cuts it; `#`
# starts an entity code; `<`, `>`, `"` and `&` are HTML once rendered. Each
# is written as an entity code (`#lt;`, `#58;`), which Mermaid decodes after
# parsing.
_MERMAID_ESCAPE = {":": "#58;", ";": "#59;", "#": "#35;",
                   "<": "#lt;", ">": "#gt;", '"': "#quot;", "&": "#amp;"}


def mermaid_text(text: str) -> str:
    text = text.replace("\r\n", " ").replace("\r", " ").replace("\n", " ")
    return "".join(_MERMAID_ESCAPE.get(c, c) for c in text)


def to_mermaid(m: M.Machine) -> str:
    """States get the ids `s1`, `s2`, ... (their state IDs, the value of `S`)
    and their names as descriptions, so no state name can collide with a
    Mermaid keyword (`state`, `note`, `end`, ...)."""
    lines = [
        "stateDiagram-v2",
        f"    %% state machine {mermaid_text(_source_name(m))}: `fsw graph --format mermaid` output",
    ]
    for st in m.states:
        lines.append(f'    state "{mermaid_text(st.name)}" as s{st.id}')
    lines.append(f"    [*] --> s{m.states[0].id}")
    for t in transitions(m):
        edge = f"    s{m.states[t.source].id} --> s{m.states[t.target].id}"
        text = label(t, m)
        lines.append(f"{edge} : {mermaid_text(text)}" if text else edge)
    return "\n".join(lines) + "\n"
