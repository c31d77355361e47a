"""An output folder that is a file, or lies under one (`--out notes.txt`,
`--out notes.txt/gen`, `--sketch notes.txt`): `fsw gen --out` and `fsw gen
--sketch` said the system's words, `cannot write notes.txt: File exists`
or `cannot write notes.txt/gen: Not a directory`, and `fsw sim --plant --out
notes.txt/flight` (and `fsw sim --tape`, the studies, `fsw dump -o`) said
`Not a directory` of the folder, and `fsw build --out notes.txt/gen` (and
`fsw sim`, `fsw flash`) said `notes.txt/gen is a file,
not a folder`, naming a path that does not exist. Every command now names
the file that is in the way and says it is a file, not a folder, exit 1,
the file untouched (`fsw sim`: 2, a bad option, as it was)."""

from __future__ import annotations

import re

import pytest

from conftest import EXAMPLES, run_fsw

CASES = {
    "gen --out FILE": ("gen", "{p}", "--out", "{f}"),
    "gen --out FILE/x": ("gen", "{p}", "--out", "{f}/gen"),
    "gen --sketch FILE": ("gen", "{p}", "--sketch", "{f}"),
    "gen --sketch FILE/x": ("gen", "{p}", "--sketch", "{f}/sk"),
    "build --out FILE/x": ("build", "{p}", "--out", "{f}/out"),
    "sim --out FILE/x": ("sim", "{p}", "--out", "{f}/out", "--duration", "1", "--fast"),
    "sim --plant --out FILE/x": ("sim", "{p}", "--plant", "tank", "--out", "{f}/flight"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_file_in_the_way_of_an_output_folder_is_named(tmp_path, case):
    notes = tmp_path / "notes.txt"
    notes.write_text("mine\n")
    argv = [a.format(p=EXAMPLES / "tank", f=notes) for a in CASES[case]]
    r = run_fsw(*argv)
    assert r.code == (2 if case.startswith("sim") else 1), r.err  # fsw sim: a bad option, as before
    assert f"{notes} is a file, not a folder" in r.err or f"cannot write {notes}: it is a file, not a folder" \
        in r.err, r.err
    assert "File exists" not in r.err and "Not a directory" not in r.err and "Traceback" not in r.err
    assert not re.search(re.escape(str(notes)) + r"/\w+ is a file", r.err)  # the file, not a path under it
    assert notes.read_text() == "mine\n"


@pytest.mark.parametrize("command", ["gen", "build"])
def test_a_link_to_nothing_in_the_way_is_said_to_be_one(tmp_path, command):
    (tmp_path / "gone").symlink_to(tmp_path / "nowhere")
    r = run_fsw(command, str(EXAMPLES / "tank"), "--out", str(tmp_path / "gone" / "out"))
    assert r.code == 1, r.err
    assert f"{tmp_path / 'gone'} is a symbolic link to nothing, not a folder" in r.err or \
        f"cannot write {tmp_path / 'gone'}: it is a symbolic link to nothing, not a folder" in r.err, r.err
    assert not (tmp_path / "nowhere").exists()
