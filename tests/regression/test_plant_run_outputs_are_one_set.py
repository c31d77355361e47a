"""A closed-loop run's files (log, CSV, plot, summary) are one set: a run
that does not finish — Ctrl-C, a failure mid-flight — leaves the previous
run's set exactly as it was and its own partial files apart, in
`OUT/incomplete/` with a note; never a new partial log beside an old
summary claiming its checks passed."""

from __future__ import annotations

import os

import pytest
from conftest import EXAMPLES

import fswkit.plant.run as plant_run
from fswkit.link.log import RX, LogWriter
from fswkit.plant.cosim import CosimError
from fswkit.plant.run import FILES, INCOMPLETE, execute, prepare

OLD = {"log": b"FSWLOG1\nthe previous flight", "csv": b"time_s\n0\n", "png": b"\x89PNG old",
       "record": b"FSWLOG1\nthe previous flight's record", "summary": b"7 of 7 checks passed\n"}


@pytest.fixture(scope="module")
def scenario():
    _app, layout, sc = prepare(str(EXAMPLES / "rocket"), "rocket", seed=1)
    return layout, sc


def _previous_run(out):
    out.mkdir()
    for k, data in OLD.items():
        (out / FILES[k]).write_bytes(data)


def _flight_stopped_by(exc):
    def fly(sc, elf, board, layout, log_path, log_meta=None, **kw):
        log = LogWriter(log_path, layout, **(log_meta or {}))
        log.commit()
        log.record(RX, 1, b"\0partial flight\0")  # the flight had begun
        log.close()
        raise exc
    return fly


@pytest.mark.parametrize("exc", [KeyboardInterrupt(), CosimError("the firmware crashed at 3.2 s simulated")],
                         ids=["ctrl-c", "failure"])
def test_an_unfinished_run_leaves_the_previous_set(scenario, tmp_path, monkeypatch, exc):
    layout, sc = scenario
    out = tmp_path / "rocket-flight"
    _previous_run(out)
    monkeypatch.setattr(plant_run, "fly", _flight_stopped_by(exc))
    with pytest.raises(type(exc)):
        execute(sc, "unused.elf", None, layout, str(out))
    for k, data in OLD.items():  # the previous set, whole and alone
        assert (out / FILES[k]).read_bytes() == data, k
    assert sorted(os.listdir(out)) == sorted(list(FILES.values()) + [INCOMPLETE])
    part = out / INCOMPLETE
    assert (part / FILES["log"]).read_bytes().endswith(b"partial flight\0")
    assert not (part / FILES["summary"]).exists()
    assert "did not finish" in (part / "INCOMPLETE.txt").read_text()


def test_a_first_run_that_does_not_finish_leaves_no_summary(scenario, tmp_path, monkeypatch):
    layout, sc = scenario
    out = tmp_path / "rocket-flight"
    monkeypatch.setattr(plant_run, "fly", _flight_stopped_by(KeyboardInterrupt()))
    with pytest.raises(KeyboardInterrupt):
        execute(sc, "unused.elf", None, layout, str(out))
    assert os.listdir(out) == [INCOMPLETE]


@pytest.mark.parametrize("signame", ["SIGTERM", "SIGHUP"])
def test_a_run_stopped_by_a_signal_leaves_the_previous_set(scenario, tmp_path, monkeypatch, signame):
    # `kill`, a closed terminal, a CI job cancelled: the run ends as by Ctrl-C, not on the spot
    # with its files in a hidden folder
    import signal

    sig = getattr(signal, signame)
    layout, sc = scenario
    out = tmp_path / "rocket-flight"
    _previous_run(out)

    def fly(sc, elf, board, layout, log_path, log_meta=None, **kw):
        log = LogWriter(log_path, layout, **(log_meta or {}))
        log.commit()
        log.record(RX, 1, b"\0partial flight\0")
        log.close()
        assert signal.getsignal(sig) not in (signal.SIG_DFL, signal.SIG_IGN, None), "the signal would kill the run"
        signal.raise_signal(sig)
        raise AssertionError("the signal did not stop the run")

    monkeypatch.setattr(plant_run, "fly", fly)
    before = signal.getsignal(sig)
    with pytest.raises(KeyboardInterrupt, match=signame):
        execute(sc, "unused.elf", None, layout, str(out))
    assert signal.getsignal(sig) == before
    for k, data in OLD.items():
        assert (out / FILES[k]).read_bytes() == data, k
    assert sorted(os.listdir(out)) == sorted(list(FILES.values()) + [INCOMPLETE])
    assert f"stopped by {signame}" in (out / INCOMPLETE / "INCOMPLETE.txt").read_text()
