"""A machine was checked only as far as its state vector config allowed:
with no `.sv` found it was told only of its syntax errors (a duplicate
state, a transition to no state, a transition in `.exit`, an unknown name
came out on the next run, once the `.sv` was named), and an element the
`.sv` declared with a type it does not know (`F65 time`) was said twice,
the second time as a falsehood: ``element `time` is not in the state
vector config``. Spec §8 wants every independent error in one run, and
only true ones. Now a machine whose `.sv` is missing is checked against its
own `[state_vector]` (the checks that need the `.sv`, an element's
presence and type there, wait for it), and an element the `.sv` declared
unreadably is not said to be missing from it."""

from __future__ import annotations

from conftest import run_fsw

SM = """[state_vector]
U64 time @alias G
U32 state @alias S
F64 x

[local]
F64 a = nope

[A]
.step
    x = y
    -> Nowhere
[A]
.exit
    -> A
"""
OWN = ["m.sm:7:9:", "unknown element `nope`",
       "m.sm:11:9:", "unknown element `y`",
       "m.sm:12:8:", "unknown state `Nowhere`",
       "m.sm:13:2:", "reuse of state name `A` (previously used on line 9)",
       "m.sm:15:5:", "illegal transition in exit label"]


def test_a_machine_without_a_state_vector_is_checked_for_the_rest(tmp_path):
    (tmp_path / "m.sm").write_text(SM)
    r = run_fsw("check", "m.sm", cwd=tmp_path)
    assert r.code == 1, r.out + r.err
    assert "m.sm:1:1:" in r.err and "no state vector config (.sv) found beside m.sm" in r.err
    for piece in OWN:
        assert piece in r.err, r.err
    assert "1 file, 6 errors" in r.out + r.err


def test_a_state_vectors_unreadable_element_is_not_called_missing(tmp_path):
    (tmp_path / "m.sv").write_text("[R]\nF65 time\nU32 state\nF64 x\n")
    (tmp_path / "m.sm").write_text(SM)
    r = run_fsw("check", "m.sv", "m.sm", cwd=tmp_path)
    assert r.code == 1, r.out + r.err
    assert "m.sv:2:1:" in r.err and "unknown type `F65`" in r.err
    assert "not in the state vector config" not in r.err, r.err
    for piece in OWN:
        assert piece in r.err, r.err
    assert "2 files, 6 errors" in r.out + r.err


def test_a_machine_is_still_told_what_its_state_vector_lacks(tmp_path):
    (tmp_path / "m.sv").write_text("[R]\nU64 time\nU32 state\nF32 x\n")
    (tmp_path / "m.sm").write_text(SM.replace("F64 x\n", "F64 x\nbool gone\n"))
    r = run_fsw("check", "m.sm", cwd=tmp_path)
    assert r.code == 1, r.out + r.err
    assert "type mismatch: `x` is F32 in the state vector config, not F64" in r.err
    assert "element `gone` is not in the state vector config (m.sv)" in r.err
