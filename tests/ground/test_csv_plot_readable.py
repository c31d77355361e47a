"""`fsw log2csv` and `fsw plot` read by people: unique columns with units
(an element named `time` no longer collides with the time column), rows in
target-time order (streams interleave and batches carry past samples), a
target reset a new boot rather than sorted into the old one; plots in
seconds, booleans shaded where true, state names that never overlap."""

from __future__ import annotations

import csv
import io
import itertools
import shutil
from pathlib import Path

import pytest

from conftest import run_fsw
from fswkit.ground import logs
from fswkit.link import wire
from fswkit.link.log import RX, LogReader, LogWriter
from fswkit.link.session import Session
from support.linkfw import build_native, simulated_link
from support.linkstream import TANK, hello, layout_of, tank_copy

TANK_HEADER = ["target time [s]", "host time [s]", "target boot", "from frame",
               "time", "state", "state name", "tankPressure", "valveOpen"]


def write_log(path: Path, layout, chunks: list[bytes], step_ns: int = 5_000_000) -> Path:
    w = LogWriter(str(path), layout)
    for i, data in enumerate(chunks):
        w.record(RX, 1_000_000_000_000 + i * step_ns, data)
    w.close()
    return path


def chunked(data: bytes, size: int = 64) -> list[bytes]:
    return [data[i:i + size] for i in range(0, len(data), size)]


def csv_rows(log: Path) -> tuple[list[str], list[dict]]:
    r = run_fsw("log2csv", str(log))
    assert r.code == 0, r.err
    return next(csv.reader(io.StringIO(r.out))), list(csv.DictReader(io.StringIO(r.out)))


def decoded(log: Path):
    reader = LogReader(str(log))
    session = Session(reader.layout)
    events = [ev for d, t, data in reader.records() if d == RX for ev in session.feed(data, t)]
    return reader.layout, events


# ---- the tank firmware's own link bytes ----------------------------------------------------


@pytest.fixture(scope="module")
def tank_link() -> bytes:
    if shutil.which("g++") is None:
        pytest.skip("no host C++ compiler")
    exe = build_native(TANK)
    return simulated_link(exe, 300, "a14=700")  # 3 s on the simulated clock


@pytest.fixture(scope="module")
def tank_log(tank_link, tmp_path_factory) -> Path:
    return write_log(tmp_path_factory.mktemp("log") / "tank.fswlog", layout_of(TANK), chunked(tank_link))


def test_tank_header_names_each_column_once_with_its_unit(tank_log):
    header, rows = csv_rows(tank_log)
    assert header == TANK_HEADER
    assert len(set(header)) == len(header)
    # the element `time` (G, in ms, stamped on the tank's Sensors) and the
    # target time (s) are two columns
    sensors = [r for r in rows if r["from frame"] == "Sensors"]
    assert len(sensors) == 150
    assert all(int(r["time"]) == round(float(r["target time [s]"]) * 1000) for r in sensors)
    assert {r["state name"] for r in rows} == {"TankVentControl"}


def test_rows_are_in_target_time_order_though_frames_arrive_out_of_it(tank_link, tank_log):
    layout, events = decoded(tank_log)
    arrived = [t for ev in events if ev.kind == "sample" for t, _ in ev.samples]
    # what made the complaint: a batch of Sensors carries samples older than
    # the Effectors frame sent before it
    assert any(b < a for a, b in itertools.pairwise(arrived))
    _, rows = csv_rows(tank_log)
    times = [float(r["target time [s]"]) for r in rows]
    assert times == sorted(times) and len(rows) == len(arrived) == 180
    assert {r["target boot"] for r in rows} == {"1"}
    assert sorted((round(t * 1000), f) for t, f in zip(times, (r["from frame"] for r in rows))) == sorted(
        (round(t), layout.streams[ev.stream].region.name) for ev in events if ev.kind == "sample"
        for t, _ in ev.samples)
    # whole milliseconds print exactly, in seconds
    assert rows[1]["target time [s]"] == "0.010" and rows[1]["from frame"] == "Effectors"


def test_a_target_reset_starts_a_new_boot(tank_link, tmp_path):
    log = write_log(tmp_path / "reset.fswlog", layout_of(TANK), chunked(tank_link) * 2)
    r = run_fsw("log2csv", str(log))
    assert r.code == 0 and "360 rows from 2 boots of the target" in r.err, r.err
    rows = list(csv.DictReader(io.StringIO(r.out)))
    boots = [int(x["target boot"]) for x in rows]
    assert boots == sorted(boots) and boots.count(1) == boots.count(2) == 180
    for b in (1, 2):
        times = [float(x["target time [s]"]) for x in rows if x["target boot"] == str(b)]
        assert times == sorted(times) and times[0] == 0.0
    second = rows[180]
    # a reset target's state vector starts afresh: nothing carried over from boot 1
    assert second["target boot"] == "2" and second["from frame"] == "Sensors" and second["valveOpen"] == ""


def test_a_reset_whose_hello_was_lost_still_starts_a_new_boot(tank_link, tmp_path):
    after_hello = tank_link[tank_link.index(b"\x00") + 1:]  # the reset target's hello frame lost
    log = write_log(tmp_path / "lost.fswlog", layout_of(TANK), chunked(tank_link) + chunked(after_hello))
    _, rows = csv_rows(log)
    assert [x["target boot"] for x in rows] == ["1"] * 180 + ["2"] * 180
    assert float(rows[180]["target time [s]"]) == 0.0


def test_table_is_values_not_text(tank_log):
    layout, events = decoded(tank_log)
    columns, rows = logs.table(layout, events)
    assert columns == TANK_HEADER
    first = next(rows)
    assert first[0] == 0.0 and isinstance(first[1], float) and first[2:4] == (1, "Sensors")
    assert first[4] == 0 and first[5] == 1 and first[6] == "TankVentControl"
    assert isinstance(first[7], float) and first[8] is None  # no Effectors sample yet
    assert all(isinstance(row[8], bool) for row in rows)


def test_fsw_plot_of_the_tank_in_seconds(tank_log, tmp_path):
    png = tmp_path / "p.png"
    r = run_fsw("plot", str(tank_log), "-e", "tankPressure", "valveOpen", "state", "-o", str(png))
    assert r.code == 0 and "330 points, 0 state transitions" in r.err, r.err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    layout, events = decoded(tank_log)
    data = logs.plot_data(layout, events, ["tankPressure", "valveOpen", "state"])
    fig, unlabelled = logs.figure(layout, data, ["tankPressure", "valveOpen", "state"], "tank")
    strip, pressure, valve, state = fig.axes
    assert state.get_xlabel() == "target time [s]" and unlabelled == 0
    assert data.span == (0.0, 2.98)  # 3 s of samples, in seconds
    assert [t.get_text() for t in state.get_yticklabels()] == ["TankVentControl"]
    assert valve.get_ylabel() == "valveOpen\n(shaded: true)"


# ---- a project whose elements are named like the columns ---------------------------------

SV = """\
[Sensors]
U64 time
U32 target
F64 time_s
F64 volts
[Effectors]
bool frame
U8 boot
"""
SM = """\
[state_vector]
U64  time    @alias G
U32  target  @alias S
F64  time_s  @read_only
F64  volts   @read_only
bool frame
U8   boot

[Wait]
.step
    frame = time_s > 775
    boot = 1
    time_s > 900: -> Vent

[Vent]
.step
    frame = true
    time_s < 700: -> Wait
"""


@pytest.fixture(scope="module")
def clash(tmp_path_factory) -> Path:
    """The tank with its elements renamed after the CSV's columns: `time`,
    `time_s`, `boot`, `frame`, `target` (the state, so `target name` too),
    and an uncalibrated analog input `volts`."""
    project = tank_copy(tmp_path_factory.mktemp("clash"))
    (project / "tank.sv").write_text(SV)
    (project / "tank.sm").write_text(SM)
    (project / "tank.aio").write_text("i A0 time_s scale=250 offset=-125\ni A1 volts\n")
    (project / "tank.dio").write_text("o 4 frame\n")
    app = (project / "tank.app").read_text()
    (project / "tank.app").write_text(app.replace("\nvalveOpen\n", "\nframe\n"))
    for name in ("tank_770.ss", "tank_counter.ss", "tank_typo.sm", "tank.ss"):
        (project / name).unlink()
    return project


def clash_frames(layout, count: int, period: int = 1) -> list[bytes]:
    """A hello, then Sensors every 20 ms (time = the target time, `target`
    changing every `period` samples) and Effectors every 40 ms, 10 ms
    behind: Wait, Vent, Wait... and `frame` true every other time."""
    sensors, effectors = layout.streams[0].region, layout.streams[1].region
    out = [hello(layout, 0, 0)]
    seq = 1
    for k in range(count):
        t = 20 * k
        out.append(wire.downlink(0x80, seq, t, sensors.struct.pack(t, 1 + (k // period) % 2, 700.0 + k, 2.5)))
        seq += 1
        if k % 2:
            out.append(wire.downlink(0x81, seq, t - 10, effectors.struct.pack(k % 4 == 1, 7)))
            seq += 1
    return out


def test_elements_named_like_columns_get_their_own_columns(clash, tmp_path):
    layout = layout_of(clash)
    assert [e.name for e in layout.elements] == ["time", "target", "time_s", "volts", "frame", "boot"]
    log = write_log(tmp_path / "clash.fswlog", layout, clash_frames(layout, 20, period=5))
    header, rows = csv_rows(log)
    assert header == ["target time [s]", "host time [s]", "target boot", "from frame", "time", "target",
                      "target name", "time_s", "volts [V]", "frame", "boot"]
    assert len(set(header)) == len(header)
    row = rows[6]  # Sensors at 80 ms (k = 4), after Effectors at 50 ms (k = 3)
    assert (row["target time [s]"], row["from frame"], row["time"], row["target"], row["target name"],
            row["time_s"], row["volts [V]"], row["frame"], row["boot"]) == (
        "0.080", "Sensors", "80", "1", "Wait", "704.0", "2.5", "0", "7")
    # Effectors at 10 ms arrived after Sensors at 20 ms: the rows are in time order
    assert [r["target time [s]"] for r in rows[:4]] == ["0.000", "0.010", "0.020", "0.040"]
    assert [r["from frame"] for r in rows[:4]] == ["Sensors", "Effectors", "Sensors", "Sensors"]


def test_columns_stay_unique_whatever_the_elements_are_named():
    from fswkit.link.layout import from_dict

    names = ["time", "time_s", "host", "target", "boot", "frame", "from", "name", "s", "V", "target_boot",
             "host_time_s", "from_frame", "snapshot"]
    d = {"schema": 1, "name": "x", "sv_size": 4 * len(names), "time_unit": "us", "rate": 100,
         "elements": [{"name": n, "type": "U32", "offset": 4 * i, "region": "R"} for i, n in enumerate(names)],
         "regions": [{"name": "R", "offset": 0, "size": 4 * len(names)}], "streams": [], "tasks": [],
         "writable": [], "states": {n: {"1": "A"} for n in ("target", "from", "time", "host")},
         "analog": {n: {"pin": "A0", "scale": 1.0, "offset": 0.0} for n in ("time", "s", "target")},
         "health_payload": 0}
    cols = logs.table_columns(from_dict(d))
    assert len(cols) == len(set(cols)) == 4 + len(names) + 4
    assert "time [V]" in cols and "target [V]" in cols and "target name" in cols


# ---- fsw plot: many close transitions ---------------------------------------------------------


def overlaps(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


@pytest.mark.parametrize("count, period", [(300, 1), (60, 1), (40, 3), (12, 1)])
def test_state_names_never_overlap(clash, tmp_path, count, period, monkeypatch):
    """The figure `fsw plot` draws and writes (logs.figure's, kept as the
    command made it: one figure, its layout the one written) has every
    name where it overlaps no other, inside the page, above the panels."""
    layout = layout_of(clash)
    log = write_log(tmp_path / "many.fswlog", layout, clash_frames(layout, count, period))
    layout, events = decoded(log)
    elements = ["time_s", "frame", "target", "volts"]
    data = logs.plot_data(layout, events, elements)
    assert len(data.transitions) == (count - 1) // period
    drawn = []
    figure = logs.figure

    def keep(*args, **kw):
        drawn.append(figure(*args, **kw))
        return drawn[-1]
    monkeypatch.setattr(logs, "figure", keep)
    out = tmp_path / "many.svg"
    r = run_fsw("plot", str(log), "-e", *elements, "-o", str(out))
    assert r.code == 0 and f"{len(data.transitions)} state transitions" in r.err, r.err
    assert out.read_text().startswith("<?xml")
    [(fig, unlabelled)] = drawn
    assert (f"{unlabelled} state names left out" in r.err) == bool(unlabelled)
    renderer = fig.canvas.get_renderer()
    labels = [t for t in fig.axes[0].texts if t.get_gid() == "state-label"]
    shown = [t for t in labels if t.get_visible()]
    assert len(labels) == len(data.transitions) and len(shown) + unlabelled == len(labels)
    assert shown and (unlabelled == 0 or count == 300)
    boxes = [t.get_window_extent(renderer) for t in shown]
    for a, b in itertools.combinations(boxes, 2):
        assert not overlaps(a, b)
    page = fig.bbox
    assert all(page.x0 <= b.x0 and b.x1 <= page.x1 and page.y0 <= b.y0 and b.y1 <= page.y1 for b in boxes)
    # the names sit above the panels, not over the data
    panels_top = max(ax.get_window_extent(renderer).y1 for ax in fig.axes[1:])
    assert all(b.y0 >= panels_top for b in boxes)
    if unlabelled:
        assert f"{unlabelled} more state names" in fig.axes[0].get_title(loc="right")


def test_booleans_are_shaded_where_true_and_axes_say_units(clash, tmp_path):
    layout = layout_of(clash)
    log = write_log(tmp_path / "b.fswlog", layout, clash_frames(layout, 41))
    layout, events = decoded(log)
    elements = ["frame", "volts", "time_s", "target"]
    data = logs.plot_data(layout, events, elements)
    fig, _ = logs.figure(layout, data, elements, "b")
    _, frame, volts, time_s, target = fig.axes
    assert frame.get_ylabel() == "frame\n(shaded: true)" and volts.get_ylabel() == "volts [V]"
    assert time_s.get_ylabel() == "time_s" and target.get_xlabel() == "target time [s]"
    assert [t.get_text() for t in target.get_yticklabels()] == ["Wait", "Vent"]
    # no line through the values: only the transitions' vertical markers
    assert all(len(line.get_xdata()) == 2 and line.get_xdata()[0] == line.get_xdata()[1] for line in frame.lines)
    (spans,) = frame.collections
    # `frame` is true at 10, 90, 170, ... ms (every 80 ms) until the next
    # Effectors sample 40 ms later: ten stretches of 0.04 s
    widths = [p.get_extents().width for p in spans.get_paths()]
    starts = [p.get_extents().x0 for p in spans.get_paths()]
    assert len(widths) == 10 and widths == pytest.approx([0.04] * 10)
    assert starts == pytest.approx([0.01 + 0.08 * i for i in range(10)])


def test_a_reset_in_a_plot_follows_the_last_boot(tank_link, tmp_path):
    log = write_log(tmp_path / "reset.fswlog", layout_of(TANK), chunked(tank_link) * 2)
    layout, events = decoded(log)
    data = logs.plot_data(layout, events, ["time"])
    xs, values, boots = data.series["time"]
    assert xs == sorted(xs) and boots.count(1) == boots.count(2) == 150
    assert len(data.resets) == 1 and data.resets[0] == pytest.approx(2.98 + 0.1)
    fig, _ = logs.figure(layout, data, ["time"], "reset")
    assert "reset: boot 2" in [t.get_text() for t in fig.axes[0].texts]
    r = run_fsw("plot", str(log), "-e", "time", "-o", str(tmp_path / "r.pdf"))
    assert r.code == 0 and "2 boots of the target, end to end" in r.err, r.err
