//! The guard's own state, typed: where it is in its life ([`Phase`]), the
//! hold on an estimate that started from an unknown state ([`Hold`]) and the
//! health of the non-volatile saves ([`NvHealth`]). Each is one value where
//! booleans side by side would allow combinations the guard never means.

/// Where the guard is in its life: waiting for its first sample (from which
/// kind of start), or running. (The values: bit 0 says running, a one-bit
/// test where the model step reads it.)
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(super) enum Phase {
    /// No sample yet after a cold boot: valve open, model not started; the
    /// first sample's ambient sets every node.
    WaitingCold = 0,
    /// No sample yet after a restore (a warm reset, or a corrupt record
    /// taken at the alarm temperature): the restored estimate stands.
    WaitingRestored = 2,
    /// No sample yet after a restore from the non-volatile record over a
    /// power loss: the first sample's ambient, if warmer than the saved one,
    /// raises every node.
    WaitingAfterPowerLoss = 4,
    /// Samples have started: the model runs.
    Running = 1,
}

impl Phase {
    /// The first sample has come.
    #[inline(always)]
    pub(super) fn started(self) -> bool {
        self as u8 & 1 != 0
    }
}

/// The trust hold of an estimate whose state was unknown (a corrupt or
/// damaged record, no sample by the start-up timeout, inputs that
/// disagreed): it must run [`super::recovery_ticks`] ticks before a clear
/// may trust it again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Hold {
    /// No hold: the estimate started from a known state, or has recovered.
    None,
    /// The state is unknown and the recovery has not begun: it begins at the
    /// first sample (a restore, the start-up timeout) or at the clear (inputs
    /// that disagreed: the recovery counts on good inputs only).
    Pending,
    /// Recovering since this tick.
    From(u32),
}

/// The non-volatile saves of the thermal record, for NV_FAILED (derate).
/// (The values: bit 0 says NV_FAILED, a one-bit test at every model step.)
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(super) enum NvHealth {
    /// No save has failed since boot or since the last clear that followed a
    /// good save.
    Good = 0,
    /// A save failed and none has succeeded since: NV_FAILED, which a clear
    /// does not clear.
    Failed = 1,
    /// A save failed and a later one succeeded: NV_FAILED until the next clear.
    SavedSince = 3,
}

impl NvHealth {
    /// NV_FAILED stands (a save failed, and no clear has seen a good one since).
    #[inline(always)]
    pub(super) fn failed(self) -> bool {
        self as u8 & 1 != 0
    }
}
