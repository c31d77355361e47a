"""Options and ports the ground commands cannot use, refused with a clear
message and the documented status, before anything is opened or written:

- `fsw ground --http-port` beyond 0..65535 was an OverflowError's
  traceback; a TCP port already taken or a `--host` that is not this
  machine's ended the process through uvicorn with status 3, the kit's own
  "internal error", after the serial port and the archive were opened;
- `--archive FILE --no-archive` archived nothing without a word;
- `fsw monitor --log -` recorded into a file named `-`;
- `fsw ground --host ::1` printed its page's address as `http://::1:8000/`;
- `fsw archive export --from inf` exported no rows, exit 0;
- a `--port` that is a regular file or a folder was pyserial's "Could not
  configure port: (25, 'Inappropriate ioctl for device')"."""

from __future__ import annotations

import socket

import pytest
from conftest import run_fsw
from support.linkstream import TANK

from fswkit.ground.archive import Archive

NO_PORT = "/dev/no-such-port"


@pytest.mark.parametrize("command", ["ground", "web"])
@pytest.mark.parametrize("value", ["-1", "65536", "70000", "eighty"])
def test_http_port_out_of_range(command, value):
    r = run_fsw(command, str(TANK), "--port", NO_PORT, "--http-port", value, "--no-archive")
    assert r.code == 2 and "--http-port" in r.err and "Traceback" not in r.err, r.err


def test_monitor_log_to_standard_output():
    # `-` names standard output for every other output; the monitor wrote a file called `-`
    r = run_fsw("monitor", str(TANK), "--port", NO_PORT, "--log", "-", "--headless")
    assert r.code == 2 and "--log -: a link log is written to a file" in r.err, r.err


def test_archive_and_no_archive_together():
    r = run_fsw("ground", str(TANK), "--port", NO_PORT, "--archive", "x.sqlite", "--no-archive")
    assert r.code == 2 and "not allowed with argument" in r.err, r.err


@pytest.mark.parametrize("taken", ["port", "host"])
def test_a_web_address_it_cannot_serve_on_is_said_first(tmp_path, taken):
    arch = tmp_path / "a.sqlite"
    with socket.create_server(("127.0.0.1", 0)) as busy:
        if taken == "port":
            where = ["--http-port", str(busy.getsockname()[1])]
            words = f"cannot serve on 127.0.0.1:{busy.getsockname()[1]}: Address already in use"
        else:
            where = ["--host", "999.1.1.1"]
            words = "cannot serve on 999.1.1.1:8000: "
        r = run_fsw("ground", str(TANK), "--port", NO_PORT, "--archive", str(arch), *where)
    assert r.code == 1 and words in r.err, r.err
    assert "cannot open" not in r.err and not arch.exists()  # before the serial port and the archive


@pytest.mark.parametrize("option", ["--from", "--to"])
@pytest.mark.parametrize("value", ["inf", "1e400", "nan", "-1"])
def test_export_span_is_finite(tmp_path, option, value):
    arch = tmp_path / "a.sqlite"
    Archive(str(arch)).close()
    r = run_fsw("archive", "export", str(arch), "-o", str(tmp_path / "x.csv"), option, value)
    assert r.code == 2 and option in r.err, r.err


@pytest.mark.parametrize("kind", ["file", "folder", "missing"])
def test_a_port_that_is_no_port(tmp_path, kind):
    port = tmp_path / "port"
    if kind == "file":
        port.write_text("my notes\n")
    elif kind == "folder":
        port.mkdir()
    words = {"file": "it is a regular file, not a serial port", "folder": "it is a folder, not a serial port",
             "missing": "no such port"}[kind]
    for argv in (("cmd", "ping", "-p", str(TANK)), ("monitor", str(TANK), "--headless"),
                 ("ground", str(TANK), "--no-web", "--no-archive")):
        r = run_fsw(*argv, "--port", str(port))
        assert r.code == 1 and f"cannot open {port}: {words}" in r.err, (argv, r.err)
    if kind == "file":
        assert port.read_text() == "my notes\n"


def test_the_address_printed_for_an_ipv6_host():
    # `--host ::1` printed http://::1:8000/, which no browser opens
    from fswkit.web.app import url

    assert url("::1", 8000) == "http://[::1]:8000/"
    assert url("127.0.0.1", 8000) == "http://127.0.0.1:8000/"
