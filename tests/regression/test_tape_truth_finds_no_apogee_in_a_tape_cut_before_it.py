"""`fsw tape truth` of a tape that ends while the vehicle still climbs (a
log cut short, a recorder that lost power in boost) wrote the tape's last
smoothed altitude as the apogee: the shared Camoes flight cut at 15 s
(apogee at 24.31 s) gave `apogee_s = 14.75`, and a tape that never left
the pad gave `apogee_s = 0.0, apogee_m_agl = 0.0`; `fsw sim --tape` then
judged the firmware's drogue against them. An apogee is now the top of a
climb that the smoothed altitude comes down from, by the band's 5 m,
before the tape ends; without that descent the truth says there is no
apogee and why, and the command says `fsw sim --tape` needs it."""

from __future__ import annotations

import pytest

from conftest import SHARED, run_fsw

CAMOES = SHARED / "flights" / "camoes_cats.csv"


def _truth(tmp_path, text: str):
    p = tmp_path / "cut.csv"
    p.write_text(text)
    r = run_fsw("tape", "truth", str(p), "-o", "-")
    assert r.code == 0, r.err
    return r


@pytest.mark.skipif(not CAMOES.exists(), reason=f"{CAMOES} is not there")
def test_a_tape_cut_in_the_climb_has_no_apogee(tmp_path):
    lines = CAMOES.read_text().splitlines(keepends=True)
    keep = [x for x in lines if x.startswith(("#", "time_s")) or float(x.split(",")[0]) <= 15.0]
    r = _truth(tmp_path, "".join(keep))
    assert "apogee_s =" not in r.out and "apogee_m_agl =" not in r.out, r.out
    assert "# no apogee_s: the tape ends at 15.00 s within 5 m of its highest smoothed altitude" in r.out, r.out
    assert "the tape gives no apogee_s" in r.err, r.err


def test_a_tape_on_the_pad_has_no_apogee(tmp_path):
    rows = "".join(f"{i / 100 - 1:g},{100000 + (i % 3)},1\n" for i in range(300))
    r = _truth(tmp_path, "# fswkit sensor tape v1\ntime_s,pressure_pa,accel_g\n" + rows)
    assert "apogee_s =" not in r.out and "# no apogee_s:" in r.out, r.out


@pytest.mark.skipif(not CAMOES.exists(), reason=f"{CAMOES} is not there")
def test_a_tape_cut_after_the_apogee_keeps_it(tmp_path):
    lines = CAMOES.read_text().splitlines(keepends=True)
    keep = [x for x in lines if x.startswith(("#", "time_s")) or float(x.split(",")[0]) <= 30.0]
    r = _truth(tmp_path, "".join(keep))
    assert "apogee_s = 24.31" in r.out, r.out
