//! `Guard`: validation + model + protection + trace + thermal memory, one call per
//! 10 ms tick. The only API the firmware main loop needs (docs/contracts.md).

use crate::memory::{Restore, ThermalRecord};
use crate::model::{InputScales, Model};
use crate::num::Num;
use crate::params::{ReducedParams, N_NODES};
use crate::protection::{alarm_update, AlarmConfig, LngBudget, LngConfig, Valve, ValveConfig};
use crate::trace::{RestoreKind, Trace, TraceBuf};
use crate::validate::{self, InputLimits, CH_ALL, CH_POSITION};

/// Fault bits of [`Output::faults`]. Bits 0-6 are latched until the clear rule
/// ([`GuardOf::clear_faults`]); bit 7 is a live status; bits 8-13 name the latched
/// bad input channels (`validate::CH_*` shifted by [`faults::CH_SHIFT`]).
pub mod faults {
    /// An input was outside its plausible range.
    pub const RANGE: u16 = 1 << 0;
    /// An input changed faster than its rate limit.
    pub const RATE: u16 = 1 << 1;
    /// An input was NaN or infinite.
    pub const NON_FINITE: u16 = 1 << 2;
    /// No new sample for `stale_steps` consecutive steps.
    pub const STALE: u16 = 1 << 3;
    /// The thermal-memory record was corrupt at boot.
    pub const MEMORY_CORRUPT: u16 = 1 << 4;
    /// The parameters could not be built into a model (model disabled, fail-safe).
    /// Not clearable at run time: needs valid parameters and a restart.
    pub const CONFIG: u16 = 1 << 5;
    /// The valve output pin reported an error (set by the board layer).
    pub const ACTUATOR: u16 = 1 << 6;
    /// LNG remaining below the low threshold (live status, not latched).
    pub const LNG_LOW: u16 = 1 << 7;
    /// Shift of the latched bad-channel mask inside the fault word.
    pub const CH_SHIFT: u16 = 8;
    /// Bits that latch.
    pub const LATCHED: u16 = 0x7f;
}

/// One input sample, wire units (f32).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(any(target_os = "none", feature = "defmt"), derive(defmt::Format))]
pub struct Sample {
    /// Motor phase current, A rms.
    pub current_a: f32,
    /// Pump port A pressure, bar.
    pub p_a_bar: f32,
    /// Pump port B pressure, bar.
    pub p_b_bar: f32,
    /// Motor speed, rpm (signed).
    pub speed_rpm: f32,
    /// Piston position, mm.
    pub position_mm: f32,
    /// Ambient temperature, degC.
    pub ambient_c: f32,
}

/// One step's result, wire units. Always finite.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(any(target_os = "none", feature = "defmt"), derive(defmt::Format))]
pub struct Output {
    /// Predicted drain-oil temperature, degC ([`DRAIN_C_UNKNOWN`] if the model is disabled).
    pub drain_c: f32,
    /// LNG valve command (`true` = open).
    pub valve_open: bool,
    /// Over-temperature alarm (drain > 60 degC, cleared below 58 degC).
    pub alarm: bool,
    /// Derate request to the actuator controller (= alarm).
    pub derate: bool,
    /// Fault word, see [`faults`].
    pub faults: u16,
    /// LNG remaining, kg.
    pub lng_remaining_kg: f32,
    /// Seconds of LNG cooling left at the present dissipation, s.
    pub lng_seconds_left: f32,
}

/// Drain temperature reported when no model is available (CONFIG fault), degC.
pub const DRAIN_C_UNKNOWN: f32 = 1.0e6;

/// Everything configurable, SI/wire units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardConfig {
    /// Reduced-model parameters.
    pub params: ReducedParams,
    /// Input ranges and rates.
    pub limits: InputLimits,
    /// LNG valve thresholds and dwell.
    pub valve: ValveConfig,
    /// Over-temperature alarm.
    pub alarm: AlarmConfig,
    /// LNG heat sink.
    pub lng: LngConfig,
    /// Consecutive missing samples that make the input stale, steps (5 = 50 ms).
    pub stale_steps: u32,
    /// Consecutive fully valid samples required before `clear_faults` succeeds, steps.
    pub clear_valid_steps: u32,
}

impl GuardConfig {
    /// Defaults: [`crate::params::DEFAULT`], Tables 2/3/6 limits, 40/38 degC valve, 60 degC alarm.
    pub const DEFAULT: GuardConfig = GuardConfig {
        params: crate::params::DEFAULT,
        limits: InputLimits::DEFAULT,
        valve: ValveConfig::DEFAULT,
        alarm: AlarmConfig::DEFAULT,
        lng: LngConfig::DEFAULT,
        stale_steps: 5,
        clear_valid_steps: 100,
    };
}

/// Number type of the firmware build: `f32`, or [`crate::num::Fx`] with `fixed-point`.
#[cfg(not(feature = "fixed-point"))]
pub type Real = f32;
/// Number type of the firmware build: `f32`, or [`crate::num::Fx`] with `fixed-point`.
#[cfg(feature = "fixed-point")]
pub type Real = crate::num::Fx;

/// The guard of the firmware build's number type.
pub type Guard = GuardOf<Real>;

/// The guard, generic over the model number type (`f64` for host tests).
#[derive(Clone, Debug)]
pub struct GuardOf<N: Num> {
    core: Option<(Model<N>, InputScales<N>)>,
    limits: InputLimits,
    valve_cfg: ValveConfig,
    alarm_cfg: AlarmConfig,
    stale_steps: u32,
    clear_valid_steps: u32,
    latched: u16,
    bad_ch: u8,
    prev: Sample,
    prev_ok: u8,
    missing: u32,
    valid_run: u32,
    have_ambient: bool,
    valve: Valve,
    alarm: bool,
    lng: LngBudget,
    lng_low: bool,
    step: u32,
    trace: TraceBuf,
}

impl<N: Num> GuardOf<N> {
    /// Builds the model once (matrix exponential) and applies the boot rule of
    /// [`crate::memory`]. Never fails: unusable parameters give a CONFIG fault and a
    /// permanently fail-safe guard (valve open, alarm, derate).
    pub fn new(config: &GuardConfig, restore: Restore) -> Self {
        let core = match (Model::<N>::new(&config.params), InputScales::<N>::new()) {
            (Ok(m), Some(s)) => Some((m, s)),
            _ => None,
        };
        let mut g = GuardOf {
            latched: if core.is_none() { faults::CONFIG } else { 0 },
            core,
            limits: config.limits,
            valve_cfg: config.valve,
            alarm_cfg: config.alarm,
            stale_steps: config.stale_steps,
            clear_valid_steps: config.clear_valid_steps,
            bad_ch: 0,
            prev: Sample::default(),
            prev_ok: 0,
            missing: 0,
            valid_run: 0,
            have_ambient: false,
            valve: Valve::new(),
            alarm: false,
            lng: LngBudget::new(&config.lng),
            lng_low: false,
            step: 0,
            trace: TraceBuf::new(),
        };
        let kind = match restore {
            Restore::Cold => RestoreKind::Cold,
            Restore::Warm(r) => {
                if let Some((m, _)) = g.core.as_mut() {
                    m.set_temperatures(&r.temps_c, r.ambient_c);
                }
                g.have_ambient = true;
                g.lng.set_used_cj(r.lng_used_cj);
                g.latched |= r.faults & faults::LATCHED & !faults::CONFIG;
                g.bad_ch = ((r.faults >> faults::CH_SHIFT) as u8) & CH_ALL;
                RestoreKind::Warm
            }
            Restore::Corrupt => {
                let t = config.alarm.alarm_c;
                if let Some((m, _)) = g.core.as_mut() {
                    m.set_temperatures(&[t; N_NODES], t);
                }
                g.have_ambient = true;
                g.lng.set_used_cj(u32::MAX);
                g.latched |= faults::MEMORY_CORRUPT;
                RestoreKind::Corrupt
            }
        };
        g.trace.write(Trace::Restore { step: 0, kind });
        g
    }

    /// One 10 ms step with a new sample. Never panics; any invalid channel latches a
    /// fault, opens the valve in this same step and is replaced by its worst case.
    pub fn step(&mut self, s: &Sample) -> Output {
        self.missing = 0;
        let c = validate::check(s, &self.prev, self.prev_ok, &self.limits);
        let mut new_bits = 0u16;
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
        self.valid_run = if c.bad == 0 { self.valid_run.saturating_add(1) } else { 0 };
        let prev_pos = if self.prev_ok & CH_POSITION != 0 { Some(self.prev.position_mm) } else { None };
        let u = validate::substitute(s, self.bad_ch, prev_pos, &self.limits);
        self.prev = *s;
        self.prev_ok = !c.bad & CH_ALL;
        self.advance(&u, new_bits)
    }

    /// One 10 ms step without a new sample: inputs are held (piston work taken as
    /// zero); after `stale_steps` consecutive misses the STALE fault latches and every
    /// channel takes its worst case.
    pub fn step_missing(&mut self) -> Output {
        self.missing = self.missing.saturating_add(1);
        self.valid_run = 0;
        self.prev_ok = 0;
        let mut new_bits = 0;
        if self.missing >= self.stale_steps {
            new_bits |= faults::STALE;
            self.bad_ch = CH_ALL;
        }
        let u = validate::substitute(&self.prev, self.bad_ch, None, &self.limits);
        self.advance(&u, new_bits)
    }

    fn advance(&mut self, u: &crate::model::ModelInput, new_bits: u16) -> Output {
        let newly = new_bits & !self.latched;
        self.latched |= new_bits;
        if newly != 0 {
            self.trace.write(Trace::Fault { step: self.step, new_bits: newly | ((self.bad_ch as u16) << faults::CH_SHIFT) });
        }
        let (drain_c, loss_w) = match self.core.as_mut() {
            Some((m, sc)) => {
                if !self.have_ambient {
                    m.set_temperatures(&[u.ambient_c; N_NODES], u.ambient_c);
                    self.have_ambient = true;
                }
                m.step(u, sc);
                (m.drain_c().to_f32(), m.last_total_kw().to_f32() * 1000.0)
            }
            None => (DRAIN_C_UNKNOWN, 0.0),
        };
        let drain_c = if drain_c.is_finite() { drain_c } else { DRAIN_C_UNKNOWN };
        let force = self.latched != 0;
        if let Some(open) = self.valve.update(drain_c, force, &self.valve_cfg) {
            let t = if open {
                Trace::ValveOpen { step: self.step, drain_c, forced: force }
            } else {
                Trace::ValveClose { step: self.step, drain_c }
            };
            self.trace.write(t);
        }
        if let Some(a) = alarm_update(&mut self.alarm, drain_c, &self.alarm_cfg) {
            let t = if a { Trace::Alarm { step: self.step, drain_c } } else { Trace::AlarmClear { step: self.step, drain_c } };
            self.trace.write(t);
        }
        let loss_w = if loss_w.is_finite() && loss_w > 0.0 { loss_w } else { 0.0 };
        self.lng.update(self.valve.is_open(), loss_w);
        let low = self.lng.is_low();
        if low && !self.lng_low {
            self.trace.write(Trace::LngLow { step: self.step, remaining_kg: self.lng.remaining_kg() });
        }
        self.lng_low = low;
        self.step = self.step.wrapping_add(1);
        Output {
            drain_c,
            valve_open: self.valve.is_open(),
            alarm: self.alarm || self.core.is_none(),
            derate: self.alarm || self.core.is_none(),
            faults: self.faults(),
            lng_remaining_kg: self.lng.remaining_kg(),
            lng_seconds_left: self.lng.seconds_left(loss_w),
        }
    }

    /// Present fault word (see [`faults`]).
    pub fn faults(&self) -> u16 {
        self.latched | ((self.bad_ch as u16) << faults::CH_SHIFT) | if self.lng_low { faults::LNG_LOW } else { 0 }
    }

    /// **Clear rule.** Latched faults (except CONFIG) clear only through this explicit
    /// call (maintenance / operator command), and only if the last
    /// `clear_valid_steps` samples (1 s by default) were all valid and none is missing.
    /// The thermal estimate is *not* reset: it relaxes from its conservative value.
    /// Returns `true` when the faults were cleared.
    pub fn clear_faults(&mut self) -> bool {
        if self.missing != 0 || self.valid_run < self.clear_valid_steps {
            return false;
        }
        let bits = (self.latched & !faults::CONFIG) | ((self.bad_ch as u16) << faults::CH_SHIFT);
        self.latched &= faults::CONFIG;
        self.bad_ch = 0;
        if bits != 0 {
            self.trace.write(Trace::FaultsCleared { step: self.step, bits });
        }
        true
    }

    /// Marks an actuator (valve pin) error reported by the board: latches ACTUATOR.
    pub fn report_actuator_fault(&mut self) {
        if self.latched & faults::ACTUATOR == 0 {
            self.latched |= faults::ACTUATOR;
            self.trace.write(Trace::Fault { step: self.step, new_bits: faults::ACTUATOR });
        }
    }

    /// Refills the LNG budget (new charge installed).
    pub fn refill_lng(&mut self, cfg: &LngConfig) {
        self.lng = LngBudget::new(cfg);
        self.lng_low = false;
    }

    /// Thermal-memory record of the present state (sealed with its CRC).
    pub fn snapshot(&self) -> ThermalRecord {
        let mut temps = [0.0f32; N_NODES];
        let mut amb = 0.0;
        if let Some((m, _)) = self.core.as_ref() {
            for (o, t) in temps.iter_mut().zip(m.temperatures_c().iter()) {
                *o = t.to_f32();
            }
            amb = m.ambient_c().to_f32();
        }
        ThermalRecord::new(temps, amb, self.lng.used_cj(), self.faults() & !faults::LNG_LOW, self.step)
    }

    /// The event trace (most recent [`crate::trace::TRACE_LEN`] events).
    pub fn trace(&self) -> &TraceBuf {
        &self.trace
    }

    /// The model, when the parameters were usable.
    pub fn model(&self) -> Option<&Model<N>> {
        self.core.as_ref().map(|(m, _)| m)
    }

    /// Steps taken since boot (10 ms each, wraps after 497 days).
    pub fn steps(&self) -> u32 {
        self.step
    }
}
