"""The web ground station's figures, measured: the rocket's firmware runs in
real time on the simulated Uno (`fsw sim examples/rocket`, its link on a
pseudo-terminal at 115,200 baud, telemetry at its configured rates), the
station owns the port and serves it to Debian's headless Chromium for
BENCH_WEB_SECONDS (20 s). Printed:

- frame-to-browser latency: from the frame's bytes reaching the station
  (the reader's host time) to the page's JavaScript receiving the
  WebSocket message (the same machine's clock), median and p99, over every
  sample frame of the window (target p99 <= 50 ms);
- the station's CPU use (this process: the port's reader, the decoder, the
  ASGI server; the browser is another process), as a share of one core
  (CPU seconds / wall seconds of the window; target <= 10 %)."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ROCKET = ROOT / "examples" / "rocket"
CHROMIUM, DRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"
SECONDS = float(os.environ.get("BENCH_WEB_SECONDS", "20"))


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main() -> int:
    import uvicorn
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.link.layout import from_app
    from fswkit.link.port import open_port
    from fswkit.target.build import load
    from fswkit.web.app import create_app
    from fswkit.web.source import LiveSource

    print("== web ground station (tools/bench_web.py) ==")
    if not (os.path.exists(CHROMIUM) and os.path.exists(DRIVER)):
        print("web bench: 0 passed, 1 failed (Debian's chromium and chromium-driver are missing: make setup)")
        return 1
    app = load(str(ROCKET), Diagnostics())
    layout = from_app(app)
    fsw = str(Path(sys.executable).with_name("fsw"))
    sim = subprocess.Popen([fsw, "sim", str(ROCKET), "--duration", str(SECONDS + 30)], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    try:
        port = sim.stdout.readline().strip()
        if not port.startswith("/dev/"):
            print(f"web bench: 0 passed, 1 failed (fsw sim gave no port: {sim.stderr.read()[-400:]})")
            return 1
        serial = open_port(port, app.baud)
        source = LiveSource(layout, serial)
        http = free_port()
        server = uvicorn.Server(uvicorn.Config(create_app(source), host="127.0.0.1", port=http,
                                               log_level="warning", ws="websockets-sansio"))
        thread = threading.Thread(target=server.run, daemon=True)
        thread.start()
        while not server.started:
            time.sleep(0.02)
        opts = webdriver.ChromeOptions()
        opts.binary_location = CHROMIUM
        for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync", "--disable-dev-shm-usage", "--no-first-run"):
            opts.add_argument(a)
        drv = webdriver.Chrome(service=Service(DRIVER), options=opts)
        try:
            drv.get(f"http://127.0.0.1:{http}/")
            deadline = time.monotonic() + 15
            while drv.execute_script("return window.fswLatency.length") < 10:
                if time.monotonic() > deadline:
                    print("web bench: 0 passed, 1 failed (no frame reached the page in 15 s)")
                    return 1
                time.sleep(0.1)
            drv.execute_script("window.fswLatency.length = 0")
            cpu0, wall0, frames0 = time.process_time(), time.monotonic(), source.frames
            time.sleep(SECONDS)
            cpu, wall, frames = time.process_time() - cpu0, time.monotonic() - wall0, source.frames - frames0
            lat = sorted(drv.execute_script("return window.fswLatency"))
        finally:
            drv.quit()
            server.should_exit = True
            thread.join(5)
            serial.close()
    finally:
        sim.terminate()
        sim.wait(10)
    if not lat:
        print("web bench: 0 passed, 1 failed (no sample frame reached the page)")
        return 1
    med = lat[len(lat) // 2] * 1000
    p99 = lat[min(len(lat) - 1, int(len(lat) * 0.99))] * 1000
    share = 100 * cpu / wall
    print(f"  window {wall:.1f} s: {frames} frames ({frames / wall:.0f}/s) through the station, "
          f"{len(lat)} sample frames timed in the page")
    print(f"  frame-to-browser latency   median {med:6.1f} ms   p99 {p99:6.1f} ms   (target p99 <= 50 ms)")
    print(f"  station CPU use            {share:6.1f} % of one core          (target <= 10 %)")
    ok = p99 <= 50 and share <= 10
    print(f"web bench: {2 if ok else int(p99 <= 50) + int(share <= 10)} passed, "
          f"{0 if ok else int(p99 > 50) + int(share > 10)} failed")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
