"""A log whose download was cut short ends inside a row: its last line has
no line end and fewer cells than the column line. Where the columns used
came before the cut, the row was read as whole, and the last cell it had
could be a number cut short: an Eggtimer log cut in `Alt` after `6` of
`60` gave a tape ending 54 ft lower than the flight, an RRC3 log cut in
`pressure` after `86` of `861.2` a row of 8,600 Pa -- exit 0. Such a last
line is now an error at its end, saying so."""

from __future__ import annotations

from conftest import run_fsw
from fswkit.tape.formats import convert

EGG = "T,Alt,Veloc,FAlt,FVeloc,FVeloc2,LDA,LowV,Apogee,N-O,Drogue,Main\n" + "".join(
    f"{i * 50},{i * 10},200,0,0,0,0,0,0,0,0,0\n" for i in range(5))
RRC3 = "time,altitude,pressure,velocity,temperature,events,voltages\n" + "".join(
    f"{i / 20:.2f},{max(0, i - 20) * 20},{861.7 - max(0, i - 20) * 0.7:.1f},0,20,-,3.8\n" for i in range(60))


def test_a_last_row_cut_short_is_refused_at_its_end(tmp_path):
    for fmt, text, cut, cells, of in (("eggtimer", EGG, "250,6", 2, 12), ("rrc3", RRC3, "3.00,800,86", 3, 7)):
        log = tmp_path / f"{fmt}.csv"
        log.write_text(text + cut)
        out = tmp_path / f"{fmt}-t.csv"
        r = run_fsw("tape", "import", fmt, str(log), "-o", str(out))
        assert r.code == 1 and not out.exists(), r.err
        line = text.count("\n") + 1
        assert r.err.startswith(f"fsw tape import: {log}:{line}:{len(cut) + 1}: the log ends inside a row: "), r.err
        assert f"{cells} cells of the column line's {of}" in r.err, r.err


def test_a_whole_last_row_without_a_line_end_is_read(tmp_path):
    log = tmp_path / "egg.csv"
    log.write_text(EGG.rstrip("\n"))
    assert convert("eggtimer", str(log)).rows == 5


def test_a_short_row_with_its_line_end_is_not_a_cut(tmp_path):
    # fewer cells than the column line, but ended: written so (the columns used are there)
    log = tmp_path / "egg.csv"
    log.write_text(EGG + "250,60\n")
    assert convert("eggtimer", str(log)).rows == 6
