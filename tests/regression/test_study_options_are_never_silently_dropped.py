"""The options of a dispersion study (`fsw sim PROJECT --plant rocket
--runs N [--jobs J]`, `--run I`) said one thing and did another:

- `--jobs J` without `--runs` was dropped without a word: with `--plant
  rocket` a single flight was flown, without `--plant` the board ran free
  on its pty until Ctrl-C;
- `--runs N` took any number (10^30 flights started a study that could only
  end by running out of memory), and `--run I` any index, though no study
  has that run;
- the table's head said `J at a time` when fewer flights than J were flown
  at a time (never more at a time than there are runs).

Now `--jobs` without `--runs` is refused before anything is built, exit 2;
`--runs` is at most MAX_RUNS (a larger study is several, each with its own
`--seed`) and `--run` is one of a study's runs, 0 to MAX_RUNS - 1, both
refused before anything is read or built; and the table says how many
flights were flown at a time."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT, run_fsw

MAX_RUNS = 1_000_000  # fswkit.cli.sim_study.MAX_RUNS: 2 weeks of flights at 3,000 an hour

ROCKET = EXAMPLES / "rocket"
needs_sim = pytest.mark.skipif(shutil.which("avr-gcc") is None
                               or not os.path.exists("/usr/include/simavr/sim_avr.h"),
                               reason="gcc-avr and libsimavr-dev are needed (make setup)")


def _fsw(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    # A child process in its own session: an option dropped in favour of a board that runs until Ctrl-C fails
    # the test when its time is up, and its group is ended with it.
    env = dict(os.environ, PYTHONPATH=str(ROOT / "host-tools") + os.pathsep + str(ROOT))
    p = subprocess.Popen([sys.executable, "-m", "fswkit.cli", *args], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=env, cwd=ROOT, start_new_session=True)
    try:
        out, err = p.communicate(timeout=timeout)
    finally:
        if p.poll() is None:
            os.killpg(p.pid, 9)
            p.communicate()
    return subprocess.CompletedProcess(p.args, p.returncode, out, err)


@pytest.mark.parametrize("plant", [("--plant", "rocket"), ()])
def test_jobs_without_runs_is_refused(tmp_path: Path, plant):
    out = tmp_path / "out"
    r = _fsw("sim", str(ROCKET), *plant, "--jobs", "2", "--out", str(out))
    assert r.returncode == 2, r.stderr
    assert "fsw sim: --jobs needs --runs N" in r.stderr, r.stderr
    assert "built" not in r.stderr and not out.exists()


@pytest.mark.parametrize("args, message", [
    (("--runs", str(MAX_RUNS + 1)), f"--runs {MAX_RUNS + 1}: at most {MAX_RUNS:,} flights in one study"),
    (("--runs", "1" + "0" * 30), f"at most {MAX_RUNS:,} flights in one study"),
    (("--run", str(MAX_RUNS)), f"--run {MAX_RUNS}: no study has that run (they are numbered 0 to {MAX_RUNS - 1:,})"),
    (("--run", "9" * 40), "no study has that run"),
])
def test_numbers_of_runs_no_study_has_are_refused(tmp_path: Path, args, message):
    # with a dispersion file that has an error: the number is refused first, before any file is read
    bad = tmp_path / "d.toml"
    bad.write_text("[wind]\ngust_sd_m_s = -1\n")
    r = run_fsw("sim", str(ROCKET), "--plant", "rocket", *args, "--dispersion", str(bad))
    assert r.code == 2, r.err
    assert message in r.err, r.err
    assert "d.toml" not in r.err and "Traceback" not in r.err


def test_the_largest_numbers_are_taken(tmp_path: Path):
    from fswkit.cli import sim_study

    assert sim_study.MAX_RUNS == MAX_RUNS
    bad = tmp_path / "d.toml"
    bad.write_text("[wind]\ngust_sd_m_s = -1\n")
    for args in (("--runs", str(MAX_RUNS)), ("--run", str(MAX_RUNS - 1))):
        r = run_fsw("sim", str(ROCKET), "--plant", "rocket", *args, "--dispersion", str(bad))
        assert r.code == 2 and f"{bad}:2: [wind] gust_sd_m_s" in r.err, r.err  # past the number: the file read


@needs_sim
def test_the_table_says_how_many_flew_at_a_time(tmp_path: Path):
    text = (ROCKET / "plant.toml").read_text()
    assert "max_s      = 90" in text
    short = tmp_path / "short.toml"
    short.write_text(text.replace("max_s      = 90", "max_s      = 12"))  # a short flight: up, not down
    r = _fsw("sim", str(ROCKET), "--plant", "rocket", "--params", str(short), "--runs", "1", "--jobs", "2",
             "--out", str(tmp_path / "study"), timeout=300)
    assert "Traceback" not in r.stderr, r.stderr
    assert "1 flight of the real firmware on simulated unos, 1 at a time" in r.stderr, r.stderr
    head = r.stdout.splitlines()[0]
    assert head.startswith("dispersion study: rocket, 1 of 1 runs") and head.endswith("; 1 at a time"), head
