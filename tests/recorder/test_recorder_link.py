"""`fsw dump` against the firmware: the tests/recorder/logged rig built for
`native` runs with its console on a pseudo-terminal and its EEPROM in a
file. Its pin 2 starts one-second "flights"; the ground dumps them as link
logs that `fsw log2csv` reads, each sample checking itself (the level is the
time / 4, the count goes up by one per step). The record survives restarts;
erasing asks first and is refused while the machine is in a state that
does not allow it."""

from __future__ import annotations

import csv
import io
import time
from pathlib import Path

import pytest

from conftest import run_fsw
from support.linkfw import PtyTarget, needs_cxx
from support.simfw import kept_native

pytestmark = [needs_cxx(), pytest.mark.costly(17, waits=True)]
RIG = Path(__file__).resolve().parent / "logged"


@pytest.fixture(scope="module")
def exe():
    return kept_native(RIG) / "logged"


def dump(port, out, *args):
    return run_fsw("dump", str(RIG), "--port", port, "-o", str(out), *args)


def rows(log: Path) -> list[dict]:
    r = run_fsw("log2csv", str(log))
    assert r.code == 0, r.err
    return list(csv.DictReader(io.StringIO(r.out)))


def check_flight(samples: list[dict]) -> None:
    """Every sample of a flight checks itself; samples are 20 ms apart."""
    assert samples
    times = [int(float(s["time_ms"])) if "time_ms" in s else None for s in samples]
    prev = None
    for s in samples:
        t = round(float(s["target time [s]"]) * 1000)  # the target's time, ms
        assert float(s["level"]) == pytest.approx(t / 4, abs=0.125)
        count = int(s["count"])
        if prev is not None and int(s["state"]) == 2:
            assert t - prev[0] == 20
            if prev[2] == 2:
                assert count == prev[1] + 2  # the machine counts every 10 ms step, the log takes every second
        prev = (t, count, int(s["state"]))
    assert times is not None


def test_a_flight_is_dumped_as_a_log_and_survives_a_restart(exe, tmp_path):
    eeprom = tmp_path / "eeprom.bin"
    out = tmp_path / "dump"
    with PtyTarget(exe, "--eeprom", str(eeprom), "d2=1") as t:
        time.sleep(1.6)  # Idle -> Run (the flight, 1 s) -> Done
        r = dump(t.port, out)
        assert r.code == 0, r.err
        assert "1 flight(s)" in r.out and "flight 1:" in r.out
    samples = rows(out / "flight-1.log")
    states = [int(s["state"]) for s in samples]
    assert states[0] == 1 and 2 in states  # the seconds before the trigger (Idle), then Run
    assert sum(st == 2 for st in states) >= 49  # 50 Hz for one second
    check_flight(samples)
    # a restart: the next flight is appended, numbered 2, and flight 1 is unchanged
    with PtyTarget(exe, "--eeprom", str(eeprom), "d2=1") as t:
        time.sleep(1.6)
        r = dump(t.port, out, "--all")
        assert r.code == 2 or r.code == 1, r.out  # flight-1.log exists: never overwritten without --force
        assert "exists" in r.err
        r = dump(t.port, out, "--all", "--force")
        assert r.code == 0, r.err
        assert "2 flight(s)" in r.out
    assert rows(out / "flight-1.log") == samples
    check_flight(rows(out / "flight-2.log"))


def test_erase_asks_first_and_only_in_the_allowed_states(exe, tmp_path):
    eeprom = tmp_path / "eeprom.bin"
    out = tmp_path / "dump"
    with PtyTarget(exe, "--eeprom", str(eeprom), "d2=1") as t:
        time.sleep(1.6)
        r = dump(t.port, out, "--erase")  # no terminal, no --yes: refused, nothing erased
        assert r.code != 0 and "--yes" in r.err
        r = dump(t.port, out, "--erase", "--yes", "--force")
        assert r.code == 0 and "erasing" in r.out, r.err
        time.sleep(0.3)
        r = dump(t.port, tmp_path / "again")
        assert r.code == 0 and "0 flight(s)" in r.out, r.out + r.err


def test_erase_is_refused_while_a_flight_is_recorded(exe, tmp_path):
    """The flight runs 1 s of the target's wall clock from its boot: on a
    loaded machine the dump's erase can come after it, in Done, where
    erasing is allowed. Such a run proves nothing either way; it is flown
    again (a new target, a new EEPROM), at most three times."""
    for attempt in range(3):
        with PtyTarget(exe, "--eeprom", str(tmp_path / f"e{attempt}.bin"), "d2=1") as t:
            time.sleep(0.3)  # in Run: recording
            started = time.monotonic()
            r = dump(t.port, tmp_path / f"d{attempt}", "--erase", "--yes")
        if "refused to erase" in r.err or "not erased: the target is recording" in r.err:  # its answer, or LOG_INFO's
            assert r.code != 0 and "Idle, Done" in r.err, r.out + r.err
            return
        assert time.monotonic() - started > 0.5, r.out + r.err  # erased only when the flight had ended first
    pytest.fail("the erase never reached the target within its flight: " + r.out + r.err)


def test_a_project_without_a_recorder_is_told_so(tmp_path):
    r = run_fsw("dump", str(Path(__file__).resolve().parents[1] / "param" / "tuned"), "--port", "/dev/null",
                "-o", str(tmp_path))
    assert r.code == 2 and "no flight recorder" in r.err


def test_fsw_plot_and_replay_read_a_dumped_flight(exe, tmp_path):
    out = tmp_path / "dump"
    with PtyTarget(exe, "--eeprom", str(tmp_path / "e.bin"), "d2=1") as t:
        time.sleep(1.6)
        assert dump(t.port, out).code == 0
    log = out / "flight-1.log"
    n = len(rows(log))
    r = run_fsw("plot", str(log), "-e", "level", "state", "-o", str(tmp_path / "f.png"))
    assert r.code == 0 and f"{2 * n} points" in r.err and (tmp_path / "f.png").stat().st_size > 1000, r.err
    r = run_fsw("replay", "--headless", "--speed", "1000", str(log))
    assert r.code == 0, r.err
    samples = [line for line in r.out.splitlines() if " sample Record " in line]
    assert len(samples) == n and "state=2 (Run)" in r.out


def test_fsw_sim_keeps_the_board_eeprom_in_a_file(tmp_path):
    """`fsw sim PROJECT --eeprom-file FILE`: the board alone keeps its EEPROM
    between runs (the harness's -E), so a record survives the simulator."""
    import subprocess
    import sys

    ee = tmp_path / "ee.bin"
    cmd = [sys.executable, "-m", "fswkit.cli", "sim", str(RIG), "--board", "uno", "--fast", "--duration", "0.5",
           "--eeprom-file", str(ee), "--out", str(tmp_path / "b")]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert ee.stat().st_size == 1024
    data = bytearray(ee.read_bytes())
    data[100] = 0x5A
    ee.write_bytes(bytes(data))
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert ee.read_bytes()[100] == 0x5A  # loaded at start, written back at the end
    r = run_fsw("sim", str(RIG), "--plant", "rocket", "--eeprom-file", str(ee))
    assert r.code == 2 and "--eeprom-file is for the free-running board" in r.err


def test_erase_needs_every_flight_dumped_first(exe, tmp_path):
    """--erase erases every flight: with two on the target, a dump of the
    newest alone does not erase them."""
    eeprom = tmp_path / "eeprom.bin"
    for _ in range(2):
        with PtyTarget(exe, "--eeprom", str(eeprom), "d2=1") as t:
            time.sleep(1.6)
    with PtyTarget(exe, "--eeprom", str(eeprom)) as t:
        time.sleep(0.3)
        r = dump(t.port, tmp_path / "newest", "--erase", "--yes")
        assert r.code == 1 and "flight(s) 1 were not dumped: add --all" in r.err, r.out + r.err
        r = dump(t.port, tmp_path / "all", "--all", "--erase", "--yes")
        assert r.code == 0 and "erasing" in r.out, r.err
        assert (tmp_path / "all" / "flight-1.log").exists() and (tmp_path / "all" / "flight-2.log").exists()


def test_a_flight_is_dumped_through_the_ground_station(exe, tmp_path, monkeypatch):
    """With `fsw ground` holding the port, `fsw dump` goes through it (its
    LOG_READ commands one at a time among the station's), the flight comes
    out whole, and the station archives the dump's commands as `fsw dump`'s."""
    import sqlite3

    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.ground.archive import Archive
    from fswkit.ground.station import Station
    from fswkit.link.layout import from_app
    from fswkit.target.build import load

    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))
    out = tmp_path / "dump"
    with PtyTarget(exe, "--eeprom", str(tmp_path / "eeprom.bin"), "d2=1") as t:
        st = Station(from_app(load(str(RIG), Diagnostics())), str(RIG), t.port, 115200,
                     archive=Archive(str(tmp_path / "a.sqlite")))
        st.start()
        try:
            time.sleep(1.6)
            r = dump(t.port, out)
            assert r.code == 0, r.err
            assert "1 flight(s)" in r.out
        finally:
            st.stop()
    check_flight(rows(out / "flight-1.log"))
    con = sqlite3.connect(tmp_path / "a.sqlite")
    reads = con.execute("SELECT count(*) FROM commands WHERE who LIKE 'fsw dump (pid%' AND status = 0").fetchone()[0]
    con.close()
    assert reads > 1
