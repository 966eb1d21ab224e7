//! The guard in caller-owned storage: boot, tick, missed ticks, the valve
//! pin's read-back, the thermal record hooks and the keyed commands. Each
//! function checks its pointers and the storage, converts the C types and
//! calls the product's own Rust code; none holds logic of its own.
//!
//! Here the storage and its checks, the panic boundary and the boot; the
//! ticks in `tick`, the record hooks and the record's byte form in
//! `records`, the keyed commands in `commands`.

use core::ffi::c_void;
use core::mem::{align_of, size_of, MaybeUninit};

use eha_guard::memory::nv::NvLoad;
use eha_guard::memory::{RecordStatus, ThermalRecord};
use eha_guard::params_block::{ParamSource, BLOCK_LEN};
use eha_guard::product::{boot_guard, CommandRules, RecordKeeper};
use eha_guard::protection::LngConfig;
use eha_guard::trace::RestoreKind;
use eha_guard::{faults, Guard, GuardConfig};

use crate::types::*;

// In the order the header lists them (cbindgen follows the module order):
// the ticks, the record hooks, the commands.
mod tick;

mod records;

mod commands;

pub use commands::*;
pub use records::*;
pub use tick::*;

/// Bytes of storage a guard needs (at least; `eha_guard_init` checks the
/// size it is given against the exact need of this build).
pub const EHA_GUARD_STORAGE_SIZE: usize = 3840;
/// Alignment of the storage, bytes.
pub const EHA_GUARD_STORAGE_ALIGN: usize = 8;

const _: () = assert!(size_of::<Shim>() <= EHA_GUARD_STORAGE_SIZE, "EHA_GUARD_STORAGE_SIZE is too small for this build");
const _: () = assert!(align_of::<Shim>() <= EHA_GUARD_STORAGE_ALIGN, "EHA_GUARD_STORAGE_ALIGN is too small for this build");

/// Storage word of an initialised guard.
const READY: u32 = 0x4548_4743; // "EHGC"
/// Storage word after a caught panic: every later call refuses it.
const POISONED: u32 = 0x0BAD_0BAD;

/// What the storage holds.
#[repr(C)]
struct Shim {
    magic: u32,
    params: ParamSource,
    restore: RestoreKind,
    lng: LngConfig,
    rules: CommandRules,
    records: RecordKeeper,
    guard: Guard,
}

/// Runs `f`; on the host a panic is caught and reported (the boundary never
/// unwinds into C); on the target the panic handler faults (`udf`).
fn boundary(on_panic: impl FnOnce(), f: impl FnOnce() -> EhaStatus) -> EhaStatus {
    #[cfg(not(target_os = "none"))]
    {
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
            Ok(s) => s,
            Err(_) => {
                on_panic();
                EhaStatus::EhaErrPanic
            }
        }
    }
    #[cfg(target_os = "none")]
    {
        let _ = on_panic;
        f()
    }
}

/// Writes `o` where `out` points, if it is not NULL.
///
/// # Safety
/// `out` is NULL or valid for a write of an `EhaOutput`.
unsafe fn put(out: *mut EhaOutput, o: EhaOutput) {
    if !out.is_null() {
        // SAFETY: non-null and valid for writes (caller).
        unsafe { out.write(o) };
    }
}

/// The storage as an initialised guard: the checks every call makes.
///
/// # Safety
/// `storage` is NULL or points to memory valid for reads and writes of
/// `EHA_GUARD_STORAGE_SIZE` bytes, not used by anything else for the call.
unsafe fn shim<'a>(storage: *mut c_void) -> Result<&'a mut Shim, EhaStatus> {
    if storage.is_null() {
        return Err(EhaStatus::EhaErrNull);
    }
    let p = storage.cast::<Shim>();
    if !p.is_aligned() {
        return Err(EhaStatus::EhaErrStorageAlign);
    }
    // SAFETY: aligned and valid for reads (caller); the word is read before
    // anything else of the storage is taken as initialised.
    let magic = unsafe { core::ptr::addr_of!((*p).magic).read() };
    if magic != READY {
        return Err(EhaStatus::EhaErrState);
    }
    // SAFETY: READY is written only after every field was initialised by
    // `eha_guard_init` (a stray match of the 32-bit word is the residual risk).
    Ok(unsafe { &mut *p })
}

/// Calls `f` on the initialised guard in `storage`, inside the panic
/// boundary; on any error the fail-safe output goes to `out`.
///
/// # Safety
/// As [`shim`]; `out` is NULL or valid for a write of an `EhaOutput`.
unsafe fn with_guard(storage: *mut c_void, out: *mut EhaOutput, f: impl FnOnce(&mut Shim) -> EhaStatus) -> EhaStatus {
    // SAFETY: forwarded (caller).
    let s = match unsafe { shim(storage) } {
        Ok(s) => s,
        Err(e) => {
            // SAFETY: forwarded (caller).
            unsafe { put(out, EhaOutput::FAIL_SAFE) };
            return e;
        }
    };
    let poison = storage.cast::<u32>();
    let status = boundary(
        // SAFETY: `storage` is aligned and valid for writes (checked above);
        // the guard behind it is not used again (every call checks the word).
        || unsafe { poison.write(POISONED) },
        || f(s),
    );
    if status == EhaStatus::EhaErrPanic {
        // SAFETY: forwarded (caller).
        unsafe { put(out, EhaOutput::FAIL_SAFE) };
    }
    status
}

/// Reads an optional record pointer.
///
/// # Safety
/// `p` is NULL or valid for a read of an `EhaRecord`.
unsafe fn record_at(p: *const EhaRecord) -> Option<ThermalRecord> {
    // SAFETY: NULL or valid for reads (caller); any bits are a valid record.
    unsafe { p.as_ref() }.map(EhaRecord::to_guard)
}

/// Initialises a guard in `storage` (`storage_size` bytes, aligned to
/// [`EHA_GUARD_STORAGE_ALIGN`]) as the product boots: the model constants of
/// the parameter block (`params`, `params_len` = `EHA_PARAMS_BLOCK_LEN`
/// bytes, 4-byte aligned, read only during this call), the thermal state
/// from `boot` (NULL: cold start), the valve open until the first sample.
///
/// Returns [`EhaStatus::EhaOk`]; [`EhaStatus::EhaNotCommissioned`] for an
/// erased block (the paper rig runs); [`EhaStatus::EhaErrParams`] or
/// [`EhaStatus::EhaErrNull`] (NULL `params`) with the guard initialised in
/// its CONFIG fail-safe; [`EhaStatus::EhaErrArg`] for an `nv_status` out of
/// range or [`EhaStatus::EhaErrNull`] for a NULL `nv_record` with
/// [`EHA_NV_VALID`], the record then taken as damaged (conservative start);
/// storage errors with nothing initialised. `info` (may be NULL) receives
/// how the guard started.
///
/// # Safety
/// `storage` valid for writes of `storage_size` bytes; `params` NULL or
/// valid for reads of `params_len` bytes; `boot` NULL or valid, with its
/// pointers NULL or valid; `info` NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_init(storage: *mut c_void, storage_size: usize, params: *const u8, params_len: usize, boot: *const EhaBoot, info: *mut EhaBootInfo) -> EhaStatus {
    if storage.is_null() {
        return EhaStatus::EhaErrNull;
    }
    if storage_size < size_of::<Shim>() {
        return EhaStatus::EhaErrStorageSize;
    }
    let p = storage.cast::<Shim>();
    if !p.is_aligned() {
        return EhaStatus::EhaErrStorageAlign;
    }
    // SAFETY: NULL or valid (caller).
    let boot = unsafe { boot.as_ref() };
    let mut status = EhaStatus::EhaOk;
    // The thermal memories: RAM slots as found, the NV load by its status.
    // SAFETY: NULL or valid (caller).
    let (a, b, nv_rec) = unsafe { boot.map_or((None, None, None), |m| (record_at(m.ram_a), record_at(m.ram_b), record_at(m.nv_record))) };
    let nv = match (boot.map_or(EHA_NV_NONE, |m| m.nv_status), nv_rec) {
        (EHA_NV_NONE, _) => NvLoad::Empty,
        (EHA_NV_VALID, Some(r)) if r.classify() == RecordStatus::Valid => NvLoad::Valid(r),
        (EHA_NV_VALID, Some(_)) | (EHA_NV_DAMAGED, _) => NvLoad::Damaged,
        (EHA_NV_VALID, None) => {
            status = EhaStatus::EhaErrNull;
            NvLoad::Damaged
        }
        _ => {
            status = EhaStatus::EhaErrArg;
            NvLoad::Damaged
        }
    };
    let clock = |s: u32| (s != EHA_RTC_NONE).then_some(s);
    let rtc_now = boot.and_then(|m| clock(m.rtc_now_s));
    let alive_s = boot.and_then(|m| clock(m.alive_s));
    let nv_failing = boot.is_some_and(|m| m.nv_failing != 0);
    let seed = boot.map_or(0, |m| u32::from(m.boot_count));
    // The block: NULL or a wrong length is refused as the product refuses a
    // bad block (CONFIG); an erased one runs the paper rig.
    // SAFETY: non-null and valid for `params_len` = BLOCK_LEN bytes (caller).
    let block: Option<&[u8; BLOCK_LEN]> = (!params.is_null() && params_len == BLOCK_LEN).then(|| unsafe { &*params.cast::<[u8; BLOCK_LEN]>() });
    let (ra, rb) = (a.unwrap_or(ThermalRecord::EMPTY), b.unwrap_or(ThermalRecord::EMPTY));
    let cfg = GuardConfig::DEFAULT;
    let poisoned = || {
        // SAFETY: aligned, valid for writes (checked above).
        unsafe { core::ptr::addr_of_mut!((*p).magic).write(POISONED) }
    };
    let booted = boundary(poisoned, || {
        // SAFETY: `p` is aligned and valid for writes of a `Shim` (checked
        // above); every field is written once before READY is.
        unsafe {
            core::ptr::addr_of_mut!((*p).magic).write(0);
            let slot = &mut *core::ptr::addr_of_mut!((*p).guard).cast::<MaybeUninit<Guard>>();
            let booted = boot_guard(slot, &cfg, block, (&ra, &rb), nv, || rtc_now, alive_s, nv_failing);
            let guard = &mut *core::ptr::addr_of_mut!((*p).guard);
            let params = match booted.params {
                ParamSource::Invalid(_) => booted.params,
                // Refused by the boundary check (NULL, length): as an
                // invalid block.
                _ if block.is_none() => {
                    guard.refuse_config();
                    ParamSource::Invalid(eha_guard::params_block::BlockError::Magic)
                }
                other => other,
            };
            core::ptr::addr_of_mut!((*p).params).write(params);
            core::ptr::addr_of_mut!((*p).restore).write(booted.restore);
            core::ptr::addr_of_mut!((*p).lng).write(cfg.lng);
            core::ptr::addr_of_mut!((*p).rules).write(CommandRules::new(booted.rig_id, seed));
            core::ptr::addr_of_mut!((*p).records).write(RecordKeeper::after_boot(&ra, &rb, &nv));
            core::ptr::addr_of_mut!((*p).magic).write(READY);
        }
        EhaStatus::EhaOk
    });
    if booted != EhaStatus::EhaOk {
        return booted;
    }
    // SAFETY: initialised above.
    let s = unsafe { &*p };
    if !info.is_null() {
        let restore = match s.restore {
            RestoreKind::Cold => EHA_RESTORE_COLD,
            RestoreKind::Warm => EHA_RESTORE_WARM,
            RestoreKind::Corrupt => EHA_RESTORE_CORRUPT,
            RestoreKind::PowerLoss => EHA_RESTORE_POWER_LOSS,
        };
        // A block whose values the model refuses is invalid too (CONFIG).
        let params = match s.params {
            _ if s.guard.faults().contains(faults::CONFIG) => EHA_PARAMS_INVALID,
            ParamSource::Default => EHA_PARAMS_DEFAULT,
            ParamSource::Block => EHA_PARAMS_BLOCK,
            ParamSource::Invalid(_) => EHA_PARAMS_INVALID,
        };
        // SAFETY: non-null and valid for writes (caller).
        unsafe { info.write(EhaBootInfo { restore, params }) };
    }
    let config = s.guard.faults().contains(faults::CONFIG);
    match (status, s.params) {
        (EhaStatus::EhaOk, _) if params.is_null() => EhaStatus::EhaErrNull,
        (EhaStatus::EhaOk, _) if config => EhaStatus::EhaErrParams,
        (EhaStatus::EhaOk, ParamSource::Default) => EhaStatus::EhaNotCommissioned,
        (st, _) => st,
    }
}

/// The exact storage this build needs, bytes (at most
/// [`EHA_GUARD_STORAGE_SIZE`]).
#[unsafe(no_mangle)]
pub extern "C" fn eha_guard_storage_need() -> usize {
    size_of::<Shim>()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[repr(C, align(8))]
    struct Storage([u8; EHA_GUARD_STORAGE_SIZE]);

    /// A panic inside a call (none is reachable in the core: forced here)
    /// is caught at the boundary: the status says so, the outputs are the
    /// fail-safe ones and the storage is poisoned for every later call.
    #[test]
    fn a_caught_panic_poisons_the_storage() {
        let mut s = Box::new(Storage([0; EHA_GUARD_STORAGE_SIZE]));
        let p = s.0.as_mut_ptr().cast::<c_void>();
        // SAFETY: the storage is valid, aligned and large enough.
        unsafe {
            let st = eha_guard_init(p, EHA_GUARD_STORAGE_SIZE, core::ptr::null(), 0, core::ptr::null(), core::ptr::null_mut());
            assert_eq!(st, EhaStatus::EhaErrNull, "a NULL block: CONFIG fail-safe, initialised");
            let mut o = EhaOutput::default();
            assert_eq!(eha_guard_tick_missing(p, &mut o), EhaStatus::EhaOk);
            let st = with_guard(p, &mut o, |_| panic!("forced by the test"));
            assert_eq!(st, EhaStatus::EhaErrPanic);
            assert_eq!(o, EhaOutput::FAIL_SAFE);
            o = EhaOutput::default();
            assert_eq!(eha_guard_tick_missing(p, &mut o), EhaStatus::EhaErrState);
            assert_eq!(o, EhaOutput::FAIL_SAFE);
        }
    }
}
