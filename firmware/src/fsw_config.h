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

// Per-task step timing (worst case, overruns): costs two clock reads per task.
#ifndef FSW_TASK_TIMING
#  define FSW_TASK_TIMING 1
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

// Console (serial) speed used by the executor's boot report and telemetry.
#ifndef FSW_CONSOLE_BAUD
#  define FSW_CONSOLE_BAUD 115200UL
#endif

// Elements and regions are little-endian in memory (spec 2); typed access
// copies bytes straight into locals, so the host must be little-endian too.
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#  error "fswkit: big-endian targets are not supported"
#endif

#endif  // FSW_CONFIG_H
