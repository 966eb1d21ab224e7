//! The records a warm reset keeps, in no-init RAM (cortex-m-rt's `.uninit`
//! sections): the two thermal record slots and the reset-cause record.

use eha_guard::memory::nv::NvLoad;
use eha_guard::memory::slots::noinit as slots;
use eha_guard::memory::ThermalRecord;
use eha_guard::product::reset::{self, CauseRecord};
use eha_guard::product::wire::ResetCause;
use eha_guard::product::BootMemory;

/// What the no-init RAM holds at boot, with what the board read elsewhere:
/// the non-volatile record `nv`, the last-alive time `alive_s` and whether
/// the non-volatile store was failing then (`nv_failing`), and the
/// hardware's reset hint (`hw_hint`). A board without those passes
/// [`NvLoad::Empty`], `None`, `false`, `None`.
#[inline]
pub fn boot_memory(nv: NvLoad, alive_s: Option<u32>, nv_failing: bool, hw_hint: Option<ResetCause>) -> BootMemory {
    BootMemory { records: slots::load(), nv, alive_s, nv_failing, cause: reset::noinit::load(), hw_hint }
}

/// Writes thermal record slot `slot` (`Board::store_record`).
#[inline]
pub fn store_record(slot: usize, rec: &ThermalRecord) {
    slots::store(slot, rec);
}

/// Writes the reset-cause record (`Board::store_cause`).
#[inline]
pub fn store_cause(rec: &CauseRecord) {
    reset::noinit::store(rec);
}

/// Records `cause` for the next boot (fault handlers, just before a reset).
#[inline]
pub fn record_cause(cause: ResetCause) {
    reset::noinit::record(cause);
}
