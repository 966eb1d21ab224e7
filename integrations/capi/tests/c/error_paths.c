/*
 * The C API's error paths, from C (host gcc, linked against the host build
 * of libeha_guard_capi.a): NULL pointers, storage too small or misaligned,
 * refused parameter blocks (NULL, length, magic, version, CRC, alignment,
 * a value out of its bounds), an uninitialised guard, out-of-range flags,
 * commands without their arm or key, damaged thermal records.
 *
 *   error_paths PARAMS_BLOCK_FILE
 *
 * PARAMS_BLOCK_FILE is a valid block (rig id "capi-test-rig"), written by
 * the Rust test that runs this (tests/error_paths.rs). Prints one line per
 * check; the exit code is the number of failed checks.
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "eha_guard.h"

static int failed, passed;

#define CHECK(cond, ...)                                                                                               \
    do {                                                                                                               \
        if (cond) {                                                                                                    \
            passed++;                                                                                                  \
        } else {                                                                                                       \
            failed++;                                                                                                  \
            printf("FAIL line %d: %s: ", __LINE__, #cond);                                                             \
            printf(__VA_ARGS__);                                                                                       \
            printf("\n");                                                                                              \
        }                                                                                                              \
    } while (0)

#define STATUS(call, want)                                                                                             \
    do {                                                                                                               \
        eha_status_t got_ = (call);                                                                                    \
        CHECK(got_ == (want), "%s returned %d, want %d", #call, (int)got_, (int)(want));                               \
    } while (0)

/* Room for a guard and a misaligned view of it. */
static _Alignas(EHA_GUARD_STORAGE_ALIGN) uint8_t storage[EHA_GUARD_STORAGE_SIZE + 16];
static _Alignas(EHA_GUARD_STORAGE_ALIGN) uint8_t storage2[EHA_GUARD_STORAGE_SIZE];
static _Alignas(4) uint8_t block[EHA_PARAMS_BLOCK_LEN];
static _Alignas(4) uint8_t scratch[EHA_PARAMS_BLOCK_LEN + 8];

/* CRC-32 (IEEE), to reseal a block after changing one of its words. */
static uint32_t crc32(const uint8_t *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++) {
            c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
        }
    }
    return ~c;
}

static void reseal(uint8_t *b)
{
    uint32_t c = crc32(b, EHA_PARAMS_BLOCK_LEN - 4);
    memcpy(b + EHA_PARAMS_BLOCK_LEN - 4, &c, 4);
}

static const eha_sample_t rest = {
    .current_a = 2.0f,
    .p_a_bar = 5.0f,
    .p_b_bar = 5.0f,
    .speed_rpm = 0.0f,
    .position_mm = 0.0f,
    .ambient_c = 20.0f,
    .valve_feedback = EHA_FEEDBACK_NONE,
};

static int fail_safe(const eha_output_t *o)
{
    return o->valve_open == 1 && o->alarm == 1 && o->derate == 1 && (o->faults & EHA_FAULT_CONFIG) && o->drain_c == EHA_DRAIN_C_UNKNOWN;
}

/* A block refused at init: the status, and a guard in its CONFIG fail-safe. */
static void refused(const uint8_t *b, size_t len, eha_status_t want, const char *what)
{
    eha_boot_info_t info;
    eha_output_t o;
    eha_status_t st = eha_guard_init(storage, EHA_GUARD_STORAGE_SIZE, b, len, NULL, &info);
    CHECK(st == want, "%s: init returned %d, want %d", what, (int)st, (int)want);
    CHECK(info.params == EHA_PARAMS_INVALID, "%s: params source %d", what, info.params);
    STATUS(eha_guard_tick(storage, &rest, &o), EHA_OK);
    CHECK(fail_safe(&o), "%s: not fail-safe: valve %d alarm %d derate %d faults %#x drain %g", what, o.valve_open, o.alarm, o.derate, o.faults, o.drain_c);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        printf("usage: error_paths PARAMS_BLOCK_FILE\n");
        return 100;
    }
    FILE *f = fopen(argv[1], "rb");
    if (!f || fread(block, 1, sizeof block, f) != sizeof block) {
        printf("cannot read %s\n", argv[1]);
        return 100;
    }
    fclose(f);

    eha_boot_info_t info;
    eha_output_t o;
    uint32_t u;

    /* Version and storage. */
    CHECK(eha_guard_version() == EHA_GUARD_VERSION, "library %#x, header %#x", eha_guard_version(), EHA_GUARD_VERSION);
    CHECK(eha_guard_storage_need() <= EHA_GUARD_STORAGE_SIZE, "need %zu > EHA_GUARD_STORAGE_SIZE", eha_guard_storage_need());
    STATUS(eha_guard_init(NULL, EHA_GUARD_STORAGE_SIZE, block, sizeof block, NULL, NULL), EHA_ERR_NULL);
    STATUS(eha_guard_init(storage, 0, block, sizeof block, NULL, NULL), EHA_ERR_STORAGE_SIZE);
    STATUS(eha_guard_init(storage, eha_guard_storage_need() - 1, block, sizeof block, NULL, NULL), EHA_ERR_STORAGE_SIZE);
    STATUS(eha_guard_init(storage + 1, EHA_GUARD_STORAGE_SIZE, block, sizeof block, NULL, NULL), EHA_ERR_STORAGE_ALIGN);

    /* An uninitialised guard: every call refuses it, outputs fail-safe. */
    memset(storage, 0, sizeof storage);
    o.valve_open = 0;
    STATUS(eha_guard_tick(storage, &rest, &o), EHA_ERR_STATE);
    CHECK(fail_safe(&o), "uninitialised tick output not fail-safe");
    STATUS(eha_guard_tick_missing(storage, &o), EHA_ERR_STATE);
    STATUS(eha_guard_command_arm(storage, EHA_COMMAND_CLEAR, &u), EHA_ERR_STATE);
    STATUS(eha_guard_tick(NULL, &rest, &o), EHA_ERR_NULL);
    CHECK(fail_safe(&o), "NULL storage tick output not fail-safe");
    STATUS(eha_guard_tick(storage + 1, &rest, &o), EHA_ERR_STORAGE_ALIGN);

    /* Parameter blocks. */
    refused(NULL, EHA_PARAMS_BLOCK_LEN, EHA_ERR_NULL, "NULL block");
    refused(block, EHA_PARAMS_BLOCK_LEN - 1, EHA_ERR_PARAMS, "short block");
    refused(block, 0, EHA_ERR_PARAMS, "empty length");
    memcpy(scratch, block, sizeof block);
    scratch[100] ^= 0x01; /* one bit of a word: CRC */
    refused(scratch, EHA_PARAMS_BLOCK_LEN, EHA_ERR_PARAMS, "CRC");
    memcpy(scratch, block, sizeof block);
    scratch[0] = 'X'; /* magic */
    refused(scratch, EHA_PARAMS_BLOCK_LEN, EHA_ERR_PARAMS, "magic");
    memcpy(scratch, block, sizeof block);
    scratch[4] = (uint8_t)(EHA_PARAMS_FORMAT_VERSION - 1); /* version */
    reseal(scratch);
    refused(scratch, EHA_PARAMS_BLOCK_LEN, EHA_ERR_PARAMS, "version");
    memcpy(scratch, block, sizeof block);
    const uint32_t nan = 0x7FC00000u; /* the first model word out of its bounds, CRC resealed */
    memcpy(scratch + 24, &nan, 4);
    reseal(scratch);
    refused(scratch, EHA_PARAMS_BLOCK_LEN, EHA_ERR_PARAMS, "bounds (NaN word, good CRC)");
    memcpy(scratch + 1, block, sizeof block); /* a valid block at an odd address */
    refused(scratch + 1, EHA_PARAMS_BLOCK_LEN, EHA_ERR_PARAMS, "misaligned block");
    memset(scratch, 0xFF, EHA_PARAMS_BLOCK_LEN); /* erased flash: the paper rig */
    STATUS(eha_guard_init(storage, EHA_GUARD_STORAGE_SIZE, scratch, EHA_PARAMS_BLOCK_LEN, NULL, &info), EHA_NOT_COMMISSIONED);
    CHECK(info.params == EHA_PARAMS_DEFAULT && info.restore == EHA_RESTORE_COLD, "erased block: params %d restore %d", info.params, info.restore);

    /* A good block, a cold start. */
    STATUS(eha_guard_init(storage, EHA_GUARD_STORAGE_SIZE, block, sizeof block, NULL, &info), EHA_OK);
    CHECK(info.params == EHA_PARAMS_BLOCK && info.restore == EHA_RESTORE_COLD, "good block: params %d restore %d", info.params, info.restore);
    uint8_t rig[16];
    STATUS(eha_guard_rig_id(storage, rig), EHA_OK);
    CHECK(memcmp(rig, "capi-test-rig\0\0\0", 16) == 0, "rig id %.16s", (const char *)rig);
    STATUS(eha_guard_output(storage, &o), EHA_OK);
    CHECK(o.valve_open == 1 && o.alarm == 0, "before the first sample the valve is open (safe state): valve %d alarm %d", o.valve_open, o.alarm);
    STATUS(eha_guard_output(storage, NULL), EHA_ERR_NULL);

    /* Commands without arm, key or rule. */
    uint32_t nonce, key, value;
    STATUS(eha_guard_command_confirm(storage, EHA_COMMAND_CLEAR, 0, &value), EHA_REFUSED_NOT_ARMED);
    STATUS(eha_guard_command_arm(storage, 7, &nonce), EHA_ERR_ARG);
    STATUS(eha_guard_command_arm(storage, EHA_COMMAND_CLEAR, NULL), EHA_ERR_NULL);
    STATUS(eha_guard_command_arm(storage, EHA_COMMAND_CLEAR, &nonce), EHA_OK);
    STATUS(eha_command_key(rig, nonce, EHA_COMMAND_CLEAR, &key), EHA_OK);
    STATUS(eha_guard_command_confirm(storage, EHA_COMMAND_CLEAR, key ^ 1u, &value), EHA_REFUSED_KEY);
    STATUS(eha_guard_command_confirm(storage, EHA_COMMAND_CLEAR, key, &value), EHA_REFUSED_NOT_ARMED); /* the arm was used */
    STATUS(eha_guard_command_arm(storage, EHA_COMMAND_CLEAR, &nonce), EHA_OK);
    STATUS(eha_command_key(rig, nonce, EHA_COMMAND_REFILL, &key), EHA_OK);
    STATUS(eha_guard_command_confirm(storage, EHA_COMMAND_REFILL, key, &value), EHA_REFUSED_NOT_ARMED); /* armed a clear */
    STATUS(eha_guard_command_arm(storage, EHA_COMMAND_CLEAR, &nonce), EHA_OK);
    STATUS(eha_command_key(rig, nonce, EHA_COMMAND_CLEAR, &key), EHA_OK);
    STATUS(eha_guard_command_confirm(storage, EHA_COMMAND_CLEAR, key, &value), EHA_REFUSED_RULE); /* no valid samples yet */
    STATUS(eha_guard_command_arm(storage, EHA_COMMAND_REFILL, &nonce), EHA_OK);
    STATUS(eha_command_key(rig, nonce, EHA_COMMAND_REFILL, &key), EHA_OK);
    STATUS(eha_guard_command_confirm(storage, EHA_COMMAND_REFILL, key, &value), EHA_REFUSED_RULE); /* valve open */
    STATUS(eha_command_key(NULL, nonce, EHA_COMMAND_CLEAR, &key), EHA_ERR_NULL);

    /* Samples: NULL, flags out of range (the tick still runs, as missing). */
    uint32_t t0, t1;
    STATUS(eha_guard_ticks(storage, &t0), EHA_OK);
    STATUS(eha_guard_tick(storage, NULL, &o), EHA_ERR_NULL);
    eha_sample_t bad = rest;
    bad.has_lng_supply = 2;
    STATUS(eha_guard_tick(storage, &bad, &o), EHA_ERR_ARG);
    bad = rest;
    bad.valve_feedback = 5;
    STATUS(eha_guard_tick(storage, &bad, &o), EHA_ERR_ARG);
    STATUS(eha_guard_ticks(storage, &t1), EHA_OK);
    CHECK(t1 == t0 + 3, "refused samples are missing ticks: %u -> %u", t0, t1);

    /* A keyed confirmation starts the 10 s interval even when the guard's
       rule refuses it (as the product does): the refused clear above holds
       the next one off for 1000 ticks. 1100 valid samples, then a keyed
       clear is done; a second within 10 s is too soon. */
    for (int k = 0; k < 1100; k++) {
        STATUS(eha_guard_tick(storage, &rest, &o), EHA_OK);
    }
    CHECK(o.faults == EHA_FAULT_NO_VALVE_FEEDBACK || (o.faults & ~(uint32_t)(EHA_FAULT_NO_VALVE_FEEDBACK | EHA_FAULT_LNG_UNCONFIRMED)) == 0, "faults %#x", o.faults);
    STATUS(eha_guard_command_arm(storage, EHA_COMMAND_CLEAR, &nonce), EHA_OK);
    STATUS(eha_command_key(rig, nonce, EHA_COMMAND_CLEAR, &key), EHA_OK);
    STATUS(eha_guard_command_confirm(storage, EHA_COMMAND_CLEAR, key, &value), EHA_OK);
    CHECK(value == 0, "trust held %u s after a cold start", value);
    STATUS(eha_guard_command_arm(storage, EHA_COMMAND_CLEAR, &nonce), EHA_OK);
    STATUS(eha_command_key(rig, nonce, EHA_COMMAND_CLEAR, &key), EHA_OK);
    STATUS(eha_guard_command_confirm(storage, EHA_COMMAND_CLEAR, key, &value), EHA_REFUSED_TOO_SOON);

    /* Missed ticks: 1 stalled (blind) and 2 missing; the valve pin read back wrong. */
    STATUS(eha_guard_ticks(storage, &t0), EHA_OK);
    STATUS(eha_guard_catch_up(storage, 3, 1, &o), EHA_OK);
    STATUS(eha_guard_ticks(storage, &t1), EHA_OK);
    CHECK(t1 == t0 + 3, "catch-up ticks %u -> %u", t0, t1);
    CHECK((o.faults & EHA_FAULT_STALE) == 0, "2 missing ticks are not STALE: %#x", o.faults);

    /* Records: the hook, the byte form, the three-way check. */
    eha_record_write_t w;
    STATUS(eha_guard_record(storage, NULL), EHA_ERR_NULL);
    STATUS(eha_guard_record(storage, &w), EHA_OK);
    CHECK(w.changed == 1 && w.slot <= 1, "record: changed %d slot %d", w.changed, w.slot);
    uint8_t first_slot = w.slot;
    eha_record_t rec = w.record;
    STATUS(eha_guard_record(storage, &w), EHA_OK);
    CHECK(w.changed == 0, "an unchanged state asks for no write");
    STATUS(eha_guard_tick(storage, &rest, &o), EHA_OK);
    for (int k = 0; k < 10; k++) { /* a model step changes the state */
        STATUS(eha_guard_tick(storage, &rest, &o), EHA_OK);
    }
    STATUS(eha_guard_record(storage, &w), EHA_OK);
    CHECK(w.changed == 1 && w.slot == (first_slot ^ 1u), "slots alternate: %d then %d", first_slot, w.slot);
    CHECK(eha_record_check(&w.record) == EHA_RECORD_VALID, "a sealed record is valid");
    CHECK(eha_record_check(NULL) == EHA_RECORD_ABSENT, "NULL record is absent");
    uint8_t bytes[EHA_RECORD_BYTES];
    STATUS(eha_record_to_bytes(&rec, bytes, sizeof bytes - 1), EHA_ERR_BUFFER);
    STATUS(eha_record_to_bytes(&rec, bytes, sizeof bytes), EHA_OK);
    eha_record_t back;
    STATUS(eha_record_from_bytes(bytes, sizeof bytes - 1, &back), EHA_ERR_BUFFER);
    STATUS(eha_record_from_bytes(bytes, sizeof bytes, &back), EHA_OK);
    CHECK(memcmp(&back, &rec, sizeof rec) == 0, "byte form round trip");
    eha_record_t damaged = rec;
    damaged.temps_c[1] += 1.0f;
    CHECK(eha_record_check(&damaged) == EHA_RECORD_DAMAGED, "a changed temperature fails the CRC");
    eha_record_t stamped = rec;
    STATUS(eha_record_set_rtc(&stamped, 1234), EHA_OK);
    CHECK(stamped.rtc_s == 1234 && eha_record_check(&stamped) == EHA_RECORD_VALID, "an RTC stamp reseals");

    /* A failed non-volatile save: NV_FAILED and derate at once. */
    STATUS(eha_guard_nv_saved(storage, &rec, 2), EHA_ERR_ARG);
    STATUS(eha_guard_nv_saved(storage, NULL, 0), EHA_ERR_NULL);
    STATUS(eha_guard_nv_saved(storage, &rec, 0), EHA_OK);
    STATUS(eha_guard_output(storage, &o), EHA_OK);
    CHECK((o.faults & EHA_FAULT_NV_FAILED) && o.derate == 1, "failed save: faults %#x derate %d", o.faults, o.derate);

    /* The valve pin read back wrong: ACTUATOR, valve open. */
    STATUS(eha_guard_report_actuator_fault(storage, &o), EHA_OK);
    CHECK((o.faults & EHA_FAULT_ACTUATOR) && o.valve_open == 1, "actuator fault: faults %#x valve %d", o.faults, o.valve_open);

    /* Boots from records: warm, damaged, non-volatile (three-way). */
    eha_boot_t boot = {.ram_a = &w.record, .nv_status = EHA_NV_NONE, .rtc_now_s = EHA_RTC_NONE, .alive_s = EHA_RTC_NONE};
    STATUS(eha_guard_init(storage2, sizeof storage2, block, sizeof block, &boot, &info), EHA_OK);
    CHECK(info.restore == EHA_RESTORE_WARM, "valid RAM record: restore %d", info.restore);
    boot.ram_a = &damaged;
    STATUS(eha_guard_init(storage2, sizeof storage2, block, sizeof block, &boot, &info), EHA_OK);
    CHECK(info.restore == EHA_RESTORE_CORRUPT, "damaged RAM record: restore %d", info.restore);
    STATUS(eha_guard_output(storage2, &o), EHA_OK);
    CHECK(o.valve_open && o.alarm && (o.faults & EHA_FAULT_MEMORY_CORRUPT) && (o.faults & EHA_FAULT_UNTRUSTED), "damaged record start: valve %d alarm %d faults %#x", o.valve_open, o.alarm, o.faults);
    boot.ram_a = NULL;
    boot.nv_status = EHA_NV_VALID;
    boot.nv_record = &rec;
    STATUS(eha_guard_init(storage2, sizeof storage2, block, sizeof block, &boot, &info), EHA_OK);
    CHECK(info.restore == EHA_RESTORE_POWER_LOSS, "valid NV record: restore %d", info.restore);
    boot.nv_record = &damaged;
    STATUS(eha_guard_init(storage2, sizeof storage2, block, sizeof block, &boot, &info), EHA_OK);
    CHECK(info.restore == EHA_RESTORE_CORRUPT, "NV record that fails its check: restore %d", info.restore);
    boot.nv_status = EHA_NV_DAMAGED;
    boot.nv_record = NULL;
    STATUS(eha_guard_init(storage2, sizeof storage2, block, sizeof block, &boot, &info), EHA_OK);
    CHECK(info.restore == EHA_RESTORE_CORRUPT, "NV damaged: restore %d", info.restore);
    boot.nv_status = EHA_NV_VALID;
    STATUS(eha_guard_init(storage2, sizeof storage2, block, sizeof block, &boot, &info), EHA_ERR_NULL);
    CHECK(info.restore == EHA_RESTORE_CORRUPT, "NV valid without its record: conservative, restore %d", info.restore);
    boot.nv_status = 7;
    STATUS(eha_guard_init(storage2, sizeof storage2, block, sizeof block, &boot, &info), EHA_ERR_ARG);
    CHECK(info.restore == EHA_RESTORE_CORRUPT, "NV status out of range: conservative, restore %d", info.restore);

    /* Wire: an uninitialised deframer, a buffer too small. */
    static _Alignas(EHA_WIRE_DEFRAMER_ALIGN) uint8_t deframer[EHA_WIRE_DEFRAMER_SIZE + 8];
    size_t used = 99, len = 0;
    uint8_t zero = 0, buf[EHA_WIRE_FRAME_MAX];
    CHECK(eha_wire_feed(deframer, &zero, 1, &used, NULL) == EHA_WIRE_ERR_STATE, "uninitialised deframer");
    STATUS(eha_wire_deframer_init(deframer, EHA_WIRE_DEFRAMER_SIZE - 80), EHA_ERR_STORAGE_SIZE);
    STATUS(eha_wire_deframer_init(deframer + 1, EHA_WIRE_DEFRAMER_SIZE), EHA_ERR_STORAGE_ALIGN);
    STATUS(eha_wire_deframer_init(deframer, EHA_WIRE_DEFRAMER_SIZE), EHA_OK);
    CHECK(eha_wire_feed(deframer, &zero, 1, &used, NULL) == EHA_WIRE_NONE && used == 1, "a lone delimiter");
    CHECK(eha_wire_feed(deframer, NULL, 1, &used, NULL) == EHA_WIRE_ERR_STATE, "NULL bytes");
    eha_tick_reply_t r = {.tick = 1, .out = o};
    STATUS(eha_wire_tick_reply(&r, buf, 10, &len), EHA_ERR_BUFFER);
    STATUS(eha_wire_tick_reply(&r, buf, sizeof buf, &len), EHA_OK);
    r.restore = 9;
    STATUS(eha_wire_tick_reply(&r, buf, sizeof buf, &len), EHA_ERR_ARG);
    STATUS(eha_wire_tick_reply(NULL, buf, sizeof buf, &len), EHA_ERR_NULL);

    printf("%d checks passed, %d failed\n", passed, failed);
    return failed;
}
