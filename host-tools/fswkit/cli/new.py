"""`fsw new`: a new project that builds as it stands (fswkit.new.project)."""

from __future__ import annotations


def cmd_new(args) -> int:
    from fswkit.new.project import main as new_main

    return new_main(args)
