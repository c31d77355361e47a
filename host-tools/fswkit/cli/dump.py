"""`fsw dump PROJECT --port P [--flight N | --all] -o DIR [--erase]`: a
target's flight record over the link, each flight written as a link log
(docs/recorder.md)."""

from __future__ import annotations

import os
import sys

from fswkit.cli.common import EXIT_CONFIG, EXIT_FAIL, EXIT_OK


def _say(msg: str) -> None:
    sys.stderr.write(f"fsw dump: {msg}\n")


def _lost(n: int, before: int | None, after: int | None) -> str:
    """A flight's records missing from the sequence, in words."""
    what = f", {n} record{'' if n == 1 else 's'} lost"
    if before is not None and after is not None:
        return f"{what} between {before / 1000:.2f} s and {after / 1000:.2f} s (samples missing)"
    if before is None:
        return f"{what} before {after / 1000:.2f} s"
    return f"{what} after {before / 1000:.2f} s"


def _file_names(flights) -> dict[int, str]:
    """Each flight's file name by id(): `flight-N.log`; a number the store
    holds more than once (numbers go 1..255, then 1 again) `flight-N.log`,
    `flight-N-2.log`, ... oldest first, so a flight has the same name
    whichever flights a dump writes."""
    seen: dict[int, int] = {}
    out = {}
    for f in flights:  # oldest first
        k = seen[f.number] = seen.get(f.number, 0) + 1
        out[id(f)] = f"flight-{f.number}.log" if k == 1 else f"flight-{f.number}-{k}.log"
    return out


def cmd_dump(args) -> int:
    from fswkit.autocode.recorder import plan
    from fswkit.cli.common import load_app

    app = load_app(args.project, None, "dump")
    if app is None:
        return EXIT_CONFIG
    p = plan(app)
    if p is None:
        _say(f"{args.project}: the application has no flight recorder (a [log] section, docs/recorder.md)")
        return EXIT_CONFIG
    if args.flight is not None and args.all:
        _say("--flight N and --all: choose one")
        return EXIT_CONFIG
    if os.path.exists(args.output) and not os.path.isdir(args.output):
        _say(f"{args.output} is not a folder")
        return EXIT_CONFIG
    return _talk(args, app, p)


def _talk(args, app, p) -> int:
    from fswkit.autocode.recorder import RecordError, decode
    from fswkit.autocode.schema import link_plan
    from fswkit.autocode.protocol import OP_LOG_ERASE
    from fswkit.cli.common import config_paths, talk_on_link
    from fswkit.link.client import LinkTimeout
    from fswkit.link.layout import from_app
    from fswkit.link.log import LogError
    from fswkit.outputs import OutputError, check, is_direct, recording
    from fswkit.progress import progress
    from fswkit.recorder.dump import DumpError, query_info, read_image, slots_read, write_flight

    def talk(ground) -> int:
        def command(op, a):
            return ground.command(op, a, tries=5, timeout=0.5)

        try:
            inf = query_info(command)
            if (inf["hash"], inf["slots"], inf["record"]) != (p.hash, p.slots, p.record):
                _say(f"the target's recorder (log hash {inf['hash']:08x}, {inf['slots']} records of "
                     f"{inf['record']} B) is not this project's ({p.hash:08x}, {p.slots} of {p.record} B): "
                     "dump with the project the firmware was built from")
                return EXIT_FAIL
            print(f"recorder: {inf['mode_name']}, flight {inf['flight']}, {inf['slots']} records of "
                  f"{inf['record']} B, next {inf['head']}; {inf['dropped']} samples dropped")
            with progress("reading records", total=slots_read(p, inf["head"]),
                          unit="records") as bar:  # minutes on a large chip
                image = read_image(command, p, link_plan(app).tx_cap, head=inf["head"], progress=bar.update)
            after = query_info(command)  # what the target did while it was read
        except (DumpError, LinkTimeout) as e:
            _say(str(e))
            return EXIT_FAIL
        try:
            flights, empty = decode(p, image)
        except RecordError as e:
            _say(f"{e}: the records were not written by this project's firmware")
            return EXIT_FAIL
        print(f"{len(flights)} flight(s) in {p.slots - empty} record(s); {empty} record(s) empty or torn")
        written = (after["seq"] - inf["seq"]) & 0xFFFF
        if written:  # read slot by slot: a record in a slot read before it was written is not in the image
            _say(f"{written} record{' was' if written == 1 else 's were'} written while the records were read "
                 "(those in slots already read are not in this dump): dump again once the flight has ended")
        still = after["mode"] == 1 and flights and flights[-1].number == after["flight"]
        if after["mode"] == 1 and not still:
            _say(f"flight {after['flight']} is being recorded and none of its records is written yet: it is not in "
                 "this dump; dump again once it has ended")
        chosen = flights
        if args.flight is not None:
            chosen = [f for f in flights if f.number == args.flight]
            if not chosen:
                _say(f"no flight {args.flight} in the record (flights: "
                     f"{', '.join(str(f.number) for f in flights) or 'none'})")
                return EXIT_FAIL
        elif not args.all and flights:
            chosen = flights[-1:]  # the newest
        skipped = [f for f in chosen if f.foreign is not None]
        for f in skipped:  # never decoded with this project's layout: its numbers would be wrong
            _say(f"flight {f.number} was recorded with another [log] (log hash {f.foreign:08x}; this project's is "
                 f"{p.hash:08x}): not decoded, not written; dump it with the project of the firmware that "
                 "recorded it (docs/recorder.md)")
        chosen = [f for f in chosen if f.foreign is None]
        try:  # its own words: an OSError here would be taken for the port going away
            os.makedirs(args.output, exist_ok=True)
        except OSError as e:
            from fswkit.outputs import not_a_folder

            _say(f"cannot create the folder {args.output}: {not_a_folder(args.output) or e.strerror or e}")
            return EXIT_FAIL
        names = _file_names(flights)
        paths = {id(f): os.path.join(args.output, names[id(f)]) for f in chosen}
        try:  # every file before the first is written: a flight log replaces only a flight log, with --force
            for path in paths.values():
                check(path, config_paths(app) + [args.port], force=args.force, log=True, ask=True,
                      what="flight log")
                if os.path.lexists(path) and not is_direct(path) and recording(path) != "a link log":
                    raise OutputError(f"{path} is there and is not a flight log: it is never replaced, even with "
                                      "--force; move it away, or dump into another folder")
        except OutputError as e:
            _say(str(e))
            return EXIT_FAIL
        for f in chosen:
            path = paths[id(f)]
            try:
                n = write_flight(path, app, p, f, force=args.force)
            except LogError as e:
                _say(str(e))
                return EXIT_FAIL
            s = f.samples
            span = f"{s[0][0] / 1000:.2f}–{s[-1][0] / 1000:.2f} s" if s else "no samples"
            trig = f", trigger at {f.start.t0 / 1000:.2f} s" if f.start else ", its start record overwritten"
            if f.start is None and any(a is None for _, a, _ in f.lost):
                trig = ", its start record lost"
            trig += "".join(f", resumed after a reset in flight at {r.t0 / 1000:.2f} s" for r in f.resumed)
            trig += "".join(_lost(k, a, b) for k, a, b in f.lost)
            if still and f is flights[-1]:
                trig += ", still being recorded (dump again once it has ended)"
            print(f"flight {f.number}: {n} samples, {span}{trig} -> {path}")
        if args.erase:
            kept = {id(f) for f in chosen}
            left = [f.number for f in flights if id(f) not in kept]
            if left:  # nothing recorded is erased before it is dumped
                how = ("add --all" if not skipped else
                       "dump the flights of another [log] with their own project first")
                _say(f"--erase erases every flight on the target, and flight(s) {', '.join(map(str, left))} "
                     f"were not dumped: {how}; nothing erased")
                return EXIT_FAIL
            if not args.yes:
                if not sys.stdin.isatty():
                    _say("--erase asks for a confirmation: add --yes when no one is at the terminal")
                    return EXIT_FAIL
                try:
                    answer = input(f"erase every record on the target ({len(flights)} flight(s), dumped above)? "
                                   "type `erase`: ")
                except EOFError:  # Ctrl-D: no answer is no
                    answer = ""
                    print()
                if answer.strip() != "erase":
                    print("not erased")
                    return EXIT_OK
            try:
                now = query_info(command)
            except DumpError as e:
                _say(f"{e}; nothing erased")
                return EXIT_FAIL
            allowed = [n for i, n in enumerate(p.states) if p.erase_ok[i + 1]]
            if now["mode"] == 1:  # the target would refuse; and a flight that ended now would go undumped
                _say(f"not erased: the target is recording flight {now['flight']} (erasing is allowed in "
                     f"{', '.join(allowed)}, and never while a flight is recorded)")
                return EXIT_FAIL
            if written or now["seq"] != inf["seq"]:  # nothing recorded is erased before it is dumped
                _say("the target wrote records since this dump began reading them: they are not in it; "
                     "dump again, then erase; nothing erased")
                return EXIT_FAIL
            ack = command(OP_LOG_ERASE, b"")
            if ack["status"] != 0:
                _say(f"the target refused to erase: {ack['reason']} (erasing is allowed in "
                     f"{', '.join(allowed)}, and never while a flight is recorded)")
                return EXIT_FAIL
            print("erasing the record on the target")
        return EXIT_FAIL if skipped else EXIT_OK

    return talk_on_link(args, from_app(app), args.baud or app.baud, _say, talk, (LinkTimeout,))
