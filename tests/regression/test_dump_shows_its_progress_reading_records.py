"""`fsw dump` of an SPI NOR chip reads every written record over the
link, one LOG_READ at a time: thousands of records at 115,200 baud take
minutes, with nothing on the terminal between the `recorder:` line and the
end, as a hung command looks. The read now shows its progress (records
read of those to read) on a terminal, as builds and flights do."""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path

from conftest import run_fsw

from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.recorder import plan

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from support.recorder_image import FakeGround, data_record, fake_target, image, start_record  # noqa: E402

RIG = Path(__file__).resolve().parent.parent / "recorder" / "spi"


def test_the_read_reports_each_record_of_those_to_read(tmp_path, monkeypatch):
    import fswkit.progress

    bars = []

    class Bar:
        def __init__(self, label, total, unit):
            self.label, self.total, self.unit, self.done = label, total, unit, []

        def update(self, done, **fields):
            self.done.append(done)

    @contextlib.contextmanager
    def progress(label, total=None, unit=""):
        bars.append(Bar(label, total, unit))
        yield bars[-1]

    monkeypatch.setattr(fswkit.progress, "progress", progress)
    p = plan(load_app(str(RIG / "spi.app"), Diagnostics()))
    recs = {0: start_record(p, 0, 1, 100)}
    for k in range(1, 40):
        recs[k] = data_record(p, k, 1, 100 + 60 * k, 20, [[b"\x02", (k + i).to_bytes(4, "little"), b"\x00\x00"]
                                                           for i in range(3)])
    with fake_target(monkeypatch, FakeGround(p, image(p, recs, blank=0xFF), head=40, seq=40)):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(tmp_path / "d"))
    assert r.code == 0, r.err
    (bar,) = bars
    assert bar.total == 41 and bar.done[-1] == 41 and bar.done == sorted(bar.done), (bar.total, bar.done[-3:])
