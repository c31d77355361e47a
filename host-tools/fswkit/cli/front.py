"""The front end's commands: `fsw check`, `fsw test`, `fsw graph`,
`fsw skeleton`, `fsw gen` (configs in; diagnostics, script runs, graphs,
generated C++ out)."""

from __future__ import annotations

import os
import sys

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.cli.common import (EXIT_CONFIG, EXIT_FAIL, EXIT_INTERNAL, EXIT_OK, load_app, plural, print_diags,
                               real_of, write_output)

CONFIG_EXTS = (".sv", ".sm", ".ss", ".app")
TABLE_EXTS = (".aio", ".dio", ".sns")  # checked through the .app that names them (board, state vector, pins)


def collect(paths: list[str], diags: Diagnostics) -> list[str] | None:
    files: list[str] = []
    for p in paths:
        if os.path.isdir(p):
            for root, dirs, names in os.walk(p):
                dirs[:] = sorted(d for d in dirs if not d.startswith("."))
                files += [os.path.normpath(os.path.join(root, n))
                          for n in sorted(names) if n.endswith(CONFIG_EXTS)]
        elif p.endswith(CONFIG_EXTS) or not os.path.exists(p):
            files.append(p)
        elif p.endswith(TABLE_EXTS):
            sys.stderr.write(f"fsw check: {p}: an I/O table ({', '.join(TABLE_EXTS)}) is checked with the application "
                             "that lists it in [configs]: give its .app, or the project's folder\n")
            return None
        else:
            sys.stderr.write(f"fsw check: {p}: not a config file (expected {', '.join(CONFIG_EXTS)} or a folder)\n")
            return None
    return files


# ---- fsw check ----------------------------------------------------------------

def cmd_check(args) -> int:
    from fswkit.autocode.project import load_machine, load_script, load_sv

    diags = Diagnostics()
    files = collect(args.paths, diags)
    if files is None:
        return EXIT_CONFIG
    if not files:
        sys.stderr.write("fsw check: no config files found\n")
        return EXIT_FAIL
    pyro_report = getattr(args, "pyro_report", False)
    if pyro_report and not any(f.endswith(".app") for f in files):
        sys.stderr.write("fsw check: --pyro-report needs an application config (.app), or a folder holding one\n")
        return EXIT_CONFIG
    apps = []
    for f in files:
        if f.endswith(".sv"):
            load_sv(f, diags)
        elif f.endswith(".sm"):
            load_machine(f, diags, args.sv, warnings=True)
        elif f.endswith(".app"):
            from fswkit.autocode.app import load_app as load_application
            apps.append(load_application(f, diags))
        else:
            load_script(f, diags, args.sm, args.sv)
    print_diags(diags)
    errors, warnings = diags.error_count, diags.warning_count
    sys.stderr.write(f"fsw check: {plural(len(files), 'file')}, {plural(errors, 'error')}, "
                     f"{plural(warnings, 'warning')}\n")
    if pyro_report and not errors:  # a report of what was proven: none where the proof failed
        from fswkit.autocode.pyrocheck import pyro_report as report
        sys.stdout.write("\n".join(report(app) for app in apps if app is not None))
    if errors or (args.strict and warnings):
        return EXIT_FAIL
    return EXIT_OK


# ---- fsw test -------------------------------------------------------------------

def _scripts(paths: list[str]) -> list[str] | None:
    """The scripts named, a folder standing for every `.ss` in it."""
    out: list[str] = []
    for p in paths:
        if os.path.isdir(p):
            found = sorted(os.path.join(p, n) for n in os.listdir(p) if n.endswith(".ss"))
            if not found:
                sys.stderr.write(f"fsw test: {p}: no state scripts (.ss) in this folder\n")
                return None
            out += found
        else:
            out.append(p)
    return out


def cmd_test(args) -> int:
    real = real_of(args, "test")
    if real is None:
        return EXIT_CONFIG
    if args.coverage and args.native:
        sys.stderr.write("fsw test: --coverage follows the interpreter's run: leave out --native\n")
        return EXIT_CONFIG
    scripts = _scripts(args.script)
    if scripts is None:
        return EXIT_CONFIG
    if args.trace and len(scripts) > 1:
        sys.stderr.write("fsw test: --trace writes one script's run: name one script\n")
        return EXIT_CONFIG
    codes = []
    coverage: dict[str, list] = {}  # machine path -> [machine, taken, visited]
    for path in scripts:
        if len(scripts) > 1:
            sys.stdout.write(f"== {path}\n")
            sys.stdout.flush()
        code, result = _test_one(path, args, real)
        codes.append(code)
        if result is not None and args.coverage:
            m = result[0]
            entry = coverage.setdefault(os.path.abspath(m.path), [m, set(), set()])
            entry[1] |= result[1].taken
            entry[2] |= result[1].visited
    incomplete = _report_coverage(coverage) if args.coverage else False
    if len(scripts) > 1:
        passed = codes.count(EXIT_OK)
        sys.stdout.write(f"{plural(len(scripts), 'script')}: {passed} passed, {len(scripts) - passed} failed\n")
    if EXIT_CONFIG in codes:
        return EXIT_CONFIG
    if EXIT_INTERNAL in codes:
        return EXIT_INTERNAL
    return EXIT_FAIL if EXIT_FAIL in codes or incomplete else EXIT_OK


def _with_params(script, given: list[str]):
    """The script run with `--param NAME=VALUE` values (checked against the
    machine's parameters), or None after a message."""
    import dataclasses

    from fswkit.autocode.params import check_value, machine_with_values, var_param
    from fswkit.usage import unknown_name

    m = script.machine
    values = {}
    typed: dict[str, str] = {}  # each value as given
    for g in given:
        name, eq, text = g.partition("=")
        name = name.strip()
        v = m.var(name) if eq else None
        if not eq:
            sys.stderr.write(f"fsw test: --param {g}: expected NAME=VALUE\n")
            return None
        if v is None or v.param is None:
            names = [x.name for x in m.vars if x.param is not None]
            sys.stderr.write(f"fsw test: --param {g}: "
                             + unknown_name("parameter", [name], names, f"machine `{m.name}`'s") + "\n")
            return None
        value, why = check_value(var_param(m, v), text)
        if why is not None:
            sys.stderr.write(f"fsw test: --param {g}: {why}\n")
            return None
        if name in values:  # which one was meant is not ours to guess
            sys.stderr.write(f"fsw test: --param {g}: `{name}` is given twice ({typed[name]} and {text.strip()}): "
                             "give it once\n")
            return None
        values[name] = value
        typed[name] = text.strip()
    return dataclasses.replace(script, machine=machine_with_values(m, values))


def _test_one(path: str, args, real):
    """Runs one script; (exit code, (machine, result) for coverage or None)."""
    from fswkit.autocode.project import load_script, source_of
    from fswkit.run.script import run

    diags = Diagnostics()
    script = load_script(path, diags, args.sm, args.sv, real=real)
    if script is None:
        print_diags(diags)
        return EXIT_CONFIG, None
    print_diags(diags)  # warnings only
    if args.param:
        script = _with_params(script, args.param)
        if script is None:
            return EXIT_CONFIG, None
    sources: dict[str, object] = {}

    def line_of(p: str, n: int) -> str:
        if p not in sources:
            sources[p] = source_of(p)
        return sources[p].line(n)

    trace = None
    if args.trace:  # written beside its path and renamed into place once whole
        from fswkit.outputs import OutputError, Replacement, check, only_its_own
        from fswkit.run.script import trace_header
        try:
            check(args.trace, [path, script.machine.path, script.machine.sv.path], what="trace")
            only_its_own(args.trace, "test", args.force, starts=trace_header(script.machine),  # its whole header
                         what="trace of this machine")
            trace = Replacement(args.trace)
        except OutputError as e:
            sys.stderr.write(f"fsw test: {e}\n")
            return EXIT_FAIL, None
    ok = False
    try:
        if args.native:
            from fswkit.run import native
            try:
                code, report = native.run(script, real, line_of, trace_path=trace and trace.path)
            except native.NativeError as e:
                sys.stderr.write(f"fsw test: {e}\n")
                return EXIT_INTERNAL, None
            except OSError as e:
                sys.stderr.write(f"fsw test: {e.filename or ''}: {e.strerror or e}\n")
                return EXIT_FAIL, None
            ok = True
            sys.stdout.write(report)
            sys.stdout.flush()
            return (EXIT_OK if code == 0 else EXIT_FAIL), None
        try:
            result = run(script, real, trace_path=trace and trace.path, source_line=line_of, cover=args.coverage)
        except OSError as e:
            sys.stderr.write(f"fsw test: cannot write trace {args.trace}: {e.strerror or e}\n")
            return EXIT_FAIL, None
        ok = True
        sys.stdout.write(result.report())
        sys.stdout.flush()
        return (EXIT_OK if result.passed else EXIT_FAIL), (script.machine, result)
    finally:
        if trace is not None:
            trace.finish(ok)


def _report_coverage(coverage: dict) -> bool:
    """Prints, per machine, the states and transitions the scripts reached
    and each one they missed; True when something was missed."""
    from fswkit.autocode.check import gotos

    missed_any = False
    for key in sorted(coverage):
        m, taken, visited = coverage[key]
        name = os.path.basename(m.path)
        moves = []
        for st in m.states:
            for label in ("entry", "step", "exit"):
                for g in gotos(getattr(st, label)):
                    moves.append((st, g))
        hit = sum(1 for _, g in moves if (g.line, g.col) in taken)
        sys.stdout.write(f"coverage of {name}: {len(visited)}/{len(m.states)} states, "
                         f"{hit}/{len(moves)} transitions\n")
        for st in m.states:
            if st.index not in visited:
                missed_any = True
                sys.stdout.write(f"  {name}:{st.line}: state {st.name} never entered\n")
        for st, g in moves:
            if (g.line, g.col) not in taken:
                missed_any = True
                sys.stdout.write(f"  {name}:{g.line}:{g.col}: transition {st.name} -> "
                                 f"{m.states[g.state].name} never taken\n")
    return missed_any


# ---- fsw graph / fsw skeleton ---------------------------------------------------------

def _machine_or_exit(args):
    from fswkit.autocode.project import load_machine

    diags = Diagnostics()
    m = load_machine(args.machine, diags, args.sv)
    print_diags(diags)
    return m


def cmd_graph(args) -> int:
    from fswkit.autocode.emit.graph import to_dot, to_mermaid

    m = _machine_or_exit(args)
    if m is None:
        return EXIT_CONFIG
    return write_output(to_mermaid(m) if args.format == "mermaid" else to_dot(m), args.output, "graph",
                        (args.machine, m.sv.path), own=True, force=args.force)  # the .sv as found beside it too


def cmd_skeleton(args) -> int:
    from fswkit.new.script import skeleton

    m = _machine_or_exit(args)
    if m is None:
        return EXIT_CONFIG
    return write_output(skeleton(m, delta_t=args.delta_t), args.output, "skeleton", (args.machine, m.sv.path),
                        own=True, force=args.force)


# ---- fsw gen ---------------------------------------------------------------------------

def cmd_gen(args) -> int:
    import contextlib

    from fswkit.target.build import BuildError, build_lock, check_out_folder, default_out, generate

    app = load_app(args.project, args.board, "gen")
    if app is None:
        return EXIT_CONFIG
    if args.sketch:
        from fswkit.new.sketch import export
        return export(app, args.sketch)
    out = args.out or os.path.join(default_out(app), "gen")
    try:
        if not args.out:
            check_out_folder(default_out(app), default=True)  # its .lock would make the folder the kit's
        # the default folder is the build's own: not rewritten while a build compiles it
        with build_lock(os.path.dirname(out), "gen") if not args.out else contextlib.nullcontext():
            files = generate(app, out)
    except (BuildError, OSError) as e:
        sys.stderr.write(f"fsw gen: {e.strerror if isinstance(e, OSError) and e.strerror else e}\n")
        return EXIT_FAIL
    sys.stderr.write(f"fsw gen: {len(files)} files in {out}\n")
    return EXIT_OK
