"""`fsw skeleton`: the generated scripts parse, pass `fsw test`, and really
take every transition they claim (checked twice: from `--trace`, and by a
recording interpreter that knows which `-> State` fired)."""

from __future__ import annotations

import csv
import os
import re
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT
from fswkit.run import script as script_mod
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.numeric import F64MODE
from fswkit.autocode.project import load_machine, load_script
from fswkit.autocode.emit.graph import transitions
from fswkit.run.interp import MachineRun
from fswkit.new.script import instrument, plan, skeleton, skeleton_runs

TANK = EXAMPLES / "tank"
MACHINES = ROOT / "tests" / "autocode" / "emit" / "machines"


def machine(path: Path):
    diags = Diagnostics()
    m = load_machine(str(path), diags)
    assert m is not None, diags.render()
    return m


def uncomment(block: str) -> str:
    """A commented-out run of the skeleton as the script it stands for."""
    lines = []
    for line in block.splitlines():
        assert line.startswith("#"), line
        lines.append(line[2:] if line.startswith("# ") else line[1:])
    return "\n".join(lines) + "\n"


def split_runs(text: str) -> list[str]:
    """The skeleton file: the first run as is (without the digest that
    `fsw` adds to its head line), each further run uncommented."""
    text = re.sub(r" \(digest [0-9a-f]{12}\)$", "", text, count=1, flags=re.M)
    parts = re.split(r"\n# ==== run \d+ of \d+ =+\n", text)
    runs = [parts[0]]
    for p in parts[1:]:
        body = p.split("#\n", 1)[1]  # past the three lines of explanation
        runs.append(uncomment(body))
    return runs


class Recording(MachineRun):
    """The interpreter on the instrumented machine: it records which
    transition (index in graph.transitions) fired at each step."""

    fired: list[int] = []

    def __init__(self, m, real, init_state=0, cover=False):
        im, self.hit = instrument(m)
        super().__init__(im, real, init_state, cover)
        Recording.fired = []

    def step(self):
        self.v[self.hit] = 0
        rc = super().step()
        if self.v[self.hit]:
            Recording.fired.append(self.v[self.hit] - 1)
        return rc


def observe(text: str, sm: Path, tmp_path: Path, fsw, monkeypatch, name: str = "run.ss"):
    """Runs a generated script twice: with `fsw test --trace` (giving the
    states visited and (from, to) state-ID pairs of every transition, read
    from S and T) and with the recording interpreter (giving transition
    indices). Both runs must pass."""
    ss = tmp_path / name
    ss.write_text(text)
    trace = tmp_path / (name + ".csv")
    r = fsw("test", str(ss), "--sm", str(sm), "--trace", str(trace))
    assert r.code == 0, r.out + r.err
    assert "assertion fail" not in r.out
    with open(trace, newline="") as f:
        rows = list(csv.DictReader(f))
    states = {int(row["S"]) for row in rows}
    pairs = set()
    for a, b in zip(rows, rows[1:]):
        if int(b["T"]) == 0:  # b is the first step of a state: a transition just happened
            pairs.add((int(a["S"]), int(b["S"])))
    diags = Diagnostics()
    s = load_script(str(ss), diags, str(sm))
    assert s is not None, diags.render()
    monkeypatch.setattr(script_mod, "MachineRun", Recording)
    result = script_mod.run(s, F64MODE)
    monkeypatch.undo()
    assert result.passed
    return states, pairs, list(Recording.fired)


def check_machine(sm: Path, tmp_path, fsw, monkeypatch, delta_t: int = 10):
    """Every run of the skeleton passes and takes what it claims; returns
    the plan and the transitions and states taken by all runs together."""
    m = machine(sm)
    p = plan(m, delta_t)
    r = fsw("skeleton", str(sm), "--delta-t", str(delta_t))
    assert r.code == 0, r.err
    texts = split_runs(r.out)
    assert texts == skeleton_runs(m, delta_t)
    assert len(texts) == max(1, len(p.runs))
    taken, visited = set(), {1}
    for k, text in enumerate(texts):
        states, pairs, fired = observe(text, sm, tmp_path, fsw, monkeypatch, f"run{k + 1}.ss")
        claimed = p.runs[k].taken if p.runs else []
        # the recording interpreter saw exactly the claimed transitions, in order
        assert [i for n, i in enumerate(fired) if i not in fired[:n]] == claimed
        for i in claimed:
            t = p.transitions[i]
            pair = (m.states[t.source].id, m.states[t.target].id)
            assert pair in pairs, (pair, pairs)
            assert f"#   {describe_of(m, i)}" in text
        taken |= set(claimed)
        visited |= states
    return m, p, taken, visited


def describe_of(m, i):
    from fswkit.autocode.emit.graph import describe
    return describe(transitions(m)[i], m)


# ---- the tank -----------------------------------------------------------------

def test_tank_skeleton_reaches_every_state_and_transition(fsw, tmp_path, monkeypatch):
    m, p, taken, visited = check_machine(TANK / "tank.sm", tmp_path, fsw, monkeypatch)
    assert taken == {0, 1}
    assert visited == {1, 2, 3}
    assert p.not_reached == {}
    # Abort and Idle are both dead ends: one script each
    assert len(p.runs) == 2


def test_tank_skeleton_text(fsw):
    r = fsw("skeleton", str(TANK / "tank.sm"))
    assert r.code == 0
    text = r.out
    assert re.match(r"# State-script skeleton for tank\.sm, made by `fsw skeleton` \(run 1 of 2\)\. "
                    r"\(digest [0-9a-f]{12}\)\n", text), text[:200]
    assert "\n[options]\ndelta_t 10\ninit_state TankVentControl\n" in text
    assert "\n[TankVentControl]\ntrue: @assert S == 1  # TODO: what must hold in TankVentControl\n" in text
    assert "\n[Abort]\ntrue: @assert S == 2  # TODO: what must hold in Abort\n" in text
    # the second run, commented out, waits for the counter and T
    assert "# G == 0: tankPressure = 776\n" in text
    assert "# G == 10010: @assert S == 3 and T == 0  # entered Idle\n" in text
    assert "# [Idle]\n# true: @assert S == 3  # TODO: what must hold in Idle\n" in text
    assert text.rstrip().endswith("# G == 10010: @stop")


def test_tank_skeleton_file_passes_as_is(fsw, tmp_path):
    """The whole file, extra runs commented out, is a passing script."""
    out = tmp_path / "tank_skel.ss"
    r = fsw("skeleton", str(TANK / "tank.sm"), "-o", str(out))
    assert r.code == 0 and r.out == ""
    r = fsw("test", str(out), "--sm", str(TANK / "tank.sm"))
    assert r.code == 0, r.out
    assert r.out.startswith("state script ran for 2 steps\n")


def test_skeleton_is_byte_reproducible(fsw, tmp_path):
    a = fsw("skeleton", str(MACHINES / "rocket.sm"))
    b = fsw("skeleton", str(MACHINES / "rocket.sm"))
    assert a.code == b.code == 0
    assert a.out == b.out
    out = tmp_path / "r.ss"
    assert fsw("skeleton", str(MACHINES / "rocket.sm"), "-o", str(out)).code == 0
    assert out.read_text() == a.out


# ---- machines written for the search ------------------------------------------------

def test_rocket_one_run_takes_everything(fsw, tmp_path, monkeypatch):
    """Time guards (T >= 200, T > 500), booleans, a chained comparison, else
    branches, a self-transition, a rolling window, and states reachable
    only through others: one script takes all seven transitions."""
    m, p, taken, visited = check_machine(MACHINES / "rocket.sm", tmp_path, fsw, monkeypatch)
    assert len(p.runs) == 1
    assert taken == set(range(7))
    assert visited == {1, 2, 3, 4, 5}
    assert p.not_reached == {}
    text = skeleton(m)
    assert "#   Ready -> Ready when T > 500\n" in text  # the self-transition
    assert "#   Ready -> Ascent when armed and 100 < altitude <= 3000\n" in text
    assert "#   Ascent -> Ready when not (altitude > 3000) and altitude < floor\n" in text
    assert "#   Apogee -> Landed when roll_avg(altitude, 4) < 1000\n" in text


def test_gates_entry_toggles_pairs_and_dead_transitions(fsw, tmp_path, monkeypatch):
    m, p, taken, visited = check_machine(MACHINES / "gates.sm", tmp_path, fsw, monkeypatch)
    names = {st.name: st.id for st in m.states}
    assert visited == {names[n] for n in ("Start", "Early", "Open", "Full", "Both")}
    assert len(taken) == 7
    # never fire, whatever the inputs: said so, with the reason
    text = skeleton(m)
    assert "# not reached: Full -> Start when false\n#   (its guard is always false)\n" in text
    assert ("# not reached: Full -> Start (unconditional)\n"
            "#   (it follows a transition that always fires first)\n") in text
    assert ("# not reached: Orphan -> Start when T > 10\n"
            "#   (state `Orphan` is never reached: no transition from the initial state leads to it)\n") in text
    assert len(p.not_reached) == 3
    # door must be off at entry and on one step later
    assert "G == 20: door = false\nG == 30: door = true\n" in text
    # two inputs at once, one through arithmetic, one negative
    assert re.search(r"#     a = 5[56](\.5)?\n#     b = -6\n", text)


def test_delta_t_is_used(fsw, tmp_path, monkeypatch):
    m, p, taken, visited = check_machine(MACHINES / "rocket.sm", tmp_path, fsw, monkeypatch, delta_t=25)
    assert taken == set(range(7))
    text = skeleton(m, delta_t=25)
    assert "\ndelta_t 25\n" in text
    for g in re.findall(r"G == (\d+)", text):
        assert int(g) % 25 == 0


def write_machine(tmp_path: Path, name: str, sv: str, sm: str) -> Path:
    (tmp_path / f"{name}.sv").write_text(sv)
    path = tmp_path / f"{name}.sm"
    path.write_text(sm)
    return path


SV = "[R]\nU64 time\nU32 state\nF64 x\nF64 y\nbool flag\n"
HEAD = ("[state_vector]\nU64 time @alias G\nU32 state @alias S\n"
        "F64 x @read_only\nF64 y @read_only\nbool flag\n")


def test_unsatisfiable_guard_is_reported_not_dropped(fsw, tmp_path, monkeypatch):
    sm = write_machine(tmp_path, "unsat", SV, HEAD + (
        "[A]\n.step\n    x > 5 and x < 3: -> B\n    y > 2: -> C\n[B]\n[C]\n"))
    m, p, taken, visited = check_machine(sm, tmp_path, fsw, monkeypatch)
    assert taken == {1}
    text = skeleton(m)
    assert "# not reached: A -> B when x > 5 and x < 3\n#   (no inputs found that make it fire" in text


def test_budget_bounds_the_search(fsw, tmp_path, monkeypatch):
    m = machine(MACHINES / "rocket.sm")
    p = plan(m, 10, budget=300)
    assert p.exhausted and p.steps_used <= 300
    assert p.not_reached
    for why in p.not_reached.values():
        assert why in ("the search ran out of its step budget first",) or "did not reach state" in why
    text = skeleton(m, budget=300)
    assert "(the search ran out of its step budget first)" in text
    # what was found still passes
    for k, run in enumerate(skeleton_runs(m, budget=300)):
        observe(run, MACHINES / "rocket.sm", tmp_path, fsw, monkeypatch, f"b{k}.ss")


def test_time_beyond_the_wait_cap_is_reported(fsw, tmp_path, monkeypatch):
    sm = write_machine(tmp_path, "late", SV, HEAD + "[A]\n.step\n    T > 1e12: -> B\n[B]\n")
    m = machine(sm)
    p = plan(m, 10, budget=200_000)
    assert 0 in p.not_reached and p.runs == []
    text = skeleton(m, budget=200_000)
    assert "# not reached: A -> B when T > 1e12\n" in text
    observe(text, sm, tmp_path, fsw, monkeypatch)


def test_machine_without_transitions(fsw, tmp_path, monkeypatch):
    sm = write_machine(tmp_path, "still", SV, HEAD + "[Only]\n.step\n    flag = x > 1\n")
    m, p, taken, visited = check_machine(sm, tmp_path, fsw, monkeypatch)
    assert p.runs == [] and visited == {1}
    assert skeleton(m).rstrip().endswith("[all_states]\nG == 0: @stop")


def test_counter_and_else_chain(fsw, tmp_path, monkeypatch):
    """A counter the machine keeps (waiting is what drives it), an else-if
    chain, an entry transition and a state reached only through another."""
    sm = write_machine(tmp_path, "count", SV, HEAD + (
        "[local]\nU16 n = 0\n"
        "[Wait]\n.step\n    if x > 10: n = n + 1\n    else if y < -2: n = 0\n    else: flag = true\n"
        "    n >= 40: -> Count\n"
        "[Count]\n.entry\n    flag and y == 0: -> Wait\n.step\n    T >= 100: -> Deep\n"
        "[Deep]\n.step\n    not flag or x <= 0: -> Count\n"))
    m, p, taken, visited = check_machine(sm, tmp_path, fsw, monkeypatch)
    assert taken == set(range(4))
    assert visited == {1, 2, 3}


def test_assigning_every_kind_of_input(fsw, tmp_path, monkeypatch):
    """Integer, float32 and bool inputs, a read-only local as last resort."""
    sv = "[R]\nU64 time\nU32 state\nI8 small\nF32 f\nbool on\n"
    sm = write_machine(tmp_path, "kinds", sv, (
        "[state_vector]\nU64 time @alias G\nU32 state @alias S\n"
        "I8 small @read_only\nF32 f @read_only\nbool on @read_only\n"
        "[local]\nbool debug = false @read_only\n"
        "[A]\n.step\n    small < -100: -> B\n"
        "[B]\n.step\n    f > 0.25 and on: -> C\n"
        "[C]\n.step\n    debug: -> A\n"))
    m, p, taken, visited = check_machine(sm, tmp_path, fsw, monkeypatch)
    assert taken == {0, 1, 2}
    text = skeleton(m)
    assert "small = -101" in text
    assert "debug = true" in text


# ---- the command line ------------------------------------------------------------------

def test_broken_machine_gives_located_error_and_exit_2(fsw):
    r = fsw("skeleton", "tank_typo.sm", cwd=TANK)
    assert r.code == 2
    assert r.out == ""
    assert r.err.startswith("state machine config error @ tank_typo.sm:18:9:\n"
                            "  |         valve0pe = true\n"
                            "  |         ^ unknown element `valve0pe`\n")


def test_missing_machine(fsw, tmp_path):
    r = fsw("skeleton", str(tmp_path / "nope.sm"))
    assert r.code == 2
    assert "nope.sm" in r.err


def test_unwritable_output(fsw, tmp_path):
    target = tmp_path / "no_such_dir" / "x.ss"
    r = fsw("skeleton", str(TANK / "tank.sm"), "-o", str(target))
    assert r.code == 1
    assert r.err.startswith(f"fsw skeleton: cannot write {target}: ")
    assert "Traceback" not in r.err
    assert not target.exists()


@pytest.mark.skipif(os.geteuid() == 0, reason="root can write anywhere")
def test_read_only_output(fsw, tmp_path):
    d = tmp_path / "ro"
    d.mkdir()
    d.chmod(0o500)
    r = fsw("skeleton", str(TANK / "tank.sm"), "-o", str(d / "x.ss"))
    assert r.code == 1
    assert "cannot write" in r.err
