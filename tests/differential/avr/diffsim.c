/* Runs an AVR ELF under simavr and copies every byte the firmware sends on
   UART0 to a file, unchanged (binary; simavr itself talks on stdout). Ends
   when the firmware sleeps with interrupts off (exit 0), crashes (exit 1),
   or reaches the simulated-time or wall-clock limit (exit 3).
   usage: diffsim -o out.bin [-m mcu] [-f hz] [-t sim_seconds] [-w wall_seconds] fw.elf */
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

static FILE* out;

static void on_uart_byte(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    (void)param;
    fputc((int)(value & 0xFFu), out);
}

int main(int argc, char** argv) {
    const char* mcu = "atmega2560";
    unsigned long hz = 16000000UL;
    double sim_limit = 60.0, wall_limit = 60.0;
    int opt;
    const char* out_path = NULL;
    while ((opt = getopt(argc, argv, "o:m:f:t:w:")) != -1) {
        switch (opt) {
            case 'o': out_path = optarg; break;
            case 'm': mcu = optarg; break;
            case 'f': hz = strtoul(optarg, NULL, 10); break;
            case 't': sim_limit = atof(optarg); break;
            case 'w': wall_limit = atof(optarg); break;
            default: fprintf(stderr, "usage: diffsim -o out [-m mcu] [-f hz] [-t s] [-w s] fw.elf\n"); return 2;
        }
    }
    if (optind + 1 != argc || out_path == NULL) {
        fprintf(stderr, "usage: diffsim -o out [-m mcu] [-f hz] [-t s] [-w s] fw.elf\n");
        return 2;
    }
    out = fopen(out_path, "wb");
    if (out == NULL) {
        fprintf(stderr, "diffsim: cannot write %s\n", out_path);
        return 2;
    }
    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    if (elf_read_firmware(argv[optind], &fw) != 0) {
        fprintf(stderr, "diffsim: cannot read %s\n", argv[optind]);
        return 2;
    }
    avr_t* avr = avr_make_mcu_by_name(mcu);
    if (!avr) {
        fprintf(stderr, "diffsim: unknown MCU %s\n", mcu);
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
    int limited = 0;
    while (state != cpu_Done && state != cpu_Crashed) {
        state = avr_run(avr);
        if ((++iter & 0xFFFFu) == 0) {
            if (avr->cycle > max_cycles) {
                fprintf(stderr, "diffsim: simulated-time limit (%.1f s) reached\n", sim_limit);
                limited = 1;
                break;
            }
            if (difftime(time(NULL), wall_start) > wall_limit) {
                fprintf(stderr, "diffsim: wall-clock limit (%.0f s) reached\n", wall_limit);
                limited = 1;
                break;
            }
        }
    }
    fclose(out);
    fprintf(stderr, "diffsim: %s, %llu cycles\n", argv[optind], (unsigned long long)avr->cycle);
    if (state == cpu_Crashed) {
        fprintf(stderr, "diffsim: the firmware crashed at pc 0x%04x\n", (unsigned)avr->pc);
        return 1;
    }
    return limited ? 3 : 0;
}
