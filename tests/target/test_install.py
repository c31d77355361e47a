"""A non-editable install works: the wheel carries the kit's own files (the
firmware runtime, the board definitions, the build's makefile, the
simulated board's harness), and the installed `fsw` builds a project and
flies it in closed loop from a folder outside the source tree, with every
kit file taken from the installed package and nothing written into it.

Offline: the wheel is built without build isolation (setuptools from the
test extras, `make setup`) and installed with --no-index into a fresh venv,
whose dependencies (numpy, pyserial, ...) come from this venv through a
path file."""

from __future__ import annotations

import hashlib
import os
import shutil
import site
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT
from support.held import fresh_folder

pytestmark = [pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed"), pytest.mark.costly(9)]
SIMAVR = os.path.exists("/usr/include/simavr/sim_avr.h")
SOURCES = ("pyproject.toml", "README.md", "host-tools", "autocode", "firmware", "boards", "mk", "integrations")


def _run(cmd, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=240, **kw)


def _files(folder: Path) -> set[str]:
    """Every file under the installed package but Python's byte code."""
    return {str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file() and "__pycache__" not in p.parts}


def _venv_place() -> Path:
    """Where the installed kit's venv is made, outside the source tree: one
    folder per tree and user in the system's temporary folder, made again
    in each run. The installed runtime's folder is then the same from run
    to run, and so is the kit's cache entry of the board's archives (keyed
    by that folder too: their debug information names it): the first run
    compiles the runtime there, later ones link it, as a user's second
    build does (about 5 s of CPU a run, and no new 1.7 MB entry in the
    user's cache each run)."""
    tag = hashlib.sha1(str(ROOT).encode()).hexdigest()[:10]
    return Path(tempfile.gettempdir()) / f"fswkit-install-test-{os.getuid()}-{tag}"


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """A fresh venv with the kit installed from its wheel; its `bin` folder.
    The venv's place is held while the module runs (another test run of
    this tree waits for it)."""
    with fresh_folder(_venv_place()) as place:
        yield _install(tmp_path_factory, place)


def _install(tmp_path_factory, place: Path) -> Path:
    tmp = tmp_path_factory.mktemp("install")
    src = tmp / "src"  # a copy: the wheel's build writes build/ and *.egg-info beside its sources
    src.mkdir()
    for name in SOURCES:
        if (ROOT / name).is_dir():
            shutil.copytree(ROOT / name, src / name, ignore=shutil.ignore_patterns("__pycache__", "build"))
        else:
            shutil.copy2(ROOT / name, src / name)
    r = _run([sys.executable, "-m", "pip", "wheel", src, "--no-deps", "--no-build-isolation", "--no-index",
              "-w", tmp / "wheel"])
    assert r.returncode == 0, ("the wheel did not build (setuptools>=77 comes with the test extras: "
                               "`make setup`):\n" + r.stdout[-2000:] + r.stderr[-3000:])
    wheel = next((tmp / "wheel").glob("fswkit-*.whl"))
    venv = place / "venv"
    r = _run([sys.executable, "-m", "venv", "--without-pip", venv])
    assert r.returncode == 0, r.stderr
    r = _run([sys.executable, "-m", "pip", "--python", venv / "bin" / "python", "install", "--no-deps", "--no-index",
              "--no-compile", wheel])
    assert r.returncode == 0, r.stdout + r.stderr
    py = venv / "bin" / "python"
    purelib = Path(_run([py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]).stdout.strip())
    deps = sorted({sysconfig.get_paths()["purelib"], *site.getsitepackages()})
    (purelib / "zz_fswkit_test_deps.pth").write_text("\n".join(deps) + "\n")  # after the venv's own
    return venv


def _env(venv: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env["PATH"] = f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    return env


def test_the_installed_kit_finds_its_files_in_the_package(installed):
    r = _run([installed / "bin" / "python", "-c",
              "import fswkit, fswkit.cli, fswkit.autocode.kit as k, fswkit.sim.board as b\n"
              "print(fswkit.__file__, fswkit.cli.__file__, k.ROOT, k.RUNTIME, k.BOARDS, k.BUILD_MK, b.HARNESS_SRC,"
              " sep='\\n')"], env=_env(installed), cwd=installed)
    assert r.returncode == 0, r.stderr
    package = (installed / "lib").resolve()
    paths = [Path(p).resolve() for p in r.stdout.split()]
    assert len(paths) == 7
    for p in paths:
        assert package in p.parents and ROOT not in p.parents, p
        assert p.exists(), p
    runtime, boards = paths[3], paths[4]
    assert (runtime / "fswkit.h").is_file() and (runtime / "fsw_executor.cpp").is_file()
    assert (boards / "uno.toml").is_file() and (boards / "native.toml").is_file()


def test_the_installed_fsw_builds_and_flies_outside_the_tree(installed, tmp_path):
    site_pkg = next((installed / "lib").glob("python*/site-packages/fswkit"))
    before = _files(site_pkg)
    work = tmp_path / "work"
    shutil.copytree(EXAMPLES / "rocket", work / "rocket", ignore=shutil.ignore_patterns("build"))
    fsw = installed / "bin" / "fsw"

    # into the project's build folder, where `fsw sim` below finds it built
    out = work / "rocket" / "build" / "uno"
    r = _run([fsw, "build", "rocket"], env=_env(installed), cwd=work)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "fsw build: rocket.app for uno (atmega328p)" in r.stdout
    assert (out / "rocket.hex").is_file()
    assert str(site_pkg / "mk" / "build.mk") in (out / "build.log").read_text()
    assert str(ROOT) not in (out / "build.log").read_text()

    if SIMAVR:
        flight = tmp_path / "flight"
        r = _run([fsw, "sim", "rocket", "--plant", "rocket", "--seed", "1", "--out", flight],
                 env=_env(installed), cwd=work)
        assert r.returncode == 0, r.stdout + r.stderr
        assert "checks passed" in r.stdout and (flight / "summary.txt").is_file()
    assert _files(site_pkg) == before  # builds and caches went elsewhere


def test_an_installed_fsw_new_writes_a_platformio_ini_whose_kit_files_exist(installed, tmp_path):
    """`fsw new` names the kit's PlatformIO hook and the runtime as an
    Arduino library in platformio.ini: an installed kit carries both."""
    r = _run([installed / "bin" / "fsw", "new", "rig", "--board", "uno"], env=_env(installed), cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    ini = (tmp_path / "rig" / "platformio.ini").read_text()
    kit = Path(next(line.split("=", 1)[1].strip() for line in ini.splitlines() if line.startswith("kit =")))
    assert (installed / "lib").resolve() in kit.resolve().parents
    assert "${fswkit.kit}/integrations/platformio/pio_hook.py" in ini
    assert "symlink://${fswkit.kit}/firmware" in ini
    hook = kit / "integrations" / "platformio" / "pio_hook.py"
    assert hook.is_file(), hook
    assert 'Import("env")' in hook.read_text()
    for name in ("library.json", "library.properties", "src/fswkit.h"):
        assert (kit / "firmware" / name).is_file(), name
