"""Progress on long work (fswkit.progress): drawn on standard error when it
is a terminal (a pseudo-terminal here), cleared when the work ends, by a
signal too; nothing at all when standard error is a pipe or progress is
turned off; bars of worker processes drawn by their parent."""

from __future__ import annotations

import fcntl
import os
import pty
import re
import signal
import struct
import subprocess
import sys
import termios
import textwrap
import threading
import time

import pytest

from conftest import ROOT

pytestmark = pytest.mark.costly(9, waits=True)

ERASE_LINE = b"\x1b[2K"

SCRIPT = textwrap.dedent("""
    import os, sys, time
    from fswkit.progress import progress

    def work(i):
        with progress(f"worker{i}", total=10.0, unit="s") as p:
            for k in range(11):
                p.update(float(k), failed=i)
                time.sleep(0.05)
        return i

    what = sys.argv[1]
    print("result on stdout", flush=True)
    if what == "plain":
        with progress("flight", total=30.0, unit="s") as p:
            for k in range(40):
                p.update(k * 0.5, state="Boost")
                time.sleep(0.01)
            time.sleep(0.4)
    elif what == "nested":
        with progress("outer", total=2, unit="runs") as p:
            with progress("inner", total=None) as q:
                q.update(5)
                time.sleep(0.4)
            p.update(1)
            time.sleep(0.3)
    elif what == "workers":
        import multiprocessing
        with progress("study", total=4, unit="runs") as p:
            with multiprocessing.get_context("fork").Pool(2) as pool:
                for n, _ in enumerate(pool.imap_unordered(work, range(4)), 1):
                    p.update(n, failed=0)
            time.sleep(0.3)
    elif what == "wait":
        try:
            with progress("flight", total=30.0, unit="s") as p:
                p.update(1.0)
                print("waiting", flush=True)
                time.sleep(30)
        except KeyboardInterrupt:
            sys.exit(130)
    print("done", flush=True)
""")


def _env(**extra) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("FSW_NO_PROGRESS", "CI", "FSW_PROGRESS_TO")}
    env["TERM"] = "xterm"
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "host-tools"), env.get("PYTHONPATH", "")])
    env.update(extra)
    return env


class OnPty:
    """The script run with its standard error on a pseudo-terminal (100
    columns) and its standard output on a pipe."""

    def __init__(self, what: str, **env):
        self.master, slave = pty.openpty()
        fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
        self.proc = subprocess.Popen([sys.executable, "-c", SCRIPT, what], stdout=subprocess.PIPE,
                                     stderr=slave, stdin=subprocess.DEVNULL, env=_env(**env))
        os.close(slave)
        self.screen = b""
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        while True:
            try:
                data = os.read(self.master, 65536)
            except OSError:
                return
            if not data:
                return
            self.screen += data

    def finish(self, timeout: float = 60) -> tuple[int, str]:
        out = self.proc.stdout.read().decode()
        code = self.proc.wait(timeout=timeout)
        self._reader.join(10)
        os.close(self.master)
        return code, out


def _cleared(screen: bytes) -> bool:
    """The display ends erased: after the last bar drawn, its lines erased
    and nothing drawn again."""
    last_bar = max(screen.rfind(b"\xe2\x94\x81"), screen.rfind(b"\xe2\x95\xb8"), screen.rfind(b"\xe2\x95\xba"))
    return last_bar >= 0 and ERASE_LINE in screen[last_bar:]


def _text(screen: bytes) -> str:
    return re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", screen.decode(errors="replace"))


def test_a_bar_is_drawn_on_a_terminal_and_cleared_at_the_end():
    run = OnPty("plain")
    code, out = run.finish()
    assert code == 0 and out == "result on stdout\ndone\n"  # standard output untouched
    text = _text(run.screen)
    assert "flight" in text and "/30.0 s" in text and "state=Boost" in text, text
    assert "ETA" in text
    assert _cleared(run.screen), run.screen[-300:]


def test_nested_bars_share_the_display():
    run = OnPty("nested")
    code, out = run.finish()
    assert code == 0 and out == "result on stdout\ndone\n"
    text = _text(run.screen)
    assert "outer" in text and "  inner" in text and "1/2 runs" in text, text
    assert _cleared(run.screen)


def test_bars_of_worker_processes_are_drawn_by_the_parent():
    run = OnPty("workers")
    code, out = run.finish()
    assert code == 0 and out == "result on stdout\ndone\n"
    text = _text(run.screen)
    assert "study" in text and "4/4 runs" in text, text  # the last update shown, however soon it came
    assert re.search(r"  worker[0-3] ", text), text  # a worker's bar, under the study's
    assert _cleared(run.screen)


@pytest.mark.parametrize("env", [{"FSW_NO_PROGRESS": "1"}, {"TERM": "dumb"}, {"CI": "true"}])
def test_turned_off_nothing_is_drawn(env):
    run = OnPty("plain", **env)
    code, out = run.finish()
    assert code == 0 and out == "result on stdout\ndone\n"
    assert run.screen == b""


def test_on_a_pipe_nothing_is_written():
    for what in ("plain", "workers"):
        r = subprocess.run([sys.executable, "-c", SCRIPT, what], capture_output=True, env=_env(), timeout=60)
        assert r.returncode == 0 and r.stdout == b"result on stdout\ndone\n" and r.stderr == b""


def _started(run: OnPty) -> None:
    line = run.proc.stdout.readline() + run.proc.stdout.readline()
    assert line == b"result on stdout\nwaiting\n", line
    deadline = time.monotonic() + 10
    while b"flight" not in run.screen and time.monotonic() < deadline:
        time.sleep(0.05)


def test_sigterm_clears_the_display_and_the_process_still_dies_by_it():
    run = OnPty("wait")
    _started(run)
    run.proc.send_signal(signal.SIGTERM)
    code, _ = run.finish()
    assert code == -signal.SIGTERM  # the status a SIGTERM gives, as without a bar
    assert _cleared(run.screen), run.screen[-300:]


def test_ctrl_c_clears_the_display():
    run = OnPty("wait")
    _started(run)
    run.proc.send_signal(signal.SIGINT)
    code, _ = run.finish()
    assert code == 130
    assert _cleared(run.screen), run.screen[-300:]


def test_a_bar_that_is_not_shown_costs_little_and_says_nothing(capsys):
    from fswkit.progress import progress

    with progress("quiet", total=3) as p:  # pytest's standard error is no terminal
        for k in range(100_000):
            p.update(k, n=k)
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err == ""
