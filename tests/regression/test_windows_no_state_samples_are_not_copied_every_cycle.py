"""The flight's save (docs/safety.md, "A reset in flight") copied every
kept span at every cycle, a machine's rolling windows too where none of
its states samples them any more: the rocket's mission pushes its three
windows in Safe, Armed, Boost and Abort only, and its 86 B were copied,
unchanged, through the coast, the descent and the landing (about 46 us of
each 100 Hz cycle). Such windows are now a watched span
(fsw::ResumeWatch): the machine's code says when they change (its pushes,
its reset), and a save copies them only until both banks hold them; then
it adds the check sums it kept to the bank's check, the same check bits
(tests/firmware/test_resume.cpp: every bank equal to a save that copies
everything). tests/safety/test_flight_resumes.py resumes the rocket in
each phase of its flight."""

from __future__ import annotations

import re

from conftest import run_fsw
from support.configs import example_copy


def _gen(tmp_path):
    proj = example_copy("rocket", tmp_path)
    r = run_fsw("gen", str(proj), "--out", str(tmp_path / "gen"))
    assert r.code == 0, r.out + r.err
    return {p.name: p.read_text() for p in (tmp_path / "gen").iterdir()}


def test_the_missions_windows_are_watched_and_the_navs_are_not(tmp_path):
    files = _gen(tmp_path)
    app, mission, nav = files["app.gen.cpp"], files["mission.gen.cpp"], files["nav.gen.cpp"]
    spans = re.findall(r"^    \{(.*?), (.*?)\},  // (.*)$",
                       app.split("kResumeSpans")[1].split("};")[0], re.M)
    i = next(k for k, (p, _, _) in enumerate(spans) if p == "reinterpret_cast<uint8_t*>(&mission::win)")
    assert f"{{{i}, &mission::win_changed, resume_watch_state[0]}}" in app, app
    assert re.search(r"kResumeConfig FSW_FLASH = \{kResumeSpans, resume_banks, 0x[0-9a-f]+UL, kResumeSize, "
                     rf"{len(spans)}, kResumeWatch, 1\}};", app), app
    # every push of the mission's windows, and its reset, says so; the nav samples in every state
    block = mission.split("switch (state) {  // sampled where still read")[1].split("default:")[0]
    assert "win.w0.push(x0);" in block and "win_changed = 1;" in block, block
    assert mission.split("void reset(uint32_t initial) {")[1].split("}")[0].count("win_changed = 1;") == 1
    assert "win_changed" not in nav
