"""README.md's Layout named the rooms, test folders and examples of an
older tree: `host-tools/fswkit/`'s `param/`, `recorder/`, `reload/` and
`web/`, a third of `tests/`'s folders and two of the five examples
(`stand`, `hpr_digital`) were missing; its Documentation list left out
docs/safety.md, sensors.md and sensor-table.md. A doc claim is a test:
every room, every test folder and every example is named in its row, and
every doc in the list."""

from __future__ import annotations

import re

from conftest import ROOT

README = (ROOT / "README.md").read_text()


def _row(folder: str) -> str:
    m = re.search(rf"^\| `{re.escape(folder)}` \|(.*)\|$", README, re.M)
    assert m, f"README.md's Layout has no row for `{folder}`"
    return m.group(1)


def _folders(path):
    return sorted(p.name for p in path.iterdir() if p.is_dir() and not p.name.startswith((".", "_")))


def test_every_room_of_the_host_tools_is_named():
    row = _row("host-tools/fswkit/")
    assert [d for d in _folders(ROOT / "host-tools" / "fswkit") if f"`{d}/`" not in row] == []


def test_every_test_folder_is_named():
    row = _row("tests/")
    named = set(re.findall(r"`(\w+)/`", row)) | set(re.findall(r"`autocode/\{([\w,]+)\}`", row)[0].split(",")) \
        | {"autocode"}
    assert [d for d in _folders(ROOT / "tests") if d not in named] == []
    autocode = set(re.findall(r"`autocode/\{([\w,]+)\}`", row)[0].split(","))
    assert [d for d in _folders(ROOT / "tests" / "autocode") if d not in autocode] == []


def test_every_example_is_named():
    row = _row("examples/")
    assert [d for d in _folders(ROOT / "examples") if f"`{d}`" not in row] == []


def test_the_documentation_list_names_every_doc():
    """docs/safety.md, sensors.md and sensor-table.md were missing from it
    (platformio.md and arduino-cli.md only point to integrations/, which the
    README links itself)."""
    section = README.split("## Documentation", 1)[1].split("\n## ", 1)[0]
    moved = {p.name for p in (ROOT / "docs").glob("*.md") if "Moved to [" in p.read_text()[:400]}
    assert moved == {"platformio.md", "arduino-cli.md"}
    assert "integrations/platformio/" in README and "integrations/arduino-cli/" in README
    assert [p.name for p in sorted((ROOT / "docs").glob("*.md"))
            if p.name not in moved and f"(docs/{p.name})" not in section] == []
