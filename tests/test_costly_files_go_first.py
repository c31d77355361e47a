"""The order make test hands test files to pytest-xdist's workers
(tests/conftest.py): files marked `costly(seconds)` first, the costliest
first, each file's tests together and in their order; the rest after, in
their collected order. And the suite's own costly marks are well formed."""

from __future__ import annotations

import ast
from pathlib import Path
from types import SimpleNamespace

import pytest

import conftest

TESTS = Path(__file__).resolve().parent


class Item:
    def __init__(self, path: str, name: str, cost: float | None, waits: bool = False):
        self.path = Path(path)
        self.name = name
        self._mark = None if cost is None else SimpleNamespace(args=(cost,), kwargs={"waits": True} if waits else {})

    def get_closest_marker(self, name: str):
        return self._mark if name == "costly" else None


def test_costly_files_first_costliest_first_the_rest_in_order():
    items = [Item("a.py", "a1", None), Item("b.py", "b1", 5), Item("c.py", "c1", 20), Item("a.py", "a2", None),
             Item("b.py", "b2", 5), Item("d.py", "d1", None), Item("c.py", "c2", 20), Item("e.py", "e1", 5)]
    conftest.pytest_collection_modifyitems(None, items)
    assert [i.name for i in items] == ["c1", "c2", "b1", "b2", "e1", "a1", "a2", "d1"]


def test_costly_files_that_wait_go_out_between_those_that_compute():
    items = [Item("w1.py", "w1a", 29, waits=True), Item("c1.py", "c1", 17), Item("w2.py", "w2", 17, waits=True),
             Item("w3.py", "w3", 14, waits=True), Item("w1.py", "w1b", 29, waits=True), Item("c2.py", "c2", 12),
             Item("r.py", "r", None), Item("c3.py", "c3", 11)]
    conftest.pytest_collection_modifyitems(None, items)
    assert [i.name for i in items] == ["c1", "w1a", "w1b", "c2", "w2", "c3", "w3", "r"]


def test_every_costly_mark_of_the_suite_gives_its_seconds():
    marked = 0
    for path in TESTS.rglob("test_*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "costly"
                    and isinstance(node.func.value, ast.Attribute) and node.func.value.attr == "mark"):
                marked += 1
                assert len(node.args) == 1 and isinstance(node.args[0], ast.Constant), f"{path}:{node.lineno}"
                assert isinstance(node.args[0].value, (int, float)) and node.args[0].value > 0, f"{path}:{node.lineno}"
                for kw in node.keywords:
                    assert kw.arg == "waits" and isinstance(kw.value, ast.Constant) and kw.value.value is True, \
                        f"{path}:{node.lineno}"
    assert marked >= 10


@pytest.mark.parametrize("path", ["examples/test_hpr_tapes_longest.py", "safety/test_digital_sensor_faults.py"])
def test_the_longest_files_are_marked(path):
    assert "pytest.mark.costly(" in (TESTS / path).read_text()
