"""`fsw sim PROJECT --plant rocket --runs N --dispersion FILE`: a small study
end to end (short flights: plant.toml's max_s cut to 16 s, just past
apogee), its table and CSV, one failing run flown again by the command the
table prints, with the same outcome; Ctrl-C ending a study with its
partial table; and the options' errors, located, before anything is
built."""

from __future__ import annotations

import csv
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT, run_fsw
from support.progress import ProgressChannel

pytestmark = pytest.mark.costly(6)

ROCKET = EXAMPLES / "rocket"
DISPERSION = ROCKET / "dispersion.toml"
needs_sim = pytest.mark.skipif(shutil.which("avr-gcc") is None
                               or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                               reason="gcc-avr and libsimavr-dev are needed (make setup)")


def _short(tmp: Path, max_s: float = 16) -> Path:
    text = (ROCKET / "plant.toml").read_text()
    assert "max_s      = 90" in text
    p = tmp / "short.toml"
    p.write_text(text.replace("max_s      = 90", f"max_s      = {max_s:g}"))
    return p


def _fsw(*args: str, **kw) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "host-tools") + os.pathsep + str(ROOT))
    return subprocess.run([sys.executable, "-m", "fswkit.cli", *args], capture_output=True, text=True, env=env,
                          cwd=ROOT, timeout=600, **kw)


@needs_sim
def test_a_small_study_and_the_replay_of_one_of_its_runs(tmp_path: Path):
    short = _short(tmp_path)
    out = tmp_path / "study"
    r = _fsw("sim", str(ROCKET), "--plant", "rocket", "--params", str(short), "--runs", "4", "--jobs", "2",
             "--dispersion", str(DISPERSION), "--seed", "3", "--out", str(out))
    assert "Traceback" not in r.stderr, r.stderr
    assert r.returncode == 1, r.stderr  # no run lands before 16 s: every one fails its landing check
    text = r.stdout
    assert text.startswith("dispersion study: rocket, 4 of 4 runs, seed 3"), text
    assert re.search(r"apogee detected within 1 s after the true apogee, not before +\d/4 +P \d\.\d{3}  "
                     r"\[\d\.\d{3}, \d\.\d{3}\]", text), text
    assert re.search(r"every check +0/4 +P 0\.000  \[0\.000, 0\.490\]", text), text
    assert re.search(r"apogee detection − true apogee \(s\) +[-+]\d\.\d{3}", text), text
    assert "0 of 4 runs passed every check" in text
    commands = [ln.strip() for ln in text.splitlines() if ln.strip().startswith("fsw sim ")]
    assert len(commands) == 4
    assert (out / "study.txt").read_text() == text
    rows = list(csv.DictReader((out / "study.csv").open()))
    assert [int(x["run"]) for x in rows] == [0, 1, 2, 3]
    assert all(x["passed"] == "0" and x["landing_detected"] == "0" for x in rows)

    # run 1 again, alone, by its printed command: the same flight
    words = shlex.split(commands[1])
    assert words[-2:] == ["--run", "1"] and words[:2] == ["fsw", "sim"]
    rr = _fsw(*words[1:], "--out", str(tmp_path / "run1"))
    assert "Traceback" not in rr.stderr, rr.stderr
    assert rr.returncode == 1
    m = re.search(r"apogee, detected: .* error ([-+]\d+\.\d) m, ([-+]\d+\.\d{3}) s", rr.stdout)
    assert m, rr.stdout
    assert float(m.group(2)) == pytest.approx(float(rows[1]["apogee_error_s"]), abs=5e-4)
    assert float(m.group(1)) == pytest.approx(float(rows[1]["apogee_error_m"]), abs=0.05)
    checks = re.findall(r"^  (PASS|FAIL)  (apogee detected|drogue fired|main fired|landing detected|the states)",
                        rr.stdout, re.M)
    assert [(v == "PASS") for v, _ in checks] == [rows[1][k.replace(" ", "_")] == "1" for _, k in checks]
    assert (tmp_path / "run1" / "summary.txt").exists()


@needs_sim
def test_ctrl_c_ends_a_study_with_the_runs_done(tmp_path: Path):
    short = _short(tmp_path, 12)
    out = tmp_path / "study"
    # the study's progress, as a display would get it from a worker: Ctrl-C is pressed once a run is done
    # (the others still flying), however fast this machine flies them
    with ProgressChannel() as channel:
        p = subprocess.Popen([sys.executable, "-m", "fswkit.cli", "sim", str(ROCKET), "--plant", "rocket",
                              "--params", str(short), "--runs", "40", "--jobs", "2", "--out", str(out)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT,
                             env=channel.env(PYTHONPATH=str(ROOT / "host-tools") + os.pathsep + str(ROOT)),
                             start_new_session=True)
        try:
            channel.wait_done("study", p)
            os.killpg(p.pid, signal.SIGINT)  # as a terminal's Ctrl-C: the whole group
            stdout, stderr = p.communicate(timeout=120)
        finally:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
    assert "Traceback" not in stderr, stderr
    assert p.returncode == 130, stderr
    assert "stopped early" in stdout and "stopped after" in stderr
    n = int(re.match(r"dispersion study: rocket, (\d+) of 40 runs", stdout).group(1))
    assert n < 40
    assert len((out / "study.csv").read_text().splitlines()) == n + 1


def sim(*args: str):
    r = run_fsw("sim", *args)
    assert "Traceback" not in r.err and "internal error" not in r.err, r.err
    return r


@pytest.mark.parametrize("args, message", [
    (("--runs", "4"), "--runs flies the rocket plant: add --plant rocket"),
    (("--plant", "tank", "--runs", "4"), "dispersion studies fly the rocket plant, not the tank"),
    (("--plant", "rocket", "--dispersion", str(DISPERSION)), "--dispersion needs --runs N"),
    (("--plant", "rocket", "--runs", "4", "--run", "2"), "one or the other"),
    (("--plant", "rocket", "--jobs", "2", "--run", "1"), "--jobs needs --runs N"),
    (("--plant", "rocket", "--runs", "4", "--fault", "stuck-baro"), "--fault does not go with --runs"),
    (("--plant", "rocket", "--runs", "4", "--tape", "x.csv"), "not a --tape"),
    (("--plant", "rocket", "--runs", "4", "--jobs", "257"), "--jobs 257: at most 256 flights at a time"),
])
def test_option_errors(args, message):
    r = sim(str(ROCKET), *args)
    assert r.code == 2, r.err
    assert message in r.err, r.err


def test_bad_numbers_of_runs():
    for bad in ("0", "-1", "many"):
        r = sim(str(ROCKET), "--plant", "rocket", "--runs", bad)
        assert r.code == 2 and "--runs" in r.err


def test_a_bad_dispersion_file_is_located_before_any_build(tmp_path: Path):
    bad = tmp_path / "d.toml"
    bad.write_text("[wind]\ngust_sd_m_s = -1\n")
    r = sim(str(ROCKET), "--plant", "rocket", "--runs", "4", "--dispersion", str(bad), "--out", str(tmp_path / "o"))
    assert r.code == 2
    assert f"{bad}:2: [wind] gust_sd_m_s: -1 is out of range" in r.err
    assert "built" not in r.err
    r = sim(str(ROCKET), "--plant", "rocket", "--runs", "4", "--dispersion", str(tmp_path / "none.toml"))
    assert r.code == 2 and "no such file" in r.err
