"""Ctrl-C during `fsw sim PROJECT --tape FLIGHT.csv --perturb N` did not
stop it: the replays still queued all flew (30 replays of the Camoes tape
went on for 135 s after Ctrl-C), then it exited 130 without a word or a
file about the runs it had finished. Every replay was also drawn and queued
up front, so a large N (`--perturb 100000000`) filled memory before the
first replay, after the build. Now Ctrl-C (or SIGTERM) stops the replays
at their next step: the runs finished by then make the table and the
files, which say "stopped early", exit status 130 (128 + N after signal
N), as a dispersion study's; and N is at most 1,000,000 (a study's runs),
refused before the build, as `--perturb 0` now is."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import EXAMPLES, ROOT, SHARED, run_fsw
from support.progress import ProgressChannel

HPR = EXAMPLES / "hpr"
TAPE = SHARED / "flights" / "ndrt2020_raven.csv"


@pytest.mark.parametrize("n", ["0", "1000001"])
def test_a_count_out_of_range_is_refused_before_the_build(tmp_path, n):
    r = run_fsw("sim", str(HPR), "--tape", str(TAPE), "--perturb", n, "--out", str(tmp_path / "out"))
    assert r.code == 2, r.err
    assert "built" not in r.err and not (tmp_path / "out").exists(), r.err
    assert "--perturb" in r.err and "Traceback" not in r.err, r.err


@pytest.mark.skipif(not TAPE.exists(), reason=f"{TAPE} is not there")
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_stopped_robustness_run_keeps_what_it_flew(tmp_path, sig):
    out = tmp_path / "out"
    fsw = os.path.join(os.path.dirname(sys.executable), "fsw")
    # the replays' progress, as a display would get it from a worker: the stop is sent once a run is done
    # (the other replay still flying), however fast this machine flies them
    err_file = open(tmp_path / "stderr", "w+b")  # noqa: SIM115 (read after the run)
    with ProgressChannel() as channel:
        # PYTHONFAULTHANDLER: a SIGABRT writes every thread's stack to stderr (below: a stop not obeyed)
        p = subprocess.Popen([fsw, "sim", str(HPR), "--tape", str(TAPE), "--perturb", "400", "--out", str(out)],
                             stdout=subprocess.PIPE, stderr=err_file, start_new_session=True, cwd=ROOT,
                             env=channel.env(PYTHONFAULTHANDLER="1"))
        try:
            channel.wait_done("perturbed replays", p, why=lambda: (tmp_path / "stderr").read_text())
            os.killpg(p.pid, sig)
            t0 = time.monotonic()
            try:
                out_text, _ = p.communicate(timeout=60)
            except subprocess.TimeoutExpired:
                os.kill(p.pid, signal.SIGABRT)  # where each of its threads was, for the report
                try:
                    p.communicate(timeout=30)
                except subprocess.TimeoutExpired:
                    pass
                pytest.fail("the replays went on 60 s after the stop; the command's threads then:\n"
                            + (tmp_path / "stderr").read_text(errors="replace")[-8000:])
            stopped_in = time.monotonic() - t0
        finally:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
                p.communicate()
            err_file.close()
    err = (tmp_path / "stderr").read_text()
    assert p.returncode == 128 + sig, (p.returncode, err)
    assert stopped_in < 30, stopped_in
    assert "Traceback" not in err, err
    assert "stopped after " in err and " of 400 perturbed replays" in err, err
    text = (out / "perturb.txt").read_text()
    assert "(stopped early" in text and text == out_text.decode()
    rows = (out / "perturb.csv").read_text().splitlines()
    assert len(rows) >= 2 and len(rows) - 1 < 400
