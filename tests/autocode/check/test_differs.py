"""One test per **[differs]** item of the language spec: where the kit
deliberately fixes a defect of the thesis's reference implementation. Each
shows the kit's behaviour with a real machine and script (`fsw test`) or
with `fsw check`. A last group pins down choices the kit made where the spec
is silent (docs/languages.md, "Choices where the spec is silent")."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from conftest import ROOT, run_fsw

REALS = ("f64", "f32")

SV = """\
[Time]
U64 time
U32 state

[Data]
F64 x
F64 y
I32 a
I32 b
bool order
bool notify
bool iffy
bool android
U8 pick
"""

ELEMENTS = """\
[state_vector]
U64 time @alias G
U32 state @alias S
F64 x
F64 y
I32 a
I32 b
bool order
bool notify
bool iffy
bool android
U8 pick
"""


def project(folder: Path, sm_body: str, ss: str, local: str = "") -> Path:
    (folder / "d.sv").write_text(SV)
    (folder / "d.sm").write_text(ELEMENTS + ("\n[local]\n" + local if local else "") + "\n" + sm_body)
    (folder / "d.ss").write_text(ss)
    return folder / "d.ss"


def final(out: str) -> dict[str, str]:
    return dict(re.findall(r"^  (\S+) = (.*)$", out.split("final state vector:\n", 1)[1], re.M))


def passes(folder: Path, sm_body: str, ss: str, real: str = "f64", local: str = "") -> dict[str, str]:
    r = run_fsw("test", str(project(folder, sm_body, ss, local)), "--real", real)
    assert r.code == 0 and r.err == "", r.err + r.out
    return final(r.out)


ONE_STEP = "[options]\ndelta_t 1\n\n[all_states]\nG == 0: @stop\n"


# ---- §1 lexical rules ---------------------------------------------------------

@pytest.mark.parametrize("real", REALS)
def test_keywords_are_whole_words_order_notify_iffy_android_are_names(tmp_path, real):
    sm = """\
[Run]
.step
    order = true
    notify = not order
    iffy = order and not notify
    android = iffy or notify
    if android and order: pick = 1
    else: pick = 2
"""
    script = """\
[options]
delta_t 1

[all_states]
G == 0: @stop
true: @assert iffy and android
"""
    v = passes(tmp_path, sm, script, real)
    assert (v["order"], v["notify"], v["iffy"], v["android"], v["pick"]) == ("true", "false", "true", "true", "1")


@pytest.mark.parametrize("real", REALS)
def test_numbers_take_an_exponent_and_a_trailing_dot(tmp_path, real):
    sm = """\
[Run]
.step
    x = 1e3 + 2.5E-3 + 5. + .5
    y = 1E+2 * 3.e-1
    a = 12 + 0.5e1
"""
    v = passes(tmp_path, sm, ONE_STEP, real)
    assert v["x"] == ("1005.502500" if real == "f64" else "1005.502502")  # binary32 rounding shows
    assert v["y"] == ("30.000000" if real == "f64" else "30.000002")  # 3.e-1 is not exact in binary32
    assert v["a"] == "17"


@pytest.mark.parametrize("real", REALS)
def test_minus_is_always_an_operator(tmp_path, real):
    sm = """\
[Run]
.step
    a = 10
    b = a-1
    x = 5-3
    y = - -1
    a = -(a + b) - -a
    pick = 7-2*3
"""
    v = passes(tmp_path, sm, ONE_STEP, real)
    # b-1 is b minus 1, not `b` then the number `-1`; the same without spaces
    assert (v["b"], v["x"], v["y"], v["a"], v["pick"]) == ("9", "2.000000", "1.000000", "-9", "1")


def test_minus_glued_to_a_number_is_still_an_operator_in_check(tmp_path):
    project(tmp_path, "[Run]\n.step\n    a = b-1\n    a = b -1\n    a = 5-3-1\n", ONE_STEP)
    r = run_fsw("check", "d.sm", cwd=tmp_path)
    assert r.code == 0, r.err


# ---- §4.3 states ------------------------------------------------------------------

def test_duplicate_state_names_are_an_error(tmp_path):
    sm = "[Run]\n.step\n    a = 1\n\n[Stop]\n\n[Run]\n.step\n    -> Stop\n"
    project(tmp_path, sm, ONE_STEP)
    r = run_fsw("check", "d.sm", cwd=tmp_path)
    assert r.code == 1
    assert r.err.startswith("state machine config error @ d.sm:20:2:\n"
                            "  | [Run]\n"
                            "  |  ^ reuse of state name `Run` (previously used on line 14)\n")
    r = run_fsw("test", "d.ss", cwd=tmp_path)
    assert r.code == 2 and r.out == ""  # a script never runs a machine with errors


ELSE_SPELLINGS = """\
[Run]
.step
    if x > 3: pick = 4
    else if x > 2: pick = 3
    else: if x > 1: pick = 2
    else
    if x > 0: pick = 1
    else:
    if x > -1 { pick = 10 }
    else if x > -2 {
        pick = 11
    } else: if x > -3 {
        pick = 12
    }
    else {
        pick = 13
    }
"""


@pytest.mark.parametrize("x, pick", [(5, 4), (3, 3), (2, 2), (1, 1), (0, 10), (-1, 11), (-2, 12), (-3, 13)])
def test_else_if_and_else_colon_if_chain_on_one_line_and_across_lines(tmp_path, x, pick):
    script = f"[options]\ndelta_t 1\n\n[all_states]\ntrue: x = {x}\nG == 0: @stop\n"
    v = passes(tmp_path, ELSE_SPELLINGS, script)
    assert v["pick"] == str(pick)


# ---- §4.4 expressions -------------------------------------------------------------

@pytest.mark.parametrize("real", REALS)
def test_parenthesised_comparison_does_not_chain(tmp_path, real):
    sm = """\
[Run]
.step
    order = (1 < 5) < 3
    notify = 1 < 5 < 3
    iffy = (3 > 2) > 1
    android = 3 > 2 > 1
    a = 10
    x = 1 < a <= 10 < 11
    y = ((1 < a) <= 10) < 11 == 1
    pick = 2 == 2 == 1
"""
    v = passes(tmp_path, sm, ONE_STEP, real)
    # (1 < 5) is the value 1, and 1 < 3: true; the chain 1 < 5 < 3 means 1 < 5 and 5 < 3: false
    assert (v["order"], v["notify"]) == ("true", "false")
    assert (v["iffy"], v["android"]) == ("false", "true")
    assert (v["x"], v["y"]) == ("1.000000", "1.000000")
    assert v["pick"] == "1"  # `==` never chains: (2 == 2) == 1


# ---- §4.5 NaN ------------------------------------------------------------------------

@pytest.mark.parametrize("real", REALS)
def test_nan_is_false_everywhere_also_inside_and_or_not(tmp_path, real):
    sm = """\
[Run]
.step
    x = 0 / 0
    order = x and true
    notify = x or false
    iffy = not x
    android = not (x and x) and not (x or x)
    if x: a = 1
    else: a = 2
    x and true: b = 1
    x or false: b = 2
    not x: pick = 3
"""
    # A NaN written to an F64 is stored as 0: use the division itself too.
    sm += "    !(0/0) and (1 or 0/0): y = 1\n    (0/0) or (0/0): y = 2\n"
    v = passes(tmp_path, sm, ONE_STEP, real)
    assert (v["order"], v["notify"], v["iffy"], v["android"]) == ("false", "false", "true", "true")
    assert (v["a"], v["b"], v["pick"], v["y"]) == ("2", "0", "3", "1.000000")


@pytest.mark.parametrize("real", REALS)
def test_nan_is_false_in_script_guards_and_asserts(tmp_path, real):
    script = """\
[options]
delta_t 1

[all_states]
0/0: a = 1
not (0/0): b = 1
true: @assert not (0/0 or 0/0)
G == 0: @stop
"""
    r = run_fsw("test", str(project(tmp_path, "[Run]\n", script)), "--real", real)
    assert r.code == 0, r.out
    assert r.out.startswith("state script ran for 1 step\n1 assert passed\n")
    assert (final(r.out)["a"], final(r.out)["b"]) == ("0", "1")


# ---- §5 state scripts -------------------------------------------------------------------

def test_max_steps_stops_a_script_that_never_reaches_stop(tmp_path):
    script = """\
[options]
delta_t 10

[all_states]
true: x = x + 1
G == 5: @stop
"""
    r = run_fsw("test", str(project(tmp_path, "[Run]\n", script)))
    assert r.code == 1
    assert r.out.startswith(
        "state script ran for 1000000 steps\n"
        "0 asserts passed\n"
        f"state script error @ {tmp_path / 'd.ss'}:6:9:\n"
        "  | G == 5: @stop\n"
        "  |         ^ `@stop` not reached within 1000000 steps "
        "(raise `max_steps` in [options] if the script needs more)\n"
        "final state vector:\n"
        "  G = 9999990\n")
    assert final(r.out)["x"] == "1000000.000000"


def test_scripts_cannot_write_g_s_or_t(tmp_path):
    script = """\
[options]
delta_t 10

[all_states]
G == 0: G = 2000
G == 10: S = 1
G == 20: T = 0
G == 30: time = 0
G == 1000: @stop
"""
    project(tmp_path, "[Run]\n", script)
    r = run_fsw("check", "d.ss", cwd=tmp_path)
    assert r.code == 1
    heads = re.findall(r"^state script error @ d\.ss:(\d+):(\d+):\n.*\n.*\^ (.*)$", r.err, re.M)
    assert [(int(l), int(c)) for l, c, _ in heads] == [(5, 9), (6, 10), (7, 10), (8, 10)]
    msgs = [m for _, _, m in heads]
    assert msgs[0].startswith("`G` cannot be written by a state script: it is the global time")
    assert msgs[1].startswith("`S` cannot be written by a state script: it is the current state's ID")
    assert msgs[2].startswith("`T` cannot be written by a state script: it is the time spent")
    assert msgs[3].startswith("`time` cannot be written by a state script: it is `G`, the global time")
    assert run_fsw("test", "d.ss", cwd=tmp_path).code == 2


# ---- choices where the spec is silent -------------------------------------------------------

def test_else_binds_to_the_nearest_if(tmp_path):
    sm = """\
[Run]
.step
    pick = 0
    x > 0: x > 10: pick = 1
    else: pick = 2
"""
    for x, pick in ((20, "1"), (5, "2"), (-5, "0")):
        script = f"[options]\ndelta_t 1\n\n[all_states]\ntrue: x = {x}\nG == 0: @stop\n"
        assert passes(tmp_path, sm, script)["pick"] == pick


def test_a_script_finds_its_machine_by_the_longest_stem_prefix(tmp_path):
    project(tmp_path, "[Run]\n.step\n    pick = 1\n", ONE_STEP)
    (tmp_path / "d_long.sm").write_text(ELEMENTS + "\n[Other]\n.step\n    pick = 2\n")
    (tmp_path / "d_long_case.ss").write_text(ONE_STEP)
    (tmp_path / "d_other.ss").write_text(ONE_STEP)
    assert final(run_fsw("test", "d_long_case.ss", cwd=tmp_path).out)["pick"] == "2"  # d_long.sm
    assert final(run_fsw("test", "d_other.ss", cwd=tmp_path).out)["pick"] == "1"  # d.sm
    # both machines find d.sv: the only .sv in the folder


def test_columns_count_tabs_to_the_next_multiple_of_8(tmp_path):
    project(tmp_path, "[Run]\n.step\n\tif x > 1 {\n\t\tpik = 1\n\t}\n", ONE_STEP)
    r = run_fsw("check", "d.sm", cwd=tmp_path)
    assert r.err.startswith("state machine config error @ d.sm:17:17:\n"
                            "  |                 pik = 1\n"
                            "  |                 ^ unknown element `pik`\n")


def test_a_byte_order_mark_is_ignored(tmp_path):
    project(tmp_path, "[Run]\n.step\n    pick = 1\n", ONE_STEP)
    for name in ("d.sv", "d.sm", "d.ss"):
        p = tmp_path / name
        p.write_bytes(b"\xef\xbb\xbf" + p.read_bytes())
    r = run_fsw("test", "d.ss", cwd=tmp_path)
    assert r.code == 0 and final(r.out)["pick"] == "1"


def test_state_vector_and_local_sections_come_before_states(tmp_path):
    (tmp_path / "d.sv").write_text(SV)
    (tmp_path / "d.sm").write_text("[Run]\n\n" + ELEMENTS)
    r = run_fsw("check", "d.sm", cwd=tmp_path)
    assert "^ `[state_vector]` must come before the first state\n" in r.err


# ---- refused here, quietly accepted by the reference (docs/languages.md 10-15) ------------

REFUSED = [
    # (what, machine body or None, script body or None, file:line:col, exact message)
    ("prefix operator", "[A]\n.step\n    pick = + pick 1\n", None, "d.sm:16:12",
     "expected an expression, found `+`"),
    ("prefix operator in a script", "[A]\n.step\n    pick = 1\n", "true: pick = + pick 1\n", "d.ss:5:14",
     "expected an expression, found `+`"),
    ("guard with nothing after `:`", "[A]\n.step\n    x > 1:\n", None, "d.sm:16:11",
     "expected a statement after `:`"),
    ("script guard with nothing after `:`", "[A]\n.step\n    pick = 1\n", "G == 100:\n", "d.ss:5:10",
     "expected a statement after `:`"),
    ("statement after `}`", "[A]\n.step\n    x > 1 {\n        pick = 1\n    } pick = 2\n", None, "d.sm:18:7",
     "unexpected `pick` after the statement"),
    ("statement after `}` on a one-line block", "[A]\n.step\n    x > 1 { pick = 1 } pick = 2\n", None,
     "d.sm:16:24", "unexpected `pick` after the statement"),
]


@pytest.mark.parametrize("what,sm,ss,where,message", REFUSED, ids=[r[0] for r in REFUSED])
def test_refused_where_the_reference_quietly_accepts(tmp_path, what, sm, ss, where, message):
    script = "[options]\ndelta_t 10\n\n[all_states]\n" + (ss or "") + "G == 100: @stop\n"
    project(tmp_path, sm, script)
    r = run_fsw("check", "d.ss" if ss else "d.sm", cwd=tmp_path)
    assert r.code == 1
    assert f" error @ {where}:\n" in r.err and f"^ {message}\n" in r.err, r.err
    assert r.err.count(" error @ ") == 1
    assert message.replace("`pick`", "`n`") in DOC  # the reference lists each message, with `n` for the name


DOC = (ROOT / "docs" / "languages.md").read_text()


def test_an_alias_equal_to_an_earlier_name_is_refused(tmp_path):
    (tmp_path / "d.sv").write_text(SV)
    (tmp_path / "d.sm").write_text(ELEMENTS.replace("U8 pick\n", "U8 pick @alias a\n") + "\n[A]\n.step\n    pick = 1\n")
    r = run_fsw("check", "d.sm", cwd=tmp_path)
    assert r.code == 1
    assert "d.sm:12:16:\n  | U8 pick @alias a\n  |                ^ reuse of name `a` (previously used on line 6)\n" in r.err
    assert "reuse of name `n` (previously used on line N)" in DOC


@pytest.mark.parametrize("decl,where,message", [
    ("U8 pick @alias T", "d.sm:12:16", "`T` is the built-in time in state and cannot name an element"),
    ("U8 T", "d.sm:12:4", "`T` is the built-in time in state and cannot name an element"),
    ("U8 pick\n\n[local]\nU8 T = 1", "d.sm:15:4", "`T` is the built-in time in state and cannot name a local"),
])
def test_t_cannot_be_a_name(tmp_path, decl, where, message):
    (tmp_path / "d.sv").write_text(SV + "U8 T\n")
    (tmp_path / "d.sm").write_text(ELEMENTS.replace("U8 pick\n", decl + "\n") + "\n[A]\n.step\n    x = 1\n")
    r = run_fsw("check", "d.sm", cwd=tmp_path)
    assert r.code == 1 and f" error @ {where}:\n" in r.err and f"^ {message}\n" in r.err, r.err
    assert message.split(" cannot")[0] in DOC


@pytest.mark.parametrize("option,value", [("delta_t", "20"), ("init_state", "A"), ("max_steps", "5")])
def test_a_repeated_script_option_is_refused(tmp_path, option, value):
    first = "" if option == "delta_t" else f"{option} {value}\n"
    ss = f"[options]\ndelta_t 10\n{first}{option} {value}\n\n[all_states]\nG == 100: @stop\n"
    project(tmp_path, "[A]\n.step\n    pick = 1\n", ss)
    r = run_fsw("check", "d.ss", cwd=tmp_path)
    line = 3 if option == "delta_t" else 4
    assert r.code == 1
    assert f"d.ss:{line}:1:\n" in r.err and f"^ duplicate option `{option}` (previously on line {line - 1})\n" in r.err
    assert "duplicate option `delta_t` (previously on line N)" in DOC
