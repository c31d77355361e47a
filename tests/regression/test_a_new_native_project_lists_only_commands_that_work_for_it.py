"""`fsw new NAME --board native` wrote the same README and platformio.ini
as for an Arduino: its "Every day" commands listed `fsw flash .` (which
refuses a native project, status 2: nothing to upload), `fsw monitor .` and
`fsw cmd ... --port PORT` (no serial port to read), said `fsw build .`
prints "flash and RAM against the board's budget" (a native build prints
neither), ended with "`fsw build .`, then `fsw flash .`", and its
platformio.ini's comment offered `pio run -t upload ... and flash it`. The
README's first paragraph also ran the board's title into its sentence
("firmware for the Native host build: the runtime on a PC ... (Uno pin
map). Nobody ..."). A native project's README now lists what works for a
program on this computer (check, test, the state script through the
generated C++, build, running the program on a simulated clock, building
for a board), each command of it runs as written, and its platformio.ini
offers no upload."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest

from conftest import run_fsw


def _every_day(readme: str) -> list[str]:
    """The commands of the README's "Every day" block, as written."""
    block = readme.split("## Every day", 1)[1].split("##", 1)[0]
    return [line.strip().split("  #", 1)[0].strip() for line in block.splitlines() if line.startswith("    ")]


def test_the_native_readme_and_platformio_ini_offer_no_upload(tmp_path):
    assert run_fsw("new", str(tmp_path / "rig"), "--board", "native").code == 0
    readme = (tmp_path / "rig" / "README.md").read_text()
    commands = _every_day(readme)
    assert commands, readme
    for command in commands:
        assert not command.startswith(("fsw flash", "fsw monitor", "fsw cmd")), (command, readme)
    assert "`fsw build .`, then `fsw flash .`" not in readme and "-t upload" not in readme
    assert "flash and RAM" not in readme
    assert "Native host build: the runtime on a PC" not in readme  # the title run into a sentence
    ini = (tmp_path / "rig" / "platformio.ini").read_text()
    assert "upload" not in ini and "and flash it" not in ini


@pytest.mark.skipif(shutil.which("g++") is None or shutil.which("avr-g++") is None,
                    reason="needs g++ and gcc-avr")
def test_every_command_of_the_native_readme_runs_as_written(tmp_path):
    assert run_fsw("new", "rig", "--board", "native", cwd=tmp_path).code == 0
    project = tmp_path / "rig"
    commands = _every_day((project / "README.md").read_text())
    ran = 0
    for command in commands:
        if command.startswith("fsw "):
            r = run_fsw(*command.split()[1:], cwd=project)
            assert r.code == 0, (command, r.err)
        else:  # the program itself
            p = subprocess.run(command, shell=True, cwd=project, capture_output=True, text=True, timeout=60)
            assert p.returncode == 0 and re.fullmatch(r"[0-9a-f]+\n", p.stdout), (command, p.stdout, p.stderr)
        ran += 1
    assert ran >= 5


def test_a_board_project_still_lists_flash_and_monitor(tmp_path):
    assert run_fsw("new", str(tmp_path / "rig"), "--board", "uno").code == 0
    commands = _every_day((tmp_path / "rig" / "README.md").read_text())
    assert "fsw flash ." in commands and "fsw monitor ." in commands
    assert "pio run -t upload" in (tmp_path / "rig" / "platformio.ini").read_text()
