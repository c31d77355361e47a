"""A POST to the web page's command or parameters endpoint whose JSON nests
deeper than the JSON reader recurses was a 500 with a traceback on the
station's console (RecursionError); it is the 400 any body that is not
JSON gets."""

from __future__ import annotations

import asyncio
import json

import pytest
from support.linkfw import tank_layout

from fswkit.web.app import AssetsMissing, create_app, uplot_dir
from fswkit.web.source import Source

try:
    uplot_dir()
    HAVE_ASSETS = True
except AssetsMissing:
    HAVE_ASSETS = False


def post(app, path: str, body: bytes):
    """(status, JSON) of the app's handler of `path` for a POST of `body`."""
    from starlette.requests import Request

    endpoint = next(r.endpoint for r in app.routes if getattr(r, "path", None) == path)
    scope = {"type": "http", "method": "POST", "path": path, "headers": [(b"content-type", b"application/json")],
             "query_string": b"", "client": ("127.0.0.1", 1), "path_params": {}}
    sent = [{"type": "http.request", "body": body, "more_body": False}]

    async def receive():
        return sent.pop(0) if sent else {"type": "http.disconnect"}

    response = asyncio.run(endpoint(Request(scope, receive)))
    return response.status_code, json.loads(response.body)


@pytest.mark.skipif(not HAVE_ASSETS, reason="uPlot is not installed (make setup)")
@pytest.mark.parametrize("path", ["/api/command", "/api/params"])
def test_a_body_nested_too_deeply_is_not_json(path):
    app = create_app(Source(tank_layout()))
    deep = b"[" * 100_000 + b"]" * 100_000
    status, answer = post(app, path, deep)
    assert status == 400 and answer == {"ok": False, "words": "the request is not JSON"}
    status, answer = post(app, path, b"{not json")  # as any other body that is not JSON
    assert status == 400 and answer["words"] == "the request is not JSON"
