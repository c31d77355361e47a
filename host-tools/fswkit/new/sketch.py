"""`fsw gen PROJECT --sketch DIR`: a project as an Arduino sketch folder
that arduino-cli (or the Arduino IDE) builds with the fswkit library
installed. arduino-cli compiles every .cpp in a sketch's top folder beside
the .ino, so the folder holds the generated files as they are, a near-empty
DIR.ino that names the headers (which is how arduino-cli finds the library),
and a sketch.yaml with the board's FQBN."""

from __future__ import annotations

import os
import re
import shlex

from fswkit.autocode.app import Application
from fswkit.autocode.cnames import comment

# Arduino's sketch name rules: letters, digits, `_`, `-`, `.`; not starting
# with `-` or `.`; at most 63 characters.
SKETCH_NAME = re.compile(r"[0-9A-Za-z_][0-9A-Za-z_.-]{0,62}\Z")

# What `fsw build` (mk/build.mk) adds to the Arduino core's platform.txt
# flags, as arduino-cli build properties: with them an exported sketch
# compiles to `fsw build`'s firmware (integrations/arduino-cli/README.md).
# A sketch folder cannot carry them (sketch.yaml has no place for flags):
# sketch.yaml names them in a comment.
# (The link's -ffunction-sections -fdata-sections: LTO compiles the program
# again there, and a board's VM drops its unused features only then; its
# -fno-toplevel-reorder keeps each function near those it calls.)
SIZE_FLAGS = "-mcall-prologues -mstrict-X -fno-move-loop-invariants -fno-tree-vrp -fira-algorithm=priority"  # mk/build.mk's SIZE_OPT
BUILD_PROPERTIES = {"compiler.c.extra_flags": SIZE_FLAGS, "compiler.cpp.extra_flags": SIZE_FLAGS,
                    "compiler.c.elf.extra_flags": "-Wl,--relax -ffunction-sections -fdata-sections -fno-toplevel-reorder"}


class SketchError(Exception):
    pass


def sketch_name(folder: str) -> str:
    """The sketch's name: its folder's, which the .ino must share."""
    name = os.path.basename(os.path.normpath(folder))
    if not SKETCH_NAME.match(name):
        raise SketchError(f"`{name}` cannot name an Arduino sketch (the folder names the sketch): use "
                          "ASCII letters (A-Z, a-z), digits, `_`, `-` and `.`, starting with a letter, a digit or `_`, "
                          "at most 63 characters")
    return name


def sketch_files(app: Application, generated: dict[str, str], name: str) -> dict[str, str]:
    """The sketch folder's files: the generated ones, NAME.ino and sketch.yaml."""
    fqbn = app.board.raw.get("arduino", {}).get("fqbn", "")
    if not app.board.is_avr or not fqbn:
        raise SketchError(f"board `{app.board.name}` is not an Arduino board: export a sketch for "
                          "one (--board uno, nano, mega2560)")
    project = comment(os.path.basename(app.path))  # a file name in a comment: autocode/cnames.py
    headers = sorted(n for n in generated if n.endswith(".h"))
    ino = [f"// {name}: the fswkit application {project} for the {app.board.name}, exported by",
           "// `fsw gen --sketch`. The application is the generated code beside this",
           "// file (app.gen.cpp holds setup() and loop()): change the configs and",
           "// export again rather than editing it. Needs the fswkit library",
           "// (integrations/arduino-cli/README.md of fswkit).",
           "#include <fswkit.h>"]
    ino += [f'#include "{h}"' for h in headers]
    files = dict(generated)
    files[name + ".ino"] = "\n".join(ino) + "\n"
    props = "".join(f"#   --build-property {shlex.quote(f'{k}={v}')}\n" for k, v in BUILD_PROPERTIES.items())
    files["sketch.yaml"] = (f"# arduino-cli: `arduino-cli compile` in this folder builds for the {app.board.name}.\n"
                            "# With fsw build's flags (its firmware; integrations/arduino-cli/README.md of fswkit):\n"
                            + props + f"default_fqbn: {fqbn}\n")
    return files


def _ours(path: str) -> bool:
    """Whether a sketch's file may be written at `path`: nothing is there, or a
    file an export wrote (its first line names fswkit, or arduino-cli for
    sketch.yaml)."""
    from fswkit.autocode.diagnostics import InputError, read_head

    try:  # a FIFO or a device is not opened for long, and is no export's file
        first = read_head(path, 400).split(b"\n", 1)[0]
    except FileNotFoundError:
        return True
    except InputError:
        return False
    except OSError:
        return not os.path.lexists(path)
    return b"fswkit" in first or first.startswith(b"# arduino-cli:")


def export(app: Application, folder: str) -> int:
    """`fsw gen PROJECT --sketch DIR`: writes the sketch folder; returns the exit status."""
    import sys

    from fswkit.autocode.emit.app import GenError, emit_app
    from fswkit.target.build import write_files

    try:
        name = sketch_name(folder)
        files = sketch_files(app, emit_app(app), name)
    except (SketchError, GenError) as e:
        sys.stderr.write(f"fsw gen: {e}\n")
        return 2 if isinstance(e, SketchError) else 1
    foreign = [f for f in sorted(files) if not _ours(os.path.join(folder, f))]
    if foreign:
        sys.stderr.write(f"fsw gen: {os.path.join(folder, foreign[0])}: a file not written by fsw gen is there: "
                         "it is never overwritten; export into another folder, or move it away first\n")
        return 1
    try:
        write_files(files, folder)
    except OSError as e:
        sys.stderr.write(f"fsw gen: cannot write {e.filename or folder}: {e.strerror or e}\n")
        return 1
    from fswkit.autocode.kit import ROOT

    fqbn = app.board.raw["arduino"]["fqbn"]
    # pasted as it is, it finds the runtime without a sketchbook link (the README's step 1)
    command = shlex.join(["arduino-cli", "compile", "-b", fqbn, "--library", os.path.join(ROOT, "firmware"), folder])
    sys.stderr.write(f"fsw gen: sketch {name} for the {app.board.name} in {folder} ({len(files)} files); "
                     f"build it with: {command}\n")
    return 0
