"""`fsw compile`: a machine as a bytecode image for the runtime's VM
(docs/bytecode.md), verified on the host before it is written."""

from __future__ import annotations

import sys

from fswkit.autocode.diagnostics import SM, Diagnostics
from fswkit.cli.common import (EXIT_CONFIG, EXIT_FAIL, EXIT_INTERNAL, EXIT_OK, plural, print_diags, real_of,
                               source_or_empty)

LAYOUT_HEAD = "fswsm-layout "  # the first line of a layout file that is not a comment (fswkit.sm.layout_text)


def _not_ours(path: str, what: str) -> str | None:
    """Why `path` may not be replaced by an image (`what` "image") or a
    layout ("layout") unasked: a file that holds something else, which a
    user wrote (a config, notes), is never overwritten without --force.
    None for a path that does not exist, is empty, is no regular file (a
    device) or holds what this command writes."""
    from fswkit.autocode.vmverify import MAGIC
    from fswkit.outputs import file_head

    head = file_head(path, 4096)
    if not head:  # nothing there to lose (or unreadable: the write says why)
        return None
    if what == "image":
        return None if head.startswith(MAGIC) else "a bytecode image"
    lines = (line.strip() for line in head.decode("utf-8", "replace").splitlines())
    first = next((line for line in lines if line and not line.startswith("#")), "")
    return None if first.startswith(LAYOUT_HEAD) else "a layout"


def cmd_compile(args) -> int:
    from fswkit.autocode import vmverify as V
    from fswkit.autocode.check import check_literals, machine_exprs
    from fswkit.autocode.emit.bytecode import BytecodeError, compile_machine
    from fswkit.autocode.project import load_machine
    from fswkit.outputs import OutputError, check, output, same_file

    real = real_of(args, "compile")
    if real is None:
        return EXIT_CONFIG

    diags = Diagnostics()
    m = load_machine(args.machine, diags, args.sv)
    if m is not None:  # a number binary32 cannot hold would be compiled as an infinity
        check_literals(machine_exprs(m), real, source_or_empty(args.machine), diags, SM, "the image's")
    print_diags(diags)
    if m is None or diags.error_count:
        return EXIT_CONFIG
    try:
        image = compile_machine(m, real)
    except BytecodeError as e:
        d = Diagnostics()
        d.error(source_or_empty(args.machine), SM, max(e.line, 1), max(e.col, 1), f"cannot compile to bytecode: {e}")
        print_diags(d)
        return EXIT_CONFIG
    reason = V.verify(image, V.layout_of(m.sv), real.bits // 8)
    if reason != V.OK:  # the compiler's own fault: never written
        sys.stderr.write(f"fsw compile: internal error: the image of {args.machine} fails the verifier "
                         f"(reason {reason}: {V.REASONS[reason]})\n")
        return EXIT_INTERNAL
    layout = getattr(args, "layout", None)
    if layout is not None and (layout == "-" or (args.output != "-" and same_file(layout, args.output))):
        if layout != "-":
            words = "the image's own path: name another file"
        elif args.output == "-":
            words = "the image goes to standard output; the layout needs a file"
        else:
            words = "a layout is written to a file, not to standard output: the layout needs a file"
        sys.stderr.write(f"fsw compile: --layout {layout}: {words}\n")
        return EXIT_CONFIG
    try:
        for path in (args.output, layout):  # checked before anything is written
            if path not in (None, "-"):
                check(path, (args.machine, m.sv.path))
        for path, what in ((args.output, "image"), (layout, "layout")):
            kind = None if path in (None, "-") or args.force else _not_ours(path, what)
            if kind is not None:
                raise OutputError(f"{path}: the file exists and is not {kind}: it is not replaced unless asked "
                                  "(--force)")

        def write_layout() -> None:
            from fswkit.sm import layout_text
            with output(layout, (args.machine, m.sv.path), newline="\n", what="layout") as out:
                out.write(layout_text(m, real.bits, None if args.output == "-" else args.output))

        if args.output == "-":
            sys.stdout.buffer.write(image)
            sys.stdout.buffer.flush()
            if layout is not None:
                write_layout()
        else:
            # the layout is written inside the image's block: a layout that cannot be written (a full
            # disk, /dev/full) leaves the image's path as it was
            with output(args.output, (args.machine, m.sv.path), binary=True) as out:
                out.write(image)
                if layout is not None:
                    write_layout()
    except OutputError as e:
        sys.stderr.write(f"fsw compile: {e}\n")
        return EXIT_FAIL
    if args.output != "-":
        sys.stderr.write(f"fsw compile: {args.output}: {len(image)} bytes, {plural(len(m.states), 'state')}, "
                         f"binary{real.bits}, schema 0x{V.layout_of(m.sv).schema:08x}\n")
    if layout is not None:
        sys.stderr.write(f"fsw compile: {layout}: the layout of {plural(len(m.sv.elements), 'element')} "
                         f"({m.sv.size} bytes) and {plural(len(m.states), 'state')}\n")
    return EXIT_OK
