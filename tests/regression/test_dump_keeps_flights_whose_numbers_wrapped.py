"""Flight numbers go 1..255 and then 1 again, and a store that never
fills (an SPI NOR chip holds thousands of records) can hold two flights of
one number. `fsw dump --all` wrote both to the one `flight-N.log`: without
`--force` it stopped half-way saying the file it had just written
"exists"; with `--force` the newer flight replaced the older, which was
then gone from the dump (and `--erase` took it from the target). A number
that the store holds more than once now names its flights `flight-N.log`,
`flight-N-2.log`, ... oldest first, whichever flights a dump writes; a
number held once is `flight-N.log` as before."""

from __future__ import annotations

import csv
import io
import sys
from pathlib import Path

from conftest import run_fsw

from fswkit.autocode.app import load_app
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.recorder import plan

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from support.recorder_image import FakeGround, data_record, fake_target, image, start_record  # noqa: E402

RIG = Path(__file__).resolve().parent.parent / "recorder" / "spi"


def _store():
    """257 flights of a start and one record of three samples: numbers
    1..255, 1, 2; flight k's samples at k seconds."""
    p = plan(load_app(str(RIG / "spi.app"), Diagnostics()))
    recs = {}
    for k in range(257):
        t = 1000 * k
        recs[2 * k] = start_record(p, 2 * k, k % 255 + 1, t)
        recs[2 * k + 1] = data_record(p, 2 * k + 1, k % 255 + 1, t, 20, [
            [b"\x02", (t + 20 * i).to_bytes(4, "little", signed=True), b"\x00\x00"] for i in range(3)])
    return p, FakeGround(p, image(p, recs, blank=0xFF), head=514, seq=514, flight=2)


def _first_time(log: Path) -> float:
    r = run_fsw("log2csv", str(log))
    assert r.code == 0, r.err
    return float(next(csv.DictReader(io.StringIO(r.out)))["target time [s]"])


def test_all_writes_every_flight_to_a_file_of_its_own(tmp_path, monkeypatch):
    p, g = _store()
    out = tmp_path / "d"
    with fake_target(monkeypatch, g):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(out), "--all")
    assert r.code == 0, r.err
    assert len(list(out.iterdir())) == 257
    assert _first_time(out / "flight-1.log") == 0.0 and _first_time(out / "flight-1-2.log") == 255.0
    assert _first_time(out / "flight-2.log") == 1.0 and _first_time(out / "flight-2-2.log") == 256.0
    assert _first_time(out / "flight-3.log") == 2.0 and not (out / "flight-3-2.log").exists()


def test_the_newest_alone_has_the_name_it_has_in_all(tmp_path, monkeypatch):
    p, g = _store()
    out = tmp_path / "d"
    with fake_target(monkeypatch, g):
        r = run_fsw("dump", str(RIG), "--port", "fake", "-o", str(out))
    assert r.code == 0, r.err
    assert [x.name for x in out.iterdir()] == ["flight-2-2.log"]
    assert _first_time(out / "flight-2-2.log") == 256.0
