/* simboard: fswkit's simulated board, the one simavr program of the kit.
   Runs an AVR firmware ELF on simavr (libsimavr) with UART0 bridged to a
   pseudo-terminal, to standard I/O, or to the control channel, analog inputs
   driven in millivolts and digital pins read, driven and timestamped in
   cycles.

   Two ways to run it:

   - Control mode (-c): commands on standard input, one response line each on
     standard output, in order (docs/sim.md has the protocol; `commands[]`
     below is its table). The caller advances simulated time (`step`, `until`,
     `batch`) or lets the board run free (`go`). fswkit.sim.board.SimBoard
     speaks it; so can a person at a terminal.
   - Free run (no -c): runs from reset until the firmware stops itself or a
     limit, optionally paced to real time (-r), then prints a summary on
     standard error. With -u stdout the UART's bytes go to standard output as
     they come, and -x picks what the exit status says: the firmware test
     suites (make test-firmware: -x unity) and the differential tests on a
     simulated AVR (-x done) run their ELFs this way.

   usage: simboard [-c] [-m MCU] [-f HZ] [-t SIM_S] [-w WALL_S]
                   [-u control|pty|stdio|stdout|none] [-l LINK] [-r]
                   [-x crash|done|unity] [-a CH=MV]... [-E EEPROM_FILE]
                   [-s CSPIN[:SIZE] [-S FLASH_FILE]] [-I KIND@ADDR]... [-R SEED] FW.elf

   -I puts a sensor (bmp280, ms5611, mpu6050, adxl345) on the AVR's TWI at
   a 7-bit address, or on its SPI with its chip select on a pin (-I
   adxl345@B1): register models driven by the host (`part`).

   -s puts an SPI NOR flash chip (a W25Q64JV's commands and timing) on the
   AVR's SPI, its chip select on pin CSPIN (B2: the Uno's D10); -S and -E
   keep that flash's and the AVR EEPROM's bytes in files between runs.

   The board stops itself at the simulated-time limit (-t, seconds; 0 = none)
   and the wall-clock limit (-w, seconds since start; 0 = none), and when its
   control channel closes. fswkit builds this file at run time with the host's
   gcc against -lsimavr (fswkit.sim.board.harness()); no binary is committed.

   simavr's own uart_pty part (libsimavrparts) is not used: it prints on
   standard output, which carries the control protocol here, points a fixed
   /tmp/simavr-uart0 link at its pty (two boards would fight over it), and
   raises UART IRQs from its own thread while the core runs in another. This
   file serves the pty from the simulation loop instead. */
#define _GNU_SOURCE
#include <simavr/avr_adc.h>
#include <simavr/avr_eeprom.h>
#include <simavr/avr_extint.h>
#include <simavr/avr_ioport.h>
#include <simavr/avr_spi.h>
#include <simavr/avr_timer.h>
#include <simavr/avr_twi.h>
#include <simavr/avr_uart.h>
#include <simavr/avr_watchdog.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_cycle_timers.h>
#include <simavr/sim_elf.h>
#include <simavr/sim_interrupts.h>
#include <simavr/sim_io.h>
#include <simavr/sim_irq.h>
#include <simavr/sim_time.h>

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#define PROTO_VERSION 1
#define RUN_BATCH 2048               /* instructions between checks of the outside world */
#define UART_HIGH_WATER (64 * 1024)  /* bytes waiting for a pty reader before the board waits */
#define MAX_WATCH 32
#define MAX_EDGES (1u << 20)
#define MAX_PEEK 4096
#define MAX_ARGS 64                  /* words of one command line */

/* ---- small helpers ------------------------------------------------------------ */

typedef struct {
    uint8_t* buf;
    size_t head, len, cap; /* bytes [head, len) are pending */
} bytes_t;

static void bytes_push(bytes_t* b, const uint8_t* p, size_t n) {
    if (b->head > 0 && b->head == b->len) b->head = b->len = 0;
    if (b->len + n > b->cap) {
        if (b->head > 0) { /* compact first */
            memmove(b->buf, b->buf + b->head, b->len - b->head);
            b->len -= b->head;
            b->head = 0;
        }
        if (b->len + n > b->cap) {
            size_t cap = b->cap ? b->cap : 256;
            while (cap < b->len + n) cap *= 2;
            uint8_t* nb = realloc(b->buf, cap);
            if (!nb) {
                fprintf(stderr, "simboard: out of memory\n");
                exit(3);
            }
            b->buf = nb;
            b->cap = cap;
        }
    }
    memcpy(b->buf + b->len, p, n);
    b->len += n;
}

static size_t bytes_pending(const bytes_t* b) { return b->len - b->head; }

static void bytes_clear(bytes_t* b) { b->head = b->len = 0; }

static double wall_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* simavr's default makes the host sleep in wall-clock time while the core
   sleeps; the board runs as fast as it can and run() paces it when asked. */
static void no_wall_sleep(avr_t* a, avr_cycle_count_t how_long) {
    (void)a;
    (void)how_long;
}

static void sleep_s(double s) {
    if (s <= 0) return;
    struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    nanosleep(&ts, NULL);
}

/* ---- the board ------------------------------------------------------------------ */

enum { UART_NONE, UART_CONTROL, UART_PTY, UART_STDIO, UART_STDOUT };
static const char* uart_names[] = {"none", "control", "pty", "stdio", "stdout"};
#define N_UART_MODES 5

/* What a free run's exit status says (-x): 1 only if the firmware crashed;
   0 only if it stopped itself (1 crashed, 3 a limit or SIGINT ended it); 0
   only if its UART output held a Unity summary `N passed, 0 failed`, N > 0. */
enum { EXIT_CRASH, EXIT_DONE, EXIT_UNITY };
static const char* exit_names[] = {"crash", "done", "unity"};

static avr_t* avr;
static const char* mcu_name = "atmega328p";
static uint32_t f_cpu = 16000000u;
static avr_cycle_count_t cycle_limit; /* 0: none */
static double wall_limit;             /* seconds since start; 0: none */
static double wall_start;
static volatile sig_atomic_t interrupted;
static int halted; /* the firmware stopped (cpu_Done) or crashed */

static int uart_mode = UART_CONTROL;
static bytes_t uart_out;   /* AVR -> host, not yet delivered */
static bytes_t uart_in;    /* host -> AVR, not yet accepted by the UART */
static int uart_xoff;      /* the AVR's receive FIFO is full */
static uint64_t uart_dropped;
static avr_irq_t* uart_in_irq;
static int pty_master = -1;
static char pty_name[128];
static char pty_link[512];
static int pty_reader; /* a process has the pty's other end open */
static int stdio_in_open = 1;
static int exit_mode = EXIT_CRASH;
static char unity_line[256]; /* -x unity: the UART line being received */
static size_t unity_len;
static long unity_passed = -1, unity_failed = -1;

typedef struct {
    char port;
    uint8_t bit;
    uint8_t level;
    int active;
} watch_t;
static watch_t watches[MAX_WATCH];
typedef struct {
    avr_cycle_count_t cycle;
    char port;
    uint8_t bit, level;
} edge_t;
static edge_t* edges;
static size_t n_edges;
static int edges_overflow;

/* `prof`: cycles spent in chosen functions (the executor's task steps), and
   in sleep. A call starts when the program counter reaches a function's first
   instruction and ends when the stack pointer rises above its value there
   (the return popped the return address): interrupts taken meanwhile count
   in the call, as they keep the CPU from other work. Calls of profiled
   functions do not nest (an entry reached during a call is not counted).
   The first function marks a cycle: a frame runs from its start to the end
   of the last profiled call before it starts again (the executor's busy
   time in that cycle, what runs between its tasks included). */
#define MAX_PROF 32
typedef struct {
    avr_flashaddr_t entry; /* byte address */
    unsigned long long calls, total, worst;
} prof_fn_t;
static prof_fn_t prof_fns[MAX_PROF];
static int prof_n;            /* 0: profiling off */
static int prof_active = -1;  /* the function in a call, or -1 */
static uint16_t prof_sp;      /* the stack pointer at its entry */
static avr_cycle_count_t prof_start, prof_last_end;
static avr_cycle_count_t prof_frame_start;
static int prof_frame_open;
static unsigned long long prof_frames, prof_frame_total, prof_frame_worst, prof_frame_worst_at, prof_sleep;

static void prof_frame_close(void) {
    if (!prof_frame_open) return;
    unsigned long long span = prof_last_end > prof_frame_start ? prof_last_end - prof_frame_start : 0;
    prof_frames++;
    prof_frame_total += span;
    if (span > prof_frame_worst) {
        prof_frame_worst = span;
        prof_frame_worst_at = prof_frame_start;
    }
    prof_frame_open = 0;
}

/* After each instruction while profiling: `c0`, `slept` and `pc0` are the
   cycle, whether the core slept before it ran, and where it ran. simavr
   sleeps in the step of the SLEEP instruction itself (to its next cycle
   timer): of that step only the instruction's cycle is awake. */
static void prof_step(avr_t* a, avr_cycle_count_t c0, int slept, avr_flashaddr_t pc0) {
    if (slept) {
        prof_sleep += a->cycle - c0;
    } else if (a->cycle - c0 > 1 && pc0 + 1 <= a->flashend &&
               (a->flash[pc0] | (a->flash[pc0 + 1] << 8)) == 0x9588 /* SLEEP */) {
        prof_sleep += a->cycle - c0 - 1;
    }
    const uint16_t sp = (uint16_t)(a->data[R_SPL] | (a->data[R_SPH] << 8));
    if (prof_active >= 0) {
        if (sp <= prof_sp) return;
        prof_fn_t* f = &prof_fns[prof_active];
        unsigned long long d = a->cycle - prof_start;
        f->calls++;
        f->total += d;
        if (d > f->worst) f->worst = d;
        prof_last_end = a->cycle;
        prof_active = -1;
    }
    for (int i = 0; i < prof_n; i++) {
        if (prof_fns[i].entry != a->pc) continue;
        if (i == 0) {
            prof_frame_close();
            prof_frame_start = a->cycle;
            prof_frame_open = 1;
        }
        prof_active = i;
        prof_sp = sp;
        prof_start = a->cycle;
        break;
    }
}

static void logger(avr_t* a, const int level, const char* fmt, va_list ap) {
    if (level > (a ? a->log : LOG_ERROR)) return;
    fputs("simavr: ", stderr);
    vfprintf(stderr, fmt, ap);
}

/* -x unity: remembers the last `N passed, M failed` line the firmware sent. */
static void unity_scan(char c) {
    if (c != '\n') {
        if (unity_len + 1 < sizeof unity_line) unity_line[unity_len++] = c;
        return;
    }
    long p, f;
    char tail[8];
    unity_line[unity_len] = 0;
    if (sscanf(unity_line, "%ld passed, %ld failed%7s", &p, &f, tail) == 2) {
        unity_passed = p;
        unity_failed = f;
    }
    unity_len = 0;
}

static void on_uart_out(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    (void)param;
    uint8_t c = (uint8_t)value;
    if (exit_mode == EXIT_UNITY) unity_scan((char)c);
    if (uart_mode == UART_NONE || (uart_mode == UART_PTY && !pty_reader)) {
        uart_dropped++; /* nobody listening, as on a board with no cable */
        return;
    }
    bytes_push(&uart_out, &c, 1);
}

static void on_uart_xon(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    (void)value;
    (void)param;
    uart_xoff = 0;
}

static void on_uart_xoff(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    (void)value;
    (void)param;
    uart_xoff = 1;
}

/* simavr 1.6 times a UART byte as start + data + a parity bit + stop bits, whatever UCSRnC says
   (avr_uart.c, avr_uart_baud_write): 11 bit times for 8N1 instead of 10, so the simulated line carried
   10/11 of the real rate. Its handler of a UBRRnL write sets cycles_per_byte; this one, chained after it
   on the same register, takes the parity bit out again unless UPMn1 (UCSRnC bit 5) turns parity on. */
static avr_uart_t* uart0;

static void on_ubrr_write(struct avr_t* a, avr_io_addr_t addr, uint8_t v, void* param) {
    (void)addr;
    (void)v;
    (void)param;
    static const int data_bits[8] = {5, 6, 7, 8, 8, 8, 8, 9};
    avr_uart_t* p = uart0;
    const int db = data_bits[avr_regbit_get(a, p->ucsz) | (avr_regbit_get(a, p->ucsz2) << 2)];
    const int sb = 1 + avr_regbit_get(a, p->usbs);
    const int parity = (a->data[p->r_ucsrc] >> 5) & 1;
    p->cycles_per_byte = p->cycles_per_byte / (avr_cycle_count_t)(1 + db + 1 + sb) * (avr_cycle_count_t)(1 + db + parity + sb);
}

static void uart_bit_times(void) {
    for (avr_io_t* io = avr->io_port; io; io = io->next)
        if (io->kind && strcmp(io->kind, "uart") == 0 && ((avr_uart_t*)io)->name == '0') uart0 = (avr_uart_t*)io;
    if (uart0) avr_register_io_write(avr, uart0->ubrrl.reg, on_ubrr_write, NULL);
}

/* simavr 1.6's ATmega328P and ATmega2560 leave the phase-correct PWM modes of
   their timers out of the mode table (the 8-bit timers' mode 1, the 16-bit
   timers' modes 1-3): an absent mode has a TOP of 0, so the timer
   overflows, and matches both compare units, every prescaler period. The
   Arduino core's init() leaves Timer1 and Timer2 (and the Mega's Timer3-5)
   in mode 1 at clk/64: they overflowed every 64 CPU cycles, three
   interrupt flags raised each time, two fifths of the simulator's time on a
   flight that never uses them. The absent modes get the entries simavr
   gives these modes on its ATmega164-1284 and ATmega32U4 cores (8, 9 and
   10-bit, one TOP + 1 period: an overflow every 256 x 64 cycles at
   clk/64, where the part's dual slope takes 510 x 64). A mode the library
   defines is left as it is. */
static void timer_pwm_modes(void) {
    static const avr_timer_wgm_t pc8 = AVR_TIMER_WGM_FCPWM8(), pc9 = AVR_TIMER_WGM_FCPWM9(),
                                 pc10 = AVR_TIMER_WGM_FCPWM10();
    for (avr_io_t* io = avr->io_port; io; io = io->next) {
        if (!io->kind || strcmp(io->kind, "timer") != 0) continue;
        avr_timer_t* t = (avr_timer_t*)io;
        const int wide = t->r_tcnth != 0; /* a 16-bit timer: modes 1-3 are 8, 9 and 10-bit */
        if (t->wgm_op[1].kind == avr_timer_wgm_none) t->wgm_op[1] = pc8;
        if (wide && t->wgm_op[2].kind == avr_timer_wgm_none) t->wgm_op[2] = pc9;
        if (wide && t->wgm_op[3].kind == avr_timer_wgm_none) t->wgm_op[3] = pc10;
    }
}

/* Hands waiting host bytes to the AVR's UART while its FIFO has room. */
static void uart_feed(void) {
    while (!uart_xoff && bytes_pending(&uart_in)) avr_raise_irq(uart_in_irq, uart_in.buf[uart_in.head++]);
}

static void on_pin(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    watch_t* w = (watch_t*)param;
    uint8_t level = value ? 1 : 0;
    if (!w->active || level == w->level) return;
    w->level = level;
    if (n_edges >= MAX_EDGES) {
        edges_overflow = 1;
        return;
    }
    edges[n_edges].cycle = avr->cycle;
    edges[n_edges].port = w->port;
    edges[n_edges].bit = w->bit;
    edges[n_edges].level = level;
    n_edges++;
}

/* ---- INT0/INT1 held low ----------------------------------------------------------- */
/* simavr polls an external interrupt pin that goes low while its sense
   control says "low level" (EICRA's reset value) every cycle until the pin
   goes high, asking the port's state through avr_ioctl, which asks every
   peripheral in turn: examples/rocket's arming switch on D2 (INT0), low on
   the pad before arming, made that two thirds of the simulator's CPU in a
   flight. The same poll here reads the pin's register directly: one poll
   per low edge, the same cycle timer every cycle, the same interrupt raised
   when it would be, so the simulation is the same cycle for cycle. simavr's
   own is turned off after every reset (its module turns it on again); a
   reset simavr makes by itself (the watchdog's) keeps simavr's until the
   next reset the harness makes, which is the same poll. */
typedef struct {
    avr_extint_t* x;
    uint8_t n;
    avr_io_addr_t r_pin; /* the PINx register of the interrupt's pin */
} lvl_src_t;
static lvl_src_t lvl_src[EXTINT_COUNT];

static avr_cycle_count_t lvl_poll(struct avr_t* a, avr_cycle_count_t when, void* param) {
    const lvl_src_t* s = *(lvl_src_t**)param;
    const avr_extint_t* x = s->x;
    if ((a->data[s->r_pin] >> x->eint[s->n].port_pin) & 1u) { /* high again: done (as simavr's) */
        free(param);
        return 0;
    }
    if (a->sreg[S_I]) {
        avr_int_vector_t* v = &s->x->eint[s->n].vector;
        if (!(avr_regbit_get(a, v->raised) || v->pending)) avr_raise_interrupt(a, v);
    }
    return when + 1;
}

static void lvl_notify(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    lvl_src_t* s = param;
    avr_extint_t* x = s->x;
    if (value || x->eint[s->n].strict_lvl_trig) return; /* not low, or simavr's own poll is on */
    if (avr_regbit_get_array(avr, x->eint[s->n].isc, 2) != 0) return; /* not "low level" (as simavr decides) */
    lvl_src_t** poll = malloc(sizeof *poll); /* one a low edge, as simavr's */
    if (!poll) return;
    *poll = s;
    avr_cycle_timer_register(avr, 1, lvl_poll, poll);
}

static void lvl_setup(avr_t* a) {
    avr_extint_t* x = NULL;
    for (avr_io_t* io = a->io_port; io; io = io->next)
        if (!strcmp(io->kind, "extint")) x = (avr_extint_t*)io;
    if (!x) return;
    for (uint8_t n = 0; n < EXTINT_COUNT; n++) {
        if (!x->eint[n].port_ioctl || !x->eint[n].isc[1].reg) continue; /* absent, or edges only */
        const char port = (char)(x->eint[n].port_ioctl & 0xFF);
        avr_ioport_t* io_port = NULL;
        for (avr_io_t* io = a->io_port; io; io = io->next)
            if (!strcmp(io->kind, "port") && ((avr_ioport_t*)io)->name == port) io_port = (avr_ioport_t*)io;
        if (!io_port) continue; /* simavr's poll stays */
        lvl_src[n] = (lvl_src_t){x, n, io_port->r_pin};
        x->eint[n].strict_lvl_trig = 0;
        avr_irq_register_notify(x->io.irq + n, lvl_notify, &lvl_src[n]);
    }
}

static avr_cycle_count_t on_target(struct avr_t* a, avr_cycle_count_t when, void* param) {
    (void)a;
    (void)when;
    (void)param;
    return 0; /* exists only so that a sleeping core wakes at the target cycle (or the limit) */
}

static void on_sigint(int sig) {
    (void)sig;
    interrupted = 1;
}

static int port_state(char port, avr_ioport_state_t* st) {
    return avr_ioctl(avr, AVR_IOCTL_IOPORT_GETSTATE(port), st) == 0 ? 0 : -1;
}

/* ---- the pty ---------------------------------------------------------------------- */

static int pty_open(void) {
    int slave;
    if (openpty(&pty_master, &slave, pty_name, NULL, NULL) != 0) {
        fprintf(stderr, "simboard: cannot create a pseudo-terminal: %s\n", strerror(errno));
        return -1;
    }
    struct termios tio;
    if (tcgetattr(slave, &tio) == 0) { /* raw bytes both ways, no echo */
        cfmakeraw(&tio);
        tcsetattr(slave, TCSANOW, &tio);
    }
    close(slave); /* until someone opens it, the master reports a hang-up */
    fcntl(pty_master, F_SETFL, fcntl(pty_master, F_GETFL) | O_NONBLOCK);
    if (pty_link[0]) {
        /* only a symbolic link (a stale one of a board: the caller checked)
           is ever replaced; a file is never removed */
        struct stat st;
        if (lstat(pty_link, &st) == 0 && S_ISLNK(st.st_mode)) unlink(pty_link);
        if (symlink(pty_name, pty_link) != 0) {
            fprintf(stderr, "simboard: cannot link %s to %s: %s\n", pty_link, pty_name, strerror(errno));
            pty_link[0] = 0;
        }
    }
    return 0;
}

/* Moves bytes between the UART queues and the pty or standard I/O. */
static void uart_service(void) {
    if (uart_mode == UART_PTY) {
        struct pollfd p = {pty_master, POLLIN, 0};
        if (poll(&p, 1, 0) < 0) return;
        pty_reader = !(p.revents & POLLHUP);
        if (!pty_reader) {
            uart_dropped += bytes_pending(&uart_out);
            bytes_clear(&uart_out);
        }
        if (p.revents & POLLIN) {
            uint8_t buf[512];
            ssize_t n = read(pty_master, buf, sizeof buf);
            if (n > 0) bytes_push(&uart_in, buf, (size_t)n);
        }
        while (pty_reader && bytes_pending(&uart_out)) {
            ssize_t n = write(pty_master, uart_out.buf + uart_out.head, bytes_pending(&uart_out));
            if (n <= 0) break; /* the reader's buffer is full: later */
            uart_out.head += (size_t)n;
        }
    } else if (uart_mode == UART_STDIO || uart_mode == UART_STDOUT) { /* stdout: blocking, nothing read */
        while (bytes_pending(&uart_out)) {
            ssize_t n = write(1, uart_out.buf + uart_out.head, bytes_pending(&uart_out));
            if (n <= 0) {
                if (n < 0 && errno == EAGAIN) break;
                uart_mode = UART_NONE; /* standard output closed */
                bytes_clear(&uart_out);
                break;
            }
            uart_out.head += (size_t)n;
        }
        if (uart_mode == UART_STDIO && stdio_in_open) {
            struct pollfd p = {0, POLLIN, 0};
            if (poll(&p, 1, 0) > 0 && (p.revents & (POLLIN | POLLHUP))) {
                uint8_t buf[512];
                ssize_t n = read(0, buf, sizeof buf);
                if (n > 0)
                    bytes_push(&uart_in, buf, (size_t)n);
                else if (n == 0)
                    stdio_in_open = 0;
            }
        }
    }
    uart_feed();
}

/* ---- the control channel ------------------------------------------------------------ */

static FILE* proto; /* responses (the original standard output) */
static char inbuf[1 << 16];
static size_t in_len;
static int in_eof;

/* Reads more of standard input; returns 0 on EOF. With wait = 0 it does not block. */
static int input_fill(int wait) {
    if (in_eof) return 0;
    if (in_len == sizeof inbuf) return 1;
    struct pollfd p = {0, POLLIN, 0};
    int r = poll(&p, 1, wait ? -1 : 0);
    if (r < 0 && errno == EINTR) return 1;
    if (r <= 0) return 1;
    ssize_t n = read(0, inbuf + in_len, sizeof inbuf - in_len);
    if (n < 0) return (errno == EINTR || errno == EAGAIN) ? 1 : (in_eof = 1, 0);
    if (n == 0) {
        in_eof = 1;
        return 0;
    }
    in_len += (size_t)n;
    return 1;
}

static int line_ready(void) { return memchr(inbuf, '\n', in_len) != NULL; }

/* The next command line (without its newline) into out; 0 on EOF. */
static int next_line(char* out, size_t cap) {
    for (;;) {
        char* nl = memchr(inbuf, '\n', in_len);
        if (nl) {
            size_t n = (size_t)(nl - inbuf);
            size_t k = n < cap - 1 ? n : cap - 1;
            memcpy(out, inbuf, k);
            out[k] = 0;
            if (k && out[k - 1] == '\r') out[k - 1] = 0;
            memmove(inbuf, nl + 1, in_len - n - 1);
            in_len -= n + 1;
            return 1;
        }
        if (in_len == sizeof inbuf) { /* an absurdly long line: drop it */
            in_len = 0;
            snprintf(out, cap, "#too-long");
            return 1;
        }
        fflush(proto);
        if (!input_fill(1) && !line_ready()) {
            if (in_len) { /* a last line without a newline */
                size_t k = in_len < cap - 1 ? in_len : cap - 1;
                memcpy(out, inbuf, k);
                out[k] = 0;
                in_len = 0;
                return 1;
            }
            return 0;
        }
    }
}

/* ---- running ------------------------------------------------------------------------ */

static const char* state_name(int st) {
    switch (st) {
        case cpu_Running: return "running";
        case cpu_Sleeping: return "sleeping";
        case cpu_Done: return "done";
        case cpu_Crashed: return "crashed";
        case cpu_Stopped: return "stopped";
        default: return "other";
    }
}

/* The EEPROM: simavr's EEPROM module keeps the bytes (across resets); the
   harness counts the byte writes the firmware starts (EECR with EEPE set)
   and, when asked, pulses reset right after the Nth of them: a power cut at
   that byte (`eeprom cut N`). With -E FILE its bytes live in FILE between
   runs. */
#define EECR_ADDR 0x3F /* data-space address of EECR on the ATmega328P and ATmega2560 */
static unsigned long long ee_writes, ee_resets, ee_cut_at;
static int ee_cut_armed;
static const char* ee_file; /* -E: NULL for none */
/* A power cut is due right after the instruction that set it (`eeprom cut`,
   `flash cut`): one flag, so that the run loop tests one word per instruction. */
static volatile int cut_now;

static void on_eecr_write(struct avr_t* a, avr_io_addr_t addr, uint8_t v, void* param) {
    (void)a, (void)addr, (void)param;
    if (!(v & 0x02)) return; /* EEPE: a write starts */
    ee_writes++;
    if (ee_cut_armed && ee_writes >= ee_cut_at) {
        ee_cut_armed = 0;
        ee_resets++;
        cut_now = 1;
    }
}

/* ---- the SPI NOR flash ---------------------------------------------------------------- */

/* -s CSPIN[:SIZE]: a Winbond W25Q-class serial NOR flash (modelled on the
   W25Q64JV datasheet) on the AVR's hardware SPI, chip select active low on
   an AVR pin. simavr's SPI module raises SPI_IRQ_OUTPUT with each byte the
   master shifts out, as the transfer ends (simavr 1.6: 100 us after SPDR is
   written, whatever the clock divider), and takes the byte shifted in on
   SPI_IRQ_INPUT; the chip answers there and then, before SPIF is seen, so
   SPDR reads it as the byte of that transfer. Each answer depends on the
   bytes before it only, as on the wire (full duplex: the chip cannot answer
   the byte it is being sent).

   As on the part: program and erase start when CS rises after a whole
   command, need the write-enable latch (WEL, set by 06h) and clear it when
   done; while one runs (BUSY) every command but the status reads is
   ignored; a page program ANDs its bytes into the array (it can only clear
   bits) and wraps within its 256-byte page. BUSY lasts the datasheet's
   typical time in simulated time (a cycle timer; also checked whenever the
   chip is touched, since simavr's reset drops cycle timers). What the chip
   does at the end (the new bytes, the erased range) is applied then, so
   that a power cut (`flash cut N`, or any power cut) can leave it half done. */
#define FL_PAGE 256u
#define FL_MFR 0xEFu       /* Winbond */
#define FL_MEMTYPE 0x40u   /* W25Q..JV-IQ (SPI) */
#define FL_CHIP_ERASE_US_PER_MIB 2500000u /* tCE: typ 20 s for the 8 MiB W25Q64JV (5 s W25Q16JV, 40 s W25Q128JV) */
enum { FL_OP_NONE, FL_OP_PROGRAM, FL_OP_ERASE };

static struct {
    uint8_t* mem; /* NULL: no flash on this board */
    uint32_t size;
    uint8_t cap;  /* log2(size): the JEDEC ID's capacity byte; the device ID is cap - 1 */
    char cs_port;
    uint8_t cs_bit;
    const char* file; /* -S: NULL for none */
    /* the transaction while CS is low */
    uint8_t cs_level; /* as the chip sees it: high (deselected) until the AVR drives it low */
    uint8_t op;
    uint32_t n;       /* bytes since CS fell */
    uint32_t addr;
    int ignored;      /* sent to a busy or powered-down chip */
    uint8_t buf[FL_PAGE], buf_set[FL_PAGE]; /* a page program's bytes, by column */
    uint8_t col;
    /* the chip */
    int wel, busy, powered_down;
    avr_cycle_count_t busy_until;
    int op_kind;      /* the program or erase in progress while busy */
    uint32_t op_addr, op_len;
    uint8_t op_data[FL_PAGE], op_set[FL_PAGE];
    unsigned long long programs, erases, ops, cuts, cut_at;
    int cut_armed;
} fl;

static uint8_t fl_status1(void) { return (uint8_t)((fl.busy ? 0x01 : 0) | (fl.wel ? 0x02 : 0)); }

/* Applies the operation in progress: whole, or (power cut) only a prefix
   of its bytes, of a length drawn from the operation's ordinal so that a
   cut test replays exactly. */
static void fl_apply(int partial) {
    uint32_t done = fl.op_len; /* erase: bytes from the start; program: columns holding data, in page order */
    if (partial) {
        uint32_t total = fl.op_len;
        if (fl.op_kind == FL_OP_PROGRAM) {
            total = 0;
            for (uint32_t i = 0; i < FL_PAGE; i++) total += fl.op_set[i];
        }
        uint64_t z = fl.ops * 0x9E3779B97F4A7C15ull; /* splitmix64 of the ordinal */
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        z ^= z >> 31;
        /* at least one byte done and one not, when there are two: half done */
        done = total >= 2 ? 1 + (uint32_t)(z % (total - 1)) : 0;
    }
    if (fl.op_kind == FL_OP_ERASE) {
        memset(fl.mem + fl.op_addr, 0xFF, done);
    } else if (fl.op_kind == FL_OP_PROGRAM) {
        for (uint32_t i = 0; i < FL_PAGE && done; i++) {
            if (!fl.op_set[i]) continue;
            fl.mem[fl.op_addr + i] &= fl.op_data[i]; /* NOR: programming only clears bits */
            done--;
        }
    }
    fl.op_kind = FL_OP_NONE;
}

static avr_cycle_count_t on_fl_done(struct avr_t* a, avr_cycle_count_t when, void* param);

static void fl_finish(void) {
    fl_apply(0);
    fl.busy = 0;
    fl.wel = 0;
    avr_cycle_timer_cancel(avr, on_fl_done, NULL);
}

static avr_cycle_count_t on_fl_done(struct avr_t* a, avr_cycle_count_t when, void* param) {
    (void)a, (void)when, (void)param;
    if (fl.busy) fl_finish();
    return 0;
}

/* An operation whose time is up is done, whether or not its timer fired. */
static void fl_tick(void) {
    if (fl.busy && avr->cycle >= fl.busy_until) fl_finish();
}

static void fl_start(int kind, uint32_t addr, uint32_t len, uint32_t usec) {
    fl.op_kind = kind;
    fl.op_addr = addr;
    fl.op_len = len;
    fl.busy = 1; /* WEL stays set until the operation ends */
    fl.busy_until = avr->cycle + avr_usec_to_cycles(avr, usec);
    avr_cycle_timer_register_usec(avr, usec, on_fl_done, NULL);
    fl.ops++;
    if (kind == FL_OP_PROGRAM)
        fl.programs++;
    else
        fl.erases++;
    if (fl.cut_armed && fl.ops >= fl.cut_at) {
        fl.cut_armed = 0;
        fl.cuts++;
        cut_now = 1; /* after this instruction: the operation has started, nothing of it is done */
    }
}

static void fl_erase_cmd(uint32_t len, uint32_t usec) {
    if (fl.n == 4 && fl.wel) fl_start(FL_OP_ERASE, fl.addr & (fl.size - 1) & ~(len - 1), len, usec);
}

/* CS rose: commands that act then (all that change the chip) do so, only
   after a whole command as the datasheet asks (a write enable of exactly 8
   bits, an erase of exactly 32). */
static void fl_deselect(void) {
    fl.cs_level = 1;
    if (fl.n == 0 || fl.ignored) {
        fl.n = 0;
        return;
    }
    switch (fl.op) {
        case 0x06: if (fl.n == 1) fl.wel = 1; break;
        case 0x04: if (fl.n == 1) fl.wel = 0; break;
        case 0xB9: if (fl.n == 1) fl.powered_down = 1; break;
        case 0xAB: fl.powered_down = 0; break;
        case 0x02:
            if (fl.n >= 5 && fl.wel) {
                memcpy(fl.op_data, fl.buf, FL_PAGE);
                memcpy(fl.op_set, fl.buf_set, FL_PAGE);
                fl_start(FL_OP_PROGRAM, fl.addr & (fl.size - 1) & ~(FL_PAGE - 1), FL_PAGE, 400); /* tPP typ 0.4 ms */
            }
            break;
        case 0x20: fl_erase_cmd(4096, 45000); break;     /* tSE typ 45 ms */
        case 0x52: fl_erase_cmd(32768, 120000); break;   /* tBE1 typ 120 ms */
        case 0xD8: fl_erase_cmd(65536, 150000); break;   /* tBE2 typ 150 ms */
        case 0xC7:
        case 0x60:
            if (fl.n == 1 && fl.wel)
                fl_start(FL_OP_ERASE, 0, fl.size,
                         (uint32_t)((unsigned long long)FL_CHIP_ERASE_US_PER_MIB * fl.size / (1u << 20)));
            break;
        default: break;
    }
    fl.n = 0;
}

/* One byte from the master while CS is low; returns the byte shifted out. */
static uint8_t fl_byte(uint8_t in) {
    const uint32_t i = fl.n++;
    if (i == 0) {
        fl.op = in;
        fl.addr = 0;
        /* the status reads work at any time; the rest waits for BUSY to
           clear, and a powered-down chip wakes on ABh only */
        fl.ignored = (fl.busy && in != 0x05 && in != 0x35 && in != 0x15) || (fl.powered_down && in != 0xAB);
        if (in == 0x02) {
            memset(fl.buf, 0xFF, FL_PAGE);
            memset(fl.buf_set, 0, FL_PAGE);
        }
        return 0xFF;
    }
    if (fl.ignored) return 0xFF; /* MISO stays high-impedance: the pull-up */
    const int addr_byte = i <= 3;
    if (addr_byte) fl.addr = (fl.addr << 8) | in;
    switch (fl.op) {
        case 0x05: return fl_status1();
        case 0x35: /* status 2 and 3: no quad enable, no protection, defaults */
        case 0x15: return 0x00;
        case 0x9F: {
            const uint8_t id[3] = {FL_MFR, FL_MEMTYPE, fl.cap};
            return id[(i - 1) % 3];
        }
        case 0x90: /* address 0: manufacturer first; 1: device first; then alternating */
            if (addr_byte) return 0xFF;
            return ((i - 4) + (fl.addr & 1)) % 2 ? (uint8_t)(fl.cap - 1) : FL_MFR;
        case 0xAB: return addr_byte ? 0xFF : (uint8_t)(fl.cap - 1); /* three dummy bytes, then the device ID */
        case 0x0B:
            if (i == 4) return 0xFF; /* the dummy byte */
            /* fall through */
        case 0x03: {
            if (addr_byte) return 0xFF;
            fl.addr &= fl.size - 1; /* the address wraps at the end of the array */
            const uint8_t v = fl.mem[fl.addr];
            fl.addr = (fl.addr + 1) & (fl.size - 1);
            return v;
        }
        case 0x02:
            if (i == 3) fl.col = (uint8_t)fl.addr;
            if (addr_byte) return 0xFF;
            fl.buf[fl.col] = in; /* past the page's end it wraps to the start, overwriting */
            fl.buf_set[fl.col] = 1;
            fl.col++;
            return 0xFF;
        default: return 0xFF;
    }
}

/* ---- parts on I2C (TWI) and SPI ------------------------------------------------------ */

/* -I KIND@ADDR puts a sensor on the AVR's TWI at a 7-bit address (0x76),
   or, for a part that has an SPI interface, on its SPI with the chip
   select (active low) on an AVR pin (`adxl345@B1`). Each part is a
   register model after its datasheet: an ID register, calibration bytes
   (NVM or PROM) the host may replace, conversions that last the datasheet's
   maximum time in simulated time, and result registers that take the raw
   counts the host set (`part ADDR raw ...`) when a conversion ends.

   The bus: simavr's TWI module (avr_twi.c) raises TWI_IRQ_OUTPUT with
   TWI_COND_START and the SLA+R/W byte as the master sends an address, then
   TWI_COND_WRITE or TWI_COND_READ for each data byte (ACK set when the
   master acknowledges a byte it reads), and TWI_COND_STOP. It expects the
   addressed slave to answer at once on TWI_IRQ_INPUT: TWI_COND_ACK with
   data bit 0 set to acknowledge an address or a written byte (else the
   master sees NACK), TWI_COND_READ with the byte for a read. One handler
   here plays every slave on the bus: the part whose address matches
   answers; an address no part has (or a part told to `fail nack`) gets no
   ACK, and a read from nobody returns 0xFF (SDA's pull-up). simavr 1.6
   takes 9 us per address or data byte whatever TWBR says.

   Conversions are computed when someone looks (a transaction's START, a
   register write, a host command), from the simulated cycle: nothing runs
   between. A host command first brings the part up to date, so that raw
   values set now are the ones the next conversion to end latches, and
   conversions that ended before keep the old ones. A read transaction sees
   the registers as they were at its START, as the BMP280's and MPU-6050's
   data shadowing promise for a burst read. */
#define MAX_PARTS 8
#define MAX_RAW 7
enum { PK_BMP280, PK_MS5611, PK_MPU6050, PK_ADXL345, N_PART_KINDS };
enum { PF_OK, PF_NACK, PF_STUCK, N_PART_FAILS };
static const char* const part_fail_names[N_PART_FAILS] = {"ok", "nack", "stuck"};

typedef struct {
    const char* name;
    uint8_t addr[2];            /* the 7-bit addresses its pins allow */
    int spi;                    /* it also has an SPI interface */
    uint8_t cal_reg, cal_len;   /* the calibration block (the MS5611: its PROM's 16 bytes) */
    int n_raw;
    const char* raw_names[MAX_RAW];
    long raw_min, raw_max;
} part_kind_t;

static const part_kind_t part_kinds[N_PART_KINDS] = {
    {"bmp280", {0x76, 0x77}, 0, 0x88, 24, 2, {"adc_P", "adc_T"}, 0, 0xFFFFF},
    {"ms5611", {0x76, 0x77}, 0, 0, 16, 2, {"D1", "D2"}, 0, 0xFFFFFF},
    {"mpu6050", {0x68, 0x69}, 0, 0x0D, 4, 7, {"ax", "ay", "az", "temp", "gx", "gy", "gz"}, -32768, 32767},
    {"adxl345", {0x53, 0x1D}, 1, 0x1E, 3, 3, {"x", "y", "z"}, -32768, 32767},
};

typedef struct {
    int kind;
    uint8_t addr;       /* 7-bit I2C address; 0 on SPI */
    char cs_port;       /* SPI: the chip select's pin */
    uint8_t cs_bit, cs_level;
    int fail;
    uint8_t reg[256];   /* the register file (the MS5611 has none) */
    uint8_t prom[16];   /* the MS5611's PROM, 8 words big-endian */
    long raw[MAX_RAW];  /* what the host set: the next conversion's result */
    long held[MAX_RAW]; /* the MS5611's last conversion result of D1 and D2 */
    /* the transaction in progress */
    uint8_t ptr, spi_read, spi_mb;
    uint32_t n;
    uint8_t out[3], out_n, out_i; /* the MS5611's answer to its last command */
    /* conversions */
    int busy;                        /* a BMP280 measurement or an MS5611 conversion runs */
    avr_cycle_count_t t0, end, period, t_meas;
    unsigned long long done;         /* conversions since t0 (periodic ones) */
    unsigned long long conversions;  /* conversions ended since power-on: `part ADDR info` */
    int ch, ready;                   /* the MS5611: the channel converted, a result unread */
    uint32_t result;
} part_t;

static part_t parts[MAX_PARTS];
static int parse_u64(const char* s, unsigned long long* out);
static int n_parts;
static avr_irq_t* twi_in;   /* TWI_IRQ_INPUT: the slaves' answers */
static part_t* twi_peer;    /* the part addressed since the last START, or NULL */
static int twi_reading;
static avr_irq_t* spi_miso; /* SPI_IRQ_INPUT, shared by the flash and the SPI parts */

static avr_cycle_count_t ns_to_cycles(uint64_t ns) {
    return (avr_cycle_count_t)((ns * f_cpu + 500000000ull) / 1000000000ull);
}

static void put_be16(uint8_t* p, long v) {
    p[0] = (uint8_t)((unsigned long)v >> 8);
    p[1] = (uint8_t)v;
}

/* BMP280 (Bosch datasheet BST-BMP280-DS001): its example calibration
   (section 8.2's worked example: dig_T1 = 27504 ... dig_P9 = 6000) and raw
   counts (adc_T = 519888, adc_P = 415148: 25.08 C, 1006.53 hPa). */
static const uint8_t bmp280_cal[24] = {0x70, 0x6B, 0x43, 0x67, 0x18, 0xFC, 0x7D, 0x8E, 0x43, 0xD6, 0xD0, 0x0B,
                                       0x27, 0x0B, 0x8C, 0x00, 0xF9, 0xFF, 0x8C, 0x3C, 0xF8, 0xC6, 0x70, 0x17};
/* t_standby in normal mode, us, by config's t_sb (BMP280; the BME280's differ) */
static const uint32_t bmp280_t_sb_us[8] = {500, 62500, 125000, 250000, 500000, 1000000, 2000000, 4000000};

/* The measurement time for ctrl_meas's oversampling, the datasheet's
   maximum (section 9.1): 1.25 ms + 2.3 ms x osrs_t + (2.3 ms x osrs_p +
   0.575 ms when pressure is measured): 6.4 ms at x1/x1 ... 43.2 ms at
   x2/x16 (typical 5.5 ... 37.5 ms). */
static avr_cycle_count_t bmp280_t_meas(const part_t* p) {
    static const uint8_t os[8] = {0, 1, 2, 4, 8, 16, 16, 16};
    const uint64_t t = os[p->reg[0xF4] >> 5 & 7], pr = os[p->reg[0xF4] >> 2 & 7];
    return ns_to_cycles(1250000 + 2300000 * t + (pr ? 2300000 * pr + 575000 : 0));
}

static void bmp280_put20(uint8_t* r, uint32_t v) {
    r[0] = (uint8_t)(v >> 12);
    r[1] = (uint8_t)(v >> 4);
    r[2] = (uint8_t)((v & 0xF) << 4);
}

/* A measurement ends: adc_P and adc_T take the host's counts (0x80000 for
   a measurement skipped, osrs 0, as on the part); `stuck`: they keep theirs. */
static void bmp280_latch(part_t* p) {
    p->conversions++;
    if (p->fail == PF_STUCK) return;
    bmp280_put20(&p->reg[0xF7], (p->reg[0xF4] >> 2 & 7) ? (uint32_t)p->raw[0] : 0x80000u);
    bmp280_put20(&p->reg[0xFA], (p->reg[0xF4] >> 5 & 7) ? (uint32_t)p->raw[1] : 0x80000u);
}

/* MS5611-01BA03 (TE datasheet): its example PROM (C1 = 40127 ... C6 =
   28312) and counts (D1 = 9085466, D2 = 8569150: 20.07 C, 1000.09 mbar);
   word 7's low 4 bits are the CRC-4 of AN520 over the 8 words. */
static const uint16_t ms5611_prom[8] = {0x0000, 40127, 36924, 23317, 23282, 33464, 28312, 0x3400};
/* conversion time by OSR 256, 512, 1024, 2048, 4096: the datasheet's maximum, us */
static const uint32_t ms5611_conv_us[5] = {600, 1170, 2280, 4540, 9040};

static uint8_t ms5611_crc4(const uint8_t* prom) {
    uint16_t w[8], rem = 0;
    for (int i = 0; i < 8; i++) w[i] = (uint16_t)(prom[2 * i] << 8 | prom[2 * i + 1]);
    w[7] &= 0xFF00;
    for (int i = 0; i < 16; i++) {
        rem ^= (i & 1) ? (w[i >> 1] & 0x00FF) : (w[i >> 1] >> 8);
        for (int b = 0; b < 8; b++) rem = (rem & 0x8000) ? (uint16_t)((rem << 1) ^ 0x3000) : (uint16_t)(rem << 1);
    }
    return (uint8_t)(rem >> 12 & 0xF);
}

/* MPU-6050 (register map RM-MPU-6000A-00): samples come at the sample
   rate, the gyro's output rate (8 kHz with the DLPF off, CONFIG 0 or 7;
   else 1 kHz) / (1 + SMPLRT_DIV), while PWR_MGMT_1's SLEEP bit is clear. */
static avr_cycle_count_t mpu6050_period(const part_t* p) {
    const uint8_t dlpf = p->reg[0x1A] & 7;
    const uint64_t gyro_hz = (dlpf == 0 || dlpf == 7) ? 8000 : 1000;
    return (avr_cycle_count_t)((uint64_t)f_cpu * (1u + p->reg[0x19]) / gyro_hz);
}

/* ADXL345 (Analog Devices datasheet, rev. G): in measure mode (POWER_CTL
   bit 3) samples come at BW_RATE's output data rate, 3200 Hz / 2^(15 - rate). */
static avr_cycle_count_t adxl345_period(const part_t* p) {
    const unsigned rate = p->reg[0x2C] & 15;
    return (avr_cycle_count_t)(((uint64_t)f_cpu << (15 - rate)) / 3200);
}

/* A sample of the MPU-6050 or the ADXL345: its data-ready flag set, the
   data registers the host's counts (`stuck`: theirs kept). */
static void sample_latch(part_t* p) {
    p->conversions++;
    if (p->kind == PK_MPU6050) {
        p->reg[0x3A] |= 0x01; /* INT_STATUS DATA_RDY_INT */
        if (p->fail != PF_STUCK)
            for (int i = 0; i < 7; i++) put_be16(&p->reg[0x3B + 2 * i], p->raw[i]);
    } else {
        p->reg[0x30] |= 0x80; /* INT_SOURCE DATA_READY */
        if (p->fail != PF_STUCK)
            for (int i = 0; i < 3; i++) {
                p->reg[0x32 + 2 * i] = (uint8_t)p->raw[i];
                p->reg[0x33 + 2 * i] = (uint8_t)((unsigned long)p->raw[i] >> 8);
            }
    }
}

/* The part's registers as at power-on (or its soft reset): the calibration
   block (non-volatile on the BMP280 and MS5611; on the others the host's
   fixture) and the host's raw values stay. */
static void part_power_on(part_t* p) {
    const part_kind_t* k = &part_kinds[p->kind];
    uint8_t cal[24];
    memcpy(cal, p->reg + k->cal_reg, k->cal_len);
    memset(p->reg, 0, sizeof p->reg);
    if (p->kind != PK_MS5611) memcpy(p->reg + k->cal_reg, cal, k->cal_len);
    p->busy = p->ready = 0;
    p->done = 0;
    p->t0 = avr->cycle;
    p->n = 0;
    p->out_n = p->out_i = 0;
    p->ptr = 0;
    p->conversions = 0;
    switch (p->kind) {
        case PK_BMP280:
            p->reg[0xD0] = 0x58;
            bmp280_put20(&p->reg[0xF7], 0x80000u); /* the data registers' reset values */
            bmp280_put20(&p->reg[0xFA], 0x80000u);
            break;
        case PK_MPU6050:
            p->reg[0x6B] = 0x40; /* SLEEP */
            p->reg[0x75] = 0x68; /* WHO_AM_I: 0x68 whatever AD0 says */
            break;
        case PK_ADXL345:
            p->reg[0x00] = 0xE5;
            p->reg[0x2C] = 0x0A; /* 100 Hz */
            p->reg[0x30] = 0x02;
            break;
        default: break;
    }
}

/* Brings the part's conversions up to the current cycle. */
static void part_tick(part_t* p) {
    const avr_cycle_count_t now = avr->cycle;
    if (now < p->t0) p->t0 = now; /* cannot happen; keeps the arithmetic safe */
    switch (p->kind) {
        case PK_BMP280:
            if ((p->reg[0xF4] & 3) == 3) { /* normal: t_meas, t_standby, t_meas, ... from t0 */
                const avr_cycle_count_t el = now - p->t0;
                const unsigned long long done = el / p->period + (el % p->period >= p->t_meas);
                if (done > p->done) {
                    p->conversions += done - p->done - 1;
                    bmp280_latch(p);
                    p->done = done;
                }
                p->busy = el % p->period < p->t_meas;
            } else if (p->busy && now >= p->end) { /* forced: back to sleep */
                bmp280_latch(p);
                p->busy = 0;
                p->reg[0xF4] &= (uint8_t)~3u;
            }
            p->reg[0xF3] = p->busy ? 0x08 : 0x00; /* status: measuring */
            break;
        case PK_MS5611:
            if (p->busy && now >= p->end) {
                p->busy = 0;
                p->conversions++;
                if (p->fail != PF_STUCK) p->held[p->ch] = p->raw[p->ch];
                p->result = (uint32_t)p->held[p->ch];
                p->ready = 1;
            }
            break;
        case PK_MPU6050:
        case PK_ADXL345: {
            const int on = p->kind == PK_MPU6050 ? !(p->reg[0x6B] & 0x40) : (p->reg[0x2D] & 0x08) != 0;
            if (!on) break;
            const unsigned long long done = (now - p->t0) / p->period;
            if (done > p->done) {
                p->conversions += done - p->done - 1;
                sample_latch(p);
                p->done = done;
            }
            break;
        }
        default: break;
    }
}

/* Periodic sampling (re)starts now: the first sample one period later. */
static void part_restart(part_t* p) {
    p->t0 = avr->cycle;
    p->done = 0;
    if (p->kind == PK_MPU6050) p->period = mpu6050_period(p);
    if (p->kind == PK_ADXL345) p->period = adxl345_period(p);
    if (p->kind == PK_BMP280) {
        p->t_meas = bmp280_t_meas(p);
        p->period = p->t_meas + ns_to_cycles(1000ull * bmp280_t_sb_us[p->reg[0xF5] >> 5]);
    }
}

/* The master writes register r of a register-file part. */
static void part_reg_write(part_t* p, uint8_t r, uint8_t v) {
    part_tick(p);
    switch (p->kind) {
        case PK_BMP280:
            if (r == 0xE0) {
                if (v == 0xB6) part_power_on(p); /* soft reset */
            } else if (r == 0xF4) {
                p->reg[r] = v;
                if ((v & 3) == 3) { /* normal: the first measurement starts now */
                    part_restart(p);
                    p->busy = 1;
                } else if (v & 3) { /* forced: one measurement */
                    p->t_meas = bmp280_t_meas(p);
                    p->end = avr->cycle + p->t_meas;
                    p->busy = 1;
                } else {
                    p->busy = 0;
                }
                p->reg[0xF3] = p->busy ? 0x08 : 0x00;
            } else if (r == 0xF5) {
                p->reg[r] = v;
                if ((p->reg[0xF4] & 3) == 3) part_restart(p);
            }
            break; /* the rest (ID, calibration, data, status) is read-only */
        case PK_MPU6050:
            if (r == 0x6B) {
                if (v & 0x80) { /* DEVICE_RESET */
                    part_power_on(p);
                    break;
                }
                const int woke = (p->reg[r] & 0x40) && !(v & 0x40);
                p->reg[r] = v;
                if (woke) part_restart(p);
            } else if (r == 0x19 || r == 0x1A) {
                p->reg[r] = v;
                part_restart(p);
            } else if (r != 0x75 && (r < 0x3A || r > 0x60)) {
                p->reg[r] = v;
            }
            break;
        case PK_ADXL345:
            if (r == 0x2D) {
                const int starts = !(p->reg[r] & 0x08) && (v & 0x08);
                p->reg[r] = v;
                if (starts) part_restart(p);
            } else if (r == 0x2C) {
                p->reg[r] = v;
                part_restart(p);
            } else if (r >= 0x1D && r <= 0x38 && r != 0x30 && (r < 0x32 || r > 0x37)) {
                p->reg[r] = v;
            }
            break;
        default: break;
    }
}

/* The master reads register r: reading clears data-ready flags. */
static uint8_t part_reg_read(part_t* p, uint8_t r) {
    const uint8_t v = p->reg[r];
    if (p->kind == PK_MPU6050 && r == 0x3A) p->reg[0x3A] &= (uint8_t)~0x01u;
    if (p->kind == PK_ADXL345 && r >= 0x32 && r <= 0x37) p->reg[0x30] &= (uint8_t)~0x80u;
    return v;
}

/* The MS5611's commands (one byte written). */
static void ms5611_command(part_t* p, uint8_t c) {
    part_tick(p);
    p->out_n = p->out_i = 0;
    if (c == 0x1E) { /* RESET: the PROM reloaded, a conversion dropped */
        p->busy = p->ready = 0;
    } else if (c == 0x00) { /* ADC read: 0 during a conversion, with none, or read a second time */
        const uint32_t v = (!p->busy && p->ready) ? p->result : 0;
        if (!p->busy) p->ready = 0;
        p->out[0] = (uint8_t)(v >> 16), p->out[1] = (uint8_t)(v >> 8), p->out[2] = (uint8_t)v;
        p->out_n = 3;
    } else if ((c & 0xF1) == 0xA0) { /* PROM read, word (c >> 1) & 7 */
        memcpy(p->out, p->prom + 2 * ((c >> 1) & 7), 2);
        p->out_n = 2;
    } else if ((c & 0xE1) == 0x40 && (c & 0x0F) <= 8) { /* CONVERT D1 (0x40..0x48) or D2 (0x50..0x58) */
        if (p->busy) return; /* one conversion at a time */
        p->ch = (c & 0x10) ? 1 : 0;
        p->end = avr->cycle + ns_to_cycles(1000ull * ms5611_conv_us[(c & 0x0F) >> 1]);
        p->busy = 1;
        p->ready = 0;
    }
}

/* An I2C transaction starts (START or repeated START with its address). */
static void part_begin(part_t* p) {
    part_tick(p);
    p->n = 0;
}

/* A byte written to the part over I2C: the register pointer, then data
   (the BMP280: pairs of register and data; the others auto-increment). */
static void part_i2c_write(part_t* p, uint8_t v) {
    const uint32_t i = p->n++;
    if (p->kind == PK_MS5611) {
        if (i == 0) ms5611_command(p, v);
        return;
    }
    if (i == 0 || (p->kind == PK_BMP280 && i % 2 == 0)) {
        p->ptr = v;
        return;
    }
    part_reg_write(p, p->ptr, v);
    if (p->kind != PK_BMP280) p->ptr++;
}

/* A byte the part returns over I2C: registers from the pointer on. */
static uint8_t part_i2c_read(part_t* p) {
    if (p->kind == PK_MS5611) return p->out_i < p->out_n ? p->out[p->out_i++] : 0x00;
    return part_reg_read(p, p->ptr++);
}

/* A byte over SPI while selected (ADXL345: a command byte, R/W bit 7,
   multi-byte bit 6, the register in bits 5-0; then data). */
static uint8_t part_spi_byte(part_t* p, uint8_t in) {
    const uint32_t i = p->n++;
    if (i == 0) {
        p->spi_read = in >> 7 & 1;
        p->spi_mb = in >> 6 & 1;
        p->ptr = in & 0x3F;
        return 0xFF;
    }
    uint8_t out = 0xFF;
    if (p->spi_read)
        out = part_reg_read(p, p->ptr);
    else
        part_reg_write(p, p->ptr, in);
    if (p->spi_mb) p->ptr = (p->ptr + 1) & 0x3F;
    return out;
}

static part_t* part_at(uint8_t addr7) {
    for (int i = 0; i < n_parts; i++)
        if (parts[i].addr && parts[i].addr == addr7) return &parts[i];
    return NULL;
}

/* Two fixes to simavr 1.6's TWI master, made with parts on the bus so that
   firmware sees what an ATmega does (without -I the TWI is simavr's own):
   - TWINT is a "sticky" flag there that nothing clears: once set it reads
     1 for ever, and a polling master (`while (!(TWCR & _BV(TWINT)))`)
     reads the status before the byte is done. Writing a one to TWINT clears
     it, as on the part; the TWI module sets it again when the next status
     comes (a handler after the module's own on TWCR).
   - An SLA+W (the address byte is written to TWDR, which simavr takes for
     a data byte) ends with the data-byte statuses 0x28 / 0x30; the part's
     are 0x18 (SLA+W sent, ACK) and 0x20 (NACK), so the first status after
     an SLA+W is corrected (TWI_IRQ_STATUS comes as TWSR is set). It still
     comes at once where the other bytes take simavr's 9 us. */
#define TWSR_ADDR 0xB9 /* data-space addresses of TWSR and TWCR on the ATmega328P and ATmega2560 */
#define TWCR_ADDR 0xBC
static int twi_sla_w; /* an SLA+W went out; its status is still to come */

static void on_twcr_write(struct avr_t* a, avr_io_addr_t addr, uint8_t v, void* param) {
    (void)addr, (void)param;
    if (v & 0x80) a->data[TWCR_ADDR] &= 0x7F;
}

static void on_twi_status(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq, (void)param;
    if (!twi_sla_w) return;
    twi_sla_w = 0;
    if (value == 0x28 || value == 0x30)
        avr->data[TWSR_ADDR] = (uint8_t)((avr->data[TWSR_ADDR] & 0x07) | (value == 0x28 ? 0x18 : 0x20));
}

static void twi_answer(uint8_t msg, uint8_t addr, uint8_t data) {
    avr_twi_msg_irq_t m;
    m.u.v = 0;
    m.u.twi.msg = msg;
    m.u.twi.addr = addr;
    m.u.twi.data = data;
    avr_raise_irq(twi_in, m.u.v);
}

/* Every slave on the bus: see the section's comment. */
static void on_twi_out(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq, (void)param;
    avr_twi_msg_irq_t m;
    m.u.v = value;
    const uint8_t msg = m.u.twi.msg, addr = m.u.twi.addr;
    if (msg & (TWI_COND_STOP | TWI_COND_START)) twi_peer = NULL;
    twi_sla_w = (msg & TWI_COND_START) && !(addr & 1);
    if (msg & TWI_COND_START) {
        part_t* p = part_at(addr >> 1);
        if (!p || p->fail == PF_NACK) return; /* nobody pulls SDA low: NACK */
        twi_peer = p;
        twi_reading = addr & 1;
        part_begin(p);
        twi_answer(TWI_COND_ACK, addr, 1);
        return;
    }
    part_t* p = twi_peer && twi_peer->fail != PF_NACK ? twi_peer : NULL;
    if ((msg & TWI_COND_WRITE) && p && !twi_reading) {
        part_i2c_write(p, m.u.twi.data);
        twi_answer(TWI_COND_ACK, addr, 1);
    } else if (msg & TWI_COND_READ) {
        twi_answer(TWI_COND_READ, addr, p && twi_reading ? part_i2c_read(p) : 0xFF);
    }
}

static void on_part_cs(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    part_t* p = (part_t*)param;
    const uint8_t level = value ? 1 : 0;
    if (level == p->cs_level) return;
    p->cs_level = level;
    if (!level) {
        part_tick(p);
        p->n = 0;
    }
}

/* The byte the SPI parts drive on MISO for `in`, ANDed as on an open bus
   (one selected at a time is the firmware's business). */
static uint8_t parts_spi_byte(uint8_t in) {
    uint8_t out = 0xFF;
    for (int i = 0; i < n_parts; i++) {
        part_t* p = &parts[i];
        if (p->cs_port && !p->cs_level && p->fail != PF_NACK) out &= part_spi_byte(p, in);
    }
    return out;
}

/* The board loses power, or the MCU resets (`power` 0): transactions on
   the wires end (the AVR lets go of the lines); after a power cut every
   part comes back as at power-on. */
static void parts_reset(int power) {
    twi_peer = NULL;
    for (int i = 0; i < n_parts; i++) {
        parts[i].cs_level = 1;
        parts[i].n = 0;
        if (power) part_power_on(&parts[i]);
    }
}

/* -I KIND@ADDR: 0 when added, else a message on standard error. */
static int part_add(const char* spec) {
    char kind[16];
    const char* at = strchr(spec, '@');
    if (!at || (size_t)(at - spec) >= sizeof kind) goto usage;
    memcpy(kind, spec, (size_t)(at - spec));
    kind[at - spec] = 0;
    int k = -1;
    for (int i = 0; i < N_PART_KINDS; i++)
        if (!strcmp(kind, part_kinds[i].name)) k = i;
    if (k < 0) goto usage;
    if (n_parts == MAX_PARTS) {
        fprintf(stderr, "simboard: -I: at most %d parts\n", MAX_PARTS);
        return -1;
    }
    part_t* p = &parts[n_parts];
    memset(p, 0, sizeof *p);
    p->kind = k;
    p->cs_level = 1;
    const char* a = at + 1;
    unsigned long long v;
    if (strlen(a) == 2 && a[0] >= 'A' && a[0] <= 'L' && a[1] >= '0' && a[1] <= '7') {
        if (!part_kinds[k].spi) {
            fprintf(stderr, "simboard: -I %s: the %s is on I2C only: give its address\n", spec, kind);
            return -1;
        }
        p->cs_port = a[0];
        p->cs_bit = (uint8_t)(a[1] - '0');
        for (int i = 0; i < n_parts; i++)
            if (parts[i].cs_port == p->cs_port && parts[i].cs_bit == p->cs_bit) goto taken;
    } else if (!parse_u64(a, &v) && (v == part_kinds[k].addr[0] || v == part_kinds[k].addr[1])) {
        p->addr = (uint8_t)v;
        if (part_at(p->addr)) goto taken;
    } else {
        fprintf(stderr, "simboard: -I %s: the %s answers at 0x%02x or 0x%02x%s\n", spec, kind, part_kinds[k].addr[0],
                part_kinds[k].addr[1], part_kinds[k].spi ? ", or on SPI with its chip select on a pin (B1)" : "");
        return -1;
    }
    if (k == PK_BMP280) memcpy(p->reg + 0x88, bmp280_cal, sizeof bmp280_cal), p->raw[0] = 415148, p->raw[1] = 519888;
    if (k == PK_MS5611) {
        for (int i = 0; i < 8; i++) put_be16(p->prom + 2 * i, ms5611_prom[i]);
        p->prom[15] |= ms5611_crc4(p->prom);
        p->raw[0] = 9085466;
        p->raw[1] = 8569150;
    }
    if (k == PK_MPU6050) p->raw[2] = 16384, p->raw[3] = -3920; /* 1 g at +-2 g; 25 C: raw / 340 + 36.53 */
    if (k == PK_ADXL345) p->raw[2] = 256;                        /* 1 g at +-2 g, 10 bits */
    n_parts++;
    return 0;
taken:
    fprintf(stderr, "simboard: -I %s: another part is there already\n", spec);
    return -1;
usage:
    fprintf(stderr, "simboard: -I KIND@ADDR: KIND one of bmp280 ms5611 mpu6050 adxl345, ADDR a 7-bit address "
                    "(0x76) or an SPI chip-select pin (B1)\n");
    return -1;
}

/* Every byte the AVR's SPI shifts out: the flash and the SPI parts (-I)
   answer when selected. Deselected, a chip leaves MISO alone and the
   pull-up reads 0xFF; the board answers anyway, because simavr 1.6
   completes a master's transfer (SPIF) only when a byte comes in. */
static void on_spi_mosi(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq, (void)param;
    uint8_t out = parts_spi_byte((uint8_t)value);
    if (fl.mem) {
        fl_tick();
        if (!fl.cs_level) out &= fl_byte((uint8_t)value);
    }
    avr_raise_irq(spi_miso, out);
}

static void on_fl_cs(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq, (void)param;
    const uint8_t level = value ? 1 : 0;
    if (level == fl.cs_level) return;
    fl_tick();
    if (level) {
        fl_deselect();
    } else {
        fl.cs_level = 0;
        fl.n = 0;
    }
}

/* A digital input driven from outside to `level`. simavr drops a raise of
   the value an IRQ already holds, but a reset clears the PIN register
   without telling the IRQ: the old value is forgotten first, so that the
   level reaches the pin however it was driven before (every path that
   drives a pin goes through here: din, batch, scheduled changes). */
static void drive_pin(avr_t* a, char port, uint8_t bit, uint32_t level) {
    avr_irq_t* irq = avr_io_getirq(a, AVR_IOCTL_IOPORT_GETIRQ(port), bit);
    irq->value = !level;
    avr_raise_irq(irq, level);
}

/* ---- resets and their causes ---------------------------------------------------------- */

/* Firmware learns why it restarted from MCUSR (ATmega328P and ATmega2560:
   PORF 0x01, EXTRF 0x02, BORF 0x04, WDRF 0x08), read at boot. simavr 1.6's
   avr_reset clears every I/O register, MCUSR included, and only avr_init
   sets PORF: after a plain avr_reset the firmware would read no cause at
   all. mcu_reset leaves exactly its cause's flag there. */
enum { CAUSE_BROWNOUT, CAUSE_WATCHDOG, CAUSE_EXTERNAL, CAUSE_POWER, N_CAUSES };
static const char* const cause_names[N_CAUSES] = {"brownout", "watchdog", "external", "power"};

/* -R SEED: the bytes a power-on leaves in SRAM. A real power-on leaves
   whatever the cells settle to; zeros (simavr's) or the old contents could
   pass a firmware's check of a value kept in RAM. One generator for the
   run, so that the same seed gives the same bytes and a second power-on
   others. */
static uint64_t ram_rng = 1;

static uint64_t splitmix64(uint64_t* s) {
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static avr_watchdog_t* watchdog_of(avr_t* a) {
    for (avr_io_t* p = a->io_port; p; p = p->next)
        if (p->kind && !strcmp(p->kind, "watchdog")) return (avr_watchdog_t*)p;
    return NULL;
}

/* The MCU resets for `cause`: registers, I/O and the program counter as at
   power-on; the cycle count (the co-simulation's clock) goes on. SRAM
   keeps its bytes, except after a power-on, which fills it from -R's
   generator. A watchdog reset goes through simavr's own path (its
   watchdog module's reset context), so the watchdog comes back enabled
   at its shortest period with WDRF set, as on the part: firmware must
   clear WDRF and turn it off early, or it resets again 16 ms later. */
static void mcu_reset(avr_t* a, int cause) {
    avr_watchdog_t* wd = cause == CAUSE_WATCHDOG ? watchdog_of(a) : NULL;
    if (wd && !wd->reset_context.wdrf) { /* else its own reset is already pending: the same path */
        wd->reset_context.avr_run = a->run;
        wd->reset_context.wdrf = 1;
    }
    /* Every pin becomes an input at the reset: a watched output the firmware
       drove high is let go then (the circuit's pull-down takes it low), not
       when the new boot writes its port again. simavr clears the registers
       without telling the pins' IRQs, so the edge is recorded here. */
    uint8_t let_go[MAX_WATCH] = {0};
    for (int i = 0; i < MAX_WATCH; i++) {
        avr_ioport_state_t st;
        watch_t* w = &watches[i];
        if (w->active && w->level && port_state(w->port, &st) == 0 && (st.ddr >> w->bit & 1u)) let_go[i] = 1;
    }
    avr_cycle_count_t cycle = a->cycle;
    avr_reset(a);
    lvl_setup(a);
    a->cycle = cycle;
    for (int i = 0; i < MAX_WATCH; i++) {
        if (!watches[i].active) continue;
        if (let_go[i]) {
            on_pin(NULL, 0, &watches[i]);
            /* and its IRQ told so: else simavr would drop the next raise to 1 as no change */
            avr_io_getirq(a, AVR_IOCTL_IOPORT_GETIRQ(watches[i].port), watches[i].bit)->value = 0;
        }
    }
    if (cause == CAUSE_POWER)
        for (uint32_t addr = (uint32_t)a->ioend + 1; addr <= a->ramend; addr += 8) {
            uint64_t r = splitmix64(&ram_rng);
            for (uint32_t i = 0; i < 8 && addr + i <= a->ramend; i++) a->data[addr + i] = (uint8_t)(r >> (8 * i));
        }
    const avr_regbit_t flag = cause == CAUSE_POWER      ? a->reset_flags.porf
                              : cause == CAUSE_EXTERNAL ? a->reset_flags.extrf
                              : cause == CAUSE_WATCHDOG ? a->reset_flags.wdrf
                                                        : a->reset_flags.borf;
    if (flag.reg) a->data[flag.reg] = (uint8_t)(flag.mask << flag.bit); /* that flag alone */
}

/* The board loses power (`eeprom cut`, `flash cut`, `reset power`): the
   chip's operation in progress stays half done, its latches and the
   transaction on the wire are lost; the AVR comes back with a power-on
   reset (MCUSR = PORF, SRAM garbage): firmware that resumes from RAM after
   a brown-out must not find anything to resume after a power cut. */
static void power_cut(avr_t* a) {
    cut_now = 0;
    if (fl.mem) {
        fl_tick();
        if (fl.busy) fl_apply(1);
        fl.busy = fl.wel = fl.powered_down = 0;
        avr_cycle_timer_cancel(a, on_fl_done, NULL);
    }
    mcu_reset(a, CAUSE_POWER);
    fl.cs_level = 1; /* CS floats: the pull-up */
    fl.n = 0;
    parts_reset(1);
}

/* ---- files that keep a memory between runs (-S, -E) ------------------------------------ */

/* Reads FILE into buf if it exists: 0 when read or absent, -1 (said on
   standard error) when unreadable or of another size. */
static int image_load(const char* path, uint8_t* buf, size_t size, const char* what) {
    FILE* f = fopen(path, "rb");
    if (!f) {
        if (errno == ENOENT) return 0; /* the first run: starts blank, saved at exit */
        fprintf(stderr, "simboard: cannot read %s (%s): %s\n", path, what, strerror(errno));
        return -1;
    }
    struct stat st;
    if (fstat(fileno(f), &st) != 0 || (unsigned long long)st.st_size != (unsigned long long)size) {
        fprintf(stderr, "simboard: %s holds %lld bytes, the %s has %zu: a file of another chip or board\n", path,
                (long long)st.st_size, what, size);
        fclose(f);
        return -1;
    }
    size_t got = fread(buf, 1, size, f);
    fclose(f);
    if (got != size) {
        fprintf(stderr, "simboard: cannot read %s (%s): short read\n", path, what);
        return -1;
    }
    return 0;
}

/* Writes buf to FILE through a temporary file renamed over it, so that a
   harness stopped meanwhile leaves the old contents whole. */
static int image_save(const char* path, const uint8_t* buf, size_t size, const char* what) {
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
    FILE* f = fopen(tmp, "wb");
    int ok = f && fwrite(buf, 1, size, f) == size;
    if (f && fclose(f) != 0) ok = 0;
    if (ok && rename(tmp, path) != 0) ok = 0;
    if (!ok) {
        fprintf(stderr, "simboard: cannot save the %s in %s: %s\n", what, path, strerror(errno));
        unlink(tmp);
        return -1;
    }
    return 0;
}

/* simavr's EEPROM module lends its bytes (GET with no buffer; its return
   value says nothing on some versions: the pointer does). */
static uint8_t* eeprom_bytes(void) {
    avr_eeprom_desc_t d = {NULL, 0, avr->e2end + 1u};
    avr_ioctl(avr, AVR_IOCTL_EEPROM_GET, &d);
    return d.ee;
}

#define SMCR_ADDR 0x53 /* data-space address of SMCR on the ATmega328P and ATmega2560; SE is its bit 0 */
#define SMCR_SE 0x01

/* Runs until cycle `target` (when has_target), a limit, the firmware
   stopping, SIGINT, or (watch_input) a command arriving on the control
   channel. Returns why it stopped. */
static const char* run_until(int has_target, avr_cycle_count_t target, int realtime, int watch_input) {
    interrupted = 0;
    if (halted) return avr->state == cpu_Crashed ? "crashed" : "done";
    if (wall_limit > 0 && wall_now() - wall_start >= wall_limit) return "wall-limit";
    if (cycle_limit && avr->cycle >= cycle_limit) return "sim-limit";
    if (has_target && avr->cycle >= target) return "target";
    const avr_cycle_count_t c0 = avr->cycle;
    const double w0 = wall_now();
    /* one comparison per instruction: the earlier of the target and the limit */
    avr_cycle_count_t stop_at = has_target ? target : ~(avr_cycle_count_t)0;
    if (cycle_limit && cycle_limit < stop_at) stop_at = cycle_limit;
    /* a sleeping core wakes there (it sleeps to its next cycle timer), not at the next event after it */
    const int wake = stop_at != ~(avr_cycle_count_t)0;
    if (wake) avr_cycle_timer_register(avr, stop_at - avr->cycle, on_target, NULL);
    const char* why = NULL;
    while (!why) {
        avr_t* const a = avr; /* a local: the compiler need not reload it after each instruction */
        for (int i = 0; i < RUN_BATCH; i++) {
            if (a->cycle >= stop_at) {
                why = (has_target && a->cycle >= target) ? "target" : "sim-limit";
                break;
            }
            const avr_cycle_count_t c0 = a->cycle;
            const int slept = a->state == cpu_Sleeping;
            const avr_flashaddr_t pc0 = a->pc;
            /* A SLEEP with SMCR's SE bit clear does nothing on the part; simavr
               sleeps whatever SE holds, so such a SLEEP runs as a NOP here (its
               opcode swapped for the NOP's for the one step).
               tests/regression/test_the_simulated_board_does_not_sleep_with_sleep_enable_clear.py */
            const int nop_sleep = !slept && pc0 + 1 <= a->flashend && a->flash[pc0 + 1] == 0x95 &&
                                  a->flash[pc0] == 0x88 && !(a->data[SMCR_ADDR] & SMCR_SE);
            if (__builtin_expect(nop_sleep, 0)) a->flash[pc0 + 1] = a->flash[pc0] = 0x00;
            int st = avr_run(a);
            if (__builtin_expect(nop_sleep, 0)) a->flash[pc0 + 1] = 0x95, a->flash[pc0] = 0x88;
            if (__builtin_expect(cut_now, 0)) power_cut(a);
            if (prof_n) prof_step(a, c0, slept, pc0);
            if (st == cpu_Done || st == cpu_Crashed) {
                halted = 1;
                why = st == cpu_Crashed ? "crashed" : "done";
                break;
            }
        }
        uart_service();
        const double now = wall_now();
        if (!why && wall_limit > 0 && now - wall_start >= wall_limit) why = "wall-limit";
        if (!why && interrupted) why = "interrupted";
        if (!why && watch_input && (line_ready() || (input_fill(0), line_ready() || in_eof))) why = "interrupted";
        /* A pty reader that falls behind holds the board back rather than lose bytes. */
        while (!why && uart_mode == UART_PTY && pty_reader && bytes_pending(&uart_out) > UART_HIGH_WATER) {
            sleep_s(0.0005);
            uart_service();
            if (interrupted) why = "interrupted";
            if (wall_limit > 0 && wall_now() - wall_start >= wall_limit) why = "wall-limit";
        }
        if (!why && realtime) { /* pace: simulated time never runs ahead of the wall clock */
            double ahead = (double)(avr->cycle - c0) / (double)f_cpu - (wall_now() - w0);
            if (ahead > 0.002) sleep_s(ahead);
        }
    }
    if (wake) avr_cycle_timer_cancel(avr, on_target, NULL);
    uart_service();
    return why;
}

static int parse_u64(const char* s, unsigned long long* out) {
    if (!s || !*s) return -1;
    char* end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 0);
    if (errno || *end || *s == '-') return -1;
    *out = v;
    return 0;
}

static int parse_port_bit(const char* p, const char* b, char* port, uint8_t* bit) {
    unsigned long long v;
    if (!p || strlen(p) != 1 || p[0] < 'A' || p[0] > 'L' || parse_u64(b, &v) || v > 7) return -1;
    avr_ioport_state_t st;
    if (port_state(p[0], &st)) return -1;
    *port = p[0];
    *bit = (uint8_t)v;
    return 0;
}

static void hex_out(const uint8_t* p, size_t n) {
    static const char digits[] = "0123456789abcdef";
    for (size_t i = 0; i < n; i++) {
        fputc(digits[p[i] >> 4], proto);
        fputc(digits[p[i] & 15], proto);
    }
}

static int hex_in(const char* s, bytes_t* out) {
    size_t n = strlen(s);
    if (n % 2) return -1;
    for (size_t i = 0; i < n; i += 2) {
        unsigned v;
        char pair[3] = {s[i], s[i + 1], 0};
        char* end;
        v = (unsigned)strtoul(pair, &end, 16);
        if (*end) return -1;
        uint8_t c = (uint8_t)v;
        bytes_push(out, &c, 1);
    }
    return 0;
}

/* ---- the commands ------------------------------------------------------------------- */
/* Each command is a handler in `commands[]`: it gets the line's words
   (argv[0] is the command) and prints exactly one response line; it returns
   0 when the board should exit, else 1. */

#define NO_ARGS ((void)argc, (void)argv) /* a command that takes no arguments ignores extra words */

/* An `err` response; returns 1 (the board goes on). */
__attribute__((format(printf, 1, 2))) static int fail(const char* fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    fputs("err ", proto);
    vfprintf(proto, fmt, ap);
    fputc('\n', proto);
    va_end(ap);
    return 1;
}

static void put_run(const char* why) {
    fprintf(proto, "ok cycle=%llu time=%.9f state=%s stop=%s", (unsigned long long)avr->cycle,
            (double)avr->cycle / (double)f_cpu, state_name(avr->state), why);
}

/* ` n=K overflow=F` and the edges since the last report, which it forgets. */
static void put_edges(void) {
    fprintf(proto, " n=%zu overflow=%d", n_edges, edges_overflow);
    for (size_t i = 0; i < n_edges; i++)
        fprintf(proto, " %c%u@%llu=%u", edges[i].port, edges[i].bit, (unsigned long long)edges[i].cycle,
                edges[i].level);
    n_edges = 0;
    edges_overflow = 0;
}

/* The UART's bytes since the last report in hex (control mode; none otherwise). */
static void put_uart(void) {
    if (uart_mode != UART_CONTROL) return;
    hex_out(uart_out.buf + uart_out.head, bytes_pending(&uart_out));
    bytes_clear(&uart_out);
}

static int run_to(int argc, char** argv, int relative) {
    unsigned long long a;
    if (argc != 2 || parse_u64(argv[1], &a)) return fail("usage: %s CYCLES", argv[0]);
    put_run(run_until(1, relative ? avr->cycle + a : a, 0, 0));
    fputc('\n', proto);
    return 1;
}

static int cmd_step(int argc, char** argv) { return run_to(argc, argv, 1); }

static int cmd_until(int argc, char** argv) { return run_to(argc, argv, 0); }

static int cmd_go(int argc, char** argv) {
    unsigned long long a = 0;
    int realtime = 0, ok = argc <= 3;
    if (ok && argc >= 2) ok = !parse_u64(argv[1], &a);
    if (ok && argc == 3) {
        realtime = !strcmp(argv[2], "realtime");
        ok = realtime || !strcmp(argv[2], "fast");
    }
    if (!ok) return fail("usage: go [UNTIL_CYCLE|0] [realtime|fast]");
    fflush(proto);
    put_run(run_until(a != 0, a, realtime, 1));
    fputc('\n', proto);
    return 1;
}

/* A `batch` word `@ID:NAME=V[,NAME=V]...`: raw counts of the part at ID (its
   I2C address, 0x76, or its SPI chip-select pin, B1) by the names `part ID
   raw` takes. Returns 0 for a good word, else 1 with *bad_part the part
   whose counts are bad (NULL: no part at ID). With apply 1, a good word's
   part is first brought up to date (conversions that ended keep the old
   counts), then takes the counts. */
static int batch_part(char* word, int apply, part_t** bad_part) {
    char* colon = strchr(word, ':');
    part_t* p = NULL;
    *bad_part = NULL;
    if (!colon || !colon[1]) return 1;
    *colon = 0;
    const char* id = word + 1;
    unsigned long long a;
    if (strlen(id) == 2 && id[0] >= 'A' && id[0] <= 'L') {
        for (int i = 0; i < n_parts; i++)
            if (!parts[i].addr && parts[i].cs_port == id[0] && parts[i].cs_bit == (uint8_t)(id[1] - '0')) p = &parts[i];
    } else if (!parse_u64(id, &a) && a > 0 && a < 0x80) {
        p = part_at((uint8_t)a);
    }
    *colon = ':';
    if (!p) return 1;
    const part_kind_t* k = &part_kinds[p->kind];
    long vals[MAX_RAW];
    memcpy(vals, p->raw, sizeof vals);
    char* s = colon + 1;
    for (;;) {
        char* comma = strchr(s, ',');
        if (comma) *comma = 0;
        char* eq = strchr(s, '=');
        int r = -1;
        if (eq) {
            *eq = 0;
            for (int j = 0; j < k->n_raw; j++)
                if (!strcmp(s, k->raw_names[j])) r = j;
            *eq = '=';
        }
        char* end = NULL;
        errno = 0;
        const long x = eq ? strtol(eq + 1, &end, 0) : 0;
        const int ok = r >= 0 && !errno && eq[1] && !*end && x >= k->raw_min && x <= k->raw_max;
        if (comma) *comma = ',';
        if (!ok) {
            *bad_part = p;
            return 1;
        }
        vals[r] = x;
        if (!comma) break;
        s = comma + 1;
    }
    if (apply) {
        part_tick(p);
        memcpy(p->raw, vals, sizeof vals);
    }
    return 0;
}

/* Speculative lock-steps (`batch?`): a co-simulation may send several steps
   in one write, their inputs worked out ahead as if the firmware's outputs
   stayed as they were. A `batch?` runs only while no step since the last
   plain `batch` has seen a watched pin's edge or a change of the guarded
   RAM bytes (`guard`); else it answers `skip` and changes nothing, so the
   caller can work the plant out again from the last step run. */
static int spec_stopped;
static uint16_t guard_addr;
static uint8_t guard_len;

static int cmd_guard(int argc, char** argv) {
    unsigned long long a, n;
    if (argc != 3 || parse_u64(argv[1], &a) || parse_u64(argv[2], &n) || n > 8 || (n && (a < 0x20 || a + n - 1 > avr->ramend)))
        return fail("usage: guard ADDR LEN (RAM bytes a `batch?` watches, LEN 0-8, 0: none)");
    guard_addr = (uint16_t)a;
    guard_len = (uint8_t)n;
    fprintf(proto, "ok\n");
    return 1;
}

/* One lock-step of a co-simulation: inputs set in the order given, a run to
   absolute cycle C, then the run's result, the UART's bytes and the edges:
   what `adc`..., `din`..., `part ID raw`..., `until C`, `uart`, `edges` do,
   in one line; ` guard=HEX` at its end when RAM bytes are guarded. `batch?`
   is the same step, run only as the comment above `spec_stopped` says. */
static int cmd_batch(int argc, char** argv) {
    static const char usage[] = "usage: batch[?] CYCLE [CH=MV]... [PB=0|1]... [@ID:NAME=V[,NAME=V]...]... "
                                "(ADC channel 0-15, port A-L bit 0-7, a part's I2C address or SPI chip-select pin)";
    unsigned long long target, v;
    const int speculative = argv[0][5] == '?';
    if (speculative && spec_stopped) {
        fprintf(proto, "skip\n");
        return 1;
    }
    spec_stopped = 0;
    if (argc < 2 || parse_u64(argv[1], &target)) return fail("%s", usage);
    for (int i = 2; i < argc; i++) { /* all checked before any is applied */
        if (argv[i][0] == '@') {
            part_t* bp;
            if (batch_part(argv[i], 0, &bp)) {
                if (!bp) return fail("batch: no part at `%s` (start the harness with -I KIND@ADDR); %s", argv[i], usage);
                const part_kind_t* k = &part_kinds[bp->kind];
                fprintf(proto, "err batch: bad raw counts `%s`: the %s takes", argv[i], k->name);
                for (int j = 0; j < k->n_raw; j++) fprintf(proto, " %s=", k->raw_names[j]);
                fprintf(proto, " (%ld..%ld)\n", k->raw_min, k->raw_max);
                return 1;
            }
            continue;
        }
        char* eq = strchr(argv[i], '=');
        if (!eq) return fail("%s", usage);
        *eq = 0;
        char port;
        uint8_t bit;
        int bad = (argv[i][0] >= '0' && argv[i][0] <= '9')
                      ? parse_u64(argv[i], &v) || v >= ADC_IRQ_TEMP || parse_u64(eq + 1, &v) || v > 1000000
                      : argv[i][0] == 0 || parse_port_bit((char[]){argv[i][0], 0}, argv[i] + 1, &port, &bit) ||
                            parse_u64(eq + 1, &v) || v > 1;
        *eq = '=';
        if (bad) return fail("batch: bad input `%s`; %s", argv[i], usage);
    }
    for (int i = 2; i < argc; i++) {
        if (argv[i][0] == '@') {
            part_t* bp;
            (void)batch_part(argv[i], 1, &bp); /* checked above */
            continue;
        }
        char* eq = strchr(argv[i], '=');
        *eq = 0;
        unsigned long long value; /* millivolts or a level */
        parse_u64(eq + 1, &value);
        if (argv[i][0] >= '0' && argv[i][0] <= '9') {
            parse_u64(argv[i], &v);
            avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, (int)v), (uint32_t)value);
        } else {
            parse_u64(argv[i] + 1, &v);
            drive_pin(avr, argv[i][0], (uint8_t)v, (uint32_t)value);
        }
    }
    uint8_t before[8];
    memcpy(before, avr->data + guard_addr, guard_len);
    const char* why = run_until(1, target, 0, 0);
    put_run(why);
    fputs(" uart=", proto);
    put_uart();
    if (strcmp(why, "target") || n_edges || edges_overflow || memcmp(before, avr->data + guard_addr, guard_len)) spec_stopped = 1;
    put_edges();
    if (guard_len) {
        fputs(" guard=", proto);
        hex_out(avr->data + guard_addr, guard_len);
    }
    fputc('\n', proto);
    return 1;
}

static int cmd_adc(int argc, char** argv) {
    unsigned long long a, b;
    if (argc != 3 || parse_u64(argv[1], &a) || a >= ADC_IRQ_TEMP || parse_u64(argv[2], &b) || b > 1000000)
        return fail("usage: adc CHANNEL MILLIVOLTS (channel 0-15)");
    avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, (int)a), (uint32_t)b);
    fprintf(proto, "ok\n");
    return 1;
}

static int cmd_din(int argc, char** argv) {
    char port;
    uint8_t bit;
    unsigned long long a;
    if (argc != 4 || parse_port_bit(argv[1], argv[2], &port, &bit) || parse_u64(argv[3], &a) || a > 1)
        return fail("usage: din PORT BIT 0|1 (a port this MCU has)");
    drive_pin(avr, port, bit, (uint32_t)a);
    fprintf(proto, "ok\n");
    return 1;
}

static int cmd_ports(int argc, char** argv) {
    NO_ARGS;
    fprintf(proto, "ok");
    for (char p = 'A'; p <= 'L'; p++) {
        avr_ioport_state_t st;
        if (port_state(p, &st) == 0)
            fprintf(proto, " %c=%02x:%02x:%02x", p, (unsigned)st.port, (unsigned)st.ddr, (unsigned)st.pin);
    }
    fprintf(proto, "\n");
    return 1;
}

static int cmd_watch(int argc, char** argv) {
    char port;
    uint8_t bit;
    if (argc != 3 || parse_port_bit(argv[1], argv[2], &port, &bit))
        return fail("usage: watch PORT BIT (a port this MCU has)");
    int free_slot = -1;
    for (int i = 0; i < MAX_WATCH; i++) {
        if (watches[i].port == port && watches[i].bit == bit) {
            free_slot = -2;
            watches[i].active = 1;
            break;
        }
        if (!watches[i].port && free_slot == -1) free_slot = i;
    }
    if (free_slot == -1) return fail("at most %d pins can be watched", MAX_WATCH);
    if (free_slot >= 0) {
        avr_ioport_state_t st;
        port_state(port, &st);
        watch_t* w = &watches[free_slot];
        w->port = port;
        w->bit = bit;
        w->level = (uint8_t)((((st.ddr & (1u << bit)) ? st.port : st.pin) >> bit) & 1u);
        w->active = 1;
        avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(port), bit), on_pin, w);
    }
    fprintf(proto, "ok\n");
    return 1;
}

static int cmd_edges(int argc, char** argv) {
    NO_ARGS;
    fprintf(proto, "ok");
    put_edges();
    fprintf(proto, "\n");
    return 1;
}

static int cmd_uart(int argc, char** argv) {
    NO_ARGS;
    fprintf(proto, "ok ");
    put_uart();
    fprintf(proto, "\n");
    return 1;
}

static int cmd_send(int argc, char** argv) {
    if (argc != 2 || uart_mode != UART_CONTROL)
        return fail("usage: send HEXBYTES (with the UART on the control channel)");
    size_t before = uart_in.len;
    if (hex_in(argv[1], &uart_in)) {
        uart_in.len = before;
        return fail("send: not an even number of hex digits");
    }
    uart_feed();
    fprintf(proto, "ok\n");
    return 1;
}

static int cmd_peek(int argc, char** argv) {
    unsigned long long a, b;
    if (argc != 3 || parse_u64(argv[1], &a) || parse_u64(argv[2], &b) || b > MAX_PEEK ||
        a + b > (unsigned long long)avr->ramend + 1)
        return fail("usage: peek ADDRESS COUNT (data space 0-0x%x, at most %d bytes)", (unsigned)avr->ramend,
                    MAX_PEEK);
    fprintf(proto, "ok ");
    hex_out(avr->data + a, (size_t)b);
    fprintf(proto, "\n");
    return 1;
}

/* `sched FILE`: input changes at given cycles, applied by the harness as
   simulated time reaches each (a cycle timer: a sleeping core wakes for
   it), so that an open-loop replay needs no round trip per change. FILE
   holds lines `CYCLE CH=MV` (ADC channel, millivolts) or `CYCLE PB=0|1`
   (port, bit, level), in cycle order; `sched` alone drops what is left. */
typedef struct {
    unsigned long long cycle;
    uint32_t value;
    char port; /* 0: ADC channel `bit` */
    uint8_t bit;
} sched_t;
static sched_t* sched_v;
static size_t sched_n, sched_at;

static avr_cycle_count_t on_sched(struct avr_t* a, avr_cycle_count_t when, void* param) {
    (void)when, (void)param;
    while (sched_at < sched_n && sched_v[sched_at].cycle <= a->cycle) {
        const sched_t* e = &sched_v[sched_at++];
        if (e->port)
            drive_pin(a, e->port, e->bit, e->value);
        else
            avr_raise_irq(avr_io_getirq(a, AVR_IOCTL_ADC_GETIRQ, e->bit), e->value);
    }
    return sched_at < sched_n ? (avr_cycle_count_t)sched_v[sched_at].cycle : 0;
}

static int cmd_sched(int argc, char** argv) {
    avr_cycle_timer_cancel(avr, on_sched, NULL);
    free(sched_v);
    sched_v = NULL;
    sched_n = sched_at = 0;
    if (argc == 1) {
        fprintf(proto, "ok n=0\n");
        return 1;
    }
    if (argc != 2) return fail("usage: sched [FILE] (lines `CYCLE CH=MV` or `CYCLE PB=0|1`, in cycle order)");
    FILE* f = fopen(argv[1], "r");
    if (!f) return fail("sched: cannot read %s: %s", argv[1], strerror(errno));
    size_t cap = 0;
    char line[128];
    unsigned long long last = 0;
    int lineno = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        unsigned long long cycle, v, value;
        char tok[32], *eq;
        if (sscanf(line, "%llu %31s", &cycle, tok) != 2 || !(eq = strchr(tok, '=')) || cycle < last) {
            fclose(f);
            return fail("sched: %s:%d: expected `CYCLE CH=MV` or `CYCLE PB=0|1`, in cycle order", argv[1], lineno);
        }
        *eq = 0;
        sched_t e = {cycle, 0, 0, 0};
        int bad;
        if (tok[0] >= '0' && tok[0] <= '9') {
            bad = parse_u64(tok, &v) || v >= ADC_IRQ_TEMP || parse_u64(eq + 1, &value) || value > 1000000;
            e.bit = (uint8_t)v;
        } else {
            bad = parse_port_bit((char[]){tok[0], 0}, tok + 1, &e.port, &e.bit) || parse_u64(eq + 1, &value) ||
                  value > 1;
        }
        if (bad) {
            fclose(f);
            return fail("sched: %s:%d: bad input `%s`", argv[1], lineno, tok);
        }
        e.value = (uint32_t)value;
        if (sched_n == cap) {
            cap = cap ? 2 * cap : 1024;
            sched_t* grown = realloc(sched_v, cap * sizeof *sched_v);
            if (!grown) {
                fclose(f);
                return fail("sched: out of memory");
            }
            sched_v = grown;
        }
        sched_v[sched_n++] = e;
        last = cycle;
    }
    fclose(f);
    if (sched_n) {
        unsigned long long first = sched_v[0].cycle;
        avr_cycle_timer_register(avr, first > avr->cycle ? first - avr->cycle : 1, on_sched, NULL);
    }
    fprintf(proto, "ok n=%zu\n", sched_n);
    return 1;
}

/* `eeprom read ADDR COUNT` (hex), `eeprom write ADDR HEX`, `eeprom cut N`
   (reset right after the Nth byte write from now), `eeprom count` (writes
   started, cuts made). */
static int cmd_eeprom(int argc, char** argv) {
    static const char usage[] = "usage: eeprom read ADDR COUNT | eeprom write ADDR HEX | eeprom cut N | eeprom count";
    unsigned long long a = 0, b = 0;
    avr_eeprom_desc_t d;
    if (argc == 2 && !strcmp(argv[1], "count")) {
        fprintf(proto, "ok writes=%llu cuts=%llu armed=%d\n", ee_writes, ee_resets, ee_cut_armed);
        return 1;
    }
    if (argc == 3 && !strcmp(argv[1], "cut")) {
        if (parse_u64(argv[2], &a) || a == 0) return fail("eeprom cut N: N >= 1 writes from now");
        ee_cut_at = ee_writes + a;
        ee_cut_armed = 1;
        fprintf(proto, "ok\n");
        return 1;
    }
    if (argc == 4 && (!strcmp(argv[1], "read") || !strcmp(argv[1], "write"))) {
        /* simavr's EEPROM module lends its bytes (GET with no buffer; its
           return value says nothing on some versions: the pointer does) */
        d.ee = NULL;
        d.offset = 0;
        d.size = avr->e2end + 1;
        avr_ioctl(avr, AVR_IOCTL_EEPROM_GET, &d);
        if (!d.ee) return fail("eeprom: this MCU has none");
        const unsigned long long size = (unsigned long long)avr->e2end + 1;
        if (!strcmp(argv[1], "read")) {
            if (parse_u64(argv[2], &a) || parse_u64(argv[3], &b) || b > MAX_PEEK || a + b > size)
                return fail("eeprom read ADDR COUNT: within 0-0x%x, at most %d bytes", (unsigned)avr->e2end, MAX_PEEK);
            fprintf(proto, "ok ");
            hex_out(d.ee + a, (size_t)b);
            fprintf(proto, "\n");
            return 1;
        }
        bytes_t data = {0};
        if (parse_u64(argv[2], &a) || hex_in(argv[3], &data)) {
            free(data.buf);
            return fail("eeprom write ADDR HEX: an address and an even number of hex digits");
        }
        if (a + data.len > size) {
            free(data.buf);
            return fail("eeprom write: beyond the EEPROM's %llu bytes", size);
        }
        if (data.len) memcpy(d.ee + a, data.buf, data.len);
        free(data.buf);
        fprintf(proto, "ok\n");
        return 1;
    }
    return fail("%s", usage);
}

/* `flash read ADDR COUNT` (hex), `flash write ADDR HEX` (stores the bytes as
   they are, bypassing the chip's rules: a test's fixture), `flash erase`
   (all 0xFF), `flash info`, `flash cut N` (a power cut right after the Nth
   program or erase from now starts, leaving it half done). */
static int cmd_flash(int argc, char** argv) {
    static const char usage[] =
        "usage: flash read ADDR COUNT | flash write ADDR HEX | flash erase | flash info | flash cut N";
    unsigned long long a = 0, b = 0;
    if (!fl.mem) return fail("flash: no SPI flash on this board (start the harness with -s CSPIN[:SIZE])");
    fl_tick(); /* an operation whose time is up shows done */
    if (argc == 2 && !strcmp(argv[1], "info")) {
        fprintf(proto,
                "ok size=%lu jedec=%02x%02x%02x cs=%c%u busy=%d wel=%d programs=%llu erases=%llu cuts=%llu armed=%d\n",
                (unsigned long)fl.size, FL_MFR, FL_MEMTYPE, fl.cap, fl.cs_port, fl.cs_bit, fl.busy, fl.wel,
                fl.programs, fl.erases, fl.cuts, fl.cut_armed);
        return 1;
    }
    if (argc == 2 && !strcmp(argv[1], "erase")) {
        memset(fl.mem, 0xFF, fl.size);
        fprintf(proto, "ok\n");
        return 1;
    }
    if (argc == 3 && !strcmp(argv[1], "cut")) {
        if (parse_u64(argv[2], &a) || a == 0) return fail("flash cut N: N >= 1 programs or erases from now");
        fl.cut_at = fl.ops + a;
        fl.cut_armed = 1;
        fprintf(proto, "ok\n");
        return 1;
    }
    if (argc == 4 && !strcmp(argv[1], "read")) {
        if (parse_u64(argv[2], &a) || parse_u64(argv[3], &b) || b > MAX_PEEK || a + b > fl.size)
            return fail("flash read ADDR COUNT: within 0-0x%lx, at most %d bytes", (unsigned long)fl.size - 1,
                        MAX_PEEK);
        fprintf(proto, "ok ");
        hex_out(fl.mem + a, (size_t)b);
        fprintf(proto, "\n");
        return 1;
    }
    if (argc == 4 && !strcmp(argv[1], "write")) {
        bytes_t data = {0};
        if (parse_u64(argv[2], &a) || hex_in(argv[3], &data)) {
            free(data.buf);
            return fail("flash write ADDR HEX: an address and an even number of hex digits");
        }
        if (a + data.len > fl.size) {
            free(data.buf);
            return fail("flash write: beyond the flash's %lu bytes", (unsigned long)fl.size);
        }
        if (data.len) memcpy(fl.mem + a, data.buf, data.len);
        free(data.buf);
        fprintf(proto, "ok\n");
        return 1;
    }
    return fail("%s", usage);
}

static int cmd_info(int argc, char** argv) {
    NO_ARGS;
    fprintf(proto, "ok proto=%d mcu=%s f_cpu=%u cycle=%llu time=%.9f state=%s uart=%s", PROTO_VERSION, mcu_name,
            (unsigned)f_cpu, (unsigned long long)avr->cycle, (double)avr->cycle / (double)f_cpu,
            state_name(avr->state), uart_names[uart_mode]);
    if (uart_mode == UART_PTY) fprintf(proto, " port=%s reader=%d", pty_name, pty_reader);
    fprintf(proto, " dropped=%llu wall=%.3f\n", (unsigned long long)uart_dropped, wall_now() - wall_start);
    return 1;
}

/* `prof ADDR...` profiles the functions at these byte addresses (the first
   marks a cycle), starting from zero; `prof` reports: `ok sleep=CYCLES
   frames=N frame_total=CYCLES frame_worst=CYCLES frame_worst_at=CYCLE` and
   `ADDR=CALLS:TOTAL:WORST` for each function. */
static int cmd_prof(int argc, char** argv) {
    if (argc > 1) {
        if (argc - 1 > MAX_PROF) return fail("prof: at most %d functions", MAX_PROF);
        prof_fn_t fns[MAX_PROF];
        for (int i = 1; i < argc; i++) {
            unsigned long long v;
            if (parse_u64(argv[i], &v) || v > avr->flashend) return fail("usage: prof [ADDRESS...] (byte addresses in flash)");
            memset(&fns[i - 1], 0, sizeof fns[i - 1]);
            fns[i - 1].entry = (avr_flashaddr_t)v;
        }
        memcpy(prof_fns, fns, sizeof fns);
        prof_n = argc - 1;
        prof_active = -1;
        prof_frame_open = 0;
        prof_frames = prof_frame_total = prof_frame_worst = prof_frame_worst_at = prof_sleep = 0;
        fprintf(proto, "ok\n");
        return 1;
    }
    if (prof_active < 0) prof_frame_close();
    fprintf(proto, "ok sleep=%llu frames=%llu frame_total=%llu frame_worst=%llu frame_worst_at=%llu", prof_sleep,
            prof_frames, prof_frame_total, prof_frame_worst, prof_frame_worst_at);
    for (int i = 0; i < prof_n; i++)
        fprintf(proto, " %lu=%llu:%llu:%llu", (unsigned long)prof_fns[i].entry, prof_fns[i].calls, prof_fns[i].total,
                prof_fns[i].worst);
    fprintf(proto, "\n");
    return 1;
}

static int cmd_stop(int argc, char** argv) {
    NO_ARGS;
    fprintf(proto, "ok\n"); /* ends a `go`; idle, it does nothing */
    return 1;
}

/* `reset [brownout|watchdog|external|power]`: the MCU resets for that cause
   (mcu_reset; brownout by default). Registers, I/O and the program counter
   as at power-on, MCUSR holding the cause's flag alone; RAM as it was but
   after `power`, which fills it with -R's pseudo-random bytes; the cycle
   count (the co-simulation's clock) goes on. `power` is the whole board's:
   the SPI flash loses power too, as in a power cut. */
static int cmd_reset(int argc, char** argv) {
    int cause = argc == 1 ? CAUSE_BROWNOUT : -1;
    for (int i = 0; argc == 2 && i < N_CAUSES; i++)
        if (!strcmp(argv[1], cause_names[i])) cause = i;
    if (cause < 0) return fail("usage: reset [brownout|watchdog|external|power]");
    if (cause == CAUSE_POWER) {
        power_cut(avr); /* the chip's operation in progress half done, its latches lost */
    } else {
        mcu_reset(avr, cause);
        parts_reset(0);
        if (fl.mem && !fl.cs_level) { /* the AVR lets go of CS: the pull-up raises it, the chip sees it rise */
            fl_tick();
            fl_deselect();
        }
    }
    halted = 0;
    fprintf(proto, "ok\n");
    return 1;
}

/* `part`: the parts of -I (docs/sim.md, "Parts on I2C and SPI"):
   `part` lists them; `part ID info|cal [HEX]|raw NAME=V...|fail MODE|reg R N`
   with ID a part's I2C address or SPI chip-select pin. */
static int cmd_part(int argc, char** argv) {
    static const char usage[] =
        "usage: part [ID info | ID cal [HEX] | ID raw NAME=VALUE... | ID fail ok|nack|stuck | ID reg REG N] "
        "(ID: an I2C address or an SPI chip-select pin)";
    if (argc == 1) {
        fprintf(proto, "ok");
        for (int i = 0; i < n_parts; i++) {
            if (parts[i].addr)
                fprintf(proto, " 0x%02x=%s", parts[i].addr, part_kinds[parts[i].kind].name);
            else
                fprintf(proto, " %c%u=%s", parts[i].cs_port, parts[i].cs_bit, part_kinds[parts[i].kind].name);
        }
        fprintf(proto, "\n");
        return 1;
    }
    if (argc < 3) return fail("%s", usage);
    part_t* p = NULL;
    unsigned long long v, n;
    if (strlen(argv[1]) == 2 && argv[1][0] >= 'A' && argv[1][0] <= 'L') {
        for (int i = 0; i < n_parts; i++)
            if (parts[i].cs_port == argv[1][0] && parts[i].cs_bit == (uint8_t)(argv[1][1] - '0')) p = &parts[i];
    } else if (!parse_u64(argv[1], &v) && v < 0x80) {
        p = part_at((uint8_t)v);
    }
    if (!p) return fail("part: no part at %s (start the harness with -I KIND@ADDR)", argv[1]);
    const part_kind_t* k = &part_kinds[p->kind];
    part_tick(p); /* conversions that ended so far latch what the host had set */
    uint8_t* cal = p->kind == PK_MS5611 ? p->prom : p->reg + k->cal_reg;
    if (argc == 3 && !strcmp(argv[2], "info")) {
        fprintf(proto, "ok kind=%s bus=%s fail=%s busy=%d conversions=%llu", k->name, p->addr ? "i2c" : "spi",
                part_fail_names[p->fail], p->busy, p->conversions);
        for (int i = 0; i < k->n_raw; i++) fprintf(proto, " %s=%ld", k->raw_names[i], p->raw[i]);
        fprintf(proto, "\n");
        return 1;
    }
    if ((argc == 3 || argc == 4) && !strcmp(argv[2], "cal")) {
        if (argc == 4) {
            bytes_t data = {0};
            if (hex_in(argv[3], &data) || data.len > k->cal_len) {
                free(data.buf);
                return fail("part cal HEX: at most %u bytes (hex) from the calibration block's first", k->cal_len);
            }
            if (data.len) memcpy(cal, data.buf, data.len);
            free(data.buf);
        }
        fprintf(proto, "ok ");
        hex_out(cal, k->cal_len);
        fprintf(proto, "\n");
        return 1;
    }
    if (argc >= 4 && !strcmp(argv[2], "raw")) {
        long vals[MAX_RAW];
        memcpy(vals, p->raw, sizeof vals);
        for (int i = 3; i < argc; i++) { /* all checked before any is applied */
            char* eq = strchr(argv[i], '=');
            int r = -1;
            if (eq) {
                *eq = 0;
                for (int j = 0; j < k->n_raw; j++)
                    if (!strcmp(argv[i], k->raw_names[j])) r = j;
                *eq = '=';
            }
            char* end;
            errno = 0;
            const long x = eq ? strtol(eq + 1, &end, 0) : 0;
            if (r < 0 || errno || !eq[1] || *end || x < k->raw_min || x > k->raw_max) {
                fprintf(proto, "err part raw: the %s takes", k->name);
                for (int j = 0; j < k->n_raw; j++) fprintf(proto, " %s=", k->raw_names[j]);
                fprintf(proto, " (%ld..%ld), not `%s`\n", k->raw_min, k->raw_max, argv[i]);
                return 1;
            }
            vals[r] = x;
        }
        memcpy(p->raw, vals, sizeof vals);
        fprintf(proto, "ok\n");
        return 1;
    }
    if (argc == 4 && !strcmp(argv[2], "fail")) {
        int f = -1;
        for (int i = 0; i < N_PART_FAILS; i++)
            if (!strcmp(argv[3], part_fail_names[i])) f = i;
        if (f < 0) return fail("part fail ok|nack|stuck");
        p->fail = f;
        fprintf(proto, "ok\n");
        return 1;
    }
    if (argc == 5 && !strcmp(argv[2], "reg")) {
        if (p->kind == PK_MS5611) return fail("part reg: the ms5611 has commands, not registers");
        if (parse_u64(argv[3], &v) || parse_u64(argv[4], &n) || v + n > 256)
            return fail("part reg REG N: registers 0-0xff");
        fprintf(proto, "ok ");
        hex_out(p->reg + v, (size_t)n);
        fprintf(proto, "\n");
        return 1;
    }
    return fail("%s", usage);
}

static int cmd_quit(int argc, char** argv) {
    NO_ARGS;
    fprintf(proto, "ok\n");
    return 0;
}

/* The protocol: docs/sim.md has a row for each. */
static const struct {
    const char* name;
    int (*run)(int argc, char** argv);
} commands[] = {
    {"info", cmd_info},   {"step", cmd_step},   {"until", cmd_until}, {"go", cmd_go},
    {"batch", cmd_batch}, {"adc", cmd_adc},     {"din", cmd_din},     {"ports", cmd_ports},
    {"watch", cmd_watch}, {"edges", cmd_edges}, {"uart", cmd_uart},   {"send", cmd_send},
    {"peek", cmd_peek},   {"stop", cmd_stop},   {"reset", cmd_reset}, {"prof", cmd_prof},
    {"eeprom", cmd_eeprom}, {"flash", cmd_flash}, {"sched", cmd_sched}, {"part", cmd_part},
    {"batch?", cmd_batch}, {"guard", cmd_guard}, {"quit", cmd_quit},
};
#define N_COMMANDS (sizeof commands / sizeof commands[0])

/* Splits a line into words and runs its command; returns 0 when the board should exit. */
static int command(char* line) {
    char* argv[MAX_ARGS];
    int argc = 0;
    for (char* tok = strtok(line, " \t"); tok; tok = strtok(NULL, " \t")) {
        if (argc == MAX_ARGS) return fail("more than %d words in one command", MAX_ARGS);
        argv[argc++] = tok;
    }
    if (argc == 0) return 1; /* empty line: no response */
    for (size_t i = 0; i < N_COMMANDS; i++)
        if (!strcmp(argv[0], commands[i].name)) return commands[i].run(argc, argv);
    fprintf(proto, "err unknown command `%s` (", argv[0]);
    for (size_t i = 0; i < N_COMMANDS; i++) fprintf(proto, i ? " %s" : "%s", commands[i].name);
    fprintf(proto, ")\n");
    return 1;
}

/* ---- start --------------------------------------------------------------------------- */

/* A free run's exit status (-x). */
static int free_run_status(const char* why) {
    if (!strcmp(why, "crashed")) {
        if (exit_mode != EXIT_CRASH)
            fprintf(stderr, "simboard: the firmware crashed at pc 0x%04x\n", (unsigned)avr->pc);
        return 1;
    }
    if (exit_mode == EXIT_DONE) return strcmp(why, "done") ? 3 : 0;
    if (exit_mode == EXIT_UNITY) {
        if (unity_passed < 0) {
            fprintf(stderr, "simboard: no \"N passed, N failed\" line in the output\n");
            return 1;
        }
        return unity_failed == 0 && unity_passed > 0 ? 0 : 1;
    }
    return 0;
}

static void usage(void) {
    fprintf(stderr,
            "usage: simboard [-c] [-m MCU] [-f HZ] [-t SIM_S] [-w WALL_S] [-u control|pty|stdio|stdout|none]\n"
            "                [-l LINK] [-r] [-x crash|done|unity] [-a CH=MV]... [-E EEPROM_FILE]\n"
            "                [-s CSPIN[:SIZE] [-S FLASH_FILE]] [-I KIND@ADDR]... [-R SEED] FW.elf\n");
}

int main(int argc, char** argv) {
    int control = 0, realtime = 0, opt;
    double sim_limit = 0;
    unsigned long long adc_init[16];
    int adc_set[16] = {0};
    const char* flash_spec = NULL;
    while ((opt = getopt(argc, argv, "cm:f:t:w:u:l:rx:a:s:S:E:R:I:")) != -1) {
        char* end;
        switch (opt) {
            case 'c': control = 1; break;
            case 'm': mcu_name = optarg; break;
            case 'f': {
                unsigned long long v;
                if (parse_u64(optarg, &v) || v == 0 || v > 0xFFFFFFFFull) {
                    fprintf(stderr, "simboard: -f needs a frequency in Hz\n");
                    return 2;
                }
                f_cpu = (uint32_t)v;
                break;
            }
            case 't':
                sim_limit = strtod(optarg, &end);
                if (*end || sim_limit < 0) { fprintf(stderr, "simboard: -t needs seconds\n"); return 2; }
                break;
            case 'w':
                wall_limit = strtod(optarg, &end);
                if (*end || wall_limit < 0) { fprintf(stderr, "simboard: -w needs seconds\n"); return 2; }
                break;
            case 'u': {
                int m = -1;
                for (int i = 0; i < N_UART_MODES; i++)
                    if (!strcmp(optarg, uart_names[i])) m = i;
                if (m < 0) { fprintf(stderr, "simboard: -u control|pty|stdio|stdout|none\n"); return 2; }
                uart_mode = m;
                break;
            }
            case 'x': {
                int m = -1;
                for (int i = 0; i < 3; i++)
                    if (!strcmp(optarg, exit_names[i])) m = i;
                if (m < 0) { fprintf(stderr, "simboard: -x crash|done|unity\n"); return 2; }
                exit_mode = m;
                break;
            }
            case 'l': snprintf(pty_link, sizeof pty_link, "%s", optarg); break;
            case 'r': realtime = 1; break;
            case 'a': {
                unsigned long long ch, mv;
                char* eq = strchr(optarg, '=');
                if (!eq) { fprintf(stderr, "simboard: -a CH=MV\n"); return 2; }
                *eq = 0;
                if (parse_u64(optarg, &ch) || ch > 15 || parse_u64(eq + 1, &mv)) {
                    fprintf(stderr, "simboard: -a CH=MV (channel 0-15, millivolts)\n");
                    return 2;
                }
                adc_init[ch] = mv;
                adc_set[ch] = 1;
                break;
            }
            case 's': flash_spec = optarg; break;
            case 'S': fl.file = optarg; break;
            case 'I':
                if (part_add(optarg) != 0) return 2;
                break;
            case 'E': ee_file = optarg; break;
            case 'R': {
                unsigned long long v;
                if (parse_u64(optarg, &v)) { fprintf(stderr, "simboard: -R needs a seed (a whole number)\n"); return 2; }
                ram_rng = (uint64_t)v;
                break;
            }
            default: usage(); return 2;
        }
    }
    if (optind + 1 != argc) {
        usage();
        return 2;
    }
    if (control && (uart_mode == UART_STDIO || uart_mode == UART_STDOUT)) {
        fprintf(stderr, "simboard: -u %s needs standard I/O, which -c uses for commands\n", uart_names[uart_mode]);
        return 2;
    }
    if (control && exit_mode != EXIT_CRASH) {
        fprintf(stderr, "simboard: -x is for a free run (without -c)\n");
        return 2;
    }
    if (!control && uart_mode == UART_CONTROL) uart_mode = UART_NONE;
    if (fl.file && !flash_spec) {
        fprintf(stderr, "simboard: -S FILE keeps the SPI flash's bytes: it needs the flash (-s CSPIN[:SIZE])\n");
        return 2;
    }
    unsigned long long flash_size = 8u << 20; /* the W25Q64JV's 64 Mbit */
    if (flash_spec) {
        char pin[3] = {0};
        const char* colon = strchr(flash_spec, ':');
        const size_t pin_len = colon ? (size_t)(colon - flash_spec) : strlen(flash_spec);
        if (pin_len == 2) memcpy(pin, flash_spec, 2);
        if (pin_len != 2 || pin[0] < 'A' || pin[0] > 'L' || pin[1] < '0' || pin[1] > '7') {
            fprintf(stderr, "simboard: -s CSPIN[:SIZE]: CSPIN is a port and bit such as B2\n");
            return 2;
        }
        /* powers of two from 64 KiB to 16 MiB: the W25Q family's sizes
           that 24-bit addresses reach, the JEDEC capacity byte their log2 */
        if (colon && (parse_u64(colon + 1, &flash_size) || flash_size < (1u << 16) || flash_size > (1u << 24) ||
                      (flash_size & (flash_size - 1)))) {
            fprintf(stderr, "simboard: -s CSPIN[:SIZE]: SIZE is a power of two from 65536 to 16777216 bytes\n");
            return 2;
        }
        fl.cs_port = pin[0];
        fl.cs_bit = (uint8_t)(pin[1] - '0');
    }

    /* Responses go to the original standard output; anything a library
       prints on standard output lands on standard error instead. */
    signal(SIGPIPE, SIG_IGN);
    if (control) {
        int fd = dup(1);
        proto = fd >= 0 ? fdopen(fd, "w") : NULL;
        if (!proto || dup2(2, 1) < 0) {
            fprintf(stderr, "simboard: cannot set up the control channel\n");
            return 2;
        }
    } else {
        proto = stderr;
    }
    avr_global_logger_set(logger);

    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    if (access(argv[optind], R_OK) != 0) {
        fprintf(stderr, "simboard: cannot read %s: %s\n", argv[optind], strerror(errno));
        return 2;
    }
    if (elf_read_firmware(argv[optind], &fw) != 0 || fw.flashsize == 0) {
        fprintf(stderr, "simboard: %s is not a firmware ELF simavr can load\n", argv[optind]);
        return 2;
    }
    avr = avr_make_mcu_by_name(mcu_name);
    if (!avr) {
        fprintf(stderr, "simboard: simavr does not know the MCU `%s`\n", mcu_name);
        return 2;
    }
    avr_init(avr);
    lvl_setup(avr);
    avr->log = LOG_ERROR;
    avr->sleep = no_wall_sleep; /* a sleeping core skips to its next event; pacing is run()'s */
    if (fw.flashbase + fw.flashsize > avr->flashend + 1u) {
        fprintf(stderr, "simboard: %s holds %u B of code, more than the %s's %u B of flash\n", argv[optind],
                (unsigned)(fw.flashbase + fw.flashsize), mcu_name, (unsigned)(avr->flashend + 1u));
        return 2;
    }
    snprintf(fw.mmcu, sizeof fw.mmcu, "%s", mcu_name);
    fw.frequency = f_cpu;
    avr_load_firmware(avr, &fw);
    avr_register_io_write(avr, EECR_ADDR, on_eecr_write, NULL); /* after the EEPROM module's own */
    avr->frequency = f_cpu;
    avr->vcc = avr->avcc = avr->aref = 5000; /* millivolts: the Arduino boards' 5 V supply and reference */
    for (int ch = 0; ch < 16; ch++)
        if (adc_set[ch]) avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ch), (uint32_t)adc_init[ch]);

    /* -E: the file's bytes replace what the ELF's .eeprom section put there */
    if (ee_file) {
        const size_t size = (size_t)avr->e2end + 1;
        uint8_t* ee = eeprom_bytes();
        uint8_t* buf = malloc(size);
        if (!ee || !buf) {
            fprintf(stderr, "simboard: -E: the %s has no EEPROM\n", mcu_name);
            return 2;
        }
        memcpy(buf, ee, size);
        if (image_load(ee_file, buf, size, "EEPROM") != 0) return 2;
        avr_eeprom_desc_t d = {buf, 0, (uint32_t)size};
        avr_ioctl(avr, AVR_IOCTL_EEPROM_SET, &d);
        free(buf);
    }

    int spi_parts = 0, i2c_parts = 0;
    for (int i = 0; i < n_parts; i++) {
        avr_ioport_state_t st;
        if (parts[i].cs_port) {
            spi_parts++;
            if (port_state(parts[i].cs_port, &st) != 0) {
                fprintf(stderr, "simboard: -I: the %s has no port %c\n", mcu_name, parts[i].cs_port);
                return 2;
            }
            if (flash_spec && parts[i].cs_port == fl.cs_port && parts[i].cs_bit == fl.cs_bit) {
                fprintf(stderr, "simboard: -I: the SPI flash's chip select is %c%u already\n", fl.cs_port, fl.cs_bit);
                return 2;
            }
        } else {
            i2c_parts++;
        }
    }
    avr_irq_t* mosi = NULL;
    if (flash_spec || spi_parts) {
        /* the SPI's name in its ioctl is 0 on simavr 1.6's megas, '0' on others */
        mosi = avr_io_getirq(avr, AVR_IOCTL_SPI_GETIRQ(0), SPI_IRQ_OUTPUT);
        spi_miso = avr_io_getirq(avr, AVR_IOCTL_SPI_GETIRQ(0), SPI_IRQ_INPUT);
        if (!mosi || !spi_miso) {
            mosi = avr_io_getirq(avr, AVR_IOCTL_SPI_GETIRQ('0'), SPI_IRQ_OUTPUT);
            spi_miso = avr_io_getirq(avr, AVR_IOCTL_SPI_GETIRQ('0'), SPI_IRQ_INPUT);
        }
        if (!mosi || !spi_miso) {
            fprintf(stderr, "simboard: %s: simavr's %s has no SPI\n", flash_spec ? "-s" : "-I", mcu_name);
            return 2;
        }
    }
    if (flash_spec) {
        avr_ioport_state_t st;
        if (port_state(fl.cs_port, &st) != 0) {
            fprintf(stderr, "simboard: -s: the %s has no port %c\n", mcu_name, fl.cs_port);
            return 2;
        }
        fl.size = (uint32_t)flash_size;
        fl.cap = (uint8_t)__builtin_ctzll(flash_size);
        fl.mem = malloc(fl.size);
        if (!fl.mem) {
            fprintf(stderr, "simboard: out of memory\n");
            return 3;
        }
        memset(fl.mem, 0xFF, fl.size); /* from the factory: erased */
        if (fl.file && image_load(fl.file, fl.mem, fl.size, "SPI flash") != 0) return 2;
        fl.cs_level = 1;
        avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(fl.cs_port), fl.cs_bit), on_fl_cs, NULL);
    }
    if (mosi) avr_irq_register_notify(mosi, on_spi_mosi, NULL);
    if (i2c_parts) {
        /* the TWI's name in its ioctl is 0 on simavr 1.6's megas, '0' on others */
        avr_irq_t* out = avr_io_getirq(avr, AVR_IOCTL_TWI_GETIRQ(0), TWI_IRQ_OUTPUT);
        twi_in = avr_io_getirq(avr, AVR_IOCTL_TWI_GETIRQ(0), TWI_IRQ_INPUT);
        if (!out || !twi_in) {
            out = avr_io_getirq(avr, AVR_IOCTL_TWI_GETIRQ('0'), TWI_IRQ_OUTPUT);
            twi_in = avr_io_getirq(avr, AVR_IOCTL_TWI_GETIRQ('0'), TWI_IRQ_INPUT);
        }
        if (!out || !twi_in) {
            fprintf(stderr, "simboard: -I: simavr's %s has no TWI\n", mcu_name);
            return 2;
        }
        avr_irq_register_notify(out, on_twi_out, NULL);
        avr_irq_t* status = avr_io_getirq(avr, AVR_IOCTL_TWI_GETIRQ(0), TWI_IRQ_STATUS);
        if (!status) status = avr_io_getirq(avr, AVR_IOCTL_TWI_GETIRQ('0'), TWI_IRQ_STATUS);
        if (status) avr_irq_register_notify(status, on_twi_status, NULL);
        avr_register_io_write(avr, TWCR_ADDR, on_twcr_write, NULL); /* after the TWI module's own */
    }
    for (int i = 0; i < n_parts; i++) {
        part_power_on(&parts[i]);
        if (parts[i].cs_port)
            avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(parts[i].cs_port), parts[i].cs_bit),
                                    on_part_cs, &parts[i]);
    }

    /* UART0: raw bytes, not simavr's line printer. */
    uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
    flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POLL_SLEEP);
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT), on_uart_out, NULL);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XON), on_uart_xon, NULL);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XOFF), on_uart_xoff, NULL);
    uart_in_irq = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);
    uart_bit_times();
    timer_pwm_modes();
    if (uart_mode == UART_PTY && pty_open() != 0) return 2;
    if (uart_mode == UART_STDIO) fcntl(1, F_SETFL, fcntl(1, F_GETFL) | O_NONBLOCK);

    edges = malloc(sizeof(edge_t) * MAX_EDGES);
    if (!edges) {
        fprintf(stderr, "simboard: out of memory\n");
        return 3;
    }
    cycle_limit = (avr_cycle_count_t)(sim_limit * (double)f_cpu + 0.5);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    struct sigaction old;
    /* SIGINT ends a run (no SA_RESTART: a blocked poll returns), unless the
       caller made the board ignore it. fswkit.sim.board.SimBoard starts the
       board in a process group of its own, out of the terminal's Ctrl-C: there
       the board's owner decides, and stops a `go` with a `stop` command. */
    if (sigaction(SIGINT, NULL, &old) == 0 && old.sa_handler != SIG_IGN) sigaction(SIGINT, &sa, NULL);
    wall_start = wall_now();

    int status = 0;
    if (control) {
        fprintf(proto, "ok proto=%d mcu=%s f_cpu=%u uart=%s", PROTO_VERSION, mcu_name, (unsigned)f_cpu,
                uart_names[uart_mode]);
        if (uart_mode == UART_PTY) fprintf(proto, " port=%s", pty_name);
        fprintf(proto, "\n");
        char line[1 << 16];
        while (next_line(line, sizeof line)) {
            if (!command(line)) break;
            if (ferror(proto)) break; /* the caller went away */
        }
        fflush(proto);
    } else {
        if (uart_mode == UART_PTY) {
            fprintf(stderr, "simboard: UART0 on %s\n", pty_name);
            fflush(stderr);
        }
        const char* why = run_until(0, 0, realtime, 0);
        fprintf(stderr, "simboard: %s, stopped (%s) at cycle %llu, %.6f s simulated, %.3f s wall\n",
                argv[optind], why, (unsigned long long)avr->cycle, (double)avr->cycle / (double)f_cpu,
                wall_now() - wall_start);
        status = free_run_status(why);
    }
    /* The board is switched off: a flash operation still running stays
       half done, as a power cut leaves it; the memories go to their files. */
    if (fl.mem) {
        fl_tick();
        if (fl.busy) fl_apply(1);
        if (fl.file && image_save(fl.file, fl.mem, fl.size, "SPI flash") != 0 && status == 0) status = 1;
    }
    if (ee_file) {
        uint8_t* ee = eeprom_bytes();
        if (ee && image_save(ee_file, ee, (size_t)avr->e2end + 1, "EEPROM") != 0 && status == 0) status = 1;
    }
    if (pty_link[0]) { /* our own link only: still pointing at our pty */
        char to[sizeof pty_name];
        ssize_t n = readlink(pty_link, to, sizeof to - 1);
        if (n > 0) {
            to[n] = 0;
            if (!strcmp(to, pty_name)) unlink(pty_link);
        }
    }
    return status;
}
