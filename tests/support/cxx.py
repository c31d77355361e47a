"""Compiling generated C++ for a board with -fsyntax-only, the flags of
mk/build.mk (what `fsw build` compiles it with), many projects per
compiler run: cheap enough for property tests over whole applications."""

from __future__ import annotations

import os
import re
import subprocess

from fswkit.autocode.board import Board

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RUNTIME = os.path.join(ROOT, "firmware", "src")
ARDUINO = "/usr/share/arduino/hardware/arduino/avr"
NATIVE_HEADERS = ("<stdio.h>", "<stdlib.h>", "<string.h>", "<time.h>", "<unistd.h>", "<inttypes.h>",
                  '"fswkit.h"', '"psl_native.h"')


def command(board: Board) -> list[str]:
    """The compiler and flags of mk/build.mk for `board`, syntax only."""
    if not board.is_avr:
        return ["g++", "-std=gnu++11", "-fno-exceptions", "-fno-rtti", "-fsyntax-only", "-I", RUNTIME]
    ard = board.raw.get("arduino", {})
    return ["avr-g++", "-std=gnu++11", "-Os", "-fno-exceptions", "-fno-rtti", "-fno-threadsafe-statics",
            "-DDECIMAL_DIG=__DECIMAL_DIG__", f"-mmcu={board.mcu}", f"-DF_CPU={board.f_cpu}L", "-DARDUINO=10819",
            f"-D{ard.get('board_define', 'ARDUINO_AVR_UNO')}", "-DARDUINO_ARCH_AVR",
            f"-I{ARDUINO}/cores/arduino", f"-I{ARDUINO}/variants/{ard.get('variant', 'standard')}",
            "-I", RUNTIME, "-fsyntax-only"]


def write(files: dict[str, str], folder: str) -> list[str]:
    """Writes generated files into `folder`; returns the .cpp paths."""
    os.makedirs(folder, exist_ok=True)
    for name, text in files.items():
        with open(os.path.join(folder, name), "w", encoding="ascii") as f:
            f.write(text)
    return sorted(os.path.join(folder, n) for n in files if n.endswith(".cpp"))


def compile_each(board: Board, cpp: list[str]) -> subprocess.CompletedProcess:
    """Every file as its own translation unit (one compiler run)."""
    return subprocess.run(command(board) + cpp, capture_output=True, text=True)


def compile_together(board: Board, cases: list[dict[str, str]], folder: str) -> subprocess.CompletedProcess:
    """Every case's generated files in one translation unit, each case in a
    namespace of its own (the runtime's and the platform's headers, all
    guarded, are included once before, so the cases' own includes of them
    add nothing): one compiler run for many applications."""
    lines = ["#include <Arduino.h>", '#include "fswkit.h"'] if board.is_avr else \
        [f"#include {h}" for h in NATIVE_HEADERS]
    for k, files in enumerate(cases):
        # The application's constants (fsw_app.h), which the generated file
        # defines in the runtime's own namespace: inside the case's they would
        # open a `fsw` of its own, which hides the runtime's from the case's
        # code, and repeat case after case. Checked in a namespace of their own.
        files = {name: re.sub(r"^namespace fsw \{(?=\n// What this application uses)", f"namespace fsw_app{k} {{",
                              text, flags=re.M)
                 for name, text in files.items()}
        cpp = write(files, os.path.join(folder, f"c{k}"))
        lines.append(f"namespace case{k} {{")
        for name, text in sorted(files.items()):
            m = re.search(r"^#ifndef (\w+)$", text, re.M) if name.endswith(".h") else None
            if m:
                lines.append(f"#undef {m.group(1)}")
        lines += [f'#include "c{k}/{os.path.basename(p)}"' for p in cpp]
        lines.append(f"}}  // namespace case{k}")
    unity = os.path.join(folder, "unity.cpp")
    with open(unity, "w") as f:
        f.write("\n".join(lines) + "\n")
    return subprocess.run(command(board) + [unity], capture_output=True, text=True)
