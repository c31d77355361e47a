#!/usr/bin/env bash
# Sets a fresh Debian/Ubuntu machine up for the kit: the Debian packages it
# needs (installed with apt, through sudo when not root) and the Python venv.
# Idempotent: each step is skipped when already done.
set -euo pipefail

VENV=${VENV:-.venv}
PYTHON=${PYTHON:-python3}

# Debian packages: the AVR toolchain and Arduino core, the simulated board,
# avrdude for flashing, graphviz to render `fsw graph`, valgrind for `make bench`,
# clang and its runtime (libFuzzer, sanitizers) for the uplink fuzzer.
APT_PACKAGES=(gcc-avr avr-libc binutils-avr avrdude arduino-core-avr simavr libsimavr-dev
              g++ make graphviz valgrind clang libclang-rt-14-dev)

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
if [ ${#missing[@]} -gt 0 ]; then
    echo "bootstrap: installing Debian packages: ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    as_root apt-get update -qq
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
"$VENV/bin/python" -m pip install -q --upgrade pip
"$VENV/bin/python" -m pip install -q -e ".[test]"
