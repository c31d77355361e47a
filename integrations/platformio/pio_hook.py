"""PlatformIO pre-build hook (`extra_scripts = pre:integrations/platformio/pio_hook.py`;
integrations/platformio/README.md).

Before every `pio run` of an environment it regenerates the fswkit project's
C++ with `fsw gen`, into `$PROJECT_SRC_DIR/<environment>/`, so the build
always compiles code fresh from the configs; a config error stops the build
with the located diagnostic and a non-zero status. Options it reads from the
environment's section of platformio.ini:

    custom_fsw_project = examples/tank   ; folder with one .app, or the .app
                                         ; (default: the PlatformIO project folder)
    custom_fsw_board   = uno             ; the kit's board (boards/*.toml);
                                         ; default: the one the .app names

When the environment's avr-g++ leaves DECIMAL_DIG undefined in C++ (Debian's
avr-gcc 5.4 does; Debian's Arduino core's WString.cpp needs it), the hook
defines DECIMAL_DIG=__DECIMAL_DIG__; a toolchain that defines it is left as
it is.

PlatformIO runs this file with SCons, which provides `Import`,
`COMMAND_LINE_TARGETS` and the build environment `env`.
"""

import inspect
import os
import shutil
import subprocess
import sys

# SCons runs this file without `__file__`; its code object still knows the path
# (integrations/platformio/pio_hook.py: the kit's checkout is two folders up).
KIT_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(
    globals().get("__file__") or inspect.currentframe().f_code.co_filename))))


class HookError(Exception):
    pass


def _option(env, name, default=""):
    value = env.GetProjectOption(name, default)
    return value.strip() if isinstance(value, str) else value


def fsw_command():
    """How to run `fsw`: this Python when it has fswkit (PlatformIO installed
    in the kit's venv), else the `fsw` command on PATH or in the kit's .venv."""
    try:
        import fswkit.cli  # noqa: F401
        return [sys.executable, "-m", "fswkit.cli"]
    except ImportError:
        pass
    exe = shutil.which("fsw") or os.path.join(KIT_ROOT, ".venv", "bin", "fsw")
    if os.path.isfile(exe) and os.access(exe, os.X_OK):
        return [exe]
    raise HookError("fswkit is not installed where PlatformIO runs: install PlatformIO into the kit's "
                    "venv (.venv/bin/pip install platformio), or put the `fsw` command on PATH")


def check_board(env, board_name):
    """The kit's board must be the one the environment builds for."""
    try:
        from fswkit.autocode.board import BoardError, load_board
    except ImportError:
        return  # checked by `fsw gen` itself when it runs as a command
    try:
        board = load_board(board_name)
    except BoardError as e:
        raise HookError(str(e))
    pio = board.raw.get("platformio", {})
    env_board = env.subst("$BOARD") if "BOARD" in env else ""
    platform = env.PioPlatform().name
    if platform == "native" or pio.get("platform") == "native":
        ok = platform == pio.get("platform")
    else:
        ok = env_board == pio.get("board")
    if not ok:
        raise HookError(f"environment `{env['PIOENV']}` builds for "
                        f"{'board `' + env_board + '`' if env_board else 'platform `' + platform + '`'}, "
                        f"but fswkit board `{board_name}` is PlatformIO's `{pio.get('board')}`: "
                        f"set custom_fsw_board")


def generate(env):
    """Runs `fsw gen` for the environment; returns the output folder."""
    project_dir = env.subst("$PROJECT_DIR")
    project = os.path.join(project_dir, _option(env, "custom_fsw_project", ".") or ".")
    board = _option(env, "custom_fsw_board", "")
    out = os.path.join(env.subst("$PROJECT_SRC_DIR"), env["PIOENV"])
    if board:
        check_board(env, board)
    argv = fsw_command() + ["gen", os.path.relpath(project, project_dir), "--out", out]
    if board:
        argv += ["--board", board]
    code = subprocess.call(argv, cwd=project_dir)
    if code != 0:
        raise HookError(f"`fsw gen` failed for environment `{env['PIOENV']}` (the configs above); "
                        "the build stops here")
    return out


def needs_decimal_dig(cxx):
    """True when this C++ compiler's <float.h> leaves DECIMAL_DIG undefined
    under -std=gnu++11 (Debian's avr-gcc 5.4 does)."""
    try:
        r = subprocess.run([cxx, "-std=gnu++11", "-x", "c++", "-E", "-dM", "-"], input="#include <float.h>\n",
                           capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return False
    return r.returncode == 0 and "#define DECIMAL_DIG " not in r.stdout


# Linked as mk/build.mk links (`fsw build`): with -flto the program is
# compiled again at the link, and without these in one section, so
# --gc-sections cannot drop what became dead only there (a board's VM, whose
# unused features fold away at the link: docs/bytecode.md), and in the order
# of their sources, each function near those it calls (2-byte relaxed calls:
# -fno-toplevel-reorder, mk/build.mk).
AVR_LINKFLAGS = ["-ffunction-sections", "-fdata-sections", "-fno-toplevel-reorder"]


def configure_toolchain(env):
    platform = env.PioPlatform()
    if platform.name != "atmelavr":
        return
    env.Append(LINKFLAGS=AVR_LINKFLAGS)
    tool_dir = platform.get_package_dir("toolchain-atmelavr")
    if not tool_dir:
        return
    cxx = os.path.join(tool_dir, "bin", "avr-g++")
    if needs_decimal_dig(cxx):
        env.Append(CPPDEFINES=[("DECIMAL_DIG", "__DECIMAL_DIG__")])


def main(env, targets):
    if env.IsCleanTarget():
        return 0
    try:
        configure_toolchain(env)
        testing = "test" in env.get("BUILD_TYPE", "")
        if not testing or env.GetProjectOption("test_build_src", False):
            out = generate(env)
            print(f"fswkit: generated {env['PIOENV']} sources in {os.path.relpath(out, env.subst('$PROJECT_DIR'))}")
    except HookError as e:
        sys.stderr.write(f"fswkit: {e}\n")
        return 1
    return 0


if "Import" in globals():  # run by PlatformIO (SCons)
    Import("env")  # noqa: F821
    _status = main(env, globals().get("COMMAND_LINE_TARGETS", []))  # noqa: F821
    if _status:
        env.Exit(_status)  # noqa: F821
