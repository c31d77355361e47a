"""Nothing a user wrote or recorded is replaced by a ground command without
being asked, and nothing recorded even then:

- `fsw log2csv -o` and `fsw plot -o` replaced any file of that name (a
  user's own CSV) without a word; now, as `fsw archive export`, only with
  `--force`;
- `--force` of `fsw archive export`, `fsw param list -o`, `fsw tape
  import` and `fsw monitor --log` let the command replace a recording (an archive of every session
  of a station, or a link log): now only a link log is ever replaced, by a
  new link log (`fsw monitor --log --force`, `fsw dump --force`);
- `fsw param list -o --force` guarded the `.app` alone: it wrote over the
  project's machine, and into the serial port it talked through;
- `fsw dump` checked no flight log against the project's configs (a
  `flight-N.log` that is a link to one was replaced), took any `--flight`
  number, refused only once the record had been read, and said a folder
  it could not create was "the port went away".

Each refusal that needs nothing from the target comes before the port is
opened."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest
from conftest import run_fsw
from support.linkfw import PtyTarget, needs_cxx
from support.linkstream import TANK, write_log

from fswkit.ground.archive import Archive

RIG = Path(__file__).resolve().parent.parent / "param" / "tuned"
LOGGED = Path(__file__).resolve().parent.parent / "recorder" / "logged"
NO_PORT = "/dev/no-such-port"


def _no_parts(folder):
    assert not [p.name for p in folder.iterdir() if p.name.endswith(".part")]


@pytest.fixture
def log(tmp_path):
    return write_log(tmp_path / "x.log", 200)


@pytest.mark.parametrize("command", ["log2csv", "plot"])
def test_a_users_file_is_replaced_only_with_force(tmp_path, log, command):
    mine = tmp_path / ("mine.csv" if command == "log2csv" else "mine.png")
    mine.write_text("my own notes\n")
    argv = [command, str(log), "-o", str(mine)] + (["-e", "tankPressure"] if command == "plot" else [])
    r = run_fsw(*argv)
    assert r.code == 1 and f"{mine} exists: it is replaced only when asked (--force)" in r.err, r.err
    assert mine.read_text() == "my own notes\n"
    r = run_fsw(*argv, "--force")
    assert r.code == 0, r.err
    assert mine.read_bytes() != b"my own notes\n"
    _no_parts(tmp_path)


def _recordings(tmp_path, stem: str):
    """A link log and an archive, each named `stem` + an extension the command writes."""
    other = write_log(tmp_path / f"{stem}-log.csv", 50, first=77)
    arch = tmp_path / f"{stem}-archive.csv"
    Archive(str(arch)).close()
    return [other, arch]


def test_export_force_never_replaces_a_recording(tmp_path, log):
    src = tmp_path / "ground.sqlite"
    Archive(str(src)).close()
    for rec in _recordings(tmp_path, "out"):
        before = rec.read_bytes()
        r = run_fsw("archive", "export", str(src), "-o", str(rec), "--force")
        assert r.code == 1 and "(a recording) is there: it is never overwritten" in r.err, r.err
        assert rec.read_bytes() == before


def test_tape_import_force_never_replaces_a_recording(tmp_path):
    # the same `--force` of outputs.check: `fsw tape import -o` replaced a link log named TAPE.csv
    src = tmp_path / "altimeter.csv"
    src.write_text("time,pressure\n0,101325\n")
    for rec in _recordings(tmp_path, "tape"):
        before = rec.read_bytes()
        r = run_fsw("tape", "import", "cats", str(src), "-o", str(rec), "--force")
        assert r.code == 1 and "(a recording) is there: it is never overwritten" in r.err, r.err
        assert rec.read_bytes() == before


def test_monitor_log_force_never_replaces_an_archive(tmp_path):
    arch = tmp_path / "ground.sqlite"
    Archive(str(arch)).close()
    before = arch.read_bytes()
    r = run_fsw("monitor", str(TANK), "--port", NO_PORT, "--log", str(arch), "--force", "--headless")
    assert r.code == 1 and "a ground station archive (a recording) is there" in r.err, r.err
    assert arch.read_bytes() == before


def test_param_list_output_is_never_a_config_the_port_or_a_recording(tmp_path):
    import pty

    project = tmp_path / "tuned"
    project.mkdir()
    for f in RIG.iterdir():
        (project / f.name).write_bytes(f.read_bytes())
    for name in ("tuned.sm", "tuned.sv", "tuned.app"):
        before = (project / name).read_bytes()
        for force in ((), ("--force",)):  # said as what it is, --force or not
            r = run_fsw("param", str(project), "list", "-o", str(project / name), *force, "--port", NO_PORT)
            assert r.code == 1 and "would overwrite an input of this command" in r.err, r.err
        assert (project / name).read_bytes() == before
    r = run_fsw("param", str(project), "list", "-o", str(tmp_path), "--port", NO_PORT)
    assert r.code == 1 and "it is a folder" in r.err, r.err
    for rec in _recordings(tmp_path, "params"):
        before = rec.read_bytes()
        r = run_fsw("param", str(project), "list", "-o", str(rec), "--force", "--port", NO_PORT)
        assert r.code == 1 and "(a recording) is there: it is never overwritten" in r.err, r.err
        assert rec.read_bytes() == before
    master, slave = pty.openpty()
    try:
        port = os.ttyname(slave)
        t0 = time.monotonic()
        r = run_fsw("param", str(project), "list", "-o", port, "--force", "--port", port)
        assert r.code == 1 and "would overwrite an input of this command" in r.err, r.err
        assert time.monotonic() - t0 < 2  # refused at once, not after waiting for the target's hello
    finally:
        os.close(master)
        os.close(slave)


@pytest.mark.parametrize("flight", ["0", "-1", "256", "x"])
def test_dump_flight_numbers_are_checked_first(tmp_path, flight):
    r = run_fsw("dump", str(LOGGED), "--port", NO_PORT, "-o", str(tmp_path), "--flight", flight)
    assert r.code == 2 and "--flight" in r.err, r.err


@needs_cxx()
def test_dump_never_replaces_a_config_or_an_archive(tmp_path):
    from support.simfw import kept_native

    exe = kept_native(LOGGED) / "logged"
    project = tmp_path / "logged"
    project.mkdir()
    for f in LOGGED.iterdir():
        (project / f.name).write_bytes(f.read_bytes())
    out = tmp_path / "dump"
    out.mkdir()
    sm = project / "logged.sm"
    before = sm.read_bytes()
    with PtyTarget(exe, "--eeprom", str(tmp_path / "e.bin"), "d2=1") as t:
        time.sleep(1.6)  # Idle -> Run (the flight, 1 s) -> Done
        (out / "flight-1.log").symlink_to(sm)
        r = run_fsw("dump", str(project), "--port", t.port, "-o", str(out), "--force")
        assert r.code == 1 and "would overwrite an input of this command" in r.err, r.err
        assert sm.read_bytes() == before
        (out / "flight-1.log").unlink()
        Archive(str(out / "flight-1.log")).close()
        kept = (out / "flight-1.log").read_bytes()
        r = run_fsw("dump", str(project), "--port", t.port, "-o", str(out), "--force")
        assert r.code == 1 and "a ground station archive (a recording) is there" in r.err, r.err
        assert (out / "flight-1.log").read_bytes() == kept
        (out / "flight-1.log").unlink()
        r = run_fsw("dump", str(project), "--port", t.port, "-o", str(project / "logged.sm" / "sub"))
        assert r.code == 1 and "cannot create the folder" in r.err and "port went away" not in r.err, r.err
        r = run_fsw("dump", str(project), "--port", t.port, "-o", str(out))
        assert r.code == 0, r.err
        r = run_fsw("dump", str(project), "--port", t.port, "-o", str(out), "--force")  # a log by a new one
        assert r.code == 0 and "flight 1:" in r.out, r.err
    _no_parts(out)
