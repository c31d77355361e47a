"""`fsw tape import` kept a log's data rows split into a str a cell: a
65 MB AltOS export took 1 GB of memory (about 15 times its size), and the
70 MB logs a long flight at a high rate writes took 1.8 GB. The rows are
now kept as their lines and split when read, and the file's bytes and text
are let go once split into lines: the same 65 MB export takes about 270 MB,
and the tape written is the same byte for byte.

Measured as the extra peak memory of an import of a 4 MB log over one of a
few rows, in processes of their own."""

from __future__ import annotations

import subprocess
import sys

from conftest import run_fsw

HEAD = ("# AltOS export written for this test\n#version,serial,flight,call,time,state,state_name,acceleration,"
        "pressure,altitude,height,speed,temperature,connected\n")


def _log(path, n: int) -> int:
    rows = [f"6, 4242, 7,N0CALL,{-1 + i * 0.01:9.2f}, 3,   boost,{(i % 7) * 0.5 - 1.5:8.2f},"
            f"{90000 - max(i - 100, 0) * 0.02:10.2f}, 1000.0,{i * 0.01:8.2f},  20.0, 20.0, 1" for i in range(n)]
    path.write_text(HEAD + "\n".join(rows) + "\n")
    return path.stat().st_size


def _peak_kb(log, out) -> int:
    code = ("import resource, sys\nfrom fswkit.cli.main import main\n"
            f"rc = main(['tape', 'import', 'altos', {str(log)!r}, '-o', {str(out)!r}])\n"
            "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)\nsys.exit(rc)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    return int(r.stdout.split()[-1])


def test_the_memory_an_import_takes_is_a_few_times_the_logs_size(tmp_path):
    _log(tmp_path / "s.csv", 300)
    small = _peak_kb(tmp_path / "s.csv", tmp_path / "s.tape.csv")
    size = _log(tmp_path / "big.csv", 44_000)
    assert size > 4_000_000
    big = _peak_kb(tmp_path / "big.csv", tmp_path / "big.tape.csv")
    extra = (big - small) * 1024
    assert extra < 6 * size, f"{extra / size:.1f} times the log's {size:,} B"
    r = run_fsw("tape", "show", str(tmp_path / "big.tape.csv"))
    assert r.code == 0 and "rows:    44,000," in r.out + r.err, r.out + r.err
