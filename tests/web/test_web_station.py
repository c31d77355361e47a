"""The web ground station in a real headless browser (Debian's Chromium
driven by Selenium through chromedriver): the tank firmware built for
`native` runs with its console on a pseudo-terminal, the station owns that
port, and the page loads, shows values as they change, sends a command
through the confirmation step and shows its acknowledgement, refuses a
value of the wrong type before sending it, and shows the link stale when
the target stops."""

from __future__ import annotations

import os
import threading
import time

import pytest

from conftest import run_fsw
from support.browser import browser, free_port, needs_chromium, press, wait_for  # noqa: F401 - browser: a fixture
from support.linkfw import TANK, PtyTarget, build_native, needs_cxx, tank_layout, volts_psi

pytestmark = [pytest.mark.costly(14, waits=True), needs_cxx(), needs_chromium]
RAW = 770  # 815.86 psi: the vent valve opens



@pytest.fixture(scope="module")
def exe():
    return build_native(TANK)


class Station:
    """The web station on a port, serving in a thread."""

    def __init__(self, port: str, project=TANK):
        import uvicorn

        from fswkit.ground.station import Station as Ground
        from fswkit.web.app import create_app
        from fswkit.web.source import LiveSource

        self.ground = Ground(tank_layout(project), project.name, port, 115200)
        self.ground.start()
        self.source = LiveSource(self.ground)
        self.http = free_port()
        self.url = f"http://127.0.0.1:{self.http}/"
        self.server = uvicorn.Server(uvicorn.Config(create_app(self.source), host="127.0.0.1", port=self.http,
                                                    log_level="warning", ws="websockets-sansio"))
        self.thread = threading.Thread(target=self.server.run, daemon=True)
        self.thread.start()
        deadline = time.monotonic() + 10
        while not self.server.started:
            assert time.monotonic() < deadline, "the station did not start"
            time.sleep(0.02)

    def close(self):
        self.server.should_exit = True
        self.thread.join(5)
        self.ground.stop()


def test_the_page_shows_the_link_commands_round_trip_and_a_stopped_target_goes_stale(exe, browser, tmp_path):
    from selenium.webdriver.common.by import By

    with PtyTarget(exe, f"a14={RAW}") as target:
        station = Station(target.port)
        try:
            browser.get(station.url)
            text = lambda i: browser.find_element(By.ID, i).text  # noqa: E731
            wait_for(lambda: text("link-status") == "live", "the link to show live", page=browser)
            assert "tank" in browser.title
            # a value arrives and updates: the time element grows
            t1 = wait_for(lambda: float(text("value-time")), "the time to show", page=browser)
            t2 = wait_for(lambda: float(text("value-time")) > t1 and float(text("value-time")), "the time to change", page=browser)
            assert t2 > t1
            assert float(text("value-tankPressure")) == float(f"{volts_psi(RAW):.6g}")
            # the plot has drawn the samples (uPlot's canvas) and the state timeline its state
            assert browser.find_element(By.CSS_SELECTOR, "#chart canvas")
            wait_for(lambda: "TankVentControl" in text("timeline"), "the state timeline", page=browser)
            # a value of the wrong type is refused in the page, before anything is sent
            box = browser.find_element(By.ID, "cmd-valveOpen")
            box.send_keys("maybe")
            press(browser, "send-valveOpen")
            assert "valveOpen is bool" in text("err-valveOpen")
            assert not browser.find_element(By.ID, "confirm").get_attribute("open")
            # a command: confirmed, sent, acknowledged, in the history
            box.clear()
            box.send_keys("false")
            press(browser, "send-valveOpen")
            wait_for(lambda: browser.find_element(By.ID, "confirm").get_attribute("open") is not None, "the dialog", page=browser)
            assert "set valveOpen = false" in text("confirm-text")
            press(browser, "confirm-yes")
            # (the station's own hello may be in the history too: the page's command is looked for)
            item = wait_for(lambda: [li for li in browser.find_elements(By.CSS_SELECTOR, "#history li")
                                     if "set valveOpen = false" in li.text], "the command in the history")[0]
            assert "set valveOpen = false" in item.text and "applied" in item.text, item.text
            assert "ok" in item.get_attribute("class")
            # a command from another client of the station (`fsw cmd` in a terminal): in the same history
            r = run_fsw("cmd", "-p", str(TANK), "--port", target.port, "set", "valveOpen", "true")
            assert r.code == 0, r.err
            item = wait_for(lambda: [li for li in browser.find_elements(By.CSS_SELECTOR, "#history li")
                                     if "fsw cmd (pid" in li.text], "fsw cmd's command in the history")[0]
            assert "set valveOpen true" in item.text and "applied" in item.text, item.text
            # docs/ground.md shows this page: `make docs-img` runs this test with FSW_SCREENSHOTS=docs/img
            shots = os.environ.get("FSW_SCREENSHOTS") or str(tmp_path)
            assert browser.save_screenshot(os.path.join(shots, "ground-web.png"))
            # the target stops: the page says the link is stale
            target.stop()
            wait_for(lambda: text("link-status").startswith("stale"), "the stale indicator", timeout=10, page=browser)
            assert "last frame" in text("link-status")
        finally:
            station.close()


def test_the_page_shows_each_charges_status_from_the_health_frame(browser):
    """The rocket built for the host, its key on, both igniters reading
    intact (2.5 V: count 512) and then the drogue's open: the page's link
    table says so in words (docs/safety.md, "Continuity")."""
    from selenium.webdriver.common.by import By

    from conftest import EXAMPLES

    from support.simfw import kept_native

    rocket = EXAMPLES / "rocket"
    exe = kept_native(rocket) / "rocket"
    for drogue, words in ((512, "armed, continuity, not fired"), (0, "armed, OPEN, not fired")):
        with PtyTarget(exe, "d2=1", f"a16={drogue}", "a17=512") as target:
            station = Station(target.port, rocket)
            try:
                browser.get(station.url)
                table = lambda: browser.find_element(By.ID, "link-table").text  # noqa: E731
                wait_for(lambda: "pyro drogue armed" in table(), "the pyro rows of the health frame", timeout=10,
                         page=browser)
                assert f"pyro drogue {words}" in table(), table()
                assert "pyro main armed, continuity, not fired" in table(), table()
            finally:
                station.close()


def test_the_page_shows_each_sensor_parts_health(browser):
    """An application with a barometer and an accelerometer built for the
    host, where nobody answers on either bus: the link table names each
    part with its health in words (docs/sensor-table.md)."""
    from selenium.webdriver.common.by import By

    from support.simfw import OUT, kept_native

    # the project and its build kept in build/sim-tests/ (support.simfw.kept_native): a file is written
    # only when its text changed, so a warm run's build finds everything up to date
    project = OUT / "web-parts"
    project.mkdir(parents=True, exist_ok=True)
    texts = {
        "p.sv": "[Data]\nU64 time\nU32 state\nF32 baroP\nF32 accelZ\nbool high\n",
        "p.sm": "[state_vector]\nU64 time @alias G\nU32 state @alias S\nF32 baroP @read_only\n"
                "bool high\n\n[Run]\n.step\n    high = baroP > 100000\n",
        "p.sns": "bmp280 i2c:0x76 pressure=baroP\nadxl345 spi:7 z=accelZ\n",
        "p.app": "[application]\nboard native\nrate 100\n[configs]\nstate_vector p.sv\n"
                 "machine p.sm\nio p.sns\n[tasks]\nsense inputs rate=100\n"
                 "control machine p rate=100\ndown telemetry rate=50\n[telemetry]\nData rate=10\n",
    }
    for name, text in texts.items():
        if not (project / name).is_file() or (project / name).read_text() != text:
            (project / name).write_text(text)
    with PtyTarget(kept_native(project) / "p") as target:
        station = Station(target.port, project)
        try:
            browser.get(station.url)
            table = lambda: browser.find_element(By.ID, "link-table").text  # noqa: E731
            wait_for(lambda: "sensor adxl345@spi:7 NO" in table(), "the sensor rows of the health frame", timeout=10,
                     page=browser)
            assert "sensor bmp280@0x76 NO ANSWER" in table(), table()
            assert "sensor adxl345@spi:7 NO ANSWER" in table(), table()
        finally:
            station.close()


@pytest.mark.parametrize("name", ["ground", "web"])
def test_fsw_ground_serves_the_page_the_terminal_tools_and_the_archive(exe, tmp_path, name):
    """`fsw ground PROJECT --port P --http-port 0 --archive A` (and its older
    name `fsw web`) prints the URL it serves; the layout and the page come
    from it; `fsw monitor` and `fsw cmd` go through it; Ctrl-C (SIGINT)
    ends it with the session in the archive, frames and command."""
    import json
    import signal
    import subprocess
    import sys
    import urllib.request

    archive = tmp_path / "a.sqlite"
    with PtyTarget(exe, f"a14={RAW}") as target:
        p = subprocess.Popen([sys.executable, "-m", "fswkit.cli", name, str(TANK), "--port", target.port,
                              "--http-port", "0", "--archive", str(archive)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            url = p.stdout.readline().strip()
            assert url.startswith("http://127.0.0.1:"), p.stderr.read() if p.poll() is not None else url
            lay = json.loads(urllib.request.urlopen(url + "api/layout", timeout=5).read())
            assert lay["name"] == "tank" and [e["name"] for e in lay["elements"] if e["writable"]] == ["valveOpen"]
            page = urllib.request.urlopen(url, timeout=5).read().decode()
            assert '<script src="/uplot/uPlot.iife.min.js">' in page
            r = run_fsw("monitor", str(TANK), "--port", target.port, "--headless", "--duration", "1")
            assert r.code == 0 and "through the ground station" in r.err, r.err
            r = run_fsw("cmd", "-p", str(TANK), "--port", target.port, "ping")
            assert r.code == 0, r.err
        finally:
            p.send_signal(signal.SIGINT)
            assert p.wait(10) == 0, p.stderr.read()
    r = run_fsw("archive", "list", str(archive))
    assert r.code == 0, r.err
    import sqlite3

    con = sqlite3.connect(archive)
    frames, = con.execute("SELECT count(*) FROM frames").fetchone()
    cmds = con.execute("SELECT who, text, status FROM commands WHERE who LIKE 'fsw cmd%'").fetchall()
    ended, = con.execute("SELECT ended FROM sessions").fetchone()
    con.close()
    assert frames > 20 and ended is not None
    assert len(cmds) == 1 and cmds[0][1] == "ping" and cmds[0][2] == 0


def test_the_page_lists_and_sets_the_firmwares_parameters(browser, tmp_path):
    """The tests/param/tuned rig (native, on a pty): the station reads its
    parameters through the port it owns; a value set in the page, after
    the confirmation, is live on the target and in the shared history; a
    value out of range is refused with its range."""
    from selenium.webdriver.common.by import By

    import uvicorn

    from conftest import ROOT
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.params import app_parameters
    from fswkit.autocode.schema import link_plan
    from fswkit.link.layout import from_app
    from fswkit.ground.station import Station as Ground
    from fswkit.target.build import load
    from fswkit.web.app import create_app
    from fswkit.web.source import LiveSource

    from support.simfw import kept_native

    rig = ROOT / "tests" / "param" / "tuned"
    exe = kept_native(rig) / "tuned"
    app = load(str(rig), Diagnostics())
    with PtyTarget(exe, "--eeprom", str(tmp_path / "e.bin")) as target:
        ground = Ground(from_app(app), str(rig), target.port, 115200)
        ground.start()
        source = LiveSource(ground, params=app_parameters(app), tx_cap=link_plan(app).tx_cap)
        http = free_port()
        server = uvicorn.Server(uvicorn.Config(create_app(source), host="127.0.0.1", port=http, log_level="warning",
                                               ws="websockets-sansio"))
        thread = threading.Thread(target=server.run, daemon=True)
        thread.start()
        try:
            while not server.started:
                time.sleep(0.02)
            browser.get(f"http://127.0.0.1:{http}/")
            text = lambda i: browser.find_element(By.ID, i).text  # noqa: E731
            wait_for(lambda: text("pval-OPEN_AT") == "800 psi", "the parameters", page=browser)
            assert text("param-state") == "defaults"
            box = browser.find_element(By.ID, "pset-OPEN_AT")
            box.send_keys("650.5")
            press(browser, "psend-OPEN_AT")
            wait_for(lambda: browser.find_element(By.ID, "confirm").get_attribute("open") is not None, "the dialog", page=browser)
            press(browser, "confirm-yes")
            wait_for(lambda: text("pval-OPEN_AT") == "650.5 psi", "the new value", page=browser)
            assert "unsaved changes" in text("param-state")
            item = browser.find_elements(By.CSS_SELECTOR, "#history li")[0]
            assert "param set OPEN_AT = 650.5" in item.text and "applied" in item.text
            box = browser.find_element(By.ID, "pset-HOLD_MS")
            box.send_keys("5")
            press(browser, "psend-HOLD_MS")
            wait_for(lambda: browser.find_element(By.ID, "confirm").get_attribute("open") is not None, "the dialog", page=browser)
            press(browser, "confirm-yes")
            wait_for(lambda: "outside its range 10..60000 ms" in text("param-err"), "the refusal", page=browser)
        finally:
            server.should_exit = True
            thread.join(5)
            ground.stop()
