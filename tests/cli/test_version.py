"""One version number: autocode/version.py, and every manifest and
header that carries it (mk/firmware.mk's fw-check-version checks the first
two with sed; this checks them all)."""

from __future__ import annotations

import json
import re

from conftest import ROOT
from fswkit.autocode.version import __version__


def test_version_py_is_a_plain_version():
    assert re.fullmatch(r"\d+\.\d+\.\d+", __version__)


def test_library_properties_for_arduino_cli():
    props = dict(line.split("=", 1) for line in (ROOT / "firmware" / "library.properties").read_text().splitlines()
                 if "=" in line)
    assert props["version"] == __version__
    assert props["name"] == "fswkit"
    assert props["dot_a_linkage"] == "true"


def test_library_json_for_platformio():
    manifest = json.loads((ROOT / "firmware" / "library.json").read_text())
    assert manifest["version"] == __version__
    assert manifest["name"] == "fswkit"
    assert manifest["build"]["libArchive"] is True  # as dot_a_linkage=true
    assert manifest["frameworks"] == "*" and manifest["platforms"] == "*"  # native too


def test_runtime_header_handshake():
    text = (ROOT / "firmware" / "src" / "fsw_version.h").read_text()
    string = re.search(r'#define FSW_RUNTIME_VERSION_STRING "(.*)"', text).group(1)
    parts = [re.search(rf"#define FSW_RUNTIME_VERSION_{p} (\d+)", text).group(1) for p in ("MAJOR", "MINOR", "PATCH")]
    assert string == ".".join(parts) == __version__
