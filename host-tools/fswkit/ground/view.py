"""The monitor's live view (rich) and its headless lines, fed decoded
events: used by `fsw monitor` and `fsw replay`."""

from __future__ import annotations

import time

from fswkit import outputs
from fswkit.link.session import Event, Session, describe
from fswkit.web.source import reset_words


# ---- the live view ---------------------------------------------------------------------

def render(session: Session, now: float, title: str):
    from rich.console import Group
    from rich.table import Table

    lay = session.layout
    t = Table(title=title, expand=False)
    t.add_column("element")
    t.add_column("type")
    t.add_column("value", justify="right")
    t.add_column("detail")
    for e in lay.elements:
        v = session.values.get(e.name)
        detail = ""
        cal = lay.analog.get(e.name)
        if cal is not None and isinstance(v, float) and cal["scale"]:
            volts = (v - cal["offset"]) / cal["scale"]
            detail = f"pin {cal['pin']}: {volts:.3f} V  (= V×{cal['scale']:g} {cal['offset']:+g})"
        elif e.name in lay.states:
            detail = "state"
        elif e.name in lay.writable:
            detail = "writable"
        t.add_row(e.name, e.type, lay.show(e.name, v), detail)
    st, ws = session.stats, session.deframer.stats
    link = Table(title="link", show_header=False)
    link.add_column("k")
    link.add_column("v", justify="right")
    lat = f"{session.latency * 1000:.1f} ms" if session.latency is not None else "—"
    schema = ("ok" if session.schema_ok else "MISMATCH") if session.hello else "waiting for hello"
    for k, v in (("schema", schema), ("frames/s", f"{session.frames_per_second(now):.1f}"),
                 ("frames", st.frames), ("lost (sequence gaps)", f"{st.lost} in {st.gaps}"),
                 ("CRC errors", ws.crc_errors), ("framing errors", ws.framing_errors),
                 ("oversized (no delimiter)", ws.oversized),
                 ("latency (above least)", lat)):
        link.add_row(k, str(v))
    h = session.health
    if h is not None:
        link.add_row("target dropped", str(h["dropped"]))
        link.add_row("executor late cycles", str(h["late"]))
        link.add_row("reset cause", f"{reset_words(h['reset_cause'])} (0x{h['reset_cause']:02x})")
        link.add_row("uplink ok/refused", f"{h['rx_ok']}/{h['rx_refused']}")
        link.add_row("uplink crc/malformed/replayed",
                     f"{h['rx_crc']}/{h['rx_malformed']}/{h['rx_replayed']}")
        tasks = Table(title="tasks")
        for c in ("task", "kind", "mode", "overruns", "worst µs", "faults"):
            tasks.add_column(c)
        for x in h["tasks"]:
            tasks.add_row(x["name"], x["kind"], x["mode_name"], str(x["overruns"]), str(x["worst_us"]),
                          str(x["faults"]))
        return Group(t, link, tasks)
    return Group(t, link)


class View:
    """Headless lines or the live rich view, fed events."""

    def __init__(self, session: Session, headless: bool, title: str, out=None):
        self.session = session
        self.headless = headless
        self.title = title
        self.out = out or outputs.stdout()
        self._live = None
        self._last = 0.0

    def __enter__(self):
        if not self.headless:
            from rich.console import Console
            from rich.live import Live

            # the live view writes through the same stream: a full terminal or pipe
            # is an output error, not the port going away
            self._live = Live(render(self.session, time.time(), self.title), refresh_per_second=8,
                              screen=False, auto_refresh=False, console=Console(file=self.out))
            self._live.__enter__()
        return self

    def __exit__(self, *exc):
        if self._live is not None:
            self.update(force=True)
            self._live.__exit__(*exc)
        return False

    def event(self, ev: Event) -> None:
        if self.headless:
            self.out.write(describe(ev, self.session.layout) + "\n")
            self.out.flush()

    def update(self, now: float | None = None, force: bool = False) -> None:
        if self._live is None:
            return
        now = time.time() if now is None else now
        if force or now - self._last >= 0.12:
            self._last = now
            self._live.update(render(self.session, now, self.title), refresh=True)
