"""The pyro proof looked up the channel's element, its arming inputs and
its continuity input in the machine by name *or alias*
(`Machine.var`). A machine may give any element a second name with
`@alias`, so examples/rocket's mission machine declaring `bool led @alias
armSwitch` (and not the key's element at all), setting `led = true` on
the pad and arming on `armSwitch: -> Armed` passed `fsw check`: the proof
took the guard for the arming key, while it read the LED the machine had
just lit itself. The machine was proven armed by the switch and never
read it. (The run-time gate still read the key's pin.)

Now the proof reads elements by their element names only: that machine's
arming transition is refused, at the transition, saying which element its
`armSwitch` is; the channel's element and continuity input are looked up
the same way."""

from __future__ import annotations

import shutil

from conftest import EXAMPLES


def rocket(tmp_path, *edits):
    shutil.copytree(EXAMPLES / "rocket", tmp_path / "rocket")
    sm = tmp_path / "rocket" / "mission.sm"
    text = sm.read_text()
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new, 1)
    sm.write_text(text)
    return tmp_path / "rocket" / "rocket.app"


def test_an_alias_of_another_element_does_not_arm(fsw, tmp_path):
    app = rocket(tmp_path,
                 ("bool armSwitch    @read_only\n", ""),
                 ("bool led\n", "bool led @alias armSwitch\n"),
                 ("[Safe]\n.entry\n    onPad = true\n    drogue = false\n    main = false\n    led = false\n",
                  "[Safe]\n.entry\n    onPad = true\n    drogue = false\n    main = false\n    led = true\n"))
    r = fsw("check", str(app))
    assert r.code == 1, r.err
    assert "mission.sm:73:74:" in r.err  # Safe's `armSwitch and ...: -> Armed`
    assert ("transition from `Safe`, reached unarmed, into armed state `Armed` does not require `armSwitch`"
            in r.err)
    assert "`armSwitch` is an alias of element `led`" in r.err
    assert "Traceback" not in r.err


def test_the_channel_is_its_element_not_an_alias(fsw, tmp_path):
    # the mission machine calls the buzzer `drogue` and never declares the
    # drogue's element: its `buzzer = true` in Landed and Abort sounds the
    # buzzer, it fires nothing (before: refused as firings of the drogue,
    # while the channel's own element went unexamined)
    app = rocket(tmp_path,
                 ("bool drogue\n", ""),
                 ("bool buzzer\n", "bool buzzer @alias drogue\n"),
                 ("    drogue = false\n    main = false\n    led = false\n    buzzer = false\n",
                  "    main = false\n    led = false\n    buzzer = false\n"),
                 ("[Apogee]\n.entry\n    drogue = true\n", "[Apogee]\n"),
                 (".exit\n    drogue = false\n", ""),
                 ("[Abort]\n.entry\n    drogue = false\n", "[Abort]\n.entry\n"))
    r = fsw("check", str(app))
    assert r.code == 0, r.err
    assert "can fire here" not in r.err
    assert "pyro channel `drogue` never fires: no state of machine `mission`" in r.err
