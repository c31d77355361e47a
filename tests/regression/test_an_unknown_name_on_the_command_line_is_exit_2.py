"""A name the project (or the log read) does not have, typed on the command
line as an element, a task or a parameter, ended with a different status by
each command: `fsw monitor --spark X`, `fsw replay --spark X`, `fsw plot -e
X`, `fsw cmd set X ...` and `fsw cmd mode X ...` exited 1 (as a failure),
`fsw param get X` and `fsw test --param X=...` 2, each with its own kind of
message (`unknown element(s) x: the log's elements are`, `unknown parameter
`x` (the project's parameters: ...)`, `` `x` is not a parameter of machine
`m` (its parameters: ...)``). So did a value of the wrong type or a mode
that is none given to `fsw cmd`, checked before the port is opened.

Now each of them is a wrong command line, status 2 (docs/cli.md, "Exit
statuses shared by all commands"), said the same way everywhere: `unknown
KIND `X` (did you mean `Y`?): the project's KINDs are ...` after the option
that named it, before any port is opened or file written. A name the target
refuses over the link stays the target's answer (status 1)."""

from __future__ import annotations

from conftest import EXAMPLES, run_fsw
from support.linkfw import TANK
from support.linkstream import write_log

ROCKET = EXAMPLES / "rocket"
NO_PORT = "/dev/no-such-port"


def clean(r):
    assert "Traceback" not in r.err and "internal error" not in r.err, r.err
    assert "cannot open" not in r.err, r.err  # refused before the port is opened
    return r


def test_an_unknown_element_of_the_project():
    r = clean(run_fsw("monitor", str(ROCKET), "--port", NO_PORT, "--spark", "altitud"))
    assert r.code == 2, r.err
    assert "fsw monitor: --spark: unknown element `altitud` (did you mean `altitude`?): " \
           "the project's elements are time, state, altitude" in r.err
    r = clean(run_fsw("monitor", str(ROCKET), "--spark", "altitud"))  # before a port is looked for
    assert r.code == 2 and "--spark: unknown element `altitud`" in r.err and "serial port" not in r.err, r.err
    r = clean(run_fsw("cmd", "set", "valveOpn", "1", "--port", NO_PORT, "-p", str(TANK)))
    assert r.code == 2, r.err
    assert "fsw cmd: set: unknown element `valveOpn` (did you mean `valveOpen`?): the project's elements are " in r.err


def test_an_unknown_task_of_the_project():
    r = clean(run_fsw("cmd", "mode", "contrl", "safed", "--port", NO_PORT, "-p", str(TANK)))
    assert r.code == 2, r.err
    assert "fsw cmd: mode: unknown task `contrl` (did you mean `control`?): the project's tasks are " in r.err


def test_a_wrong_value_or_mode_for_cmd_is_a_wrong_command_line_too():
    for argv, msg in ((("set", "valveOpen", "maybe"), "`valveOpen` is bool"),
                      (("mode", "control", "asleep"), "unknown mode `asleep`"),
                      (("set", "valveOpen"), "usage: fsw cmd set ELEMENT VALUE"),
                      (("ping", "now"), "takes no arguments")):
        r = clean(run_fsw("cmd", *argv, "--port", NO_PORT, "-p", str(TANK)))
        assert r.code == 2 and msg in r.err, (argv, r.code, r.err)


def test_an_unknown_element_of_the_log(tmp_path):
    log = write_log(tmp_path / "tank.fswlog", 5)
    r = clean(run_fsw("replay", str(log), "--headless", "--spark", "tankPresure"))
    assert r.code == 2 and r.out == "", r.err
    assert "fsw replay: --spark: unknown element `tankPresure` (did you mean `tankPressure`?): " \
           "the log's elements are " in r.err
    out = tmp_path / "p.png"
    r = clean(run_fsw("plot", str(log), "-e", "tankPresure", "-o", str(out)))
    assert r.code == 2 and not out.exists(), r.err
    assert "fsw plot: -e: unknown element `tankPresure` (did you mean `tankPressure`?): " \
           "the log's elements are " in r.err
    r = clean(run_fsw("plot", str(log), "-e", "a", "tankPressure", "b", "-o", str(out)))
    assert r.code == 2 and "-e: unknown elements `a`, `b`: the log's elements are " in r.err, r.err


def test_an_unknown_parameter():
    r = clean(run_fsw("param", str(ROCKET), "get", "MAIN_ALTT", "--port", NO_PORT))
    assert r.code == 2, r.err
    assert "fsw param: get: unknown parameter `MAIN_ALTT` (did you mean `MAIN_ALT`?): " \
           "the project's parameters are LAUNCH_G, " in r.err
    r = clean(run_fsw("param", str(ROCKET), "set", "MAIN_ALTT=200", "--port", NO_PORT))
    assert r.code == 2 and "fsw param: set: unknown parameter `MAIN_ALTT` (did you mean `MAIN_ALT`?)" in r.err
    r = clean(run_fsw("test", str(ROCKET / "mission_pad.ss"), "--param", "MAIN_ALTT=3"))
    assert r.code == 2, r.err
    assert "fsw test: --param MAIN_ALTT=3: unknown parameter `MAIN_ALTT` (did you mean `MAIN_ALT`?): " \
           "machine `mission`'s parameters are LAUNCH_G, " in r.err
