"""A ground station on a test's pty target, its web page open in the test's
browser."""

from __future__ import annotations

import contextlib

from support.browser import served


@contextlib.contextmanager
def station_page(browser, target, layout, project: str = "tank"):
    """Starts a station on `target.port` for `layout` (no socket for other
    clients), serves its page and opens it in `browser`: yields the station,
    stopped at the end (the target is the caller's)."""
    from fswkit.ground.station import Station
    from fswkit.web.app import create_app
    from fswkit.web.source import LiveSource

    st = Station(layout, project, target.port, 115200, serve=False)
    st.start()
    try:
        with served(create_app(LiveSource(st))) as url:
            browser.get(url)
            yield st
    finally:
        st.stop()
