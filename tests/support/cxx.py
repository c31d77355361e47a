"""Compiling generated C++ for a board, the flags of mk/build.mk (what
`fsw build` compiles it with), cheap enough for property tests over whole
applications. avr-g++ checks with -fsyntax-only, many files per compiler
run. The host's g++ compiles each file to an object instead (-O0, as the
flags have it: barely dearer, and it checks at least as much), one
compiler run a file, named relative to its folder: a compiler cache
(ccache, as `make test` uses) keeps those, the same from run to run
wherever the test's folder is, where it cannot keep a syntax-only run or
one of several files. Many projects in one translation unit
(`compile_together`) are checked for syntax only, by either compiler."""

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
    """The compiler and flags of mk/build.mk for `board`: syntax only for
    avr-g++; to an object (`-o` to follow) for the host's g++."""
    if not board.is_avr:
        return ["g++", "-std=gnu++11", "-fno-exceptions", "-fno-rtti", "-I", RUNTIME, "-c"]
    ard = board.raw.get("arduino", {})
    return ["avr-g++", "-std=gnu++11", "-Os", "-fno-exceptions", "-fno-rtti", "-fno-threadsafe-statics",
            "-DDECIMAL_DIG=__DECIMAL_DIG__", f"-mmcu={board.mcu}", f"-DF_CPU={board.f_cpu}L", "-DARDUINO=10819",
            f"-D{ard.get('board_define', 'ARDUINO_AVR_UNO')}", "-DARDUINO_ARCH_AVR",
            f"-I{ARDUINO}/cores/arduino", f"-I{ARDUINO}/variants/{ard.get('variant', 'standard')}",
            "-I", RUNTIME, "-fsyntax-only"]


def syntax_only(board: Board) -> list[str]:
    """`command(board)` checking syntax only, for the host's g++ too."""
    cmd = command(board)
    return cmd if board.is_avr else [x for x in cmd if x != "-c"] + ["-fsyntax-only"]


def write(files: dict[str, str], folder: str) -> list[str]:
    """Writes generated files into `folder`; returns the .cpp paths."""
    os.makedirs(folder, exist_ok=True)
    for name, text in files.items():
        with open(os.path.join(folder, name), "w", encoding="ascii") as f:
            f.write(text)
    return sorted(os.path.join(folder, n) for n in files if n.endswith(".cpp"))


def _to_object(board: Board, src: str) -> subprocess.CompletedProcess:
    """The host's g++ on one file, in its folder, to an object beside it."""
    folder, name = os.path.split(os.path.abspath(src))
    return subprocess.run(command(board) + [name, "-o", os.path.splitext(name)[0] + ".o"], capture_output=True,
                          text=True, cwd=folder)


def compile_each(board: Board, cpp: list[str]) -> subprocess.CompletedProcess:
    """Every file as its own translation unit: one compiler run for
    avr-g++, one a file for the host's g++ (its output after each failing
    file's path; the status the first failure's)."""
    if board.is_avr:
        return subprocess.run(command(board) + cpp, capture_output=True, text=True)
    code, out, err = 0, [], []
    for src in cpp:
        r = _to_object(board, src)
        out.append(r.stdout)
        if r.returncode != 0:
            code = code or r.returncode
            err.append(f"{src}:\n")
        err.append(r.stderr)
    return subprocess.CompletedProcess(command(board) + cpp, code, "".join(out), "".join(err))


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
    # syntax only, the host's g++ too: an object (or assembly) of a hundred
    # projects costs several times the check, every `make fuzz` chunk anew,
    # and the assembler would refuse the cases' C functions and variables of
    # the same name (one symbol for all their namespaces)
    return subprocess.run(syntax_only(board) + [unity], capture_output=True, text=True)


def program(flags: list[str], sources: list, exe, cwd, objects=(), link=()) -> subprocess.CompletedProcess:
    """A host program: each source compiled with the host's g++ and `flags`
    to an object of its own (in `cwd`/obj), then the objects and `objects`
    linked into `exe` with `flags` and `link`. Runs in `cwd`, a source in
    it named relative to it (and `flags`' -I folders there best given so):
    a compiler cache (ccache, as `make test` uses) keeps the objects from
    run to run wherever the test's folder is, where it cannot keep one
    command of several sources. The first failing compile's process, else
    the link's."""
    cwd = os.path.abspath(cwd)
    os.makedirs(os.path.join(cwd, "obj"), exist_ok=True)
    objs = []
    for src in map(str, sources):
        src = os.path.abspath(os.path.join(cwd, src))
        name = os.path.relpath(src, cwd) if src.startswith(cwd + os.sep) else src
        objs.append(os.path.join("obj", os.path.splitext(os.path.basename(src))[0] + ".o"))
        r = subprocess.run(["g++", *flags, "-c", name, "-o", objs[-1]], capture_output=True, text=True, cwd=cwd)
        if r.returncode != 0:
            return r
    return subprocess.run(["g++", *flags, *objs, *map(str, objects), *link, "-o", str(exe)], capture_output=True,
                          text=True, cwd=cwd)
