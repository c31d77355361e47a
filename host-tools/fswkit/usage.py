"""Bad input on the command line, found by a command's own checks rather
than by argparse: a name the project (or the log read) does not have, given
as an element, a task or a parameter. Every `fsw` command refuses it the
same way, before any port is opened or any output written: `OPTION: unknown
KIND `NAME` (did you mean `CLOSE`?): THE PROJECT'S KINDs are ...`, exit 2
(docs/cli.md, "Exit statuses shared by all commands"). A name the target
refuses over the link is the target's answer, not this."""

from __future__ import annotations

import difflib


class UsageError(ValueError):
    """A wrong command line found after parsing it: its message says what
    and how to put it right; the command exits with status 2."""


def unknown_name(kind: str, names, known, whose: str = "the project's") -> str:
    """The message for `names` (one or several) that are not among `known`,
    the `kind` of thing they were to name (element, task, parameter): the
    closest known name when there is one, and every known one."""
    names, known = list(names), list(known)
    hint = ""
    if len(names) == 1:
        close = difflib.get_close_matches(names[0], known, n=1)
        hint = f" (did you mean `{close[0]}`?)" if close else ""
    listed = ", ".join(known) if known else "none"
    return (f"unknown {kind}{'s' if len(names) > 1 else ''} {', '.join(f'`{n}`' for n in names)}{hint}: "
            f"{whose} {kind}s are {listed}")
