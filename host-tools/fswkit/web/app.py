"""The web station's ASGI application (Starlette): the page and its assets,
the layout as JSON, a WebSocket per browser that carries every message of
the source (and the link's figures twice a second), and the command
endpoint. Served by uvicorn (`serve`)."""

from __future__ import annotations

import asyncio
import contextlib
import json
import os

from starlette.applications import Starlette
from starlette.requests import Request
from starlette.responses import FileResponse, JSONResponse, Response
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket, WebSocketDisconnect

from fswkit.autocode.types import TYPES

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
            "state_elements": list(lay.states), "has_uplink": lay.has_uplink}


def create_app(source: Source, title: str = "fsw ground") -> Starlette:
    assets = uplot_dir()

    async def index(request: Request) -> Response:
        return FileResponse(os.path.join(STATIC, "index.html"))

    async def layout(request: Request) -> Response:
        return JSONResponse(layout_json(source) | {"title": title})

    async def command(request: Request) -> Response:
        try:
            body = await request.json()
        except ValueError:
            return JSONResponse({"ok": False, "words": "the request is not JSON"}, status_code=400)
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
        try:
            body = await request.json()
        except ValueError:
            return JSONResponse({"ok": False, "words": "the request is not JSON"}, status_code=400)
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
                await q.put(source.link())
                await asyncio.sleep(0.5)

        ticker = asyncio.create_task(ticks())
        try:
            while True:
                msg = await q.get()
                batch = [msg]
                while not q.empty() and len(batch) < 200:  # what waits goes in one WebSocket message
                    batch.append(q.get_nowait())
                await ws.send_text(json.dumps(batch))
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
        WebSocketRoute("/ws", feed),
        Mount("/static", StaticFiles(directory=STATIC)),
        Mount("/uplot", StaticFiles(directory=assets)),
    ], lifespan=lifespan)
    app.state.source = source
    return app


def serve(app: Starlette, host: str = "127.0.0.1", port: int = 8000, on_ready=None) -> None:
    """Runs uvicorn in this thread until Ctrl-C; `on_ready(url)` once it listens."""
    import uvicorn

    config = uvicorn.Config(app, host=host, port=port, log_level="warning", lifespan="on", ws="websockets-sansio")
    server = uvicorn.Server(config)

    async def main():
        task = asyncio.create_task(server.serve())
        while not server.started and not task.done():
            await asyncio.sleep(0.02)
        if server.started and on_ready is not None:
            bound = server.servers[0].sockets[0].getsockname()[1] if server.servers else port
            on_ready(f"http://{host}:{bound}/")
        await task

    asyncio.run(main())
