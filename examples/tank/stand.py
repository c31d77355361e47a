"""A test stand for the tank's vent controller (tank.sm), through libfswsm
(docs/bytecode.md, "The host library, libfswsm"): the machine runs in the
runtime's own VM, here on the host, while this script plays the tank.

Each step the stand sets the tank pressure, steps the controller at
G = 10 ms a step, and prints the valve command it gave back. The pressure
rises past the vent threshold (775), falls back, rises again, and finally
past the abort threshold (825): the controller opens and closes the valve
with it, then aborts (its .exit leaves the valve open).

    .venv/bin/python examples/tank/stand.py [--real f32]"""

from __future__ import annotations

import argparse
import os
import sys

from fswkit.sm import FswsmError, Machine

HERE = os.path.dirname(os.path.abspath(__file__))


def profile() -> list[float]:
    """The stand's pressure, a value a step (kPa)."""
    up = [760.0 + 4 * k for k in range(8)]      # 760 .. 788: crosses 775 going up
    down = [786.0 - 5 * k for k in range(6)]    # 786 .. 761: crosses it going down
    again = [770.0 + 8 * k for k in range(9)]   # 770 .. 834: past 825, the abort
    return up + down + again + [700.0, 650.0]   # after the abort: nothing moves it


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--real", choices=("f64", "f32"), default="f64", help="the library's evaluation type")
    args = ap.parse_args(argv)
    try:
        m = Machine.from_sm(os.path.join(HERE, "tank.sm"), real=args.real)
    except FswsmError as e:
        sys.stderr.write(f"stand: {e}\n")
        return 1
    print(f"tank.sm through libfswsm ({args.real}): {len(m.states)} states, {m.sv_size}-byte state vector")
    print(f"{'step':>4} {'G':>5} {'pressure':>9}  {'state':<16} valve")
    valve = None
    for k, p in enumerate(profile()):
        m["tankPressure"] = p
        m.step(g=10 * k)
        now = m["valveOpen"]
        change = "" if valve is None or now == valve else "  <- opened" if now else "  <- closed"
        valve = now
        print(f"{k:>4} {m['G']:>5} {p:>9.1f}  {m.state:<16} {'OPEN' if now else 'shut'}{change}")
    print(f"final state: {m.state}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
