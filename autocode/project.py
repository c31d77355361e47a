"""Finding and loading a project's configs: the machine and state vector
beside a state script, the state vector beside a machine."""

from __future__ import annotations

import os

from . import model as M
from .check import check_literals, check_sm, check_ss, check_ss_alone, check_sv, machine_exprs, script_exprs
from .collect import fewer_collections
from .diagnostics import SM, SS, Diagnostics, Source, decode, read_input, read_source
from .parser import parse_sm, parse_ss, parse_sv


def find_beside(path: str, ext: str) -> str | None:
    """The `ext` file that belongs with `path`: same stem; else the one whose
    stem is the longest prefix of this stem (`tank_770.ss` → `tank.sm`);
    else the only one in the folder; for a state vector, else the one the
    folder's only application config names (a machine to upload beside its
    project, docs/reload.md)."""
    folder = os.path.dirname(path)
    stem = os.path.splitext(os.path.basename(path))[0]
    try:
        listing = sorted(os.listdir(folder or "."))
    except OSError:
        return None
    names = [n for n in listing if n.endswith(ext)]
    stems = [n[: -len(ext)] for n in names]
    if stem in stems:
        return os.path.join(folder, stem + ext)
    prefixes = [s for s in stems if stem.startswith(s) and stem[len(s)] in "_-."]
    if prefixes:
        return os.path.join(folder, max(prefixes, key=len) + ext)
    if len(names) == 1:
        return os.path.join(folder, names[0])
    apps = [n for n in listing if n.endswith(".app")]
    if ext == ".sv" and not names and len(apps) == 1:
        return _app_state_vector(os.path.join(folder, apps[0]))
    return None


def _app_state_vector(app: str) -> str | None:
    """The `state_vector` an application config's [configs] names (the
    config read only that far: its own errors are `fsw check`'s of it)."""
    from .appsyntax import parse_app
    from .diagnostics import APP

    src = read_source(app, Diagnostics(), APP)
    if src is None:
        return None
    rows = [c for c in parse_app(src, Diagnostics()).configs if c.kind.text == "state_vector" and c.file is not None]
    return rows[0].path if len(rows) == 1 else None


@fewer_collections()
def load_sv(path: str, diags: Diagnostics) -> M.StateVector | None:
    from .diagnostics import SV

    src = read_source(path, diags, SV)
    if src is None:
        return None
    return check_sv(parse_sv(src, diags), src, diags)


@fewer_collections()
def load_machine(sm_path: str, diags: Diagnostics, sv_path: str | None = None,
                 warnings: bool = False) -> M.Machine | None:
    """The checked machine, or None with every error in `diags`."""
    src = read_source(sm_path, diags, SM)
    if src is None:
        return None
    if sv_path is None:
        sv_path = find_beside(sm_path, ".sv")
        if sv_path is None:
            diags.error(src, SM, 1, 1, f"no state vector config (.sv) found beside {sm_path}: "
                                       "name one with --sv")
            # Its own errors still count (spec §8): checked against a state
            # vector that has every element it lists, as it lists it.
            mine = Diagnostics()
            f = parse_sm(src, mine)
            check_sm(f, src, M.StateVector(sm_path, False, (), (), 0, frozenset(d.name for d in f.elements)), mine)
            diags.extend(mine)
            return None
    # Counted apart: errors already in `diags` (another file's, or this
    # state vector's reported before) must not decide, and neither may
    # this one's be missed because `diags` had seen them.
    mine = Diagnostics()
    m = None
    sv = load_sv(sv_path, mine)
    f = parse_sm(src, mine)
    if sv is not None:
        m = check_sm(f, src, sv, mine, warnings=warnings and not mine.errors)
    diags.extend(mine)
    return m if not mine.errors else None


@fewer_collections()
def load_script(ss_path: str, diags: Diagnostics, sm_path: str | None = None,
                sv_path: str | None = None, real=None) -> M.Script | None:
    """The checked script, or None with every error in `diags`. `real`: the
    evaluation type the script will run in; its literals and its machine's
    must be finite there too."""
    src = read_source(ss_path, diags, SS)
    if src is None:
        return None
    if sm_path is None:
        sm_path = find_beside(ss_path, ".sm")
        if sm_path is None:
            diags.error(src, SS, 1, 1, f"no state machine config (.sm) found beside {ss_path}: "
                                       "name one with --sm")
            mine = Diagnostics()
            check_ss_alone(parse_ss(src, mine), src, mine)  # its own errors still count
            diags.extend(mine)
            return None
    m = load_machine(sm_path, diags, sv_path)
    mine = Diagnostics()
    f = parse_ss(src, mine)
    if m is None:  # what can be said without the machine is said now (spec §8)
        check_ss_alone(f, src, mine)
        script = None
    else:
        script = check_ss(f, src, m, mine)
    if script is not None and real is not None:
        check_literals(machine_exprs(m), real, source_of(m.path), mine, SM)
        check_literals(script_exprs(script), real, src, mine, SS)
    diags.extend(mine)
    return script if not mine.errors else None


def source_of(path: str) -> Source:
    """A file's text for rendering a diagnostic after the fact."""
    return Source.from_text(path, decode(read_input(path)))
