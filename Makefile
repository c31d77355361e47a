# fswkit: the two commands a newcomer needs are `make demo` and `make test`.
# Every target sets the machine up first (tools/bootstrap.sh: Debian packages
# and the Python venv), so a fresh clone needs nothing else.

VENV    ?= .venv
PY      := $(VENV)/bin/python
FSW     := $(VENV)/bin/fsw
STAMP   := $(VENV)/.bootstrapped
BUILD   ?= build

.PHONY: all setup test test-python fuzz bench clean

include mk/firmware.mk

all: test

$(STAMP): pyproject.toml tools/bootstrap.sh
	VENV=$(VENV) tools/bootstrap.sh
	touch $@

setup: $(STAMP)

## test: every test suite: pytest, then the runtime's Unity suites natively
## (R = binary64 and binary32) and on a simulated ATmega328P
test: setup test-python test-firmware

test-python: setup
	$(PY) -m pytest tests

## fuzz: long property-based runs of the front end (1,000,000 cases)
fuzz: setup
	FSW_FUZZ_EXAMPLES=$${FSW_FUZZ_EXAMPLES:-1000000} $(PY) -m pytest -q -p no:cacheprovider tests/fuzz

## bench: measured numbers against targets.md (deterministic counts)
bench: setup
	$(PY) tools/bench.py
	$(PY) tools/bench_firmware.py
	$(MAKE) --no-print-directory bench-firmware

clean:
	rm -rf $(BUILD) .pytest_cache .hypothesis
