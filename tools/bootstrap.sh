#!/usr/bin/env bash
# Sets a fresh Debian/Ubuntu machine up for the kit: the Debian packages it
# needs (installed with apt, through sudo when not root) and the Python venv.
# Idempotent: each step is skipped when already done.
set -euo pipefail

VENV=${VENV:-.venv}
PYTHON=${PYTHON:-python3}

# Debian packages: the AVR toolchain and Arduino core, the simulated board,
# avrdude for flashing, graphviz to render `fsw graph`, valgrind for `make bench`,
# clang and its runtime (libFuzzer, sanitizers) for the uplink fuzzer, ccache
# for `make test`'s compiles (Makefile).
APT_PACKAGES=(gcc-avr avr-libc binutils-avr avrdude arduino-core-avr simavr libsimavr-dev
              g++ make graphviz valgrind clang libclang-rt-14-dev
              chromium chromium-driver ccache)
# Installed where the distribution has them: arduino-ctags, which arduino-cli
# runs on an exported sketch's .ino with Debian's Arduino core
# (integrations/arduino-cli/README.md).
OPTIONAL_APT_PACKAGES=(arduino-ctags)

as_root() {
    if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

missing=()
for p in "${APT_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed"; then
        missing+=("$p")
    fi
done
if ! "$PYTHON" -c 'import ensurepip, venv' >/dev/null 2>&1; then
    missing+=(python3-venv)
fi
if ! command -v npm >/dev/null 2>&1; then  # a Node.js of another origin brings its own npm
    missing+=(nodejs npm)
fi
# An optional package is looked up in apt's lists as they are, and in fresh
# ones when required packages make apt-get update run anyway.
has_candidate() { apt-cache policy "$1" 2>/dev/null | grep -q 'Candidate: [^(]'; }
optional=()
for p in "${OPTIONAL_APT_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed"; then
        optional+=("$p")
    fi
done
updated=
if [ ${#missing[@]} -gt 0 ]; then
    export DEBIAN_FRONTEND=noninteractive
    as_root apt-get update -qq
    updated=1
fi
for p in ${optional[@]+"${optional[@]}"}; do
    if has_candidate "$p"; then
        missing+=("$p")
    else
        echo "bootstrap: $p is not in this distribution's packages: skipped (arduino-cli needs it to compile a sketch)"
    fi
done
if [ ${#missing[@]} -gt 0 ] && [ -z "$updated" ]; then
    export DEBIAN_FRONTEND=noninteractive
    as_root apt-get update -qq
fi
if [ ${#missing[@]} -gt 0 ]; then
    echo "bootstrap: installing Debian packages: ${missing[*]}"
    # A parallel apt run can race for the archive lock: retry once.
    as_root apt-get install -y -qq --no-install-recommends "${missing[@]}" \
        || { sleep 5; as_root apt-get install -y -qq --no-install-recommends "${missing[@]}"; }
fi

if ! "$PYTHON" -c 'import sys; sys.exit(sys.version_info < (3, 11))'; then
    echo "bootstrap: Python 3.11 or newer is needed ($PYTHON is $("$PYTHON" --version 2>&1))" >&2
    exit 1
fi
if [ ! -x "$VENV/bin/python" ]; then
    echo "bootstrap: creating the Python venv in $VENV"
    "$PYTHON" -m venv "$VENV"
fi
# The kit and its test tools go in with uv (from PyPI; about 5 s where pip
# takes 20), reading the package index and local wheels that pip's
# environment names (PIP_INDEX_URL, PIP_EXTRA_INDEX_URL, PIP_FIND_LINKS). A
# pip configuration file that names an index (uv does not read those), or
# uv failing, leaves the work to pip itself.
pip_install() {
    "$VENV/bin/python" -m pip install -q --upgrade pip
    "$VENV/bin/python" -m pip install -q -e ".[test]"
}
if "$VENV/bin/python" -m pip config list 2>/dev/null \
        | grep -qE '^[a-z]+\.(index-url|extra-index-url|find-links|no-index)='; then
    pip_install
elif "$VENV/bin/python" -m pip install -q "uv>=0.4,<1" \
        && UV_INDEX_URL=${PIP_INDEX_URL:-${UV_INDEX_URL:-}} \
           UV_EXTRA_INDEX_URL=${PIP_EXTRA_INDEX_URL:-${UV_EXTRA_INDEX_URL:-}} \
           UV_FIND_LINKS=${PIP_FIND_LINKS:-${UV_FIND_LINKS:-}} \
           "$VENV/bin/uv" pip install -q --python "$VENV/bin/python" -e ".[test]"; then
    :
else
    echo "bootstrap: uv could not install the kit's Python packages: pip installs them"
    pip_install
fi

# The web ground station draws its plots with uPlot, from the npm registry,
# into build/web (fswkit.web.app finds it there; FSW_UPLOT_DIR elsewhere).
UPLOT=uplot@1.6.32
if [ ! -f build/web/node_modules/uplot/package.json ] || \
   ! grep -q '"version": "1.6.32"' build/web/node_modules/uplot/package.json; then
    echo "bootstrap: installing $UPLOT from the npm registry into build/web"
    mkdir -p build/web
    npm install --no-save --no-audit --no-fund --loglevel=error --prefix build/web "$UPLOT" >/dev/null \
        || { sleep 5; npm install --no-save --no-audit --no-fund --loglevel=error --prefix build/web "$UPLOT" >/dev/null; }
fi
