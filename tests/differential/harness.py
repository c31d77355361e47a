"""Runs generated projects (gen_programs.py) through the interpreter and
through the generated C++, many cases per executable.

Batching: compiling one runner per case costs about a second. Here each
case's generated code lives in its own outer namespace (`fsw_c<k>`, the
emitters' `ns` option) with its runner as `fsw_c<k>::run` (their `entry`
option), several cases share a translation unit, the translation units
compile in parallel (one job per core), and one dispatcher `main` runs
every case of the batch in one process, each writing its report and its
binary trace to files of its own."""

from __future__ import annotations

import hashlib
import os
import re
import shlex
import shutil
import struct
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

from fswkit.run import native
from fswkit.autocode import model as M
from fswkit.autocode.check import check_sm, check_ss, check_sv
from fswkit.autocode.diagnostics import Diagnostics, Source
from fswkit.autocode.emit.machine import emit_machine
from fswkit.autocode.emit.script import script_files
from fswkit.autocode.emit.sv import emit_sv
from fswkit.autocode.numeric import Real
from fswkit.autocode.parser import parse_sm, parse_ss, parse_sv
from fswkit.run.script import run as interp_run

from gen_programs import Case

JOBS = max(1, min(2, os.cpu_count() or 1))
# What generated machines and runners call (with the native PSL: the lock).
RUNTIME_SOURCES = ("fsw_convert.cpp", "fsw_element.cpp", "fsw_f64.cpp", "fsw_machine.cpp", "fsw_sv.cpp", "fsw_window.cpp",
                   "psl_native.cpp")
# Generated scripts stop within a few hundred steps; a native trace longer
# than this is reported as such, not converted.
MAX_ROWS = 20000


class GeneratorBug(Exception):
    """A generated project did not compile as configs (a bug in the generator)."""


class CompileFailure(Exception):
    """The generated C++ of case `key` did not compile (a bug in the emitter)."""

    def __init__(self, key: int, stderr: str):
        super().__init__(f"the generated C++ of case {key} does not compile:\n{stderr}")
        self.key = key


def load(case: Case) -> tuple[M.Script, object]:
    """The checked script of a case, and its `source_line(path, n)`."""
    srcs = {case.name + ext: Source.from_text(case.name + ext, text)
            for ext, text in ((".sv", case.sv), (".sm", case.sm), (".ss", case.ss))}
    d = Diagnostics()
    sv = check_sv(parse_sv(srcs[case.name + ".sv"], d), srcs[case.name + ".sv"], d)
    m = check_sm(parse_sm(srcs[case.name + ".sm"], d), srcs[case.name + ".sm"], sv, d) if not d.errors else None
    s = check_ss(parse_ss(srcs[case.name + ".ss"], d), srcs[case.name + ".ss"], m, d) \
        if m is not None and not d.errors else None
    if s is None:
        raise GeneratorBug(d.render() + "\n" + case.repro())

    def source_line(path: str, n: int) -> str:
        return srcs[path].line(n) if path in srcs else ""
    return s, source_line


@dataclass
class Outcome:
    code: int  # 0 passed, 1 failed
    report: str
    trace: str  # the CSV trace (fsw test --trace)


def run_interpreter(script: M.Script, real: Real, source_line, trace_path: str) -> Outcome:
    result = interp_run(script, real, trace_path=trace_path, source_line=source_line)
    with open(trace_path) as f:
        trace = f.read()
    return Outcome(0 if result.passed else 1, result.report(), trace)


# ---- native batches ----------------------------------------------------------------

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def prune_cache(max_bytes: int = 400 << 20) -> None:
    """Drops the least recently used objects until the cache holds at most
    `max_bytes` (every emitter change makes a new set)."""
    objs = []
    for sub in ("obj", "avr"):
        d = os.path.join(cache_dir(), sub)
        if os.path.isdir(d):
            for n in os.listdir(d):
                p = os.path.join(d, n)
                st = os.stat(p)
                objs.append((st.st_mtime, st.st_size, p))
    total = sum(size for _, size, _ in objs)
    for _, size, p in sorted(objs):
        if total <= max_bytes:
            break
        os.remove(p)
        total -= size


def scratch_dir(fallback: str) -> str:
    """A fresh directory for one run's thousands of small files: in memory
    (/dev/shm) where there is one, else under `fallback`."""
    import tempfile
    shm = "/dev/shm"
    base = shm if os.path.isdir(shm) and os.access(shm, os.W_OK) else fallback
    return tempfile.mkdtemp(prefix="fswdiff-", dir=base)


def cache_dir() -> str:
    """Compiled objects, named by the hash of everything that goes into
    them (so a stale one can never be used): $FSW_DIFF_CACHE, else
    build/differential."""
    return os.environ.get("FSW_DIFF_CACHE") or os.path.join(ROOT, "build", "differential")


def _cc(cmd: list[str]) -> None:
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise native.NativeError("the generated code did not compile:\n" + " ".join(cmd) + "\n" + r.stderr[-6000:])


def _runtime_hash() -> bytes:
    h = hashlib.sha256()
    for n in sorted(os.listdir(native.RUNTIME)):
        with open(os.path.join(native.RUNTIME, n), "rb") as f:
            h.update(n.encode() + b"\0" + f.read())
    return h.digest()


def flags(real: Real, opt: str = "-O0", cxx: str = native.CXX) -> list[str]:
    """native.py's flags for `cxx` (warnings as errors included) at optimisation `opt`."""
    return [x for x in native.CXXFLAGS if not x.startswith("-O")] + [opt] + native.compiler_flags(cxx) + \
        native.FLAGS[real.bits]


def default_cxx() -> str:
    """$FSW_DIFF_CXX (a command, flags allowed), else clang++ where
    installed (at -O0 it compiles the script runners in less than half of
    g++'s time; `fsw test --native` and test_examples.py build with g++
    -O2), else native.CXX."""
    env = os.environ.get("FSW_DIFF_CXX")
    if env:
        return env
    return "clang++" if shutil.which("clang++") else native.CXX


def _compile_cached(src_text: str, name: str, cmd_flags: list[str], include: list[str], key: bytes,
                    workdir: str, cxx: str) -> str:
    """Compiles `src_text` (written as `name` in `workdir`) to an object kept
    in the cache under the hash of `key`, the text, the compiler and flags."""
    h = hashlib.sha256(key + src_text.encode() + " ".join([cxx] + cmd_flags).encode()).hexdigest()[:24]
    obj = os.path.join(cache_dir(), "obj", h + ".o")
    if os.path.exists(obj):
        os.utime(obj)  # recently used: kept by prune_cache
        return obj
    os.makedirs(os.path.dirname(obj), exist_ok=True)
    src = os.path.join(workdir, name)
    with open(src, "w") as f:
        f.write(src_text)
    tmp = obj + f".tmp{os.getpid()}.{threading.get_ident()}"
    _cc(shlex.split(cxx) + cmd_flags + ["-I", native.RUNTIME] + [x for d in include for x in ("-I", d)]
        + ["-c", src, "-o", tmp])
    os.replace(tmp, obj)
    return obj


class Batch:
    """The generated C++ of many cases, compiled into one program.

    `add()` writes a case's generated files; every `per_tu` cases form a
    translation unit that starts compiling at once on `pool` (shared by
    batches, one job per core), so compilation overlaps whatever the caller
    does next (running the interpreter). `run()` links and runs them all."""

    kind = "batch"

    def __init__(self, workdir: str, real: Real, pool: ThreadPoolExecutor, per_tu: int = 25,
                 opt: str = "-O0", timeout: float = 300, cxx: str | None = None):
        self.real, self.pool, self.per_tu = real, pool, per_tu
        self.cxx = cxx or default_cxx()
        self.timeout = timeout
        self.flags = flags(real, opt, self.cxx)
        self.dir = os.path.join(workdir, f"{self.kind}-{real.name}")
        os.makedirs(self.dir, exist_ok=True)
        self.items: list[tuple[int, M.Script]] = []
        self.pending: list[str] = []  # #include lines of the unit being filled
        self.pending_key = hashlib.sha256()
        self.objects = []  # futures
        self.rt_key = _runtime_hash()
        rt = [os.path.join(native.RUNTIME, n) for n in RUNTIME_SOURCES]
        self.objects += [pool.submit(self._runtime_object, s) for s in rt]

    def _runtime_object(self, src: str) -> str:
        with open(src) as f:
            text = f.read()
        return _compile_cached(text, "rt_" + os.path.basename(src), self.flags, [native.RUNTIME],
                               self.rt_key, self.dir, self.cxx)

    def add(self, k: int, script: M.Script, source_line) -> None:
        files = script_files(script, self.real, source_line, ns=f"fsw_c{k}", entry="run")
        self._add_files(k, files, "script_main.cpp")
        self.items.append((k, script))

    def _add_files(self, k: int, files: dict[str, str], last: str) -> None:
        """Writes case k's files; the unit includes the state vector, the
        machine, then `last`."""
        d = os.path.join(self.dir, f"c{k}")
        os.makedirs(d, exist_ok=True)
        for name in sorted(files):
            with open(os.path.join(d, name), "w") as f:
                f.write(files[name])
            self.pending_key.update(f"c{k}/{name}\0".encode() + files[name].encode() + b"\0")
        machine = [n for n in sorted(files) if n.endswith(".gen.cpp") and n != "sv.gen.cpp"][0]
        self.pending += [f'#include "c{k}/sv.gen.cpp"', f'#include "c{k}/{machine}"', f'#include "c{k}/{last}"']
        if len(self.pending) >= 3 * self.per_tu:
            self._flush()

    def _flush(self) -> None:
        if not self.pending:
            return
        text = "\n".join(self.pending) + "\n"
        key = self.rt_key + self.pending_key.digest()
        name = f"tu{len(self.objects)}.cpp"
        self.objects.append(self.pool.submit(self._compile_unit, text, name, key, list(self.pending)))
        self.pending, self.pending_key = [], hashlib.sha256()

    def _compile_unit(self, text: str, name: str, key: bytes, lines: list[str]) -> str:
        try:
            return _compile_cached(text, name, self.flags, [self.dir], key, self.dir, self.cxx)
        except native.NativeError as e:
            # Which case? Each one's three files on their own.
            for i in range(0, len(lines), 3):
                k = int(lines[i].split('"c', 1)[1].split("/", 1)[0])
                one = os.path.join(self.dir, f"one{k}.cpp")
                with open(one, "w") as f:
                    f.write("\n".join(lines[i:i + 3]) + "\n")
                r = subprocess.run(shlex.split(self.cxx) + self.flags + ["-I", native.RUNTIME, "-I", self.dir,
                                                               "-fsyntax-only", one], capture_output=True, text=True)
                if r.returncode != 0:
                    raise CompileFailure(k, r.stderr[-6000:]) from None
            raise e

    def _main(self) -> str:
        keys = [k for k, _ in self.items]
        main = ["#include <stdio.h>", "#include <stdlib.h>", ""]
        main += [f"namespace fsw_c{k} {{ int run(int argc, char** argv); }}" for k in keys]
        main += ["", "typedef int (*Run)(int, char**);",
                 "static const Run kRun[] = {" + ", ".join(f"fsw_c{k}::run" for k in keys) + "};",
                 "static const int kKey[] = {" + ", ".join(str(k) for k in keys) + "};",
                 f"static const int kCases = {len(keys)};", "",
                 "// runner DIR [K]: every case (or case K only): its report to DIR/<k>.out, its",
                 "// trace to DIR/<k>.raw, a line `<k> <exit status>` to DIR/status.",
                 "int main(int argc, char** argv) {",
                 "    if (argc < 2) return 2;",
                 "    char path[4096];",
                 "    snprintf(path, sizeof path, \"%s/status\", argv[1]);",
                 "    FILE* status = fopen(path, \"w\");",
                 "    if (status == 0) return 2;",
                 "    const int only = argc > 2 ? atoi(argv[2]) : -1;",
                 "    for (int i = 0; i < kCases; ++i) {",
                 "        if (only >= 0 && kKey[i] != only) continue;",
                 "        snprintf(path, sizeof path, \"%s/%d.out\", argv[1], kKey[i]);",
                 "        if (freopen(path, \"w\", stdout) == 0) return 2;",
                 "        char trace[4096];",
                 "        snprintf(trace, sizeof trace, \"%s/%d.raw\", argv[1], kKey[i]);",
                 "        char* args[] = {argv[0], trace, 0};",
                 "        const int rc = kRun[i](2, args);",
                 "        fflush(stdout);",
                 "        fprintf(status, \"%d %d\\n\", kKey[i], rc);",
                 "        fflush(status);",
                 "    }",
                 "    fclose(status);",
                 "    return 0;",
                 "}", ""]
        return "\n".join(main)

    def build(self) -> str:
        self._flush()
        main = self._main()
        self.objects.append(self.pool.submit(_compile_cached, main, "main.cpp", self.flags, [], b"", self.dir,
                                             self.cxx))
        objs = [f.result() for f in self.objects]
        exe = os.path.join(self.dir, "runner")
        _cc(shlex.split(self.cxx) + objs + ["-o", exe])
        return exe

    def run(self) -> dict[int, Outcome]:
        """Links and runs every case: the outcome of each (report, CSV trace)."""
        exe = self.build()
        out = os.path.join(self.dir, "run")
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        try:
            r = subprocess.run([exe, out], capture_output=True, text=True, timeout=self.timeout)
            died = f"status {r.returncode}: {r.stderr[-2000:]}" if r.returncode != 0 else None
        except subprocess.TimeoutExpired:
            died = f"timed out after {self.timeout} s"
        status = {}
        if os.path.exists(os.path.join(out, "status")):
            with open(os.path.join(out, "status")) as f:
                for line in f:
                    k, rc = line.split()
                    status[int(k)] = int(rc)
        results: dict[int, Outcome] = {}
        for k, script in self.items:
            if k not in status:
                # The case that was running when the runner died, and those after it.
                results[k] = Outcome(-1, f"native runner: {died or 'no result'}", "")
                continue
            with open(os.path.join(out, f"{k}.out")) as f:
                report = f.read()
            raw = os.path.join(out, f"{k}.raw")
            rows = os.path.getsize(raw) // (8 * len(script.machine.vars))
            if rows > MAX_ROWS:  # a run that missed its @stop: do not convert megabytes
                results[k] = Outcome(status[k], report, f"(native trace of {rows} steps)\n")
                continue
            csv = os.path.join(out, "trace.csv")
            native._raw_to_csv(script.machine, raw, csv)
            with open(csv) as f:
                trace = f.read()
            results[k] = Outcome(status[k], report, trace)
        return results


# ---- machines driven by raw element values (gen_programs.machine_case) ------------------

def load_machine(case) -> M.Machine:
    d = Diagnostics()
    srcs = [Source.from_text(case.name + ext, text) for ext, text in ((".sv", case.sv), (".sm", case.sm))]
    sv = check_sv(parse_sv(srcs[0], d), srcs[0], d)
    m = check_sm(parse_sm(srcs[1], d), srcs[1], sv, d) if not d.errors else None
    if m is None:
        raise GeneratorBug(d.render() + "\n" + case.repro())
    return m


def _decode(t, raw: bytes):
    if t.kind == "float":
        return struct.unpack("<f" if t.size == 4 else "<d", raw)[0]
    return int.from_bytes(raw, "little", signed=t.kind == "int" and t.signed)


def _same(t, a, b) -> bool:
    """Equal values, floats bit for bit (so -0 differs from +0)."""
    if t.kind == "float":
        fmt = "<f" if t.size == 4 else "<d"
        return struct.pack(fmt, a) == struct.pack(fmt, b)
    return int(a) == int(b)


def interpret_machine(case, m: M.Machine, real: Real) -> list[dict[int, object]]:
    """The interpreter's variables after each step, the inputs written
    before it (a NaN input as the 0 it reads as: spec §4.5)."""
    from fswkit.run.interp import OK, MachineRun

    run = MachineRun(m, real, case.init_state)
    idx = [m.var(name).index for name, _ in case.input_types]
    rows = []
    for n, raw_row in enumerate(case.steps):
        for i, raw in zip(idx, raw_row):
            t = m.vars[i].type
            x = _decode(t, raw)
            run.v[i] = 0.0 if x != x else x
        run.v[m.g] = n * case.delta_t
        if run.step() != OK:
            raise AssertionError("the interpreter refused a step with increasing G")
        rows.append(dict(enumerate(run.v)))
    return rows


class RawBatch(Batch):
    """Machines driven by raw element values: per case a driver writes the
    inputs' bytes into the state vector, sets G, steps, and dumps the state
    vector, the machine's stored locals and T after every step."""

    kind = "raw"

    def add_machine(self, k: int, case, m: M.Machine) -> None:
        files = {}
        files.update(emit_sv(m.sv, f"fsw_r{k}"))
        files.update(emit_machine(m, self.real, ns=f"fsw_r{k}"))
        name = [n for n in files if n.endswith(".gen.h") and n != "sv.gen.h"][0][:-6]
        header = files[f"{name}.gen.h"]
        locs = {mm.group(1): int(mm.group(2)) for mm in re.finditer(r"^    L_(\w+) = (\d+),", header, re.M)}
        loc_size = int(re.search(r"kLocSize = (\d+)", header).group(1)) if locs else 0
        width = sum(m.var(n).type.size for n, _ in case.input_types)
        d = ['#include <stdio.h>', f'#include "{name}.gen.h"', '#include "sv.gen.h"', "",
             f"namespace fsw_r{k} {{", "int drive(FILE* in, FILE* out) {",
             f"    {name}::reset({case.init_state + 1});",
             f"    uint8_t buf[{max(width, 1)}];",
             f"    for (uint64_t n = 0; n < {len(case.steps)}; ++n) {{",
             f"        if (fread(buf, 1, {width}, in) != {width}) return 2;"]
        off = 0
        for nm, _ in case.input_types:
            size = m.var(nm).type.size
            d.append(f"        memcpy(sv + E_{nm}, buf + {off}, {size});")
            off += size
        d += [f"        fsw::store<uint64_t>(sv + E_{m.vars[m.g].name}, n * {case.delta_t}ULL);",
              f"        if ({name}::step() != fsw::kOk) return 1;",
              "        fwrite(sv, 1, kSvSize, out);"]
        if locs:
            d.append(f"        fwrite({name}::loc, 1, {name}::kLocSize, out);")
        d += [f"        const uint64_t t = fsw::machine_T({name}::machine);", "        fwrite(&t, 8, 1, out);", "    }",
              "    return 0;", "}", "}", ""]
        files["driver.cpp"] = "\n".join(d)
        self._add_files(k, files, "driver.cpp")
        self.items.append((k, (case, m, locs, loc_size)))

    def _main(self) -> str:
        keys = [k for k, _ in self.items]
        main = ["#include <stdio.h>", "#include <stdlib.h>", ""]
        main += [f"namespace fsw_r{k} {{ int drive(FILE* in, FILE* out); }}" for k in keys]
        main += ["", "typedef int (*Drive)(FILE*, FILE*);",
                 "static const Drive kDrive[] = {" + ", ".join(f"fsw_r{k}::drive" for k in keys) + "};",
                 "static const int kKey[] = {" + ", ".join(str(k) for k in keys) + "};",
                 f"static const int kCases = {len(keys)};", "",
                 "// driver DIR: case k reads DIR/<k>.in, writes DIR/<k>.rows; `<k> <status>` to DIR/status.",
                 "int main(int argc, char** argv) {",
                 "    if (argc < 2) return 2;",
                 "    char path[4096];",
                 "    snprintf(path, sizeof path, \"%s/status\", argv[1]);",
                 "    FILE* status = fopen(path, \"w\");",
                 "    if (status == 0) return 2;",
                 "    for (int i = 0; i < kCases; ++i) {",
                 "        snprintf(path, sizeof path, \"%s/%d.in\", argv[1], kKey[i]);",
                 "        FILE* in = fopen(path, \"rb\");",
                 "        snprintf(path, sizeof path, \"%s/%d.rows\", argv[1], kKey[i]);",
                 "        FILE* out = fopen(path, \"wb\");",
                 "        if (in == 0 || out == 0) return 2;",
                 "        const int rc = kDrive[i](in, out);",
                 "        fclose(in);",
                 "        fclose(out);",
                 "        fprintf(status, \"%d %d\\n\", kKey[i], rc);",
                 "        fflush(status);",
                 "    }",
                 "    fclose(status);",
                 "    return 0;",
                 "}", ""]
        return "\n".join(main)

    def run_raw(self) -> dict[int, object]:
        """Per case: a list of rows {var index: value} (the native side), or
        a string saying why there are none."""
        exe = self.build()
        out = os.path.join(self.dir, "run")
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        for k, (case, m, _, _) in self.items:
            with open(os.path.join(out, f"{k}.in"), "wb") as f:
                f.write(b"".join(b"".join(row) for row in case.steps))
        try:
            r = subprocess.run([exe, out], capture_output=True, text=True, timeout=self.timeout)
            died = f"status {r.returncode}: {r.stderr[-2000:]}" if r.returncode != 0 else None
        except subprocess.TimeoutExpired:
            died = f"timed out after {self.timeout} s"
        status = {}
        if os.path.exists(os.path.join(out, "status")):
            with open(os.path.join(out, "status")) as f:
                for line in f:
                    k, rc = line.split()
                    status[int(k)] = int(rc)
        results: dict[int, object] = {}
        for k, (case, m, locs, loc_size) in self.items:
            if status.get(k) != 0:
                results[k] = f"native driver: status {status.get(k)} ({died or 'refused a step'})"
                continue
            with open(os.path.join(out, f"{k}.rows"), "rb") as f:
                data = f.read()
            sv_size = max(m.sv.size, 1)
            width = sv_size + loc_size + 8
            rows = []
            for n in range(len(data) // width):
                row = data[n * width:(n + 1) * width]
                vals: dict[int, object] = {}
                for v in m.vars:
                    if v.kind == M.ELEMENT:
                        e = m.sv.find(v.name)
                        vals[v.index] = _decode(v.type, row[e.offset:e.offset + v.type.size])
                    elif v.kind == M.LOCAL and v.name in locs:
                        o = sv_size + locs[v.name]
                        vals[v.index] = _decode(v.type, row[o:o + v.type.size])
                    elif v.kind == M.TIME_IN_STATE:
                        vals[v.index] = int.from_bytes(row[width - 8:], "little")
                rows.append(vals)
            results[k] = rows
        return results


def raw_difference(case, m: M.Machine, interp_rows, native_rows) -> str | None:
    """Where the native machine parts from the interpreter: only what the
    machine writes is compared (S, T, writable elements, stored locals),
    not the inputs the harness wrote."""
    if isinstance(native_rows, str):
        return native_rows
    inputs = {m.var(n).index for n, _ in case.input_types} | {m.g}
    if len(native_rows) != len(interp_rows):
        return f"{len(native_rows)} native rows, {len(interp_rows)} steps"
    for n, (a, b) in enumerate(zip(interp_rows, native_rows), 1):
        diffs = [f"{m.vars[i].display}: interpreter {a[i]!r}, native {b[i]!r}"
                 for i in sorted(b) if i not in inputs and not _same(m.vars[i].type, a[i], b[i])]
        if diffs:
            return f"step {n}: " + "; ".join(diffs)
    return None


# ---- comparison ------------------------------------------------------------------------

def first_difference(a: Outcome, b: Outcome) -> str | None:
    """None when the two runs agree; else where they part, briefly."""
    if a.trace != b.trace:
        ra, rb = a.trace.splitlines(), b.trace.splitlines()
        head = ra[0].split(",") if ra else []
        for i, (x, y) in enumerate(zip(ra, rb)):
            if x != y:
                xa, ya = x.split(","), y.split(",")
                cols = [f"{head[j] if j < len(head) else j}: interpreter {xa[j] if j < len(xa) else '-'}, "
                        f"native {ya[j] if j < len(ya) else '-'}"
                        for j in range(max(len(xa), len(ya)))
                        if (xa[j] if j < len(xa) else None) != (ya[j] if j < len(ya) else None)]
                prev = ra[i - 1] if i > 1 else "(none)"
                return (f"traces differ at step {i} (previous row: {prev})\n  " + "\n  ".join(cols))
        return f"traces differ in length: interpreter {len(ra) - 1} steps, native {len(rb) - 1} steps"
    if a.code != b.code:
        return f"exit status: interpreter {a.code}, native {b.code}"
    if a.report != b.report:
        return f"reports differ:\n--- interpreter\n{a.report}--- native\n{b.report}"
    return None


def run_cases(cases: list[Case], modes: list[str], workdir: str, opt: str = "-O0", per_tu: int = 25,
              timeout: float = 300):
    """Every case in every mode through both paths. Yields (mode, case,
    interpreter outcome, native outcome or None)."""
    from fswkit.autocode.numeric import REALS

    loaded = [(c, *load(c)) for c in cases]
    with ThreadPoolExecutor(JOBS) as pool:
        batches = {}
        for mode in modes:
            b = Batch(workdir, REALS[mode], pool, per_tu=per_tu, opt=opt, timeout=timeout)
            for c, s, sl in loaded:
                b.add(c.index, s, sl)
            b._flush()
            batches[mode] = b
        interp = {}
        for mode in modes:  # while the compiler works
            for c, s, sl in loaded:
                interp[mode, c.index] = run_interpreter(s, REALS[mode], sl,
                                                        os.path.join(workdir, "trace.csv"))
        for mode in modes:
            nat = batches[mode].run()
            for c, _, _ in loaded:
                yield mode, c, interp[mode, c.index], nat.get(c.index)


def main(argv: list[str]) -> int:
    """python harness.py SEED N [f64|f32|both] [K...]: runs script cases
    (all N, or only cases K...) and prints every mismatch. With N written
    `raw:N` it runs raw-input machine cases instead. FSW_DIFF_CXX and
    FSW_DIFF_OPT pick the compiler and the optimisation level."""
    import gen_programs as gp
    from fswkit.autocode.numeric import REALS

    seed, raw, n = int(argv[0]), argv[1].startswith("raw:"), int(argv[1].split(":")[-1])
    modes = ["f64", "f32"] if len(argv) < 3 or argv[2] == "both" else [argv[2]]
    keys = [int(x) for x in argv[3:]] or list(range(n))
    opt = os.environ.get("FSW_DIFF_OPT", "-O0")
    work = scratch_dir("/tmp")
    bad = 0
    t0 = time.monotonic()
    try:
        if not raw:
            for mode, c, it, nat in run_cases([gp.case(seed, k) for k in keys], modes, work, opt=opt):
                d = first_difference(it, nat) if nat is not None else "no native result"
                if d:
                    bad += 1
                    print(f"== {mode} case {c.index}: {d}\n{c.repro()}")
        else:
            cs = [gp.machine_case(seed, k) for k in keys]
            ms = [load_machine(c) for c in cs]
            with ThreadPoolExecutor(JOBS) as pool:
                for mode in modes:
                    b = RawBatch(work, REALS[mode], pool, opt=opt)
                    for c, m in zip(cs, ms):
                        b.add_machine(c.index, c, m)
                    nat = b.run_raw()
                    for c, m in zip(cs, ms):
                        d = raw_difference(c, m, interpret_machine(c, m, REALS[mode]), nat[c.index])
                        if d:
                            bad += 1
                            print(f"== {mode} raw case {c.index}: {d}\n{c.repro()}")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"{len(keys)} {'raw ' if raw else ''}cases x {len(modes)} modes, {bad} mismatches, "
          f"{time.monotonic() - t0:.1f}s")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
