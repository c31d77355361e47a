"""The banks a flight is resumed from (docs/safety.md, "A reset in
flight") are checked with a Fletcher-16 seeded with the application's
link schema: the state vector's layout, the tasks, the streams, the
machines' states. It left out what else the banks hold: each machine's
stored locals, the recorder's flight, an uploaded machine's RAM. So two
builds of examples/rocket whose mission machine lists `peak` and `still`
(two F32 locals) in the other order seeded the check alike, and a bank
written by one was taken by the other: after the reset the apogee
detector's `peak` would have been the landing detector's `still`.

Now the seed also covers the kept locals (their types and names in their
order) and rolling windows, the evaluation type, the runtime's version, and which of the
recorder's flight and an uploaded machine's RAM the banks hold; the same
project still gets the same seed."""

from __future__ import annotations

import re
import shutil

from conftest import EXAMPLES


def seed(fsw, tmp_path, name: str, *edits) -> str:
    proj = tmp_path / name
    shutil.copytree(EXAMPLES / "rocket", proj)
    sm = proj / "mission.sm"
    text = sm.read_text()
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new, 1)
    sm.write_text(text)
    r = fsw("gen", str(proj), "--out", str(tmp_path / f"{name}-gen"))
    assert r.code == 0, r.err
    cpp = (tmp_path / f"{name}-gen" / "app.gen.cpp").read_text()
    [found] = re.findall(r"kResumeConfig FSW_FLASH = \{kResumeSpans, resume_banks, (0x[0-9a-f]{8})UL", cpp)
    return found


def test_locals_in_another_order_seed_the_check_otherwise(fsw, tmp_path):
    peak, still = "F32 peak          = 0\n", "F32 still         = 0\n"
    a = seed(fsw, tmp_path, "a")
    b = seed(fsw, tmp_path, "b", (peak, "@@\n"), (still, peak), ("@@\n", still))
    assert a != b


def test_the_same_project_gets_the_same_seed(fsw, tmp_path):
    a = seed(fsw, tmp_path, "a")
    # an initial value is no layout: the kept value is the flight's
    b = seed(fsw, tmp_path, "b", ("F32 peak          = 0\n", "F32 peak          = 1\n"))
    assert a == b
