"""A machine keeps its file's stem as its C++ namespace in `fsw_gen` unless
the generated code uses that name (autocode/cnames.py TAKEN). The list was
drawn from an application without the optional sections: `fsw check`
accepted a stand whose reloadable machine is `reload.sm`, a rocket's
`params.sm`, `rec.sm`, `resume.sm` or `time_base.sm`, and a digital
rocket's `sensor_health.sm`, and their C++ did not compile
(`reference to 'reload' is ambiguous`). Every name the application's
generated file declares at its top level ([reload], [log], parameters,
resume, sensor tables) is now taken, and those projects build."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from conftest import EXAMPLES
from support import cxx

from fswkit.autocode.app import load_app
from fswkit.autocode.board import load_board
from fswkit.autocode.cnames import machine_ident
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.app import emit_app

# a lowercase name declared at the top level of the generated file (a
# variable, an array, a function): the line starts at column 0
DECL = re.compile(r"^(?![\s#/}])[^\n]*?\b([a-z][a-z0-9_]*)\s*(?:\[[^\]\n]*\])?\s*(?:\(|;|=|\{)", re.M)
APPS = ("stand/stand.app", "rocket/rocket.app", "hpr/hpr.app", "hpr_digital/hpr_digital.app", "tank/tank.app")


@pytest.mark.parametrize("app", APPS)
def test_no_machine_keeps_a_name_the_application_code_declares(app):
    a = load_app(str(EXAMPLES / app), Diagnostics(), board_override="native")
    assert a is not None
    code = re.sub(r"//[^\n]*", "", emit_app(a)["app.gen.cpp"])  # a comment's words declare nothing
    declared = set(DECL.findall(code))
    kept = sorted(n for n in declared if machine_ident(n) == n)
    assert kept == []


def _renamed(tmp: Path, app: str, machine: str, name: str) -> Path:
    """A copy of the example `app` whose machine `machine` is `name.sm`."""
    src = EXAMPLES / app
    dst = tmp / src.parent.name
    shutil.copytree(src.parent, dst, ignore=shutil.ignore_patterns("build"))
    text = (dst / src.name).read_text().replace("../", f"{EXAMPLES}/")
    path = next(Path(line.split()[1]) for line in text.splitlines()
                if line.startswith("machine ") and line.split()[1].endswith(f"{machine}.sm"))
    shutil.copy(path if path.is_absolute() else dst / path, dst / f"{name}.sm")
    text = text.replace(f" {path}\n", f" {name}.sm\n")
    text = re.sub(rf"(\bmachine\s+){machine}\b(?!\.)", rf"\g<1>{name}", text)
    (dst / src.name).write_text(text)
    return dst / src.name


def test_projects_with_those_machine_names_build(tmp_path):
    cpp = []
    for app, machine, name in (("stand/stand.app", "tank", "reload"), ("rocket/rocket.app", "nav", "time_base"),
                               ("rocket/rocket.app", "nav", "params"),
                               ("hpr_digital/hpr_digital.app", "nav", "sensor_health")):
        d = Diagnostics()
        a = load_app(str(_renamed(tmp_path / name, app, machine, name)), d, board_override="native")
        assert a is not None, d.render()
        assert name in [m.name for m in a.machines]
        cpp += cxx.write(emit_app(a), str(tmp_path / "cxx" / name))
    r = cxx.compile_each(load_board("native"), cpp)
    assert r.returncode == 0, r.stderr[-3000:]
