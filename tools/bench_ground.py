"""The ground station's figures, measured with the real commands on the
simulated Uno (docs/ground.md). Printed:

1. **All clients at once** (BENCH_GROUND_SECONDS, 60 s): the rocket's
   firmware runs in real time (`fsw sim examples/rocket`, its link on a
   pseudo-terminal at 115,200 baud), `fsw ground` owns the port and
   archives into a fresh SQLite file; Debian's headless Chromium shows the
   page, `fsw monitor --headless` watches, `fsw cmd ping` goes every
   second, and a second monitor attaches after half the window. Counted
   against the archive: frames missed by each client over its window,
   commands acknowledged exactly once, frames the second monitor reports
   lost (target 0 everywhere); frame-to-browser latency, median and p99
   (from the frame's bytes reaching the station to the page's JavaScript
   receiving it; target p99 <= 50 ms).
2. **Full rate**: a stream set that fills the Uno's link (tools/bench_link.py's
   line-rate project, 22 floats at 100 Hz) through `fsw ground` with the
   page open for BENCH_GROUND_FULL_SECONDS (20 s): the station's CPU use as
   a share of one core (its process's user + system time over the window;
   target <= 10 %) and the archive's write rate in that run.
3. **Archive write rate** at its limit: that run's bytes decoded and
   written again into a new archive as fast as one core does it (frames/s,
   MB/s of link bytes)."""

from __future__ import annotations

import os
import re
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ROCKET = ROOT / "examples" / "rocket"
CHROMIUM, DRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"
SECONDS = float(os.environ.get("BENCH_GROUND_SECONDS", "60"))
FULL_SECONDS = float(os.environ.get("BENCH_GROUND_FULL_SECONDS", "20"))
FSW = str(Path(sys.executable).with_name("fsw"))
TICK = os.sysconf("SC_CLK_TCK")

sys.path.insert(0, str(ROOT / "tools"))


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def cpu_seconds(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICK  # utime, stime


def browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
              "--disable-component-update", "--disable-sync", "--disable-dev-shm-usage", "--no-first-run"):
        opts.add_argument(a)
    return webdriver.Chrome(service=Service(DRIVER), options=opts)


class Run:
    """`fsw sim PROJECT` (the board, on a pty) and `fsw ground` on its port."""

    def __init__(self, project: Path, seconds: float, archive: Path, env: dict):
        self.env = env
        self.sim = subprocess.Popen([FSW, "sim", str(project), "--duration", str(seconds + 60)],
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        self.port = self.sim.stdout.readline().strip()
        if not self.port.startswith("/dev/"):
            raise SystemExit(f"ground bench: 0 passed, 1 failed (fsw sim gave no port: {self.sim.stderr.read()[-400:]})")
        self.http = free_port()
        self.ground = subprocess.Popen([FSW, "ground", str(project), "--port", self.port, "--archive", str(archive),
                                        "--http-port", str(self.http)],
                                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        self.url = self.ground.stdout.readline().strip()
        if not self.url.startswith("http"):
            raise SystemExit(f"ground bench: 0 passed, 1 failed (fsw ground: {self.ground.stderr.read()[-600:]})")

    def stop(self) -> str:
        self.ground.send_signal(signal.SIGINT)
        try:
            _, err = self.ground.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            self.ground.kill()
            _, err = self.ground.communicate()
        self.sim.terminate()
        self.sim.wait(10)
        return err


def wait_page(drv, n: int = 10, timeout: float = 20.0) -> bool:
    deadline = time.monotonic() + timeout
    while drv.execute_script("return window.fswSeqs.length") < n:
        if time.monotonic() > deadline:
            return False
        time.sleep(0.1)
    return True


def monitor(project: Path, port: str, seconds: float, env: dict) -> subprocess.Popen:
    return subprocess.Popen([FSW, "monitor", str(project), "--port", port, "--headless", "--duration", str(seconds)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


def seqs_of(out: str) -> list[int]:
    return [int(m) for m in re.findall(r"^seq=(\d+)", out, re.M)]


def missed(seen: list[int], archived: list[int]) -> int:
    """Frames the archive has between a client's first and last that the client did not see."""
    if not seen:
        return len(archived)
    want = {s for s in archived if seen[0] <= s <= seen[-1]}
    return len(want - set(seen))


def all_clients(tmp: Path, env: dict) -> tuple[list[str], bool]:
    archive = tmp / "all.sqlite"
    run = Run(ROCKET, SECONDS, archive, env)
    lines, ok = [], True
    drv = browser()
    try:
        drv.get(run.url)
        if not wait_page(drv):
            return ["  no frame reached the page in 20 s"], False
        drv.execute_script("window.fswLatency.length = 0; window.fswSeqs.length = 0")
        mon = monitor(ROCKET, run.port, SECONDS, env)
        late = None
        sent = refused = 0
        start = time.monotonic()
        while time.monotonic() - start < SECONDS:
            t0 = time.monotonic()
            r = subprocess.run([FSW, "cmd", "-p", str(ROCKET), "--port", run.port, "ping"], capture_output=True,
                               text=True, env=env)
            sent += 1
            refused += r.returncode != 0
            if late is None and time.monotonic() - start >= SECONDS / 2:
                late = monitor(ROCKET, run.port, SECONDS / 2 - 2, env)
            time.sleep(max(0.0, 1.0 - (time.monotonic() - t0)))
        mon_out, mon_err = mon.communicate(timeout=60)
        late_out, late_err = late.communicate(timeout=60)
        page = drv.execute_script("return window.fswSeqs")
        lat = sorted(drv.execute_script("return window.fswLatency"))
    finally:
        drv.quit()
        err = run.stop()
    con = sqlite3.connect(archive)
    archived = [s for (s,) in con.execute("SELECT seq FROM frames ORDER BY id")]
    samples = [s for (s,) in con.execute("SELECT seq FROM frames WHERE kind = 'sample' ORDER BY id")]
    cmds = con.execute("SELECT cmd_seq, status FROM commands WHERE who LIKE 'fsw cmd%'").fetchall()
    acks = [s for (s,) in con.execute("SELECT json_extract(info, '$.cmd_seq') FROM frames WHERE kind = 'ack'")]
    con.close()
    once = sum(1 for seq, status in cmds if status == 0 and acks.count(seq) == 1)
    late_lost = re.search(r"(\d+) lost in (\d+) gaps", late_err)
    figures = {
        "monitor": missed(seqs_of(mon_out), archived),
        "late monitor": missed(seqs_of(late_out), archived),
        "browser": missed([s for s in page if s is not None], samples),
    }
    lines.append(f"  {SECONDS:.0f} s, rocket on the simulated Uno: {len(archived)} frames archived; "
                 f"clients: the page, a monitor, `fsw cmd` every second, a monitor attached after {SECONDS / 2:.0f} s")
    for who, n in figures.items():
        lines.append(f"  frames missed by the {who:<13} {n:6d}   (target 0)")
        ok &= n == 0
    lines.append(f"  commands sent {sent}, refused or unanswered {refused}, archived {len(cmds)}, "
                 f"acknowledged exactly once {once}   (target: all)")
    ok &= refused == 0 and once == sent == len(cmds)
    n_late = int(late_lost.group(1)) if late_lost else -1
    lines.append(f"  lost reported by the late monitor {n_late:4d}   (target 0)")
    ok &= n_late == 0
    if lat:
        med = lat[len(lat) // 2] * 1000
        p99 = lat[min(len(lat) - 1, int(len(lat) * 0.99))] * 1000
        lines.append(f"  frame-to-browser latency   median {med:6.1f} ms   p99 {p99:6.1f} ms   (target p99 <= 50 ms)")
        ok &= p99 <= 50
    else:
        lines.append("  frame-to-browser latency: no sample timed")
        ok = False
    if "Traceback" in err:
        lines.append("  fsw ground: " + err[-400:])
        ok = False
    return lines, ok


def full_rate(tmp: Path, env: dict) -> tuple[list[str], bool, Path | None]:
    from bench_link import line_rate_project

    project = line_rate_project(tmp / "fill22", 22)
    archive = tmp / "full.sqlite"
    run = Run(project, FULL_SECONDS, archive, env)
    drv = browser()
    try:
        drv.get(run.url)
        if not wait_page(drv):
            return ["  full rate: no frame reached the page"], False, None
        con = sqlite3.connect(archive)
        frames0 = con.execute("SELECT count(*) FROM frames").fetchone()[0]
        link0 = con.execute("SELECT coalesce(sum(length(data)), 0) FROM chunks WHERE dir = 0").fetchone()[0]
        con.close()
        cpu0, wall0 = cpu_seconds(run.ground.pid), time.monotonic()
        time.sleep(FULL_SECONDS)
        cpu, wall = cpu_seconds(run.ground.pid) - cpu0, time.monotonic() - wall0
        con = sqlite3.connect(archive)
        frames1 = con.execute("SELECT count(*) FROM frames").fetchone()[0]
        link1 = con.execute("SELECT coalesce(sum(length(data)), 0) FROM chunks WHERE dir = 0").fetchone()[0]
        con.close()
    finally:
        drv.quit()
        run.stop()
    capacity = 16_000_000 / (8 * (((16_000_000 // 4 // 115200 - 1) // 2) + 1)) / 10
    share = 100 * cpu / wall
    rate = (link1 - link0) / wall
    lines = [f"  full rate: {rate:,.0f} B/s of link ({100 * rate / capacity:.0f} % of UART0's {capacity:,.0f} B/s), "
             f"{(frames1 - frames0) / wall:,.0f} frames/s archived, the page open",
             f"  station CPU use            {share:6.1f} % of one core          (target <= 10 %)"]
    return lines, share <= 10, archive


def write_rate(archive: Path, tmp: Path) -> list[str]:
    """The archive's own limit: the recorded link decoded and archived again."""
    from fswkit.ground.archive import Archive, ArchiveReader
    from fswkit.link.log import RX
    from fswkit.link.session import Session

    reader = ArchiveReader(str(archive))
    chunks = [(t, d) for direction, t, d in reader.records() if direction == RX]
    session = Session(reader.layout)
    out = Archive(str(tmp / "again.sqlite"))
    out.begin(layout=reader.layout, project="bench", port="-", baud=115200, started=time.time())
    n = size = 0
    c0 = time.process_time()
    for t, data in chunks:
        out.rx(int(t * 1e9), data)
        for ev in session.feed(data, t):
            out.event(ev)
            n += 1
        size += len(data)
        out.tick()
    out.close()
    cpu = time.process_time() - c0
    return [f"  archive write rate at its limit: {n / cpu:,.0f} frames/s, {size / cpu / 1e6:.2f} MB/s of link bytes "
            f"({n} frames decoded and written again, one core)"]


def main() -> int:
    print("== ground station (tools/bench_ground.py) ==")
    if not (os.path.exists(CHROMIUM) and os.path.exists(DRIVER)):
        print("ground bench: 0 passed, 1 failed (Debian's chromium and chromium-driver are missing: make setup)")
        return 1
    tmp = Path(tempfile.mkdtemp(prefix="fsw-bench-ground-"))
    env = dict(os.environ, FSW_RUNTIME_DIR=str(tmp / "run"))
    lines, ok1 = all_clients(tmp, env)
    print("\n".join(lines))
    lines, ok2, archive = full_rate(tmp, env)
    print("\n".join(lines))
    if archive is not None:
        print("\n".join(write_rate(archive, tmp)))
    passed = int(ok1) + int(ok2)
    print(f"ground bench: {passed} passed, {2 - passed} failed")
    return 0 if passed == 2 else 1


if __name__ == "__main__":
    sys.exit(main())
