"""Claims the docs and the runtime's comments made about the tree were
false: `fsw_version.h` named a checking script that does not exist,
docs/runtime.md cited `examples/tank/expected.md` (it lives beside the
project, in ../shared), and `fsw_config.h` said it held every knob of the
runtime while two lived in `fsw_link.h`. A doc claim is a test: every path
the docs and the runtime cite exists, and every `#ifndef FSW_...` default
is in fsw_config.h."""

from __future__ import annotations

import re

from conftest import ROOT

CITING = sorted([*ROOT.glob("docs/*.md"), ROOT / "README.md", *ROOT.glob("integrations/*/README.md"),
                 *ROOT.glob("firmware/src/*.h"), *ROOT.glob("firmware/src/*.cpp")])
PATH = re.compile(r"(?<![\w./-])((?:[\w.-]+/)+[\w.-]+\.(?:py|c|cpp|h|md|sh|mk|toml|ini|sm|sv|ss|app|aio|dio|png))\b")
# Paths that name a family, not a file (`test_X.cpp`: one per suite), or a
# folder made by a build.
PLACEHOLDER = re.compile(r"(^|/)build/|_X\b|\bNAME\b|\bPROJECT\b|\bDIR\b|^\.\./|^~/|^/")
SYSTEM = ("avr/", "util/")  # avr-libc's headers


def cited_paths():
    for doc in CITING:
        for lineno, line in enumerate(doc.read_text().splitlines(), 1):
            for m in PATH.finditer(line):
                if not PLACEHOLDER.search(m.group(1)) and not m.group(1).startswith(SYSTEM):
                    yield doc, lineno, m.group(1)


def _exists(doc, path: str) -> bool:
    return any((base / path).exists() for base in (ROOT, doc.parent, ROOT / "firmware" / "src"))


def test_every_path_the_docs_and_the_runtime_cite_exists():
    seen = list(cited_paths())
    assert len(seen) > 50  # the scan finds citations
    missing = [f"{doc.relative_to(ROOT)}:{n}: {p}" for doc, n, p in seen if not _exists(doc, p)]
    assert missing == []


def test_every_runtime_knob_has_its_default_in_fsw_config_h():
    knob = re.compile(r"^#\s*ifndef\s+(FSW_\w+)\s*$", re.M)
    config = (ROOT / "firmware" / "src" / "fsw_config.h").read_text()
    assert len(knob.findall(config)) >= 10
    elsewhere = [f"{h.name}: {k}" for h in sorted((ROOT / "firmware" / "src").glob("*.h")) if h.name != "fsw_config.h"
                 for k in knob.findall(h.read_text()) if not k.endswith("_H")]
    assert elsewhere == []
