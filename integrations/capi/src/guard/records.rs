//! The thermal record hooks (RAM slots, the non-volatile save and its
//! outcome) and the record's check, clock stamp and byte form.

use super::*;

/// After each tick: whether the thermal record must be stored. When the
/// state it holds changed, `w.changed` is 1, `w.record` is the sealed record
/// for RAM slot `w.slot` (alternating A/B), and `w.nv_due` says whether the
/// non-volatile store is due by the product's write policy (then save it,
/// optionally stamped with `eha_record_set_rtc`, and report with
/// `eha_guard_nv_saved`). Call it every tick, after the tick.
///
/// # Safety
/// As [`eha_guard_tick`]; `w` valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_record(storage: *mut c_void, w: *mut EhaRecordWrite) -> EhaStatus {
    if w.is_null() {
        return EhaStatus::EhaErrNull;
    }
    // SAFETY: forwarded (caller).
    unsafe {
        with_guard(storage, core::ptr::null_mut(), |s| {
            if !s.records.changed(&s.guard) {
                (*w).changed = 0;
                return EhaStatus::EhaOk;
            }
            let mut slot = 0usize;
            let rec = s.records.write_ram(&s.guard, |k, _| slot = k);
            let nv_due = s.records.nv_due(s.guard.ticks(), &rec);
            w.write(EhaRecordWrite { changed: 1, slot: u8::from(slot != 0), nv_due: u8::from(nv_due), reserved: 0, record: EhaRecord::of(&rec) });
            EhaStatus::EhaOk
        })
    }
}

/// The outcome of a non-volatile save of `record` asked for by
/// `eha_guard_record`: `saved` 1 written, 0 failed (NV_FAILED with derate
/// at once; the next attempt after 60 s).
///
/// # Safety
/// As [`eha_guard_tick`]; `record` valid.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_nv_saved(storage: *mut c_void, record: *const EhaRecord, saved: u8) -> EhaStatus {
    // SAFETY: NULL or valid (caller).
    let Some(rec) = (unsafe { record_at(record) }) else { return EhaStatus::EhaErrNull };
    if saved > 1 {
        return EhaStatus::EhaErrArg;
    }
    // SAFETY: forwarded (caller).
    unsafe {
        with_guard(storage, core::ptr::null_mut(), |s| {
            let tick = s.guard.ticks();
            s.records.nv_result(tick, &rec, Some(saved == 1), &mut s.guard);
            EhaStatus::EhaOk
        })
    }
}

/// [`eha_record_check`]: no record (no magic): a cold start.
pub const EHA_RECORD_ABSENT: i32 = 0;
/// A valid record.
pub const EHA_RECORD_VALID: i32 = 1;
/// A damaged record (magic present; CRC, version or range bad).
pub const EHA_RECORD_DAMAGED: i32 = 2;

/// Classifies a record by the boot rules: `EHA_RECORD_*` (a NULL record
/// is absent).
///
/// # Safety
/// `record` NULL or valid.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_record_check(record: *const EhaRecord) -> i32 {
    // SAFETY: NULL or valid (caller).
    match unsafe { record_at(record) }.map(|r| r.classify()) {
        None | Some(RecordStatus::Absent) => EHA_RECORD_ABSENT,
        Some(RecordStatus::Valid) => EHA_RECORD_VALID,
        Some(RecordStatus::Corrupt) => EHA_RECORD_DAMAGED,
    }
}

/// Stamps a record with the battery-backed clock's seconds (before its
/// non-volatile save) and reseals it.
///
/// # Safety
/// `record` valid for reads and writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_record_set_rtc(record: *mut EhaRecord, rtc_s: u32) -> EhaStatus {
    // SAFETY: NULL or valid (caller).
    let Some(r) = (unsafe { record.as_mut() }) else { return EhaStatus::EhaErrNull };
    *r = EhaRecord::of(&r.to_guard().with_rtc((rtc_s != EHA_RTC_NONE).then_some(rtc_s)));
    EhaStatus::EhaOk
}

/// The record's byte form (`EHA_RECORD_BYTES` bytes, little-endian).
///
/// # Safety
/// `record` valid; `out` valid for writes of `out_len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_record_to_bytes(record: *const EhaRecord, out: *mut u8, out_len: usize) -> EhaStatus {
    // SAFETY: NULL or valid (caller).
    let Some(r) = (unsafe { record_at(record) }) else { return EhaStatus::EhaErrNull };
    if out.is_null() {
        return EhaStatus::EhaErrNull;
    }
    if out_len < crate::EHA_RECORD_BYTES {
        return EhaStatus::EhaErrBuffer;
    }
    // SAFETY: valid for `out_len` ≥ RECORD_BYTES bytes (caller).
    unsafe { out.cast::<[u8; crate::EHA_RECORD_BYTES]>().write_unaligned(r.to_le_bytes()) };
    EhaStatus::EhaOk
}

/// A record from its byte form (not checked: see `eha_record_check`).
///
/// # Safety
/// `bytes` valid for reads of `len` bytes; `record` valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_record_from_bytes(bytes: *const u8, len: usize, record: *mut EhaRecord) -> EhaStatus {
    if bytes.is_null() || record.is_null() {
        return EhaStatus::EhaErrNull;
    }
    if len != crate::EHA_RECORD_BYTES {
        return EhaStatus::EhaErrBuffer;
    }
    // SAFETY: valid for RECORD_BYTES bytes (caller).
    let b = unsafe { bytes.cast::<[u8; crate::EHA_RECORD_BYTES]>().read_unaligned() };
    // SAFETY: valid for writes (caller).
    unsafe { record.write(EhaRecord::of(&ThermalRecord::from_le_bytes(&b))) };
    EhaStatus::EhaOk
}
