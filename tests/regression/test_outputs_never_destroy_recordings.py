"""No command truncates or replaces a recording it was not asked to: an
output path equal to one of the command's inputs is refused, a link log is
never overwritten by another output, `fsw monitor --log` refuses an
existing file unless `--force` and even then replaces it only once the
target has proved to be the right one, and every output file is written
beside its path and renamed into place, so a failed write leaves the old
file whole."""

from __future__ import annotations

import contextlib
import os
import resource
import signal
import sys

import pytest
from conftest import run_fsw
from support.linkstream import TANK, PtyStream, layout_of, tank_copy, write_log


def _log(path, first=0, n=400):
    return write_log(path, n, first).read_bytes()


def _no_parts(folder):
    assert not [p.name for p in folder.iterdir() if p.name.endswith(".part")]


def test_log2csv_onto_its_own_log_is_refused(tmp_path):
    log = tmp_path / "x.log"
    before = _log(log)
    r = run_fsw("log2csv", str(log), "-o", str(log))
    assert r.code == 1 and "overwrite an input" in r.err, r.err
    assert log.read_bytes() == before
    other = tmp_path / "other.log"
    kept = _log(other, first=77)
    r = run_fsw("log2csv", str(log), "-o", str(other))
    assert r.code == 1 and "a link log (a recording) is there" in r.err, r.err
    assert other.read_bytes() == kept
    _no_parts(tmp_path)


def test_graph_and_skeleton_onto_their_machine_are_refused(tmp_path):
    project = tank_copy(tmp_path)
    sm = project / "tank.sm"
    before = sm.read_bytes()
    for command in ("graph", "skeleton"):
        r = run_fsw(command, str(sm), "-o", str(sm))
        assert r.code == 1 and "overwrite an input" in r.err, r.err
        assert sm.read_bytes() == before


def test_monitor_log_keeps_an_existing_recording(tmp_path):
    old = tmp_path / "old.log"
    before = _log(old)
    # without --force: refused before the port is even opened
    r = run_fsw("monitor", str(TANK), "--port", "/dev/no-such-port", "--log", str(old), "--headless")
    assert r.code == 1 and "never overwritten unless asked" in r.err, r.err
    assert old.read_bytes() == before
    # with --force, a target of other configs is refused: the old recording stays
    project = tank_copy(tmp_path, uplink=False)
    layout = layout_of(project)
    with PtyStream(layout, schema=layout.schema ^ 1, hello_first=True) as target:
        r = run_fsw("monitor", str(project), "--port", target.port, "--headless", "--frames", "100",
                    "--log", str(old), "--force")
    assert r.code == 1 and "schema mismatch" in r.err, r.err
    assert old.read_bytes() == before
    _no_parts(tmp_path)
    # with --force and the right target, it is replaced by the new recording
    with PtyStream(layout, hello_first=True) as target:
        r = run_fsw("monitor", str(project), "--port", target.port, "--headless", "--frames", "100",
                    "--log", str(old), "--force")
    assert r.code == 0, r.err
    assert old.read_bytes() != before and old.read_bytes().startswith(b"FSWLOG1\n")
    _no_parts(tmp_path)


@contextlib.contextmanager
def writes_fail_past(limit: int):
    """In the block, a file's bytes past `limit` are not written (EFBIG), as
    on a full disk. Python writes no compiled bytecode meanwhile: importlib
    ignores a short write, and a module first imported in the block (`fsw
    new`'s, say) would leave a cut .pyc that every later import of it in
    the test run fails on ("marshal data too short")."""
    old = resource.getrlimit(resource.RLIMIT_FSIZE)
    old_sig = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    old_dont = sys.dont_write_bytecode
    sys.dont_write_bytecode = True
    try:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, old[1]))
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, old)
        signal.signal(signal.SIGXFSZ, old_sig)
        sys.dont_write_bytecode = old_dont


def test_a_failed_write_leaves_the_old_file(tmp_path):
    log = tmp_path / "x.log"
    _log(log, n=3000)
    csv = tmp_path / "x.csv"
    csv.write_text("the previous export\n")
    with writes_fail_past(65536):
        r = run_fsw("log2csv", str(log), "-o", str(csv), "--force")
    assert r.code == 1 and "File too large" in r.err and "Traceback" not in r.err, r.err
    assert csv.read_text() == "the previous export\n"
    _no_parts(tmp_path)


@pytest.mark.parametrize("command", ["graph", "skeleton"])
def test_a_small_output_that_cannot_be_written_is_named(tmp_path, command):
    # the whole text fails at the last flush, and again as the file closes: the message still names the file
    project = tank_copy(tmp_path)
    out = tmp_path / "out.txt"
    with writes_fail_past(100):
        r = run_fsw(command, str(project / "tank.sm"), "-o", str(out))
    assert r.code == 1 and f"cannot write {out}: File too large" in r.err, r.err
    assert not out.exists()
    _no_parts(tmp_path)


@pytest.mark.parametrize("limit", [100, 1024])  # fails making the starter script, or writing the project
def test_new_project_on_a_full_disk_leaves_no_half_project(tmp_path, limit):
    # a half-written project would stand in the way of the next `fsw new` ("already exists")
    with writes_fail_past(limit):
        r = run_fsw("new", "probe", cwd=tmp_path)
    assert r.code == 1 and "cannot write" in r.err and "File too large" in r.err, r.err
    assert os.listdir(tmp_path) == []
    r = run_fsw("new", "probe", cwd=tmp_path)
    assert r.code == 0, r.err
    assert os.listdir(tmp_path) == ["probe"] and (tmp_path / "probe" / "probe.app").is_file()
    (tmp_path / "empty").mkdir()  # an empty folder may still be the project's
    r = run_fsw("new", "empty", cwd=tmp_path)
    assert r.code == 0 and (tmp_path / "empty" / "empty.sm").is_file(), r.err
    umask = os.umask(0)
    os.umask(umask)
    assert (tmp_path / "probe").stat().st_mode & 0o777 == 0o777 & ~umask  # a folder as mkdir makes it


def test_sketch_export_never_overwrites_a_file_it_did_not_write(tmp_path):
    project = tank_copy(tmp_path)
    sketch = tmp_path / "mine"
    sketch.mkdir()
    (sketch / "mine.ino").write_text("// my own sketch\nvoid setup() {}\nvoid loop() {}\n")
    r = run_fsw("gen", str(project), "--sketch", str(sketch))
    assert r.code == 1 and f"{sketch / 'mine.ino'}" in r.err and "not written by fsw gen" in r.err, r.err
    assert (sketch / "mine.ino").read_text().startswith("// my own sketch")
    assert sorted(os.listdir(sketch)) == ["mine.ino"]  # refused before anything is written
    # a sketch it exported is exported again over itself
    fresh = tmp_path / "fresh"
    for _ in range(2):
        r = run_fsw("gen", str(project), "--sketch", str(fresh))
        assert r.code == 0, r.err


@pytest.mark.parametrize("signame", ["SIGTERM", "SIGHUP"])
def test_an_output_stopped_by_a_signal_leaves_the_old_file(tmp_path, monkeypatch, signame):
    # `kill` mid-export: as Ctrl-C, the old file stays and no temporary file is left beside it
    import fswkit.ground.logs

    sig = getattr(signal, signame)
    log = tmp_path / "x.log"
    _log(log)
    csv = tmp_path / "x.csv"
    csv.write_text("the previous export\n")

    def log2csv(path, f, ignore_schema, *more, **options):
        f.write("seq,sample\n1,0\n")
        assert signal.getsignal(sig) not in (signal.SIG_DFL, signal.SIG_IGN, None), "the signal would kill it"
        signal.raise_signal(sig)
        raise AssertionError("the signal did not stop the export")

    monkeypatch.setattr(fswkit.ground.logs, "log2csv", log2csv)
    before = signal.getsignal(sig)
    r = run_fsw("log2csv", str(log), "-o", str(csv), "--force")
    assert r.code == 128 + sig, r.err
    assert signal.getsignal(sig) == before
    assert csv.read_text() == "the previous export\n"
    _no_parts(tmp_path)


def test_graph_and_skeleton_onto_the_state_vector_they_found_are_refused(tmp_path):
    # the .sv is an input too when found beside the machine, not named by --sv
    project = tank_copy(tmp_path)
    sv = project / "tank.sv"
    before = sv.read_bytes()
    for command in ("graph", "skeleton"):
        for spelling in (str(sv), "./tank.sv"):
            r = run_fsw(command, "tank.sm", "-o", spelling, cwd=project)
            assert r.code == 1 and "overwrite an input" in r.err, r.err
            assert sv.read_bytes() == before


@pytest.mark.parametrize("stop", ["ctrl-c", "SIGTERM", "SIGHUP"])
def test_monitor_stopped_before_the_target_answered_keeps_the_old_recording(tmp_path, monkeypatch, stop):
    # --force replaces the old recording only once the target is known to be the right one:
    # stopping the monitor while it still waits for the hello keeps it, and leaves no temporary file
    import pty

    from fswkit.link.client import Ground

    old = tmp_path / "old.log"
    before = _log(old)

    def handshake(self, *a, **kw):
        if stop == "ctrl-c":
            raise KeyboardInterrupt
        sig = getattr(signal, stop)
        assert signal.getsignal(sig) not in (signal.SIG_DFL, signal.SIG_IGN, None), "the signal would kill it"
        signal.raise_signal(sig)
        raise AssertionError("the signal did not stop the monitor")

    monkeypatch.setattr(Ground, "handshake", handshake)
    master, slave = pty.openpty()
    try:
        r = run_fsw("monitor", str(TANK), "--port", os.ttyname(slave), "--headless", "--log", str(old), "--force")
    finally:
        os.close(master)
        os.close(slave)
    assert r.code == (0 if stop == "ctrl-c" else 128 + getattr(signal, stop)), r.err
    assert old.read_bytes() == before
    _no_parts(tmp_path)


def test_monitor_log_onto_its_configs_or_port_is_refused_even_with_force(tmp_path):
    # --force replaces an old recording, never one of the project's configs nor the port read
    project = tank_copy(tmp_path)
    port = tmp_path / "port"
    port.write_text("a file standing for the port\n")
    for victim in ("tank.app", "tank.sv", "tank.sm", "tank.aio", "tank.dio", str(port)):
        f = project / victim
        before = f.read_bytes()
        r = run_fsw("monitor", str(project), "--port", str(port), "--headless", "--log", str(f), "--force")
        assert r.code == 1 and "overwrite an input" in r.err, r.err
        assert f.read_bytes() == before
    r = run_fsw("monitor", str(project), "--port", str(port), "--headless", "--log", "")
    assert r.code == 2 and "--log: an empty string" in r.err, r.err


@pytest.mark.parametrize("argv", [
    ("test", "tank.ss", "--trace", ""), ("build", ".", "--out", ""), ("gen", ".", "--out", ""),
    ("sim", ".", "--plant", "tank", "--out", ""), ("skeleton", "tank.sm", "-o", ""),
    ("monitor", ".", "--port", "", "--headless"), ("test", "tank.ss", "--sv", ""), ("build", ".", "--board", ""),
], ids=lambda a: " ".join(a[:1] + a[-2:]))
def test_an_empty_path_is_refused_not_taken_for_the_default(tmp_path, argv):
    # `--trace ""` wrote no trace and `--out ""` built into the default folder, with exit status 0
    project = tank_copy(tmp_path)
    r = run_fsw(*argv, cwd=project)
    opt = next(a for a in argv if a.startswith("-") and argv[argv.index(a) + 1] == "")
    opt = {"-o": "--output"}.get(opt, opt)
    assert r.code == 2 and f"{opt}: an empty string" in r.err, r.err
    assert not (project / "build").exists()


def test_test_trace_onto_its_script_or_machine_is_refused(tmp_path):
    project = tank_copy(tmp_path)
    for victim in ("tank.ss", "tank.sm", "tank.sv"):
        f = project / victim
        before = f.read_bytes()
        r = run_fsw("test", str(project / "tank.ss"), "--trace", str(f))
        assert r.code == 1 and "overwrite an input" in r.err, r.err
        assert f.read_bytes() == before
    trace = project / "trace.csv"
    r = run_fsw("test", str(project / "tank.ss"), "--trace", str(trace))
    assert r.code == 0 and trace.read_text().startswith("step"), r.err
    _no_parts(project)


def test_no_output_overwrites_a_ground_station_archive(tmp_path):
    # an archive holds every session of a station: like a log, no command's
    # output replaces it (the class: every output goes through outputs.check)
    from fswkit.ground.archive import Archive

    log = tmp_path / "x.log"
    _log(log)
    project = tank_copy(tmp_path)
    # each output named as its command would write it (the plot's format is its extension)
    for name, args in (("ground.csv", ("log2csv", str(log), "-o")),
                       ("ground.png", ("plot", str(log), "-e", "tankPressure", "-o")),
                       ("ground.dot", ("graph", str(project / "tank.sm"), "-o"))):
        arch = tmp_path / name
        Archive(str(arch)).close()
        before = arch.read_bytes()
        r = run_fsw(*args, str(arch))
        assert r.code != 0 and "a ground station archive (a recording) is there" in r.err, (args, r.err)
        assert arch.read_bytes() == before
