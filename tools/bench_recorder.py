"""The flight recorder (docs/recorder.md), measured on the simulated Uno:

- the rocket example's closed-loop flight: what its record holds (bytes per
  record, samples per record and bytes per sample, records per second),
  how many seconds of such a flight the EEPROM left by the parameters
  holds, and the byte rate against the EEPROM's (3.4 ms a byte on silicon);
- what the feature costs the rocket: flash and RAM (static, and the stack's
  measured high-water mark) against the same rocket without `[log]` and
  its recorder task (target: RAM <= 128 B);
- power cuts (fswkit.testing.recorder_cuts): BENCH_RECORDER_CUTS (1,000)
  resets at random moments and cuts after random EEPROM writes with the
  tests/recorder/logged rig: corrupt records accepted (target 0), records
  lost beyond the one being written (target 0), earlier records changed.

Byte counts and simulated seconds, deterministic for a seed."""

from __future__ import annotations

import os
import re
import shutil
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ROCKET = ROOT / "examples" / "rocket"
LOGGED = ROOT / "tests" / "recorder" / "logged"
CUTS = int(os.environ.get("BENCH_RECORDER_CUTS", "1000"))


def build(project: Path, out: Path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import firmware, load

    app = load(str(project), Diagnostics())
    if app is None:
        raise SystemExit(f"bench_recorder: {project} does not check")
    return app, firmware(app, str(out))


def without_log(tmp: Path) -> Path:
    """A copy of the rocket without its `[log]` section and recorder task."""
    dst = tmp / "rocket-nolog"
    shutil.copytree(ROCKET, dst, ignore=shutil.ignore_patterns("build"))
    app = (dst / "rocket.app").read_text()
    app = re.sub(r"\n\[log\][^\[]*", "\n", app)
    app = re.sub(r"\nlog +recorder[^\n]*", "", app)
    (dst / "rocket.app").write_text(app)
    return dst


def fly(project: Path, elf: str):
    from fswkit.plant.cosim import fly as cosim_fly
    from fswkit.plant.run import prepare

    app, layout, sc = prepare(str(project), "rocket")
    return app, cosim_fly(sc, elf, app.board, layout)


def main() -> int:
    from fswkit.autocode.recorder import EEPROM_WRITE_S, plan
    from fswkit.recorder.check import newest_flight
    from fswkit.target.build import elf_size
    from fswkit.testing.recorder_cuts import power_cuts

    print("== flight recorder (tools/bench_recorder.py) ==")
    passed = failed = 0
    with tempfile.TemporaryDirectory(prefix="fsw-bench-rec-") as tmp:
        tmp = Path(tmp)
        app, built = build(ROCKET, tmp / "rocket")
        nolog = without_log(tmp)
        app0, built0 = build(nolog, tmp / "nolog")
        app, run = fly(ROCKET, built.artifact)
        _, run0 = fly(nolog, built0.artifact)
        p, flight, flights, empty = newest_flight(app, run.eeprom)
        s = flight.samples
        n_rec = len(flight.records)
        per = len(s) / n_rec
        span = (s[-1][0] - s[0][0]) / 1000
        rate = float(max(app.log.rates))
        written = (n_rec + 1) * p.record
        print(f"  rocket, closed-loop flight (seed 1): {len(s)} samples at {rate:g} Hz, "
              f"{s[0][0] / 1000:.2f}-{s[-1][0] / 1000:.2f} s ({span:.1f} s)")
        print(f"    records       {n_rec} of samples + 1 start, {p.record} B each ({written} B); "
              f"{per:.1f} samples and {p.record / per:.2f} B a sample")
        print(f"    records/s     {n_rec / span:.3f} ({rate / per:.3f} at {rate:g} Hz); "
              f"{written / span:.1f} B/s of the EEPROM's {1 / EEPROM_WRITE_S:.0f} B/s on silicon")
        fit = (p.slots - 1) * per / rate
        print(f"    store         {p.slots} records from EEPROM byte {p.base} (after the parameters): "
              f"{fit:.0f} s of such flight at {rate:g} Hz (the flight took {span:.0f} s)")
        pre = min((t for t, _, n in run.transitions if n == p.states[app.log.trigger - 1]), default=None)
        ok = pre is not None and (pre * 1000 - s[0][0]) / 1000 >= float(app.log.before) and fit >= span
        print(f"    covers        {(pre * 1000 - s[0][0]) / 1000:.2f} s before launch; "
              f"{'PASS' if ok else 'FAIL'} (>= {float(app.log.before):g} s, the whole flight fits)")
        passed += ok
        failed += not ok
        f1, r1 = elf_size(built.artifact)
        f0, r0 = elf_size(built0.artifact)
        st1, st0 = run.ram["ram_usage"].stack, run0.ram["ram_usage"].stack
        print(f"  cost on the rocket: flash +{f1 - f0:,} B ({f0:,} -> {f1:,}); RAM +{r1 - r0} B static "
              f"({r0:,} -> {r1:,}: {p.ram} B the recorder's, the rest its task's row), stack high-water "
              f"{st0} -> {st1} B ({st1 - st0:+d})")
        ok = r1 - r0 <= 128
        print(f"    RAM           {'PASS' if ok else 'FAIL'} ({r1 - r0} B static <= 128 B)")
        passed += ok
        failed += not ok

        lapp, lbuilt = build(LOGGED, tmp / "logged")
        rep = power_cuts(lbuilt.artifact, plan(lapp), CUTS, seed=1)
        print(f"  power cuts, tests/recorder/logged (50 Hz, {plan(lapp).record} B records): {rep.cuts} cuts "
              f"({rep.resets} resets at random moments, {rep.write_cuts} after a random EEPROM write), "
              f"{rep.flights} flights, {rep.erases} erases")
        print(f"    checked       {rep.records_checked} records, {rep.samples_checked} samples; "
              f"{rep.lost_in_progress} cuts lost the record being built, and nothing else")
        ok = not rep.problems and rep.cuts == CUTS
        print(f"    result        {'PASS' if ok else 'FAIL'}: {len(rep.problems)} problems "
              "(corrupt records accepted, records lost or changed)")
        for why in rep.problems[:10]:
            print(f"      {why}")
        passed += ok
        failed += not ok
    print(f"recorder: {passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
