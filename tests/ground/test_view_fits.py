"""The monitor's live view fits the terminal (never wider nor taller, every
section there in some form), draws sparklines of chosen elements, and
gives link figures one can trust: the age of the last frame, STALE after
2 s, the owner's note on the title line. No target needed."""

from __future__ import annotations

import io
import math

import pytest
from rich.cells import cell_len
from rich.console import Console

from conftest import EXAMPLES, run_fsw
from fswkit.autocode.protocol import HEALTH_PAYLOAD, HEALTH_TASK, HELLO_PAYLOAD
from fswkit.ground.view import STALE_AFTER, Spark, View, render, sparkline
from fswkit.link import wire
from fswkit.link.log import LogWriter
from fswkit.link.session import Session
from support.linkfw import tank_layout

ROCKET = EXAMPLES / "rocket"
T0 = 1000.0  # host time of the first frame
SIZES = [(80, 24), (100, 30), (60, 20), (200, 60)]


def rocket_view(spark=("altitude", "accel"), samples: int = 80):
    """A headless View of the rocket layout fed a hello, `samples` samples
    of its Flight stream (and some of Outputs), then a health frame with
    the task `nav` safed and three overruns of `mission`; returns (view, the
    host time of the last frame)."""
    lay = tank_layout(ROCKET)
    s = Session(lay)
    v = View(s, headless=True, title="rocket on /dev/ttyACM0", spark=spark, out=io.StringIO())

    def feed(frame, at):
        for ev in s.feed(frame, at):
            v.event(ev)

    feed(wire.downlink(wire.HELLO, 0, 0, HELLO_PAYLOAD.pack(wire.PROTOCOL, lay.schema, 0, 0, 1, 0, 0, 0x01, 0, 0)),
         T0)
    flight, outs = lay.streams[0].region, lay.streams[1].region
    seq, at = 1, T0
    for k in range(samples):
        at = T0 + 0.02 * k
        alt = 500 * math.sin(k / 12) + 500
        feed(wire.downlink(0x80, seq, 20 * k, flight.struct.pack(20 * k, 3, alt, 9.81 + math.cos(k / 5),
                                                                 101325.0 - 12 * alt)), at)
        seq += 1
        if k % 10 == 0:
            feed(wire.downlink(0x81, seq, 20 * k, outs.struct.pack(*[(0, 1)[i % 2] if e.type == "bool" else 2.5 if e.type == "F32" else 0x04
                                                                for i, e in enumerate(outs.elements)])), at)
            seq += 1
    head = HEALTH_PAYLOAD.pack(0, seq, 0, 1600, 2, 0x01, 3, 0, 0, 0, 0, 0, 0, 0)
    tasks = b"".join(HEALTH_TASK.pack(1 if n == "nav" else 2, 0, 3 if n == "mission" else 0, 120 + 37 * i)
                     for i, (n, _) in enumerate(lay.tasks))
    pyro = bytes([0x01 | 0x02] * len(lay.pyro))  # armed, continuity, not fired
    at += 0.01
    feed(wire.downlink(wire.HEALTH, seq, 20 * samples, head + tasks + pyro), at)
    return v, at


def shown(view: View, now: float, size, note: str = "") -> list[str]:
    w, h = size
    con = Console(record=True, width=w, height=h, file=io.StringIO())
    con.print(render(view.session, now, view.title, size, view.sparks, view.last_frame, note, T0))
    return con.export_text().splitlines()


def fits(lines, size) -> None:
    w, h = size
    assert len(lines) <= h, f"{len(lines)} lines on a terminal of {h}"
    wide = [ln for ln in lines if cell_len(ln) > w]
    assert not wide, wide


# ---- it fits ------------------------------------------------------------------------

@pytest.mark.parametrize("size", SIZES + [(40, 10), (30, 6), (20, 3), (1, 1)])
def test_never_wider_nor_taller_than_the_terminal(size):
    v, last = rocket_view()
    fits(shown(v, last + 0.05, size, note="reconnecting: the port went away"), size)
    fits(shown(View(Session(tank_layout(ROCKET)), True, "rocket", out=io.StringIO()), T0, size), size)


@pytest.mark.parametrize("size", SIZES)
def test_every_section_is_there_in_some_form(size):
    v, last = rocket_view()
    lines = shown(v, last + 0.05, size)
    text = "\n".join(lines)
    fits(lines, size)
    assert lines[0].startswith("rocket on /dev/ttyACM0")
    for figure in ("link", "last frame", "frames/s", "lost 0", "latency", "reset power-on"):
        assert figure in text, (figure, text)
    assert [ln for ln in lines if ln.startswith("altitude ") and "▁" in ln and "█" in ln]
    assert [ln for ln in lines if ln.startswith("accel ") and "min " in ln]
    assert "3 (Boost)" in text  # the state element, chosen first in little room
    assert "safed" in text and "mission" in text


def test_at_80x24_the_link_and_the_tasks_are_whole():
    v, last = rocket_view()
    text = "\n".join(shown(v, last + 0.05, (80, 24)))
    for figure in ("CRC errors 0", "framing errors 0", "late cycles 2", "uplink ok 3", "schema ok"):
        assert figure in text, figure
    for task in ("uplink", "sense", "nav", "mission", "log", "act", "downlink"):
        assert f"\n{task} " in text, task
    for element in ("time", "pressure", "armSwitch", "onPad"):
        assert element in text


def test_in_little_room_the_sections_collapse():
    v, last = rocket_view()
    lines = shown(v, last + 0.05, (60, 11))
    fits(lines, (60, 11))
    text = "\n".join(lines)
    assert any(ln.startswith("tasks 6 ok, 1 safed") for ln in lines), text
    assert "more" in text  # the elements left out, counted
    assert "altitude" in text and "accel" in text


def test_a_wide_terminal_shows_every_element_with_its_detail():
    v, last = rocket_view()
    text = "\n".join(shown(v, last + 0.05, (200, 60)))
    assert "pin A0:" in text and "writable" in text and "worst µs" in text
    # each charge's status from the health frame, in words
    assert "pyro drogue armed, continuity, not fired" in text and "pyro main armed, continuity, not fired" in text


def test_rendering_is_cheap():
    import time

    v, last = rocket_view()
    con = Console(record=True, width=80, height=24, file=io.StringIO())
    start = time.process_time()  # CPU time: a loaded machine's other work is not the view's cost
    for i in range(40):
        con.print(render(v.session, last + i / 8, v.title, (80, 24), v.sparks, v.last_frame, "", T0))
    assert (time.process_time() - start) / 40 < 0.03  # 8 views a second take a small part of one


# ---- sparklines ---------------------------------------------------------------------

def test_sparkline_of_a_known_series():
    assert sparkline(range(8)) == "▁▂▃▄▅▆▇█"
    assert sparkline([7, 0, 7]) == "█▁█"
    assert sparkline([5.0, 5.0, 5.0]) == "▄▄▄"  # no range: the middle
    assert sparkline([0, float("nan"), 1, float("inf")]) == "▁·█·"
    assert sparkline(range(100), 4) == "▁▃▆█"  # the last 4 values, scaled among themselves
    assert sparkline([-3.4e38, 3.4e38]) == "▁█"  # no overflow on the widest range
    assert sparkline([]) == ""


def test_the_view_keeps_the_last_60_values_of_each_sparkline():
    v, last = rocket_view(samples=80)
    alt, accel = v.sparks
    assert (alt.name, accel.name) == ("altitude", "accel")
    assert len(alt.values) == 60
    assert alt.values[-1] == pytest.approx(500 * math.sin(79 / 12) + 500, rel=1e-6)


def test_sparkline_line_shows_the_current_value_min_and_max():
    v, last = rocket_view()
    s = v.sparks[0]
    s.values.clear()
    s.values.extend(float(x) for x in range(8))
    v.session.values["altitude"] = 7.0
    line = next(ln for ln in shown(v, last, (80, 24)) if ln.startswith("altitude "))
    assert "▁▂▃▄▅▆▇█" in line and line.split()[2] == "7" and "min 0  max 7" in line


def test_a_sparkline_of_an_element_no_stream_carries():
    v, last = rocket_view(spark=("padPressure",))
    assert v.sparks[0].streamed is False
    text = "\n".join(shown(v, last, (80, 24)))
    assert "not in a stream" in text


def test_sparklines_and_views_made_by_hand():
    lay = tank_layout(ROCKET)
    s = Session(lay)
    lines = Console(record=True, width=80, height=24, file=io.StringIO())
    lines.print(render(s, 5.0, "rocket", (80, 24), [Spark("altitude", values=[1.0, 2.0])]))
    assert "▁█" in lines.export_text()


# ---- link figures -------------------------------------------------------------------

def test_stale_after_two_seconds_without_a_frame():
    v, last = rocket_view()
    fresh = "\n".join(shown(v, last + 1.0, (80, 24)))
    assert "STALE" not in fresh and "last frame 1.0 s ago" in fresh
    stale = "\n".join(shown(v, last + STALE_AFTER + 0.5, (80, 24)))
    assert "STALE last frame 2.5 s ago" in stale
    assert "0.0 frames/s" in stale
    assert "STALE" in "\n".join(shown(v, last + 3.0, (30, 6)))  # kept even in little room


def test_no_frame_yet_then_stale():
    s = Session(tank_layout(ROCKET))
    v = View(s, True, "rocket", out=io.StringIO())
    v.update(T0)
    assert v.started == T0
    first = "\n".join(shown(v, T0 + 1.0, (80, 24)))
    assert "no frame yet" in first and "waiting for hello" in first and "waiting for a health frame" in first
    assert "STALE no frame in 3.0 s" in "\n".join(shown(v, T0 + 3.0, (80, 24)))


def test_the_age_counts_up_with_update():
    v, last = rocket_view()
    for dt in (0.05, 0.5, 1.5):
        v.update(last + dt)
    assert v.last_frame == last  # updates without frames leave the last frame's time
    text = "\n".join(shown(v, v._now, (80, 24)))
    assert "last frame 1.5 s ago" in text


def test_lost_frames_are_shown():
    v, last = rocket_view()
    v.session.stats.lost, v.session.stats.gaps = 5, 2
    assert "lost 5 in 2 gaps" in "\n".join(shown(v, last, (80, 24)))


def test_the_note_is_on_the_title_line():
    v, last = rocket_view()
    note = "reconnecting: the port went away"
    for size in SIZES:
        lines = shown(v, last, size, note=note)
        assert note in lines[0], (size, lines[0])
    assert shown(v, last, (40, 10), note=note)[0].strip() == note  # the note before the title
    v.note = note
    assert v.note == note
    v.note = None  # the owner's "nothing to say"
    assert v.note == ""


# ---- the commands -------------------------------------------------------------------

def clean(r):
    assert "Traceback" not in r.err and "internal error" not in r.err, r.err
    return r


def test_unknown_spark_element_before_the_port_is_opened():
    r = clean(run_fsw("monitor", str(ROCKET), "--port", "/dev/no-such-port", "--spark", "altitude",
                      "--spark", "altitud"))
    assert r.code == 2, r.err
    assert "unknown element `altitud`" in r.err and "did you mean `altitude`" in r.err
    assert "elements are time, state, altitude" in r.err and "cannot open" not in r.err


def _tank_log(path):
    lay = tank_layout()
    w = LogWriter(str(path), lay)
    hello = HELLO_PAYLOAD.pack(wire.PROTOCOL, lay.schema, 0, 0, 0, 1, 0, 0, 0, 0)
    w.record(0, 1_000_000_000, wire.downlink(wire.HELLO, 0, 0, hello))
    region = lay.streams[0].region
    for k in range(1, 30):
        w.record(0, 1_000_000_000 + k * 10_000_000,
                 wire.downlink(0x80, k, 10 * k, region.struct.pack(10 * k, 2, 800.0 + k)))
    w.close()
    return path


def test_replay_with_sparklines(tmp_path, monkeypatch):
    monkeypatch.setenv("COLUMNS", "80")
    monkeypatch.setenv("LINES", "24")
    log = _tank_log(tmp_path / "tank.fswlog")
    r = clean(run_fsw("replay", str(log), "--speed", "0", "--spark", "tankPressure"))
    assert r.code == 0, r.err
    line = next(ln for ln in r.out.splitlines() if ln.startswith("tankPressure ") and "▁" in ln)
    assert line.rstrip().endswith("min 801  max 829") and " 829 " in line
    assert all(cell_len(ln) <= 80 for ln in r.out.splitlines())
    r = clean(run_fsw("replay", str(log), "--headless", "--spark", "tankPresure"))
    assert r.code == 2 and "unknown element `tankPresure`" in r.err and "valveOpen" in r.err
    assert r.out == ""


def test_at_80x24_the_rocket_shows_whole_as_docs_cli_md_says():
    """docs/cli.md counted the rocket's elements as 14 when it had 17: the
    count it gives is the rocket's, and the 80×24 view shows every one of
    them, every task and both sparklines, nothing left out."""
    import re

    from conftest import ROOT

    said = re.search(r"the rocket example \((\d+) elements, (\d+) tasks\) shows whole with two sparklines",
                     (ROOT / "docs" / "cli.md").read_text())
    assert said
    v, last = rocket_view()
    names = [e.name for e in v.session.layout.elements]
    tasks = ("uplink", "sense", "nav", "mission", "log", "act", "downlink")
    assert (len(names), len(tasks)) == (int(said.group(1)), int(said.group(2)))
    lines = shown(v, last + 0.05, (80, 24))
    fits(lines, (80, 24))
    words = " ".join(lines).split()
    assert [n for n in names if n not in words] == [] and "more" not in words
    assert all(t in words for t in tasks)
    assert sum(ln.startswith(("altitude ▁", "altitude ▂", "altitude ▃", "altitude ▄", "altitude ▅", "accel "))
               and "min" in ln for ln in lines) == 2
