#!/usr/bin/env python3
"""Machines replaced at run time (docs/reload.md), measured (not a test):

- what `[reload]` costs on an Uno: examples/stand against the same
  application without its [reload] section (examples/tank), flash and
  static RAM, from `fsw build`;
- the upload of the rocket's mission machine (examples/rocket/mission.sm)
  to a running board, committed, verified and activated: at 115200 baud on
  a clean link, and at 9,600 baud with a fifth of the frames lost each way
  (a radio), with what the board's checks of the image cost: the longest
  slice (the CRC or the verifier reading the EEPROM, a slice at each of the
  machine task's steps), the switch's copy of the image into RAM, and the
  executor's late cycles, overruns and longest task steps from its health
  frames. The rocket with [reload] does not fit an Uno (its EEPROM holds
  the parameters and the record, the VM's flash does not fit beside the
  recorder), so the two variants are built for the ATmega2560 from
  examples/rocket's configs, the 9,600-baud one with its telemetry slowed
  to what that line carries;
- a power cut at every EEPROM byte write of an upload and its activation
  on examples/stand: the board reboots into the old machine or the new one.

    .venv/bin/python tools/bench_reload.py   (make bench)

Every time is simulated time on the simulated board."""

from __future__ import annotations

import os
import re
import shutil
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(ROOT, "build", "bench", "reload")
CONFIGS = (".sv", ".sm", ".ss", ".aio", ".dio", ".app", ".toml")


def built(folder: str):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import firmware, load

    diags = Diagnostics()
    app = load(folder, diags)
    if app is None:
        sys.exit(f"bench_reload: {folder}:\n{diags.render()}")
    b = firmware(app, os.path.join(OUT, os.path.basename(folder)))
    if not b.fits:
        sys.exit(f"bench_reload: {folder} does not fit:\n{b.report}")
    return app, b


def rocket_variant(name: str, baud: int) -> str:
    """examples/rocket's configs with [reload] of its mission machine, for
    the ATmega2560, at `baud` (telemetry slowed to fit 9,600)."""
    folder = os.path.join(OUT, name)
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    src = os.path.join(ROOT, "examples", "rocket")
    for n in sorted(os.listdir(src)):
        p = os.path.join(src, n)
        if os.path.isfile(p) and n.endswith(CONFIGS):
            shutil.copy(p, folder)
        elif os.path.isdir(p) and n != "build":
            shutil.copytree(p, os.path.join(folder, n))
    app = os.path.join(folder, "rocket.app")
    with open(app) as f:
        text = f.read()
    text = re.sub(r"(?m)^board\s+\w+", "board mega2560", text, count=1)
    text = re.sub(r"(?m)^\[budget\][^\[]*", "", text)  # the Uno's budget
    if baud != 115200:
        text = re.sub(r"(?m)^(name\s+\w+)", rf"\1\nbaud  {baud}", text, count=1)
        text = re.sub(r"(?m)^Flight\s+rate=\d+", "Flight   rate=5", text)
        text = re.sub(r"(?m)^Outputs\s+rate=\d+", "Outputs  rate=1", text)
    text += "\n[reload]\nmachine  mission\nsize     1024\nram      192\nactivate Safe\n"
    with open(app, "w") as f:
        f.write(text)
    return folder


def main() -> int:
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.cli.machine import image_for
    from fswkit.reload.sim import power_cuts, timed_upload

    os.makedirs(OUT, exist_ok=True)
    tank_app, tank = built(os.path.join(ROOT, "examples", "tank"))
    stand_app, stand = built(os.path.join(ROOT, "examples", "stand"))
    df, dr = stand.size.flash - tank.size.flash, stand.size.ram - tank.size.ram
    print("[reload] on an Uno: examples/stand against examples/tank (the same application without [reload])")
    print(f"  flash {tank.size.flash:,} -> {stand.size.flash:,} B (+{df:,}: the VM, its EEPROM verifier, the store "
          f"and its link commands)")
    store = _store_bytes(stand.artifact)
    print(f"  static RAM {tank.size.ram:,} -> {stand.size.ram:,} B (+{dr:,}: the image buffer of "
          f"{stand_app.reload.size} B, {stand_app.reload.ram} B for an image's windows and locals, the "
          f"layout's record (its element table is in flash), the store: {store} B, the check's state in slices "
          f"included)")
    print(f"  targets (the VM alone, tools/bench_vm.py): flash <= 3,072 B, RAM <= 64 B beyond the state vector")

    d = Diagnostics()
    rows = []
    for name, baud, loss in (("rocket-115200", 115200, 0.0), ("rocket-9600", 9600, 0.2)):
        app, b = built(rocket_variant(name, baud))
        got = image_for(app, os.path.join(ROOT, "examples", "rocket", "mission.sm"), d)
        if got is None:
            sys.exit(f"bench_reload: mission.sm does not compile:\n{d.render()}")
        image, mask, _m = got
        r = timed_upload(b.artifact, "mega2560", app, image, mask, loss=loss, seed=1)
        rows.append((baud, loss, len(image) + len(mask), r))
    print()
    print("upload of examples/rocket/mission.sm to a running ATmega2560 (simulated time)")
    print(f"  {'link':<28} {'bytes':>6} {'upload':>9} {'activate':>9} {'commands':>9} {'sent again':>11} "
          f"{'busy':>5}  frames lost up / down")
    for baud, loss, n, r in rows:
        link = f"{baud} baud" + (f", {loss:.0%} lost each way" if loss else ", clean")
        print(f"  {link:<28} {n:>6} {r.seconds:>8.2f}s {r.activate_s:>8.2f}s {r.sent:>9} {r.resent:>11} "
              f"{r.busy:>5}  {r.up_dropped} of {r.up_frames} / {r.down_dropped} of {r.down_frames}")
    print("  the board's checks (the commit's, the activation's: the CRC, then the verifier reading the EEPROM), "
          "a slice at each mission step, at 16 MHz:")
    for baud, _loss, _n, r in rows:
        worst = ", ".join(f"{t} {us / 1e3:.2f}" for t, us in r.worst_us.items() if t in ("uplink", "mission"))
        print(f"    {baud:>6} baud: the longest slice {r.longest_slice / 16e3:.2f} ms ({r.slices} slices), "
              f"the longest reload command {r.longest_command / 16e3:.2f} ms, the switch's copy into RAM "
              f"{r.copy / 16e3:.2f} ms; longest steps (ms): {worst}; {r.late} late cycles, "
              f"{sum(r.overruns.values())} overruns")

    volts = {"A0": (740 + 125.0) / 250.0}  # 740 psi: the vent controller holds, a new one may take over
    got = image_for(stand_app, os.path.join(ROOT, "examples", "stand", "tank_700.sm"), d)
    cut = power_cuts(stand.artifact, "uno", stand_app, got[0], got[1], stride=1, analog=volts)
    print()
    print(f"power cut at every EEPROM byte write of an upload and its activation (examples/stand, "
          f"{len(got[0]) + len(got[1])} B): {cut.writes} writes, {cut.cases} cuts; the board came back running the "
          f"old machine {cut.old} times, the new one {cut.new} times, anything else {len(cut.bad)} times")
    for k, why in cut.bad:
        print(f"  cut after write {k}: {why}")
    print(f"reload bench: {1 if not cut.bad else 0} passed, {1 if cut.bad else 0} failed")
    return 1 if cut.bad else 0


def _store_bytes(elf: str) -> int:
    """sizeof(fsw::ReloadStore) in a build: its one variable's size."""
    from fswkit.target.build import elf_symbols

    return next(size for _a, size, kind, name in elf_symbols(elf)  # (link-time optimised: its name mangled)
                if kind in "bBdD" and (name.endswith("::reload") or "_GLOBAL__N_16reloadE" in name))


if __name__ == "__main__":
    sys.exit(main())
