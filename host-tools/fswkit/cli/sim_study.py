"""`fsw sim PROJECT --plant rocket --runs N [--jobs J] [--dispersion
FILE.toml] [--seed S] [--out DIR]`: a dispersion study (fswkit.plant.study),
its table on standard output and in DIR/study.txt, one row per run in
DIR/study.csv; and `--run I`: run I of a study flown again alone, exactly,
with its files (log, CSV, plot, summary) as a single flight writes them."""

from __future__ import annotations

import os
import sys
import time

STUDY_FILES = ("study.txt", "study.csv")
MAX_JOBS = 256
# The runs of one study (numbered 0 to MAX_RUNS - 1): two weeks of flights at 3,000 an hour, the table's
# results held in memory meanwhile. A larger study is several, each with its own --seed.
MAX_RUNS = 1_000_000


def study_run(args) -> int:
    from fswkit.outputs import OutputError, Stopped, check, stopped_by_signals, write_text
    from fswkit.plant import dispersion as dispersion_mod
    from fswkit.progress import progress
    from fswkit.plant import study
    from fswkit.plant.params import ParamsError
    from fswkit.plant.run import SetupError, prepare, refuse_users_files
    from fswkit.sim.command import build, is_elf, say
    from fswkit.target.build import BuildError, default_output

    if args.jobs is not None and args.runs is None:
        say("--jobs needs --runs N (how many flights of a study fly at a time)")
        return 2
    if args.runs is not None and args.runs > MAX_RUNS:
        say(f"--runs {args.runs}: at most {MAX_RUNS:,} flights in one study (a larger one is several, each with "
            "its own --seed)")
        return 2
    if args.run is not None and args.run >= MAX_RUNS:
        say(f"--run {args.run}: no study has that run (they are numbered 0 to {MAX_RUNS - 1:,})")
        return 2
    what = "--runs" if args.runs is not None else "--run" if args.run is not None else "--dispersion"
    if args.plant != "rocket":
        say(f"{what} flies the rocket plant: add --plant rocket" if args.plant is None else
            f"{what}: dispersion studies fly the rocket plant, not the {args.plant}")
        return 2
    if args.runs is None and args.run is None:
        say("--dispersion needs --runs N (a study) or --run I (one run of a study, again)")
        return 2
    if args.runs is not None and args.run is not None:
        say("--runs N flies a study; --run I flies one of its runs again: one or the other")
        return 2
    if args.jobs is not None and args.jobs > MAX_JOBS:
        say(f"--jobs {args.jobs}: at most {MAX_JOBS} flights at a time (each is a process and a simulated board)")
        return 2
    for opt, given in (("--duration", args.duration is not None), ("--fast", args.fast),
                       ("--analog", bool(args.analog)), ("--link", args.link is not None),
                       ("--fault", args.fault is not None)):
        if given:
            say(f"{opt} does not go with {what}: the dispersion file says how each flight differs")
            return 2
    if is_elf(args.project) or args.project.endswith(".elf"):
        say(f"{args.project}: {what} needs the project (its folder or .app), not a firmware ELF")
        return 2
    seed = 1 if args.seed is None else args.seed
    # the plant file's errors and the dispersion file's, all in one run (past_flight's need both files' values)
    setup_error = None
    try:
        app, layout, sc = prepare(args.project, "rocket", params=args.params, seed=seed, board=args.board)
    except SetupError as e:
        setup_error = str(e)
    try:
        disp, disp_errors = (dispersion_mod.load_all(args.dispersion) if args.dispersion is not None
                             else (dispersion_mod.Dispersion.none(), []))
    except ParamsError as e:
        disp, disp_errors = None, e.errors
    if setup_error is not None:
        for line in setup_error.splitlines():
            sys.stderr.write(f"fsw sim: {line}\n" if line and not line.startswith((" ", "|")) else line + "\n")
    for line in disp_errors:
        sys.stderr.write(f"fsw sim: {line}\n")
    if setup_error is not None or disp is None:
        return 2
    params = args.params or os.path.join(os.path.dirname(app.path) or ".", "plant.toml")
    command = ["fsw", "sim", args.project, "--plant", "rocket"]
    if args.params:
        command += ["--params", args.params]
    if args.board:
        command += ["--board", args.board]
    if args.dispersion:
        command += ["--dispersion", args.dispersion]

    span = study.span_of(sc)  # each run's events drawn up to the end of its flight
    past = disp.past_flight(span)
    for line in past:
        sys.stderr.write(f"fsw sim: {line}\n")
    if past or disp_errors:
        return 2
    if args.run is not None:
        return _one_run(args, app, layout, params, disp, seed, span)

    try:
        out = args.out or default_output(app, "rocket-study")
        os.makedirs(out, exist_ok=True)
        for name in STUDY_FILES:
            check(os.path.join(out, name), [params, args.dispersion], what="study's " + name)
        refuse_users_files(out, STUDY_FILES)
    except (OutputError, BuildError) as e:
        say(str(e))
        return 2
    except OSError as e:
        from fswkit.outputs import not_a_folder

        say(f"cannot create the output folder {out}: {not_a_folder(out) or e.strerror or e}")
        return 2
    built = build(args.project, args.board)
    if isinstance(built, int):
        return built
    elf, board = built
    jobs = min(args.jobs or study.cores(), args.runs)  # never more at a time than there are runs
    setup = study.Setup(app, layout, params, elf, board, disp, seed, command, span)
    say(f"dispersion study: {args.runs} flight{'s' if args.runs != 1 else ''} of the real firmware on simulated "
        f"{board.name}s, {jobs} at a time, seed {seed}")
    finished: list = []
    t0 = time.monotonic()
    with progress("study", total=args.runs, unit="runs") as bar:
        def on_result(r):
            finished.append(r)
            bar.update(len(finished), failed=sum(not x.passed for x in finished))

        with stopped_by_signals():
            try:
                results, complete = study.run_study(setup, args.runs, jobs, on_result)
            except Stopped:  # outside the wait for results (the pool starting or ending): the runs done so far
                results, complete = sorted(finished, key=lambda r: r.index), False
    wall = time.monotonic() - t0
    text = study.text(setup, results, args.runs, jobs, wall, complete, args.dispersion)
    sys.stdout.write(text)
    sys.stdout.flush()
    try:
        write_text(os.path.join(out, "study.txt"), text, [params, args.dispersion], what="the study's table")
        write_text(os.path.join(out, "study.csv"), study.csv_text(results), [params, args.dispersion],
                   what="the study's runs")
    except OutputError as e:
        say(str(e))
        return 1
    say(f"wrote {os.path.join(out, 'study.txt')}, {os.path.join(out, 'study.csv')}")
    if not complete:
        from fswkit import outputs

        say(f"stopped after {len(results)} of {args.runs} runs")
        return 128 + (outputs.stopped_by or 2)
    return 0 if all(r.passed for r in results) else 1


def _one_run(args, app, layout, params, disp, seed, span) -> int:
    """`--run I`: run I of the study flown again alone, its files written."""
    from fswkit.cli.common import flown, folder_and_firmware
    from fswkit.plant import study
    from fswkit.outputs import OutputError
    from fswkit.plant.run import execute, refuse_inputs
    from fswkit.target.build import BuildError, default_output
    from fswkit.sim.command import say

    setup = study.Setup(app, layout, params, "", None, disp, seed, span_s=span)
    d = study.draw_run(setup, args.run)
    sc = study.scenario_for(setup, d)
    try:
        out = args.out or default_output(app, f"rocket-run-{args.run}")
        refuse_inputs(out, [params, args.dispersion])
    except (OutputError, BuildError) as e:
        say(str(e))
        return 2
    built = folder_and_firmware(args.project, args.board, out)
    if isinstance(built, int):
        return built
    elf, board = built
    row = d.row()
    facts = ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in row.items()
                      if v is not None)
    say(f"run {args.run} of the study with seed {seed} (sensor noise seed {d.noise_seed}): {facts}")
    return flown(lambda: execute(sc, elf, board, layout, out), out)
