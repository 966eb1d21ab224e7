//! Why the MCU reset, kept across the reset in no-init RAM.
//!
//! While the product runs, the record says "running". The panic, HardFault
//! and watchdog-warning handlers overwrite it with their cause right before
//! they reset the MCU; the next boot reads it. A record that still says
//! "running" at boot means a reset nobody recorded (pin, debugger, or a
//! watchdog whose warning interrupt did not run): the board's hardware flag,
//! if it has one, names it. An invalid record is a power-on.

use super::wire::ResetCause;

const MAGIC: u32 = 0x5253_5431; // "RST1"
/// Cause code while the product runs normally.
const RUNNING: u8 = 0xFF;

/// The record in no-init RAM (12 bytes, no padding).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct CauseRecord {
    magic: u32,
    boots: u16,
    cause: u8,
    _pad: u8,
    /// `!(magic ^ boots ^ cause)`: a torn or random record fails it.
    check: u32,
}

impl CauseRecord {
    /// What RAM holds after power-on: no valid record (all zero here).
    pub const POWER_ON: CauseRecord = CauseRecord { magic: 0, boots: 0, cause: 0, _pad: 0, check: 0 };

    /// A sealed record.
    pub fn new(cause: u8, boots: u16) -> Self {
        let mut r = CauseRecord { magic: MAGIC, boots, cause, _pad: 0, check: 0 };
        r.check = r.expected_check();
        r
    }

    fn expected_check(&self) -> u32 {
        !(self.magic ^ u32::from(self.boots) ^ (u32::from(self.cause) << 16))
    }

    fn valid(&self) -> bool {
        self.magic == MAGIC && self.check == self.expected_check()
    }

    /// The record a fault handler writes before it resets the MCU.
    pub fn with_cause(&self, cause: ResetCause) -> Self {
        let boots = if self.valid() { self.boots } else { 0 };
        CauseRecord::new(cause as u8, boots)
    }
}

/// The boot rule: from the record left in RAM and the board's hardware hint
/// (e.g. the STM32's IWDG reset flag), the cause of this boot, the boot count
/// since power-on, and the record to write while running.
pub fn at_boot(left: &CauseRecord, hw_hint: Option<ResetCause>) -> (ResetCause, u16, CauseRecord) {
    if !left.valid() {
        return (ResetCause::PowerOn, 1, CauseRecord::new(RUNNING, 1));
    }
    let cause = match left.cause {
        RUNNING => hw_hint.unwrap_or(ResetCause::Other),
        c => ResetCause::from_code(c),
    };
    let boots = left.boots.saturating_add(1);
    (cause, boots, CauseRecord::new(RUNNING, boots))
}

/// The record in no-init RAM (target only).
#[cfg(target_os = "none")]
pub mod noinit {
    use super::CauseRecord;
    use crate::product::wire::ResetCause;
    use core::mem::MaybeUninit;

    #[link_section = ".uninit.reset_cause"]
    static mut RECORD: MaybeUninit<CauseRecord> = MaybeUninit::uninit();

    /// Reads the record (whatever bits are there).
    pub fn load() -> CauseRecord {
        // SAFETY: every bit pattern is a valid `CauseRecord` (integers, explicit
        // padding field); volatile because the memory was never initialised.
        unsafe { core::ptr::read_volatile(core::ptr::addr_of!(RECORD).cast::<CauseRecord>()) }
    }

    /// Writes the record.
    pub fn store(r: &CauseRecord) {
        // SAFETY: single word-aligned static; written from the main loop at boot
        // and from fault handlers just before a reset.
        unsafe { core::ptr::write_volatile(core::ptr::addr_of_mut!(RECORD).cast::<CauseRecord>(), *r) }
    }

    /// Records `cause` for the next boot (called by fault handlers).
    pub fn record(cause: ResetCause) {
        store(&load().with_cause(cause));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_on_then_recorded_causes_then_unrecorded_reset() {
        let junk = CauseRecord { magic: 0xDEAD_BEEF, boots: 7, cause: 1, _pad: 0, check: 0 };
        let (c, boots, running) = at_boot(&junk, Some(ResetCause::Watchdog));
        assert_eq!((c, boots), (ResetCause::PowerOn, 1));
        // A panic handler records its cause; the next boot reads it.
        let (c, boots, running) = at_boot(&running.with_cause(ResetCause::Panic), None);
        assert_eq!((c, boots), (ResetCause::Panic, 2));
        // A reset nobody recorded: the hardware hint names it, else Other.
        assert_eq!(at_boot(&running, Some(ResetCause::Watchdog)).0, ResetCause::Watchdog);
        assert_eq!(at_boot(&running, None).0, ResetCause::Other);
        // A torn record is a power-on, not a recorded cause.
        let mut torn = running.with_cause(ResetCause::HardFault);
        torn.boots ^= 4;
        assert_eq!(at_boot(&torn, None).0, ResetCause::PowerOn);
    }
}
