"""The loaders run the garbage collector less often (fswkit.autocode.collect)
and give the caller its own thresholds back, whatever happens: nested,
after an error, across threads, and never lowered below what the caller
had set."""

from __future__ import annotations

import gc
import threading

import pytest

from conftest import EXAMPLES
from fswkit.autocode import collect
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.project import load_machine, load_script


@pytest.fixture
def thresholds():
    saved = gc.get_threshold()
    gc.set_threshold(700, 10, 10)
    yield
    gc.set_threshold(*saved)


def test_thresholds_raised_inside_and_restored_after(thresholds):
    with collect.fewer_collections():
        assert gc.get_threshold() == collect.THRESHOLDS
        with collect.fewer_collections():
            assert gc.get_threshold() == collect.THRESHOLDS
        assert gc.get_threshold() == collect.THRESHOLDS
    assert gc.get_threshold() == (700, 10, 10)


def test_restored_after_an_error(thresholds):
    with pytest.raises(ZeroDivisionError):
        with collect.fewer_collections():
            1 / 0
    assert gc.get_threshold() == (700, 10, 10)


def test_higher_thresholds_are_left_alone():
    saved = gc.get_threshold()
    gc.set_threshold(500_000, 20, 30)
    try:
        with collect.fewer_collections():
            assert gc.get_threshold() == (500_000, 20, 30)
        assert gc.get_threshold() == (500_000, 20, 30)
    finally:
        gc.set_threshold(*saved)


def test_restored_when_the_last_of_several_threads_leaves(thresholds):
    inside, leave = threading.Barrier(3), threading.Event()

    def reader():
        with collect.fewer_collections():
            inside.wait()
            leave.wait()

    threads = [threading.Thread(target=reader) for _ in range(2)]
    for t in threads:
        t.start()
    inside.wait()
    assert gc.get_threshold() == collect.THRESHOLDS
    leave.set()
    for t in threads:
        t.join()
    assert gc.get_threshold() == (700, 10, 10)


def test_loaders_give_the_same_results_and_the_thresholds_back(thresholds):
    ss = str(EXAMPLES / "hpr" / "mission_pad.ss")
    d = Diagnostics()
    script = load_script(ss, d)
    assert script is not None and not d.errors
    assert gc.get_threshold() == (700, 10, 10)
    gc.disable()
    try:
        d2 = Diagnostics()
        assert load_script(ss, d2) == script and not d2.errors
    finally:
        gc.enable()
    bad = Diagnostics()
    assert load_machine(str(EXAMPLES / "no-such" / "x.sm"), bad) is None and bad.errors
    assert gc.get_threshold() == (700, 10, 10)
