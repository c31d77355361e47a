"""integrations/platformio/pio_hook.py run the way PlatformIO runs it: SCons executes the file
with `Import`, `COMMAND_LINE_TARGETS` and the build environment in its
globals (and no `__file__`). The hook regenerates the project's C++ before
every build and stops a build on a broken config with its located
diagnostic."""

from __future__ import annotations

import os
import shutil
import stat
import subprocess

import pytest

from conftest import EXAMPLES, ROOT

HOOK = ROOT / "integrations" / "platformio" / "pio_hook.py"
# what the hook adds to every atmelavr build: the link's sections, as mk/build.mk links
SECTIONS = {"LINKFLAGS": ["-ffunction-sections", "-fdata-sections"]}
TANK = EXAMPLES / "tank"


class Exited(Exception):
    def __init__(self, code):
        super().__init__(code)
        self.code = code


class FakePlatform:
    def __init__(self, name, packages=None):
        self.name = name
        self.packages = packages or {}

    def get_package_dir(self, name):
        return self.packages.get(name)


class FakeEnv:
    """The parts of PlatformIO's SCons environment the hook uses."""

    def __init__(self, project_dir, src_dir, pioenv, options, board=None, platform=None, build_type="release",
                 clean=False):
        self.vars = {"PROJECT_DIR": str(project_dir), "PROJECT_SRC_DIR": str(src_dir), "PIOENV": pioenv,
                     "BUILD_TYPE": build_type}
        if board:
            self.vars["BOARD"] = board
        self.options = options
        self.platform = platform or FakePlatform("atmelavr")
        self.clean = clean
        self.appended = []

    def __getitem__(self, key):
        return self.vars[key]

    def __contains__(self, key):
        return key in self.vars

    def get(self, key, default=None):
        return self.vars.get(key, default)

    def subst(self, text):
        for k, v in self.vars.items():
            text = text.replace("$" + k, v)
        return text

    def GetProjectOption(self, name, default=None):
        return self.options.get(name, default)

    def PioPlatform(self):
        return self.platform

    def IsCleanTarget(self):
        return self.clean

    def Append(self, **kw):
        self.appended.append(kw)

    def Exit(self, code):
        raise Exited(code)


def run_hook(env, targets=()):
    """Executes the hook as SCons executes an SConscript: compiled with its
    path as the file name, `__file__` absent, SCons's names in globals."""
    code = compile(HOOK.read_text(), str(HOOK), "exec")
    globs = {"__name__": "SCons.Script", "Import": lambda *names: None, "env": env,
             "COMMAND_LINE_TARGETS": list(targets)}
    exec(code, globs)
    return globs


def uno_env(tmp_path, project, **over):
    options = {"custom_fsw_project": project, "custom_fsw_board": "uno"}
    options.update(over.pop("options", {}))
    return FakeEnv(ROOT, tmp_path / "src", "uno", options, board="uno",
                   platform=over.pop("platform", FakePlatform("atmelavr")), **over)


def test_hook_regenerates_the_code_fsw_gen_makes(fsw, tmp_path):
    env = uno_env(tmp_path, "examples/tank")
    run_hook(env)
    out = tmp_path / "src" / "uno"
    ref = tmp_path / "ref"
    assert fsw("gen", str(TANK), "--board", "uno", "--out", str(ref)).code == 0
    names = sorted(p.name for p in ref.iterdir())
    assert sorted(p.name for p in out.iterdir()) == names
    for n in names:
        assert (out / n).read_bytes() == (ref / n).read_bytes(), n


def test_every_build_compiles_fresh_code(tmp_path):
    env = uno_env(tmp_path, "examples/tank")
    run_hook(env)
    app = tmp_path / "src" / "uno" / "app.gen.cpp"
    good = app.read_text()
    app.write_text("// edited by hand: the next build must not compile this\n")
    (tmp_path / "src" / "uno" / "stale.gen.cpp").write_text("int stale;\n")
    run_hook(env)
    assert app.read_text() == good
    assert not (tmp_path / "src" / "uno" / "stale.gen.cpp").exists()


def test_broken_config_stops_the_build_with_the_located_diagnostic(tmp_path, capfd):
    project = tmp_path / "tank"
    shutil.copytree(TANK, project, ignore=shutil.ignore_patterns("build"))
    sm = project / "tank.sm"
    sm.write_text(sm.read_text().replace("        valveOpen = true\n", "        valveOpne = true\n", 1))
    env = FakeEnv(tmp_path, tmp_path / "src", "uno", {"custom_fsw_project": "tank", "custom_fsw_board": "uno"},
                  board="uno")
    with pytest.raises(Exited) as e:
        run_hook(env)
    assert e.value.code == 1
    err = capfd.readouterr().err
    assert "state machine config error @ tank/tank.sm:18:9:" in err
    assert "|         valveOpne = true\n" in err and "^ unknown element `valveOpne`" in err
    assert "fswkit: `fsw gen` failed for environment `uno`" in err
    assert "Traceback" not in err
    assert not (tmp_path / "src" / "uno" / "app.gen.cpp").exists()


def test_board_that_is_not_the_environments_stops_the_build(tmp_path, capfd):
    env = uno_env(tmp_path, "examples/tank", options={"custom_fsw_board": "mega2560"})
    with pytest.raises(Exited):
        run_hook(env)
    err = capfd.readouterr().err
    assert "environment `uno` builds for board `uno`, but fswkit board `mega2560` is PlatformIO's " \
           "`megaatmega2560`: set custom_fsw_board" in err


def test_unknown_board_stops_the_build(tmp_path, capfd):
    env = uno_env(tmp_path, "examples/tank", options={"custom_fsw_board": "pdp11"})
    with pytest.raises(Exited):
        run_hook(env)
    assert "fswkit: unknown board `pdp11` (known boards:" in capfd.readouterr().err


def test_native_environment_generates_for_the_host(tmp_path):
    env = FakeEnv(ROOT, tmp_path / "src", "native", {"custom_fsw_project": "examples/tank",
                                                      "custom_fsw_board": "native"},
                  platform=FakePlatform("native"))
    run_hook(env)
    app = (tmp_path / "src" / "native" / "app.gen.cpp").read_text()
    assert "static_assert(sizeof(fsw::Real) == 8" in app and "// Board `native`" in app
    assert env.appended == []  # no toolchain probe off AVR


def test_test_builds_and_clean_do_not_generate(tmp_path):
    env = uno_env(tmp_path, "examples/tank", build_type="test")
    run_hook(env)
    assert not (tmp_path / "src").exists()
    env = uno_env(tmp_path, "examples/tank", clean=True)
    run_hook(env)
    assert not (tmp_path / "src").exists()


def _toolchain(tmp_path, script):
    bindir = tmp_path / "toolchain" / "bin"
    bindir.mkdir(parents=True)
    cxx = bindir / "avr-g++"
    cxx.write_text(script)
    cxx.chmod(cxx.stat().st_mode | stat.S_IEXEC)
    return str(tmp_path / "toolchain")


def test_decimal_dig_is_defined_only_where_the_toolchain_lacks_it(tmp_path):
    lacks = _toolchain(tmp_path / "a", "#!/bin/sh\ncat >/dev/null\necho '#define FLT_DIG 6'\n")
    has = _toolchain(tmp_path / "b", "#!/bin/sh\ncat >/dev/null\necho '#define DECIMAL_DIG 17'\n")
    env = uno_env(tmp_path, "examples/tank", platform=FakePlatform("atmelavr", {"toolchain-atmelavr": lacks}))
    run_hook(env)
    assert env.appended == [SECTIONS, {"CPPDEFINES": [("DECIMAL_DIG", "__DECIMAL_DIG__")]}]
    env = uno_env(tmp_path, "examples/tank", platform=FakePlatform("atmelavr", {"toolchain-atmelavr": has}))
    run_hook(env)
    assert env.appended == [SECTIONS]  # no define


@pytest.mark.skipif(shutil.which("avr-g++") is None, reason="gcc-avr not installed")
def test_debian_avr_gcc_needs_decimal_dig(tmp_path):
    # Debian's avr-gcc 5.4 leaves DECIMAL_DIG undefined in C++: the Arduino
    # core's WString.cpp needs it.
    real = os.path.realpath(shutil.which("avr-g++"))
    tool = tmp_path / "toolchain"
    (tool / "bin").mkdir(parents=True)
    (tool / "bin" / "avr-g++").symlink_to(real)
    version = subprocess.run([real, "-dumpversion"], capture_output=True, text=True).stdout.strip()
    if not version.startswith("5."):
        pytest.skip(f"avr-gcc {version} is not Debian's 5.4")
    env = uno_env(tmp_path, "examples/tank", platform=FakePlatform("atmelavr", {"toolchain-atmelavr": str(tool)}))
    run_hook(env)
    assert env.appended == [SECTIONS, {"CPPDEFINES": [("DECIMAL_DIG", "__DECIMAL_DIG__")]}]


def test_hook_finds_the_kits_checkout_without_file(tmp_path):
    # SCons gives the hook no `__file__`: the checkout (for its .venv/bin/fsw
    # fallback) comes from the code object's file name, two folders up.
    globs = run_hook(uno_env(tmp_path, "examples/tank"))
    assert "__file__" not in globs
    assert globs["KIT_ROOT"] == str(ROOT)
