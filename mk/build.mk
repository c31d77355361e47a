# Builds one application's firmware: the generated code, the fswkit runtime
# and (for a board) the Arduino core. `fsw build` runs it with the board's
# settings; it can also be run by hand:
#
#   make -f mk/build.mk GEN=build/uno/gen OUT=build/uno NAME=tank \
#        MCU=atmega328p F_CPU=16000000 VARIANT=standard BOARD_DEFINE=ARDUINO_AVR_UNO
#   make -f mk/build.mk native GEN=build/native/gen OUT=build/native NAME=tank
#
# Flags follow the Arduino core's platform.txt (LTO, -Os, gc-sections), plus
# -DDECIMAL_DIG=__DECIMAL_DIG__, which Debian's core needs with gcc-avr 5.4,
# and three that trade a few cycles per call for flash: -mcall-prologues
# (shared register save/restore) and linker relaxation (short calls and
# jumps where they reach), together about 4 % of a firmware's flash, and
# -mstrict-X (the X pointer only as the AVR addresses with it: no
# adjust-and-restore sequences around it; 62 B of the rocket's flash), and one
# that costs nothing measurable: -fno-move-loop-invariants (values hoisted out
# of loops hold registers an 8-bit MCU then saves and reloads; 70 B of the
# rocket's flash, its busy time per cycle unchanged). Two more trade a
# little CPU for flash: -fno-tree-vrp (no value-range propagation: its
# jump threading copies blocks) and -fira-algorithm=priority (register
# allocation by priority, not by Chaitin-Briggs colouring): together -162 B
# of the core rocket's flash and 4 B of its stack, +2.8 us a cycle awake
# (380.8 -> 383.6 us, target 400; 58 B a us), -122 B of the whole rocket's
# for +2.1 us (2026-12-07, night; docs/runtime.md). (-fno-gcse would save
# 230 B more, but costs 26 B of measured stack and slows nav: not used.)
# The link repeats -ffunction-sections -fdata-sections: LTO compiles the
# program again at the link, and without them puts it in one section each,
# so --gc-sections cannot drop a function that became dead only there,
# once a constant the generated code defines was folded (the VM's features,
# fsw::vm_features: 760 B of examples/stand's flash; 18 B of the rocket's).
# It also keeps the program's functions in the order of their sources
# (-fno-toplevel-reorder): a function then lies near those it calls (a
# machine's step near the element reads and the float library, the link's
# near each other), within the 4 KB a relaxed 2-byte `rcall` reaches, where
# LTO's own order left 104 of the core rocket's calls 4-byte `call`s (28
# since: 148 B of its flash, 2026-12-07). Unreferenced variables are
# dropped all the same (-fdata-sections, --gc-sections).

# RUNTIME is the runtime's folder: `fsw build` passes it (fswkit.autocode.kit,
# which knows where the kit's files are, in a checkout or an installed
# kit); by hand it defaults to firmware/src beside this file's folder, as
# both a checkout and an installed kit lay them out.
THIS_MK  := $(lastword $(MAKEFILE_LIST))
RUNTIME  ?= $(dir $(THIS_MK))../firmware/src
ARDUINO  ?= /usr/share/arduino/hardware/arduino/avr
CORE_DIR := $(ARDUINO)/cores/arduino
VAR_DIR  := $(ARDUINO)/variants/$(VARIANT)

AVR_CC   ?= avr-gcc
AVR_CXX  ?= avr-g++
AVR_AR   ?= avr-gcc-ar
AVR_OBJCOPY ?= avr-objcopy
HOST_CXX ?= g++

GEN_SRCS := $(sort $(wildcard $(GEN)/*.cpp))
RT_SRCS  := $(filter-out %/psl_native.cpp,$(sort $(wildcard $(RUNTIME)/*.cpp)))
RT_HDRS  := $(wildcard $(RUNTIME)/*.h)
CORE_SRCS := $(wildcard $(CORE_DIR)/*.c) $(wildcard $(CORE_DIR)/*.cpp) $(wildcard $(CORE_DIR)/*.S)

# EXTRA_DEFS: more -D options for every object of this build, core and
# runtime alike (a build option of docs/runtime.md, e.g.
# -DFSW_CONSOLE_ARDUINO_SERIAL=1; the tests build with it)
DEFS     := -mmcu=$(MCU) -DF_CPU=$(F_CPU)L -DARDUINO=10819 -D$(BOARD_DEFINE) -DARDUINO_ARCH_AVR $(EXTRA_DEFS)
INCS     := -I$(CORE_DIR) -I$(VAR_DIR)
SIZE_OPT := -mcall-prologues -mstrict-X -fno-move-loop-invariants -fno-tree-vrp -fira-algorithm=priority
OPT      := -Os $(SIZE_OPT) -g -ffunction-sections -fdata-sections -flto -fno-fat-lto-objects
CFLAGS   := -std=gnu11 $(OPT) $(DEFS) $(INCS)
CXXFLAGS := -std=gnu++11 $(OPT) -fno-exceptions -fno-rtti -fno-threadsafe-statics \
            -DDECIMAL_DIG=__DECIMAL_DIG__ $(DEFS) $(INCS)
WARN     := -Wall -Wextra
DEPS     := -MMD -MP
LDFLAGS  := -mmcu=$(MCU) -Os $(SIZE_OPT) -g -flto -ffunction-sections -fdata-sections -fno-toplevel-reorder \
            -fuse-linker-plugin -Wl,--gc-sections -Wl,--relax
NATIVE_FLAGS := -std=gnu++11 -O2 -ffp-contract=off -fno-exceptions -fno-rtti $(WARN)

# LIBS: a folder holding this very configuration's core.a and libfswkit.a,
# built before (`fsw build` passes its cache's, fswkit.target.libcache, with
# their hash in LIBS_KEY): the firmware links them instead of those built in
# OUT. NATIVE_RT: the same for a native build, a folder of the runtime's
# objects (NATIVE_RT_KEY).
ARCHIVES := $(if $(LIBS),$(LIBS)/libfswkit.a $(LIBS)/core.a,$(OUT)/libfswkit.a $(OUT)/core.a)

CORE_OBJS := $(patsubst $(CORE_DIR)/%,$(OUT)/core/%.o,$(CORE_SRCS))
RT_OBJS   := $(patsubst $(RUNTIME)/%.cpp,$(OUT)/rt/%.o,$(RT_SRCS))
GEN_OBJS  := $(patsubst $(GEN)/%.cpp,$(OUT)/gen/%.o,$(GEN_SRCS))
NATIVE_SRCS := $(filter-out %/psl_arduino.cpp,$(sort $(wildcard $(RUNTIME)/*.cpp)))

# ---- what decides a rebuild ----------------------------------------------------
# Every object depends on a stamp of the whole build configuration: the
# board (MCU, clock, variant, board define), every flag, the source folders
# and their file lists, and each tool's path and version (`tool_id`). The
# stamp is rewritten only when the configuration changes, so a build for
# another board, with other flags or another compiler rebuilds everything
# and an unchanged one rebuilds nothing. Headers are decided per object by
# the compiler's dependency files (-MMD -MP), the Arduino core's included.
# AVR_TOOLS_KEY: a hash of the AVR tools' identity (each one's path, size,
# date and version, and the C library's path, size and date) computed by
# the caller for the tools make runs here (`fsw build` passes it,
# fswkit.target.build.make_args): it stands in the stamp for the tools and
# their C library, which make otherwise asks itself for (tool_id, file_id:
# five shells and the tools' --version, about 30 ms of CPU a run).
tool_id = $(shell p=$$(command -v $(1)) && echo "$$p=$$(readlink -f "$$p") $$(stat -Lc '%s %Y' "$$p")" \
              "$$($(1) --version 2>&1 | head -n 1)")
file_id = $(shell f=$$($(1)) && echo "$$f $$(stat -Lc '%s %Y' "$$f" 2>/dev/null)")

GOALS      := $(or $(MAKECMDGOALS),avr)
AVR_STAMP  := $(OUT)/.config-avr
NATIVE_STAMP := $(OUT)/.config-native
ifneq ($(filter-out native $(OUT)/$(NAME),$(GOALS)),)
ifneq ($(AVR_TOOLS_KEY),)
AVR_TOOLS := tools=$(AVR_TOOLS_KEY)
else
AVR_TOOLS := cc=$(call tool_id,$(AVR_CC)) cxx=$(call tool_id,$(AVR_CXX)) ar=$(call tool_id,$(AVR_AR)) \
    objcopy=$(call tool_id,$(AVR_OBJCOPY)) libc=$(call file_id,$(AVR_CC) -mmcu=$(MCU) -print-file-name=libc.a)
endif
AVR_CONFIG := mcu=$(MCU) f_cpu=$(F_CPU) variant=$(VARIANT) board=$(BOARD_DEFINE) \
    arduino=$(realpath $(ARDUINO)) runtime=$(realpath $(RUNTIME)) gen=$(realpath $(GEN)) \
    cflags=$(CFLAGS) cxxflags=$(CXXFLAGS) warn=$(WARN) ldflags=$(LDFLAGS) $(AVR_TOOLS) \
    sources=$(notdir $(CORE_SRCS) $(RT_SRCS) $(GEN_SRCS)) libs=$(LIBS) $(LIBS_KEY)
ifneq ($(file <$(AVR_STAMP)),$(AVR_CONFIG))
$(shell mkdir -p $(OUT))
$(file >$(AVR_STAMP),$(AVR_CONFIG))
endif
endif
ifneq ($(filter native $(OUT)/$(NAME),$(GOALS)),)
NATIVE_CONFIG := runtime=$(realpath $(RUNTIME)) gen=$(realpath $(GEN)) flags=$(NATIVE_FLAGS) \
    cxx=$(call tool_id,$(HOST_CXX)) sources=$(notdir $(NATIVE_SRCS) $(GEN_SRCS)) rt=$(NATIVE_RT) $(NATIVE_RT_KEY)
ifneq ($(file <$(NATIVE_STAMP)),$(NATIVE_CONFIG))
$(shell mkdir -p $(OUT))
$(file >$(NATIVE_STAMP),$(NATIVE_CONFIG))
endif
endif
CONFIG := $(AVR_STAMP) $(THIS_MK)

.PHONY: avr native
avr: $(OUT)/$(NAME).hex

$(OUT)/core/%.c.o: $(CORE_DIR)/%.c $(CONFIG)
	@mkdir -p $(@D)
	$(AVR_CC) $(CFLAGS) $(DEPS) -w -c $< -o $@
$(OUT)/core/%.cpp.o: $(CORE_DIR)/%.cpp $(CONFIG)
	@mkdir -p $(@D)
	$(AVR_CXX) $(CXXFLAGS) $(DEPS) -w -c $< -o $@
$(OUT)/core/%.S.o: $(CORE_DIR)/%.S $(CONFIG)
	@mkdir -p $(@D)
	$(AVR_CC) $(DEFS) $(INCS) $(DEPS) -x assembler-with-cpp -c $< -o $@
$(OUT)/core.a: $(CORE_OBJS) $(CONFIG)
	rm -f $@ && $(AVR_AR) rcs $@ $(CORE_OBJS)

$(OUT)/rt/%.o: $(RUNTIME)/%.cpp $(CONFIG)
	@mkdir -p $(@D)
	$(AVR_CXX) $(CXXFLAGS) $(WARN) $(DEPS) -I$(RUNTIME) -c $< -o $@
$(OUT)/libfswkit.a: $(RT_OBJS) $(CONFIG)
	rm -f $@ && $(AVR_AR) rcs $@ $(RT_OBJS)

$(OUT)/gen/%.o: $(GEN)/%.cpp $(CONFIG)
	@mkdir -p $(@D)
	$(AVR_CXX) $(CXXFLAGS) $(WARN) $(DEPS) -I$(RUNTIME) -I$(GEN) -c $< -o $@

$(OUT)/$(NAME).elf: $(GEN_OBJS) $(ARCHIVES) $(CONFIG)
	$(AVR_CC) $(LDFLAGS) -o $@ $(GEN_OBJS) $(ARCHIVES) -lm
$(OUT)/$(NAME).hex: $(OUT)/$(NAME).elf
	$(AVR_OBJCOPY) -O ihex -R .eeprom $< $@

# The same link, kept although it does not fit the MCU's memory, for a
# report of what uses it (`fsw build` asks for it when the link overflows).
$(OUT)/$(NAME).overflow.elf: $(GEN_OBJS) $(ARCHIVES) $(CONFIG)
	$(AVR_CC) $(LDFLAGS) -Wl,--noinhibit-exec -o $@ $(GEN_OBJS) $(ARCHIVES) -lm

-include $(CORE_OBJS:.o=.d) $(RT_OBJS:.o=.d) $(GEN_OBJS:.o=.d)

# ---- host executable ----------------------------------------------------------
# Each source its own object (in OUT/native/, headers decided per object by
# -MMD -MP, as above), then the link: an edited source recompiles alone,
# and a compiler cache (ccache) can keep every object, which it cannot for
# a command that compiles several sources at once.
native: $(OUT)/$(NAME)
NATIVE_GEN_OBJS := $(patsubst $(GEN)/%.cpp,$(OUT)/native/gen/%.o,$(GEN_SRCS))
NATIVE_CONFIG_DEPS := $(NATIVE_STAMP) $(THIS_MK)
$(OUT)/native/gen/%.o: $(GEN)/%.cpp $(NATIVE_CONFIG_DEPS)
	@mkdir -p $(@D)
	$(HOST_CXX) $(NATIVE_FLAGS) $(DEPS) -I$(RUNTIME) -I$(GEN) -c $< -o $@
ifneq ($(NATIVE_RT),)
NATIVE_RT_OBJS := $(sort $(wildcard $(NATIVE_RT)/*.o))
else
NATIVE_RT_OBJS := $(patsubst $(RUNTIME)/%.cpp,$(OUT)/native/rt/%.o,$(NATIVE_SRCS))
$(OUT)/native/rt/%.o: $(RUNTIME)/%.cpp $(NATIVE_CONFIG_DEPS)
	@mkdir -p $(@D)
	$(HOST_CXX) $(NATIVE_FLAGS) $(DEPS) -I$(RUNTIME) -I$(GEN) -c $< -o $@
endif
$(OUT)/$(NAME): $(NATIVE_GEN_OBJS) $(NATIVE_RT_OBJS) $(NATIVE_CONFIG_DEPS)
	@mkdir -p $(@D)
	$(HOST_CXX) $(NATIVE_FLAGS) -o $@ $(NATIVE_GEN_OBJS) $(NATIVE_RT_OBJS) -pthread

-include $(NATIVE_GEN_OBJS:.o=.d) $(filter $(OUT)/native/%,$(NATIVE_RT_OBJS:.o=.d))
