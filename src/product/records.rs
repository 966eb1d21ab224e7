//! The thermal record's write rules, apart from the board that stores it:
//! when a record is due (the state it holds changed), the A/B slot and
//! sequence number of the next RAM record, when the non-volatile store is
//! due ([`NvPolicy`]) and how long a failed save holds the next attempt
//! off ([`super::NV_RETRY_TICKS`]). The product loop ([`super::AppOf`])
//! and the C API (`integrations/capi`) both drive their storage with it.

use super::NV_RETRY_TICKS;
use crate::memory::nv::{NvLoad, NvPolicy};
use crate::memory::slots::AbWriter;
use crate::memory::ThermalRecord;
use crate::num::Num;
use crate::GuardOf;

/// The write state of the thermal record.
#[derive(Clone, Copy, Debug)]
pub struct RecordKeeper {
    records: AbWriter,
    /// The guard's [`GuardOf::epoch`] when the A/B record was last written
    /// (the record is rewritten only when the state it holds changed).
    record_epoch: Option<u32>,
    nv_policy: NvPolicy,
    nv_last: Option<ThermalRecord>,
    /// Tick of the last failed non-volatile save: no attempt for
    /// [`NV_RETRY_TICKS`] after it (compared by wrapping difference, so the
    /// 497-day wrap of the tick counter does not stop the saves).
    nv_failed_at: Option<u32>,
}

impl RecordKeeper {
    /// The keeper after boot: the A/B writer continues after the newest
    /// valid RAM record of `a`, `b`; `nv` is what the non-volatile store held.
    #[inline(always)]
    pub fn after_boot(a: &ThermalRecord, b: &ThermalRecord, nv: &NvLoad) -> Self {
        RecordKeeper {
            records: AbWriter::after_boot(a, b),
            record_epoch: None,
            nv_policy: NvPolicy::DEFAULT,
            nv_last: nv.valid(),
            nv_failed_at: None,
        }
    }

    /// The state the record holds changed since the last RAM write.
    #[inline(always)]
    pub fn changed<N: Num>(&self, guard: &GuardOf<N>) -> bool {
        self.record_epoch != Some(guard.epoch())
    }

    /// The guard's record, sealed with the next sequence number and handed
    /// to `store(slot, record)` (slot 0 = A, 1 = B); returns it.
    #[inline(always)]
    pub fn write_ram<N: Num>(&mut self, guard: &GuardOf<N>, store: impl FnMut(usize, &ThermalRecord)) -> ThermalRecord {
        self.record_epoch = Some(guard.epoch());
        self.records.write(&guard.snapshot_unsealed(), store)
    }

    /// The non-volatile store is due for `rec` at `tick` by the write policy,
    /// and no failed save within [`NV_RETRY_TICKS`] holds it off.
    #[inline(always)]
    pub fn nv_due(&self, tick: u32, rec: &ThermalRecord) -> bool {
        let retry = self.nv_failed_at.is_none_or(|t| tick.wrapping_sub(t) >= NV_RETRY_TICKS);
        retry && self.nv_policy.due(self.nv_last.as_ref(), rec)
    }

    /// The outcome of a non-volatile save of `rec` at `tick` (`None`: the
    /// board has no store), reported to the guard (a failure raises
    /// NV_FAILED with derate).
    #[inline(always)]
    pub fn nv_result<N: Num>(&mut self, tick: u32, rec: &ThermalRecord, saved: Option<bool>, guard: &mut GuardOf<N>) {
        match saved {
            None => {}
            Some(true) => {
                self.nv_last = Some(*rec);
                self.nv_failed_at = None;
                guard.report_nv_save(true);
            }
            Some(false) => {
                self.nv_failed_at = Some(tick);
                guard.report_nv_save(false);
            }
        }
    }

    /// The last non-volatile save failed (and none succeeded since).
    pub fn nv_failing(&self) -> bool {
        self.nv_failed_at.is_some()
    }

    /// The write policy of the non-volatile store.
    pub fn nv_policy(&self) -> &NvPolicy {
        &self.nv_policy
    }
}
