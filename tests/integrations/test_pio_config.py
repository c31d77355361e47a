"""platformio.ini as PlatformIO itself reads it (`pio project config`, which
needs no network): the environments, the hook, the runtime library, the
Unity suites on the host and on the simulated MCU, each environment's board
matching the kit's board definition."""

from __future__ import annotations

import json
import re
import tomllib

from conftest import ROOT, needs_pio, project_config


def board_toml(name: str) -> dict:
    with open(ROOT / "boards" / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


def make_suites(var: str) -> list[str]:
    text = (ROOT / "mk" / "firmware.mk").read_text()
    return re.search(rf"^{var}\s*:=\s*(.*)$", text, re.M).group(1).split()


@needs_pio
def test_platformio_ini_parses_with_the_environments_of_the_issue(tmp_path):
    cfg = project_config(ROOT, tmp_path)
    envs = sorted(s[4:] for s in cfg if s.startswith("env:"))
    assert envs == ["megaatmega2560", "nanoatmega328", "native", "uno"]
    pio = cfg["platformio"]
    assert pio["default_envs"] == ["uno"]
    assert pio["test_dir"] == str(ROOT / "tests" / "integrations" / "pio")
    for name in envs:
        env = cfg[f"env:{name}"]
        assert env["extra_scripts"] == ["pre:integrations/platformio/pio_hook.py"]
        assert env["custom_fsw_project"] == "examples/tank"
        assert env["lib_deps"] == ["fswkit=symlink://firmware"]
        assert env["test_framework"] == "unity"
        # The toolchain decides about DECIMAL_DIG (the hook), never the config.
        assert "DECIMAL_DIG" not in json.dumps(env)
    assert cfg["env:native"]["platform"] == "native"


@needs_pio
def test_each_board_environment_matches_the_kits_board_and_runs_its_suites_in_simavr(tmp_path):
    cfg = project_config(ROOT, tmp_path)
    host_only = sorted(set(make_suites("FW_SUITES")) - set(make_suites("FW_AVR_SUITES")))
    for name in ("uno", "nanoatmega328", "megaatmega2560"):
        env = cfg[f"env:{name}"]
        b = board_toml(env["custom_fsw_board"])
        assert env["platform"] == b["platformio"]["platform"] == "atmelavr"
        assert env["framework"] == ["arduino"]
        assert env["board"] == b["platformio"]["board"]
        cmd = env["test_testing_command"]
        assert cmd[:3] == ["timeout", "120", "simavr"]
        assert cmd[cmd.index("-m") + 1] == b["sim"]["simavr_mcu"]
        assert cmd[cmd.index("-f") + 1] == str(b["board"]["f_cpu"])
        assert cmd[-1] == str(ROOT / "build" / "pio" / "build" / name / "firmware.elf")
        assert env["test_ignore"] == ["test_" + s for s in host_only]


def test_pio_test_folders_are_the_runtime_suites():
    """tests/integrations/pio/test_X/ includes tests/firmware/test_X.cpp, one per suite."""
    pio_dir = ROOT / "tests" / "integrations" / "pio"
    folders = sorted(p.name for p in pio_dir.iterdir() if p.is_dir() and p.name.startswith("test_"))
    assert folders == sorted("test_" + s for s in make_suites("FW_SUITES"))
    for f in folders:
        text = (pio_dir / f / f"{f}.cpp").read_text()
        assert f'#include "../../../firmware/{f}.cpp"' in text
        assert (ROOT / "tests" / "firmware" / f"{f}.cpp").is_file()
    assert '#include "../../firmware/test_support.cpp"' in (pio_dir / "test_support.cpp").read_text()
    assert '#include "../../firmware/unity_config.h"' in (pio_dir / "unity_config.h").read_text()
