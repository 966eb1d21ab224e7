//! The keyed maintenance commands (clear, refill): arm, confirm, the key
//! the maintenance side computes, the rig id that keys them, the tick count.

use eha_guard::product::wire::{command_key, Cmd, Refusal};

use super::*;

/// Command code: clear the latched faults.
pub const EHA_COMMAND_CLEAR: i32 = 1;
/// Refill the LNG budget (a new charge installed).
pub const EHA_COMMAND_REFILL: i32 = 2;

fn arm_of(cmd: i32) -> Option<(Cmd, Cmd)> {
    match cmd {
        EHA_COMMAND_CLEAR => Some((Cmd::ClearArm, Cmd::ClearConfirm)),
        EHA_COMMAND_REFILL => Some((Cmd::RefillArm, Cmd::RefillConfirm)),
        _ => None,
    }
}

/// Arms a clear or a refill (`EHA_COMMAND_*`): `nonce` receives the nonce
/// the confirmation's key is computed from (`eha_command_key`). A new arm
/// replaces an armed one.
///
/// # Safety
/// As [`eha_guard_tick`]; `nonce` valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_command_arm(storage: *mut c_void, command: i32, nonce: *mut u32) -> EhaStatus {
    if nonce.is_null() {
        return EhaStatus::EhaErrNull;
    }
    let Some((arm, _)) = arm_of(command) else { return EhaStatus::EhaErrArg };
    // SAFETY: forwarded (caller).
    unsafe {
        with_guard(storage, core::ptr::null_mut(), |s| {
            nonce.write(s.rules.arm(arm, s.guard.ticks()));
            EhaStatus::EhaOk
        })
    }
}

/// Confirms the armed `command` with its `key`: the product's rules (the
/// matching arm within 1 s, the key, 10 s since the last confirmed one,
/// then the guard's own rule). `value` (may be NULL) receives, for a
/// confirmed clear, the seconds UNTRUSTED still holds (0: trust restored).
/// Returns [`EhaStatus::EhaOk`] or an `EhaRefused*` status.
///
/// # Safety
/// As [`eha_guard_tick`]; `value` NULL or valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_command_confirm(storage: *mut c_void, command: i32, key: u32, value: *mut u32) -> EhaStatus {
    let Some((_, confirm)) = arm_of(command) else { return EhaStatus::EhaErrArg };
    // SAFETY: forwarded (caller).
    unsafe {
        with_guard(storage, core::ptr::null_mut(), |s| {
            let tick = s.guard.ticks();
            match s.rules.confirm(confirm, key, tick, &mut s.guard, &s.lng) {
                Ok(v) => {
                    if !value.is_null() {
                        value.write(v);
                    }
                    EhaStatus::EhaOk
                }
                Err(Refusal::NotArmed) => EhaStatus::EhaRefusedNotArmed,
                Err(Refusal::Key) => EhaStatus::EhaRefusedKey,
                Err(Refusal::TooSoon) => EhaStatus::EhaRefusedTooSoon,
                Err(Refusal::Rule) | Err(Refusal::Unavailable) => EhaStatus::EhaRefusedRule,
            }
        })
    }
}

/// The key that confirms an armed command: what the maintenance side
/// computes from the `nonce` of the arm and the parameter block's 16-byte
/// rig id (`eha_guard_rig_id`; all zero without a block).
///
/// # Safety
/// `rig_id` valid for reads of 16 bytes; `key` valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_command_key(rig_id: *const u8, nonce: u32, command: i32, key: *mut u32) -> EhaStatus {
    if rig_id.is_null() || key.is_null() {
        return EhaStatus::EhaErrNull;
    }
    let Some((_, confirm)) = arm_of(command) else { return EhaStatus::EhaErrArg };
    // SAFETY: valid for 16 bytes (caller); writes valid (caller).
    unsafe { key.write(command_key(&*rig_id.cast::<[u8; 16]>(), nonce, confirm)) };
    EhaStatus::EhaOk
}

/// The rig id that keys the commands (16 bytes into `out`).
///
/// # Safety
/// As [`eha_guard_tick`]; `out` valid for writes of 16 bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_rig_id(storage: *mut c_void, out: *mut u8) -> EhaStatus {
    if out.is_null() {
        return EhaStatus::EhaErrNull;
    }
    // SAFETY: forwarded (caller).
    unsafe {
        with_guard(storage, core::ptr::null_mut(), |s| {
            out.cast::<[u8; 16]>().write_unaligned(*s.rules.rig_id());
            EhaStatus::EhaOk
        })
    }
}

/// Ticks the guard has taken since boot (10 ms each, wrapping).
///
/// # Safety
/// As [`eha_guard_tick`]; `ticks` valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eha_guard_ticks(storage: *mut c_void, ticks: *mut u32) -> EhaStatus {
    if ticks.is_null() {
        return EhaStatus::EhaErrNull;
    }
    // SAFETY: forwarded (caller).
    unsafe {
        with_guard(storage, core::ptr::null_mut(), |s| {
            ticks.write(s.guard.ticks());
            EhaStatus::EhaOk
        })
    }
}
