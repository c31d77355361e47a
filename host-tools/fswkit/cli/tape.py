"""`fsw tape import` (a recorder's log to a sensor tape), `fsw tape truth`
(a tape's truth worked out from it) and `fsw tape show` (a tape's header,
span, rates, columns, and its truth file's events): fswkit.tape. Bad input
is a located message and exit 1, never a traceback."""

from __future__ import annotations

import os
import sys

from fswkit.cli.common import EXIT_CONFIG, EXIT_FAIL, EXIT_OK


def _fail(command: str, e) -> int:
    for line in str(e).splitlines():
        sys.stderr.write(f"fsw tape {command}: {line}\n")
    return EXIT_FAIL


def cmd_import(args) -> int:
    from fswkit.outputs import OutputError, check
    from fswkit.tape import TapeError, write_tape
    from fswkit.tape.formats import FORMATS, convert
    from dataclasses import replace

    for option, value in (("--output", args.output), ("LOG", args.log)):
        if value == "":  # as main.py refuses an empty option of the other commands
            sys.stderr.write(f"fsw tape import: {option}: an empty string names nothing: give a path\n")
            return EXIT_CONFIG
    if args.alt_unit is not None and not FORMATS[args.format].alt_unit:
        sys.stderr.write(f"fsw tape import: --alt-unit: a {FORMATS[args.format].title} log says its altitude's "
                         "unit; the option is for eggtimer and rrc3 logs, whose altitude has none\n")
        return EXIT_CONFIG
    try:  # the output is refused before any work (an input, a folder, a missing folder, a file there)
        if args.output != "-":
            check(args.output, (args.log,), force=args.force, ask=True, what="tape")
        tape = convert(args.format, args.log, args.pad_alt, args.alt_unit)
        write_tape(args.output, replace(tape, path=args.output), force=args.force, inputs=(args.log,))
    except (TapeError, OutputError) as e:
        return _fail("import", e)
    if args.output != "-":
        sys.stderr.write(f"fsw tape import: {args.output}: {tape.rows:,} row{'s' if tape.rows != 1 else ''}, "
                         f"{tape.start:.2f} to "
                         f"{tape.end:.2f} s, columns {', '.join(tape.columns_available()) or 'none'}\n")
    if args.pad_alt is not None and not any("ISA standard atmosphere with the pad at" in d for d in tape.derived):
        # the pad altitude only sets pressure made from an altitude: given and unused is said, not ignored
        why = "the log has pressure of its own" if "pressure_pa" in tape.columns_available() \
            else "the log has no altitude to make pressure from"
        sys.stderr.write(f"fsw tape import: --pad-alt is not used: {why}\n")
    from_alt = any("ISA standard atmosphere with the pad at" in d for d in tape.derived)
    if FORMATS[args.format].alt_unit and from_alt and args.alt_unit is None:  # assumed: said, never silent
        sys.stderr.write("fsw tape import: the log's altitude read in feet, the recorder's default (--alt-unit m "
                         "for a recorder set to metres)\n")
    elif args.alt_unit is not None and not from_alt:
        sys.stderr.write("fsw tape import: --alt-unit is not used: the log has pressure of its own\n")
    _beyond_troposphere(args.output, tape)
    late = _dropped_late(tape)
    if late:  # a clock that restarted mid-log loses what follows: said here, not only in the header
        rows = f"{late:,} rows of the log dropped: their time is" if late != 1 else \
            "1 row of the log dropped: its time is"
        sys.stderr.write(f"fsw tape import: {rows} not after the previous row's (the tape's header counts them)\n")
    return EXIT_OK


def cmd_truth(args) -> int:
    from fswkit.outputs import OutputError, check, output
    from fswkit.tape import TapeError, read_tape, truth_path
    from fswkit.tape.truth import check_altitudes, compute, format_truth

    for option, value in (("--output", args.output), ("TAPE", args.tape)):
        if value == "":
            sys.stderr.write(f"fsw tape truth: {option}: an empty string names nothing: give a path\n")
            return EXIT_CONFIG
    path = args.output or truth_path(args.tape)
    try:  # the output is refused before any work: an input, a folder, a file there without --force
        if path != "-":
            check(path, (args.tape,), force=args.force, ask=True, what="truth file")
        tape = read_tape(args.tape)
        check_altitudes(tape)
        values = compute(tape)
        name = os.path.splitext(os.path.basename(args.tape))[0]
        text = format_truth(name, tape, values, os.path.basename(args.tape))
        with output(path, (args.tape,), force=args.force, ask=True, what="truth file") as f:
            f.write(text)
    except (TapeError, OutputError) as e:
        return _fail("truth", e)
    missing = [k for k in ("apogee_s", "burnout_s") if not any(key == k and v is not None for key, v, _ in values)]
    if path != "-":
        got = {k: v for k, v, _ in values if v is not None}
        said = ", ".join(f"{k} {got[k]:.2f} s" for k in ("burnout_s", "apogee_s", "landing_s") if k in got)
        sys.stderr.write(f"fsw tape truth: {path}: {said or 'no events'}\n")
    if missing:  # written all the same: the user gives what the tape cannot, as its comment says
        sys.stderr.write(f"fsw tape truth: the tape gives no {' and no '.join(missing)}: `fsw sim --tape` needs "
                         f"{'them' if len(missing) > 1 else 'it'}: write {' and '.join(missing)} into the truth "
                         "file by hand (its comments say why they are missing)\n")
    return EXIT_OK


def _beyond_troposphere(output: str, tape) -> None:
    """Says the pressures beyond the ISA troposphere that an import kept as
    the log has them (a glitch row; docs/tapes.md), at the tape's lines
    (rows of the tape written to standard output): `fsw tape truth`
    refuses them."""
    from dataclasses import replace

    from fswkit.tape import TapeError, read_tape
    from fswkit.tape.truth import check_altitudes

    try:
        check_altitudes(read_tape(output) if output != "-" else replace(tape, path="-"))
    except TapeError as e:
        n = len(e.messages) + e.hidden
        sys.stderr.write(f"fsw tape import: {output}: {n:,} pressure{'s' if n != 1 else ''} beyond the ISA "
                         f"troposphere kept as the log has {'them' if n != 1 else 'it'} (`fsw tape truth` refuses "
                         f"{'them' if n != 1 else 'it'}):\n")
        for line in str(e).splitlines():
            sys.stderr.write(f"fsw tape import: {line}\n")


def _dropped_late(tape) -> int:
    """The rows a converter dropped for a time not after the previous row's,
    as its `# derived: rows dropped: N with a time ...` header line counts them."""
    import re

    for d in tape.derived:
        m = re.match(r"rows dropped: (\d+) with a time not after", d)
        if m:
            return int(m.group(1))
    return 0


def show_text(tape, truth=None, truth_error: str | None = None) -> str:
    """What `fsw tape show` prints for `tape` (and its Truth, if any)."""
    import numpy as np

    out = [f"{tape.path}: fswkit sensor tape v1"]
    for s in tape.sources:
        out.append(f"  source:  {s}")
    if tape.flight:
        out.append(f"  flight:  {tape.flight}")
    for d in tape.derived:
        out.append(f"  derived: {d}")
    for n in tape.notes:
        out.append(f"  note:    {n}")
    out.append(f"  rows:    {tape.rows:,}, time {tape.start:.3f} to {tape.end:.3f} s (span {tape.span:.2f} s)")
    for col in ("pressure_pa", "accel_g"):
        have = tape.available(col)
        if not have.any():
            out.append(f"  {col + ':':12s} not available")
            continue
        t = tape.time[have]
        v = (tape.pressure if col == "pressure_pa" else tape.accel)[have]
        early, late = tape.rate_hz(col, t1=10.0), tape.rate_hz(col, t0=10.0)
        if early and late and abs(early - late) > 0.05 * max(early, late):
            rate = f"{early:.1f} Hz median to 10 s, {late:.1f} Hz after"
        else:
            rate = f"{tape.rate_hz(col):.1f} Hz median"
        n = int(have.sum())
        out.append(f"  {col + ':':12s} {n:,} value{'s' if n != 1 else ''}, {t[0]:.3f} to {t[-1]:.3f} s, {rate}, "
                   f"min {np.min(v):.4g}, max {np.max(v):.4g}")
    if tape.available("pressure_pa").any():
        alt = tape.altitude_agl()
        after = tape.time >= 0
        if (after & ~np.isnan(alt)).any():
            i = int(np.nanargmax(np.where(after, alt, np.nan)))
            out.append(f"  max ISA altitude {alt[i]:.1f} m above the pad ({tape.pad_pressure():.1f} Pa) "
                       f"at {tape.time[i]:.2f} s (unsmoothed)")
    if truth_error:
        out.append(f"  truth:   {truth_error}")
    elif truth is not None:
        out.append(f"  truth:   {truth.path}" + (f" ({truth.recorder})" if truth.recorder else ""))
        for k, v in truth.events():
            out.append(f"    {k:44s} {v:9.2f} s")
        for k in ("apogee_m_agl", "raw_max_alt_m_agl", "max_boost_accel_g", "max_accel_g", "pad_pressure_pa"):
            v = getattr(truth, k)
            if v is not None:
                out.append(f"    {k:44s} {v:9.1f}")
    return "\n".join(out) + "\n"


def cmd_show(args) -> int:
    from fswkit.tape import TapeError, read_tape, read_truth, truth_path

    if args.tape == "":
        sys.stderr.write("fsw tape show: TAPE: an empty string names nothing: give a path\n")
        return EXIT_CONFIG
    try:
        tape = read_tape(args.tape)
    except TapeError as e:
        return _fail("show", e)
    truth = err = None
    tp = truth_path(args.tape)
    if os.path.exists(tp):
        try:
            truth = read_truth(tp)
        except TapeError as e:
            err = str(e).splitlines()[0]
    sys.stdout.write(show_text(tape, truth, err))
    return EXIT_FAIL if err else EXIT_OK
