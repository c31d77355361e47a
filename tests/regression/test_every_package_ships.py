"""A new room of the kit (fswkit.recorder) was not in pyproject.toml's
package list: the editable install found it, an installed `fsw sim` did
not (ModuleNotFoundError). Every package folder under host-tools/fswkit and
autocode must be listed."""

from __future__ import annotations

import tomllib

from conftest import ROOT


def test_every_package_folder_is_in_the_package_list():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(cfg["packages"])
    found = set()
    for base, name in ((ROOT / "host-tools" / "fswkit", "fswkit"), (ROOT / "autocode", "fswkit.autocode")):
        for init in base.rglob("__init__.py"):
            rel = init.parent.relative_to(base)
            found.add(".".join((name,) + rel.parts))
    missing = sorted(found - listed)
    assert missing == [], f"packages not in pyproject.toml: {missing}"
