"""`fsw sim --tape --perturb N` took Ctrl-C as Python's KeyboardInterrupt,
raised wherever the main thread happened to be; when that was inside
concurrent.futures.wait, between the locks of the futures it takes one by
one, a future's lock stayed held, the replay finishing it waited for it,
and so did the pool's join: once in a CI run the replays went on 60 s
after Ctrl-C and the command never ended
(test_perturbed_replays_stop_on_ctrl_c.py). Now, while the replays fly,
SIGINT, SIGTERM and SIGHUP only set the stop, which the loop sees within
STOP_POLL_S; the runs finished make the table, and the exit status names
the signal as before."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

from fswkit import outputs
from fswkit.plant import tape_replay as tr


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_a_signal_during_the_replays_only_sets_the_stop(monkeypatch, sig):
    handlers = []

    def fake_replay(i, seq, tape, truth, cfg, elf, board, layout, stop=None):
        if i == 0:
            return tr.PerturbResult(i, {"speed": 1.0}, [])
        if i == 1:
            handlers.append(signal.getsignal(sig))
            os.kill(os.getpid(), sig)  # the main thread takes it
        assert stop.wait(10), "the stop was never set"
        return tr.PerturbResult(i, {}, [], "stopped")

    monkeypatch.setattr(tr, "_one_perturbed", fake_replay)
    monkeypatch.setattr(outputs, "stopped_by", None)
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    t0 = time.monotonic()
    with pytest.raises(tr.StoppedRuns) as stopped:
        tr.robustness(None, None, None, None, None, None, 1000, 1, workers=2)
    assert time.monotonic() - t0 < 5
    # the handler in place while the replays flew sets a flag and raises nothing
    assert handlers and handlers[0] not in (signal.default_int_handler, signal.SIG_DFL, signal.SIG_IGN)
    handlers[0](sig, None)
    assert [r.index for r in stopped.value.results][:1] == [0]
    assert all(r.index < 2 or r.error for r in stopped.value.results)
    assert outputs.stopped_by == (None if sig == signal.SIGINT else sig)
    assert {s: signal.getsignal(s) for s in before} == before  # the handlers are given back
    assert threading.active_count() == 1 or all(not t.name.startswith("ThreadPoolExecutor")
                                                for t in threading.enumerate())
