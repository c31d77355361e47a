"""`fsw sim --plant/--tape/--run I --out DIR` wrote its set of files
(telemetry.log, flight.csv, flight.png, record.log, summary.txt) into
whatever folder it was given, replacing the user's own files of those
names there — a `flight.csv` of a real flight, the user's `summary.txt`, a
link log recorded from a real target under `telemetry.log` — and a run
stopped by Ctrl-C removed a folder of the user's named `incomplete` to put
its partial files there; `fsw sim --runs N --out DIR` replaced a
`study.csv` of the user's. Now such a folder is refused before any work,
naming what is there, unless an earlier run of `fsw sim` wrote it (its
`telemetry.log`, `study.txt`, `perturb.txt` or `incomplete/INCOMPLETE.txt`
says so); new, empty and earlier runs' folders are written as before. A
folder under one of the files' names, even in an earlier run's folder, made
the new set stop half moved in (its log and CSV beside no summary) while
the message said the folder still held the last finished run's; it is
refused before any work now."""

from __future__ import annotations

from conftest import EXAMPLES, run_fsw

from fswkit.plant.run import is_run_folder

TANK = EXAMPLES / "tank"
ROCKET = EXAMPLES / "rocket"


def _refused(r, out, names) -> None:
    assert r.code == 2, r.out + r.err
    assert (f"{out} holds files an earlier run of fsw sim did not write ({names}): a run replaces only its own "
            "files; name another --out, or move them away") in r.err, r.err
    assert "Traceback" not in r.err


def test_a_flight_keeps_the_users_files_and_folder(tmp_path):
    out = tmp_path / "mine"
    (out / "incomplete").mkdir(parents=True)
    (out / "incomplete" / "notes.txt").write_text("the pad crew's notes\n")
    (out / "flight.csv").write_text("time_s,altitude_m\n0,0\n")
    (out / "telemetry.log").write_bytes(b"FSWLOG1\n" + (9).to_bytes(4, "little") + b'{"a": 1}\n' + b"real bytes")
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    r = run_fsw("sim", str(TANK), "--plant", "tank", "--out", str(out))
    _refused(r, out, "telemetry.log, flight.csv, incomplete")
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before
    assert (out / "incomplete" / "notes.txt").read_text() == "the pad crew's notes\n"
    assert sorted(p.name for p in out.iterdir()) == ["flight.csv", "incomplete", "telemetry.log"]


def test_a_file_given_as_the_flight_folder_is_refused(tmp_path):
    f = tmp_path / "notes.txt"
    f.write_text("keep\n")
    r = run_fsw("sim", str(TANK), "--plant", "tank", "--out", str(f))
    assert r.code == 2 and "Traceback" not in r.err, r.err
    assert f.read_text() == "keep\n"


def test_a_study_keeps_the_users_table(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "study.csv").write_text("my own table\n")
    r = run_fsw("sim", str(ROCKET), "--plant", "rocket", "--runs", "2", "--out", str(out))
    _refused(r, out, "study.csv")
    assert (out / "study.csv").read_text() == "my own table\n"


def test_a_run_that_stopped_leaves_a_folder_the_next_run_takes(tmp_path):
    out = tmp_path / "flight"
    (out / "incomplete").mkdir(parents=True)
    (out / "incomplete" / "INCOMPLETE.txt").write_text("This run did not finish (interrupted (Ctrl-C)): ...\n")
    assert is_run_folder(str(out))
    (out / "incomplete" / "INCOMPLETE.txt").write_text("mine\n")
    assert not is_run_folder(str(out))


def test_a_new_folder_then_the_same_folder_again(tmp_path):
    out = tmp_path / "flight"
    for _ in range(2):  # the second run replaces the first's files: the folder is a run's
        r = run_fsw("sim", str(TANK), "--plant", "tank", "--out", str(out))
        assert r.code == 0, r.err
    assert (out / "summary.txt").is_file() and (out / "telemetry.log").is_file()


def test_a_folder_under_a_files_name_is_refused_before_any_work(tmp_path):
    out = tmp_path / "flight"
    out.mkdir()
    (out / "study.txt").write_text("dispersion study: an earlier run's\n")  # the folder is a run's
    (out / "flight.png").mkdir()
    (out / "flight.png" / "mine.txt").write_text("keep\n")
    r = run_fsw("sim", str(TANK), "--plant", "tank", "--out", str(out))
    assert r.code == 2, r.out + r.err
    assert (f"{out / 'flight.png'} is not a regular file: a run's flight.png replaces only a file; move it away, "
            "or name another --out") in r.err, r.err
    assert sorted(p.name for p in out.iterdir()) == ["flight.png", "study.txt"]
