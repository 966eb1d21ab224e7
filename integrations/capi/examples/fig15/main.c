/*
 * The EHA guard in a C firmware loop, on QEMU mps2-an386 (Cortex-M4F),
 * linked against libeha_guard_capi.a through include/eha_guard.h.
 *
 * What a C controller does every 10 ms: take the sample, tick the guard,
 * store the thermal record when it changed, drive the valve and OK pins
 * and read them back, send the outputs. Here the sample arrives as the
 * product's UART frame and the outputs leave as its tick reply, over the
 * QEMU lockstep transport of the processor-in-the-loop harness
 * (eha_guard::protocol::lockstep): per tick, a little-endian u16 length and
 * that many received bytes on semihosting stdin; the tick's reply and an
 * end-of-tick frame on semihosting ":tt" (append: the host's stderr); at
 * end of input a completion marker and the stack's high-water mark (painted
 * at reset) on semihosting stdout, then exit 0. The host runs it in closed
 * loop with the reference plant and compares every reply with the Rust
 * application's, bit for bit (integrations/capi/tests/fig15_qemu.rs).
 *
 * Exit codes: 0 done, 3 HardFault, 4 unexpected exception, 5 stdin read
 * failed, 6 write failed, 7 semihosting open failed, 8 header and library
 * versions differ, 9 the guard storage was refused.
 */
#include <stddef.h>
#include <stdint.h>

#include "eha_guard.h"
#include "semihost.h"

enum { EXIT_READ = 5, EXIT_WRITE = 6, EXIT_OPEN = 7, EXIT_VERSION = 8, EXIT_STORAGE = 9 };

/* The guard and the deframer live in caller-owned static storage. */
static uint8_t guard[EHA_GUARD_STORAGE_SIZE] __attribute__((aligned(EHA_GUARD_STORAGE_ALIGN)));
static uint8_t deframer[EHA_WIRE_DEFRAMER_SIZE] __attribute__((aligned(EHA_WIRE_DEFRAMER_ALIGN)));
/* Thermal records A and B in RAM that a warm reset keeps (zero in QEMU at
   power-on: no record, a cold start). */
static eha_record_t records[2] __attribute__((section(".noinit")));
/* The parameter block region (link.ld). */
extern const uint8_t __eha_params[];

static uint8_t rx[1024];
static uint8_t tx[4 * EHA_WIRE_FRAME_MAX];

/* The valve and OK pins of this board: a register written and read back. */
static volatile uint8_t pin_port;

/* SysTick as a cycle counter (24-bit, counting down, core clock). */
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

static int read_exact(int32_t fd, uint8_t *buf, uint32_t len)
{
    uint32_t at = 0;
    while (at < len) {
        int32_t n = sh_read(fd, buf + at, len - at);
        if (n < 0) {
            sh_exit(EXIT_READ);
        }
        if (n == 0) {
            if (at == 0) {
                return 0; /* end of input */
            }
            sh_exit(EXIT_READ); /* a chunk cut short */
        }
        at += (uint32_t)n;
    }
    return 1;
}

static size_t tx_len;

static void tx_frame(eha_status_t st, size_t n)
{
    if (st != EHA_OK) {
        sh_exit(EXIT_WRITE);
    }
    tx_len += n;
}

static void tx_flush(int32_t fd)
{
    if (sh_write(fd, tx, (uint32_t)tx_len) != 0) {
        sh_exit(EXIT_WRITE);
    }
    tx_len = 0;
}

uint32_t stack_high_water_b(void);

/* "stack_high_water_b=N\n" on semihosting stdout (the harness reads it). */
static void report_stack(void)
{
    char line[32] = "stack_high_water_b=";
    char digits[10];
    uint32_t v = stack_high_water_b(), n = 0, at = 19;
    do {
        digits[n++] = (char)('0' + v % 10);
        v /= 10;
    } while (v != 0);
    while (n > 0) {
        line[at++] = digits[--n];
    }
    line[at++] = '\n';
    int32_t fd = sh_open_tt(4);
    if (fd < 0 || sh_write(fd, (const uint8_t *)line, at) != 0) {
        sh_exit(EXIT_WRITE);
    }
}

static uint16_t sat_add16(uint16_t a, uint16_t b)
{
    uint32_t s = (uint32_t)a + b;
    return s > 0xFFFFu ? 0xFFFFu : (uint16_t)s;
}

int main(void)
{
    int32_t in = sh_open_tt(0);
    int32_t out = sh_open_tt(8);
    if (in < 0 || out < 0) {
        return EXIT_OPEN;
    }
    if (eha_guard_version() != EHA_GUARD_VERSION) {
        return EXIT_VERSION;
    }
    SYST_RVR = 0x00FFFFFFu;
    SYST_CVR = 0;
    SYST_CSR = 0x5u; /* core clock, enabled, no interrupt */

    /* Boot: the parameter block, the RAM records (no non-volatile store
       on this board, no clock). */
    const eha_boot_t boot = {
        .ram_a = &records[0],
        .ram_b = &records[1],
        .nv_record = NULL,
        .nv_status = EHA_NV_NONE,
        .rtc_now_s = EHA_RTC_NONE,
        .alive_s = EHA_RTC_NONE,
        .nv_failing = 0,
        .boot_count = 1,
    };
    eha_boot_info_t info;
    eha_status_t st = eha_guard_init(guard, sizeof guard, __eha_params, EHA_PARAMS_BLOCK_LEN, &boot, &info);
    if (st == EHA_ERR_STORAGE_SIZE || st == EHA_ERR_STORAGE_ALIGN || (st == EHA_ERR_NULL && info.params != EHA_PARAMS_INVALID)) {
        return EXIT_STORAGE;
    }
    /* Any other status leaves a running guard (a refused block: CONFIG,
       valve open, alarm); the replies say so. */
    const uint8_t not_commissioned = st == EHA_NOT_COMMISSIONED;
    if (eha_wire_deframer_init(deframer, sizeof deframer) != EHA_OK) {
        return EXIT_STORAGE;
    }

    uint32_t tick = 0, accepted = 0, missing = 0;
    uint16_t last_seq = 0, rejected_crc = 0, rejected_framing = 0, rejected_sequence = 0;
    uint8_t have_seq = 0;
    eha_output_t o;
    eha_guard_output(guard, &o);

    for (;;) {
        uint8_t hdr[2];
        if (!read_exact(in, hdr, 2)) {
            break;
        }
        uint32_t n = (uint32_t)hdr[0] | ((uint32_t)hdr[1] << 8);
        if (n > sizeof rx || (n > 0 && !read_exact(in, rx, n))) {
            sh_exit(EXIT_READ);
        }
        uint32_t t0 = SYST_CVR;
        tick++;

        /* 1. transport: the newest valid sample frame of the tick. */
        eha_sample_t sample = {0};
        uint8_t fresh = 0;
        for (size_t at = 0; at < n;) {
            eha_wire_message_t msg;
            size_t used = 0;
            eha_wire_event_t ev = eha_wire_feed(deframer, rx + at, n - at, &used, &msg);
            if (ev == EHA_WIRE_ERR_STATE || used == 0) {
                sh_exit(EXIT_STORAGE);
            }
            at += used;
            switch (ev) {
            case EHA_WIRE_SAMPLE: {
                uint16_t ahead = (uint16_t)(msg.seq - last_seq);
                if (have_seq && (ahead == 0 || ahead > 0x8000u)) {
                    rejected_sequence = sat_add16(rejected_sequence, 1);
                    break;
                }
                last_seq = msg.seq;
                have_seq = 1;
                accepted++;
                sample = msg.sample;
                fresh = 1;
                break;
            }
            case EHA_WIRE_REJECTED_CRC:
                rejected_crc = sat_add16(rejected_crc, 1);
                break;
            case EHA_WIRE_REJECTED_FRAMING:
                rejected_framing = sat_add16(rejected_framing, 1);
                break;
            default: /* no frame ended; commands are not served by this example */
                break;
            }
        }

        /* 2. validate, estimate, protect. */
        if (fresh) {
            eha_guard_tick(guard, &sample, &o);
        } else {
            missing++;
            eha_guard_tick_missing(guard, &o);
        }

        /* 3. outputs: the thermal record when it changed, then the pins
           (read back: a mismatch latches ACTUATOR and opens the valve). */
        eha_record_write_t w;
        if (eha_guard_record(guard, &w) == EHA_OK && w.changed) {
            records[w.slot & 1] = w.record;
            eha_guard_output(guard, &o);
        }
        uint8_t valve_pin, ok_pin;
        eha_pins_for(&o, &valve_pin, &ok_pin);
        pin_port = (uint8_t)(valve_pin | (ok_pin << 1));
        uint8_t back = pin_port;
        if (back != (uint8_t)(valve_pin | (ok_pin << 1))) {
            eha_guard_report_actuator_fault(guard, &o);
            eha_pins_for(&o, &valve_pin, &ok_pin);
            pin_port = (uint8_t)(valve_pin | (ok_pin << 1));
            back = pin_port;
        }

        eha_tick_reply_t r = {
            .tick = tick,
            .sample_seq = last_seq,
            .fresh = fresh,
            .not_commissioned = not_commissioned,
            .out = o,
            .valve_pin = back & 1u,
            .ok_pin = (back >> 1) & 1u,
            .restore = (uint8_t)info.restore,
            .reset_cause = 0, /* power-on: this board keeps no reset cause */
            .overruns = 0,
            .rejected = sat_add16(sat_add16(rejected_crc, rejected_framing), rejected_sequence),
        };
        size_t len;
        tx_frame(eha_wire_tick_reply(&r, tx + tx_len, sizeof tx - tx_len, &len), len);
        uint32_t cycles = (t0 - SYST_CVR) & 0x00FFFFFFu;
        tx_frame(eha_wire_lockstep_tick_end(cycles, tx + tx_len, sizeof tx - tx_len, &len), len);
        tx_flush(out);
    }

    /* End of input: the completion marker, then a clean exit. */
    const eha_lockstep_done_t done = {
        .tick = tick,
        .accepted = accepted,
        .missing = missing,
        .rejected_crc = rejected_crc,
        .rejected_framing = rejected_framing,
        .rejected_sequence = rejected_sequence,
        .boots = 1,
        .faults = o.faults,
    };
    size_t len;
    tx_frame(eha_wire_lockstep_done(&done, tx, sizeof tx, &len), len);
    tx_frame(eha_wire_lockstep_tick_end(0, tx + tx_len, sizeof tx - tx_len, &len), len);
    tx_flush(out);
    report_stack();
    return 0;
}
