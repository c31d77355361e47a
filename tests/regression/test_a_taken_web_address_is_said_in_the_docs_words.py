"""`fsw ground` on a TCP port another program holds said `cannot serve on
127.0.0.1:8000: Address already in use (while attempting to bind on
address ('127.0.0.1', 8000))`: Python's own words about its bind, a tuple
included, after the ones docs/cli.md quotes. The message now ends with the
system's reason, as the doc says, for `fsw ground` and `fsw web` alike."""

from __future__ import annotations

import socket

import pytest

from conftest import run_fsw
from support.linkstream import TANK


@pytest.mark.parametrize("command", ["ground", "web"])
def test_a_taken_http_port_is_said_as_the_doc_says(tmp_path, command):
    with socket.create_server(("127.0.0.1", 0)) as busy:
        port = busy.getsockname()[1]
        r = run_fsw(command, str(TANK), "--port", "/dev/no-such-port", "--no-archive", "--http-port", str(port))
    assert r.code == 1, r.err
    assert r.err.strip().splitlines()[-1] == f"fsw {command}: cannot serve on 127.0.0.1:{port}: Address already in use"
