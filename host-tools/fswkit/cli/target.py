"""The target's commands: `fsw build`, `fsw flash`, `fsw ports` (the build
service of fswkit.target.build, the upload of fswkit.target.flash, the
ports of fswkit.target.ports)."""

from __future__ import annotations

import os
import sys

from fswkit.cli.common import EXIT_CONFIG, EXIT_FAIL, EXIT_OK, load_app


def build(app, out: str) -> int:
    """Builds the application's firmware in `out` and says what was built
    (board, size table, files) as `fsw build` does; its exit status."""
    from fswkit.target.build import BuildError, firmware

    try:
        built = firmware(app, out, command="build")
    except BuildError as e:
        sys.stderr.write(f"fsw build: {e}\n")
        return e.code
    b = app.board
    print(f"fsw build: {os.path.basename(app.path)} for {b.name} ({b.mcu})")
    if built.size is None:
        print(f"  {built.artifact}")
        return EXIT_OK
    if not built.fits:
        sys.stderr.write(f"fsw build: {built.report}\n")
        return EXIT_FAIL
    print(built.size.table())
    print(f"  {built.elf}\n  {built.hex}")
    return EXIT_OK


# ---- fsw build -------------------------------------------------------------------------

def cmd_build(args) -> int:
    from fswkit.target.build import BuildError, check_out_folder, default_out

    app = load_app(args.project, args.board, "build")
    if app is None:
        return EXIT_CONFIG
    try:
        check_out_folder(args.out or default_out(app), default=not args.out)
    except BuildError as e:
        sys.stderr.write(f"fsw build: {e}\n")
        return e.code
    return build(app, args.out or default_out(app))


# ---- fsw flash -------------------------------------------------------------------------

def cmd_flash(args) -> int:
    """Builds the firmware, then uploads it with avrdude (or `pio run -t
    upload`) through the port named, else the only one connected."""
    from fswkit.target.build import BuildError, build_lock, check_out_folder, default_out, firmware_name
    from fswkit.target.flash import FlashError, check_board_on_port, check_port, upload_avrdude, upload_pio
    from fswkit.target.ports import PortError, default_port

    app = load_app(args.project, args.board, "flash")
    if app is None:
        return EXIT_CONFIG
    board = app.board
    if not board.is_avr or not board.raw.get("upload", {}).get("tool"):
        sys.stderr.write(f"fsw flash: board `{board.name}` runs on this computer, there is nothing to "
                         f"upload (`fsw build --board {board.name}` builds it)\n")
        return EXIT_CONFIG
    try:
        if args.out or args.via != "pio":  # `--via pio` builds in PlatformIO's folder
            check_out_folder(args.out or default_out(app), default=not args.out)
        port, listing = default_port(args.port, "flash")
        if not args.port:
            sys.stderr.write(f"fsw flash: using {listing.label() if listing else port}, "
                             "the only serial port found\n")
        if not args.force:
            check_board_on_port(board, listing, port)
        check_port(port, int(board.raw["upload"]["baud"]))
        if args.via == "pio":
            return upload_pio(app, port)
        out = args.out or default_out(app)
        with build_lock(out, "flash"):  # no other build rewrites the image between building and uploading it
            code = build(app, out)
            if code != EXIT_OK:
                return code
            return upload_avrdude(board, os.path.join(out, firmware_name(app) + ".hex"), port, args.verbose)
    except BuildError as e:
        sys.stderr.write(f"fsw flash: {e}\n")
        return EXIT_FAIL
    except OSError as e:  # the build folder cannot be made or locked
        sys.stderr.write(f"fsw flash: {e.filename or ''}: {e.strerror or e}\n")
        return EXIT_FAIL
    except PortError as e:
        sys.stderr.write(f"fsw flash: {e}\n")
        return EXIT_FAIL
    except FlashError as e:
        sys.stderr.write(f"fsw flash: {e}\n")
        return e.code


# ---- fsw ports -------------------------------------------------------------------------

def cmd_ports(args) -> int:
    from fswkit.target.ports import PortError, format_table, list_ports

    try:
        ports = list_ports(include_all=args.all)
    except PortError as e:
        sys.stderr.write(f"fsw ports: {e}\n")
        return EXIT_FAIL
    if not ports:
        sys.stderr.write("fsw ports: no serial port found" + ("" if args.all else " (connect a board by USB; "
                         "--all lists built-in ports too)") + "\n")
        return EXIT_FAIL
    sys.stdout.write(format_table(ports))
    return EXIT_OK
