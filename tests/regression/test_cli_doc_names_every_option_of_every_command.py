"""docs/cli.md, "every command", did not name every option `fsw --help`
lists, nor list every option a synopsis line could take: the long forms
of the short options (`--output` of `-o`, `cmd`'s `--project`, `plot`'s
`--element`, `flash`'s `--verbose`) were nowhere, `fsw sim --run I`'s
synopsis left out the `--params` and `--board` that the study's rerun
command prints, and `fsw sim --plant` refused `--eeprom-file` with the pty
mode's options while the doc listed only four of them; "Where the commands
live" left out three of the command line's modules. A doc claim is a
test: every option of every command's parser is named in that command's
section of docs/cli.md, every option a synopsis line shows is one of the
command's, and every module of the command line is placed."""

from __future__ import annotations

import argparse
import re

import pytest

from conftest import ROOT, run_fsw

from fswkit.cli.main import parser

DOC = (ROOT / "docs" / "cli.md").read_text()
OPTION = re.compile(r"(?<![\w-])(--?[a-zA-Z][\w-]*)")
ALIASES = {"web": "ground"}  # `fsw web` is `fsw ground`'s older name, documented in its section


def _subparsers(p: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for a in p._actions:
        if isinstance(a, argparse._SubParsersAction):
            return dict(a.choices)
    return {}


def _options(p: argparse.ArgumentParser) -> set[str]:
    found = {s for a in p._actions for s in a.option_strings} - {"-h", "--help"}
    for sp in _subparsers(p).values():  # `fsw archive list|export`, `fsw tape import|show`
        found |= _options(sp)
    return found


def _section(command: str) -> str:
    m = re.search(rf"^## fsw {re.escape(command)}\n(.*?)(?=^## |\Z)", DOC, re.M | re.S)
    assert m, f"docs/cli.md has no section `## fsw {command}`"
    return m.group(1)


def _synopsis(section: str) -> str:
    """The section's first indented block: its synopsis lines."""
    m = re.search(r"^\n?((?: {4}.*\n)+)", section.lstrip("\n") + "\n")
    return m.group(1) if m else ""


COMMANDS = sorted(_subparsers(parser()).items())


def test_every_command_has_a_section():
    assert len(COMMANDS) >= 20
    missing = [n for n, _ in COMMANDS if not re.search(rf"^## fsw {ALIASES.get(n, n)}$", DOC, re.M)]
    assert missing == []


@pytest.mark.parametrize("name,sub", COMMANDS, ids=[n for n, _ in COMMANDS])
def test_every_option_the_parser_takes_is_named_in_its_section(name, sub):
    text = _section(ALIASES.get(name, name))
    named = set(OPTION.findall(text))
    assert sorted(_options(sub) - named) == []


@pytest.mark.parametrize("name,sub", COMMANDS, ids=[n for n, _ in COMMANDS])
def test_every_option_a_synopsis_shows_is_the_commands(name, sub):
    if name in ALIASES:
        return
    synopsis = _synopsis(_section(name))
    assert synopsis.lstrip().startswith(f"fsw {name}"), synopsis
    assert sorted(set(OPTION.findall(synopsis)) - _options(sub)) == []


def test_the_study_rerun_synopsis_takes_what_a_study_prints_for_it():
    entries = re.split(r"\n(?=    fsw )", _synopsis(_section("sim")))  # one entry: its line and continuations
    entry = next(e for e in entries if "--run I" in e)
    for opt in ("--params", "--board", "--dispersion", "--seed", "--out"):
        assert opt in entry, opt


@pytest.mark.parametrize("option", ["--duration 1", "--fast", "--analog A0=1", "--link x", "--eeprom-file x"])
def test_the_pty_options_the_doc_says_plant_refuses_are_refused(tmp_path, option):
    listed = re.search(r"((?:`--[\w-]+`(?:,\s|\sand\s)?)+)\s+belong\s+to\s+the\s+pty\s+mode\s+and\s+are\s+refused\s+with\s+`--plant`",
                       _section("sim"))
    assert listed and f"`{option.split()[0]}`" in listed.group(1)
    opt, *value = option.split()
    r = run_fsw("sim", str(ROOT / "examples" / "tank"), "--plant", "tank", "--out", str(tmp_path / "f"), opt,
                *[str(tmp_path / v) if opt in ("--link", "--eeprom-file") else v for v in value])
    assert r.code == 2, r.err
    assert f"{opt} is for the free-running board on a pty" in r.err


def test_where_the_commands_live_names_every_module_of_the_cli():
    """The section left out `machine.py`, `sim_study.py` and `common.py`,
    and gave `web.py` only `fsw web`."""
    section = _section_any("## Where the commands live")
    modules = sorted(p.name for p in (ROOT / "host-tools" / "fswkit" / "cli").glob("*.py")
                     if p.name not in ("__init__.py", "__main__.py", "main.py"))
    assert [m for m in modules if f"`{m}`" not in section] == []
    assert re.search(r"`web\.py` \(`ground`", section)


def _section_any(heading: str) -> str:
    return DOC.split(heading + "\n", 1)[1].split("\n## ", 1)[0]
