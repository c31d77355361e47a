"""A POST to the web page's parameters (or command) endpoint is JSON, and
JSON's reader keeps the last of two members of one name:
`{"values": {"OPEN_AT": "700", "OPEN_AT": "710"}}` set 710 and said
nothing of the 700, as `fsw param set` did before it refused a name given
twice. Now a body that names a key twice in one object is refused (400),
naming the key, before anything is sent to the target."""

from __future__ import annotations

import pytest
from support.linkfw import tank_layout

from fswkit.web.app import AssetsMissing, create_app, uplot_dir
from fswkit.web.source import Source

try:
    uplot_dir()
    HAVE_ASSETS = True
except AssetsMissing:
    HAVE_ASSETS = False


class Recording(Source):
    """A source that records what would have been set or sent."""

    def __init__(self):
        super().__init__(tank_layout())
        self.params = ("OPEN_AT",)
        self.sets, self.commands = [], []

    async def params_set(self, who, values):
        self.sets.append(values)
        return {"ok": True}

    async def command(self, who, kind, target, value):
        self.commands.append((kind, target, value))
        return {"ok": True}


@pytest.mark.skipif(not HAVE_ASSETS, reason="uPlot is not installed (make setup)")
def test_a_key_named_twice_is_refused_and_nothing_is_sent():
    from test_web_requests_nested_too_deeply import post

    source = Recording()
    app = create_app(source)
    status, answer = post(app, "/api/params", b'{"values": {"OPEN_AT": "700", "OPEN_AT": "710"}}')
    assert status == 400 and answer == {"ok": False, "words": "the request names `OPEN_AT` twice in one object"}
    status, answer = post(app, "/api/command", b'{"kind": "set", "target": "valveOpen", "value": "true", '
                                               b'"value": "false"}')
    assert status == 400 and answer["words"] == "the request names `value` twice in one object", answer
    assert source.sets == [] and source.commands == []
    status, answer = post(app, "/api/params", b'{"values": {"OPEN_AT": "700"}}')
    assert status == 200 and source.sets == [{"OPEN_AT": "700"}]
