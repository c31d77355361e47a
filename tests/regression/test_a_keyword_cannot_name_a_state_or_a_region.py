"""A section header named by a keyword (`[else]`, `[not]`, `[and]`) was
taken as a state of a machine or a region of a state vector without a word,
though spec §1 makes `if else and or not true false` keywords, never names:
a state called `else` could not be the target of any transition (`-> else`
said only ``expected a state name after `->`, found `else` ``, as if the
state did not exist), and a keyword named no element, alias or local
either. Now the header is refused where it stands, in a machine
(`` `else` is a keyword and cannot name a state ``) and in a state vector
(`` `and` is a keyword and cannot name a region ``), and the rest of the
file is still checked."""

from __future__ import annotations

import pytest

from conftest import run_fsw

from fswkit.autocode.lexer import KEYWORDS

SV = "[Vehicle]\nU64 time\nU32 state\n"
SM = """[state_vector]
U64 time @alias G
U32 state @alias S

[Idle]
.step
    G > 10: -> Idle

[{name}]
.entry
    nope = 1
"""


@pytest.mark.parametrize("name", sorted(KEYWORDS))
def test_a_keyword_state_is_refused_at_its_header(tmp_path, name):
    (tmp_path / "m.sv").write_text(SV)
    (tmp_path / "m.sm").write_text(SM.format(name=name))
    r = run_fsw("check", str(tmp_path / "m.sm"))
    assert r.code == 1, r.out + r.err
    assert f"m.sm:9:2:\n  | [{name}]\n  |  ^ `{name}` is a keyword and cannot name a state\n" in r.err
    assert "m.sm:11:5:" in r.err and "unknown element `nope`" in r.err  # the state's body is still checked
    assert "1 file, 2 errors" in r.out + r.err


def test_a_keyword_region_is_refused_at_its_header(tmp_path):
    (tmp_path / "v.sv").write_text("[and]\nU64 time\n[Ok]\nU32 state\n[true]\nbool b\nbool b\n")
    r = run_fsw("check", str(tmp_path / "v.sv"))
    assert r.code == 1, r.out + r.err
    assert "v.sv:1:2:\n  | [and]\n  |  ^ `and` is a keyword and cannot name a region\n" in r.err
    assert "v.sv:5:2:\n  | [true]\n  |  ^ `true` is a keyword and cannot name a region\n" in r.err
    assert "reuse of element name `b`" in r.err
    assert "1 file, 3 errors" in r.out + r.err


def test_a_keyword_in_a_longer_name_is_still_a_name(tmp_path):
    (tmp_path / "m.sv").write_text("[android]\nU64 time\nU32 state\n")
    (tmp_path / "m.sm").write_text(SM.format(name="notify").replace("    nope = 1\n", "    -> Idle\n")
                                   .replace("-> Idle\n\n", "-> notify\n\n", 1))
    r = run_fsw("check", str(tmp_path / "m.sm"))
    assert r.code == 0, r.out + r.err
