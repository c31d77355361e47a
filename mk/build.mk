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
# and two that trade a few cycles per call for flash: -mcall-prologues
# (shared register save/restore) and linker relaxation (short calls and
# jumps where they reach); together about 4 % of a firmware's flash.

THIS_MK  := $(lastword $(MAKEFILE_LIST))  # a change of flags rebuilds everything
RUNTIME  ?= $(dir $(THIS_MK))../firmware/src
ARDUINO  ?= /usr/share/arduino/hardware/arduino/avr
CORE_DIR := $(ARDUINO)/cores/arduino
VAR_DIR  := $(ARDUINO)/variants/$(VARIANT)

AVR_CC   ?= avr-gcc
AVR_CXX  ?= avr-g++
HOST_CXX ?= g++

GEN_SRCS := $(sort $(wildcard $(GEN)/*.cpp))
RT_SRCS  := $(filter-out %/psl_native.cpp,$(sort $(wildcard $(RUNTIME)/*.cpp)))
RT_HDRS  := $(wildcard $(RUNTIME)/*.h)
CORE_SRCS := $(wildcard $(CORE_DIR)/*.c) $(wildcard $(CORE_DIR)/*.cpp) $(wildcard $(CORE_DIR)/*.S)

DEFS     := -mmcu=$(MCU) -DF_CPU=$(F_CPU)L -DARDUINO=10819 -D$(BOARD_DEFINE) -DARDUINO_ARCH_AVR
INCS     := -I$(CORE_DIR) -I$(VAR_DIR)
SIZE_OPT := -mcall-prologues
OPT      := -Os $(SIZE_OPT) -g -ffunction-sections -fdata-sections -flto -fno-fat-lto-objects
CFLAGS   := -std=gnu11 $(OPT) $(DEFS) $(INCS)
CXXFLAGS := -std=gnu++11 $(OPT) -fno-exceptions -fno-rtti -fno-threadsafe-statics \
            -DDECIMAL_DIG=__DECIMAL_DIG__ $(DEFS) $(INCS)
WARN     := -Wall -Wextra

CORE_OBJS := $(patsubst $(CORE_DIR)/%,$(OUT)/core/%.o,$(CORE_SRCS))
RT_OBJS   := $(patsubst $(RUNTIME)/%.cpp,$(OUT)/rt/%.o,$(RT_SRCS))
GEN_OBJS  := $(patsubst $(GEN)/%.cpp,$(OUT)/gen/%.o,$(GEN_SRCS))

.PHONY: avr native
avr: $(OUT)/$(NAME).hex

$(OUT)/core/%.c.o: $(CORE_DIR)/%.c $(THIS_MK)
	@mkdir -p $(@D)
	$(AVR_CC) $(CFLAGS) -w -c $< -o $@
$(OUT)/core/%.cpp.o: $(CORE_DIR)/%.cpp $(THIS_MK)
	@mkdir -p $(@D)
	$(AVR_CXX) $(CXXFLAGS) -w -c $< -o $@
$(OUT)/core/%.S.o: $(CORE_DIR)/%.S $(THIS_MK)
	@mkdir -p $(@D)
	$(AVR_CC) $(DEFS) $(INCS) -x assembler-with-cpp -c $< -o $@
$(OUT)/core.a: $(CORE_OBJS)
	rm -f $@ && avr-gcc-ar rcs $@ $^

$(OUT)/rt/%.o: $(RUNTIME)/%.cpp $(RT_HDRS) $(THIS_MK)
	@mkdir -p $(@D)
	$(AVR_CXX) $(CXXFLAGS) $(WARN) -I$(RUNTIME) -c $< -o $@
$(OUT)/libfswkit.a: $(RT_OBJS)
	rm -f $@ && avr-gcc-ar rcs $@ $^

$(OUT)/gen/%.o: $(GEN)/%.cpp $(wildcard $(GEN)/*.h) $(RT_HDRS) $(THIS_MK)
	@mkdir -p $(@D)
	$(AVR_CXX) $(CXXFLAGS) $(WARN) -I$(RUNTIME) -I$(GEN) -c $< -o $@

$(OUT)/$(NAME).elf: $(GEN_OBJS) $(OUT)/libfswkit.a $(OUT)/core.a $(THIS_MK)
	$(AVR_CC) -mmcu=$(MCU) -Os $(SIZE_OPT) -g -flto -fuse-linker-plugin -Wl,--gc-sections -Wl,--relax -o $@ \
	    $(GEN_OBJS) $(OUT)/libfswkit.a $(OUT)/core.a -lm
$(OUT)/$(NAME).hex: $(OUT)/$(NAME).elf
	avr-objcopy -O ihex -R .eeprom $< $@

# ---- host executable ----------------------------------------------------------
NATIVE_SRCS := $(filter-out %/psl_arduino.cpp,$(sort $(wildcard $(RUNTIME)/*.cpp)))
native: $(OUT)/$(NAME)
$(OUT)/$(NAME): $(GEN_SRCS) $(NATIVE_SRCS) $(wildcard $(GEN)/*.h) $(RT_HDRS)
	@mkdir -p $(@D)
	$(HOST_CXX) -std=gnu++11 -O2 -ffp-contract=off -fno-exceptions -fno-rtti $(WARN) \
	    -I$(RUNTIME) -I$(GEN) -o $@ $(GEN_SRCS) $(NATIVE_SRCS) -pthread
