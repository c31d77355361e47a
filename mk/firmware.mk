# Firmware runtime test suites (Unity): natively with the host's g++ in two
# evaluation modes (R = binary64, and R = binary32 with software F64 as on
# AVR), and on a simulated ATmega328P under simavr.
#
#   make -f mk/firmware.mk test-firmware          # both
#   make -f mk/firmware.mk test-firmware-native
#   make -f mk/firmware.mk test-firmware-avr
#   make -f mk/firmware.mk bench-firmware         # callgrind counts + AVR sizes
#
# The root Makefile includes this file (`include mk/firmware.mk`); it assumes
# tools/bootstrap.sh already ran (g++, gcc-avr, avr-libc, arduino-core-avr,
# simavr, libsimavr-dev), but for fw-build-ahead, which leaves what it cannot
# build yet to test-firmware. Everything is built under build/firmware/.

FW_BUILD      ?= build/firmware
FW_SRC        := firmware/src
FW_TESTS      := tests/firmware
FW_UNITY      := build/unity
FW_ARDUINO    ?= /usr/share/arduino/hardware/arduino/avr

FW_HOST_CXX   ?= g++
FW_HOST_CC    ?= gcc
FW_AVR_CXX    ?= avr-g++
FW_AVR_CC     ?= avr-gcc

# Suites: one file per scenario, tests/firmware/test_<name>.cpp.
FW_SUITES     := convert f64 window machine tank executor clock sv io pyro link param resume parts vm vm_step
FW_AVR_SUITES := convert f64 window machine tank executor clock sv io pyro resume parts vm vm_step float
# Suites that talk to the simulated board's sensor parts on the AVR (harness
# -I): built and run natively and on AVR like the others, but not in the
# PlatformIO view (tests/integrations/pio has one folder per FW_SUITES
# entry above), whose plain simavr has no parts on its TWI.
FW_PART_SUITES := baro accel
FW_SUITES     += $(FW_PART_SUITES)
FW_AVR_SUITES += $(FW_PART_SUITES)
# Extra harness options per AVR suite (FW_HARNESS_OPTS_<suite>): the simulated
# parts a suite talks to on the TWI.
FW_HARNESS_OPTS_baro := -I bmp280@0x76 -I ms5611@0x77
FW_HARNESS_OPTS_accel := -I adxl345@0x53 -I adxl345@B1 -I mpu6050@0x68 -I bmp280@0x76 -I ms5611@0x77
fw_rparen     := )
FW_HARNESS_CASE = $(foreach s,$(FW_AVR_SUITES),$(if $(FW_HARNESS_OPTS_$(s)),*/test_$(s).elf$(fw_rparen) opts="$(FW_HARNESS_OPTS_$(s))";;))

FW_RT_SRCS    := $(wildcard $(FW_SRC)/*.cpp)
FW_RT_HDRS    := $(wildcard $(FW_SRC)/*.h)
FW_TEST_HDRS  := $(FW_TESTS)/test_support.h $(FW_TESTS)/unity_config.h $(FW_TESTS)/vm_images.h $(wildcard $(FW_TESTS)/*.inc)
FW_UNITY_SRC  := $(FW_UNITY)/unity.c

# ---- flags --------------------------------------------------------------------
# The runtime is held to stricter warnings than the tests.
FW_WARN       := -Wall -Wextra -Werror
FW_RT_WARN    := $(FW_WARN) -Wconversion -Wshadow -Wdouble-promotion
FW_CXXSTD     := -fno-exceptions -fno-rtti
FW_INC        := -I$(FW_SRC) -I$(FW_TESTS) -I$(FW_UNITY) -DUNITY_INCLUDE_CONFIG_H
# Undefined behaviour (incl. out-of-range float->int casts) fails the run.
FW_SAN        := -fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all
FW_HOST_FLAGS := -std=c++11 -O2 -g $(FW_CXXSTD) $(FW_INC) $(FW_SAN)
FW_MODE_f64   :=
FW_MODE_f32   := -DFSW_REAL_IS_FLOAT=1 -DFSW_F64_SOFT=1

FW_AVR_MCU    ?= atmega328p
FW_AVR_FCPU   ?= 16000000L
FW_AVR_DEFS   := -mmcu=$(FW_AVR_MCU) -DF_CPU=$(FW_AVR_FCPU) -DARDUINO=10819 \
                 -DARDUINO_AVR_UNO -DARDUINO_ARCH_AVR -DDECIMAL_DIG=__DECIMAL_DIG__
FW_AVR_CORE_INC := -I$(FW_ARDUINO)/cores/arduino -I$(FW_ARDUINO)/variants/standard
FW_AVR_OPT    := -Os -ffunction-sections -fdata-sections
FW_AVR_CXXFLAGS := -std=gnu++11 $(FW_AVR_OPT) $(FW_CXXSTD) -fno-threadsafe-statics $(FW_AVR_DEFS) $(FW_AVR_CORE_INC)
FW_AVR_CFLAGS := -std=gnu11 $(FW_AVR_OPT) $(FW_AVR_DEFS) $(FW_AVR_CORE_INC)
FW_AVR_LDFLAGS := -mmcu=$(FW_AVR_MCU) -Os -Wl,--gc-sections

# ---- what decides a rebuild ---------------------------------------------------
# As in mk/build.mk: each set of objects depends on a stamp of its flags and
# compilers (path, size, date, version), rewritten only when they change,
# and each object on the headers it includes (the compiler's -MMD files).
fw_tool_id = $(shell p=$$(command -v $(1)) && echo "$$p=$$(readlink -f "$$p") $$(stat -Lc '%s %Y' "$$p")" \
                 "$$($(1) --version 2>&1 | head -n 1)")
FW_DEPS       := -MMD -MP
FW_STAMP_f64  := $(FW_BUILD)/native-f64/.config
FW_STAMP_f32  := $(FW_BUILD)/native-f32/.config
FW_STAMP_avr  := $(FW_BUILD)/avr/.config
ifneq ($(filter test-firmware test-firmware-native test-firmware-avr bench-firmware $(FW_BUILD)/%,$(MAKECMDGOALS)),)
FW_HOST_ID    := cxx=$(call fw_tool_id,$(FW_HOST_CXX)) cc=$(call fw_tool_id,$(FW_HOST_CC))
FW_CONFIG_f64 := $(FW_HOST_ID) flags=$(FW_HOST_FLAGS) $(FW_MODE_f64) $(FW_RT_WARN) $(FW_WARN) $(FW_UNITY)
FW_CONFIG_f32 := $(FW_HOST_ID) flags=$(FW_HOST_FLAGS) $(FW_MODE_f32) $(FW_RT_WARN) $(FW_WARN) $(FW_UNITY)
FW_CONFIG_avr := cxx=$(call fw_tool_id,$(FW_AVR_CXX)) cc=$(call fw_tool_id,$(FW_AVR_CC)) \
                 cxxflags=$(FW_AVR_CXXFLAGS) cflags=$(FW_AVR_CFLAGS) ldflags=$(FW_AVR_LDFLAGS) $(FW_RT_WARN) \
                 arduino=$(realpath $(FW_ARDUINO))
ifneq ($(file <$(FW_STAMP_f64)),$(FW_CONFIG_f64))
$(shell mkdir -p $(dir $(FW_STAMP_f64)))
$(file >$(FW_STAMP_f64),$(FW_CONFIG_f64))
endif
ifneq ($(file <$(FW_STAMP_f32)),$(FW_CONFIG_f32))
$(shell mkdir -p $(dir $(FW_STAMP_f32)))
$(file >$(FW_STAMP_f32),$(FW_CONFIG_f32))
endif
ifneq ($(file <$(FW_STAMP_avr)),$(FW_CONFIG_avr))
$(shell mkdir -p $(dir $(FW_STAMP_avr)))
$(file >$(FW_STAMP_avr),$(FW_CONFIG_avr))
endif
endif
$(FW_STAMP_f64) $(FW_STAMP_f32) $(FW_STAMP_avr):
	@mkdir -p $(@D) && touch $@

.PHONY: test-firmware test-firmware-native test-firmware-avr bench-firmware fw-unity fw-check-version fw-build-ahead

# Both sets, then one total line (CI reads `N passed, N failed`). A suite
# that dies before printing its own line still fails the run. Built and run
# on every core (FW_JOBS), each target's output kept whole (-Otarget). From
# nothing the suites compile in about 50 s of CPU (2026-12-07); `make test`
# has them compiled by fw-build-ahead during the set-up, before pytest, and
# finds them up to date here.
FW_JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
test-firmware:
	@mkdir -p $(FW_BUILD)
	@$(MAKE) --no-print-directory -j$(FW_JOBS) -Otarget -f $(firstword $(MAKEFILE_LIST)) \
	    test-firmware-native test-firmware-avr > $(FW_BUILD)/test.log 2>&1; status=$$?; cat $(FW_BUILD)/test.log; \
	  awk -v st=$$status '/^[0-9]+ passed, [0-9]+ failed/ {p += $$1; f += $$3} \
	    END {if (st != 0 && f == 0) f = 1; printf "firmware: %d passed, %d failed\n", p, f}' $(FW_BUILD)/test.log; \
	  exit $$status

# The suites built and not run, each failure left for test-firmware, which
# builds again what is missing and reports it (-k: the rest is built all the
# same; the output in $(FW_BUILD)/build-ahead.log). The root Makefile's
# `make test` runs it while tools/bootstrap.sh sets the venv up: on a fresh
# clone the suites' compile then overlaps the venv's download instead of
# following pytest. A set-up machine finds everything up to date.
fw-build-ahead:
	@mkdir -p $(FW_BUILD)
	@$(MAKE) --no-print-directory -k -j$(FW_JOBS) -f $(firstword $(MAKEFILE_LIST)) $(FW_NBINS_f64) $(FW_NBINS_f32) \
	    $(FW_BUILD)/native-f64/window_limits.stamp $(FW_ABINS) > $(FW_BUILD)/build-ahead.log 2>&1 || true

$(FW_UNITY_SRC):
	tools/fetch_unity.sh
fw-unity: $(FW_UNITY_SRC)

# ---- version handshake: library.properties, fsw_version.h, version.py agree ----
fw-check-version:
	@py=$$(sed -n 's/^__version__ = "\(.*\)"/\1/p' autocode/version.py); \
	lib=$$(sed -n 's/^version=//p' firmware/library.properties); \
	hdr=$$(sed -n 's/^#define FSW_RUNTIME_VERSION_STRING "\(.*\)"/\1/p' $(FW_SRC)/fsw_version.h); \
	parts=$$(sed -n 's/^#define FSW_RUNTIME_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\)/\2/p' $(FW_SRC)/fsw_version.h | paste -sd.); \
	if [ "$$py" = "$$lib" ] && [ "$$py" = "$$hdr" ] && [ "$$py" = "$$parts" ]; then \
	  echo "firmware version $$py matches the Python package"; \
	else echo "version mismatch: version.py=$$py library.properties=$$lib fsw_version.h=$$hdr/$$parts" >&2; exit 1; fi

# ---- native ---------------------------------------------------------------------
# $(1) = mode (f64 | f32)
define FW_NATIVE_MODE
FW_NDIR_$(1) := $(FW_BUILD)/native-$(1)
FW_NRT_OBJS_$(1) := $$(patsubst $(FW_SRC)/%.cpp,$(FW_BUILD)/native-$(1)/rt/%.o,$(FW_RT_SRCS))
FW_NBINS_$(1) := $$(patsubst %,$(FW_BUILD)/native-$(1)/test_%,$(FW_SUITES))

$(FW_BUILD)/native-$(1)/rt/%.o: $(FW_SRC)/%.cpp $(FW_RT_HDRS) $(FW_STAMP_$(1))
	@mkdir -p $$(@D)
	$(FW_HOST_CXX) $(FW_HOST_FLAGS) $(FW_MODE_$(1)) $(FW_RT_WARN) $(FW_DEPS) -c $$< -o $$@

$(FW_BUILD)/native-$(1)/obj/%.o: $(FW_TESTS)/%.cpp $(FW_RT_HDRS) $(FW_TEST_HDRS) $(FW_UNITY_SRC) $(FW_STAMP_$(1))
	@mkdir -p $$(@D)
	$(FW_HOST_CXX) $(FW_HOST_FLAGS) $(FW_MODE_$(1)) $(FW_WARN) $(FW_DEPS) -c $$< -o $$@

$(FW_BUILD)/native-$(1)/obj/unity.o: $(FW_UNITY_SRC) $(FW_TESTS)/unity_config.h $(FW_STAMP_$(1))
	@mkdir -p $$(@D)
	$(FW_HOST_CC) -std=c99 -O2 -g $(FW_INC) $(FW_SAN) $(FW_DEPS) -c $$< -o $$@

$(FW_BUILD)/native-$(1)/test_%: $(FW_BUILD)/native-$(1)/obj/test_%.o $(FW_BUILD)/native-$(1)/obj/test_support.o \
		$(FW_BUILD)/native-$(1)/obj/unity.o $$(FW_NRT_OBJS_$(1)) $(FW_STAMP_$(1))
	$(FW_HOST_CXX) $(FW_SAN) -pthread -o $$@ $$(filter %.o,$$^)

-include $$(wildcard $(FW_BUILD)/native-$(1)/rt/*.d $(FW_BUILD)/native-$(1)/obj/*.d)
endef
$(eval $(call FW_NATIVE_MODE,f64))
$(eval $(call FW_NATIVE_MODE,f32))

# Keep objects between runs (they would otherwise count as intermediate).
.SECONDARY: $(foreach m,f64 f32,$(FW_NRT_OBJS_$(m)) \
    $(patsubst %,$(FW_BUILD)/native-$(m)/obj/%.o,$(addprefix test_,$(FW_SUITES)) test_support unity))

# A window of 100000 compiles; 100001 must not (spec 4.4 boundary pair).
$(FW_BUILD)/native-f64/window_limits.stamp: $(FW_TESTS)/window_limit.cpp $(FW_RT_HDRS)
	@mkdir -p $(@D)
	$(FW_HOST_CXX) -std=c++11 -fsyntax-only $(FW_WARN) -I$(FW_SRC) -DFSW_TEST_N=100000 $<
	@if $(FW_HOST_CXX) -std=c++11 -fsyntax-only -I$(FW_SRC) -DFSW_TEST_N=100001 $< 2>/dev/null; then \
	  echo "window_limit: N=100001 compiled but must be refused" >&2; exit 1; fi
	@touch $@

test-firmware-native: fw-check-version $(FW_NBINS_f64) $(FW_NBINS_f32) $(FW_BUILD)/native-f64/window_limits.stamp
	@fail=0; for t in $(FW_NBINS_f64) $(FW_NBINS_f32); do \
	  echo "== $$t"; $$t || fail=1; done; exit $$fail

# ---- AVR (simavr) --------------------------------------------------------------
FW_ADIR       := $(FW_BUILD)/avr
FW_CORE_C     := $(wildcard $(FW_ARDUINO)/cores/arduino/*.c)
FW_CORE_CPP   := $(wildcard $(FW_ARDUINO)/cores/arduino/*.cpp)
FW_CORE_S     := $(wildcard $(FW_ARDUINO)/cores/arduino/*.S)
FW_CORE_OBJS  := $(patsubst $(FW_ARDUINO)/cores/arduino/%,$(FW_ADIR)/core/%.o,$(FW_CORE_C) $(FW_CORE_CPP) $(FW_CORE_S))
FW_ART_OBJS   := $(patsubst $(FW_SRC)/%.cpp,$(FW_ADIR)/rt/%.o,$(FW_RT_SRCS))
FW_ABINS      := $(patsubst %,$(FW_ADIR)/test_%.elf,$(FW_AVR_SUITES))
# The suites run on the kit's simulated board (host-tools/fswkit/sim/harness.c),
# compiled and cached as `fsw sim` builds it; the venv's Python finds it.
FW_PY         ?= $(if $(PY),$(PY),.venv/bin/python)

$(FW_ADIR)/core/%.c.o: $(FW_ARDUINO)/cores/arduino/%.c $(FW_STAMP_avr)
	@mkdir -p $(@D)
	$(FW_AVR_CC) $(FW_AVR_CFLAGS) $(FW_DEPS) -c $< -o $@
$(FW_ADIR)/core/%.cpp.o: $(FW_ARDUINO)/cores/arduino/%.cpp $(FW_STAMP_avr)
	@mkdir -p $(@D)
	$(FW_AVR_CXX) $(FW_AVR_CXXFLAGS) $(FW_DEPS) -c $< -o $@
$(FW_ADIR)/core/%.S.o: $(FW_ARDUINO)/cores/arduino/%.S $(FW_STAMP_avr)
	@mkdir -p $(@D)
	$(FW_AVR_CC) $(FW_AVR_DEFS) $(FW_AVR_CORE_INC) $(FW_DEPS) -x assembler-with-cpp -c $< -o $@
$(FW_ADIR)/core.a: $(FW_CORE_OBJS) $(FW_STAMP_avr)
	rm -f $@ && avr-ar rcs $@ $(FW_CORE_OBJS)
# The runtime links as an archive, as the Arduino IDE does with
# dot_a_linkage=true: only the PSL parts a build uses are pulled in.
$(FW_ADIR)/libfswkit.a: $(FW_ART_OBJS) $(FW_STAMP_avr)
	rm -f $@ && avr-ar rcs $@ $(FW_ART_OBJS)

$(FW_ADIR)/rt/%.o: $(FW_SRC)/%.cpp $(FW_RT_HDRS) $(FW_STAMP_avr)
	@mkdir -p $(@D)
	$(FW_AVR_CXX) $(FW_AVR_CXXFLAGS) $(FW_RT_WARN) $(FW_DEPS) -c $< -o $@
$(FW_ADIR)/obj/%.o: $(FW_TESTS)/%.cpp $(FW_RT_HDRS) $(FW_TEST_HDRS) $(FW_UNITY_SRC) $(FW_STAMP_avr)
	@mkdir -p $(@D)
	$(FW_AVR_CXX) $(FW_AVR_CXXFLAGS) -I$(FW_SRC) -I$(FW_TESTS) -I$(FW_UNITY) -DUNITY_INCLUDE_CONFIG_H $(FW_WARN) $(FW_DEPS) -c $< -o $@
$(FW_ADIR)/obj/unity.o: $(FW_UNITY_SRC) $(FW_TESTS)/unity_config.h $(FW_STAMP_avr)
	@mkdir -p $(@D)
	$(FW_AVR_CC) $(FW_AVR_CFLAGS) -I$(FW_TESTS) -I$(FW_UNITY) -DUNITY_INCLUDE_CONFIG_H $(FW_DEPS) -c $< -o $@
$(FW_ADIR)/test_%.elf: $(FW_ADIR)/obj/test_%.o $(FW_ADIR)/obj/test_support.o $(FW_ADIR)/obj/unity.o \
		$(FW_ADIR)/libfswkit.a $(FW_ADIR)/core.a $(FW_STAMP_avr)
	$(FW_AVR_CXX) $(FW_AVR_LDFLAGS) -o $@ $(filter-out $(FW_STAMP_avr),$^)
	@avr-size -C --mcu=$(FW_AVR_MCU) $@ | grep -E 'Program|Data' | sed 's|^|  $(notdir $@) |'

.SECONDARY: $(FW_CORE_OBJS) $(FW_ART_OBJS) \
    $(patsubst %,$(FW_ADIR)/obj/%.o,$(addprefix test_,$(FW_AVR_SUITES)) test_support unity)
-include $(wildcard $(FW_ADIR)/core/*.d $(FW_ADIR)/rt/*.d $(FW_ADIR)/obj/*.d)

# Each suite runs until it stops itself; its UART output is copied to standard
# output and the run passes only on a closing `N passed, 0 failed` line, N > 0.
test-firmware-avr: $(FW_ABINS)
	@sim=$$($(FW_PY) -c 'from fswkit.sim.board import harness; print(harness())') || exit 1; \
	fail=0; for t in $(FW_ABINS); do \
	  echo "== $$t (simavr $(FW_AVR_MCU))"; \
	  opts=; case $$t in $(FW_HARNESS_CASE) esac; \
	  $$sim -u stdout -x unity -m $(FW_AVR_MCU) -t 30 -w 30 $$opts $$t || fail=1; done; exit $$fail

# ---- benchmarks (report only; not part of the test run) ------------------------
FW_BENCH := $(FW_BUILD)/bench
$(FW_BENCH)/bench_windows: $(FW_TESTS)/bench/bench_windows.cpp $(FW_TESTS)/tank_hand.inc $(FW_RT_SRCS) $(FW_RT_HDRS)
	@mkdir -p $(@D)
	$(FW_HOST_CXX) -std=c++11 -O2 $(FW_CXXSTD) -I$(FW_SRC) $(FW_WARN) -o $@ $< $(FW_RT_SRCS)
$(FW_BENCH)/size_%.elf: $(FW_TESTS)/bench/size_sketch.cpp $(FW_ADIR)/libfswkit.a $(FW_ADIR)/core.a
	@mkdir -p $(@D)
	$(FW_AVR_CXX) $(FW_AVR_CXXFLAGS) -I$(FW_SRC) $(FW_WARN) -DFSW_SIZE_TANK=$(if $(filter tank,$*),1,0) \
	    -o $@ $< $(FW_ADIR)/libfswkit.a $(FW_ADIR)/core.a $(FW_AVR_LDFLAGS)

# Instructions per update (x86-64, -O2, callgrind) net of the driver loop,
# and AVR flash/RAM the tank machine adds over an empty sketch.
bench-firmware: $(FW_BENCH)/bench_windows $(FW_BENCH)/size_empty.elf $(FW_BENCH)/size_tank.elf
	@ir() { valgrind --tool=callgrind --callgrind-out-file=/dev/null $(FW_BENCH)/bench_windows $$1 $$2 2>&1 \
	        | sed -n 's/.*refs: *//p' | tr -d ,; }; \
	n=20000; base=$$(( $$(ir none $$n) - $$(ir none 0) )); \
	printf '%-22s %s\n' "measure" "instructions per update (net)"; \
	for k in avg max min median tank; do \
	  d=$$(( $$(ir $$k $$n) - $$(ir $$k 0) )); \
	  if [ $$k = tank ]; then printf '%-22s %d\n' "tank step" $$(( d / n )); \
	  else printf '%-22s %d\n' "roll_$$k(x, 100)" $$(( (d - base) / n )); fi; done
	@sz() { avr-size -A $$1 | awk '/^\.text|^\.data/ {f += $$2} /^\.data|^\.bss/ {r += $$2} END {print f, r}'; }; \
	set -- $$(sz $(FW_BENCH)/size_empty.elf) $$(sz $(FW_BENCH)/size_tank.elf); \
	echo "tank machine + state vector on $(FW_AVR_MCU): +$$(( $$3 - $$1 )) B flash, +$$(( $$4 - $$2 )) B RAM (empty sketch: $$1 B flash, $$2 B RAM)"
