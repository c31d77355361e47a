"""The link schema: computed by the one front end for both ends, covering
the layout and what flows over the link, and nothing else."""

from __future__ import annotations

import shutil

from conftest import run_fsw
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.schema import app_schema_hash, link_plan
from fswkit.target.build import load
from support.linkfw import TANK


def variant(tmp_path, name, old, new):
    d = tmp_path / name
    shutil.copytree(TANK, d, ignore=shutil.ignore_patterns("build"))
    text = (d / "tank.app").read_text()
    assert old in text
    (d / "tank.app").write_text(text.replace(old, new))
    return d


def schema_of(project) -> int:
    app = load(str(project), Diagnostics())
    assert app is not None
    return app_schema_hash(app)


def test_schema_covers_the_link_and_only_the_link(tmp_path):
    base = schema_of(TANK)
    same = variant(tmp_path, "comment", "# regions streamed to the ground", "# a different comment")
    assert schema_of(same) == base
    for name, old, new in [("rate", "Sensors    rate=50", "Sensors    rate=25"),
                           ("writable", "\nvalveOpen\n", "\n"),
                           ("tasks", "act      outputs       rate=100\n", "act      outputs       rate=50\n"),
                           ("order", "Sensors    rate=50\nEffectors  rate=10", "Effectors  rate=10\nSensors    rate=50")]:
        assert schema_of(variant(tmp_path, name, old, new)) != base, name


def test_generated_code_carries_the_same_schema(tmp_path):
    r = run_fsw("gen", str(TANK), "--out", str(tmp_path))
    assert r.code == 0
    app = load(str(TANK), Diagnostics())
    assert f"kLinkSchema = 0x{app_schema_hash(app):08x}UL" in (tmp_path / "app.gen.cpp").read_text()
    plan = link_plan(app)
    assert [(s.region.name, s.every, s.batch) for s in plan.streams] == [("Sensors", 2, 2), ("Effectors", 10, 1)]


def test_streams_the_link_cannot_carry_are_refused(tmp_path):
    slow = variant(tmp_path, "slow", "rate  100\n", "rate  100\nbaud  2400\n")
    r = run_fsw("gen", str(slow), "--out", str(tmp_path / "gen"))
    assert r.code == 2 and "the link carries" in r.err and "Traceback" not in r.err
    r = run_fsw("check", str(slow / "tank.app"))  # the checker refuses it: not only the generator
    assert r.code == 1 and "tank.app:24:1:" in r.err and "the link carries 240 B/s at 2400 baud" in r.err
