"""Digital sensors in flight (docs/sensor-table.md, docs/sim.md "Digital
sensor parts"): examples/hpr_digital's real firmware on the simulated Uno,
its BMP280 and ADXL345 simulated as register models on the I2C and fed by
the plant, closed loop.

- The nominal flight passes every check of the flight, and both parts
  report ok in the health frame to the end.
- The barometer stops answering in coast (`--fault baro-nack@15`): its
  fault flag (`baroFault`) is in the very next telemetry sample of it,
  11 ms later (the driver polls the part every cycle while it converts,
  and the inputs task raises the flag in the step that sees the first
  unanswered transaction), the
  health frame says NO ANSWER from its next frame on, the executor never
  overruns or runs late, and the mission falls back to its backup timers:
  the drogue at APOGEE_BACKUP after launch, and no main on the altitude the
  filter extrapolates without a barometer (the flight is cut at 90 s, before
  the main's own backup timer).
- A real flight's tape through the parts passes every check.

Two flights at a time on one build of the firmware."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES
from support.closed_loop import build_project, fly_all, needs_avr_sim

pytestmark = [needs_avr_sim, pytest.mark.costly(17)]

DIGITAL = EXAMPLES / "hpr_digital"
FAIL_S = 15.0
CUT_S = 90.0


@pytest.fixture(scope="module")
def flights(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("digital")
    cut = tmp / "cut.toml"  # the project's plant, flown to CUT_S only
    cut.write_text(f'extends = "{DIGITAL / "plant.toml"}"\n\n[scenario]\nmax_s = {CUT_S}\n')
    flown = fly_all(DIGITAL, build_project(DIGITAL),
                    {"nominal": {}, "nack": {"fault": f"baro-nack@{FAIL_S:g}", "params": str(cut)}})
    return {name: flight for name, (_app, flight) in flown.items()}


def _executor_kept_time(flight) -> None:
    h = flight.run.session.health
    assert h["late"] == 0 and h["dropped"] == 0, flight.report.text()
    assert sum(t["overruns"] for t in h["tasks"]) == 0, flight.report.text()
    worst = max(h["tasks"], key=lambda t: t["worst_us"])
    print(f"worst task step {worst['worst_us']} µs ({worst['name']})")
    assert worst["worst_us"] < 10_000  # within the 100 Hz cycle


def test_the_nominal_flight_passes_every_check(flights):
    f = flights["nominal"]
    assert f.report.checks and all(c.passed for c in f.report.checks), f.report.text()
    assert [p["words"] for p in f.run.session.health["sensors"]] == ["ok", "ok"]
    assert f.run.part_health["bmp280@0x76"][1] == 0 and f.run.part_health["adxl345@0x53"][1] == 0
    assert not any(row.get("baroFault") or row.get("accelFault") for _, row in f.run.samples)
    _executor_kept_time(f)


def test_a_barometer_that_stops_answering_is_flagged_at_once(flights):
    f = flights["nack"]
    assert f.run.part_failures == [(FAIL_S, "bmp280@0x76", "nack")]
    flags = [(t, row["baroFault"]) for t, row in f.run.samples if "baroFault" in row]
    before = [v for t, v in flags if t < FAIL_S]
    after = [(t, v) for t, v in flags if t >= FAIL_S]
    assert before and not any(before)
    # the Status stream (10 Hz) samples 11 ms past each tenth of a second: its sample 11 ms (about a cycle) after
    # the failure already says so, and every later one
    assert after[0][0] - FAIL_S <= 0.02 and all(v for _, v in after), after[:3]
    frames, faulty, first = f.run.part_health["bmp280@0x76"]
    assert faulty > 0 and first >= FAIL_S
    healths = frames / CUT_S  # health frames a second
    assert first - FAIL_S <= 1.0 / healths + 0.05, (first, healths)
    assert f.run.session.health["sensors"][0]["words"] == "NO ANSWER"
    assert f.run.session.health["sensors"][1]["words"] == "ok"  # the accelerometer, on the same bus, unharmed
    _executor_kept_time(f)


def test_the_mission_falls_back_to_its_backup_timers(flights):
    f = flights["nack"]
    text = f.report.text()
    launch = next(t for t, _, name in f.run.transitions if name == "Boost")
    rises = {role: [e.t for e in f.run.pin_events if e.role == role and e.level] for role in ("drogue", "main")}
    # APOGEE_BACKUP = 40 s after the mission's launch; its Boost state is entered 50-80 ms after liftoff
    assert len(rises["drogue"]) == 1 and 39.8 <= rises["drogue"][0] - launch <= 40.2, text
    assert rises["main"] == [], text  # never on the extrapolated altitude; MAIN_BACKUP is 100 s under the drogue
    names = [name for _, _, name in f.run.transitions]
    assert names == ["Safe", "Armed", "Boost", "Coast", "Apogee", "Drogue"], names
    backup = [c for c in f.report.checks if "backup timer" in c.name]
    assert backup and all(c.passed for c in backup), text


@pytest.mark.skipif(not (EXAMPLES.parent.parent / "shared" / "flights").is_dir(),
                    reason="../shared/flights is absent: no real flight to replay")
def test_a_real_flight_through_the_parts():
    from support.hpr_tapes import build_hpr, replay_and_check

    replay_and_check("ndrt2020_raven", build_hpr(DIGITAL))
