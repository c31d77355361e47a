"""`fsw param PROJECT list|get|set|save|load|diff`: a target's parameters
over the link (docs/parameters.md, fswkit.param)."""

from __future__ import annotations

import sys

from fswkit.cli.common import EXIT_CONFIG, EXIT_FAIL, EXIT_OK, config_paths, load_app
from fswkit.usage import unknown_name


def _say(msg: str) -> None:
    sys.stderr.write(f"fsw param: {msg}\n")


def _show(p, v, unit: bool = False) -> str:
    """A value as the ground shows it (with its unit when `unit` and it has one)."""
    if p.type.is_bool:
        return "true" if v else "false"
    text = f"{v:.9g}" if p.type.is_float else str(v)
    return f"{text} {p.unit}" if unit and p.unit else text


def cmd_param(args) -> int:
    from fswkit.autocode.params import app_parameters, check_value
    from fswkit.autocode.schema import link_plan
    from fswkit.link.layout import from_app
    from fswkit.param.files import ParamFileError, params_text, read_params

    app = load_app(args.project, None, "param")
    if app is None:
        return EXIT_CONFIG
    params = app_parameters(app)
    if not params:
        _say(f"{args.project}: the application declares no parameters (a machine's [parameters] section, "
             "docs/languages.md)")
        return EXIT_CONFIG
    by_name = {p.name: p for p in params}
    # everything the user typed is checked before the port is opened
    wanted: dict[str, object] = {}
    typed: dict[str, str] = {}  # each value as given
    file_values = None
    if args.action in ("get",):
        if not args.args:
            _say("usage: fsw param PROJECT get NAME...")
            return EXIT_CONFIG
        for n in args.args:
            if n not in by_name:
                _say("get: " + unknown_name("parameter", [n], by_name))
                return EXIT_CONFIG
    elif args.action == "set":
        if not args.args:
            _say("usage: fsw param PROJECT set NAME=VALUE...")
            return EXIT_CONFIG
        for a in args.args:
            name, eq, text = a.partition("=")
            if not eq:
                _say(f"`{a}`: expected NAME=VALUE")
                return EXIT_CONFIG
            p = by_name.get(name.strip())
            if p is None:
                _say("set: " + unknown_name("parameter", [name.strip()], by_name))
                return EXIT_CONFIG
            v, why = check_value(p, text)
            if why is not None:
                _say(why)
                return EXIT_CONFIG
            if p.name in wanted:  # which one was meant is not ours to guess
                _say(f"`{p.name}` is given twice ({typed[p.name]} and {text.strip()}): give it once")
                return EXIT_CONFIG
            wanted[p.name] = v
            typed[p.name] = text.strip()
    elif args.action in ("load", "diff"):
        if args.action == "load" and len(args.args) != 1:
            _say("usage: fsw param PROJECT load FILE.toml")
            return EXIT_CONFIG
        if len(args.args) > 1:
            _say("usage: fsw param PROJECT diff [FILE.toml]")
            return EXIT_CONFIG
        if args.args:
            try:
                file_values = read_params(args.args[0], params)
            except ParamFileError as e:
                sys.stderr.write(f"{e}\n")
                return EXIT_CONFIG
            if args.action == "load" and not file_values:  # a load saves: it would save the live values, unasked
                sys.stderr.write(f"{args.args[0]}: names no parameter: nothing to load (a file holds one "
                                 "`NAME = value` per parameter it sets; `fsw param save` keeps the live values)\n")
                return EXIT_CONFIG
    elif args.args:
        _say(f"`{args.action}` takes no arguments")
        return EXIT_CONFIG
    if args.output is not None and args.action != "list":
        _say("-o/--output goes with `list`")
        return EXIT_CONFIG
    if args.output is not None:
        import os

        from fswkit.outputs import OutputError, check

        try:  # not a config, not the port, not a folder, never a recording, --force or not
            check(args.output, config_paths(app) + [args.port], force=args.force, what="parameter file")
        except OutputError as e:
            _say(str(e))
            return EXIT_FAIL
        if os.path.lexists(args.output) and not args.force:
            _say(f"{args.output} exists: it is replaced only when asked (--force)")
            return EXIT_FAIL
    return _talk(args, app, params, by_name, wanted, file_values, from_app(app), link_plan(app).tx_cap,
                 params_text)


def _talk(args, app, params, by_name, wanted, file_values, layout, tx_cap, params_text) -> int:
    from fswkit.cli.common import talk_on_link
    from fswkit.param.client import ParamClient, ParamError, PortTransport, not_read, uploaded_note

    baud = args.baud or app.baud

    def talk(ground) -> int:
        client = ParamClient(PortTransport(ground), params, tx_cap, baud=baud)
        try:  # whatever --ignore-schema says: a value means a parameter only through its table
            client.table_info(args.project)
        except ParamError as e:
            _say(str(e))
            return EXIT_FAIL
        machine = app.machines[app.reload.machine].name if getattr(app, "reload", None) is not None else None
        slot = client.uploaded_slot(machine)
        if args.action in ("set", "load"):
            why = not_read(params, set(wanted) | set(file_values or ()), machine, slot, args.project)
            if why is not None:
                _say(f"{args.action} refused: {why}")
                return EXIT_FAIL
        note = uploaded_note(params, machine, slot, args.project)
        if note is not None:
            _say(f"note: {note}")
        return _action(args, client, params, by_name, wanted, file_values, params_text)

    return talk_on_link(args, layout, baud, _say, talk, (ParamError,))


def _action(args, client, params, by_name, wanted, file_values, params_text) -> int:
    a = args.action
    if a == "set":
        client.set(wanted)
        print("fsw param: set " + ", ".join(f"{k} = {_show(by_name[k], v, unit=True)}" for k, v in wanted.items())
              + " (live, not saved: `fsw param save` keeps them across power cycles)")
        return EXIT_OK
    if a == "save":
        inf = client.save()
        print(f"fsw param: saved in {inf['source_name']} (sequence {inf['seq']})")
        return EXIT_OK
    if a == "load":
        inf = client.load(file_values)
        print(f"fsw param: loaded {len(file_values)} value(s) from {args.args[0]}, verified (CRC 0x{inf['crc']:04x}),"
              f" saved in {inf['source_name']} (sequence {inf['seq']})")
        return EXIT_OK
    inf = client.info()
    values = client.get_all()
    if a == "get":
        for n in args.args:
            print(f"{n} = {_show(by_name[n], values[n])}")
        return EXIT_OK
    if a == "diff":
        ref = file_values if file_values is not None else {p.name: p.default for p in params}
        what = args.args[0] if args.args else "the defaults"
        differ = [p for p in params if p.name in ref and p.pack(values[p.name]) != p.pack(ref[p.name])]
        for p in differ:
            print(f"{p.name}: target {_show(p, values[p.name])}, {what} {_show(p, ref[p.name])}")
        print(f"fsw param: {len(differ)} of {len(ref)} differ from {what}")
        return 1 if differ else EXIT_OK
    # list
    state = (f"{inf['source_name']}" + (f", sequence {inf['seq']}" if inf['source'] >= 2 else "")
             + (", unsaved changes" if inf["dirty"] else "") + (", writing" if inf["writing"] else ""))
    print(f"parameters of {args.project}: {len(params)} ({state}; live CRC 0x{inf['crc']:04x})")
    w = max(len(p.name) for p in params)
    for p in params:
        v = values[p.name]
        mark = " " if p.pack(v) == p.pack(p.default) else "*"
        unit = f" {p.unit}" if p.unit else ""
        print(f"{mark} {p.name:<{w}}  {_show(p, v):>12}{unit:<6}  default {_show(p, p.default)}, "
              f"{p.range_text()}, in {' '.join(p.when)}")
    if args.output is not None:
        from fswkit.outputs import write_text

        write_text(args.output, params_text(params, values, f"parameters read from the target of {args.project}"))
        print(f"fsw param: wrote {args.output}")
    return EXIT_OK
