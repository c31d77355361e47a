"""`fsw tape import` of a log with a pressure no flight reads (a sensor's
glitch row, 1 Pa, or the Juno III RRC3 log's closing 191 hPa) wrote it
into the tape without a word, as docs/tapes.md says it converts such rows
as they are: the tape's truth then came out hundreds of metres off (now
refused by `fsw tape truth`). The row is still converted as it is, but
the import now says so, at the tape's line, and that the truth refuses
it; a log within the troposphere says nothing of it. (1 Pa, beyond any
barometer's range, is now refused at the log's cell:
test_tape_import_refuses_a_log_value_no_flight_records; the Juno III's
19,100 Pa is within it.)"""

from __future__ import annotations

from conftest import run_fsw

ALTOS = "#version,serial,flight,call,time,state,state_name,acceleration,pressure,altitude,height,speed\n"


def _import(tmp_path, glitch: str):
    rows = [(-0.2, "90000"), (-0.1, "90001"), (0.0, "89990"), (0.1, glitch), (0.2, "89800")]
    log = tmp_path / "log.csv"
    log.write_text(ALTOS + "".join(f"6,1,1,X,{t},2,pad,0.0{i},{p},1,1,1\n" for i, (t, p) in enumerate(rows)))
    out = tmp_path / "tape.csv"
    r = run_fsw("tape", "import", "altos", str(log), "-o", str(out))
    assert r.code == 0, r.err
    assert out.exists()
    return r, out


def test_a_glitch_pressure_is_said_at_its_tape_line(tmp_path):
    r, out = _import(tmp_path, "19100")
    line = next(i for i, x in enumerate(out.read_text().splitlines(), 1) if x.startswith("0.1,19100,"))
    assert (f"fsw tape import: {out}: 1 pressure beyond the ISA troposphere kept as the log has it "
            "(`fsw tape truth` refuses it):") in r.err, r.err
    assert f"fsw tape import: {out}:{line}: pressure_pa 19100 is " in r.err, r.err


def test_a_log_within_it_says_nothing_of_it(tmp_path):
    r, _ = _import(tmp_path, "89900")
    assert "troposphere" not in r.err, r.err
