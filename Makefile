# fswkit: the two commands a newcomer needs are `make demo` and `make test`.
# Every target sets the machine up first (tools/bootstrap.sh: Debian packages
# and the Python venv), so a fresh clone needs nothing else.

VENV    ?= .venv
PY      := $(VENV)/bin/python
FSW     := $(VENV)/bin/fsw
STAMP   := $(VENV)/.bootstrapped
BUILD   ?= build

.PHONY: all setup setup-and-build-ahead fuzz-build-ahead demo docs-img test test-python fuzz fuzz-uplink fuzz-vm bench clean

include mk/firmware.mk

all: test

$(STAMP): pyproject.toml tools/bootstrap.sh
	VENV=$(VENV) tools/bootstrap.sh
	touch $@

# uPlot for the web ground station (tools/bootstrap.sh installs it from the
# npm registry into build/web): set up again after a `make clean`
UPLOT   := build/web/node_modules/uplot/package.json
$(UPLOT): | $(STAMP)
	VENV=$(VENV) tools/bootstrap.sh

setup: $(STAMP) $(UPLOT)
	@:

## demo: the example rocket's firmware built for an Uno from its configs,
## flown in closed loop on the simulated board (a 1-D rocket model at 1 kHz),
## its telemetry streamed over the simulated serial link; prints the flight
## summary and where the plot, logs and CSV are (build/demo/).
## DEMO_EXAMPLE=hpr (analog barometer and accelerometer) or hpr_digital (a
## BMP280 and an ADXL345 on I2C) flies the high-power computer instead
DEMO_SEED ?= 1
DEMO_EXAMPLE ?= rocket
demo: setup
	$(FSW) sim examples/$(DEMO_EXAMPLE) --plant rocket --seed $(DEMO_SEED) --out $(BUILD)/demo

## docs-img: the demo flight's plot shown in README.md (a test checks that
## docs/img/rocket-flight.png is this tree's seed-1 flight) and the web
## station's page and its archive tab as the browser tests see them (docs/ground.md)
docs-img: setup
	$(FSW) sim examples/rocket --plant rocket --seed 1 --out $(BUILD)/docs-img
	mkdir -p docs/img && cp $(BUILD)/docs-img/flight.png docs/img/rocket-flight.png
	FSW_SCREENSHOTS=docs/img $(PY) -m pytest -q -p no:cacheprovider tests/web/test_web_station.py \
	  tests/web/test_web_archive.py

# The tests' compiles go through ccache (Debian's ccache, which
# tools/bootstrap.sh installs): its folder of compiler names first on PATH, so
# every avr-gcc, avr-g++, gcc, g++ and clang++ that the kit's builds and the
# tests start looks its object up by the hash of its preprocessed source,
# its flags and the compiler, and compiles only on a miss. About 800
# compiles a run are the same from run to run (the runtime for a build
# variant, the examples' generated code) and half of them repeat within one
# run (the same program built in two tests' folders). The cache is in the
# kit's cache folder ($FSW_CACHE_DIR, else ~/.cache/fswkit), ccache/, at
# most 2 GB; the folder a source was compiled in is left out of the hash
# (CCACHE_NOHASHDIR), so a program's debug information may name the folder
# of the build that filled the entry. Links (LTO's code generation among
# them), failed compiles and calls with several sources are never cached.
# FSW_CCACHE=0 runs the compilers themselves.
ifneq ($(FSW_CCACHE),0)
FSW_CACHE_ROOT := $(or $(FSW_CACHE_DIR),$(or $(XDG_CACHE_HOME),$(HOME)/.cache)/fswkit)
test test-python test-firmware setup-and-build-ahead fw-build-ahead fuzz-build-ahead: export PATH := /usr/lib/ccache:$(PATH)
test test-python test-firmware setup-and-build-ahead fw-build-ahead fuzz-build-ahead: export CCACHE_DIR := $(FSW_CACHE_ROOT)/ccache
test test-python test-firmware setup-and-build-ahead fw-build-ahead fuzz-build-ahead: export CCACHE_NOHASHDIR := 1
test test-python test-firmware setup-and-build-ahead fw-build-ahead fuzz-build-ahead: export CCACHE_MAXSIZE := 2G
endif

## test: every test suite: pytest, then the runtime's Unity suites natively
## (R = binary64 and binary32) and on a simulated ATmega328P
test: setup-and-build-ahead test-python test-firmware

# The set-up, with what needs no venv compiled meanwhile: the Unity suites
# (fw-build-ahead, mk/firmware.mk) and the two libFuzzer binaries that
# tests/fuzz/test_fuzz_vm.py and tests/link/test_fuzz_uplink.py run
# (fuzz-build-ahead). On a fresh clone tools/bootstrap.sh mostly waits on the
# network while it fills the venv, and those compiles (about 50 and 13 s of
# CPU) fit in that wait instead of running after pytest or inside it.
# Whatever fails to build there (the Debian packages not installed yet) is
# built again, and reported, by the target that runs it. A set-up machine
# finds everything up to date.
setup-and-build-ahead:
	@$(MAKE) --no-print-directory -j2 setup fw-build-ahead fuzz-build-ahead

fuzz-build-ahead:
	@mkdir -p $(BUILD)/fuzz
	@$(MAKE) --no-print-directory -k $(FUZZ_UPLINK) $(FUZZ_VM) > $(BUILD)/fuzz/build-ahead.log 2>&1 || true

# pytest on every core (pytest-xdist), a test file's tests on one worker so
# that a module's costly set-up (a wheel, a firmware build) runs once. Two
# workers more than the cores: the link and ground-station tests spend most of
# their time waiting on a board paced to the wall clock, and the others run
# meanwhile (on 2 cores, 2026-12-07: 178 and 181 s with four workers, 190 and
# 193 s with three). The files marked `costly` go out first, costliest first
# (tests/conftest.py); xdist's own order (most tests first) is turned off.
# Python's compiled bytecode, the test modules' with pytest's rewritten
# asserts included, is kept in $(BUILD)/pycache between runs, outside the
# source tree, also where the environment sets PYTHONDONTWRITEBYTECODE (as
# some containers do): each worker would otherwise compile every test module
# again, about 4 s of CPU a worker (and the fswkit modules in every `fsw`
# the tests start). What the last run compiled in its temporary folders is
# dropped first, so that the cache does not grow from run to run.
PYTEST_JOBS ?= $(shell echo $$(( $$(nproc 2>/dev/null || echo 2) + 2 )))
PYCACHE := $(abspath $(BUILD))/pycache
test-python: setup
	rm -rf "$(PYCACHE)$$(realpath -m "$${TMPDIR:-/tmp}")"
	PYTHONDONTWRITEBYTECODE= PYTHONPYCACHEPREFIX=$(PYCACHE) \
	  $(PY) -m pytest -n $(PYTEST_JOBS) --dist loadfile --no-loadscope-reorder tests

## fuzz: the front end's mutation fuzzer (1,000,000 cases on both cores,
## about an hour; crashing inputs land in build/fuzz/), the uplink parser, the
## differential tests, and 20,000 random applications that the checker must
## refuse or that must compile for their board and natively (FSW_GEN_CASES),
## and the front end's property tests at about 17 times their `make test`
## count (FSW_PROPERTY_SCALE 5; make test's is 0.3)
fuzz: setup fuzz-uplink fuzz-vm
	$(PY) tools/fuzz_frontend.py --cases $${FSW_FUZZ_EXAMPLES:-1000000} --out $(BUILD)/fuzz/frontend
	FSW_DIFF_SEED=$${FSW_DIFF_SEED:-2} FSW_DIFF_CASES=$${FSW_DIFF_CASES:-20000} \
	  FSW_DIFF_RAW_CASES=$${FSW_DIFF_RAW_CASES:-5000} FSW_DIFF_AVR_CASES=$${FSW_DIFF_AVR_CASES:-400} \
	  FSW_VM_AVR_CASES=$${FSW_VM_AVR_CASES:-400} FSW_VM_CASES=$${FSW_VM_CASES:-2000} \
	  FSW_VM_RAW_CASES=$${FSW_VM_RAW_CASES:-1000} \
	  $(PY) -m pytest -q -p no:cacheprovider tests/differential/test_generated.py tests/differential/test_simavr.py \
	  tests/differential/test_bytecode.py tests/differential/test_bytecode_avr.py
	FSW_GEN_CASES=$${FSW_GEN_CASES:-20000} $(PY) -m pytest -q -p no:cacheprovider \
	  tests/regression/test_accepted_configs_build.py
	FSW_PROPERTY_SCALE=$${FSW_PROPERTY_SCALE:-5} $(PY) -m pytest -q -p no:cacheprovider \
	  tests/autocode/lexer tests/autocode/parser tests/autocode/check/test_check_properties.py tests/run/test_interp_properties.py

## fuzz-uplink: the firmware's uplink parser under libFuzzer with ASan + UBSan
## (clang); FUZZ_RUNS inputs (make fuzz: 10,000,000; make test: a short run),
## FUZZ_SECONDS a time limit (0: none)
FUZZ_RUNS ?= 10000000
FUZZ_SECONDS ?= 0
FUZZ_UPLINK := $(BUILD)/fuzz/uplink/fuzz_uplink
FUZZ_UPLINK_SRCS := tests/fuzz/uplink/fuzz_uplink.cpp $(filter-out %/psl_arduino.cpp %/psl_arduino_console.cpp %/psl_arduino_eeprom.cpp,$(wildcard firmware/src/*.cpp))
$(FUZZ_UPLINK): $(FUZZ_UPLINK_SRCS) $(wildcard firmware/src/*.h)
	@mkdir -p $(@D)
	clang++ -std=c++11 -g -O1 -fno-exceptions -fno-rtti -fsanitize=fuzzer,address,undefined \
	    -fno-sanitize-recover=all -Ifirmware/src -o $@ $(FUZZ_UPLINK_SRCS)
fuzz-uplink: $(FUZZ_UPLINK)
	@mkdir -p $(BUILD)/fuzz/uplink/corpus
	@cp -n tests/fuzz/uplink/seeds/* $(BUILD)/fuzz/uplink/corpus/ 2>/dev/null || true
	@$(FUZZ_UPLINK) -runs=$(FUZZ_RUNS) -max_total_time=$(FUZZ_SECONDS) -seed=1 -max_len=512 -print_final_stats=1 \
	    -artifact_prefix=$(BUILD)/fuzz/uplink/ \
	    $(BUILD)/fuzz/uplink/corpus 2>$(BUILD)/fuzz/uplink/log.txt; st=$$?; \
	  grep -E "stat::number_of_executed_units|stat::average_exec_per_sec|ERROR|invariant" $(BUILD)/fuzz/uplink/log.txt; \
	  if [ $$st -eq 0 ]; then echo "uplink fuzz: 1 passed, 0 failed"; else tail -30 $(BUILD)/fuzz/uplink/log.txt; \
	  echo "uplink fuzz: 0 passed, 1 failed"; fi; exit $$st

## fuzz-vm: the bytecode verifier and VM under libFuzzer with ASan + UBSan
## (clang): no image the verifier accepts reads or writes outside the state
## vector, and the EEPROM verifier agrees with the RAM one, in one call and
## in slices, each slice within its reads (docs/reload.md).
## Seeds: tests/fuzz/vm/seeds/ compiled against the target's state vector, and
## every example machine (fsw compile). The images of tests/fuzz/vm/regressions
## (inputs that once failed) run first, once each. FUZZ_RUNS, FUZZ_SECONDS
## as for fuzz-uplink
FUZZ_VM := $(BUILD)/fuzz/vm/fuzz_vm
FUZZ_VM_SRCS := tests/fuzz/vm/fuzz_vm.cpp $(filter-out %/psl_arduino.cpp %/psl_arduino_console.cpp %/psl_arduino_eeprom.cpp,$(wildcard firmware/src/*.cpp))
$(FUZZ_VM): $(FUZZ_VM_SRCS) $(wildcard firmware/src/*.h)
	@mkdir -p $(@D)
	clang++ -std=c++11 -g -O1 -fno-exceptions -fno-rtti -fsanitize=fuzzer,address,undefined \
	    -fno-sanitize-recover=all -Ifirmware/src -o $@ $(FUZZ_VM_SRCS)
fuzz-vm: $(FUZZ_VM) | $(STAMP)
	@mkdir -p $(BUILD)/fuzz/vm/corpus
	@for sm in tests/fuzz/vm/seeds/*.sm; do \
	  $(FSW) compile $$sm --sv tests/fuzz/vm/seeds/fuzz.sv --real f64 -o $(BUILD)/fuzz/vm/corpus/seed-$$(basename $$sm .sm).fsm \
	    >/dev/null || exit 1; done
	@for sm in examples/*/*.sm; do \
	  $(FSW) compile $$sm --real f64 -o $(BUILD)/fuzz/vm/corpus/$$(basename $$(dirname $$sm))-$$(basename $$sm .sm).fsm \
	    >/dev/null 2>&1 || true; done
	@$(FUZZ_VM) -runs=0 -artifact_prefix=$(BUILD)/fuzz/vm/ tests/fuzz/vm/regressions 2>$(BUILD)/fuzz/vm/regressions.txt || \
	  { tail -30 $(BUILD)/fuzz/vm/regressions.txt; echo "vm fuzz: 0 passed, 1 failed (a past finding, tests/fuzz/vm/regressions)"; exit 1; }
	@$(FUZZ_VM) -runs=$(FUZZ_RUNS) -max_total_time=$(FUZZ_SECONDS) -seed=1 -max_len=4096 -print_final_stats=1 \
	    -artifact_prefix=$(BUILD)/fuzz/vm/ $(BUILD)/fuzz/vm/corpus 2>$(BUILD)/fuzz/vm/log.txt; st=$$?; \
	  grep -E "stat::number_of_executed_units|stat::average_exec_per_sec|ERROR|vm_verify says|vm_check_eeprom:" $(BUILD)/fuzz/vm/log.txt; \
	  if [ $$st -eq 0 ]; then echo "vm fuzz: 1 passed, 0 failed"; else tail -30 $(BUILD)/fuzz/vm/log.txt; \
	  echo "vm fuzz: 0 passed, 1 failed"; fi; exit $$st

## bench: measured numbers against targets.md (deterministic counts). Every
## bench runs, one failing or not: those that failed are named at the end,
## and make bench then exits 1.
BENCHES := bench bench_firmware bench_sim bench_link bench_flights bench_tapes bench_busy bench_study \
           bench_ground bench_params bench_recorder bench_vm bench_reload
bench: setup
	@failed=""; \
	for b in $(BENCHES); do \
	  echo "$(PY) tools/$$b.py"; $(PY) tools/$$b.py || failed="$$failed tools/$$b.py"; \
	done; \
	$(MAKE) --no-print-directory bench-firmware || failed="$$failed bench-firmware"; \
	if [ -n "$$failed" ]; then echo "make bench: failed:$$failed"; exit 1; fi; \
	echo "make bench: every bench ran and passed"

clean:
	rm -rf $(BUILD) .pytest_cache .hypothesis
