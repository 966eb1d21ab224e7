//! Boot: the model constants (parameter block or compiled-in default), the
//! thermal state (RAM records, else the non-volatile record cooled over the
//! off-time), the guard built in place; and the catch-up of timer periods
//! that had no tick of their own.

use super::reset::CauseRecord;
use super::wire::ResetCause;
use super::{MAX_MISSED_TICKS, MAX_STALL_TICKS};
use crate::memory::cooling::RestCooling;
use crate::memory::nv::{NvLoad, NvPolicy};
use crate::memory::slots;
use crate::memory::{boot_restore, Restore, ThermalRecord};
use crate::model::ModelConsts;
use crate::num::Num;
use crate::params_block::{self, ParamSource, BLOCK_LEN};
use crate::trace::RestoreKind;
use crate::{GuardConfig, GuardOf};

/// What the board found in its memories at boot.
#[derive(Clone, Copy, Debug)]
pub struct BootMemory {
    /// No-init RAM slot A and B.
    pub records: (ThermalRecord, ThermalRecord),
    /// What the non-volatile store holds (none, valid, damaged).
    pub nv: NvLoad,
    /// The last-alive stamp in the clock's battery-backed register, s
    /// ([`Board::rtc_alive`](super::Board::rtc_alive); `None`: the board has none or it is empty).
    pub alive_s: Option<u32>,
    /// The last-alive word says the non-volatile saves were failing: the
    /// flash record misses the machine's state since (a conservative
    /// start after a power loss).
    pub nv_failing: bool,
    /// The reset-cause record left in no-init RAM.
    pub cause: CauseRecord,
    /// The board's hardware reset flag, if it names a cause (e.g. IWDG).
    pub hw_hint: Option<ResetCause>,
}

/// The model constants of a boot and where they come from: a valid
/// parameter block (and its rig id, the key of the armed commands), else
/// `default` (the compiled-in paper rig on the boards: NOT_COMMISSIONED,
/// rig id all zero); an invalid block gives [`ParamSource::Invalid`], on
/// which the caller refuses the configuration
/// ([`GuardOf::refuse_config`]: CONFIG, fail-safe).
#[inline(always)]
pub fn boot_params<'a>(block: Option<&'a [u8; BLOCK_LEN]>, default: &'a ModelConsts<f32>) -> (&'a ModelConsts<f32>, ParamSource, [u8; 16]) {
    let (model, params) = match block.map(params_block::view) {
        None | Some(Ok(None)) => (default, ParamSource::Default),
        Some(Ok(Some(c))) => (c, ParamSource::Block),
        Some(Err(e)) => (default, ParamSource::Invalid(e)),
    };
    let mut rig_id = [0u8; 16];
    if let (ParamSource::Block, Some(b)) = (params, block) {
        let id = params_block::rig_id_bytes(b);
        for (d, s) in rig_id.iter_mut().zip(id) {
            *d = *s;
        }
    }
    (model, params, rig_id)
}

/// The thermal state of a boot ([`boot_restore`] under the default
/// non-volatile write policy): the RAM records' rule `ram`, else the
/// non-volatile record `nv` after a power loss, cooled over the off-time
/// (`now_s` and `alive_s`, the clock's seconds now and at the last-alive
/// stamp) by the model's bound at rest (none under an invalid block).
#[inline(always)]
pub fn boot_state(ram: Restore, nv: NvLoad, params: ParamSource, model: &ModelConsts<f32>, now_s: Option<u32>, alive_s: Option<u32>, nv_failing: bool) -> Restore {
    // The cooling bound at rest of the model in use (none under CONFIG).
    let cool = match params {
        ParamSource::Invalid(_) => None,
        _ => RestCooling::from_consts(model),
    };
    boot_restore(ram, nv, &NvPolicy::DEFAULT, cool.as_ref(), now_s, alive_s, nv_failing)
}

/// What [`boot_guard`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Booted {
    /// Where the model constants come from.
    pub params: ParamSource,
    /// The parameter block's rig id (all zero without a block): the key of
    /// the armed commands ([`super::CommandRules`]).
    pub rig_id: [u8; 16],
    /// How the thermal state started.
    pub restore: RestoreKind,
}

/// Boots the guard in place at `slot` as the product does: the model
/// constants of `block` ([`boot_params`]: `cfg.model` without one, CONFIG
/// and fail-safe for an invalid one), the thermal state of the RAM records
/// `ram` (A, B) and the non-volatile load `nv` ([`boot_state`]; `rtc_s`, the
/// clock's seconds, is read only when `nv` holds something).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn boot_guard<N: Num>(
    slot: &mut core::mem::MaybeUninit<GuardOf<N>>,
    cfg: &GuardConfig,
    block: Option<&[u8; BLOCK_LEN]>,
    ram: (&ThermalRecord, &ThermalRecord),
    nv: NvLoad,
    rtc_s: impl FnOnce() -> Option<u32>,
    alive_s: Option<u32>,
    nv_failing: bool,
) -> Booted {
    let (model, params, rig_id) = boot_params(block, cfg.model);
    let now_s = if nv != NvLoad::Empty { rtc_s() } else { None };
    let restore = boot_state(slots::restore_from(ram.0, ram.1), nv, params, model, now_s, alive_s, nv_failing);
    let cfg = GuardConfig { model, ..*cfg };
    let guard = GuardOf::<N>::new_in(slot, &cfg, restore);
    if let ParamSource::Invalid(_) = params {
        guard.refuse_config();
    }
    Booted { params, rig_id, restore: restore_kind(&restore) }
}

/// Accounts `lost` timer periods that had no tick of their own: those a
/// non-volatile save `stalled` are blind ticks ([`GuardOf::tick_blind`],
/// at most [`MAX_STALL_TICKS`]), the others missing ticks
/// ([`GuardOf::tick_missing`], at most [`MAX_MISSED_TICKS`]).
pub fn catch_up<N: Num>(guard: &mut GuardOf<N>, lost: u32, stalled: u32) {
    let blind = lost.min(stalled);
    let _ = guard.tick_blind(blind.min(MAX_STALL_TICKS));
    for _ in 0..(lost - blind).min(MAX_MISSED_TICKS) {
        let _ = guard.tick_missing();
    }
}

pub(super) fn restore_kind(r: &Restore) -> RestoreKind {
    match r {
        Restore::Cold => RestoreKind::Cold,
        Restore::Warm(_) => RestoreKind::Warm,
        Restore::Corrupt => RestoreKind::Corrupt,
        Restore::PowerLoss(_) => RestoreKind::PowerLoss,
    }
}

