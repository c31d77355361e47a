"""`fsw gen` and `fsw build`: an application's configs to generated C++,
and the generated C++ to firmware (`.elf`/`.hex` for a board, an
executable for `native`) with a flash/RAM table against the board."""

from __future__ import annotations

import os
import shutil
import subprocess
from dataclasses import dataclass

from fswkit.autocode.app import Application, load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit_app import emit_app

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD_MK = os.path.join(ROOT, "mk", "build.mk")


class BuildError(Exception):
    pass


def find_app(project: str) -> str:
    """The application config of a project: the `.app` file itself, or the
    only `.app` in the folder."""
    if os.path.isfile(project):
        if not project.endswith(".app"):
            raise BuildError(f"{project}: not an application config (.app)")
        return project
    if not os.path.isdir(project):
        raise BuildError(f"{project}: no such file or folder")
    apps = sorted(n for n in os.listdir(project) if n.endswith(".app"))
    if len(apps) != 1:
        found = ", ".join(apps) if apps else "none"
        raise BuildError(f"{project}: expected one application config (.app) in the folder, found {found}")
    return os.path.join(project, apps[0])


def load(project: str, diags: Diagnostics, board: str | None = None) -> Application | None:
    return load_app(find_app(project), diags, board_override=board)


def default_out(app: Application) -> str:
    return os.path.join(os.path.dirname(app.path) or ".", "build", app.board.name)


def write_files(files: dict[str, str], out: str) -> list[str]:
    """Writes generated files, leaving unchanged ones untouched (so Make
    rebuilds only what changed), and removes stale generated files."""
    os.makedirs(out, exist_ok=True)
    written = []
    for name in sorted(files):
        path = os.path.join(out, name)
        text = files[name]
        try:
            with open(path) as f:
                if f.read() == text:
                    continue
        except OSError:
            pass
        with open(path, "w") as f:
            f.write(text)
        written.append(path)
    for name in os.listdir(out):
        if name.endswith((".gen.cpp", ".gen.h")) and name not in files:
            os.remove(os.path.join(out, name))
    return written


@dataclass
class Size:
    flash: int  # .text + .data
    ram: int  # .data + .bss
    flash_budget: int
    ram_budget: int
    owner: str = ""  # whose budget: the board's name, or "the application's"

    @property
    def fits(self) -> bool:
        return self.flash <= self.flash_budget and self.ram <= self.ram_budget

    def table(self) -> str:
        def row(name, used, budget, note=""):
            pct = 100.0 * used / budget if budget else 0.0
            return f"  {name:<6}{used:>8,} / {budget:>8,} B  {pct:5.1f} %{note}"
        note = f"  ({self.owner} budget)" if self.owner else ""
        ram_note = ("  (data + bss; the budget counts the stack too: fsw sim measures it)" if self.owner
                    else "  (data + bss; the stack uses the rest)")
        return "\n".join([row("flash", self.flash, self.flash_budget, note),
                          row("RAM", self.ram, self.ram_budget, ram_note)])


def size_of(app, flash: int, ram: int) -> Size:
    """The firmware's size against its budget: the application's `[budget]`
    where it sets one, else the board's memory."""
    b = app.board
    mine = app.flash_budget is not None or app.ram_budget is not None
    return Size(flash, ram, app.flash_budget or b.flash, app.ram_budget or b.ram,
                "the application's" if mine else "")


def elf_size(elf: str) -> tuple[int, int]:
    """(flash, RAM) bytes of an AVR ELF: .text + .data, .data + .bss."""
    r = subprocess.run(["avr-size", "-A", elf], capture_output=True, text=True)
    if r.returncode != 0:
        raise BuildError(f"avr-size failed: {r.stderr.strip()}")
    sec = {}
    for line in r.stdout.splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[0].startswith(".") and parts[1].isdigit():
            sec[parts[0]] = int(parts[1])
    return sec.get(".text", 0) + sec.get(".data", 0), sec.get(".data", 0) + sec.get(".bss", 0)


def make(app: Application, out: str, jobs: int = 2) -> tuple[str, subprocess.CompletedProcess]:
    """Runs mk/build.mk for the application; returns (artifact, process)."""
    gen = os.path.join(out, "gen")
    b = app.board
    name = os.path.splitext(os.path.basename(app.path))[0]
    args = ["make", "--no-print-directory", f"-j{jobs}", "-f", BUILD_MK, f"GEN={gen}", f"OUT={out}",
            f"NAME={name}"]
    if b.is_avr:
        ard = b.raw.get("arduino", {})
        for tool in ("avr-g++", "avr-gcc", "avr-size", "make"):
            if shutil.which(tool) is None:
                raise BuildError(f"`{tool}` is not installed: run `make setup` (or tools/bootstrap.sh)")
        args += ["avr", f"MCU={b.mcu}", f"F_CPU={b.f_cpu}", f"VARIANT={ard.get('variant', 'standard')}",
                 f"BOARD_DEFINE={ard.get('board_define', 'ARDUINO_AVR_UNO')}"]
        artifact = os.path.join(out, name + ".elf")
    else:
        if shutil.which("g++") is None or shutil.which("make") is None:
            raise BuildError("`g++` and `make` are needed for native builds: run `make setup`")
        args += ["native"]
        artifact = os.path.join(out, name)
    proc = subprocess.run(args, capture_output=True, text=True)
    return artifact, proc
