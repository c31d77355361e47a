"""Parameters (docs/parameters.md), measured on the simulated Uno with
tests/param/many (64 F32 parameters, its link at 9,600 baud):

- a lossy radio: every value listed, then a file changing all 64 loaded
  and verified, with 20 % of the frames dropped in each direction, over
  BENCH_PARAM_SEEDS seeds (20): simulated seconds (target < 3 s), frames
  sent and sent again;
- power cuts: a load of 64 values and a SET + SAVE, each cut after every
  one of its EEPROM byte writes: after the reboot the old set or the new,
  never a mix, always from a bank whose CRC holds;
- what the feature costs: flash and RAM of the firmware with its 64
  parameters against the same machine with the 64 as constants (folded
  into the code); RAM beyond the values themselves (target <= 96 B).

Simulated seconds and byte counts, deterministic for a seed."""

from __future__ import annotations

import os
import re
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MANY = ROOT / "tests" / "param" / "many"
SEEDS = int(os.environ.get("BENCH_PARAM_SEEDS", "20"))


def build(project: Path, out: Path):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import firmware, load

    app = load(str(project), Diagnostics())
    if app is None:
        raise SystemExit(f"bench_params: {project} does not check")
    return app, firmware(app, str(out))


def main() -> int:
    from fswkit.autocode.params import app_parameters, block_size
    from fswkit.param.sim import lossy_list_and_load, power_cuts
    from fswkit.target.build import elf_size

    print("== parameters (tools/bench_params.py) ==")
    failed = passed = 0
    with tempfile.TemporaryDirectory(prefix="fsw-bench-params-") as tmp:
        tmp = Path(tmp)
        app, built = build(MANY, tmp / "many")
        elf = built.artifact
        runs = [lossy_list_and_load(elf, "uno", app, 0.2, seed) for seed in range(1, SEEDS + 1)]
        total = [r.list_s + r.load_s for r in runs]
        ok = all(r.verified and r.values_ok for r in runs)
        print(f"  lossy link, 64 parameters at 9,600 baud, 20 % of frames dropped each way, {SEEDS} seeds:")
        print(f"    list      median {statistics.median(r.list_s for r in runs):.2f} s   max "
              f"{max(r.list_s for r in runs):.2f} s")
        print(f"    load      median {statistics.median(r.load_s for r in runs):.2f} s   max "
              f"{max(r.load_s for r in runs):.2f} s  (staged, committed, verified by CRC, bank written)")
        print(f"    together  median {statistics.median(total):.2f} s   max {max(total):.2f} s   (target < 3 s)")
        print(f"    commands {sum(r.sent for r in runs) / SEEDS:.0f} sent a run, {sum(r.resent for r in runs) / SEEDS:.0f}"
              f" of them again; frames dropped up {sum(r.up_dropped for r in runs)}/{sum(r.up_frames for r in runs)},"
              f" down {sum(r.down_dropped for r in runs)}/{sum(r.down_frames for r in runs)}; all verified: {ok}")
        writes = 1 + block_size(app_parameters(app)) + 9  # clear the magic, the values, the header, the magic
        print("    (simavr writes an EEPROM byte at once; an ATmega328P takes 3.4 ms, so on silicon the load's "
              f"{writes} bank writes add {writes * 3.4 / 1000:.2f} s of EEPROM time, in the background)")
        if ok and max(total) < 3.0:
            passed += 1
        else:
            failed += 1
        for op in ("load", "save"):
            c = power_cuts(elf, "uno", app, stride=1, op=op)
            print(f"  power cuts, {op}: {c.cases} cut points (every one of its {c.writes} EEPROM writes): "
                  f"{c.old} rebooted with the old set, {c.new} with the new, {len(c.bad)} wrong")
            if c.bad or c.new != 1 or c.old + c.new != c.cases:
                failed += 1
                for k, why in c.bad[:5]:
                    print(f"    cut after write {k}: {why}")
            else:
                passed += 1
        # the cost: the same machine with its 64 parameters as constants
        flat = tmp / "flat"
        flat.mkdir()
        for f in MANY.iterdir():
            if f.is_file():
                text = f.read_text()
                if f.suffix == ".sm":
                    text = text.replace("[parameters]", "[local]")
                    text = re.sub(r" @min \S+ @max \S+ @when \S+", " @read_only", text)
                (flat / f.name).write_text(text)
        _, built_flat = build(flat, tmp / "flat-build")
        f1, r1 = elf_size(elf)
        f0, r0 = elf_size(built_flat.artifact)
        values = block_size(app_parameters(app))
        print("  cost of 64 F32 parameters on the Uno (against the same values folded as constants):")
        print(f"    flash +{f1 - f0:,} B ({f0:,} -> {f1:,}: the store, the tables, the link's commands, reads from RAM)")
        print(f"    RAM   +{r1 - r0:,} B ({r0:,} -> {r1:,}, data + bss): {values} B of values and "
              f"{r1 - r0 - values} B beyond them (target <= 96 B)")
        if r1 - r0 - values <= 96:
            passed += 1
        else:
            failed += 1
    print(f"parameters: {passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
