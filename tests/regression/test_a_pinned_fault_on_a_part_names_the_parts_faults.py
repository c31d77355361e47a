"""`fsw sim --fault pinned-baro` on a project whose barometer is a digital
part said `its failures are barom-nack and barom-stuck`: the first five
letters of "barometer", fault names `--fault` refuses (they are
`baro-nack`, `baro-stuck`, `baro-noisy`; docs/sim.md, "Digital sensor
parts"). It now names the part's faults as `--fault` takes them, every
one of them."""

from __future__ import annotations

import re

import pytest

from conftest import EXAMPLES, run_fsw

from fswkit.plant.scenario import PART_FAULTS, parse_fault


@pytest.mark.parametrize("fault,role", [("pinned-baro", "baro"), ("pinned-accel", "accel")])
def test_the_faults_named_are_the_ones_fault_takes(tmp_path, fault, role):
    r = run_fsw("sim", str(EXAMPLES / "hpr_digital"), "--plant", "rocket", "--fault", fault,
                "--out", str(tmp_path / "f"))
    assert r.code == 2, r.err
    m = re.search(r"its failures are (.*)$", r.err, re.M)
    assert m, r.err
    named = re.findall(r"`?([a-z]+-[a-z]+)`?", m.group(1))
    assert sorted(named) == sorted(k for k in PART_FAULTS if k.startswith(role + "-")), r.err
    for name in named:
        assert parse_fault(name) == (name, None)
