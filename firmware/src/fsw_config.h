// fswkit build options: every knob of the runtime, one line of reason each,
// `#ifndef` defaults (override with -D on the compiler line) and `#error`
// checks on combinations that cannot work.
#ifndef FSW_CONFIG_H
#define FSW_CONFIG_H

// Platform layer: the Arduino PSL under an Arduino core, else the native
// host PSL (simulated clock and pins for tests and host runs).
#ifndef FSW_PLATFORM_ARDUINO
#  if defined(ARDUINO)
#    define FSW_PLATFORM_ARDUINO 1
#  else
#    define FSW_PLATFORM_ARDUINO 0
#  endif
#endif
#ifndef FSW_PLATFORM_NATIVE
#  define FSW_PLATFORM_NATIVE (!FSW_PLATFORM_ARDUINO)
#endif
#if FSW_PLATFORM_ARDUINO == FSW_PLATFORM_NATIVE
#  error "fswkit: exactly one of FSW_PLATFORM_ARDUINO and FSW_PLATFORM_NATIVE must be 1"
#endif
#if defined(__AVR__) && !FSW_PLATFORM_ARDUINO
#  error "fswkit: AVR builds use the Arduino PSL (build with the Arduino core, ARDUINO defined)"
#endif

// Evaluation type R (spec 4.5): binary32 where `double` is 32 bits (AVR),
// binary64 elsewhere. A host may set 1 to reproduce a board's arithmetic.
#ifndef FSW_REAL_IS_FLOAT
#  if defined(__AVR__) || (defined(__SIZEOF_DOUBLE__) && __SIZEOF_DOUBLE__ == 4)
#    define FSW_REAL_IS_FLOAT 1
#  else
#    define FSW_REAL_IS_FLOAT 0
#  endif
#endif
#if !FSW_REAL_IS_FLOAT && defined(__SIZEOF_DOUBLE__) && __SIZEOF_DOUBLE__ != 8
#  error "fswkit: FSW_REAL_IS_FLOAT=0 needs a 64-bit double; this target's double is narrower"
#endif

// F64 elements converted in software from/to their binary64 bit pattern:
// required where `double` is 32 bits; a host may set 1 to mirror AVR exactly.
#ifndef FSW_F64_SOFT
#  if defined(__SIZEOF_DOUBLE__) && __SIZEOF_DOUBLE__ != 8
#    define FSW_F64_SOFT 1
#  else
#    define FSW_F64_SOFT 0
#  endif
#endif
#if !FSW_F64_SOFT && defined(__SIZEOF_DOUBLE__) && __SIZEOF_DOUBLE__ != 8
#  error "fswkit: FSW_F64_SOFT=0 needs a 64-bit double"
#endif
#if FSW_F64_SOFT && !FSW_REAL_IS_FLOAT
#  error "fswkit: FSW_F64_SOFT=1 converts binary64 to binary32 only: set FSW_REAL_IS_FLOAT=1"
#endif

// Width of rolling-window indices: 16 bits on 8-bit MCUs (no window there can
// exceed RAM anyway, and it halves index RAM), 32 bits elsewhere.
#ifndef FSW_WINDOW_INDEX_BITS
#  if defined(__AVR__)
#    define FSW_WINDOW_INDEX_BITS 16
#  else
#    define FSW_WINDOW_INDEX_BITS 32
#  endif
#endif
#if FSW_WINDOW_INDEX_BITS == 16
#  define FSW_WINDOW_MAX_N 65535UL
#elif FSW_WINDOW_INDEX_BITS == 32
#  define FSW_WINDOW_MAX_N 100000UL  // the language's limit (spec 4.4)
#else
#  error "fswkit: FSW_WINDOW_INDEX_BITS must be 16 or 32"
#endif

// Hardware watchdog kicked once per executor cycle (AVR only; the native PSL
// counts kicks instead). Timeout in ms: one of 15 30 60 120 250 500 1000 2000.
#ifndef FSW_WATCHDOG
#  if defined(__AVR__)
#    define FSW_WATCHDOG 1
#  else
#    define FSW_WATCHDOG 0
#  endif
#endif
#ifndef FSW_WATCHDOG_MS
#  define FSW_WATCHDOG_MS 250
#endif
#if FSW_WATCHDOG && FSW_PLATFORM_ARDUINO && !defined(__AVR__)
#  error "fswkit: FSW_WATCHDOG is implemented for AVR boards only: set FSW_WATCHDOG=0"
#endif
#if FSW_WATCHDOG_MS != 15 && FSW_WATCHDOG_MS != 30 && FSW_WATCHDOG_MS != 60 && \
    FSW_WATCHDOG_MS != 120 && FSW_WATCHDOG_MS != 250 && FSW_WATCHDOG_MS != 500 && \
    FSW_WATCHDOG_MS != 1000 && FSW_WATCHDOG_MS != 2000
#  error "fswkit: FSW_WATCHDOG_MS must be one of 15 30 60 120 250 500 1000 2000"
#endif

// The executor sleeps between cycles (AVR): Timer1 in CTC mode paces the
// cycles and keeps the clock (micros/millis: the Arduino core's Timer0
// overflow interrupt is turned off, so its millis()/delay() stop), the CPU
// idles until a compare interrupt FSW_WAKE_EARLY_US before the cycle is due,
// then waits out the rest with interrupts off and starts the cycle on the
// timer's count. 0: the executor polls micros() as on other platforms.
#ifndef FSW_SLEEP
#  if defined(__AVR__)
#    define FSW_SLEEP 1
#  else
#    define FSW_SLEEP 0
#  endif
#endif
#if FSW_SLEEP && !defined(__AVR__)
#  error "fswkit: FSW_SLEEP is implemented for AVR boards only: set FSW_SLEEP=0"
#endif
// How long before a cycle is due the sleeping executor wakes: longer than
// the interrupt handlers that may run back to back then, before the CPU
// turns interrupts off to wait out the rest (the one running when the
// timer's compare came, then each other one pending), so the cycle still
// starts on the timer's count. The rest is awake time spent spinning, every
// cycle. 0, the default: 16 us, or 24 us where the application has sensor
// parts (fsw_app.h kAppSensors: the TWI handler). The kit's handlers but
// the TWI's take at most about 15 us back to back on a 16 MHz AVR (ADC up
// to 85 cycles with the vector's jump, UART receive 47, UART transmit 39,
// EEPROM ready about 30, the timer's compare 17, and about 25 of the loop
// before it turns interrupts off); a start the wait reaches too late to
// count the ending sub-period first (about 3 us) is counted late
// (psl_arduino.cpp cycle_wait).
#ifndef FSW_WAKE_EARLY_US
#  define FSW_WAKE_EARLY_US 0
#endif
#if FSW_WAKE_EARLY_US != 0 && (FSW_WAKE_EARLY_US < 4 || FSW_WAKE_EARLY_US > 1000)
#  error "fswkit: FSW_WAKE_EARLY_US must be 0 (the kit's choice) or 4..1000"
#endif
// How long before a cycle the sleeping executor stops starting background
// work (loop()'s service of the link and of the EEPROM writers, docs/runtime.md):
// longer than such a pass takes, so that none holds the CPU past a cycle's
// start (it would start late, counted in `late`).
#ifndef FSW_BACKGROUND_GUARD_US
#  define FSW_BACKGROUND_GUARD_US 256
#endif
#if FSW_BACKGROUND_GUARD_US < 0 || FSW_BACKGROUND_GUARD_US > 16000
#  error "fswkit: FSW_BACKGROUND_GUARD_US must be 0..16000"
#endif

// Per-task step timing (worst case, overruns): costs two clock reads per task.
#ifndef FSW_TASK_TIMING
#  define FSW_TASK_TIMING 1
#endif

// Digital channels of generated code on the port registers (AVR): the
// generator resolves each channel's pin to a port and bit from the board
// file (`arduino.ports`, which a test holds to the variant's pins_arduino.h)
// and `FSW_PIN` hands them to inline code: two instructions a pin, no pin
// tables, no `digitalWrite`. 0: through the PAL's pin numbers (the core's
// pinMode/digitalRead/digitalWrite), e.g. for a core whose variant maps pins
// differently from the board file.
#ifndef FSW_AVR_PORTS
#  if defined(__AVR__)
#    define FSW_AVR_PORTS 1
#  else
#    define FSW_AVR_PORTS 0
#  endif
#endif
#if FSW_AVR_PORTS && !defined(__AVR__)
#  error "fswkit: FSW_AVR_PORTS is for AVR only"
#endif

// Constant tables (tasks, I/O channels) in flash: AVR copies initialised
// data to RAM at boot, so read-only tables go to PROGMEM there.
#ifndef FSW_USE_PROGMEM
#  if defined(__AVR__)
#    define FSW_USE_PROGMEM 1
#  else
#    define FSW_USE_PROGMEM 0
#  endif
#endif
#if FSW_USE_PROGMEM && !defined(__AVR__)
#  error "fswkit: FSW_USE_PROGMEM is for AVR only"
#endif

// Stack measurement (AVR): at boot, before the stack is used, the free RAM
// between the end of the static data (`_end`) and the top of RAM is filled
// with FSW_STACK_PAINT_BYTE; a debugger or the simulated board later finds
// how deep the stack ever reached (the lowest byte no longer painted; the
// simulated board, fswkit.sim.board, expects the default byte). 18 bytes of flash,
// no RAM; at boot 7 cycles a byte of free RAM (under 1 ms on an Uno, ~4 ms on
// a Mega: well inside the 15 ms a watchdog left armed by a reset allows).
#ifndef FSW_STACK_PAINT
#  if defined(__AVR__)
#    define FSW_STACK_PAINT 1
#  else
#    define FSW_STACK_PAINT 0
#  endif
#endif
#ifndef FSW_STACK_PAINT_BYTE
#  define FSW_STACK_PAINT_BYTE 0xC5
#endif
#if FSW_STACK_PAINT && !defined(__AVR__)
#  error "fswkit: FSW_STACK_PAINT is implemented for AVR boards only"
#endif

// Console (serial) speed used by the executor's boot report and telemetry.
#ifndef FSW_CONSOLE_BAUD
#  define FSW_CONSOLE_BAUD 115200UL
#endif

// Console driver on Arduino: 1 = the core's `Serial` (HardwareSerial: any
// board, and sketches that print with Serial themselves), 0 = the kit's own
// interrupt-driven UART0 driver (AVR only: 0.66 KB less flash and 43 B less
// RAM for the tank example; it defines the USART0 interrupts, so a sketch
// that also uses Serial must set 1).
#ifndef FSW_CONSOLE_ARDUINO_SERIAL
#  if defined(__AVR__)
#    define FSW_CONSOLE_ARDUINO_SERIAL 0
#  else
#    define FSW_CONSOLE_ARDUINO_SERIAL 1
#  endif
#endif
#if !FSW_CONSOLE_ARDUINO_SERIAL && FSW_PLATFORM_ARDUINO && !defined(__AVR__)
#  error "fswkit: the built-in UART driver is for AVR boards: set FSW_CONSOLE_ARDUINO_SERIAL=1"
#endif
// The receive ring of the built-in UART0 driver, bytes (a power of two,
// 4..256), for a program whose code does not size it (generated code sizes
// its own for what its ground keeps in flight: 32 bytes where the ground
// sends one command at a time, this where it pipelines them, the parameter
// client's 90 bytes in flight; docs/runtime.md, "The console"). Up to ~117
// bytes arrive in a 10 ms cycle at 115200 baud; one command is at most 24.
// The driver has no transmit ring: it sends the link's frames from the
// link's own transmit buffer (pal::console_send).
#ifndef FSW_CONSOLE_RX_SIZE
#  define FSW_CONSOLE_RX_SIZE 64
#endif
#if (FSW_CONSOLE_RX_SIZE & (FSW_CONSOLE_RX_SIZE - 1)) != 0 || FSW_CONSOLE_RX_SIZE < 4 || FSW_CONSOLE_RX_SIZE > 256
#  error "fswkit: FSW_CONSOLE_RX_SIZE must be a power of two, 4..256"
#endif

// The link's receive buffer, bytes: the longest uplink frame encoded (SET of
// an 8-byte element: 13 bytes + CRC, one COBS code byte) with room to spare.
#ifndef FSW_LINK_RX_CAP
#  define FSW_LINK_RX_CAP 24
#endif
// Uplink bytes read per run of the uplink task (bounds its step time).
#ifndef FSW_LINK_RX_PER_RUN
#  define FSW_LINK_RX_PER_RUN 64
#endif
// Bytes of the parameter store's stage queue (PARAM_STAGE arguments waiting
// for the EEPROM; docs/parameters.md). A STAGE that does not fit is BUSY.
// The longest STAGE a frame carries: FSW_LINK_RX_CAP encoded bytes less a
// COBS code byte, the opcode and sequence number (3) and the CRC (2), 18
// bytes; fsw_param.h refuses a queue that could not take it.
#ifndef FSW_PARAM_QUEUE
#  define FSW_PARAM_QUEUE 18
#endif

// The bytecode VM (fsw_vm.h, docs/bytecode.md). Its operand stack, in Reals
// (on the C stack while a step runs): an image that needs more is refused by
// the verifier (kVmBadStack).
#ifndef FSW_VM_STACK
#  define FSW_VM_STACK 12
#endif
// Forward jumps the verifier tracks at once (nesting of if/and/or); more is
// refused (kVmTooNested). Each costs 3 bytes of RAM on an AVR (4 on a host):
// in the reload store's check (fsw_reload.h), on the stack of vm_verify.
#ifndef FSW_VM_PENDING
#  define FSW_VM_PENDING 16
#endif
#if FSW_VM_STACK < 2 || FSW_VM_STACK > 255
#  error "fswkit: FSW_VM_STACK must be 2..255"
#endif

// Machines replaced at run time (fsw_reload.h, docs/reload.md): the most
// image bytes one WRITE command carries (the writer's buffer, RAM).
#ifndef FSW_RELOAD_QUEUE
#  define FSW_RELOAD_QUEUE 32
#endif
#if FSW_RELOAD_QUEUE < 10 || FSW_RELOAD_QUEUE > 200
#  error "fswkit: FSW_RELOAD_QUEUE must be 10..200"
#endif
// A slice of an image's check (fsw_reload.h: its CRC, then the verifier, a
// slice at each machine-task step): the EEPROM bytes it reads. 48: a slice
// takes at most 0.4 ms of a 16 MHz AVR (tools/bench_reload.py).
#ifndef FSW_RELOAD_SLICE
#  define FSW_RELOAD_SLICE 48
#endif
#if FSW_RELOAD_SLICE < 16 || FSW_RELOAD_SLICE > 2048
#  error "fswkit: FSW_RELOAD_SLICE must be 16..2048"
#endif

// Elements and regions are little-endian in memory (spec 2); typed access
// copies bytes straight into locals, so the host must be little-endian too.
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#  error "fswkit: big-endian targets are not supported"
#endif

#endif  // FSW_CONFIG_H
