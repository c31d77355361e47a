"""When a script's machine had an error, `fsw check` and `fsw test` said
nothing of the script's own errors but its syntax: a `delta_t 0`, an
unknown or repeated option, a `max_steps` that is no whole number, a
script without `@stop` came out only on the next run, once the machine was
mended. None of them depends on the machine, and spec §8 wants every
independent error in one run. Now they are reported with the machine's
(the checks that need the machine's names, states and locals still wait
for it)."""

from __future__ import annotations

from conftest import run_fsw

SV = "[Vehicle]\nU64 time\nU32 state\nF64 x\n"
SM = ("[state_vector]\nU64 time @alias G\nU32 state @alias S\nF64 x\n\n"
      "[Only]\n.step\n    x = nope\n")
SS = """[options]
delta_t 0
max_steps 2.5
max_steps 3
init_state Nowhere
speed 4

[all_states]
true: x = 1
true: @assert unknown_but_not_yet_said > 1
"""


def test_the_script_errors_that_need_no_machine_come_with_the_machines(tmp_path):
    for name, text in (("m.sv", SV), ("m.sm", SM), ("m.ss", SS)):
        (tmp_path / name).write_text(text)
    for args in (("check", "m.sm", "m.ss"), ("test", "m.ss")):
        r = run_fsw(*args, cwd=tmp_path)
        assert r.code == (1 if args[0] == "check" else 2), r.out + r.err
        assert "m.sm:8:9:" in r.err and "unknown element `nope`" in r.err
        assert "m.ss:2:9:\n  | delta_t 0\n  |         ^ `delta_t` must be a positive integer, found `0`\n" in r.err
        assert "m.ss:3:11:" in r.err and "`max_steps` must be a positive integer, found `2.5`" in r.err
        assert "m.ss:4:1:" in r.err and "duplicate option `max_steps` (previously on line 3)" in r.err
        assert "m.ss:6:1:" in r.err and "unknown option `speed`" in r.err
        assert "m.ss:10:1:" in r.err and "the state script has no `@stop`: it would never end" in r.err
        # what needs the machine waits for it
        assert "unknown state `Nowhere`" not in r.err
        assert "unknown element `unknown_but_not_yet_said`" not in r.err
        assert r.err.count("state script error") == 5


def test_a_sound_script_of_a_broken_machine_adds_nothing(tmp_path):
    for name, text in (("m.sv", SV), ("m.sm", SM),
                       ("m.ss", "[options]\ndelta_t 1\n[all_states]\ntrue: @stop\n")):
        (tmp_path / name).write_text(text)
    r = run_fsw("check", "m.sm", "m.ss", cwd=tmp_path)
    assert r.code == 1
    assert "m.ss" not in r.err and "1 error" in r.out + r.err
