"""The web station's ASGI application (Starlette): the page and its assets,
the layout as JSON, a WebSocket per browser that carries every message of
the source (and the link's figures twice a second), the command
endpoint, and the archive browser's read-only queries of the station's
archive (fswkit.web.archive). Served by uvicorn (`serve`), behind two
guards against other sites' pages in the operator's browser (`SameOrigin`,
and Starlette's TrustedHostMiddleware on a loopback address)."""

from __future__ import annotations

import asyncio
import contextlib
import ipaddress
import json
import os
import shutil
import socket
import tempfile
from urllib.parse import urlsplit

from starlette.applications import Starlette
from starlette.background import BackgroundTask
from starlette.concurrency import run_in_threadpool
from starlette.datastructures import Headers
from starlette.middleware import Middleware
from starlette.middleware.trustedhost import TrustedHostMiddleware
from starlette.requests import Request
from starlette.responses import FileResponse, JSONResponse, Response
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket, WebSocketClose, WebSocketDisconnect

from fswkit.autocode.types import TYPES

from . import archive as browse
from .source import CommandError, Source

STATIC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "static")
UPLOT_VERSION = "1.6.32"


class AssetsMissing(Exception):
    pass


def uplot_dir() -> str:
    """Where uPlot's dist files are: FSW_UPLOT_DIR, else what `make setup`
    installed from the npm registry into build/web (a source checkout)."""
    from fswkit.autocode.kit import ROOT

    d = os.environ.get("FSW_UPLOT_DIR") or os.path.join(ROOT, "build", "web", "node_modules", "uplot", "dist")
    if not os.path.isfile(os.path.join(d, "uPlot.iife.min.js")):
        raise AssetsMissing(f"the web station draws its plots with uPlot, which is not installed at {d}: run "
                            f"`make setup`, or `npm install --prefix DIR uplot@{UPLOT_VERSION}` and set "
                            "FSW_UPLOT_DIR=DIR/node_modules/uplot/dist")
    return d


def layout_json(source: Source) -> dict:
    lay = source.layout
    elements = []
    for e in lay.elements:
        t = TYPES[e.type]
        elements.append({"name": e.name, "type": e.type, "region": e.region, "kind": t.kind,
                         "lo": t.lo if t.is_int else None, "hi": t.hi if t.is_int else None,
                         "writable": e.name in lay.writable, "states": lay.states.get(e.name)})
    return {"name": lay.name, "schema": f"0x{lay.schema:08x}", "time_unit": lay.time_unit, "rate": lay.rate,
            "has_params": bool(getattr(source, "params", ())),
            "elements": elements, "tasks": [{"name": n, "kind": k} for n, k in lay.tasks],
            "state_elements": list(lay.states), "has_uplink": lay.has_uplink,
            "pyro": list(lay.pyro), "sensors": list(lay.sensors)}


def archive_of(source: Source) -> tuple[str | None, object]:
    """(the path of the station's archive or None, the archive)."""
    archive = getattr(getattr(source, "station", None), "archive", None)
    return getattr(archive, "path", None), archive


NO_ARCHIVE = "this station archives nothing (it was started with --no-archive): there are no sessions to browse"


class SameOrigin:
    """ASGI middleware: what a page of another site open in the operator's
    browser could make it send is refused. Browsers let any page POST a
    text/plain body to any address without asking it first, and open a
    WebSocket to any address; they say whose page asks in `Origin`. So:
    a POST or a WebSocket whose Origin is not this station's own page (the
    scheme and the Host the request was sent to) is refused, 403; a POST
    whose body is not declared `application/json` (which a cross-site page
    cannot send without the browser asking first, and the station never
    grants) is refused, 415. A script or a terminal tool sends no Origin."""

    def __init__(self, app):
        self.app = app

    async def __call__(self, scope, receive, send) -> None:
        kind = scope["type"]
        if kind not in ("http", "websocket") or (kind == "http" and scope["method"] in ("GET", "HEAD", "OPTIONS")):
            await self.app(scope, receive, send)
            return
        headers = Headers(scope=scope)
        origin = headers.get("origin")
        if origin is not None and not same_origin(origin, headers.get("host", "")):
            if kind == "websocket":
                await WebSocketClose(code=1008)(scope, receive, send)  # before the handshake: HTTP 403
                return
            words = (f"refused: a request from {origin[:120]}, not from this station's page (a page of another "
                     "site cannot command the target)")
            await JSONResponse({"ok": False, "words": words}, status_code=403)(scope, receive, send)
            return
        if kind == "http" and headers.get("content-type", "").split(";")[0].strip().lower() != "application/json":
            words = "a command or a parameter is sent as a JSON body declared `Content-Type: application/json`"
            await JSONResponse({"ok": False, "words": words}, status_code=415)(scope, receive, send)
            return
        await self.app(scope, receive, send)


def same_origin(origin: str, host: str) -> bool:
    """Whether `origin` (a request's Origin header) is the page served at
    `host` (its Host header): http(s) and the same host and port."""
    parts = urlsplit(origin)
    return parts.scheme in ("http", "https") and bool(host) and parts.netloc.lower() == host.lower()


def loopback(host: str) -> bool:
    """Whether the station serves on a loopback address only (`--host`)."""
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return host.lower() == "localhost"


MAX_BODY = 1 << 20  # bytes of a command's or the parameters' JSON (a few hundred bytes each in use)


async def json_body(request: Request):
    """The request's body as JSON, read up to MAX_BODY bytes; or the
    refusal to answer: 413 past MAX_BODY (read no further: a client on the
    port cannot fill the station's memory), 400 for a body that is not JSON
    (nested deeper than the reader recurses included) or names a key twice
    in one object."""
    size = request.headers.get("content-length", "")
    if size.isdigit() and int(size) > MAX_BODY:
        return JSONResponse({"ok": False, "words": f"the request is over {MAX_BODY:,} bytes"}, status_code=413)
    chunks, n = [], 0
    async for chunk in request.stream():
        n += len(chunk)
        if n > MAX_BODY:
            return JSONResponse({"ok": False, "words": f"the request is over {MAX_BODY:,} bytes"}, status_code=413)
        chunks.append(chunk)
    try:
        return json.loads(b"".join(chunks), object_pairs_hook=_members)
    except _Twice as e:
        return JSONResponse({"ok": False, "words": f"the request names `{e}` twice in one object"}, status_code=400)
    except (ValueError, RecursionError):
        return JSONResponse({"ok": False, "words": "the request is not JSON"}, status_code=400)


class _Twice(ValueError):
    """A JSON object of the request names a key twice (its args: the key)."""


def _members(pairs: list) -> dict:
    """A JSON object of a request as a dict; _Twice for a key named twice
    (JSON's reader keeps the last, and which one was meant is not ours to
    guess)."""
    out = {}
    for k, v in pairs:
        if k in out:
            raise _Twice(k if len(k) <= 60 else k[:60] + "...")
        out[k] = v
    return out


def exposure(host: str, port: int) -> str | None:
    """What to say when the page is served beyond this machine (`--host`
    not a loopback address): it has no login, and commands the target."""
    if loopback(host):
        return None
    return (f"the page on {host} port {port} is open to every computer that can reach this one, and it commands "
            "the target with no login (--host 127.0.0.1 keeps it to this machine)")


def create_app(source: Source, title: str = "fsw ground", host: str = "127.0.0.1") -> Starlette:
    """The station's application, served on `host` (`--host`). On a
    loopback address a request must name this machine as its Host
    (localhost, 127.0.0.1, ::1): a site whose name is made to resolve to
    127.0.0.1 (DNS rebinding) would otherwise be the page's own origin."""
    assets = uplot_dir()
    archive_path, archive = archive_of(source)
    ignore_schema = bool(getattr(getattr(source, "station", None), "ignore_schema", False))

    def live_session() -> int | None:
        return None if archive is None else archive.session  # the session the station writes now

    def refused(e: browse.BrowseError) -> Response:
        return JSONResponse({"ok": False, "words": e.words}, status_code=e.status)

    async def archive_sessions(request: Request) -> Response:
        if archive_path is None:
            return JSONResponse({"ok": True, "archive": None, "words": NO_ARCHIVE, "sessions": []})
        try:
            rows = await run_in_threadpool(browse.list_sessions, archive_path, live_session())
        except browse.BrowseError as e:
            return refused(e)
        return JSONResponse({"ok": True, "archive": archive_path, "live": live_session(), "sessions": rows})

    def session_of(request: Request) -> browse.Session:
        if archive_path is None:
            raise browse.BrowseError(404, NO_ARCHIVE)
        return browse.Session(archive_path, request.path_params["id"], live_session())

    async def archive_session(request: Request) -> Response:
        def work():
            s = session_of(request)
            q = request.query_params
            names = s.check_elements(q.get("elements"))
            lo, hi = browse.range_args(s, q)
            points = browse.points_arg(q)
            return {"ok": True, "session": s.info(), "from": lo, "to": hi, "points": points,
                    "series": s.series(names, lo, hi, points)}
        try:
            return JSONResponse(await run_in_threadpool(work))
        except browse.BrowseError as e:
            return refused(e)

    async def archive_events(request: Request) -> Response:
        try:
            return JSONResponse({"ok": True} | await run_in_threadpool(lambda: session_of(request).events()))
        except browse.BrowseError as e:
            return refused(e)

    async def archive_export(request: Request) -> Response:
        fmt = request.path_params["fmt"]
        if fmt not in ("csv", "parquet"):
            return JSONResponse({"ok": False, "words": f"export.{fmt}: the session exports as export.csv or "
                                 "export.parquet"}, status_code=404)
        folder = tempfile.mkdtemp(prefix="fsw-export-")  # removed once the file is sent, or at once
        sent = False
        try:
            out, name = await run_in_threadpool(lambda: browse.export(
                archive_path, session_of(request), fmt, request.query_params, ignore_schema, folder))
            media = "text/csv; charset=utf-8" if fmt == "csv" else "application/vnd.apache.parquet"
            response = FileResponse(out, media_type=media, filename=name,
                                    background=BackgroundTask(shutil.rmtree, folder, ignore_errors=True))
            sent = True
            return response
        except browse.BrowseError as e:
            return refused(e)
        finally:
            if not sent:
                shutil.rmtree(folder, ignore_errors=True)

    async def index(request: Request) -> Response:
        return FileResponse(os.path.join(STATIC, "index.html"))

    async def layout(request: Request) -> Response:
        return JSONResponse(layout_json(source) | {"title": title})

    async def command(request: Request) -> Response:
        body = await json_body(request)
        if isinstance(body, Response):
            return body
        if not isinstance(body, dict) or not all(isinstance(body.get(k), str) for k in ("kind", "target", "value")):
            return JSONResponse({"ok": False, "words": "expected {kind, target, value} as strings"}, status_code=400)
        who = f"web {request.client.host if request.client else '?'}"
        try:
            entry = await source.command(who, body["kind"], body["target"], body["value"])
        except CommandError as e:
            return JSONResponse({"ok": False, "words": str(e)}, status_code=422)
        return JSONResponse(entry)

    async def params(request: Request) -> Response:
        if request.method == "GET":
            if not hasattr(source, "params_now"):
                return JSONResponse({"ok": False, "words": "this source has no target"})
            return JSONResponse(await source.params_now())
        body = await json_body(request)
        if isinstance(body, Response):
            return body
        if not isinstance(body, dict) or not isinstance(body.get("values"), dict):
            return JSONResponse({"ok": False, "words": "expected {values: {NAME: VALUE}}"}, status_code=400)
        who = f"web {request.client.host if request.client else '?'}"
        try:
            entry = await source.params_set(who, body["values"])
        except (CommandError, AttributeError) as e:
            return JSONResponse({"ok": False, "words": str(e)}, status_code=422)
        return JSONResponse(entry)

    async def feed(ws: WebSocket) -> None:
        await ws.accept()
        q = source.subscribe()
        await ws.send_text(json.dumps({"t": "history", "commands": list(source.history)}))

        async def ticks():
            while True:
                await q.put(json.dumps(source.link()))
                await asyncio.sleep(0.5)

        ticker = asyncio.create_task(ticks())
        try:
            while True:
                msg = await q.get()
                batch = [msg]
                while not q.empty() and len(batch) < 200:  # what waits goes in one WebSocket message
                    batch.append(q.get_nowait())
                await ws.send_text("[" + ",".join(batch) + "]")  # each message encoded once, for every browser
        except (WebSocketDisconnect, RuntimeError):
            pass
        finally:
            ticker.cancel()
            source.unsubscribe(q)

    @contextlib.asynccontextmanager
    async def lifespan(app):
        await source.start()
        try:
            yield
        finally:
            await source.stop()

    app = Starlette(routes=[
        Route("/", index),
        Route("/api/layout", layout),
        Route("/api/command", command, methods=["POST"]),
        Route("/api/params", params, methods=["GET", "POST"]),
        Route("/api/archive/sessions", archive_sessions),
        Route("/api/archive/{id}", archive_session),
        Route("/api/archive/{id}/events", archive_events),
        Route("/api/archive/{id}/export.{fmt}", archive_export),
        WebSocketRoute("/ws", feed),
        Mount("/static", StaticFiles(directory=STATIC)),
        Mount("/uplot", StaticFiles(directory=assets)),
    ], lifespan=lifespan, middleware=[
        Middleware(TrustedHostMiddleware,
                   allowed_hosts=["localhost", "127.0.0.1", "[::1]"] if loopback(host) else ["*"]),
        Middleware(SameOrigin),
    ])
    app.state.source = source
    return app


def listen(host: str, port: int) -> socket.socket:
    """The web server's socket, listening on host:port before anything
    else starts: an OSError with the system's reason when it cannot (the
    port taken, a host that does not resolve or is not this machine's),
    where uvicorn would log it and exit the process."""
    family = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)[0][0]
    return socket.create_server((host, port), family=family)


def url(host: str, port: int) -> str:
    """The page's address on host:port (an IPv6 address in brackets)."""
    return f"http://[{host}]:{port}/" if ":" in host else f"http://{host}:{port}/"


def serve(app: Starlette, host: str = "127.0.0.1", port: int = 8000, on_ready=None,
          sock: socket.socket | None = None) -> None:
    """Runs uvicorn in this thread until Ctrl-C; `on_ready(url)` once it
    listens, on `sock` (from `listen`) when given."""
    import uvicorn

    config = uvicorn.Config(app, host=host, port=port, log_level="warning", lifespan="on", ws="websockets-sansio",
                            ws_per_message_deflate=False)  # on localhost, compressing costs more than it saves
    server = uvicorn.Server(config)

    async def main():
        task = asyncio.create_task(server.serve(sockets=[sock] if sock is not None else None))
        while not server.started and not task.done():
            await asyncio.sleep(0.02)
        if server.started and on_ready is not None:
            bound = server.servers[0].sockets[0].getsockname()[1] if server.servers else port
            on_ready(url(host, bound))
        await task

    asyncio.run(main())
