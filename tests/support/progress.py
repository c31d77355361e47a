"""A command's progress (fswkit.progress) as a display gets it from a
worker: a datagram socket named by FSW_PROGRESS_TO, for tests that act
once a command says it has done some of its work (Ctrl-C once a run is
done, however fast the machine flies them)."""

from __future__ import annotations

import json
import os
import shutil
import socket
import tempfile
import time


class ProgressChannel:
    """`with ProgressChannel() as ch:` a socket the command started with
    `ch.env(...)` sends its progress to; `ch.wait_done(label, p)` returns
    once `label`'s bar says a unit is done."""

    def __enter__(self) -> ProgressChannel:
        self._dir = tempfile.mkdtemp(prefix="fsw-")  # a socket's path is at most 107 bytes: not under tmp_path
        self.path = os.path.join(self._dir, "progress")
        self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self._sock.bind(self.path)
        return self

    def __exit__(self, *exc) -> None:
        self._sock.close()
        shutil.rmtree(self._dir)

    def env(self, **extra: str) -> dict[str, str]:
        """This process's environment with progress on (neither
        FSW_NO_PROGRESS nor CI), sent here, and `extra`."""
        env = {k: v for k, v in os.environ.items() if k not in ("FSW_NO_PROGRESS", "CI")}
        env.update(extra, FSW_PROGRESS_TO=f"1:{self.path}")
        return env

    def wait_done(self, label: str, p, timeout: float = 300, why=lambda: "") -> None:
        """Until the bar `label` says a unit is done; fails when process
        `p` ends first or after `timeout` s (the build, then the first
        runs), with `why()` in the message."""
        deadline = time.monotonic() + timeout
        done = 0
        while done < 1:
            left = deadline - time.monotonic()
            assert left > 0 and p.poll() is None, (done, p.poll(), why())
            self._sock.settimeout(min(left, 5.0))
            try:
                message = json.loads(self._sock.recv(65536))
            except TimeoutError:
                continue
            if message["l"] == label and message["k"] == "u":
                done = message["d"]
