//! `Guard`: validation + model + protection + trace + thermal memory, one call per
//! 10 ms tick (docs/firmware.md).
//!
//! Multi-rate: every tick validates the sample (same-tick fault latching and
//! fail-safe valve opening), substitutes worst cases and accumulates the tick's
//! losses and exchange drivers ([`Model::tick_n`]); every
//! [`crate::params::TICKS_PER_STEP`] ticks the model advances one 100 ms step and the
//! valve/alarm hysteresis, dwell, LNG budget and trace run on the new estimate.

mod boot;
mod control;
mod state;
mod step;
mod tick;
mod types;
pub use crate::interface::{Output, Reports, Sample, DRAIN_C_UNKNOWN};
pub use types::GuardConfig;
// `ClearResult`, `recovery_ticks` and the trust constants are defined below.

use crate::crosscheck::{CrossCheck, Verdict};
use crate::memory::ThermalRecord;
use crate::model::{InputScales, Model, ModelInputN};
use crate::num::Num;
use crate::params::{N_NODES, TICKS_PER_STEP};
use crate::protection::{alarm_update_with, LngBudget, LngConfig, Valve};
use crate::trace::{Trace, TraceBuf};
use crate::faults::{self, ChannelSet, Faults};
use state::{Hold, NvHealth, Phase};
use crate::validate::{self, Channels, LimitsN};

/// Channels the sensor cross-check compares: a window with any of them substituted
/// by its worst case is not evaluated.
const CROSS_CHANNELS: ChannelSet = ChannelSet::CURRENT.union(ChannelSet::P_A).union(ChannelSet::P_B).union(ChannelSet::SPEED);

/// Number type of the firmware build: `f32`, or [`crate::num::Fx`] with `fixed-point`.
#[cfg(not(feature = "fixed-point"))]
pub type Real = f32;
/// Number type of the firmware build: `f32`, or [`crate::num::Fx`] with `fixed-point`.
#[cfg(feature = "fixed-point")]
pub type Real = crate::num::Fx;

/// The guard of the firmware build's number type.
pub type Guard = GuardOf<Real>;

/// The outcome of [`GuardOf::clear_faults`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClearResult {
    /// The latched faults cleared and the estimate is trusted (or was).
    Cleared,
    /// The latched faults cleared, but the estimate started from an unknown
    /// state less than [`recovery_ticks`] ago: UNTRUSTED (alarm, derate)
    /// holds for this many more ticks, then a clear restores it.
    TrustHeld(u32),
    /// The clear rule was not met (a missing or invalid sample in the last
    /// `clear_valid_ticks`): nothing cleared.
    Refused,
}

impl ClearResult {
    /// The latched faults were cleared.
    pub fn cleared(self) -> bool {
        self != ClearResult::Refused
    }
}

/// The largest error of an estimate that started from an unknown state, K:
/// a start at the alarm temperature (60 °C) against an oil up to 100 °C.
pub const TRUST_START_ERROR_K: f32 = 40.0;
/// The error below which the estimate has forgotten its start, K.
pub const TRUST_TOLERANCE_K: f32 = 0.5;
/// `ln(TRUST_START_ERROR_K / TRUST_TOLERANCE_K)` = ln 80 (no `ln` in `core`;
/// checked by a test).
const LN_ERROR_RATIO: f32 = 4.382_027;

/// Ticks (10 ms) an estimate needs to forget an unknown start: its error
/// decays at least as fast as the slowest cooling rate at rest of the model
/// (`rest_rate`, the bound the power-off cooling uses), so after
/// `ln(40 K / 0.5 K) / min(rest_rate)` it is within 0.5 K of the truth
/// (56.2 h for the paper rig). Without a cooling bound (a rate of 0 or not
/// finite) the recovery is unknown: never (capped at 2^30 ticks, 124 days).
pub fn recovery_ticks(model: &crate::model::ModelConsts<f32>) -> u32 {
    const CAP: u32 = 1 << 30;
    let min = model.rest_rate.iter().fold(f32::INFINITY, |m, r| m.min(*r));
    if !(min > 0.0 && min.is_finite()) {
        return CAP;
    }
    let ticks = LN_ERROR_RATIO / min * 100.0;
    if ticks >= CAP as f32 {
        CAP
    } else {
        ticks as u32 + 1
    }
}

/// Protection thresholds converted to the model number type (degC).
#[derive(Clone, Copy, Debug)]
struct Thresholds<N> {
    open: N,
    close: N,
    alarm: N,
    clear: N,
}

/// Everything the tick needs that exists only with usable parameters.
#[derive(Clone, Copy, Debug)]
struct Core<N: Num> {
    model: Model<N>,
    scales: InputScales<N>,
    limits: LimitsN<N>,
    th: Thresholds<N>,
    /// The commissioning margin added to the model's case oil, K
    /// ([`crate::model::ModelConsts::drain_margin_k`], within its bounds).
    margin: N,
    /// Sensor cross-check; `None` without a torque constant (disabled).
    cc: Option<CrossCheck<N>>,
}

impl<N: Num> Core<N> {
    /// The drain-oil estimate of every decision and report (valve, alarm,
    /// trace, outputs), degC: the model's case oil plus the commissioning
    /// margin, on the hot side. The model's own state stays physical: the
    /// margin never feeds back into it (nor into the thermal record).
    #[inline(always)]
    fn drain_c(&self) -> N {
        self.model.drain_c().add(self.margin)
    }

    /// Builds the core in place at `dst`; `false` (and an all-zero core, a
    /// valid value by the [`Num`] contract, never read) when the
    /// configuration cannot be built.
    ///
    /// # Safety
    /// `dst` must be valid for writes of a `Core<N>`.
    #[inline(never)]
    unsafe fn init_in(dst: *mut Self, config: &GuardConfig) -> bool {
        // SAFETY: `dst` is valid for writes (caller); all-zero bytes are a
        // valid `Core<N>` (numbers, bools and an Option of numbers; the
        // `Num` contract covers N and its associated types).
        unsafe {
            dst.write_bytes(0, 1);
            let ok = Model::<N>::init_in(core::ptr::addr_of_mut!((*dst).model), config.model).is_ok() && Self::init_small(dst, config);
            if !ok {
                dst.write_bytes(0, 1);
            }
            ok
        }
    }

    /// The small fields of the core (everything but the model).
    ///
    /// # Safety
    /// As [`Core::init_in`].
    unsafe fn init_small(dst: *mut Self, config: &GuardConfig) -> bool {
        let Some(scales) = InputScales::<N>::new() else { return false };
        let Some(limits) = LimitsN::new(&config.limits, &scales) else { return false };
        let t = [
            config.valve.open_c,
            config.valve.close_c,
            config.alarm.alarm_c,
            config.alarm.clear_c,
        ];
        if t.iter().any(|x| !x.is_finite() || x.abs() >= 250.0) {
            return false;
        }
        let f = |x: f32| N::from_exact(x, x as f64);
        let th = Thresholds {
            open: f(t[0]),
            close: f(t[1]),
            alarm: f(t[2]),
            clear: f(t[3]),
        };
        let cc = if config.model.k_sh > 0.0 {
            let Some(cc) = CrossCheck::new(&config.crosscheck, TICKS_PER_STEP) else { return false };
            Some(cc)
        } else {
            None
        };
        // SAFETY: `dst` is valid for writes (caller).
        unsafe {
            core::ptr::addr_of_mut!((*dst).scales).write(scales);
            core::ptr::addr_of_mut!((*dst).limits).write(limits);
            core::ptr::addr_of_mut!((*dst).th).write(th);
            core::ptr::addr_of_mut!((*dst).margin).write(N::from_f32(config.model.drain_margin_k));
            core::ptr::addr_of_mut!((*dst).cc).write(cc);
        }
        true
    }
}

/// The core, and whether the configuration built it: the one way to reach it
/// ([`CoreSlot::get`]), so no code can use a core that was not built.
#[derive(Clone, Copy, Debug)]
struct CoreSlot<N: Num> {
    core: Core<N>,
    /// The configuration built into a model (else CONFIG, fail-safe).
    ok: bool,
}

impl<N: Num> CoreSlot<N> {
    /// The core, when the configuration built it.
    #[inline(always)]
    fn get(&self) -> Option<&Core<N>> {
        self.ok.then_some(&self.core)
    }

    /// [`CoreSlot::get`], mutable.
    #[inline(always)]
    fn get_mut(&mut self) -> Option<&mut Core<N>> {
        self.ok.then_some(&mut self.core)
    }

    /// Builds the slot in place at `dst` ([`Core::init_in`]); whether the
    /// core was built.
    ///
    /// # Safety
    /// `dst` must be valid for writes of a `CoreSlot<N>`.
    #[inline(always)]
    unsafe fn init_in(dst: *mut Self, config: &GuardConfig) -> bool {
        // SAFETY: `dst` is valid for writes (caller): so are its fields.
        unsafe {
            let ok = Core::<N>::init_in(core::ptr::addr_of_mut!((*dst).core), config);
            core::ptr::addr_of_mut!((*dst).ok).write(ok);
            ok
        }
    }
}

/// The guard, generic over the model number type (`f64` for host tests).
/// `repr(C)`: the fields in their declared order, which a change of the
/// small state then does not reshuffle. Where the model and the hot fields
/// sit decides the size and cost of the firmware's code (their offsets are
/// immediates of its instructions): this order, rustc's own before the
/// state was typed, gave the product image 40 868 B, rustc's new choice
/// 41 148 B.
#[derive(Clone, Debug)]
#[repr(C)]
pub struct GuardOf<N: Num> {
    /// The trust hold of an estimate whose state was unknown: a corrupt or
    /// damaged record, no sample by the start-up timeout, a record saved
    /// while recovering (pending until the first sample), or inputs found to
    /// disagree (SENSOR_DISAGREE: pending until the clear, when the inputs
    /// are good again).
    hold: Hold,
    /// Speed plausibility (`None`: no usable constants, CONFIG).
    speed: Option<crate::speedcheck::SpeedCheck>,
    valve: Valve,
    trace: TraceBuf,
    /// The outputs, refreshed whenever one of them changes (fault latching, the
    /// fail-safe opening, a model step, clear/refill): a tick on the fast path
    /// returns them as they are.
    out: Output,
    /// The model and its constants, when the configuration built them.
    core: CoreSlot<N>,
    /// Valve dwell in model steps (the configured ticks, rounded up).
    dwell_model_steps: u32,
    stale_ticks: u32,
    startup_timeout_ticks: u32,
    clear_valid_ticks: u32,
    latched: Faults,
    prev: Channels<N>,
    /// Ticks waited for the first sample (replayed at the start).
    waited: u32,
    /// The first sample's own inputs, for that replay.
    replay_u: ModelInputN<N>,
    missing: u32,
    /// Tick index from which every sample was present and valid (the run of valid
    /// samples of the clear rule is `tick - valid_since`).
    valid_since: u32,
    /// Tick from which the present valve and credit state hold in this model step.
    mark: u32,
    /// Ticks of this model step before `mark` with the valve commanded open (LNG
    /// budget), and with the exchanger credited (open, no fault latched, LNG left,
    /// the position feedback, if any, not saying shut).
    open_acc: u32,
    credit_acc: u32,
    /// Mean loss of the last model step, cJ per tick (= W).
    last_cj: u32,
    /// Least supply pressure that says the tank has LNG, bar.
    min_supply_bar: f32,
    /// Consecutive reports differing from the command.
    fb_mismatch: u32,
    /// Reports differing from the command that latch ACTUATOR.
    mismatch_ticks: u32,
    /// Ticks the estimate needs to forget an unknown start
    /// ([`recovery_ticks`]).
    recovery_ticks: u32,
    lng: LngBudget,
    tick: u32,
    /// Changes of the outputs and of the recorded state ([`GuardOf::epoch`]).
    epoch: u32,
    // One-byte state last (no padding).
    /// Inside [`GuardOf::tick_blind`] or the replay of the wait: no
    /// cooling credit.
    blind: bool,
    /// Waiting until the first sample (valve open, model not started, STALE
    /// only after `startup_timeout_ticks`), then running; at the first sample
    /// the protection is evaluated once on the initial (or restored) estimate.
    phase: Phase,
    /// The LNG budget is used up: no exchanger credit.
    lng_empty: bool,
    alarm: bool,
    /// The estimate is not trusted (corrupt record at boot, no sample by the start-up
    /// timeout): alarm and derate held until a successful `clear_faults`.
    untrusted: bool,
    lng_low: bool,
    /// A non-volatile save failed (`faults::NV_FAILED`, derate) and no
    /// clear has seen a good save since, or not.
    nv: NvHealth,
    /// Last valve position reported by [`GuardOf::valve_feedback`] (None: no feedback).
    fb: Option<bool>,
    /// The LNG supply pressure says the tank has LNG (None: not reported,
    /// [`GuardOf::lng_supply`]).
    supply: Option<bool>,
    /// Channels latched bad: at their worst case until a clear.
    bad_ch: ChannelSet,
    /// Channels whose previous value is valid (the rate check's reference).
    prev_ok: ChannelSet,
    /// `prev_ok` before the missing ticks since the last sample: the rate
    /// check of the next sample over the gap.
    gap_ok: ChannelSet,
}
