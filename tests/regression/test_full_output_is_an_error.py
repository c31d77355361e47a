"""Output that cannot be written — a full standard output, `-o /dev/full`,
a full disk under a link log — is a clear message naming what could not be
written and a non-zero exit, for every command that writes (one output
path for all of them): never a traceback, an "internal error", or a full
disk reported as the serial port going away."""

from __future__ import annotations

import contextlib
import io

import pytest
from conftest import run_fsw
from support.linkstream import TANK, PtyStream, layout_of, tank_copy, write_log

FULL = "/dev/full"


def run_into_full_stdout(*argv: str):
    from fswkit.cli import main

    err = io.StringIO()
    full = open(FULL, "w")
    try:
        with contextlib.redirect_stdout(full), contextlib.redirect_stderr(err):
            try:
                code = main(list(argv))
            except SystemExit as e:
                code = e.code
    finally:
        with contextlib.suppress(OSError):
            full.close()
    return code, err.getvalue()


def clean_failure(code, err):
    assert code == 1, err
    assert "No space left on device" in err, err
    assert "Traceback" not in err and "internal error" not in err, err


@pytest.fixture(scope="module")
def log(tmp_path_factory):
    return str(write_log(tmp_path_factory.mktemp("full") / "clean.log", 3000))


def _commands(log):
    sm = str(TANK / "tank.sm")
    return [("log2csv", log), ("replay", log, "--headless", "--speed", "0"), ("graph", sm), ("skeleton", sm),
            ("test", str(TANK / "tank.ss"))]


def test_full_standard_output(log):
    for argv in _commands(log):
        clean_failure(*run_into_full_stdout(*argv))


@pytest.mark.parametrize("command", ["log2csv", "graph", "skeleton"])
def test_output_file_on_a_full_device(log, command):
    src = log if command == "log2csv" else str(TANK / "tank.sm")
    r = run_fsw(command, src, "-o", FULL)
    clean_failure(r.code, r.err)
    assert FULL in r.err


def test_monitor_log_on_a_full_disk_is_not_the_port(tmp_path):
    project = tank_copy(tmp_path, uplink=False)
    with PtyStream(layout_of(project)) as target:
        r = run_fsw("monitor", str(project), "--port", target.port, "--headless", "--frames", "200",
                    "--log", FULL, "--force")
    clean_failure(r.code, r.err)
    assert "the port went away" not in r.err and f"cannot write the log {FULL}" in r.err


@pytest.mark.parametrize("view", ["--headless", "--live"])
def test_monitor_view_on_a_full_standard_output(tmp_path, view):
    project = tank_copy(tmp_path, uplink=False)
    argv = ["monitor", str(project), "--frames", "200"] + (["--headless"] if view == "--headless" else [])
    with PtyStream(layout_of(project)) as target:
        code, err = run_into_full_stdout(*argv, "--port", target.port)
    clean_failure(code, err)
    assert "the port went away" not in err and err.count("cannot write standard output") == 1, err


def test_full_standard_output_is_named(tmp_path, log):
    # said as standard output: not a bare system error, nor the build folder the command wrote into
    argvs = _commands(log) + [("new", str(tmp_path / "fresh")),
                              ("build", str(TANK), "--board", "native", "--out", str(tmp_path / "native"))]
    for argv in argvs:
        code, err = run_into_full_stdout(*argv)
        clean_failure(code, err)
        assert err.count("cannot write standard output: No space left on device") == 1, (argv, err)
        assert str(tmp_path) not in err, (argv, err)
