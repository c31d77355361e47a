"""The ground station (`fsw ground`) owns a target's port and serves every
client at once: the terminal monitor and `fsw cmd` (separate processes,
through its local socket) and an in-process listener (the web page's
source) see the same frames, commands from all of them are acknowledged
once each, a second opener is told who holds the port, a client that
attaches late counts no frame lost that was never sent to it, and the
station comes back by itself after a board reset and a cable pull, saying
why. The target is the tank example built for the host, its console on a
pseudo-terminal the test keeps, behind a symbolic link (the board's
port, which a replug points at a new pty)."""

from __future__ import annotations

import os
import pty
import re
import subprocess
import sys
import threading
import time
import tty

import pytest

from support.linkfw import TANK, build_native, needs_cxx, tank_layout

pytestmark = [needs_cxx(), pytest.mark.costly(29, waits=True)]
FSW = os.path.join(os.path.dirname(sys.executable), "fsw")


@pytest.fixture(scope="module")
def exe():
    return build_native(TANK)


@pytest.fixture(autouse=True)
def runtime(tmp_path, monkeypatch):
    """Holder records and sockets of this test only."""
    monkeypatch.setenv("FSW_RUNTIME_DIR", str(tmp_path / "run"))


class Board:
    """The tank firmware on a pty whose master the test holds: a reset
    restarts the program on the same pty; a pull closes the pty (the port
    goes away) and a plug makes a new one behind the same link."""

    def __init__(self, exe, link: str, *args: str):
        self.exe, self.link, self.args = exe, link, args
        self.proc = None
        self.plug()

    def plug(self) -> None:
        self.master, slave = pty.openpty()
        tty.setraw(slave)
        name = os.ttyname(slave)
        os.close(slave)
        tmp = self.link + ".new"
        os.symlink(name, tmp)
        os.replace(tmp, self.link)
        self.start()

    def start(self) -> None:
        self.proc = subprocess.Popen([str(self.exe), *self.args], stdin=self.master, stdout=self.master,
                                     stderr=subprocess.DEVNULL)

    def stop(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(5)

    def reset(self) -> None:
        self.stop()
        self.start()

    def pull(self) -> None:
        # the device node goes, as a USB serial adapter's does (the pty's
        # number is soon another test's)
        os.unlink(self.link)
        self.stop()
        os.close(self.master)
        self.master = None

    def close(self) -> None:
        self.stop()
        if self.master is not None:
            os.close(self.master)


@pytest.fixture
def board(exe, tmp_path):
    b = Board(exe, str(tmp_path / "ttyBOARD"), "a14=770")
    yield b
    b.close()


class Recorder:
    """An in-process client: every decoded event of the station and its notes."""

    def __init__(self, station):
        self.events, self.notes = [], []
        self.lock = threading.Lock()
        station.listen(self.on_events)
        station.notes(lambda text, up: self.notes.append((text, up)))

    def on_events(self, evs):
        with self.lock:
            self.events += evs

    def seqs(self, kind=None):
        with self.lock:
            return [e.seq for e in self.events if kind is None or e.kind == kind]

    def wait_note(self, pattern: str, timeout: float = 10.0) -> str:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            for text, _ in list(self.notes):
                if re.search(pattern, text):
                    return text
            time.sleep(0.05)
        raise AssertionError(f"no note like {pattern!r}: {self.notes}")


@pytest.fixture
def station(board, tmp_path):
    from fswkit.ground.archive import Archive
    from fswkit.ground.station import Station

    st = Station(tank_layout(), str(TANK), board.link, 115200, archive=Archive(str(tmp_path / "ground.sqlite")))
    rec = Recorder(st)
    st.start()
    rec.wait_note("target up")
    yield st, rec
    st.stop()


def fsw(*args, timeout=60):
    return subprocess.run([FSW, *args], capture_output=True, text=True, timeout=timeout, env=os.environ)


def test_monitor_cmd_and_an_in_process_client_at_once(station, board):
    st, rec = station
    mon = subprocess.Popen([FSW, "monitor", str(TANK), "--port", board.link, "--headless", "--duration", "6"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(1.0)
    acks = []
    for i in range(8):  # commands from two kinds of client, one at a time on the wire
        r = fsw("cmd", "-p", str(TANK), "--port", board.link, "set", "valveOpen", "true" if i % 2 else "false")
        assert r.returncode == 0, r.stderr
        acks.append(int(re.search(r"command (\d+)", r.stdout).group(1)))
        acks.append(st.command("test", 0x01)["cmd_seq"])  # a ping from the in-process client
        time.sleep(0.3)
    out, err = mon.communicate(timeout=30)
    assert mon.returncode == 0, err
    assert "through the ground station" in err
    assert re.search(r"0 lost in 0 gaps", err), err
    seen = [int(m) for m in re.findall(r"^seq=(\d+)", out, re.M)]
    assert len(seen) > 100
    # every frame the station decoded between the monitor's first and last is one the monitor printed
    station_seqs = [s for s in rec.seqs() if seen[0] <= s <= seen[-1]]
    assert seen == station_seqs
    # each command was acknowledged once, and with its own number
    assert len(set(acks)) == len(acks)
    ack_events = [e.info["cmd_seq"] for e in rec.events if e.kind == "ack"]
    for a in acks:
        assert ack_events.count(a) == 1, (a, ack_events)
    # the archive has every frame and every command, with who sent it
    st.archive.tick(time.monotonic() + 1)
    import sqlite3

    con = sqlite3.connect(st.archive.path)
    archived = [s for (s,) in con.execute("SELECT seq FROM frames ORDER BY id")]
    assert archived[:len(rec.seqs())] == rec.seqs()[:len(archived)] and len(archived) >= len(seen)
    who = [w for (w,) in con.execute("SELECT who FROM commands WHERE status = 0")]
    assert sum(w.startswith("fsw cmd (pid") for w in who) == 8
    assert who.count("test") == 8
    con.close()


def test_a_second_opener_is_told_who_holds_the_port(station, board):
    r = fsw("ground", str(TANK), "--port", board.link, "--no-web", "--no-archive", timeout=30)
    assert r.returncode == 1
    assert f"busy: held by fsw ground, pid {os.getpid()}" in r.stderr, r.stderr
    assert "Traceback" not in r.stderr

    from fswkit.target.flash import FlashError, check_port

    with pytest.raises(FlashError, match=rf"busy: held by fsw ground, pid {os.getpid()}"):
        check_port(board.link, 115200)


def test_without_a_station_the_tools_hold_the_port_and_say_so(board):
    mon = subprocess.Popen([FSW, "monitor", str(TANK), "--port", board.link, "--headless", "--duration", "4"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 10
        while not mon.stdout.readline().startswith("seq=") and time.monotonic() < deadline:
            pass
        r = fsw("cmd", "-p", str(TANK), "--port", board.link, "ping")
        assert r.returncode == 1, r.stderr
        assert f"busy: held by fsw monitor, pid {mon.pid}" in r.stderr and "fsw ground" in r.stderr, r.stderr
    finally:
        out, err = mon.communicate(timeout=30)
    assert mon.returncode == 0 and "0 lost in 0 gaps" in err, err  # the refused command cost the monitor nothing


def test_a_client_attaching_late_counts_nothing_lost(station, board):
    from fswkit.ground.client import StationLink
    from fswkit.link.session import Session

    st, rec = station
    deadline = time.monotonic() + 20
    while st.session.stats.frames < 300 and time.monotonic() < deadline:  # past a wrap of the 8-bit number
        time.sleep(0.1)
    assert st.session.stats.frames >= 300
    session = Session(tank_layout())
    link = StationLink(st.socket_path, session, "late client")
    try:
        assert session.hello is not None and session.schema_ok  # the station's hello, adopted
        end = time.monotonic() + 2.5  # long enough for a health frame to renumber the frames
        while time.monotonic() < end:
            link.read(0.05)
    finally:
        link.close()
    assert session.stats.frames > 50
    assert session.seq_known
    assert session.stats.lost == 0 and session.stats.gaps == 0


def test_the_station_comes_back_after_a_reset_and_a_cable_pull(station, board):
    from fswkit.ground.client import StationLink
    from fswkit.link.session import Session

    st, rec = station
    session = Session(tank_layout())
    link = StationLink(st.socket_path, session, "watching client")
    try:
        board.reset()
        rec.wait_note(r"the target restarted: reset cause")
        board.pull()
        rec.wait_note(r"the port went away")
        time.sleep(0.6)  # a few tries at a port that is not there
        board.plug()
        rec.wait_note(r"reconnected")
        n = len(rec.seqs())
        rec.wait_note(r"target up|restarted")
        deadline = time.monotonic() + 5
        while len(rec.seqs()) < n + 20 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert len(rec.seqs()) >= n + 20, "no frames after the replug"
        # the client stayed attached through both, and heard why
        seen_before = session.stats.frames
        end = time.monotonic() + 1.0
        while time.monotonic() < end:
            link.read(0.05)
        assert session.stats.frames > seen_before
        assert st.reconnects == 1
        assert link.up and re.search("target up|restarted|reconnected", link.note), link.note
    finally:
        link.close()


def test_param_and_cmd_go_through_the_station_while_a_monitor_watches(tmp_path):
    """`fsw param` pipelines its own numbered commands: through the station
    it leases the uplink, and a monitor attached all along loses nothing."""
    from conftest import ROOT
    from fswkit.ground.station import Station
    from fswkit.link.layout import from_app
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import load

    from support.simfw import kept_native

    rig = ROOT / "tests" / "param" / "tuned"
    b = Board(kept_native(rig) / "tuned", str(tmp_path / "ttyRIG"), "--eeprom", str(tmp_path / "e.bin"))
    try:
        st = Station(from_app(load(str(rig), Diagnostics())), str(rig), b.link, 115200)
        rec = Recorder(st)
        st.start()
        try:
            rec.wait_note("target up")
            mon = subprocess.Popen([FSW, "monitor", str(rig), "--port", b.link, "--headless", "--duration", "4"],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            time.sleep(0.8)
            r = fsw("param", str(rig), "set", "OPEN_AT=860", "--port", b.link)
            assert r.returncode == 0, r.stderr
            r = fsw("param", str(rig), "get", "OPEN_AT", "--port", b.link)
            assert r.returncode == 0, r.stderr
            assert "860" in r.stdout
            r = fsw("cmd", "-p", str(rig), "--port", b.link, "ping")
            assert r.returncode == 0, r.stderr
            out, err = mon.communicate(timeout=30)
            assert mon.returncode == 0, err
            assert re.search(r"0 lost in 0 gaps", err), err
            assert st.command("test", 0x01)["status"] == 0  # the station numbers afresh after the lease
            # an acknowledgement's data (PARAM_INFO's: the store's state) reaches a client as bytes
            from fswkit.autocode.protocol import OP_PARAM_INFO
            from fswkit.ground.client import StationLink
            from fswkit.link.session import Session

            link = StationLink(st.socket_path, Session(st.layout), "a script")
            try:
                ack = link.command(OP_PARAM_INFO, text="param info")
            finally:
                link.close()
            assert ack["status"] == 0 and isinstance(ack["data"], bytes) and len(ack["data"]) > 0
        finally:
            st.stop()
    finally:
        b.close()
