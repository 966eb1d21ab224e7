//! `Guard`: validation + model + protection + trace + thermal memory, one call per
//! 10 ms tick (docs/firmware.md).
//!
//! Multi-rate: every tick validates the sample (same-tick fault latching and
//! fail-safe valve opening), substitutes worst cases and accumulates the tick's
//! losses and exchange drivers ([`Model::tick_n`]); every
//! [`crate::params::TICKS_PER_STEP`] ticks the model advances one 100 ms step and the
//! valve/alarm hysteresis, dwell, LNG budget and trace run on the new estimate.

mod types;
pub mod faults;
pub use faults::Faults;
pub use types::{GuardConfig, Output, Sample, DRAIN_C_UNKNOWN};

use crate::crosscheck::{CrossCheck, Verdict};
use crate::memory::{Restore, ThermalRecord};
use crate::model::{InputScales, Model, ModelInputN};
use crate::num::Num;
use crate::params::{N_NODES, TICKS_PER_STEP};
use crate::protection::{alarm_update_with, LngBudget, LngConfig, Valve};
use crate::trace::{RestoreKind, Trace, TraceBuf};
use crate::validate::{self, Channels, LimitsN, CH_ALL, CH_CURRENT, CH_POSITION, CH_P_A, CH_P_B, CH_SPEED};

/// Channels the sensor cross-check compares: a window with any of them substituted
/// by its worst case is not evaluated.
const CROSS_CHANNELS: u8 = CH_CURRENT | CH_P_A | CH_P_B | CH_SPEED;

/// Number type of the firmware build: `f32`, or [`crate::num::Fx`] with `fixed-point`.
#[cfg(not(feature = "fixed-point"))]
pub type Real = f32;
/// Number type of the firmware build: `f32`, or [`crate::num::Fx`] with `fixed-point`.
#[cfg(feature = "fixed-point")]
pub type Real = crate::num::Fx;

/// The guard of the firmware build's number type.
pub type Guard = GuardOf<Real>;

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
    /// Sensor cross-check; `None` without a torque constant (disabled).
    cc: Option<CrossCheck<N>>,
}

impl<N: Num> Core<N> {
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
            core::ptr::addr_of_mut!((*dst).cc).write(cc);
        }
        true
    }
}

/// The guard, generic over the model number type (`f64` for host tests).
#[derive(Clone, Debug)]
pub struct GuardOf<N: Num> {
    /// The model and its constants; used only when `core_ok`.
    core: Core<N>,
    /// The configuration built into a model (else CONFIG, fail-safe).
    core_ok: bool,
    /// Valve dwell in model steps (the configured ticks, rounded up).
    dwell_model_steps: u32,
    stale_ticks: u32,
    startup_timeout_ticks: u32,
    clear_valid_ticks: u32,
    latched: Faults,
    bad_ch: u8,
    prev: Channels<N>,
    prev_ok: u8,
    missing: u32,
    /// Tick index from which every sample was present and valid (the run of valid
    /// samples of the clear rule is `tick - valid_since`).
    valid_since: u32,
    /// `false` until the first sample: until then the guard waits (valve open, model
    /// not started, STALE only after `startup_timeout_ticks`). A cold start takes
    /// the first sample's ambient, and the protection is evaluated once on the
    /// initial (or restored) estimate.
    started: bool,
    cold: bool,
    /// Restored from the non-volatile record after a power loss: the first
    /// sample's ambient, if warmer than the saved one, raises every node.
    after_power_loss: bool,
    /// Tick from which the present valve and credit state hold in this model step.
    mark: u32,
    /// Ticks of this model step before `mark` with the valve commanded open (LNG
    /// budget), and with the exchanger credited (open, no fault latched, LNG left,
    /// the position feedback, if any, not saying shut).
    open_acc: u32,
    credit_acc: u32,
    /// Mean loss of the last model step, cJ per tick (= W).
    last_cj: u32,
    valve: Valve,
    /// Last valve position reported by [`GuardOf::valve_feedback`] (None: no feedback).
    fb: Option<bool>,
    /// Consecutive reports differing from the command.
    fb_mismatch: u32,
    /// Reports differing from the command that latch ACTUATOR.
    mismatch_ticks: u32,
    /// The LNG budget is used up: no exchanger credit.
    lng_empty: bool,
    alarm: bool,
    /// The estimate is not trusted (corrupt record at boot, no sample by the start-up
    /// timeout): alarm and derate held until a successful `clear_faults`.
    untrusted: bool,
    lng: LngBudget,
    lng_low: bool,
    tick: u32,
    /// The outputs, refreshed whenever one of them changes (fault latching, the
    /// fail-safe opening, a model step, clear/refill): a tick on the fast path
    /// returns them as they are.
    out: Output,
    trace: TraceBuf,
}

/// Invariant kept by every place that latches a fault: `latched != 0` implies the
/// valve is commanded open, so the per-tick fast path needs no fail-safe check.
impl<N: Num> GuardOf<N> {
    /// Builds the model once (matrix exponential) and applies the boot rule of
    /// [`crate::memory`]. Never fails: unusable parameters give a CONFIG fault and a
    /// permanently fail-safe guard (valve open, alarm, derate).
    pub fn new(config: &GuardConfig, restore: Restore) -> Self {
        let mut g = core::mem::MaybeUninit::uninit();
        Self::new_in(&mut g, config, restore);
        // SAFETY: `new_in` initialised every field.
        unsafe { g.assume_init() }
    }

    /// [`GuardOf::new`] written in place into `slot` (the firmware keeps the
    /// guard in a static: the boot stack holds no copy of it or its model).
    #[inline(never)]
    pub fn new_in<'a>(slot: &'a mut core::mem::MaybeUninit<Self>, config: &GuardConfig, restore: Restore) -> &'a mut Self {
        /// Writes fields of the struct behind a raw pointer.
        macro_rules! put {
            ($p:expr, $($f:ident : $v:expr),* $(,)?) => { $( core::ptr::addr_of_mut!((*$p).$f).write($v); )* };
        }
        let p = slot.as_mut_ptr();
        // SAFETY: `p` points to `slot`, valid for writes; `Core::init_in` and
        // `put!` write every field exactly once before the reference is made.
        let g = unsafe {
            let ok = Core::<N>::init_in(core::ptr::addr_of_mut!((*p).core), config);
            put!(p,
            core_ok: ok,
            latched: if ok { Faults::NONE } else { faults::CONFIG },
            dwell_model_steps: config.valve.dwell_ticks.div_ceil(TICKS_PER_STEP),
            stale_ticks: config.stale_ticks,
            startup_timeout_ticks: config.startup_timeout_ticks,
            clear_valid_ticks: config.clear_valid_ticks,
            bad_ch: 0,
            prev: [N::ZERO; 6],
            prev_ok: 0,
            missing: 0,
            valid_since: 0,
            started: false,
            cold: true,
            after_power_loss: false,
            mark: 0,
            open_acc: 0,
            credit_acc: 0,
            last_cj: 0,
            // Open from boot: the safe state while the guard waits for its first sample.
            valve: Valve::open(),
            fb: None,
            fb_mismatch: 0,
            mismatch_ticks: config.actuator_mismatch_ticks,
            lng_empty: false,
            alarm: false,
            untrusted: false,
            lng: LngBudget::new(&config.lng),
            lng_low: false,
            tick: 0,
            out: Output {
                drain_c: DRAIN_C_UNKNOWN,
                ..Output::default()
            },
            trace: TraceBuf::new(),
            );
            &mut *p
        };
        let kind = match restore {
            Restore::Cold => RestoreKind::Cold,
            Restore::Warm(r) | Restore::PowerLoss(r) => {
                g.after_power_loss = matches!(restore, Restore::PowerLoss(_));
                if let Some(c) = g.core_ok.then_some(&mut g.core) {
                    c.model.set_temperatures(&r.temps_c, r.ambient_c);
                }
                g.cold = false;
                g.lng.set_used_cj(r.lng_used_cj);
                let saved = Faults::from_bits(r.faults);
                g.latched |= saved & faults::LATCHED & !faults::CONFIG;
                g.bad_ch = saved.channel_mask() & CH_ALL;
                if r.valve_open() {
                    // The valve was open: it stays open for at least its dwell.
                    g.valve.force_open();
                }
                // Saved before a clear restored trust: still not trusted.
                g.untrusted = saved.contains(faults::UNTRUSTED);
                if let Some(c) = g.core_ok.then_some(&mut g.core) {
                    c.model.set_loss_max(g.latched.contains(faults::SENSOR_DISAGREE));
                }
                if g.after_power_loss {
                    RestoreKind::PowerLoss
                } else {
                    RestoreKind::Warm
                }
            }
            Restore::Corrupt => {
                let t = config.alarm.alarm_c;
                if let Some(c) = g.core_ok.then_some(&mut g.core) {
                    c.model.set_temperatures(&[t; N_NODES], t);
                }
                g.cold = false;
                g.lng.set_used_cj(u32::MAX);
                g.latched |= faults::MEMORY_CORRUPT;
                g.untrusted = true;
                RestoreKind::Corrupt
            }
        };
        g.trace.write(Trace::Restore { tick: 0, kind });
        g.lng_empty = g.lng.is_empty();
        g.boot_outputs();
        g
    }

    /// Outputs before the first sample: the restored estimate (none on a cold boot)
    /// with the alarm evaluated on it; no model, no alarm and derate on: CONFIG.
    #[cold]
    #[inline(never)]
    fn boot_outputs(&mut self) {
        match self.core_ok.then_some(&self.core) {
            Some(c) if !self.cold => {
                let d = c.model.drain_c();
                let f = d.to_f32();
                self.out.drain_c = if f.is_finite() { f } else { DRAIN_C_UNKNOWN };
                let raised = if self.untrusted {
                    self.alarm = true;
                    true
                } else {
                    alarm_update_with(&mut self.alarm, d, c.th.alarm, c.th.clear) == Some(true)
                };
                if raised {
                    self.trace.write(Trace::Alarm { tick: 0, drain_c: self.out.drain_c });
                }
            }
            Some(_) => {}
            None => self.alarm = true,
        }
        self.refresh_out();
    }

    /// One 10 ms tick with a new sample. Never panics; any invalid channel latches a
    /// fault, opens the valve in this same tick and is replaced by its worst case.
    #[inline(never)]
    pub fn tick(&mut self, s: &Sample) -> Output {
        if let Some(core) = self.core_ok.then_some(&self.core) {
            // Fast path: every channel in range and within its rate and every previous
            // value valid (so this is not the first tick). Nothing to latch, the valve
            // is not forced by this tick (an earlier latched fault has already opened
            // it), the outputs only change at a model step. Channels latched bad by an
            // earlier fault still take their worst case. Anything else is classified
            // by `tick_slow`.
            let (v, ok) = validate::convert_check(s, &self.prev, &core.scales, &core.limits);
            if ok & (self.prev_ok == CH_ALL) {
                // `missing` is 0 here: a missing tick clears `prev_ok`.
                let u = if self.bad_ch == 0 {
                    validate::direct(&v, &self.prev)
                } else {
                    Self::substitute_latched(&v, &self.prev, self.bad_ch, &core.limits)
                };
                self.prev = v;
                return self.advance(&u);
            }
        }
        self.tick_slow(s)
    }

    /// Fast-path inputs while channels are latched bad: their worst cases.
    #[inline(never)]
    #[cold]
    fn substitute_latched(
        v: &Channels<N>,
        prev: &Channels<N>,
        bad_ch: u8,
        limits: &LimitsN<N>,
    ) -> ModelInputN<N> {
        let [_, _, _, _, prev_pos, _] = *prev;
        validate::substitute(v, bad_ch, Some(prev_pos), limits)
    }

    /// [`GuardOf::tick`] off the fast path: classifies the sample (distinct fault and
    /// channel bits), substitutes worst cases, latches and forces the valve open.
    #[inline(never)]
    #[cold]
    fn tick_slow(&mut self, s: &Sample) -> Output {
        self.missing = 0;
        let Some(core) = self.core_ok.then_some(&self.core) else {
            return self.slow_tail(None, Faults::NONE, N::ZERO);
        };
        let (v, nonfinite) = validate::convert(s, &core.scales);
        let c = validate::check(&v, nonfinite, &self.prev, self.prev_ok, &core.limits);
        let mut new_bits = Faults::NONE;
        if c.range {
            new_bits |= faults::RANGE;
        }
        if c.rate {
            new_bits |= faults::RATE;
        }
        if c.non_finite {
            new_bits |= faults::NON_FINITE;
        }
        self.bad_ch |= c.bad;
        if c.bad != 0 {
            self.valid_since = self.tick.wrapping_add(1);
        }
        let [_, _, _, _, prev_pos, _] = self.prev;
        let prev_pos = if self.prev_ok & CH_POSITION != 0 {
            Some(prev_pos)
        } else {
            None
        };
        let u = validate::substitute(&v, self.bad_ch, prev_pos, &core.limits);
        // A cold start takes this sample's own ambient when it is valid (also when
        // an earlier STALE makes the model run on the worst case from now on), else
        // the worst case.
        let [_, _, _, _, _, amb] = v;
        let start_amb = if c.bad & validate::CH_AMBIENT == 0 { amb } else { u.ambient_c };
        self.prev = v;
        self.prev_ok = !c.bad & CH_ALL;
        self.slow_tail(Some(&u), new_bits, start_amb)
    }

    /// One 10 ms tick without a new sample: inputs are held (piston work taken as
    /// zero); after `stale_ticks` consecutive misses the STALE fault latches and every
    /// channel takes its worst case. Before the first sample the guard waits instead
    /// ([`GuardOf::wait_tick`]).
    pub fn tick_missing(&mut self) -> Output {
        if !self.started {
            return self.wait_tick();
        }
        self.missing = self.missing.saturating_add(1);
        self.valid_since = self.tick.wrapping_add(1);
        self.prev_ok = 0;
        let mut new_bits = Faults::NONE;
        if self.missing >= self.stale_ticks {
            new_bits |= faults::STALE;
            self.bad_ch = CH_ALL;
        }
        let u = self.core_ok.then(|| validate::substitute(&self.prev, self.bad_ch, None, &self.core.limits));
        self.slow_tail(u.as_ref(), new_bits, N::ZERO)
    }

    /// A tick without a sample before the first sample (boot, or samples not yet
    /// flowing): the model is not started and accumulates nothing, the valve stays
    /// open; after `startup_timeout_ticks` such ticks STALE latches (every channel
    /// worst case once samples arrive, until a clear).
    #[cold]
    #[inline(never)]
    fn wait_tick(&mut self) -> Output {
        self.missing = self.missing.saturating_add(1);
        self.valid_since = self.tick.wrapping_add(1);
        if self.missing >= self.startup_timeout_ticks {
            if !self.latched.contains(faults::STALE) {
                self.trace.write(Trace::Fault {
                    tick: self.tick,
                    new_bits: faults::STALE | Faults::channels(CH_ALL),
                });
            }
            self.latched |= faults::STALE;
            self.bad_ch = CH_ALL;
            // No estimate and no input: alarm and derate until a clear.
            self.untrusted = true;
            if !self.alarm {
                self.alarm = true;
                self.trace.write(Trace::Alarm {
                    tick: self.tick,
                    drain_c: self.out.drain_c,
                });
            }
        }
        // The valve is open since boot (nothing closes it before the first sample).
        self.refresh_out();
        self.tick = self.tick.wrapping_add(1);
        self.mark = self.tick;
        self.out
    }

    /// Slow-path tail: latches `new_bits` and opens the valve at once when any fault
    /// is latched (fail-safe in the same tick), starts the model at the first sample
    /// (cold: at `start_amb`), then the common tick.
    fn slow_tail(&mut self, u: Option<&ModelInputN<N>>, new_bits: Faults, start_amb: N) -> Output {
        // The valve / credit state may change for this tick: count the ticks before.
        self.settle(self.tick);
        let newly = new_bits & !self.latched;
        self.latched |= new_bits;
        if !newly.is_empty() {
            self.trace.write(Trace::Fault {
                tick: self.tick,
                new_bits: newly | Faults::channels(self.bad_ch),
            });
        }
        if !self.latched.is_empty() && self.valve.force_open() {
            self.trace.write(Trace::ValveOpen {
                tick: self.tick,
                drain_c: self.out.drain_c,
                forced: true,
            });
        }
        match u {
            Some(u) if self.core_ok => {
                if !self.started {
                    self.start(start_amb);
                }
                self.refresh_out();
                self.advance(u)
            }
            _ => {
                // No model (CONFIG): fail-safe outputs, nothing to estimate.
                self.alarm = true;
                self.out.drain_c = DRAIN_C_UNKNOWN;
                self.refresh_out();
                self.tick = self.tick.wrapping_add(1);
                self.out
            }
        }
    }

    /// The per-tick part common to both paths: the model's tick accumulation, and
    /// every `TICKS_PER_STEP` ticks the model step with the protection.
    #[inline(always)]
    fn advance(&mut self, u: &ModelInputN<N>) -> Output {
        let full = match self.core_ok.then_some(&mut self.core) {
            Some(c) => c.model.tick_n(u),
            None => false,
        };
        if full {
            self.model_step();
        }
        self.tick = self.tick.wrapping_add(1);
        self.out
    }

    /// First sample: a cold start takes every node to `ambient_c`; the valve leaves
    /// the open start-up state by the hysteresis relay on the initial (or restored)
    /// estimate (closed only below the closing threshold, with no qualification: the
    /// opening was not temperature-driven), then the protection is evaluated once.
    #[cold]
    #[inline(never)]
    fn start(&mut self, ambient_c: N) {
        self.started = true;
        // Nothing of the waiting time is counted: no model ran, no credit, no LNG booked.
        self.mark = self.tick;
        self.open_acc = 0;
        self.credit_acc = 0;
        let Some(c) = self.core_ok.then_some(&mut self.core) else {
            return;
        };
        if self.cold {
            c.model.set_uniform(ambient_c);
        } else if self.after_power_loss {
            // The air may have been warmer during the off-time than at the save:
            // every node is raised by the first sample's excess over the saved
            // ambient (the cooling bound assumes the larger of the two).
            let rise = ambient_c.sub(c.model.ambient_c());
            if rise > N::ZERO {
                let t = c.model.temperatures_c().map(|x| x.add(rise).to_f32());
                c.model.set_temperatures(&t, ambient_c.to_f32());
            }
        }
        let d = c.model.drain_c();
        if self.latched.is_empty() && d < c.th.close && self.valve.is_open() {
            self.valve.set(false);
            self.trace.write(Trace::ValveClose {
                tick: self.tick,
                drain_c: d.to_f32(),
            });
        }
        self.protect(0, 0);
    }

    /// Adds the ticks from `mark` up to (not including) `upto` to the open / credited
    /// counts in the present valve and fault state. Called before anything changes
    /// that state, so the counts need no per-tick work: the valve command changes
    /// only at a model step and on the slow path (forced open), the credit also when
    /// faults latch or clear.
    fn settle(&mut self, upto: u32) {
        let n = upto.wrapping_sub(self.mark);
        if self.valve.is_open() {
            self.open_acc = self.open_acc.wrapping_add(n);
            if self.latched.is_empty() && !self.lng_empty && self.fb != Some(false) {
                // The exchanger runs over these ticks. No cooling credit under a
                // latched fault (conservative: the exchanger itself may be what
                // failed), with the LNG used up, or while the valve's position
                // feedback says shut.
                self.credit_acc = self.credit_acc.wrapping_add(n);
            }
        }
        self.mark = upto;
    }

    /// Every `TICKS_PER_STEP` ticks: the model step, then the protection.
    #[inline(never)]
    fn model_step(&mut self) {
        // This tick belongs to the model step that ends now, in the state it had.
        self.settle(self.tick.wrapping_add(1));
        let (open_ticks, credit_ticks) = (self.open_acc, self.credit_acc);
        self.open_acc = 0;
        self.credit_acc = 0;
        let Some(c) = self.core_ok.then_some(&mut self.core) else {
            return;
        };
        c.model.update(credit_ticks);
        // Mean total loss kW → cJ per 10 ms tick (= W), never negative.
        let cj = c.model.last_total_kw().round_times(1000).max(0) as u32;
        if let Some(cc) = c.cc.as_mut() {
            let (from_p, from_i) = c.model.last_mech_pair_kw();
            match cc.step(from_p, from_i, self.bad_ch & CROSS_CHANNELS == 0) {
                Verdict::None => {}
                // While they disagree (and once latched) the model heats with the
                // larger of the two losses.
                Verdict::Window(d) => c.model.set_loss_max(d || self.latched.contains(faults::SENSOR_DISAGREE)),
                Verdict::Latch => {
                    c.model.set_loss_max(true);
                    self.latch_disagree();
                }
            }
        }
        // The valid run of the clear rule is `tick - valid_since`; keep it from
        // wrapping (2^30 ticks = 124 days is far above any clear_valid_ticks).
        if self.tick.wrapping_sub(self.valid_since) > 1 << 30 {
            self.valid_since = self.tick.wrapping_sub(1 << 30);
        }
        self.protect(cj, open_ticks);
    }

    /// The current and the pressures / speed have disagreed for `persist_windows`
    /// windows: SENSOR_DISAGREE latches (the valve opens in `protect`, this same
    /// tick) and the estimate is not trusted (alarm and derate until a clear).
    #[cold]
    #[inline(never)]
    fn latch_disagree(&mut self) {
        if !self.latched.contains(faults::SENSOR_DISAGREE) {
            self.latched |= faults::SENSOR_DISAGREE;
            self.trace.write(Trace::Fault {
                tick: self.tick,
                new_bits: faults::SENSOR_DISAGREE,
            });
        }
        self.untrusted = true;
    }

    /// Valve hysteresis and dwell, alarm, LNG budget (`open_ticks` ticks of the model
    /// step with the valve open, at `cj` centijoules per tick) and the outputs that
    /// change only here.
    fn protect(&mut self, cj: u32, open_ticks: u32) {
        let Some(c) = self.core_ok.then_some(&self.core) else {
            return;
        };
        let force = !self.latched.is_empty();
        let d = c.model.drain_c();
        let th = &c.th;
        let valve_ev = self
            .valve
            .update_with(d, force, th.open, th.close, self.dwell_model_steps);
        let alarm_ev = if self.untrusted {
            // Held whatever the estimate says (raised at boot or at the timeout).
            (!core::mem::replace(&mut self.alarm, true)).then_some(true)
        } else {
            alarm_update_with(&mut self.alarm, d, th.alarm, th.clear)
        };
        let drain_c = d.to_f32();
        let drain_c = if drain_c.is_finite() {
            drain_c
        } else {
            DRAIN_C_UNKNOWN
        };
        self.out.drain_c = drain_c;
        if let Some(open) = valve_ev {
            let t = if open {
                Trace::ValveOpen {
                    tick: self.tick,
                    drain_c,
                    forced: force,
                }
            } else {
                Trace::ValveClose {
                    tick: self.tick,
                    drain_c,
                }
            };
            self.trace.write(t);
        }
        if let Some(a) = alarm_ev {
            let t = if a {
                Trace::Alarm {
                    tick: self.tick,
                    drain_c,
                }
            } else {
                Trace::AlarmClear {
                    tick: self.tick,
                    drain_c,
                }
            };
            self.trace.write(t);
        }
        self.lng.update_cj_ticks(cj, open_ticks);
        // The credit state of the ticks from here on (`settle` ran for the step's).
        self.lng_empty = self.lng.is_empty();
        self.last_cj = cj;
        let low = self.lng.is_low();
        if low && !self.lng_low {
            self.trace.write(Trace::LngLow {
                tick: self.tick,
                remaining_kg: self.lng.remaining_kg(),
            });
        }
        self.lng_low = low;
        self.refresh_out();
    }

    /// Rebuilds the cached outputs from the present state.
    fn refresh_out(&mut self) {
        self.out = Output {
            drain_c: self.out.drain_c,
            valve_open: self.valve.is_open(),
            alarm: self.alarm,
            derate: self.alarm,
            faults: self.faults(),
            lng_remaining_kg: self.lng.remaining_kg(),
            lng_seconds_left: self.lng.seconds_left_cj(self.last_cj),
        };
    }

    /// The outputs as the last tick left them (at boot: the waiting state).
    pub fn output(&self) -> Output {
        self.out
    }

    /// Present faults (see [`faults`]).
    pub fn faults(&self) -> Faults {
        self.latched
            | Faults::channels(self.bad_ch)
            | Faults::when(self.lng_low, faults::LNG_LOW)
            | Faults::when(self.untrusted, faults::UNTRUSTED)
    }

    /// **Clear rule.** Latched faults (except CONFIG) clear only through this explicit
    /// call (maintenance / operator command), and only if the last
    /// `clear_valid_ticks` samples (1 s by default) were all valid and none is missing.
    /// The thermal estimate is *not* reset: it relaxes from its conservative value.
    /// A successful clear also restores trust in the estimate ([`faults::UNTRUSTED`]:
    /// after a corrupt record or no sample by the start-up timeout the alarm and
    /// derate are held until then). Returns `true` when the faults were cleared.
    pub fn clear_faults(&mut self) -> bool {
        let valid_run = self.tick.wrapping_sub(self.valid_since);
        if self.missing != 0 || valid_run < self.clear_valid_ticks {
            return false;
        }
        let bits = (self.latched & !faults::CONFIG) | Faults::channels(self.bad_ch);
        self.settle(self.tick);
        self.latched &= faults::CONFIG;
        self.bad_ch = 0;
        // A valve still disagreeing with its command latches again after the full time;
        // so do sensors that still disagree.
        self.fb_mismatch = 0;
        if let Some(c) = self.core_ok.then_some(&mut self.core) {
            if let Some(cc) = c.cc.as_mut() {
                cc.restart_count();
                c.model.set_loss_max(cc.disagrees());
            }
        }
        // The controller accepts the estimate as it is (it is not reset); the alarm
        // follows it again from the next model step.
        let bits = bits | Faults::when(self.untrusted, faults::UNTRUSTED);
        self.untrusted = false;
        if !bits.is_empty() {
            self.trace.write(Trace::FaultsCleared {
                tick: self.tick,
                bits,
            });
        }
        self.refresh_out();
        true
    }

    /// Marks an actuator (valve pin) error reported by the board: latches ACTUATOR
    /// and commands the valve open at once (fail-safe).
    pub fn report_actuator_fault(&mut self) {
        self.settle(self.tick);
        if !self.latched.contains(faults::ACTUATOR) {
            self.latched |= faults::ACTUATOR;
            self.trace.write(Trace::Fault {
                tick: self.tick,
                new_bits: faults::ACTUATOR,
            });
        }
        if self.valve.force_open() {
            self.trace.write(Trace::ValveOpen {
                tick: self.tick,
                drain_c: self.out.drain_c,
                forced: true,
            });
        }
        self.refresh_out();
    }

    /// Reports the valve position read back from the valve (limit switch or
    /// position sensor), `true` = open. Optional; when used, call it once per tick,
    /// before [`GuardOf::tick`] / [`GuardOf::tick_missing`] (the position holds until
    /// the next report). The model credits the exchanger only while the report does
    /// not say shut; `actuator_mismatch_ticks` consecutive reports that differ from
    /// the command latch ACTUATOR (valve forced open, no credit). Without reports the
    /// command is taken as the position (residual risk: docs/firmware.md).
    pub fn valve_feedback(&mut self, open: bool) {
        if self.fb != Some(open) {
            // The credit may change from this tick on: count the ticks before.
            self.settle(self.tick);
            self.fb = Some(open);
        }
        if open == self.valve.is_open() {
            self.fb_mismatch = 0;
            return;
        }
        self.fb_mismatch = self.fb_mismatch.saturating_add(1);
        if self.fb_mismatch >= self.mismatch_ticks {
            self.report_actuator_fault();
        }
    }

    /// Refills the LNG budget (new charge installed).
    pub fn refill_lng(&mut self, cfg: &LngConfig) {
        // The credit may change from this tick on: count the ticks before.
        self.settle(self.tick);
        self.lng = LngBudget::new(cfg);
        self.lng_empty = self.lng.is_empty();
        self.lng_low = false;
        self.refresh_out();
    }

    /// Thermal-memory record of the present state, valve state included
    /// (sealed with its CRC; sequence number 0: the writer sets it).
    pub fn snapshot(&self) -> ThermalRecord {
        let mut temps = [0.0f32; N_NODES];
        let mut amb = 0.0;
        if let Some(c) = self.core_ok.then_some(&self.core) {
            for (o, t) in temps.iter_mut().zip(c.model.temperatures_c().iter()) {
                *o = t.to_f32();
            }
            amb = c.model.ambient_c().to_f32();
        }
        ThermalRecord::new(
            temps,
            amb,
            self.lng.used_cj(),
            (self.faults() & !faults::LNG_LOW).bits(),
            self.tick,
        )
        .with_seq(0, self.valve.is_open())
    }

    /// The event trace (most recent [`crate::trace::TRACE_LEN`] events).
    pub fn trace(&self) -> &TraceBuf {
        &self.trace
    }

    /// Appends a board-level event (overrun, reset, command) to the trace.
    pub fn trace_event(&mut self, t: Trace) {
        self.trace.write(t);
    }

    /// Refuses the configuration after boot (an invalid parameter block):
    /// CONFIG latches and the model is disabled, as for constants the model
    /// rejects at init: valve open, alarm, drain reported as
    /// [`DRAIN_C_UNKNOWN`]. CONFIG is never cleared.
    pub fn refuse_config(&mut self) {
        self.core_ok = false;
        self.latched |= faults::CONFIG;
    }

    /// The model, when the parameters were usable.
    pub fn model(&self) -> Option<&Model<N>> {
        self.core_ok.then_some(&self.core).map(|c| &c.model)
    }

    /// Ticks taken since boot (10 ms each, wraps after 497 days).
    pub fn ticks(&self) -> u32 {
        self.tick
    }
}
