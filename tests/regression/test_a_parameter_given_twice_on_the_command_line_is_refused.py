"""`fsw param set OPEN_AT=700 OPEN_AT=710` set 710 and said nothing of the
700, and `fsw test --param OPEN_AT=700 --param OPEN_AT=710` ran with 710:
of two values typed for one parameter, the last won without a word (a
parameter file's TOML refuses a key written twice). Now a name given twice
is refused, naming both values, before any port is opened or run begins."""

from __future__ import annotations

from pathlib import Path

from conftest import run_fsw

RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"


def test_fsw_param_set_refuses_a_name_given_twice(tmp_path):
    r = run_fsw("param", str(RIG), "set", "OPEN_AT=700", "TRIM=1", "OPEN_AT = 710", "--port", str(tmp_path / "none"))
    assert r.code == 2, r.out + r.err
    assert "`OPEN_AT` is given twice (700 and 710): give it once" in r.err, r.err


def test_fsw_test_refuses_a_param_given_twice():
    r = run_fsw("test", str(RIG / "vent.ss"), "--param", "OPEN_AT=700", "--param", "OPEN_AT=710")
    assert r.code == 2, r.out + r.err
    assert "`OPEN_AT` is given twice (700 and 710): give it once" in r.err, r.err


def test_one_value_each_still_runs():
    r = run_fsw("test", str(RIG / "vent.ss"), "--param", "OPEN_AT=700", "--param", "TRIM=1")
    assert "given twice" not in r.err, r.err
