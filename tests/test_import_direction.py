"""The direction of the imports: `autocode/` (fswkit.autocode, the ground
floor) imports nothing of the host tools above it, and no module of the kit
imports, through any chain, a module that imports it back. Read from the
source with `ast`, function-level imports included (an import inside a
function is a dependency all the same, only a later one)."""

from __future__ import annotations

import ast
import functools
from pathlib import Path

from conftest import ROOT

AUTOCODE = ROOT / "autocode"
HOST = ROOT / "host-tools" / "fswkit"


def modules() -> dict[str, Path]:
    """{dotted module name: file} of the kit: host-tools/fswkit is package
    fswkit, autocode/ is fswkit.autocode (pyproject.toml's package-dir)."""
    out: dict[str, Path] = {}
    for base, package in ((HOST, "fswkit"), (AUTOCODE, "fswkit.autocode")):
        for path in sorted(base.rglob("*.py")):
            if "__pycache__" in path.parts:
                continue
            parts = list(path.relative_to(base).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            out[".".join([package, *parts])] = path
    return out


@functools.cache
def _import_nodes(path: Path) -> tuple:
    """The file's import statements, function-level ones included, read
    once for all the tests (the modules do not change during a run)."""
    tree = ast.parse(path.read_text(), str(path))
    return tuple(n for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom)))


def imports(name: str, path: Path, known: set[str]) -> list[tuple[int, str]]:
    """(line, module) of every import of a module of the kit in the file,
    relative ones resolved; `from P import x` names P.x when that is a
    module, else P. An import that resolves outside the kit's package is
    kept as its dotted name (`fswkit` alone, `fswkit.nothing`)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = []
    for node in _import_nodes(path):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names if a.name.split(".")[0] == "fswkit"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".")
                up = node.level - 1
                base = ".".join(parts[:len(parts) - up]) if up < len(parts) else ""
                target = ".".join(p for p in (base, node.module) if p) if base else "<outside the package>"
            else:
                target = node.module or ""
            if target.split(".")[0] not in ("fswkit", "<outside the package>"):
                continue
            for a in node.names:
                sub = f"{target}.{a.name}"
                out.append((node.lineno, sub if sub in known else target))
    return out


def graph() -> dict[str, set[str]]:
    """{module: modules of the kit it imports}."""
    mods = modules()
    known = set(mods)
    out: dict[str, set[str]] = {}
    for name, path in mods.items():
        deps = set()
        for _, target in imports(name, path, known):
            while target and target not in known:  # `import fswkit.a.b` of a name inside a module
                target = target.rpartition(".")[0]
            if target and target != name:
                deps.add(target)
        out[name] = deps
    return out


def cycles(g: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module
    (networkx's, as the code generator's window analysis uses): each is a
    set of modules that import each other, through some chain. Sorted,
    each sorted."""
    import networkx as nx

    dg = nx.DiGraph()
    dg.add_nodes_from(g)
    dg.add_edges_from((a, b) for a, bs in g.items() for b in bs)
    return sorted(sorted(c) for c in nx.strongly_connected_components(dg) if len(c) > 1)


def describe(component: list[str], g: dict[str, set[str]]) -> str:
    """A cycle as `a -> b -> ... -> a` through the component's imports."""
    members = set(component)
    start = component[0]
    path, seen = [start], {start}
    node = start
    while True:
        nxt = sorted(d for d in g[node] if d in members)
        back = [d for d in nxt if d == start]
        if back and len(path) > 1:
            return " -> ".join(path + [start])
        fresh = [d for d in nxt if d not in seen]
        if not fresh:
            return " -> ".join(path + [nxt[0]]) + f" (the modules {', '.join(component)} import each other)"
        node = fresh[0]
        path.append(node)
        seen.add(node)


def test_the_cycle_finder_finds_a_cycle_and_only_cycles():
    g = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": {"e"}, "e": set(), "f": {"f", "e"}, "g": {"h"}, "h": {"g"}}
    assert cycles(g) == [["a", "b", "c"], ["g", "h"]]
    assert describe(["a", "b", "c"], g) == "a -> b -> c -> a"
    assert cycles({"a": {"b"}, "b": {"c"}, "c": set()}) == []
    # a long chain does not exhaust the recursion: the finder is iterative
    chain = {f"m{i}": {f"m{i + 1}"} for i in range(5000)}
    chain["m5000"] = {"m0"}
    assert len(cycles(chain)[0]) == 5001


def test_imports_are_resolved_relative_and_from_import_alike(tmp_path):
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    f = pkg / "mod.py"
    f.write_text("import fswkit.a.b as x\nfrom . import sib\nfrom .. import up\nfrom fswkit.c import d, e\n"
                 "def f():\n    from ...x import y\n")
    found = imports("fswkit.pkg.mod", f, {"fswkit.a.b", "fswkit.pkg.sib", "fswkit.c.d"})
    assert found == [(1, "fswkit.a.b"), (2, "fswkit.pkg.sib"), (3, "fswkit"), (4, "fswkit.c.d"), (4, "fswkit.c"),
                     (6, "<outside the package>")]


def test_autocode_imports_nothing_outside_itself():
    mods = modules()
    known = set(mods)
    bad = []
    for name, path in mods.items():
        if not name.startswith("fswkit.autocode"):
            continue
        for line, target in imports(name, path, known):
            if target != "fswkit.autocode" and not target.startswith("fswkit.autocode."):
                bad.append(f"{path.relative_to(ROOT)}:{line}: imports {target}")
    assert not bad, "autocode/ is the ground floor and imports nothing of the host tools:\n" + "\n".join(bad)


def test_no_import_cycles_among_the_kits_modules():
    g = graph()
    assert "fswkit.cli.main" in g and "fswkit.target.build" in g and "fswkit.autocode.app" in g
    found = cycles(g)
    assert not found, "modules that import each other (a cycle):\n" + "\n".join(describe(c, g) for c in found)


def test_the_rooms_never_import_the_command_line():
    """The command line sits on top: its commands call into the rooms, and no
    room calls a command (`fsw flash` once built through `fsw build`'s
    command, with a hand-made argparse.Namespace). fswkit.testing sits above
    it: its runner and fuzzer run `fsw` commands as a user does."""
    g = graph()
    bad = [f"{m} imports {d}" for m in sorted(g) if not m.startswith(("fswkit.cli", "fswkit.testing"))
           for d in sorted(g[m]) if d == "fswkit.cli" or d.startswith("fswkit.cli.")]
    assert not bad, "\n".join(bad)
