"""The page's archive browser (its Archive tab) and the link's note and
latency in its header: the thinning of a long series to what a plot
shows (its least and greatest values kept), the archive routes on an
archive written here (errors in words, a long session capped), and in
headless Chromium (as tests/web/test_web_station.py drives it) the tank
firmware on a pty behind a station that archives: the header shows the
latency and the station's notes, and the archive tab lists the session,
draws it, lists its command and notes, and downloads it as `fsw log2csv`
writes it."""

from __future__ import annotations

import io
import json
import math
import os
import re
import time
import urllib.error
import urllib.request
from types import SimpleNamespace

import pytest

from conftest import run_fsw
from support.browser import browser, needs_chromium, press, served, wait_for  # noqa: F401 - browser: a fixture
from support.linkfw import TANK, PtyTarget, build_native, needs_cxx, tank_layout, volts_psi

pytestmark = pytest.mark.costly(10, waits=True)

RAW = 770  # 815.86 psi


# ---- the thinning ----------------------------------------------------------------------

def test_a_series_within_the_points_is_kept_whole_and_in_order():
    from fswkit.web.archive import decimate

    pairs = [(i * 0.01, float(i % 7)) for i in range(500)][::-1]
    xs, ys = decimate(pairs, 0.0, 10.0, 500)
    assert xs == [i * 0.01 for i in range(500)] and ys == [float(i % 7) for i in range(500)]
    # one more than the points: thinned, to the points at most
    xs, ys = decimate(pairs + [(5.001, 3.0)], 0.0, 10.0, 500)
    assert len(xs) <= 500 and xs == sorted(xs)


def test_a_long_series_is_capped_and_keeps_each_spans_least_and_greatest_value():
    from fswkit.web.archive import decimate

    n = 200_000
    ys = [math.sin(i / 3000) for i in range(n)]
    ys[123_457] = 50.0  # a spike one sample wide
    ys[7] = -50.0  # a dip at the start
    pairs = [(i / 1000, y) for i, y in enumerate(ys)]
    xs, out = decimate(pairs, 0.0, n / 1000, 1000)
    assert len(xs) <= 1000 and xs == sorted(xs)
    assert (123.457, 50.0) in zip(xs, out) and (0.007, -50.0) in zip(xs, out)
    # each span's extremes: the greatest and least value of the whole series are the thinned one's
    assert max(out) == max(ys) and min(out) == min(ys)
    for x, y in zip(xs, out):  # every point kept is a sample of the series, where it was
        assert ys[round(x * 1000)] == y
    # a range: only samples within it, the spike kept
    xs, out = decimate(pairs, 100.0, 150.0, 200)
    assert len(xs) <= 200 and 100.0 <= xs[0] and xs[-1] <= 150.0 and 50.0 in out


def test_gaps_stay_where_a_span_has_no_value_and_series_sampled_together_thin_alike():
    from fswkit.web.archive import Thinning, decimate

    pairs = [(i, None if 400 <= i < 600 else 1.0) for i in range(1000)]
    xs, ys = decimate(pairs, 0, 1000, 100)
    gaps = [x for x, y in zip(xs, ys) if y is None]
    assert gaps and all(400 <= x < 600 for x in gaps) and len(xs) <= 100
    t = Thinning(0, 1000, 100, k=2)
    t.feed((i, i, -i) for i in range(1000))
    (xa, ya), (xb, yb) = t.result()
    assert t.n == 1000 and len(xa) <= 100 and len(xb) <= 100
    assert max(ya) == 999 and min(yb) == -999


# ---- the routes, on an archive written here ----------------------------------------------------


def get(url: str) -> tuple[int, bytes]:
    try:
        with urllib.request.urlopen(url, timeout=30) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def get_json(url: str) -> tuple[int, dict]:
    status, body = get(url)
    return status, json.loads(body)


def archived(path, *, sessions: int, seconds: float, t0: float) -> None:
    """`sessions` sessions of the tank's layout, each `seconds` of Sensors
    frames (a batch of two samples every 40 ms; a pressure spike at the
    middle, a NaN at 1 s) and Effectors frames, a command and a note."""
    from fswkit.ground.archive import Archive
    from fswkit.link.session import Event

    lay = tank_layout()
    with Archive(str(path)) as a:
        for k in range(sessions):
            start = t0 + k * (seconds + 10)
            a.begin(layout=lay, project="tank", port="/dev/ttyX", baud=115200, started=start)
            frames = int(seconds / 0.04)
            for i in range(frames):
                ms = i * 40
                p = [800.0 + math.sin(i / 50), 800.0 + math.sin((i + 0.5) / 50)]
                if i == frames // 2:
                    p[1] = 900.0
                if i == 25:
                    p[0] = math.nan
                state = 1 if i < frames * 3 // 4 else 3
                host = start + ms / 1000 + 0.02
                a.event(Event("sample", 2 * i, ms, host, 0, [(ms, (ms, state, p[0])), (ms + 20, (ms + 20, state, p[1]))]))
                a.event(Event("sample", 2 * i + 1, ms, host, 1, [(ms, (i % 50 < 10,))]))
            a.command(who="web: 127.0.0.1", text="set valveOpen = true", op=1, args=b"", sent=start + 2, cmd_seq=1,
                      status=0, words="applied", acked=start + 2.012)
            a.note(start + 3, "the port went away (EIO); waiting for it to come back")
            a.tick(0)


def archive_app(path, live=None):
    from fswkit.web.app import create_app
    from fswkit.web.source import Source

    src = Source(tank_layout())
    if path is not None:
        src.station = SimpleNamespace(archive=SimpleNamespace(path=str(path), session=live), ignore_schema=False)
    return create_app(src)


def test_the_archive_routes_cap_a_long_session_and_refuse_in_words(tmp_path):
    path = tmp_path / "a.sqlite"
    t0 = time.time() - 3600
    archived(path, sessions=2, seconds=400.0, t0=t0)  # 20,000 samples of each Sensors element a session
    with served(archive_app(path, live=2)) as url:
        status, r = get_json(url + "api/archive/sessions")
        assert status == 200 and [s["id"] for s in r["sessions"]] == [1, 2]
        one, two = r["sessions"]
        assert not one["live"] and two["live"] and one["frames"] == 20000 and one["commands"] == 1
        assert one["ended"] is not None and abs(one["duration"] - (one["ended"] - one["started"])) < 1e-6

        # the session alone: its elements and span
        status, r = get_json(url + "api/archive/1")
        assert status == 200 and r["series"] == [] and r["session"]["name"] == "tank"
        assert [e["name"] for e in r["session"]["elements"]] == ["time", "state", "tankPressure", "valveOpen"]
        assert r["session"]["elements"][1]["states"]["1"] == "TankVentControl"

        # a long range: at most `points` per element, the spike and the least value kept; NaN a gap
        status, r = get_json(url + "api/archive/1?elements=tankPressure,valveOpen,state&points=400")
        assert status == 200, r
        p, v, s = r["series"]
        assert p["total"] == 20000 and p["thinned"] and len(p["x"]) <= 400
        assert max(y for y in p["y"] if y is not None) == 900.0
        assert min(y for y in p["y"] if y is not None) == pytest.approx(799.0, abs=1e-3)
        assert v["total"] == 10000 and len(v["x"]) <= 400 and set(v["y"]) == {0, 1}
        assert set(s["y"]) == {1, 3}
        # at the default, 5,000 at most; a zoom sends that range anew, whole
        status, r = get_json(url + "api/archive/1?elements=tankPressure")
        assert len(r["series"][0]["x"]) <= 5000 and r["points"] == 5000
        status, r = get_json(url + "api/archive/1?elements=tankPressure&from=0.89&to=1.21")
        xs, ys = r["series"][0]["x"], r["series"][0]["y"]
        assert not r["series"][0]["thinned"] and xs == [round(0.9 + k * 0.02, 6) for k in range(16)]
        assert None in ys  # the NaN at 1 s: a gap, not a failed answer

        status, r = get_json(url + "api/archive/1/events")
        assert status == 200
        assert [(t["from"], t["to"]) for t in r["transitions"]] == [(None, "TankVentControl"), ("TankVentControl", "Idle")]
        assert r["transitions"][1]["t"] == pytest.approx(300.0, abs=0.05)
        c, = r["commands"]
        assert c["who"] == "web: 127.0.0.1" and c["ok"] and c["t"] == pytest.approx(2.0) and c["acked"] == pytest.approx(0.012, abs=1e-4)
        n, = r["notes"]
        assert n["text"].startswith("the port went away") and n["t"] == pytest.approx(3.0)

        # what is refused, and why
        for route, code, words in [
            ("api/archive/9", 404, "no session 9 in the archive"),
            ("api/archive/9", 404, "its sessions are 1-2"),
            ("api/archive/abc", 404, "no session `abc`"),
            ("api/archive/-1/events", 404, "no session `-1`"),
            ("api/archive/9/export.csv", 404, "no session 9"),
            ("api/archive/1?elements=pressure", 422, "unknown element(s) pressure: session 1's elements are time"),
            ("api/archive/1?elements=tankPressure&from=5&to=2", 422, "from=5 is not before to=2"),
            ("api/archive/1?elements=tankPressure&from=x", 422, "from=x: give seconds"),
            ("api/archive/1?elements=tankPressure&to=inf", 422, "to=inf: give seconds"),
            ("api/archive/1?elements=tankPressure&points=5001", 422, "points=5001: give a whole number from 2 to 5000"),
            ("api/archive/1?elements=tankPressure&points=1", 422, "points=1"),
            ("api/archive/1/export.xlsx", 404, "export.csv or export.parquet"),
        ]:
            status, r = get_json(url + route)
            assert status == code and not r["ok"] and words in r["words"], (route, status, r)
        status, r = get_json(url + "api/archive/1?elements=tankPressure&points=2")
        assert status == 200 and len(r["series"][0]["x"]) <= 2
    # a station that archives nothing says so
    with served(archive_app(None)) as url:
        status, r = get_json(url + "api/archive/sessions")
        assert status == 200 and r["archive"] is None and "archives nothing" in r["words"]
        status, r = get_json(url + "api/archive/1")
        assert status == 404 and "archives nothing" in r["words"]


# ---- in the browser, on the tank firmware --------------------------------------------------------

@pytest.fixture(scope="module")
def exe():
    return build_native(TANK)


@needs_cxx()
@needs_chromium
def test_the_archive_browser_shows_the_session_its_command_and_notes_and_exports_it(exe, browser, tmp_path):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    from fswkit.ground.archive import Archive, _clock
    from fswkit.ground.station import Station as Ground
    from fswkit.web.app import create_app
    from fswkit.web.source import LiveSource

    path = tmp_path / "a.sqlite"
    with PtyTarget(exe, f"a14={RAW}") as target:
        ground = Ground(tank_layout(), "tank", target.port, 115200, archive=Archive(str(path)))
        ground.start()
        try:
            with served(create_app(LiveSource(ground))) as url:
                text = lambda i: browser.find_element(By.ID, i).text  # noqa: E731
                browser.get(url)
                wait_for(lambda: text("link-status") == "live", "the link to show live", page=browser)
                # the header: the frame-to-page latency's median, beside the frame count
                wait_for(lambda: re.fullmatch(r"latency \d+(\.\d)? ms", text("link-latency")), "the latency", page=browser)
                # a command through the page's route, acknowledged
                req = urllib.request.Request(url + "api/command", method="POST", headers={"Content-Type": "application/json"},
                                             data=json.dumps({"kind": "set", "target": "valveOpen", "value": "false"}).encode())
                with urllib.request.urlopen(req, timeout=10) as r:
                    assert json.loads(r.read())["ok"]
                time.sleep(1.0)
                # the target stops: the station's note beside the link indicator
                target.stop()
                wait_for(lambda: "the port went away" in text("link-note"), "the station's note", page=browser)
                wait_for(lambda: text("link-status").startswith("stale"), "the stale indicator", page=browser)
                time.sleep(1.0)  # the archive's last batch committed

                # the archive tab: the session, live, in local time
                press(browser, "tab-archive")
                row = wait_for(lambda: browser.find_element(By.ID, "session-1"), "the sessions list", page=browser)
                started = json.loads(get(url + "api/archive/sessions")[1])["sessions"][0]["started"]
                assert "live" in row.text and "tank" in row.text and target.port in row.text
                assert _clock(started) in row.text and "running" in row.text
                row.click()
                # the plot: points drawn; the command, the notes and the first state listed
                points = wait_for(lambda: int(browser.find_element(By.ID, "archive-chart").get_attribute("data-points")),
                                  "the plot's points")
                assert points > 50 and browser.find_element(By.CSS_SELECTOR, "#archive-chart canvas")
                assert "#archive/1" in browser.current_url
                wait_for(lambda: "set valveOpen = false" in text("archive-command-table"), "the command", page=browser)
                cmds = text("archive-command-table")
                assert "127.0.0.1" in cmds and "applied" in cmds, cmds
                notes = text("archive-note-list")
                assert "target up, last reset" in notes and "the port went away" in notes, notes
                assert "starts in TankVentControl" in text("archive-transition-list")
                assert "the whole session" in text("archive-range")
                # docs/ground.md shows this tab: `make docs-img` runs this test with FSW_SCREENSHOTS=docs/img
                shots = os.environ.get("FSW_SCREENSHOTS") or str(tmp_path)
                assert browser.save_screenshot(os.path.join(shots, "ground-archive.png"))
                # a drag across the plot: that range asked anew, and offered for download
                over = browser.find_element(By.CSS_SELECTOR, "#archive-chart .u-over")
                w = over.size["width"]
                ActionChains(browser).move_to_element_with_offset(over, -w // 2 + 2, 0).click_and_hold() \
                    .move_by_offset(w // 8, 0).release().perform()
                wait_for(lambda: " of " in text("archive-range") and "whole" not in text("archive-range"), "the zoom", page=browser)
                shown = text("archive-range")
                lo, hi = (float(v) for v in re.match(r"([\d.]+)–([\d.]+) s", shown).groups())
                assert 0 <= lo < hi < 2.0, shown
                assert browser.find_element(By.ID, "archive-part").is_displayed()
                href = browser.find_element(By.ID, "archive-csv-range").get_attribute("href")
                assert "export.csv?from=" in href
                status, part = get(href)
                assert status == 200 and part.startswith(b"target time [s],host time [s]")
                ActionChains(browser).double_click(over).perform()
                wait_for(lambda: "the whole session" in text("archive-range"), "the whole session again", page=browser)
                # a session that is not there: the page says so
                browser.get(url + "#archive/99")
                wait_for(lambda: "no session 99 in the archive" in text("archive-err"), "the refusal in the page", page=browser)
                assert "its sessions are 1" in text("archive-err")

                # the CSV download is `fsw log2csv` of the archive's session, byte for byte
                status, csv_text = get(url + "api/archive/1/export.csv")
                r = run_fsw("log2csv", str(path), "--session", "1")
                assert status == 200 and r.code == 0, r.err
                assert csv_text.decode() == r.out and r.out.count("\n") > 50
                assert 1 < part.count(b"\n") < r.out.count("\n")  # the range's rows only
                status, pq = get(url + "api/archive/1/export.parquet")
                assert status == 200
                import pyarrow.parquet as parquet

                table = parquet.read_table(io.BytesIO(pq))
                assert table.num_rows == r.out.count("\n") - 1
                assert table.column("tankPressure")[-1].as_py() == pytest.approx(volts_psi(RAW))
                # a long range asked for few points: capped
                status, s = get_json(url + "api/archive/1?elements=tankPressure,state&points=20")
                assert status == 200 and all(len(x["x"]) <= 20 and x["thinned"] for x in s["series"])
                assert s["series"][0]["total"] > 50  # about 2 s at 50 Hz
        finally:
            ground.stop()
