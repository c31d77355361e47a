#!/usr/bin/env python3
"""Mutation fuzzer for the front end (`make fuzz`): the command line over
fswkit.testing.fuzz, which holds the corpus, mutators and invariants (its
docstring says what a case is and what must hold). Case i is a pure
function of (seed, i); failing inputs go to build/fuzz/crashes/.

    tools/fuzz_frontend.py --cases 1000000 [--seed 1] [--workers 2]
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import sys
import tempfile
import time
from pathlib import Path

from fswkit.testing import fuzz as engine

ROOT = Path(__file__).resolve().parent.parent


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=int(os.environ.get("FSW_FUZZ_EXAMPLES", 1000000)))
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds one case may take")
    ap.add_argument("--cli-every", type=int, default=100, help="run `fsw check`/`fsw test` every N cases")
    ap.add_argument("--generated", type=int, default=60, help="generated programs in the corpus")
    ap.add_argument("--out", default=str(ROOT / "build" / "fuzz" / "crashes"))
    ap.add_argument("--replay", type=int, metavar="CASE", help="rebuild case CASE into --out and run it once")
    args = ap.parse_args(argv)
    say = lambda s: print(s, file=sys.stderr, flush=True)  # noqa: E731

    t0 = time.monotonic()
    projects = engine.corpus(args.generated)
    say(f"fuzz: corpus of {len(projects)} projects ({time.monotonic() - t0:.1f} s)")
    if args.replay is not None:
        files = engine.make_case(projects, args.seed, args.replay)[0]
        engine.record(Path(args.out), args.replay, files, "replay", f"seed {args.seed} case {args.replay}\n")
        workdir = tempfile.mkdtemp()
        try:
            engine.run_case(files, workdir, cli=True)
        finally:
            shutil.rmtree(workdir, ignore_errors=True)
        print("1 passed, 0 failed")
        return 0
    shutil.rmtree(args.out, ignore_errors=True)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # so that the workers are stopped too
    o = engine.fuzz(args.cases, args.seed, args.workers, args.timeout, args.out, args.cli_every,
             projects=projects, progress=say)
    rate = o.cases / o.seconds if o.seconds else 0.0
    print(f"fuzz: {o.cases} cases, seed {args.seed}, {args.workers} workers, "
          f"{o.seconds:.1f} s ({rate:.0f} cases/s)")
    for s, n in sorted(o.signatures.items(), key=lambda kv: -kv[1])[:20]:
        print(f"  {n} x {s}")
    if o.failed:
        print(f"failing inputs: {args.out}/")
    print(f"{o.passed} passed, {o.failed} failed")
    return 1 if o.failed or o.cases != args.cases else 0


if __name__ == "__main__":
    sys.exit(main())
