"""Closed-loop runs: the examples' real firmware on the simulated Uno in
lock-step with their plants (fsw sim --plant). The rocket flies two seeds
whose checks all pass, the stuck-barometer and pinned-sensor faults behave
as the mission machine promises, the tank regulates then aborts, and a run
is deterministic for its seed. Every flight of this module is flown once, two
at a time (about 25 s of wall time on two cores), and the tests read the
results; the flights whose files no test reads write none (no CSV, no
plot), and the command's tank flight is also the second run of the tank's
seed 1 that the determinism test compares byte for byte."""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT
from fswkit.plant.run import FILES, execute, prepare
from support.simfw import kept_sim

pytestmark = [pytest.mark.skipif(shutil.which("avr-gcc") is None or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                                 reason="gcc-avr and libsimavr-dev are needed (make setup)"),
              pytest.mark.costly(9)]

ROCKET, TANK = EXAMPLES / "rocket", EXAMPLES / "tank"
SEEDS = (1, 2)  # make bench flies seeds 1-20
HOLD_S = 6.0  # the pinned-sensor faults sit armed on the pad until then (plant.toml says 20 s)


@pytest.fixture(scope="module")
def flights(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("flights")
    rocket_elf, board = kept_sim(ROCKET)  # built into build/sim-tests/, once for every test file
    tank_elf, _ = kept_sim(TANK)
    short = tmp / "short-hold.toml"
    text = (ROCKET / "plant.toml").read_text()
    assert "hold_s     = 20" in text
    short.write_text(text.replace("hold_s     = 20", f"hold_s     = {HOLD_S:g}"))

    def rocket(name, seed, fault=None, params=None, files=True):
        _app, layout, sc = prepare(str(ROCKET), "rocket", seed=seed, fault=fault, params=params)
        return execute(sc, rocket_elf, board, layout, str(tmp / name) if files else None)

    def tank(name, seed):
        _app, layout, sc = prepare(str(TANK), "tank", seed=seed)
        return execute(sc, tank_elf, board, layout, str(tmp / name))

    def cli_tank():
        out = tmp / "cli-tank"
        r = subprocess.run([sys.executable, "-m", "fswkit.cli", "sim", str(TANK), "--plant", "tank", "--seed", "1",
                            "--out", str(out)], capture_output=True, text=True, cwd=ROOT)
        return r, out

    jobs = {f"seed{s}": (rocket, f"seed{s}", s) for s in SEEDS}
    jobs["stuck-baro"] = (rocket, "stuck-baro", 1, "stuck-baro", None, False)
    jobs["pinned-accel"] = (rocket, "pinned-accel", 4, "pinned-accel", str(short), False)
    jobs["pinned-baro"] = (rocket, "pinned-baro", 5, "pinned-baro", str(short), False)
    jobs["tank1"] = (tank, "tank1", 1)
    jobs["tank2"] = (tank, "tank2", 2)
    jobs["cli-tank"] = (cli_tank,)
    with ThreadPoolExecutor(2) as pool:
        futures = {k: pool.submit(fn, *a) for k, (fn, *a) in jobs.items()}
        return {k: f.result() for k, f in futures.items()}


def _csv(path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


# ---- the rocket ------------------------------------------------------------------------

@pytest.mark.parametrize("seed", SEEDS)
def test_nominal_flight_passes_every_check(flights, seed):
    fl = flights[f"seed{seed}"]
    rep = fl.report
    assert rep.passed, rep.text()
    assert [c.name for c in rep.checks][5:7] == [
        "the record covers 0.5 s before launch to landing at the log's rates (10 Hz)",
        "the record matches the telemetry value for value where both have a sample (within half a step where the "
        "encoding quantises)"]
    assert [c.name.split(" ")[0] for c in rep.checks] == ["apogee", "drogue", "main", "landing", "the", "the", "the",
                                                           "flash", "RAM"]
    assert "flight recorder: 1 flight(s)" in rep.text() and fl.files.get("record", "").endswith("record.log")
    f = rep.facts
    assert 300 <= f["true_apogee_m"] <= 500
    assert 0 <= f["apogee_error_s"] <= 1.0 and abs(f["apogee_error_m"]) < 5
    assert f["drogue_drop_m"] <= 30 and abs(f["main_alt_m"] - 150) <= 15
    assert 20 <= f["drogue_descent_m_s"] <= 25 and 6 <= f["main_descent_m_s"] <= 7.5
    assert f["landed"] and fl.run.sim_s <= 50
    # the link was clean, and the plant really ran at 1 kHz in lock-step
    s = fl.run.session
    assert s.stats.lost == 0 and s.deframer.stats.crc_errors == 0 and s.hello["schema_ok"]
    assert fl.run.steps == round(fl.run.sim_s * 1000)
    # several steps to a write while nothing the board says can change them (test_speculative_steps.py)
    assert fl.run.round_trips < fl.run.steps / 8


def test_the_pins_the_firmware_drives_deploy_the_chutes(flights):
    fl = flights["seed1"]
    sc, run = fl.scenario, fl.run
    drogue = [e for e in run.pin_events if e.role == "drogue"]
    main = [e for e in run.pin_events if e.role == "main"]
    # each pyro channel: one pulse of PULSE = 1000 ms, as mission.sm holds it
    assert [e.level for e in drogue] == [True, False] and [e.level for e in main] == [True, False]
    assert drogue[1].t - drogue[0].t == pytest.approx(1.0, abs=0.011)
    assert main[1].t - main[0].t == pytest.approx(1.0, abs=0.011)
    # the charges fire fire_ms after the rising edge and the canopy follows
    assert sc.rocket.deployed["drogue"] == pytest.approx(drogue[0].t + 0.020, abs=1e-9)
    assert sc.rocket.deployed["main"] == pytest.approx(main[0].t + 0.020, abs=1e-9)
    # the apogee state's entry, seen in telemetry (stamped with G, read as the executor cycle starts;
    # the state is streamed every other cycle, at 50 Hz), and the drogue pin (written by the outputs
    # task later in the entry's cycle) agree: the pin rises after the last sample still before
    # Apogee and within the cycle of the first sample in it
    t_apogee = next(t for t, _, n in run.transitions if n == "Apogee")
    t_before = max(t for t, row in run.samples if t < t_apogee and "state" in row)
    assert t_apogee - t_before == pytest.approx(0.020, abs=1e-9)
    assert t_before < drogue[0].t < t_apogee + 0.010


def test_flight_files(flights):
    fl = flights["seed1"]
    files = fl.files
    assert set(files) == set(FILES)
    rows = _csv(files["csv"])
    assert len(rows) == len(fl.run.rows)
    # truth and telemetry side by side: the telemetered altitude follows the true one
    flying = [r for r in rows if r["tm_state_name"] in ("Coast", "Drogue", "Main") and float(r["time_s"]) > 6]
    assert flying and all(abs(float(r["altitude_m"]) - float(r["tm_altitude"])) < 12 for r in flying)
    assert {r["tm_state_name"] for r in rows} >= {"Safe", "Armed", "Boost", "Coast", "Apogee", "Drogue", "Main",
                                                   "Landed"}
    assert Path(files["png"]).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert Path(files["summary"]).read_text() == fl.report.text()


def test_the_log_reads_back_with_the_ground_tools(flights, tmp_path):
    from conftest import run_fsw

    log = flights["seed2"].files["log"]
    out = tmp_path / "tm.csv"
    r = run_fsw("log2csv", log, "-o", str(out))
    assert r.code == 0, r.err
    rows = _csv(out)
    run = flights["seed2"].run
    flight_rows = [x for x in rows if x["from frame"] == "Flight"]
    assert len(flight_rows) == sum(1 for _, row in run.samples if "altitude" in row)
    assert {x["state"] for x in flight_rows} == {str(sid) for _, sid, _ in run.transitions}
    r = run_fsw("plot", log, "-e", "altitude", "state", "-o", str(tmp_path / "p.png"))
    assert r.code == 0 and f"{len(run.transitions) - 1} state transitions" in r.err


def test_stuck_barometer_drogue_by_the_backup_timer(flights):
    fl = flights["stuck-baro"]
    assert fl.report.passed, fl.report.text()
    sc, run = fl.scenario, fl.run
    drogue = next(e for e in run.pin_events if e.role == "drogue" and e.level)
    after = drogue.t - sc.rocket.liftoff
    assert 11.0 <= after <= 11.2  # APOGEE_BACKUP = 11000 ms after launch
    assert drogue.t > sc.rocket.apogee_t  # the barometer never saw the apogee
    # the barometer stuck at the pad's reading is "below MAIN_ALT" at once: the
    # main waits for its own backup, PULSE + MAIN_BACKUP = 11 s after the drogue
    main = next(e for e in run.pin_events if e.role == "main" and e.level)
    assert 11.0 <= main.t - drogue.t <= 11.05
    # the frozen barometer: the telemetered pressure stopped changing at ignition
    pressures = {row["pressure"] for t, row in run.samples if "pressure" in row and t > 3.2}
    assert len(pressures) == 1


@pytest.mark.parametrize("fault", ["pinned-accel", "pinned-baro"])
def test_pinned_sensor_keeps_the_vehicle_safe_on_the_pad(flights, fault):
    fl = flights[fault]
    assert fl.report.passed, fl.report.text()
    run = fl.run
    assert run.sim_s == pytest.approx(HOLD_S)
    assert not [e for e in run.pin_events if e.level]
    assert {n for _, _, n in run.transitions} == {"Safe", "Armed"}
    element = "accel" if fault == "pinned-accel" else "pressure"
    full = 20.0 if fault == "pinned-accel" else 5 * 6250 + 76875  # 5 V through rocket.aio's calibration
    last = [row[element] for _, row in run.samples if element in row][-1]
    assert last == pytest.approx(full, rel=1e-3)


# ---- the tank ------------------------------------------------------------------------

def test_tank_regulates_then_aborts_on_the_failure(flights):
    fl = flights["tank1"]
    assert fl.report.passed, fl.report.text()
    run, sc = fl.run, fl.scenario
    opens = [e for e in run.pin_events if e.level]
    assert len([e for e in opens if e.t < 9.0]) >= 10  # the valve cycles while regulating
    abort = next(t for t, _, n in run.transitions if n == "Abort")
    assert 9.0 < abort < 12.0
    psi = dict((row[0], row[1]) for row in run.rows)
    assert max(p for t, p in psi.items() if t < 9.0) < 790  # regulation held it near 775
    assert sc.valve  # TankVentControl's exit left the valve open


def test_runs_are_deterministic_for_their_seed(flights):
    # seed 1 flown twice, here and by the command (test_the_command_flies_the_tank), seed 2 once
    _r, cli = flights["cli-tank"]
    a, b = flights["tank1"].files, flights["tank2"].files
    again = {name: str(cli / FILES[name]) for name in ("csv", "log", "summary")}
    for name in ("csv", "log", "summary"):
        if name == "summary":  # the same but for the wall time it took
            strip = lambda text: [ln for ln in text.splitlines() if " wall (" not in ln]  # noqa: E731
            assert strip(Path(again[name]).read_text()) == strip(Path(a[name]).read_text())
        else:
            assert Path(again[name]).read_bytes() == Path(a[name]).read_bytes()
    assert Path(b["csv"]).read_bytes() != Path(a["csv"]).read_bytes()


def test_the_command_flies_the_tank(flights):
    r, out = flights["cli-tank"]
    assert r.returncode == 0, r.stderr
    assert "6 of 6 checks passed" in r.stdout  # 4 of the tank, 2 of the budget
    assert Path(out / FILES["summary"]).read_text() == r.stdout
    assert {p.name for p in out.iterdir()} == set(FILES.values()) - {FILES["record"]}  # the tank keeps no record
    assert f"wrote {out / FILES['log']}" in r.stderr


def test_the_readme_plot_is_the_demo_flight_of_this_firmware(flights):
    """docs/img/rocket-flight.png (shown in README.md) is `make demo`'s plot
    (seed 1): its text chunk holds the SHA-256 of the flight's CSV, which
    must be this tree's seed-1 flight. Stale after a change to the firmware,
    the configs or the plant: `make docs-img` flies it again."""
    import hashlib

    from fswkit.plant.report import DIGEST_KEY, png_text

    digest = hashlib.sha256(Path(flights["seed1"].files["csv"]).read_bytes()).hexdigest()
    shown = png_text(str(ROOT / "docs" / "img" / "rocket-flight.png")).get(DIGEST_KEY)
    assert shown == digest, "docs/img/rocket-flight.png is not this tree's demo flight: run `make docs-img`"


MEMORY = ("RAM (measured", "PASS  flash within", "PASS  RAM within")  # the build's bytes, quoted as measured


def _shown_lines(block: list[str]) -> list[str]:
    """A doc's quoted run, less what is not the report's (the command, its
    `fsw sim:` lines on standard error, `...`, the wall time) and the
    firmware's sizes, which the docs quote as measured on their day: what
    is left is the flight, which a seed makes the same byte for byte."""
    return [ln for ln in block if ln.strip() != "..." and not ln.startswith(("$ ", "fsw sim:")) and " wall (" not in ln
            and not ln.strip().startswith(MEMORY)]


def _in_report(line: str, text: str) -> bool:
    if line.endswith("..."):  # a line the doc cuts short: the report's begins so
        return any(r.startswith(line[:-3]) for r in text.splitlines())
    return line in text.splitlines()


@pytest.mark.parametrize("doc,seed", [("README.md", 1), ("docs/cli.md", 2)])
def test_the_runs_the_docs_quote_are_this_firmwares(flights, doc, seed):
    """README.md's demo flight (`make demo`, seed 1) and docs/cli.md's
    `--seed 2` flight are quoted as the report prints them (cli.md quoted
    a seed-3 flight with a RAM line of another build). Stale after a change
    to the firmware's behaviour, the configs or the plant: fly the seed
    again and paste its lines."""
    text = (ROOT / doc).read_text()
    if doc == "README.md":
        block = text.split("```\napogee, true", 1)[1].split("```", 1)[0]
        lines = ("apogee, true" + block).splitlines()
    else:
        start = text.index(f"    $ fsw sim examples/rocket --plant rocket --out build/flight --seed {seed}\n")
        lines = []
        for ln in text[start:].splitlines():
            if not ln.startswith("    "):
                break
            lines.append(ln[4:])
    shown = _shown_lines(lines)
    assert len(shown) >= 8 and shown[-1] == "9 of 9 checks passed"
    report = flights[f"seed{seed}"].report.text()
    assert [ln for ln in shown if not _in_report(ln, report)] == []
