"""A parameter file's errors are located at `file:line:col` (docs/
parameters.md), but the reader found a key by a pattern of `NAME =` only:
a table (`[motor]`, `[[x]]`) or a dotted key (`motor.mass = 1`) was said
to be at 1:1, and a key also written inside a multi-line string above it
was located in the string. Now each is located where the file has it."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import run_fsw

RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


@pytest.mark.parametrize("text, words", [
    ("OPEN_AT = 650\n\n[motor]\nmass = 1\n", "3:1: `motor` is a table"),
    ("OPEN_AT = 650\n  motor.mass = 1\n", "2:3: `motor` is a table"),
    ("OPEN_AT = 650\n[[x]]\na = 1\n", "2:1: `x` is an array of tables"),
    ("OPEN_AT = 650\n[ \"motor\" . mass ]\n", "2:1: `motor` is a table"),
    ('note = """\nOPEN_AT = 1\n"""\nOPEN_AT = 5\n', "4:11: `OPEN_AT` = 5 is outside its range"),
    ("note = '''\nVENT = 1\n'''\nVENT = 1\n", "4:8: `VENT` is bool"),
])
def test_the_error_names_the_line_and_column_the_file_has(tmp_path, text, words):
    f = tmp_path / "p.toml"
    f.write_text(text)
    r = run_fsw("param", str(RIG), "diff", str(f), "--port", str(tmp_path / "no-port"))
    assert r.code == 2, r.out + r.err
    assert f"{f}:{words}" in r.err, r.err
