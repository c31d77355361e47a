"""`fsw param` against the firmware: the tests/param/tuned rig built for
`native` runs with its console on a pseudo-terminal and its EEPROM in a
file, and the ground lists, sets, saves, loads and diffs its parameters.
Refusals say why (out of range, outside the allowed states, a file's
unknown name); values survive a restart only once saved; the machine sees
a new value at once."""

from __future__ import annotations

import subprocess
import time
from pathlib import Path

import pytest

from conftest import run_fsw
from support.linkfw import PtyTarget, needs_cxx
from support.simfw import kept_native

pytestmark = needs_cxx()
RIG = Path(__file__).resolve().parent / "tuned"


@pytest.fixture(scope="module")
def exe():
    return kept_native(RIG) / "tuned"


def param(port, *args):
    return run_fsw("param", str(RIG), *args, "--port", port)


def cmd(port, *args):
    r = run_fsw("cmd", *args, "-p", str(RIG), "--port", port)
    assert r.code == 0, r.err


def test_list_set_save_and_a_restart(exe, tmp_path):
    eeprom = tmp_path / "eeprom.bin"
    with PtyTarget(exe, "--eeprom", str(eeprom)) as t:
        time.sleep(0.2)
        r = param(t.port, "list")
        assert r.code == 0, r.err
        assert "(defaults; live CRC" in r.out
        assert "OPEN_AT" in r.out and "800" in r.out and "100..900" in r.out and "psi" in r.out
        r = param(t.port, "set", "OPEN_AT=650.5", "TRIM=-7")
        assert r.code == 0, r.err
        r = param(t.port, "get", "OPEN_AT", "TRIM", "HOLD_MS")
        assert r.out.splitlines() == ["OPEN_AT = 650.5", "TRIM = -7", "HOLD_MS = 500"]
        r = param(t.port, "list")
        assert "unsaved changes" in r.out
    # not saved: a restart boots the defaults
    with PtyTarget(exe, "--eeprom", str(eeprom)) as t:
        time.sleep(0.2)
        assert param(t.port, "get", "OPEN_AT").out.strip() == "OPEN_AT = 800"
        assert param(t.port, "set", "OPEN_AT=650.5").code == 0
        r = param(t.port, "save")
        assert r.code == 0 and "saved in bank A (sequence 1)" in r.out, r.out + r.err
    with PtyTarget(exe, "--eeprom", str(eeprom)) as t:
        time.sleep(0.2)
        r = param(t.port, "list")
        assert "(bank A, sequence 1;" in r.out and "unsaved" not in r.out
        assert param(t.port, "get", "OPEN_AT").out.strip() == "OPEN_AT = 650.5"
        r = param(t.port, "save")
        assert "saved in bank B (sequence 2)" in r.out


def test_refusals_say_why(exe, tmp_path):
    with PtyTarget(exe, "--eeprom", str(tmp_path / "e.bin")) as t:
        time.sleep(0.2)
        r = param(t.port, "set", "OPEN_AT=950")  # checked on the ground first
        assert r.code == 2 and "outside its range 100..900 psi" in r.err
        r = param(t.port, "set", "NOPE=1")
        assert r.code == 2 and "unknown parameter `NOPE`" in r.err
        r = param(t.port, "set", "VENT=maybe")
        assert r.code == 2 and "bool" in r.err
        cmd(t.port, "set", "arm", "true")  # Safe -> Armed
        time.sleep(0.1)
        r = param(t.port, "set", "HOLD_MS=700")
        assert r.code == 1
        assert "`HOLD_MS` may change only while machine `tuned` is in Safe (WRONG_STATE)" in r.err
        assert param(t.port, "set", "OPEN_AT=700").code == 0  # allowed in Armed
        # all or nothing: one refused value, none applied
        r = param(t.port, "set", "OPEN_AT=710", "HOLD_MS=700")
        assert r.code == 1
        assert param(t.port, "get", "OPEN_AT").out.strip() == "OPEN_AT = 700"


def test_the_machine_sees_a_new_value_at_once(exe, tmp_path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.client import Ground
    from fswkit.link.layout import from_app
    from fswkit.link.port import open_port
    from fswkit.link.session import Session
    from fswkit.target.build import load

    lay = from_app(load(str(RIG), Diagnostics()))
    with PtyTarget(exe, "--eeprom", str(tmp_path / "e.bin")) as t:
        time.sleep(0.2)
        cmd(t.port, "set", "pressure", "850")
        cmd(t.port, "set", "arm", "true")
        time.sleep(0.8)  # HOLD_MS = 500 in Armed: 850 - 3 > 800, the valve opens

        def valve():
            port = open_port(t.port, 115200)
            try:
                g = Ground(port, Session(lay))
                g.handshake()
                deadline = time.monotonic() + 2
                while time.monotonic() < deadline:
                    for ev in g.read():
                        if ev.kind == "sample":
                            return g.session.values["valve"]
                raise AssertionError("no sample")
            finally:
                port.close()

        assert valve() is True
        assert param(t.port, "set", "OPEN_AT=860").code == 0
        time.sleep(0.2)
        assert valve() is False  # 847 < 860


def test_load_applies_a_file_whole_and_diff_compares(exe, tmp_path):
    f = tmp_path / "field3.toml"
    f.write_text("# field 3\nOPEN_AT = 720.25\nHOLD_MS = 1500\nVENT = false\n")
    with PtyTarget(exe, "--eeprom", str(tmp_path / "e.bin")) as t:
        time.sleep(0.2)
        r = param(t.port, "load", str(f))
        assert r.code == 0, r.err
        assert "loaded 3 value(s)" in r.out and "verified (CRC 0x" in r.out and "bank A (sequence 1)" in r.out
        r = param(t.port, "diff", str(f))
        assert r.code == 0 and "0 of 3 differ" in r.out
        r = param(t.port, "diff")
        assert r.code == 1 and "OPEN_AT: target 720.25, the defaults 800" in r.out
        out = tmp_path / "read.toml"
        assert param(t.port, "list", "-o", str(out)).code == 0
        text = out.read_text()
        assert "OPEN_AT = 720.25" in text and "VENT = false" in text and "TRIM = -3" in text
        r = param(t.port, "list", "-o", str(out))  # never overwritten without --force
        assert r.code == 1 and "--force" in r.err
        # the file written is one `load` takes
        assert param(t.port, "load", str(out)).code == 0


@pytest.mark.parametrize("text, where, what", [
    ("OPEN_AT = 950\n", "1:11", "outside its range 100..900 psi"),
    ("\nNOPE = 3\n", "2:1", "unknown parameter `NOPE`"),
    ("HOLD_MS = 1.5\n", "1:11", "give a whole number"),
    ("VENT = 1\n", "1:8", "give true or false"),
    ("[rig]\nOPEN_AT = 1\n", "1:1", "is a table"),
    ("OPEN_AT = \n", "1:11", "not valid TOML"),
    ("TRIM = -51\n", "1:8", "outside its range -50..50"),
])
def test_a_bad_file_is_refused_with_its_place_before_the_port_opens(text, where, what, tmp_path):
    f = tmp_path / "bad.toml"
    f.write_text(text)
    r = param("/nonexistent/port", "load", str(f))
    assert r.code == 2, r.err
    assert f"{f}:{where}:" in r.err and what in r.err, r.err
    assert "Traceback" not in r.err


def test_a_script_runs_with_its_parameters_and_param_overrides_them():
    """vent.ss sets OPEN_AT = 600 and HOLD_MS = 100: the valve opens at
    610 psi after 100 ms in Armed. --param OPEN_AT=650 keeps it shut (the
    script's assertion fails), in the interpreter and natively alike."""
    script = str(RIG / "vent.ss")
    r = run_fsw("test", script)
    assert r.code == 0, r.out + r.err
    for native in ((), ("--native",)):
        r = run_fsw("test", script, "--param", "OPEN_AT=650", *native)
        assert r.code == 1 and "valve = false" in r.out, r.out + r.err
    r = run_fsw("test", script, "--param", "OPEN_AT=650", "--param", "TRIM=45")  # 610 + 45 > 650
    assert r.code == 0, r.out + r.err
    r = run_fsw("test", script, "--param", "OPEN_AT=5000")
    assert r.code == 2 and "outside its range 100..900 psi" in r.err
    r = run_fsw("test", script, "--param", "SPEED=3")
    assert r.code == 2 and "unknown parameter `SPEED`: machine `tuned`'s parameters are OPEN_AT" in r.err


def test_fsw_sim_flies_one_image_with_another_parameter_file(tmp_path):
    """--fw-params programs the file's values into the simulated board's
    EEPROM before boot: the rocket's main fires at the file's MAIN_ALT, and
    the flight's checks judge it against that altitude."""
    import shutil

    if shutil.which("avr-g++") is None:
        pytest.skip("gcc-avr is needed (make setup)")
    from conftest import EXAMPLES

    f = tmp_path / "field.toml"
    f.write_text("MAIN_ALT = 250\n")
    r = run_fsw("sim", str(EXAMPLES / "rocket"), "--plant", "rocket", "--seed", "1", "--fw-params", str(f),
                "--out", str(tmp_path / "flight"))
    assert r.code == 0, r.out + r.err
    assert "main fired within ±15 m of MAIN_ALT = 250 m" in r.out, r.out
    f.write_text("MAIN_ALT = 5\n")
    r = run_fsw("sim", str(EXAMPLES / "rocket"), "--plant", "rocket", "--fw-params", str(f),
                "--out", str(tmp_path / "flight2"))
    assert r.code == 2 and f"{f}:1:12: `MAIN_ALT` = 5 is outside its range 30..3000 m" in r.err, r.err


def test_fsw_sim_params_takes_a_parameter_file_too(tmp_path):
    """`--params FILE` with only top-level NAME = value lines is the
    firmware's parameters; a file with tables stays the plant's config."""
    import shutil

    if shutil.which("avr-g++") is None:
        pytest.skip("gcc-avr is needed (make setup)")
    from conftest import EXAMPLES

    f = tmp_path / "field.toml"
    f.write_text("MAIN_ALT = 5\n")
    r = run_fsw("sim", str(EXAMPLES / "rocket"), "--plant", "rocket", "--params", str(f),
                "--out", str(tmp_path / "flight"))
    assert r.code == 2 and "`MAIN_ALT` = 5 is outside its range 30..3000 m" in r.err, r.err
    r = run_fsw("sim", str(EXAMPLES / "rocket"), "--plant", "rocket", "--params", str(f), "--fw-params", str(f))
    assert r.code == 2 and "give one" in r.err
    # a plant file whose tables all come from the file it extends is still a plant file: it was read as
    # the firmware's parameters ("unknown parameter 'extends'"), and a study refused it for a --fw-params
    p = tmp_path / "faster.toml"
    p.write_text(f'extends = "{EXAMPLES / "rocket" / "plant.toml"}"\nrate_hz = 3000\n')
    r = run_fsw("sim", str(EXAMPLES / "rocket"), "--plant", "rocket", "--params", str(p),
                "--out", str(tmp_path / "flight"))
    assert r.code == 2 and "rate_hz" in r.err and "parameter" not in r.err, r.err
    r = run_fsw("sim", str(EXAMPLES / "rocket"), "--plant", "rocket", "--params", str(p), "--runs", "2")
    assert r.code == 2 and "rate_hz" in r.err and "--fw-params" not in r.err, r.err
