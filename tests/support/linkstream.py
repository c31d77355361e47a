"""A target's clean downlink, made frame by frame as the firmware makes it
(tests/regression helpers): samples of the tank's streams, health frames
with the full 32-bit frame counter, a hello every ten of them; and the
tank project, with or without its uplink."""

from __future__ import annotations

import shutil
import struct
from pathlib import Path

from conftest import EXAMPLES

from fswkit.autocode.protocol import HEALTH_PAYLOAD, HELLO_PAYLOAD
from fswkit.link import wire

TANK = EXAMPLES / "tank"


def tank_copy(tmp: Path, uplink: bool = True) -> Path:
    """The tank project copied into `tmp` (without its build folder)."""
    out = tmp / "tank"
    shutil.copytree(TANK, out, ignore=shutil.ignore_patterns("build"))
    if not uplink:
        app = (out / "tank.app").read_text().replace("uplink   uplink        rate=100\n", "")
        (out / "tank.app").write_text(app.replace("[uplink]               # elements the ground may write\n"
                                                  "valveOpen\n", ""))
    return out


def layout_of(project: Path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import load
    from fswkit.link.layout import from_app

    return from_app(load(str(project), Diagnostics()))


def hello(layout, full: int, t: int) -> bytes:
    payload = HELLO_PAYLOAD.pack(wire.PROTOCOL, layout.schema, t >> 32, full, 1, 0, 0, 0, 0, 0)
    return wire.downlink(wire.HELLO, full, t, payload)


def health(layout, full: int, t: int) -> bytes:
    head = HEALTH_PAYLOAD.pack(t >> 32, full, 0, full, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0)
    tasks = b"".join(struct.pack("<BBHH", 2, 0, 0, 10) for _ in layout.tasks)
    payload = head + tasks
    assert len(payload) == layout.health_payload
    return wire.downlink(wire.HEALTH, full, t, payload)


def sample(layout, full: int, t: int, stream: int = 0) -> bytes:
    st = layout.streams[stream]
    one = bytes((full + i) & 0xFF or 1 for i in range(st.region.size))
    return wire.downlink(0x80 | stream, full, t, one)


def stream(layout, first: int, count: int, skip=(), hello_first: bool = False) -> list[bytes]:
    """`count` frames of a clean link whose frame counter starts at `first`
    (a ground that attaches mid-stream sees these): samples, a health frame
    every 25 frames, a hello every 250; the frames numbered in `skip` are
    left out (lost on the link)."""
    out = []
    for k in range(count):
        full = first + k
        t = 10 * full
        if k == 0 and hello_first:
            f = hello(layout, full, t)
        elif full % 250 == 0:
            f = hello(layout, full, t)
        elif full % 25 == 0:
            f = health(layout, full, t)
        else:
            f = sample(layout, full, t)
        if full not in skip:
            out.append(f)
    return out


def write_log(path, count: int, first: int = 0, step_ns: int = 10_000_000, project: Path = TANK) -> Path:
    """A link log at `path` of `count` frames of `project`'s clean link
    (see `stream`, a hello first), received `step_ns` apart."""
    from fswkit.link.log import RX, LogWriter

    layout = layout_of(project)
    w = LogWriter(str(path), layout)
    for i, f in enumerate(stream(layout, first, count, hello_first=True)):
        w.record(RX, 1_000_000_000 + i * step_ns, f)
    w.close()
    return Path(path)


class PtyTarget:
    """A target on a pseudo-terminal: `port` is its name for the ground;
    a thread runs `_run`, which talks through `master` until `_stop`."""

    def __init__(self):
        import os
        import pty
        import threading
        import tty

        self.master, self.slave = pty.openpty()
        tty.setraw(self.slave)
        tty.setraw(self.master)
        self.port = os.ttyname(self.slave)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def start(self):
        self._thread.start()
        return self

    def _run(self) -> None:
        raise NotImplementedError

    def close(self) -> None:
        import os

        self._stop.set()
        self._thread.join(timeout=5)
        os.close(self.master)
        os.close(self.slave)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class PtyStream(PtyTarget):
    """A target on a pseudo-terminal that streams `frames` over and over
    (renumbered past the last) until stopped: the port a monitor opens."""

    def __init__(self, layout, first: int = 5000, hello_first: bool = False, schema: int | None = None):
        super().__init__()
        self.layout = layout
        self._first, self._hello_first, self._schema = first, hello_first, schema
        self.start()

    def _run(self) -> None:
        import os
        import select

        lay = self.layout
        if self._schema is not None:
            import dataclasses
            lay = dataclasses.replace(lay, schema=self._schema)
        n = self._first
        first = True
        while not self._stop.is_set():
            frames = stream(lay, n, 50, hello_first=first and self._hello_first)
            first = False
            n += 50
            data = b"".join(frames)
            while data and not self._stop.is_set():
                _, w, _ = select.select([], [self.master], [], 0.05)
                if w:
                    try:
                        k = os.write(self.master, data[:512])
                    except OSError:
                        return
                    data = data[k:]
                # whatever the ground sends is read and dropped
                r, _, _ = select.select([self.master], [], [], 0)
                if r:
                    try:
                        os.read(self.master, 4096)
                    except OSError:
                        return
            self._stop.wait(0.02)
