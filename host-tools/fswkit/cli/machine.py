"""`fsw machine PROJECT list|upload|activate|revert`: the machine that an
application's `[reload]` names, replaced on a running target over the link
without reflashing (docs/reload.md, fswkit.reload)."""

from __future__ import annotations

import sys

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.cli.common import EXIT_CONFIG, EXIT_FAIL, EXIT_OK, load_app, print_diags, source_or_empty


WAIT = 10.0  # seconds `activate`, `revert` and `upload --activate` wait for the switch (--wait)


def _say(msg: str) -> None:
    sys.stderr.write(f"fsw machine: {msg}\n")


def image_for(app, path: str, diags: Diagnostics):
    """(image, state mask, machine) of the machine in `path`, compiled
    against the application's state vector for its board's evaluation type;
    None with the reasons in `diags` or said."""
    from fswkit.autocode import vmverify as V
    from fswkit.autocode.diagnostics import SM
    from fswkit.autocode.emit.app import real_of
    from fswkit.autocode.emit.bytecode import BytecodeError, compile_machine
    from fswkit.autocode.project import load_machine

    m = load_machine(path, diags, app.sv.path)
    if m is None:
        return None

    if not _in_application(app, m, path, diags):
        return None
    features = V.board_features(app)
    if not _board_runs(app, m, features, path, diags):
        return None
    real = real_of(app)
    try:
        image = compile_machine(m, real)
    except BytecodeError as e:
        diags.error(source_or_empty(path), SM, max(e.line, 1), max(e.col, 1), f"cannot compile to bytecode: {e}")
        return None
    reason = V.verify(image, V.layout_of(app.sv), real.bits // 8, features=features)
    if reason != V.OK:
        _say(f"internal error: the image of {path} fails the verifier ({V.REASONS[reason]})")
        return None
    from fswkit.autocode.emit.bytecode import window_ram

    # the RAM the board's VM gives its windows and locals (16-bit window
    # indices and byte alignment on an AVR): the board would refuse more
    need = window_ram(m, real) if app.board.name == "native" else window_ram(m, real, idx_bytes=2, align=1)
    if need > app.reload.ram:
        _say(f"{path}: machine `{m.name}` needs {need} B for its windows and locals: more than the {app.reload.ram} B "
             f"[reload] ram gives an uploaded machine")
        return None
    allow = app.reload.activate
    mask = bytearray((len(m.states) + 7) // 8)
    for st in m.states:
        if st.name in allow:
            mask[(st.id - 1) // 8] |= 1 << ((st.id - 1) % 8)
    if not any(mask):
        _say(f"{path}: machine `{m.name}` has none of the states in which [reload] lets another machine take over "
             f"({', '.join(allow)}): once running it could never be replaced again; add one of them")
        return None
    return bytes(image), bytes(mask), m


def _board_runs(app, m, features: int, path: str, diags: Diagnostics) -> bool:
    """Whether the board's VM has what machine `m` (read from `path`)
    needs: the firmware was built with a VM that has only the window
    functions of the generated machine, the value types of it and its
    state vector, and what `[reload] vm` names (vmverify.board_features,
    docs/bytecode.md); each local and window it lacks is an error in
    `diags`, located."""
    from fswkit.autocode import model as M
    from fswkit.autocode import vmverify as V
    from fswkit.autocode.diagnostics import SM

    gen = app.machines[app.reload.machine].name
    extra = " and [reload] `vm` names" if app.reload.vm else ""
    why = (f"the firmware's VM was built without it (its VM has what the machine `{gen}` and the state vector use"
           f"{extra}: {', '.join(V.feature_names(features & ~V.FEAT_LOCK))}, and U32, U64 and bool); "
           f"{{fix}}, or name it in [reload] `vm` (or add it to `{gen}`) and build and flash the firmware again")
    ok = True
    for v in m.vars:
        if v.kind == M.LOCAL and not V.takes(V.TYPE_CODES[v.type.name], features):
            diags.error(source_or_empty(path), SM, v.line, 1, f"local `{v.name}` is {v.type.name}: "
                        + why.format(fix="declare it with a type the board takes"))
            ok = False
    for w in m.windows:
        if not features & V.FEATURE_BITS[f"roll_{w.func}"]:
            diags.error(source_or_empty(path), SM, w.line, w.col, f"roll_{w.func}: "
                        + why.format(fix="use a window function the board has"))
            ok = False
    return ok


def _in_application(app, m, path: str, diags: Diagnostics) -> bool:
    """Whether machine `m` (read from `path`) may take the place of the
    generated machine that [reload] names; the reasons in `diags`, located.
    The firmware's tables (the pyro gates' fire states, the recorder's
    states, the activation's states) and the ground's state names hold the
    generated machine's state numbers, so the uploaded machine keeps them,
    and may add states after them; and the application with it in place
    passes `fsw check` (one writer per element, the pyro proof, ...)."""
    from fswkit.autocode.app import load_app
    from fswkit.autocode.diagnostics import SM

    gen = app.machines[app.reload.machine]
    why = ("the firmware and the ground know a state by its number (the pyro gates, the recorder, the telemetry's "
           "state names): keep the generated machine's states in their order, and add new ones after them")
    for old, new in zip(gen.states, m.states):
        if old.name != new.name:
            diags.error(source_or_empty(path), SM, new.line, 2,
                        f"state {new.id} is `{new.name}` here but `{old.name}` in the generated machine `{gen.name}`: "
                        f"{why}")
            return False
    if len(m.states) < len(gen.states):
        missing = ", ".join(st.name for st in gen.states[len(m.states):])
        diags.error(source_or_empty(path), SM, m.states[-1].line if m.states else 1, 1,
                    f"machine `{m.name}` has {len(m.states)} states: the generated machine `{gen.name}` has "
                    f"{len(gen.states)} ({missing} missing): {why}")
        return False
    whole = Diagnostics()
    if load_app(app.path, whole, instead={gen.name: path}) is not None:
        return True
    diags.extend(Diagnostics([d for d in whole.items if d.severity == "error"]))  # its warnings are said already
    return False


def _misplaced(args) -> str | None:
    """What is wrong with an option given to an action it means nothing to
    (ignored, it would leave the user believing it did something)."""
    a = args.action
    if args.activate and a != "upload":
        return "--activate goes with `upload`"
    if args.restart and a != "upload":
        return "--restart goes with `upload`"
    if args.wait is not None and not (a in ("activate", "revert") or a == "upload" and args.activate):
        return "--wait goes with `activate`, `revert` and `upload --activate`"
    return None


def cmd_machine(args) -> int:
    wrong = _misplaced(args)
    if wrong is not None:
        _say(wrong)
        return EXIT_CONFIG
    if args.wait is None:
        args.wait = WAIT
    app = load_app(args.project, None, "machine")
    if app is None:
        return EXIT_CONFIG
    if app.reload is None:
        _say(f"{args.project}: the application has no [reload] section: no machine of it can be replaced at run "
             "time (docs/reload.md)")
        return EXIT_CONFIG
    a = args.action
    built = None
    which = None
    if a == "upload":
        if len(args.args) != 1 or not args.args[0].endswith(".sm"):
            _say("usage: fsw machine PROJECT upload MACHINE.sm [--activate] (the machine's .sm: its state names "
                 "decide where another machine may take over)")
            return EXIT_CONFIG
        d = Diagnostics()
        built = image_for(app, args.args[0], d)
        print_diags(d)
        if built is None:
            return EXIT_CONFIG
        size = len(built[0]) + len(built[1])
        if size > app.reload.size:
            _say(f"{args.args[0]}: the image and its state mask take {size} B: more than the slots' "
                 f"{app.reload.size} B ([reload] size in {args.project})")
            return EXIT_CONFIG
    elif a == "activate":
        if len(args.args) != 1 or args.args[0] not in ("1", "2", "builtin"):
            _say("usage: fsw machine PROJECT activate 1|2|builtin")
            return EXIT_CONFIG
        which = 0 if args.args[0] == "builtin" else int(args.args[0])
    elif args.args:
        _say(f"`{a}` takes no arguments")
        return EXIT_CONFIG
    return _talk(args, app, built, which)


def _describe(app, inf) -> list[str]:
    from fswkit.reload.client import NONE, reason_words

    name = app.machines[app.reload.machine].name

    def what(k: int) -> str:
        return f"the generated `{name}`" if k == 0 else f"the image in slot {k}"

    lines = [f"machine `{name}` of {app.name}: {what(inf.active)} runs"
             + (f"; switching to {what(inf.pending)} at its next allowed state" if inf.pending != NONE else "")]
    for s in inf.slots:
        if s.status == 0:
            lines.append(f"  slot {s.number}: empty")
        else:
            lines.append(f"  slot {s.number}: {s.status_name}, image of {s.length} B, CRC 0x{s.crc:04x}"
                         + (f", activation {s.seq}" if s.seq else "") + ("  (running)" if inf.active == s.number
                                                                         else ""))
    if inf.up_slot:
        lines.append(f"  an upload into slot {inf.up_slot} is open: {inf.up_next} of {inf.up_len + inf.up_nmask} B "
                     "written (`upload` resumes it)")
    if inf.refused:
        lines.append(f"  refused last: slot {inf.refused}, {reason_words(inf.reason)}")
    lines.append(f"  slots of {inf.size} B; {inf.ram} B for an image's windows and locals; another machine may take "
                 f"over in {', '.join(app.reload.activate)}")
    return lines


def _talk(args, app, built, which) -> int:
    from fswkit.autocode.schema import link_plan
    from fswkit.cli.common import talk_on_link
    from fswkit.link.layout import from_app
    from fswkit.param.client import ParamError, PortTransport
    from fswkit.reload.client import MachineClient, MachineError

    baud = args.baud or app.baud

    def talk(ground) -> int:
        client = MachineClient(PortTransport(ground), link_plan(app).tx_cap, baud=baud)
        a = args.action
        if a == "upload":
            image, mask, m = built
            slot, resumed = client.upload(image, mask, restart=args.restart)
            print(f"fsw machine: {args.args[0]} (machine `{m.name}`, {len(image)} B) "
                  f"{'resumed and ' if resumed else ''}committed in slot {slot}, verified by the target")
            if args.activate:
                client.activate(slot, args.wait)
                print(f"fsw machine: slot {slot} runs")
        elif a == "activate":
            client.activate(which, args.wait)
            print(f"fsw machine: {'the generated machine' if which == 0 else f'slot {which}'} runs")
        elif a == "revert":
            target, _inf = client.revert(args.wait)
            print(f"fsw machine: reverted: {'the generated machine' if target == 0 else f'slot {target}'} runs")
        inf = client.info()
        for line in _describe(app, inf):
            print(line)
        return EXIT_OK

    return talk_on_link(args, from_app(app), baud, _say, talk, (MachineError, ParamError))
