/* simboard: fswkit's simulated board. Runs an AVR firmware ELF on simavr
   (libsimavr) with UART0 bridged to a pseudo-terminal, to standard I/O, or to
   the control channel, analog inputs driven in millivolts and digital pins
   read, driven and timestamped in cycles.

   Two ways to run it:

   - Control mode (-c): commands on standard input, one response line each on
     standard output, in order (docs/sim.md has the protocol). The caller
     advances simulated time (`step`, `until`) or lets the board run free
     (`go`). fswkit.sim.board.SimBoard speaks it; so can a person at a terminal.
   - Free run (no -c): runs from reset until a limit, optionally paced to real
     time (-r), then prints a summary on standard error.

   usage: simboard [-c] [-m MCU] [-f HZ] [-t SIM_S] [-w WALL_S]
                   [-u control|pty|stdio|none] [-l LINK] [-r] [-a CH=MV]... FW.elf

   The board stops itself at the simulated-time limit (-t, seconds; 0 = none)
   and the wall-clock limit (-w, seconds since start; 0 = none), and when its
   control channel closes. fswkit builds this file at run time with the host's
   gcc against -lsimavr (host-tools/fswkit/sim.py); no binary is committed.

   simavr's own uart_pty part (libsimavrparts) is not used: it prints on
   standard output, which carries the control protocol here, points a fixed
   /tmp/simavr-uart0 link at its pty (two boards would fight over it), and
   raises UART IRQs from its own thread while the core runs in another. This
   file serves the pty from the simulation loop instead. */
#define _GNU_SOURCE
#include <simavr/avr_adc.h>
#include <simavr/avr_ioport.h>
#include <simavr/avr_uart.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_cycle_timers.h>
#include <simavr/sim_elf.h>
#include <simavr/sim_io.h>
#include <simavr/sim_irq.h>

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

static void sleep_s(double s) {
    if (s <= 0) return;
    struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    nanosleep(&ts, NULL);
}

/* ---- the board ------------------------------------------------------------------ */

enum { UART_NONE, UART_CONTROL, UART_PTY, UART_STDIO };
static const char* uart_names[] = {"none", "control", "pty", "stdio"};

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

static void logger(avr_t* a, const int level, const char* fmt, va_list ap) {
    if (level > (a ? a->log : LOG_ERROR)) return;
    fputs("simavr: ", stderr);
    vfprintf(stderr, fmt, ap);
}

static void on_uart_out(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    (void)param;
    uint8_t c = (uint8_t)value;
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

static avr_cycle_count_t on_target(struct avr_t* a, avr_cycle_count_t when, void* param) {
    (void)a;
    (void)when;
    (void)param;
    return 0; /* exists only so that a sleeping core wakes at the target cycle */
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
    } else if (uart_mode == UART_STDIO) {
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
        if (stdio_in_open) {
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

/* Runs until cycle `target` (when has_target), a limit, the firmware
   stopping, SIGINT, or (watch_input) a command arriving on the control
   channel. Returns why it stopped. */
static const char* run_until(int has_target, avr_cycle_count_t target, int realtime, int watch_input) {
    interrupted = 0;
    if (halted) return avr->state == cpu_Crashed ? "crashed" : "done";
    if (wall_limit > 0 && wall_now() - wall_start >= wall_limit) return "wall-limit";
    if (cycle_limit && avr->cycle >= cycle_limit) return "sim-limit";
    if (has_target && avr->cycle >= target) return "target";
    if (has_target) avr_cycle_timer_register(avr, target - avr->cycle, on_target, NULL);
    const avr_cycle_count_t c0 = avr->cycle;
    const double w0 = wall_now();
    /* one comparison per instruction: the earlier of the target and the limit */
    avr_cycle_count_t stop_at = has_target ? target : ~(avr_cycle_count_t)0;
    if (cycle_limit && cycle_limit < stop_at) stop_at = cycle_limit;
    const char* why = NULL;
    while (!why) {
        for (int i = 0; i < RUN_BATCH; i++) {
            if (avr->cycle >= stop_at) {
                why = (has_target && avr->cycle >= target) ? "target" : "sim-limit";
                break;
            }
            int st = avr_run(avr);
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
    if (has_target) avr_cycle_timer_cancel(avr, on_target, NULL);
    uart_service();
    return why;
}

static void respond_run(const char* why) {
    fprintf(proto, "ok cycle=%llu time=%.9f state=%s stop=%s\n", (unsigned long long)avr->cycle,
            (double)avr->cycle / (double)f_cpu, state_name(avr->state), why);
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

/* Handles one command; returns 0 when the board should exit. */
static int command(char* line) {
    char* argv[8];
    int argc = 0;
    for (char* tok = strtok(line, " \t"); tok && argc < 8; tok = strtok(NULL, " \t")) argv[argc++] = tok;
    if (argc == 0) return 1; /* empty line: no response */
    const char* cmd = argv[0];
    unsigned long long a, b;

    if (!strcmp(cmd, "step") || !strcmp(cmd, "until")) {
        if (argc != 2 || parse_u64(argv[1], &a)) {
            fprintf(proto, "err usage: %s CYCLES\n", cmd);
            return 1;
        }
        respond_run(run_until(1, !strcmp(cmd, "step") ? avr->cycle + a : a, 0, 0));
    } else if (!strcmp(cmd, "go")) {
        int realtime = 0, ok = argc <= 3;
        a = 0;
        if (ok && argc >= 2) ok = !parse_u64(argv[1], &a);
        if (ok && argc == 3) {
            realtime = !strcmp(argv[2], "realtime");
            ok = realtime || !strcmp(argv[2], "fast");
        }
        if (!ok) {
            fprintf(proto, "err usage: go [UNTIL_CYCLE|0] [realtime|fast]\n");
            return 1;
        }
        fflush(proto);
        respond_run(run_until(a != 0, a, realtime, 1));
    } else if (!strcmp(cmd, "adc")) {
        if (argc != 3 || parse_u64(argv[1], &a) || a >= ADC_IRQ_TEMP || parse_u64(argv[2], &b) || b > 1000000) {
            fprintf(proto, "err usage: adc CHANNEL MILLIVOLTS (channel 0-15)\n");
            return 1;
        }
        avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, (int)a), (uint32_t)b);
        fprintf(proto, "ok\n");
    } else if (!strcmp(cmd, "din")) {
        char port;
        uint8_t bit;
        if (argc != 4 || parse_port_bit(argv[1], argv[2], &port, &bit) || parse_u64(argv[3], &a) || a > 1) {
            fprintf(proto, "err usage: din PORT BIT 0|1 (a port this MCU has)\n");
            return 1;
        }
        avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(port), bit), (uint32_t)a);
        fprintf(proto, "ok\n");
    } else if (!strcmp(cmd, "ports")) {
        fprintf(proto, "ok");
        for (char p = 'A'; p <= 'L'; p++) {
            avr_ioport_state_t st;
            if (port_state(p, &st) == 0)
                fprintf(proto, " %c=%02x:%02x:%02x", p, (unsigned)st.port, (unsigned)st.ddr, (unsigned)st.pin);
        }
        fprintf(proto, "\n");
    } else if (!strcmp(cmd, "watch")) {
        char port;
        uint8_t bit;
        if (argc != 3 || parse_port_bit(argv[1], argv[2], &port, &bit)) {
            fprintf(proto, "err usage: watch PORT BIT (a port this MCU has)\n");
            return 1;
        }
        int free_slot = -1;
        for (int i = 0; i < MAX_WATCH; i++) {
            if (watches[i].port == port && watches[i].bit == bit) {
                free_slot = -2;
                watches[i].active = 1;
                break;
            }
            if (!watches[i].port && free_slot == -1) free_slot = i;
        }
        if (free_slot == -1) {
            fprintf(proto, "err at most %d pins can be watched\n", MAX_WATCH);
            return 1;
        }
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
    } else if (!strcmp(cmd, "edges")) {
        fprintf(proto, "ok n=%zu overflow=%d", n_edges, edges_overflow);
        for (size_t i = 0; i < n_edges; i++)
            fprintf(proto, " %c%u@%llu=%u", edges[i].port, edges[i].bit, (unsigned long long)edges[i].cycle,
                    edges[i].level);
        fprintf(proto, "\n");
        n_edges = 0;
        edges_overflow = 0;
    } else if (!strcmp(cmd, "uart")) {
        fprintf(proto, "ok ");
        if (uart_mode == UART_CONTROL) {
            hex_out(uart_out.buf + uart_out.head, bytes_pending(&uart_out));
            bytes_clear(&uart_out);
        }
        fprintf(proto, "\n");
    } else if (!strcmp(cmd, "send")) {
        if (argc != 2 || uart_mode != UART_CONTROL) {
            fprintf(proto, "err usage: send HEXBYTES (with the UART on the control channel)\n");
            return 1;
        }
        size_t before = uart_in.len;
        if (hex_in(argv[1], &uart_in)) {
            uart_in.len = before;
            fprintf(proto, "err send: not an even number of hex digits\n");
            return 1;
        }
        uart_feed();
        fprintf(proto, "ok\n");
    } else if (!strcmp(cmd, "peek")) {
        if (argc != 3 || parse_u64(argv[1], &a) || parse_u64(argv[2], &b) || b > MAX_PEEK ||
            a + b > (unsigned long long)avr->ramend + 1) {
            fprintf(proto, "err usage: peek ADDRESS COUNT (data space 0-0x%x, at most %d bytes)\n",
                    (unsigned)avr->ramend, MAX_PEEK);
            return 1;
        }
        fprintf(proto, "ok ");
        hex_out(avr->data + a, (size_t)b);
        fprintf(proto, "\n");
    } else if (!strcmp(cmd, "info")) {
        fprintf(proto, "ok proto=%d mcu=%s f_cpu=%u cycle=%llu time=%.9f state=%s uart=%s", PROTO_VERSION,
                mcu_name, (unsigned)f_cpu, (unsigned long long)avr->cycle, (double)avr->cycle / (double)f_cpu,
                state_name(avr->state), uart_names[uart_mode]);
        if (uart_mode == UART_PTY) fprintf(proto, " port=%s reader=%d", pty_name, pty_reader);
        fprintf(proto, " dropped=%llu wall=%.3f\n", (unsigned long long)uart_dropped, wall_now() - wall_start);
    } else if (!strcmp(cmd, "stop")) {
        fprintf(proto, "ok\n"); /* ends a `go`; idle, it does nothing */
    } else if (!strcmp(cmd, "quit")) {
        fprintf(proto, "ok\n");
        return 0;
    } else {
        fprintf(proto, "err unknown command `%s` (info step until go adc din ports watch edges uart send peek stop quit)\n",
                cmd);
    }
    return 1;
}

/* ---- start --------------------------------------------------------------------------- */

static void usage(void) {
    fprintf(stderr,
            "usage: simboard [-c] [-m MCU] [-f HZ] [-t SIM_S] [-w WALL_S] [-u control|pty|stdio|none]\n"
            "                [-l LINK] [-r] [-a CH=MV]... FW.elf\n");
}

int main(int argc, char** argv) {
    int control = 0, realtime = 0, opt;
    double sim_limit = 0;
    unsigned long long adc_init[16];
    int adc_set[16] = {0};
    while ((opt = getopt(argc, argv, "cm:f:t:w:u:l:ra:")) != -1) {
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
                for (int i = 0; i < 4; i++)
                    if (!strcmp(optarg, uart_names[i])) m = i;
                if (m < 0) { fprintf(stderr, "simboard: -u control|pty|stdio|none\n"); return 2; }
                uart_mode = m;
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
            default: usage(); return 2;
        }
    }
    if (optind + 1 != argc) {
        usage();
        return 2;
    }
    if (control && uart_mode == UART_STDIO) {
        fprintf(stderr, "simboard: -u stdio needs standard I/O, which -c uses for commands\n");
        return 2;
    }
    if (!control && uart_mode == UART_CONTROL) uart_mode = UART_NONE;

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
    avr->log = LOG_ERROR;
    if (fw.flashbase + fw.flashsize > avr->flashend + 1u) {
        fprintf(stderr, "simboard: %s holds %u B of code, more than the %s's %u B of flash\n", argv[optind],
                (unsigned)(fw.flashbase + fw.flashsize), mcu_name, (unsigned)(avr->flashend + 1u));
        return 2;
    }
    snprintf(fw.mmcu, sizeof fw.mmcu, "%s", mcu_name);
    fw.frequency = f_cpu;
    avr_load_firmware(avr, &fw);
    avr->frequency = f_cpu;
    avr->vcc = avr->avcc = avr->aref = 5000; /* millivolts: the Arduino boards' 5 V supply and reference */
    for (int ch = 0; ch < 16; ch++)
        if (adc_set[ch]) avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ch), (uint32_t)adc_init[ch]);

    /* UART0: raw bytes, not simavr's line printer. */
    uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
    flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POLL_SLEEP);
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT), on_uart_out, NULL);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XON), on_uart_xon, NULL);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XOFF), on_uart_xoff, NULL);
    uart_in_irq = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);
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
       caller made the board ignore it, as fswkit.sim.board.SimBoard does: there
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
        if (!strcmp(why, "crashed")) status = 1;
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
