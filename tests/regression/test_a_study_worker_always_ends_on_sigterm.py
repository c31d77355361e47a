"""Ctrl-C during a dispersion study hung `fsw sim --runs` for good, rarely
(once in CI): the pool ends its workers with one SIGTERM and waits
for them without a time limit, and a worker's SIGTERM handler raises
SystemExit. A SIGTERM that lands where Python only prints an exception
("Exception ignored in: ...": an at-fork hook, a __del__) left the worker
running, and the study waiting. The worker now also arms an alarm when
told to stop, whose default action ends it; and starting a simulated board
runs no Python in the forked child (the board's own process group keeps
the terminal's Ctrl-C from it, where a preexec_fn used to)."""

import multiprocessing
import os
import signal
import time

from fswkit.plant import study
from fswkit.sim import board


def _worker_in_a_swallowing_hook(ready) -> None:
    cpus = multiprocessing.get_context("fork").Queue()
    cpus.put(None)
    study._worker_init(cpus)
    study.TERM_GRACE_S = 1

    def slow_hook():
        ready.set()
        time.sleep(30)  # the SIGTERM arrives here; its SystemExit is printed, not raised

    os.register_at_fork(after_in_parent=slow_hook)
    if os.fork() == 0:
        os._exit(0)
    time.sleep(30)
    os._exit(0)  # reached only if the stop was lost


def test_a_worker_ends_even_when_its_sigterm_is_swallowed():
    ctx = multiprocessing.get_context("fork")
    ready = ctx.Event()
    p = ctx.Process(target=_worker_in_a_swallowing_hook, args=(ready,))
    p.start()
    try:
        assert ready.wait(20)
        t0 = time.monotonic()
        p.terminate()
        p.join(15)
        assert not p.is_alive(), "the worker outlived its SIGTERM"
        assert p.exitcode in (-signal.SIGALRM, 128 + signal.SIGTERM), p.exitcode
        assert time.monotonic() - t0 < 10
    finally:
        if p.is_alive():
            p.kill()
            p.join()


def test_starting_a_board_runs_no_python_in_the_child(monkeypatch):
    """Popen's preexec_fn runs Python (and every at-fork hook) in the
    worker between fork and exec; the board must start without one."""
    seen = {}
    real = board.subprocess.Popen

    class Spy(real):
        def __init__(self, args, **kwargs):
            if args[0] != "/bin/true":  # the board's other tools (the pin map's preprocessor) run as ever
                super().__init__(args, **kwargs)
                return
            seen.update(kwargs)
            raise OSError(2, "not started in this test")

    monkeypatch.setattr(board.subprocess, "Popen", Spy)
    monkeypatch.setattr(board, "check_elf", lambda elf, mcu: None)
    monkeypatch.setattr(board, "harness", lambda: "/bin/true")
    try:
        board.SimBoard(os.devnull)
    except board.SimError:
        pass
    assert seen, "SimBoard did not start its harness through subprocess.Popen"
    assert seen.get("preexec_fn") is None
    assert seen.get("process_group") == 0
