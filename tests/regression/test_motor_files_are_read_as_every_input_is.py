"""A RASP motor file (`[motor] file` in plant.toml) was read with a plain
open(): a FIFO named as one hung `fsw sim --plant rocket` forever, a
device such as /dev/zero was read until memory ran out, and a file of any
size was read whole. A file saved with a UTF-8 byte-order mark (Windows
editors write one) was refused when it began with a comment ("a motor's
header has 7 fields ... this one has 1" at 1:2) and otherwise flew a motor
whose name began with the invisible mark.

Now a motor file is read as every other input of the tools is
(fswkit.autocode.diagnostics.read_input): what is not a regular file is
refused without being read, as is a file over MAX_INPUT bytes, each a
located error under the plant.toml line that names it and exit status 2,
before anything is built; and a byte-order mark is not part of the text."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import EXAMPLES

from fswkit.autocode.diagnostics import MAX_INPUT
from fswkit.plant.motor import EngError, load

ROCKET = EXAMPLES / "rocket"
FSW = str(Path(sys.executable).parent / "fsw")
G80T = (ROCKET / "motors" / "G80T.eng").read_text()


def _plant(tmp_path: Path, motor: str) -> Path:
    text = (ROCKET / "plant.toml").read_text()
    start, end = text.index("[motor]"), text.index("[drogue]")
    p = tmp_path / "plant.toml"
    p.write_text(text[:start] + f'[motor]\nfile = "{motor}"\n\n' + text[end:])
    return p


def _sim(tmp_path: Path, plant: Path) -> subprocess.CompletedProcess:
    # A child process, so that a reader that blocks fails the test rather than hangs it.
    return subprocess.run([FSW, "sim", str(ROCKET), "--plant", "rocket", "--params", str(plant),
                           "--out", str(tmp_path / "out")], capture_output=True, text=True, timeout=60)


def test_a_fifo_motor_file_is_refused_at_once(tmp_path: Path):
    os.mkfifo(tmp_path / "m.eng")
    r = _sim(tmp_path, _plant(tmp_path, "m.eng"))
    assert r.returncode == 2, r.stderr
    assert "[motor] file: the motor file" in r.stderr
    assert f"{tmp_path / 'm.eng'}: not a regular file (a FIFO)" in r.stderr
    assert "Traceback" not in r.stderr and not (tmp_path / "out" / "flight.csv").exists()


def test_a_device_motor_file_is_refused(tmp_path: Path):
    (tmp_path / "m.eng").symlink_to("/dev/zero")
    r = _sim(tmp_path, _plant(tmp_path, "m.eng"))
    assert r.returncode == 2, r.stderr
    assert f"{tmp_path / 'm.eng'}: not a regular file (a device)" in r.stderr


def test_a_huge_motor_file_is_refused_unread(tmp_path: Path):
    big = tmp_path / "big.eng"
    big.write_text(G80T + ("; padding\n" * (MAX_INPUT // 10 + 1)))
    assert big.stat().st_size > MAX_INPUT
    with pytest.raises(EngError) as e:
        load(str(big))
    assert e.value.errors == [f"{big}: file too large: {big.stat().st_size:,} bytes, over the {MAX_INPUT:,} "
                              "the tools read from one file"]


def test_a_folder_is_still_said_to_be_one(tmp_path: Path):
    with pytest.raises(EngError, match="a folder, not a motor file"):
        load(str(tmp_path))


@pytest.mark.parametrize("text", [G80T, G80T[G80T.index("G80T "):]])  # a comment first, the header first
def test_a_byte_order_mark_is_not_part_of_the_file(tmp_path: Path, text: str):
    f = tmp_path / "bom.eng"
    f.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    (m,) = load(str(f))
    assert m.name == "G80T"
    assert m.total_impulse == pytest.approx(118.6, abs=0.1)
