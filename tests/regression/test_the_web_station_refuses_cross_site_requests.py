"""The web station's page commands the target (SET an element, a task's
MODE, a parameter: a valve, an igniter's arming), and it took those POSTs
from any web page the operator's browser had open: a page of any site could
`fetch("http://127.0.0.1:8000/api/command", {method: "POST", body: ...})`
with a text/plain body (a request browsers send without asking the server
first), and the station read it as JSON and sent the command. A page of any
site could also open the WebSocket and read the whole telemetry, and a site
whose name is made to resolve to 127.0.0.1 (DNS rebinding) could read and
command as the page itself does.

Now the station refuses a request whose Origin is not its own page's (403),
a command or parameter POST whose body is not declared application/json
(415: a cross-site page cannot send that without the browser asking first,
which the station never grants), a WebSocket whose Origin is another site's,
and, served on a loopback address, any request that names another host
(400). A script or a terminal tool (no Origin header) and the page itself go
on as before."""

from __future__ import annotations

import http.client
import json

import pytest
from support.browser import served
from support.linkfw import tank_layout

from fswkit.web.app import AssetsMissing, create_app, uplot_dir
from fswkit.web.source import Source

try:
    uplot_dir()
    HAVE_ASSETS = True
except AssetsMissing:
    HAVE_ASSETS = False

pytestmark = pytest.mark.skipif(not HAVE_ASSETS, reason="uPlot is not installed (make setup)")

COMMAND = json.dumps({"kind": "set", "target": "valveOpen", "value": "true"}).encode()
EVIL = "http://evil.example"


@pytest.fixture(scope="module")
def station():
    with served(create_app(Source(tank_layout()))) as url:
        yield int(url.rstrip("/").rsplit(":", 1)[1])


def request(port: int, method: str, path: str, headers: dict, body: bytes | None = None):
    """(status, body as text) of one request; Host is 127.0.0.1:PORT unless `headers` names another."""
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    try:
        c.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
        headers = {"Host": f"127.0.0.1:{port}"} | headers
        if body is not None:
            headers["Content-Length"] = str(len(body))
        for k, v in headers.items():
            c.putheader(k, v)
        c.endheaders(body)
        r = c.getresponse()
        return r.status, r.read().decode("utf-8", "replace")
    finally:
        c.close()


@pytest.mark.parametrize("path", ["/api/command", "/api/params"])
@pytest.mark.parametrize("ctype", ["text/plain", "application/json"])
def test_a_post_from_another_sites_page_is_refused(station, path, ctype):
    status, text = request(station, "POST", path, {"Origin": EVIL, "Content-Type": ctype}, COMMAND)
    assert status == 403, text
    assert json.loads(text) == {"ok": False, "words": f"refused: a request from {EVIL}, not from this station's "
                                "page (a page of another site cannot command the target)"}
    status, text = request(station, "POST", path, {"Origin": "null", "Content-Type": ctype}, COMMAND)
    assert status == 403, text  # a sandboxed frame, a file:// page


@pytest.mark.parametrize("path", ["/api/command", "/api/params"])
def test_a_post_not_declared_json_is_refused(station, path):
    status, text = request(station, "POST", path, {"Content-Type": "text/plain"}, COMMAND)
    assert status == 415, text
    assert "application/json" in json.loads(text)["words"]
    status, text = request(station, "POST", path, {}, COMMAND)  # no Content-Type at all
    assert status == 415, text


def test_the_page_and_scripts_still_command(station):
    """The page's own POST (its Origin, JSON) and a script's (no Origin)
    reach the command: this source takes none, and says so (422)."""
    for headers in ({"Origin": f"http://127.0.0.1:{station}"}, {}):
        status, text = request(station, "POST", "/api/command",
                               headers | {"Content-Type": "application/json; charset=utf-8"}, COMMAND)
        assert status == 422 and "takes no commands" in json.loads(text)["words"], (status, text)


def test_another_host_name_is_refused_on_loopback(station):
    """DNS rebinding: a site's name resolving to 127.0.0.1 would make the
    browser send its own name as Host (and as Origin)."""
    status, text = request(station, "GET", "/api/layout", {"Host": f"rebind.example:{station}"})
    assert status == 400, text
    status, text = request(station, "POST", "/api/command", {"Host": f"rebind.example:{station}", "Origin":
                           f"http://rebind.example:{station}", "Content-Type": "application/json"}, COMMAND)
    assert status == 400, text
    for host in (f"127.0.0.1:{station}", f"localhost:{station}"):
        status, text = request(station, "GET", "/api/layout", {"Host": host})
        assert status == 200 and json.loads(text)["name"] == "tank", (host, status, text)


def _handshake(port: int, origin: str | None) -> int:
    headers = {"Connection": "Upgrade", "Upgrade": "websocket", "Sec-WebSocket-Version": "13",
               "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ=="}
    if origin is not None:
        headers["Origin"] = origin
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    try:
        c.putrequest("GET", "/ws", skip_host=True, skip_accept_encoding=True)
        for k, v in ({"Host": f"127.0.0.1:{port}"} | headers).items():
            c.putheader(k, v)
        c.endheaders()
        return c.getresponse().status
    finally:
        c.close()


def test_the_telemetry_socket_is_refused_to_another_site(station):
    assert _handshake(station, EVIL) == 403
    assert _handshake(station, f"http://127.0.0.1:{station}") == 101
    assert _handshake(station, None) == 101  # a script's client


@pytest.mark.parametrize("path", ["/api/command", "/api/params"])
def test_a_body_past_the_limit_is_not_read(station, path):
    """A client that can reach the port sent bodies of any size, each read
    whole into the station's memory before it was looked at."""
    from fswkit.web.app import MAX_BODY

    big = b'{"kind": "' + b"x" * MAX_BODY + b'"}'
    status, text = request(station, "POST", path, {"Content-Type": "application/json"}, big)
    assert status == 413 and json.loads(text)["words"] == f"the request is over {MAX_BODY:,} bytes", text
    # without a length, cut off as it streams in
    c = http.client.HTTPConnection("127.0.0.1", station, timeout=10)
    try:
        c.putrequest("POST", path, skip_host=True, skip_accept_encoding=True)
        for k, v in {"Host": f"127.0.0.1:{station}", "Content-Type": "application/json",
                     "Transfer-Encoding": "chunked"}.items():
            c.putheader(k, v)
        c.endheaders()
        chunk = b"x" * 65536
        try:
            for _ in range(MAX_BODY // len(chunk) + 2):
                c.send(b"%x\r\n%s\r\n" % (len(chunk), chunk))
            c.send(b"0\r\n\r\n")
        except OSError:
            pass  # the station may close the connection before the rest is sent
        r = c.getresponse()
        assert r.status == 413, r.read()
    finally:
        c.close()


def test_serving_beyond_this_machine_is_said():
    """`--host 0.0.0.0` (a tablet on the range's network) opens the page,
    which commands the target with no login, to the whole network: `fsw
    ground` says so when it starts; on a loopback address it says nothing."""
    from fswkit.web.app import exposure

    for host in ("127.0.0.1", "localhost", "::1", "127.0.0.2"):
        assert exposure(host, 8000) is None, host
    for host in ("0.0.0.0", "::", "192.168.1.20", "groundstation.local"):
        assert exposure(host, 8000) == (f"the page on {host} port 8000 is open to every computer that can reach "
                                        "this one, and it commands the target with no login (--host 127.0.0.1 "
                                        "keeps it to this machine)"), host
