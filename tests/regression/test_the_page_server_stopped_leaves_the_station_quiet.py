"""The web page's server stopped (Ctrl-C, or a test's server shut down)
while its ground station ran on: the station's next note, command or
frames were handed to the page's event loop, closed by then, and its
thread died with a traceback (`RuntimeError: Event loop is closed`, seen
from the station's hello thread after a replug). Now the page's source
gives up all three of its registrations with the station when it stops,
and a call that races the loop's closing is dropped: the page is gone,
there is no one to tell."""

from __future__ import annotations

import asyncio

from fswkit.web.source import LiveSource


class FakeStation:
    """The registrations LiveSource makes with a station."""

    def __init__(self, layout):
        self.layout, self.up, self.note = layout, True, ""
        self.listeners, self.note_fns, self.command_fns = [], [], []

    def listen(self, fn):
        self.listeners.append(fn)

    def unlisten(self, fn):
        self.listeners.remove(fn)

    def notes(self, fn):
        self.note_fns.append(fn)

    def unnotes(self, fn):
        self.note_fns.remove(fn)

    def commands(self, fn):
        self.command_fns.append(fn)

    def uncommands(self, fn):
        self.command_fns.remove(fn)


def _layout():
    from support.linkstream import TANK, layout_of

    return layout_of(TANK)


def test_a_stopped_source_is_no_longer_told_anything():
    st = FakeStation(_layout())
    src = LiveSource(st)

    async def life():
        await src.start()
        assert st.listeners and st.note_fns and st.command_fns
        src.subscribe()
        await src.stop()

    asyncio.run(life())
    assert st.listeners == [] and st.note_fns == [] and st.command_fns == []


def test_a_call_racing_the_loops_close_is_dropped():
    st = FakeStation(_layout())
    src = LiveSource(st)

    async def life():
        await src.start()
        src.subscribe()

    asyncio.run(life())  # the loop is closed now, and the source was not stopped
    src._commanded({"who": "fsw cmd", "text": "set valveOpen true", "ok": True})
    src._note("the port went away", False)
    src.publish_threadsafe({"t": "note", "text": "x", "up": True})
