"""The application languages' stages one at a time: the parser gives a tree
of rows with positions (appsyntax), the checker resolves a tree and reports
on it (appcheck, iotables), the model stage assembles an `Application`
(app.application), and load_app chains them."""

from __future__ import annotations

import shutil
from fractions import Fraction

import pytest

from conftest import EXAMPLES
from fswkit.autocode import app as A
from fswkit.autocode import model as M
from fswkit.autocode.appcheck import Report, check_app, complete, options, positive
from fswkit.autocode.appsyntax import (AppFile, ChannelRow, ConfigFile, Problem, Setting, StreamRow, TaskRow,
                                       WritableRow, parse_app, parse_options, parse_table)
from fswkit.autocode.board import load_board
from fswkit.autocode.diagnostics import Diagnostics, Source
from fswkit.autocode.iotables import check_channels
from fswkit.autocode.lexer import ID, NUM, Tok, lex


def src(text: str, path: str = "rig/x.app") -> Source:
    return Source.from_text(path, text)


def where(diags: Diagnostics) -> list[tuple[int, int, str]]:
    return [(d.line, d.col, d.message) for d in diags.items]


# ---- parse ------------------------------------------------------------------------

APP = """\
# a rig
[application]
board uno
rate  100

[configs]
state_vector tank.sv
machine      my tank.sm   # a name with a space
io           tank.aio

[tasks]
sense    inputs        rate=100
control  machine tank  rate=50 mode=controlMode
act      outputs       rate=100 stray

[telemetry]
Sensors  rate=10

[uplink]
valveOpen
heater extra

[budget]
flash 12288
"""


def test_parse_gives_rows_with_positions():
    diags = Diagnostics()
    tree = parse_app(src(APP), diags)
    assert diags.items == []
    assert isinstance(tree, AppFile)
    board, rate = tree.application
    assert isinstance(board, Setting)
    assert (board.key.text, board.key.line, board.key.col) == ("board", 3, 1)
    assert [(v.text, v.kind, v.line, v.col) for v in rate.values] == [("100", NUM, 4, 7)]

    sv, machine, io = tree.configs
    assert isinstance(sv, ConfigFile) and sv.path == "rig/tank.sv"
    assert (machine.file.text, machine.file.line, machine.file.col) == ("my tank.sm", 8, 14)  # the file name as written, one token
    assert machine.path == "rig/my tank.sm"  # to the comment, as written

    sense, control, act = tree.tasks
    assert isinstance(control, TaskRow)
    assert (control.name.text, control.kind.text, control.machine.text) == ("control", "machine", "tank")
    assert [(o.key.text, o.value.text, o.value.col) for o in control.options.items] == \
        [("rate", "50", 29), ("mode", "controlMode", 37)]
    assert control.options.stray is None and sense.machine is None
    assert [o.key.text for o in act.options.items] == ["rate"]
    assert act.options.stray == Problem(Tok(ID, "stray", 14, 33), "unexpected `stray`: expected `key=value`")

    (stream,) = tree.telemetry
    assert isinstance(stream, StreamRow) and stream.region.text == "Sensors"
    first, second = tree.uplink
    assert isinstance(first, WritableRow) and first.extra is None
    assert (second.extra.text, second.extra.line, second.extra.col) == ("extra", 21, 8)
    assert [s.key.text for s in tree.budget] == ["flash"]
    assert tree.time == ()  # an absent section has no rows


def test_parse_reports_only_the_file_structure():
    diags = Diagnostics()
    tree = parse_app(src("stray\n[bogus]\nx\n[tasks]\na inputs\n[tasks]\nb outputs\n[time\n"), diags)
    assert where(diags) == [
        (8, 1, "malformed section header: expected `[Name]` alone on its line"),
        (1, 1, "unexpected `stray` before the first section"),
        (2, 2, "unknown section `[bogus]`: expected one of [application], [configs], [time], [tasks], "
               "[telemetry], [uplink], [budget], [log], [pyro], [reload]"),
        (6, 2, "duplicate section `[tasks]`"),
    ]
    assert [t.name.text for t in tree.tasks] == ["a"]  # the first of a duplicate section


def test_a_machine_task_without_a_machine_name_has_none():
    tree = parse_app(src("[tasks]\nc machine rate=5\nd machine 7\n"), Diagnostics())
    assert [t.machine for t in tree.tasks] == [None, None]


def test_options_keep_a_key_given_twice_and_stop_at_a_stray_token():
    (toks,) = [t for t in lex(src("a b rate=1 rate=2 = 3 mode=x\n"), Diagnostics(), "x") if t]
    opts = parse_options(toks, 2)
    assert [(o.key.text, o.value.text) for o in opts.items] == [("rate", "1"), ("rate", "2")]
    assert opts.stray.tok.text == "=" and opts.stray.tok.col == 19


def test_parse_table_rows_and_problems():
    diags = Diagnostics()
    table = parse_table(src("i A0 p scale=-2 offset=3 x\nq 4 v\no 4\ni A1 t scale=-\n\n# c\n", "t.aio"),
                        True, diags)
    assert diags.items == []
    a, b, c, d = table.rows
    assert isinstance(a, ChannelRow)
    assert [(k.key.text, k.negative, k.number.text) for k in a.calibrations] == [("scale", True, "2"),
                                                                                 ("offset", False, "3")]
    assert a.stray.message == "unexpected `x`: expected `scale=K` or `offset=B`"
    assert b == Problem(Tok(ID, "q", 2, 1), "expected a direction `i` or `o`, found `q`")
    assert c == Problem(Tok(NUM, "4", 3, 3), "expected an element after the pin")
    (cal,) = d.calibrations
    assert cal.number is None and cal.problem.message == "expected a number after `scale=`"


# ---- check ------------------------------------------------------------------------

@pytest.fixture
def tank(tmp_path):
    shutil.copytree(EXAMPLES / "tank", tmp_path / "tank", ignore=shutil.ignore_patterns("build"))
    return tmp_path / "tank"


def checked(path, text, board=None):
    diags = Diagnostics()
    s = src(text, str(path / "tank.app"))
    before = diags.error_count
    parts = check_app(parse_app(s, diags), diags, board, load_board)
    return parts, diags, s, before


def test_check_resolves_a_tree(tank):
    parts, diags, s, before = checked(tank, (tank / "tank.app").read_text())
    assert diags.items == [] and complete(parts, s, diags, before)
    assert parts.board.name == "uno" and parts.rate == 100 and parts.baud == 115200
    assert [m.name for m in parts.machines] == ["tank"]
    assert [(c.pin, c.element.name) for c in parts.channels] == [("A0", "tankPressure"), ("4", "valveOpen")]
    assert [(t.name, t.kind, t.divider) for t in parts.tasks][:3] == [("uplink", "uplink", 1),
                                                                      ("sense", "inputs", 1),
                                                                      ("control", "machine", 1)]
    assert [(x.region.name, x.divider) for x in parts.streams] == [("Sensors", 2), ("Effectors", 10)]
    assert [e.name for e in parts.writable] == ["valveOpen"]
    assert (parts.sv_tok.text, parts.sv_tok.line, parts.sv_tok.col) == ("tank.sv", 9, 14)  # the file name as written
    assert parts.machine_toks["tank"].line == 10


def test_check_reports_each_section_in_order(tank):
    text = (tank / "tank.app").read_text()
    text = text.replace("rate  100\n", "rate  100\nspeed 3\n").replace("unit   ms", "unit   s")
    text = text.replace("act      outputs       rate=100", "act      outputs       rate=7")
    text = text.replace("Effectors  rate=10", "Effectors  rate=10 rate=5")
    parts, diags, s, before = checked(tank, text)
    assert [m for _, _, m in where(diags)] == [
        "unknown setting `speed`: expected `name`, `board`, `rate`, `baud` or `reset_cause`",
        "`unit` is one of: ms, us",
        "task rate 7 Hz must divide the executor rate 100 Hz",
        "`rate=` given twice",
    ]
    assert not complete(parts, s, diags, before)


def test_check_without_a_state_vector_stops(tank):
    parts, diags, _, _ = checked(tank, "[application]\nboard uno\n")
    assert parts is None
    assert where(diags) == [(1, 1, "missing `state_vector` in [configs]")]


def test_an_application_without_a_machine_says_so(tank):
    parts, diags, s, before = checked(tank, "[application]\nboard uno\n[configs]\nstate_vector tank.sv\n")
    assert diags.items == []
    assert not complete(parts, s, diags, before)
    assert where(diags) == [(1, 1, "an application needs at least one `machine` in [configs]")]


def test_positive_and_options_helpers():
    diags = Diagnostics()
    s = src("[tasks]\na inputs rate=0 rate=2.5 x\n")
    (row,) = parse_app(s, diags).tasks
    r = Report(s, diags)
    opts = options(row.options, r)
    assert positive(opts["rate"][1], r, "`rate`") == Fraction(5, 2)  # the last value of a key given twice
    assert positive(row.options.items[0].value, r, "`rate`") is None
    assert [m for _, _, m in where(diags)] == ["`rate=` given twice", "unexpected `x`: expected `key=value`",
                                               "`rate` must be a positive number, found `0`"]


def test_check_channels_of_a_parsed_table(tank):
    from fswkit.autocode.check import check_sv
    from fswkit.autocode.parser import parse_sv

    diags = Diagnostics()
    sv_src = src((tank / "tank.sv").read_text(), "tank.sv")
    sv = check_sv(parse_sv(sv_src, diags), sv_src, diags)
    table = parse_table(src("i A0 tankPressure scale=2 offset=-1\ni A0 tankPressure\no 3 valveOpen scale=1\n",
                            "t.aio"), True, diags)
    channels = check_channels(table, sv, load_board("uno"), diags)
    assert [(c.pin_number, c.scale, c.offset) for c in channels] == [(14, 2.0, -1.0)]
    assert where(diags) == [(2, 3, "pin `A0` is already used (t.aio:1)"),
                            (3, 15, "`scale=` applies only to analog inputs")]


# ---- model ------------------------------------------------------------------------

def test_the_model_is_assembled_from_the_checked_parts(tank):
    parts, diags, s, before = checked(tank, (tank / "tank.app").read_text())
    assert complete(parts, s, diags, before)
    app = A.application(str(tank / "tank.app"), parts)
    assert isinstance(app, M.Application)
    assert app.tasks == tuple(parts.tasks) and app.telemetry == tuple(parts.streams)
    assert app.time_element.name == "time" and app.flash_budget is None
    assert app == A.load_app(str(tank / "tank.app"), Diagnostics())  # what the loader gives


def test_the_model_names_stay_importable_from_app():
    assert A.Application is M.Application and A.Task is M.Task and A.Channel is M.Channel
    assert A.TASK_MODES == {"disabled": 0, "safed": 1, "enabled": 2}
