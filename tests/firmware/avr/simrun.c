/* Runs a firmware test ELF on a simulated AVR (simavr): copies UART0 output
   to stdout, stops when the firmware sleeps with interrupts off (or on a
   simulated-time or wall-clock limit), and exits 0 only when the output
   holds a "N passed, 0 failed" line with N > 0.
   usage: simrun [-m mcu] [-f hz] [-t sim_seconds] [-w wall_seconds] fw.elf */
#include <simavr/avr_uart.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_elf.h>
#include <simavr/sim_io.h>
#include <simavr/sim_irq.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static char line[256];
static size_t line_len;
static long passed = -1, failed = -1;

static void on_uart_byte(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    (void)param;
    const char c = (char)value;
    putchar(c);
    if (c == '\n') {
        long p, f;
        char tail[8];
        line[line_len] = 0;
        if (sscanf(line, "%ld passed, %ld failed%7s", &p, &f, tail) == 2) {
            passed = p;
            failed = f;
        }
        line_len = 0;
    } else if (line_len + 1 < sizeof line) {
        line[line_len++] = c;
    }
}

int main(int argc, char** argv) {
    const char* mcu = "atmega328p";
    unsigned long hz = 16000000UL;
    double sim_limit = 60.0, wall_limit = 60.0;
    int opt;
    while ((opt = getopt(argc, argv, "m:f:t:w:")) != -1) {
        switch (opt) {
            case 'm': mcu = optarg; break;
            case 'f': hz = strtoul(optarg, NULL, 10); break;
            case 't': sim_limit = atof(optarg); break;
            case 'w': wall_limit = atof(optarg); break;
            default: fprintf(stderr, "usage: simrun [-m mcu] [-f hz] [-t s] [-w s] fw.elf\n"); return 2;
        }
    }
    if (optind + 1 != argc) {
        fprintf(stderr, "usage: simrun [-m mcu] [-f hz] [-t s] [-w s] fw.elf\n");
        return 2;
    }
    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    if (elf_read_firmware(argv[optind], &fw) != 0) {
        fprintf(stderr, "simrun: cannot read %s\n", argv[optind]);
        return 2;
    }
    avr_t* avr = avr_make_mcu_by_name(mcu);
    if (!avr) {
        fprintf(stderr, "simrun: unknown MCU %s\n", mcu);
        return 2;
    }
    avr_init(avr);
    avr->log = LOG_ERROR;
    avr_load_firmware(avr, &fw);
    avr->frequency = (uint32_t)hz;

    uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
    flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POLL_SLEEP);
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT),
                            on_uart_byte, NULL);

    const avr_cycle_count_t max_cycles = (avr_cycle_count_t)(sim_limit * (double)hz);
    const time_t wall_start = time(NULL);
    int state = cpu_Running;
    unsigned long iter = 0;
    while (state != cpu_Done && state != cpu_Crashed) {
        state = avr_run(avr);
        if ((++iter & 0xFFFFu) == 0) {
            if (avr->cycle > max_cycles) {
                fprintf(stderr, "\nsimrun: simulated-time limit (%.1f s) reached\n", sim_limit);
                break;
            }
            if (difftime(time(NULL), wall_start) > wall_limit) {
                fprintf(stderr, "\nsimrun: wall-clock limit (%.0f s) reached\n", wall_limit);
                break;
            }
        }
    }
    fflush(stdout);
    if (state != cpu_Done && state != cpu_Crashed) fprintf(stderr, "simrun: stopped at pc 0x%04x\n", (unsigned)avr->pc);
    fprintf(stderr, "simrun: %s, %.3f simulated s\n", argv[optind], (double)avr->cycle / (double)hz);
    if (state == cpu_Crashed) {
        fprintf(stderr, "simrun: the firmware crashed\n");
        return 1;
    }
    if (passed < 0) {
        fprintf(stderr, "simrun: no \"N passed, N failed\" line in the output\n");
        return 1;
    }
    return (failed == 0 && passed > 0) ? 0 : 1;
}
