"""`lock` given twice in a state vector config (on two lines, or in two
`[options]` sections) was accepted without a word, where a script's option
given twice (`duplicate option `delta_t``) and an annotation given twice on
an element (`redundant read-only annotation`, spec §4.1) are errors: every
config of the kit says an option once. It is now
`` duplicate option `lock` (previously on line N) ``, at the repeated one."""

from __future__ import annotations

from conftest import run_fsw


def test_lock_twice_is_a_located_error(tmp_path):
    (tmp_path / "v.sv").write_text("[options]\nlock\nlock\n[R]\nU64 time\n[options]\nlock\n")
    r = run_fsw("check", str(tmp_path / "v.sv"))
    assert r.code == 1, r.out + r.err
    assert "v.sv:3:1:\n  | lock\n  | ^ duplicate option `lock` (previously on line 2)\n" in r.err
    assert "v.sv:7:1:\n  | lock\n  | ^ duplicate option `lock` (previously on line 2)\n" in r.err
    assert "1 file, 2 errors" in r.out + r.err


def test_lock_once_in_either_place_is_fine(tmp_path):
    for text in ("[options]\nlock\n[R]\nU64 time\n", "[R]\nU64 time\n[options]\n[options]\nlock\n"):
        (tmp_path / "v.sv").write_text(text)
        r = run_fsw("check", str(tmp_path / "v.sv"))
        assert r.code == 0, r.out + r.err
