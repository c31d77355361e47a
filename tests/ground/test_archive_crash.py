"""The archive survives `kill -9`: a process writes frames as the station
does (each chunk, its decoded frame, a tick) and is killed with SIGKILL at
random moments, several times over the same archive. After each kill the
database is whole (PRAGMA integrity_check), every frame written more than a
second before the kill is there — whole batches only, never a chunk
without its frame — and the next process appends a new session."""

from __future__ import annotations

import json
import os
import random
import signal
import sqlite3
import subprocess
import sys
import time

from fswkit.ground.archive import Archive, ArchiveReader, is_archive, sessions
from support.linkstream import TANK, hello, layout_of, sample

# The writer: frames numbered from 0 (a hello, then samples whose 32-bit
# frame counter is their number), each archived as the station archives a
# read: received() with its decoded events (a tick with them); about 2,000
# frames a second.
WRITER = r"""
import json, sys, time
from fswkit.ground.archive import Archive
from fswkit.link.layout import from_dict
from fswkit.link.session import Session

path, frames_file = sys.argv[1], sys.argv[2]
with open(frames_file) as f:
    spec = json.load(f)
layout = from_dict(spec["layout"])
frames = [bytes.fromhex(h) for h in spec["frames"]]
a = Archive(path)
started = time.time()
sid = a.begin(layout=layout, project="tank", port="/dev/crash", baud=115200, started=started)
decoder = Session(layout)
print(sid, started, flush=True)
n = 0
while True:
    data = frames[n % len(frames)]
    t = time.time_ns()
    a.received(t, data, decoder.feed(data, t / 1e9))
    n += 1
    time.sleep(0.0005)
"""



def test_kill_9_loses_at_most_the_last_second(tmp_path):
    seed = int.from_bytes(os.urandom(4), "little")
    rnd = random.Random(seed)
    layout = layout_of(TANK)
    # a hello, then samples numbered 1.. (frame counter and target time alike)
    frames = [hello(layout, 0, 0)] + [sample(layout, n, 10 * n) for n in range(1, 20_000)]
    spec = tmp_path / "frames.json"
    spec.write_text(json.dumps({"layout": layout.raw, "frames": [f.hex() for f in frames]}))
    path = tmp_path / "station.sqlite"
    index = {f: i for i, f in enumerate(frames)}
    # SIGKILL at a random moment of a session: two within its first second, two after it
    moments = [rnd.uniform(0.02, 0.5), rnd.uniform(0.5, 1.0), rnd.uniform(1.1, 1.5), rnd.uniform(1.1, 1.5)]
    rnd.shuffle(moments)

    for k, moment in enumerate(moments):
        p = subprocess.Popen([sys.executable, "-c", WRITER, str(path), str(spec)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        try:
            line = p.stdout.readline()
            assert line, p.stderr.read()
            sid, started = int(line.split()[0]), float(line.split()[1])
            assert sid == k + 1
            time.sleep(moment)
            killed = time.time()
            p.send_signal(signal.SIGKILL)
        finally:
            p.kill()
            p.wait(timeout=10)
            p.stdout.close()
            p.stderr.close()
        why = f"(kill {k + 1}, {killed - started:.2f} s into the session; seed {seed})"

        # the killed session reads back, before anything opens the archive to write
        assert is_archive(path), why
        r = ArchiveReader(str(path), sid)
        assert r.truncated and r.header["ended"] is None, why
        got = [(t, data) for _, t, data in r.records()]
        r.close()
        numbers = [index[data] for _, data in got]
        assert numbers == list(range(len(numbers))), f"frames missing in the middle {why}"
        if killed - started > 1.0:
            assert got and got[-1][0] >= killed - 1.0, \
                f"the last frame kept was written {killed - got[-1][0]:.2f} s before the kill {why}"

        con = sqlite3.connect(path)
        assert con.execute("PRAGMA integrity_check").fetchall() == [("ok",)], why
        frames_kept = con.execute("SELECT count(*) FROM frames WHERE session = ?", (sid,)).fetchone()[0]
        assert frames_kept == len(got), f"chunks and frames of different batches {why}"
        con.close()

    with Archive(str(path)) as a:  # one more session after the last kill, ended properly
        a.begin(layout=layout, project="tank", port="/dev/after", baud=115200, started=time.time())
        a.rx(time.time_ns(), frames[0])
    rows = sessions(str(path))
    assert [s["id"] for s in rows] == list(range(1, len(moments) + 2))
    assert [s["ended"] is None for s in rows] == [True] * len(moments) + [False]
    assert rows[-1]["bytes"] == len(frames[0])
