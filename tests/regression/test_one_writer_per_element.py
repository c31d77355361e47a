"""A second machine could write the first machine's `S` element: telemetry
then reported a state the machine was not in. Every element has at most one
writer among the machines (their assignments and their own `S`), the input
channels and the executor (`G`, each task's mode, overruns and worst_us,
the reset cause); a second writer is refused where it is written, naming
the first. The uplink is not a writer of this kind (ground overrides of a
machine's element are allowed); docs/application.md says which it may
write."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES

SV = """\
[Flight]
U64 time
U32 stateA
U32 stateB
F32 alt
F32 vel
[Control]
U8 controlMode
U16 ctlOver
U8 cause
"""

A_SM = """\
[state_vector]
U64 time @alias G
U32 stateA @alias S
F32 alt @read_only
F32 vel

[Run]
.step
    vel = alt * 2
"""

B_SM = """\
[state_vector]
U64 time @alias G
{s_decl}
{decl}

[Run]
.step
    {stmt}
"""

APP = """\
[application]
board uno
{reset}
[configs]
state_vector rig.sv
machine a.sm
machine b.sm
io rig.aio

[tasks]
sense    inputs
control  machine a mode=controlMode overruns=ctlOver
control2 machine b {b_opts}
"""

AIO = "i A0 alt\n"


def project(tmp_path, decl="", stmt="", s_decl="U32 stateB @alias S", b_opts="", reset=""):
    b_sm = B_SM.format(s_decl=s_decl, decl=decl, stmt=stmt or "stateB == 0: -> Run")
    app = APP.format(b_opts=b_opts, reset=reset)
    for name, text in (("rig.sv", SV), ("a.sm", A_SM), ("b.sm", b_sm), ("rig.app", app), ("rig.aio", AIO)):
        (tmp_path / name).write_text(text)
    return tmp_path


def test_one_writer_each_is_accepted(fsw, tmp_path):
    # b reads a's state, velocity and the input; nobody writes twice
    r = fsw("check", str(project(tmp_path, "U32 stateA @read_only\nF32 vel @read_only", "vel > 1 and stateA == 1: -> Run")
                         / "rig.app"))
    assert r.code == 0, r.err


@pytest.mark.parametrize("kw, where, message", [
    # another machine's S
    (dict(decl="U32 stateA", stmt="stateA = 3"), "b.sm:8:5",
     "element `stateA` is already written by machine `a` (its `S`): machine `b` (b.sm:8) cannot write it too"),
    # two machines alias one element as S
    (dict(s_decl="U32 stateA @alias S", stmt="stateA == 0: -> Run"), "b.sm:3:1",
     "element `stateA` is already written by machine `a` (its `S`): machine `b` (its `S`) cannot write it too"),
    # two machines assign one element
    (dict(decl="F32 vel", stmt="vel = 1"), "b.sm:8:5",
     "element `vel` is already written by machine `a` (a.sm:9): machine `b` (b.sm:8) cannot write it too"),
    # a machine assigns what an input channel reads into
    (dict(decl="F32 alt", stmt="alt = 1"), "b.sm:8:5",
     "element `alt` is already written by input channel {p}/rig.aio:1: machine `b` (b.sm:8) cannot write it too"),
    # a machine assigns a task's mode element (the executor's)
    (dict(decl="U8 controlMode", stmt="controlMode = 0"), "b.sm:8:5",
     "element `controlMode` is already written by the executor (the mode of task `control`): "
     "machine `b` (b.sm:8) cannot write it too"),
    # two tasks mirror their overruns into one element
    (dict(b_opts="overruns=ctlOver"), "rig.app:13:29",
     "element `ctlOver` is already written by the executor (the overruns of task `control`): "
     "the executor (the overruns of task `control2`) cannot write it too"),
    # two tasks keep their mode in one element
    (dict(b_opts="mode=controlMode"), "rig.app:13:25",
     "element `controlMode` is already written by the executor (the mode of task `control`): "
     "the executor (the mode of task `control2`) cannot write it too"),
    # the reset cause into a task's mode element
    (dict(reset="reset_cause controlMode\n"), "rig.app:3:13",
     "element `controlMode` is already written by the executor (the mode of task `control`): "
     "the executor (the reset cause) cannot write it too"),
])
def test_a_second_writer_is_refused(fsw, tmp_path, kw, where, message):
    p = project(tmp_path, **kw)
    r = fsw("check", str(p / "rig.app"))
    assert r.code != 0
    assert f"error @ {p}/{where}:" in r.err, r.err
    assert message.format(p=p) in r.err, r.err
    assert "Traceback" not in r.err


@pytest.mark.parametrize("app", ["tank/tank.app", "rocket/rocket.app"])
def test_examples_have_one_writer_per_element(fsw, app):
    r = fsw("check", "--strict", str(EXAMPLES / app))
    assert r.code == 0, r.err
