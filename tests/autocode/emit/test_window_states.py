"""Which states sample a window (autocode/emit/machine.py window_needs,
docs/codegen.md): those from which a state that reads it can still be
reached. Worked out per strongly connected component of the transition
graph, in linear time (`still_read`): the same sets as a reachability
search from every state, on random graphs, and a 2,000-state ring (every
state reaching every other) in well under a second, where that search
took 2.7 s of the 2,000-state machine's 3.1 s of emission."""

from __future__ import annotations

import random
import time

from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.machine import still_read, window_needs
from fswkit.autocode.project import load_machine


def _searched(succ: dict[int, list[int]], reads: dict[int, int]) -> dict[int, int]:
    """The same by a search from every node."""
    out = {}
    for s in succ:
        seen, todo, mask = {s}, [s], 0
        while todo:
            v = todo.pop()
            mask |= reads[v]
            for t in succ[v]:
                if t not in seen:
                    seen.add(t)
                    todo.append(t)
        out[s] = mask
    return out


def test_the_same_as_a_search_from_every_state_on_random_graphs():
    rng = random.Random(7)
    for case in range(400):
        n = rng.randint(1, 40)
        density = rng.choice((0.02, 0.05, 0.1, 0.3))
        succ = {i: sorted({j for j in range(n) if rng.random() < density}) for i in range(n)}
        reads = {i: (1 << rng.randrange(6)) if rng.random() < 0.3 else 0 for i in range(n)}
        assert still_read(succ, reads) == _searched(succ, reads), (case, succ, reads)


def test_a_long_chain_needs_no_recursion():
    n = 50_000  # far past Python's recursion limit
    succ = {i: [i + 1] for i in range(n - 1)}
    succ[n - 1] = []
    reads = {i: 0 for i in range(n)}
    reads[n - 1] = 1
    assert set(still_read(succ, reads).values()) == {1}


def window_states(m) -> dict[int, frozenset[int]] | None:
    """window_needs by window: the states whose step samples it."""
    needs = window_needs(m)
    if needs is None:
        return None
    need, bit = needs
    return {w: frozenset(s for s, mask in need.items() if mask & b) for w, b in bit.items()}


def _ring(tmp_path, states: int):
    (tmp_path / "ring.sv").write_text("[Sensors]\nU64 time\nU32 state\nF64 p\n[Effectors]\nbool v\n")
    lines = ["[state_vector]", "U64 time @alias G", "U32 state @alias S", "F64 p @read_only", "bool v"]
    for i in range(states):
        lines += [f"[S{i}]", ".step"]
        if i % 10 == 0:
            lines.append(f"    v = roll_avg(p, {2 + i % 3}) > 1")
        lines.append(f"    T > 5: -> S{(i + 1) % states}")
    lines += ["[Stop]", ".step", "    v = roll_max(p, 4) > 2"]
    path = tmp_path / "ring.sm"
    path.write_text("\n".join(lines) + "\n")
    d = Diagnostics()
    m = load_machine(str(path), d)
    assert m is not None, d.render()
    return m


def test_a_2000_state_ring_in_well_under_a_second(tmp_path):
    m = _ring(tmp_path, 2000)
    t = time.process_time()
    got = window_states(m)
    took = time.process_time() - t
    ring = frozenset(st.index for st in m.states if st.name != "Stop")
    stop = next(st.index for st in m.states if st.name == "Stop")
    assert len(ring) == 2000 and got is not None and len(got) == 201
    for w in m.windows:
        # a ring state's window: sampled all around the ring (each state reaches every other), not in
        # Stop, which no ring state reaches; Stop's own window only in Stop
        assert got[w.index] == (frozenset({stop}) if w.func == "max" else ring), w
    assert took < 0.5, f"{took:.2f} s"
