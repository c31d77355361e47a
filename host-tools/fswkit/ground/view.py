"""The monitor's live view (rich) and its headless lines, fed decoded
events: used by `fsw monitor` and `fsw replay`. The view fits the terminal:
each section has forms from full down to one line, and the lines are shared
out by priority (docs/cli.md, fsw monitor)."""

from __future__ import annotations

import math
import time
from collections import deque

from fswkit import outputs
from fswkit.link.layout import Layout
from fswkit.link.session import Event, Session, describe
from fswkit.usage import UsageError, unknown_name
from fswkit.web.source import reset_words

SPARK_VALUES = 60  # the values a sparkline keeps and shows at most
STALE_AFTER = 2.0  # seconds without a frame before the link is marked STALE
BLOCKS = "▁▂▃▄▅▆▇█"
NOT_A_NUMBER = "·"  # a NaN or infinite value in a sparkline
GAP = "   "  # between the items of a line and the columns of a grid

_LABEL, _ALARM, _STALE = "dim", "bold red", "bold white on red"
_NOTE, _TITLE, _HEAD = "bold black on yellow", "bold", "bold"


# ---- sparklines -------------------------------------------------------------------------

class Spark:
    """The recent values of one element; `streamed`: whether a telemetry
    stream carries it (else only snapshots bring it a value)."""

    __slots__ = ("name", "values", "streamed")

    def __init__(self, name: str, streamed: bool = True, values=()):
        self.name, self.streamed = name, streamed
        self.values: deque = deque(values, maxlen=SPARK_VALUES)


def spark_elements(layout: Layout, names, whose: str = "the project's") -> tuple[str, ...]:
    """The elements asked for sparklines, each once, in the order asked;
    UsageError naming the elements (`whose`: the project's, the log's) for
    a name that is not one."""
    for n in names:
        if layout.element(n) is None:
            raise UsageError("--spark: " + unknown_name("element", [n], [e.name for e in layout.elements], whose))
    return tuple(dict.fromkeys(names))


def sparkline(values, width: int = SPARK_VALUES) -> str:
    """The last `width` values as blocks ▁..█, scaled between their least
    and greatest (all ▄ when they are equal); NaN and infinities as ·."""
    vals = list(values)[-width:] if width > 0 else []
    finite = [float(v) for v in vals if math.isfinite(v)]
    if not finite:
        return NOT_A_NUMBER * len(vals)
    lo, hi = min(finite) * 0.5, max(finite) * 0.5  # halved: hi - lo cannot overflow
    span = hi - lo
    out = []
    for v in vals:
        if not math.isfinite(v):
            out.append(NOT_A_NUMBER)
        elif span == 0:
            out.append(BLOCKS[3])
        else:
            out.append(BLOCKS[min(7, max(0, int((v * 0.5 - lo) / span * 7 + 0.5)))])
    return "".join(out)


def _number(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(int(v))


# ---- lines ------------------------------------------------------------------------------

def _line(*parts, width: int, strip: bool = True):
    """A Text of (text, style) parts, cut to `width` cells with an ellipsis
    (and its trailing blanks, unless `strip` is false)."""
    from rich.text import Text

    t = Text(no_wrap=True, overflow="ellipsis", end="\n")
    for p in parts:
        if isinstance(p, Text):
            t.append_text(p)
        elif isinstance(p, tuple):
            t.append(*p)
        else:
            t.append(p)
    if strip:
        t.rstrip()
    if t.cell_len > width:
        t.truncate(width, overflow="ellipsis")
    return t


def _item(*parts):
    from rich.text import Text

    t = Text()
    for p in parts:
        if isinstance(p, tuple):
            t.append(*p)
        else:
            t.append(p)
    return t


def _kv(label: str, value, alarm: bool = False):
    return _item((label + " ", _LABEL), (str(value), _ALARM if alarm else ""))


def _flow(items, width: int, lines: int, more=None):
    """Items packed left to right into at most `lines` lines of `width`,
    in order; what does not fit is left out (`more(n)`: an item saying how
    many, kept on the last line)."""
    from rich.text import Text

    rows: list[list] = []
    for it in items:
        if rows and sum(x.cell_len for x in rows[-1]) + len(GAP) * len(rows[-1]) + it.cell_len <= width:
            rows[-1].append(it)
        elif len(rows) < lines:
            rows.append([it])
        else:
            break
    left = len(items) - sum(len(r) for r in rows)
    tail = None
    if left and more is not None and rows:
        last = rows[-1]
        while True:
            tail = more(left)
            used = sum(x.cell_len for x in last) + len(GAP) * len(last)
            if used + tail.cell_len <= width or len(last) <= 1:
                break
            last.pop()
            left += 1
            tail = None
    out = []
    for i, r in enumerate(rows):
        t = Text(no_wrap=True, overflow="ellipsis", end="\n")
        for j, it in enumerate(r + ([tail] if tail is not None and i == len(rows) - 1 else [])):
            if j:
                t.append(GAP)
            t.append_text(it)
        if t.cell_len > width:
            t.truncate(width, overflow="ellipsis")
        out.append(t)
    return out


def _pack(items, width: int):
    """The items' lines when all of them are shown."""
    return _flow(items, width, len(items) or 1)


def _grid(cells, width: int, cols: int, rows: int):
    """Cells (Texts of equal width) down then across, `cols` columns."""
    from rich.text import Text

    out = []
    for r in range(rows):
        t = Text(no_wrap=True, overflow="ellipsis", end="\n")
        for c in range(cols):
            k = c * rows + r
            if k >= len(cells):
                break
            if c:
                t.append(GAP)
            t.append_text(cells[k])
        t.rstrip()
        if t.cell_len > width:
            t.truncate(width, overflow="ellipsis")
        out.append(t)
    return out


def _columns(cell_width: int, width: int, most: int) -> int:
    return max(1, min(most, (width + len(GAP)) // (cell_width + len(GAP))))


# ---- the sections -----------------------------------------------------------------------

class _Section:
    """A section's forms, by name: (height, build() -> lines); `partial`:
    build(k) for heights between its least and its greatest form."""

    def __init__(self, forms: dict, partial=None):
        self.forms = forms
        self.partial = partial
        self.least = min(h for h, _ in forms.values())
        self.most = max(h for h, _ in forms.values())
        self.k = self.least

    def lines(self, k: int):
        best = None  # the tallest form that fits, the later one of equals
        for h, b in self.forms.values():
            if h <= k and (best is None or h >= best[0]):
                best = (h, b)
        if self.partial is not None and (best is None or best[0] < k) and k < self.most:
            return self.partial(k)
        return best[1]() if best is not None else []


def _title(title: str, note: str, width: int):
    if not note:
        return _line((title, _TITLE), width=width)
    tag = f" {note} "
    room = width - len(tag) - 2
    if room < 8:
        return _line((tag, _NOTE), width=width, strip=False)
    head = title if len(title) <= room else title[:room - 1] + "…"
    return _line((head, _TITLE), "  ", (tag, _NOTE), width=width, strip=False)


def _link_items(session: Session, now: float, last_frame, started):
    st, ws = session.stats, session.deframer.stats
    # the label and the age of the last frame are one item: never apart
    if last_frame is None:
        waited = now - started if started is not None else 0.0
        if waited > STALE_AFTER:
            first = _item(("link", _HEAD), " ", ("STALE", _STALE), f" no frame in {_age(waited)}")
        else:
            first = _item(("link", _HEAD), " no frame yet")
    else:
        age = max(0.0, now - last_frame)
        if age > STALE_AFTER:
            first = _item(("link", _HEAD), " ", ("STALE", _STALE), f" last frame {_age(age)} ago")
        else:
            first = _item(("link", _HEAD), " ", ("last frame ", _LABEL), f"{_age(age)} ago")
    items = [first]
    items.append(_item(f"{session.frames_per_second(now):.1f}", (" frames/s", _LABEL)))
    items.append(_kv("lost", f"{st.lost} in {st.gaps} gaps" if st.lost else "0", st.lost > 0))
    lat = f"{session.latency * 1000:.1f} ms" if session.latency is not None else "—"
    items.append(_kv("latency", lat))
    h, hello = session.health, session.hello
    cause = h["reset_cause"] if h is not None else hello["reset_cause"] if hello is not None else None
    if cause is not None:
        items.append(_kv("reset", reset_words(cause)))
    if st.restarts:
        items.append(_kv("target restarts", st.restarts, True))
    for p in (h or {}).get("pyro", ()):  # each charge's status: an open igniter stands out
        items.append(_kv(f"pyro {p['name']}", p["words"], p["continuity"] is False or p["firing"]))
    for s in (h or {}).get("sensors", ()):  # each part's health: a fault stands out
        items.append(_kv(f"sensor {s['name']}", s["words"], s["fault"]))
    if hello is None:
        items.append(_item(("waiting for hello", "yellow")))
    else:
        items.append(_kv("schema", "ok" if session.schema_ok or hello["schema_ok"] else "MISMATCH",
                         not hello["schema_ok"]))
    items += [_kv("CRC errors", ws.crc_errors, ws.crc_errors > 0),
              _kv("framing errors", ws.framing_errors, ws.framing_errors > 0),
              _kv("frames", st.frames)]
    if st.undecoded:
        items.append(_kv("undecoded", st.undecoded, True))
    if h is not None:
        items += [_kv("target dropped", h["dropped"], h["dropped"] > 0),
                  _kv("late cycles", h["late"], h["late"] > 0)]
    items.append(_kv("oversized", ws.oversized, ws.oversized > 0))
    if h is not None:
        items += [_kv("uplink ok", h["rx_ok"]), _kv("refused", h["rx_refused"], h["rx_refused"] > 0),
                  _kv("uplink crc/malformed/replayed", f"{h['rx_crc']}/{h['rx_malformed']}/{h['rx_replayed']}",
                      h["rx_crc"] + h["rx_malformed"] + h["rx_replayed"] > 0)]
    return items


def _age(s: float) -> str:
    if s < 10:
        return f"{s:.1f} s"
    if s < 120:
        return f"{s:.0f} s"
    if s < 7200:
        return f"{int(s // 60)} min {int(s % 60)} s"
    return f"{int(s // 3600)} h {int(s % 3600 // 60)} min"


def _link(session, now, last_frame, started, width):
    items = _link_items(session, now, last_frame, started)
    full = len(_pack(items, width))
    forms = {"line": (1, lambda: _flow(items, width, 1)), "full": (full, lambda: _pack(items, width))}
    return _Section(forms, partial=lambda k: _flow(items, width, k))


def _sparks(session: Session, sparks, width):
    if not sparks:
        return None
    lay = session.layout
    nw = max(len(s.name) for s in sparks)
    cur = {s.name: lay.show(s.name, session.values.get(s.name)) for s in sparks}
    cw = max(len(c) for c in cur.values())

    def span(vals):
        finite = [v for v in vals if math.isfinite(v)]
        return f"min {_number(min(finite))}  max {_number(max(finite))}" if finite else ""

    # the bars share one width, so the current values line up: as long as
    # the room allows up to SPARK_VALUES, less the min and max if they crowd it
    rw = max(len(span(s.values)) for s in sparks)
    bar = min(SPARK_VALUES, width - nw - 2 - cw - len(GAP) - rw)
    with_span = bar >= 12
    if not with_span:
        bar = max(1, min(SPARK_VALUES, width - nw - 2 - cw))

    def one(s: Spark):
        if not s.values:
            why = "no value yet" if s.streamed else "not in a stream: a value with each snapshot only"
            return _line((s.name.ljust(nw), _HEAD), " ", cur[s.name], GAP, (why, _LABEL), width=width)
        shown = list(s.values)[-bar:]
        parts = [(s.name.ljust(nw), _HEAD), " ", (sparkline(shown, bar).ljust(bar), "cyan"), " ",
                 (cur[s.name].rjust(cw), "bold")]
        if with_span:
            parts += [GAP, (span(shown), _LABEL)]
        return _line(*parts, width=width)

    def some(k):
        if k >= len(sparks):
            return [one(s) for s in sparks]
        rest = [_kv(s.name, cur[s.name]) for s in sparks[k - 1:]]
        return [one(s) for s in sparks[:k - 1]] + _flow([_item(("no room for sparklines:", _LABEL))] + rest,
                                                       width, 1)

    return _Section({"all": (len(sparks), lambda: some(len(sparks)))}, partial=some)


def _elements(session: Session, sparks, width):
    lay = session.layout
    els = lay.elements
    if not els:
        return _Section({"line": (1, lambda: [_line(("elements", _HEAD), " none", width=width)])})
    shown = {e.name: lay.show(e.name, session.values.get(e.name)) for e in els}
    nw = max(len(e.name) for e in els)
    vw = max(8, max(len(v) for v in shown.values()))
    n = len(els)

    def detail(name):
        v = session.values.get(name)
        cal = lay.analog.get(name)
        if cal is not None and isinstance(v, float) and cal["scale"]:
            volts = (v - cal["offset"]) / cal["scale"]
            return f"pin {cal['pin']}: {volts:.3f} V  (= V×{cal['scale']:g} {cal['offset']:+g})"
        if name in lay.states:
            return "state"
        if name in lay.writable:
            return "writable"
        return ""

    def table():
        tw = max(4, max(len(e.type) for e in els))
        out = [_line(("element".ljust(nw) + GAP + "type".ljust(tw) + GAP + "value".rjust(vw) + GAP + "detail",
                      _LABEL), width=width)]
        for e in els:
            out.append(_line((e.name.ljust(nw), _HEAD), GAP, (e.type.ljust(tw), _LABEL), GAP,
                             shown[e.name].rjust(vw), GAP, (detail(e.name), _LABEL), width=width))
        return out

    def cell(e):
        return _item((e.name.ljust(nw), _HEAD), " ", shown[e.name].rjust(vw))

    cw = nw + 1 + vw
    cols = _columns(cw, width, 6)
    rows = -(-n // cols)

    # in less room: the elements of the sparklines, the states, the analog and
    # writable ones first, then the others in their order
    spark_names = [s.name for s in sparks]
    rank = {e.name: (0 if e.name in spark_names else 1 if e.name in lay.states else
                     2 if e.name in lay.analog else 3 if e.name in lay.writable else 4, e.index) for e in els}
    chosen = sorted(els, key=lambda e: rank[e.name])

    def more(left):
        return _item((f"+{left} more", _LABEL))

    def flow():
        items = [_kv(e.name, shown[e.name]) for e in chosen]
        items[0] = _item(("elements ", _HEAD), items[0])
        return _flow(items, width, 1, more)

    def some(k):
        if k <= 1:
            return flow()
        m = min(n, (k - 1) * cols)
        picked = sorted(chosen[:m], key=lambda e: e.index)
        r = -(-m // cols)
        out = _grid([cell(e) for e in picked], width, cols, r)
        left = n - m
        if left:
            names = ", ".join(e.name for e in chosen[m:])
            out.append(_line((f"+{left} more: {names}", _LABEL), width=width))
        return out

    forms = {"line": (1, flow), "grid": (rows, lambda: _grid([cell(e) for e in els], width, cols, rows))}
    if nw + 4 + vw + 3 * len(GAP) + 8 <= width:
        forms["table"] = (n + 1, table)
    return _Section(forms, partial=some)


def _tasks(session: Session, width):
    lay = session.layout
    h = session.health
    if h is None:
        names = ", ".join(n for n, _ in lay.tasks)
        return _Section({"line": (1, lambda: [_line(("tasks", _HEAD), " ", ("waiting for a health frame", "yellow"),
                                                    GAP, (f"{len(lay.tasks)}: {names}", _LABEL), width=width)])})
    tasks = h["tasks"]
    if not tasks:
        return _Section({"line": (1, lambda: [_line(("tasks", _HEAD), " none", width=width)])})
    nw = max(4, max(len(x["name"]) for x in tasks))
    kw = max(4, max(len(x["kind"]) for x in tasks))

    def summary():
        count: dict[str, int] = {}
        for x in tasks:
            m = "ok" if x["mode_name"] == "enabled" else x["mode_name"]
            count[m] = count.get(m, 0) + 1
        modes = ", ".join(f"{c} {m}" for m, c in sorted(count.items(), key=lambda mc: mc[0] != "ok"))
        items = [_item(("tasks", _HEAD), " ", (modes, _ALARM if count.get("safed") else ""))]
        over = [x for x in tasks if x["overruns"]]
        faults = [x for x in tasks if x["faults"]]
        if over:
            items.append(_kv("overruns", f"{sum(x['overruns'] for x in over)} ("
                             + ", ".join(x["name"] for x in over) + ")", True))
        if faults:
            items.append(_kv("faults", f"{sum(x['faults'] for x in faults)} ("
                             + ", ".join(x["name"] for x in faults) + ")", True))
        worst = max(tasks, key=lambda x: x["worst_us"])
        items.append(_kv("worst", f"{worst['worst_us']} µs ({worst['name']})"))
        return _flow(items, width, 1)

    def mode_style(x):
        return _ALARM if x["mode_name"] == "safed" else _LABEL if x["mode_name"] == "disabled" else ""

    def table():
        head = (f"{'task':<{nw}}{GAP}{'kind':<{kw}}{GAP}{'mode':<8}{GAP}{'overruns':>8}{GAP}{'worst µs':>8}"
                f"{GAP}{'faults':>6}")
        out = [_line((head, _LABEL), width=width)]
        for x in tasks:
            out.append(_line((x["name"].ljust(nw), _HEAD), GAP, (x["kind"].ljust(kw), _LABEL), GAP,
                             (x["mode_name"].ljust(8), mode_style(x)), GAP,
                             (f"{x['overruns']:>8}", _ALARM if x["overruns"] else ""), GAP,
                             f"{x['worst_us']:>8}", GAP, (f"{x['faults']:>6}", _ALARM if x["faults"] else ""),
                             width=width))
        return out

    ww = max(len(str(x["worst_us"])) for x in tasks)

    def cell(x):
        t = _item((x["name"].ljust(nw), _HEAD), " ", (x["mode_name"].ljust(8), mode_style(x)), " ",
                  f"{x['worst_us']:>{ww}} µs")
        if x["overruns"]:
            t.append(f" over {x['overruns']}", _ALARM)
        if x["faults"]:
            t.append(f" faults {x['faults']}", _ALARM)
        return t

    cells = [cell(x) for x in tasks]
    cw = max(c.cell_len for c in cells)
    for c in cells:
        c.pad_right(cw - c.cell_len)
    cols = _columns(cw, width, len(tasks))
    rows = -(-len(tasks) // cols)
    forms = {"line": (1, summary)}
    if rows > 1 or cols >= len(tasks):
        forms["grid"] = (rows, lambda: _grid(cells, width, cols, rows))
    if nw + kw + 8 + 8 + 8 + 6 + 5 * len(GAP) <= width:
        forms["table"] = (len(tasks) + 1, table)
    return _Section(forms)


# ---- the view ---------------------------------------------------------------------------

def render(session: Session, now: float, title: str, size: tuple[int, int] = (80, 24), sparks=(),
           last_frame: float | None = None, note: str = "", started: float | None = None):
    """The live view for a console of `size` (width, height): never wider
    nor taller. `sparks`: Spark histories to draw; `last_frame`: when the
    last frame came (the clock of `now`), `started`: when the view began
    waiting for one; `note`: a word from the view's owner, on the title line."""
    from rich.console import Group
    from rich.text import Text

    width, height = max(1, int(size[0])), max(1, int(size[1]))
    sparks = list(sparks)
    link = _link(session, now, last_frame, started, width)
    spk = _sparks(session, sparks, width)
    els = _elements(session, sparks, width)
    tasks = _tasks(session, width)
    sections = [s for s in (link, spk, els, tasks) if s is not None]
    left = height - 1 - sum(s.k for s in sections)

    def grow(sec, to, partial=True):
        nonlocal left
        if sec is None or to is None or to <= sec.k:
            return
        if to - sec.k <= left:
            left -= to - sec.k
            sec.k = to
        elif partial and sec.partial is not None and left > 0:
            sec.k += left
            left = 0

    def form(sec, name):
        f = sec.forms.get(name) if sec is not None else None
        return f[0] if f is not None else None

    # what each section gains in turn, while there is room: all the
    # sparklines asked for, two lines of link figures, the tasks and the
    # elements in columns, every link figure, then the full tables
    grow(spk, spk.most if spk is not None else None)
    grow(link, 2)
    grow(tasks, form(tasks, "grid"), partial=False)
    grow(els, form(els, "grid"))
    grow(link, link.most)
    grow(tasks, form(tasks, "table"), partial=False)
    grow(els, form(els, "table"), partial=False)
    spaced = left >= len(sections)  # a blank line before each section

    lines = [_title(title, note, width)]
    for s in sections:
        if spaced:
            lines.append(Text("", end="\n"))
        lines += s.lines(s.k)
    return Group(*lines[:height])


class View:
    """Headless lines or the live rich view, fed events. Its owner sets
    `note` (shown on the title line) and calls update() every ~50 ms, frames
    or none: the age of the last frame counts up."""

    def __init__(self, session: Session, headless: bool, title: str, out=None, spark=()):
        self.session = session
        self.headless = headless
        self.title = title
        self.out = out or outputs.stdout()
        self._live = None
        self._last = 0.0
        self._now: float | None = None
        self._note = ""
        self._dirty = False
        self.last_frame: float | None = None  # host time of the last frame seen
        self.started: float | None = None  # the first update's time
        self._frames = 0
        self._fresh = False  # an event came since the last update
        lay = session.layout
        names = spark_elements(lay, spark)
        streamed = {n for st in lay.streams for n in st.region.names}
        self.sparks = [Spark(n, n in streamed) for n in names]
        by_name = {s.name: s for s in self.sparks}
        # per stream: (position in its samples' tuples, the history fed)
        self._feeds = {}
        for st in lay.streams:
            f = [(i, by_name[n].values) for i, n in enumerate(st.region.names) if n in by_name]
            if f:
                self._feeds[st.index] = f
        self._by_name = by_name

    @property
    def note(self) -> str:
        return self._note

    @note.setter
    def note(self, text: str | None) -> None:
        text = text or ""
        if text != self._note:
            self._note = text
            self._dirty = True

    def __enter__(self):
        if not self.headless:
            from rich.console import Console
            from rich.live import Live

            # the live view writes through the same stream: a full terminal or pipe
            # is an output error, not the port going away
            console = Console(file=self.out)
            self._live = Live(self._render(time.time(), console), refresh_per_second=8, screen=False,
                              auto_refresh=False, console=console)
            self._live.__enter__()
        return self

    def __exit__(self, *exc):
        if self._live is not None:
            self.update(self._now, force=True)
            self._live.__exit__(*exc)
        return False

    def event(self, ev: Event) -> None:
        if ev.host_time:
            self.last_frame = ev.host_time
            self._fresh = True
        if ev.kind == "sample":
            feed = self._feeds.get(ev.stream)
            if feed:
                for _, vals in ev.samples:
                    for i, hist in feed:
                        hist.append(vals[i])
        elif ev.kind == "snapshot" and self._by_name and ev.info.get("complete"):
            for s in self.sparks:
                if not s.streamed and s.name in ev.info["values"]:
                    s.values.append(ev.info["values"][s.name])
        if self.headless:
            self.out.write(describe(ev, self.session.layout) + "\n")
            self.out.flush()

    def update(self, now: float | None = None, force: bool = False) -> None:
        now = time.time() if now is None else now
        self._now = now
        if self.started is None:
            self.started = now
        frames = self.session.stats.frames
        if frames != self._frames:  # frames that made no event (before the schema was known) count too
            self._frames = frames
            if not self._fresh:
                self.last_frame = now
        self._fresh = False
        if self._live is None:
            return
        if force or self._dirty or now - self._last >= 0.12:
            self._last = now
            self._dirty = False
            self._live.update(self._render(now, self._live.console), refresh=True)

    def _render(self, now: float, console):
        w, h = console.size
        return render(self.session, now, self.title, (w, h), self.sparks, self.last_frame, self._note,
                      self.started)
