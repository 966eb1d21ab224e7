//! Protection logic on the predicted drain temperature: LNG valve with
//! hysteresis, immediate opening and a dwell-qualified closing, over-temperature alarm with derate request,
//! and the LNG heat-sink budget (paper section IV, eqs. 23-25, Table 6).

/// LNG valve thresholds and dwell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ValveConfig {
    /// Opens when the predicted drain temperature exceeds this, degC (paper: 40 degC).
    /// An opening is never delayed.
    pub open_c: f32,
    /// Closes when the predicted drain temperature has stayed below this for the
    /// whole dwell, degC. The 2 K band is 4 sigma of the 0.5 K sensor noise the
    /// issue specifies.
    pub close_c: f32,
    /// Dwell, 10 ms ticks (200 = 2 s): the valve closes only after the estimate has
    /// been below `close_c` at every decision of the last `dwell_ticks` (which is
    /// also the minimum open time, counted from any opening, forced or not). It
    /// never delays an opening. The guard decides on temperature once per model step
    /// and counts the dwell in model steps (`dwell_ticks / TICKS_PER_STEP`, rounded
    /// up: 20 steps of 100 ms).
    pub dwell_ticks: u32,
}

impl ValveConfig {
    /// 40 degC open, 38 degC close, 2 s dwell.
    pub const DEFAULT: ValveConfig = ValveConfig {
        open_c: 40.0,
        close_c: 38.0,
        dwell_ticks: 200,
    };
}

/// LNG valve state machine: hysteresis relay whose opening is immediate and whose
/// closing is qualified by the dwell.
///
/// Why a qualified closing and not just a minimum open time: with a minimum open
/// time alone, noise on the estimate near the closing threshold closes the valve
/// on one low sample and the next high sample reopens it a decision later (two
/// toggles 0.2 s apart with sigma = 0.5 K at a mean of 38.5 degC, `tests/core/valve.rs`).
/// Requiring the whole dwell below the closing threshold keeps an opening
/// undelayed and still gives at most one toggle per dwell under that noise. It errs
/// on the hot side: the valve stays open up to one dwell longer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Valve {
    open: bool,
    /// Consecutive decisions with the estimate below the closing threshold while
    /// open (reset by every opening and by every decision not below it).
    below: u32,
}

impl Valve {
    /// Closed.
    pub const fn new() -> Self {
        Valve { open: false, below: 0 }
    }

    /// Open (the guard's state from boot until its first sample).
    pub const fn open() -> Self {
        Valve { open: true, below: 0 }
    }

    /// `true` when commanded open.
    #[inline(always)]
    pub fn is_open(&self) -> bool {
        self.open
    }

    /// Fail-safe opening (a latched fault), at once. Returns `true` when the command
    /// changed. Restarts the closing qualification either way.
    #[inline(always)]
    pub fn force_open(&mut self) -> bool {
        self.below = 0;
        if self.open {
            false
        } else {
            self.open = true;
            true
        }
    }

    /// Sets the command without a decision (start-up: the state the relay gives the
    /// initial estimate). Restarts the closing qualification.
    pub fn set(&mut self, open: bool) {
        self.open = open;
        self.below = 0;
    }

    /// One decision (the dwell counts calls: 10 ms ticks here, model steps in the
    /// guard). `force_open` (faults, non-finite estimate) opens at once and holds it
    /// open. Otherwise: open at once when `drain_c > open_c`; close when `drain_c <
    /// close_c` at this and the `dwell_ticks - 1` decisions before it (at least one).
    /// A NaN temperature keeps it open / opens it. Returns `Some(new_state)` when the
    /// command changed.
    pub fn update(&mut self, drain_c: f32, force_open: bool, cfg: &ValveConfig) -> Option<bool> {
        self.update_with(
            drain_c,
            force_open,
            cfg.open_c,
            cfg.close_c,
            cfg.dwell_ticks,
        )
    }

    /// [`Valve::update`] for any ordered number type (thresholds in the same type).
    /// An unordered value (NaN) forces the valve open.
    #[inline(always)]
    pub fn update_with<T: PartialOrd>(
        &mut self,
        drain: T,
        force_open: bool,
        open_above: T,
        close_below: T,
        dwell_ticks: u32,
    ) -> Option<bool> {
        if force_open || drain.partial_cmp(&drain).is_none() {
            return self.force_open().then_some(true);
        }
        if !self.open {
            if drain > open_above {
                self.set(true);
                return Some(true);
            }
            return None;
        }
        if drain < close_below {
            self.below = self.below.saturating_add(1);
            if self.below >= dwell_ticks {
                self.set(false);
                return Some(false);
            }
        } else {
            self.below = 0;
        }
        None
    }
}

impl Default for Valve {
    fn default() -> Self {
        Self::new()
    }
}

/// Over-temperature alarm thresholds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlarmConfig {
    /// Raised when the predicted drain exceeds this, degC (paper: 60 degC permissible).
    pub alarm_c: f32,
    /// Cleared when it falls below this, degC.
    pub clear_c: f32,
}

impl AlarmConfig {
    /// 60 degC raise, 58 degC clear.
    pub const DEFAULT: AlarmConfig = AlarmConfig {
        alarm_c: 60.0,
        clear_c: 58.0,
    };
}

/// Alarm with hysteresis; returns `Some(new_state)` on change. NaN raises it.
pub fn alarm_update(active: &mut bool, drain_c: f32, cfg: &AlarmConfig) -> Option<bool> {
    alarm_update_with(active, drain_c, cfg.alarm_c, cfg.clear_c)
}

/// [`alarm_update`] for any ordered number type. An unordered value raises it.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
#[inline(always)]
pub fn alarm_update_with<T: PartialOrd>(
    active: &mut bool,
    drain: T,
    alarm_above: T,
    clear_below: T,
) -> Option<bool> {
    let want = if drain.partial_cmp(&drain).is_none() {
        true
    } else if *active {
        !(drain < clear_below)
    } else {
        drain > alarm_above
    };
    if want != *active {
        *active = want;
        Some(want)
    } else {
        None
    }
}

/// LNG heat-sink parameters (Table 6) and the charge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LngConfig {
    /// Charge volume, L (paper: 5 L, 2x redundancy over the 2.3 L needed).
    pub charge_l: f32,
    /// LNG density, kg/m^3 (Table 6: 430).
    pub density_kg_per_m3: f32,
    /// Latent heat of vaporisation, J/kg (Table 6: 509 kJ/kg).
    pub latent_j_per_kg: f32,
    /// Sensible specific heat, J/(kg K) (Table 6: 2.9 kJ/(kg K)).
    pub sensible_j_per_kg_k: f32,
    /// LNG inlet-outlet temperature rise, K (Table 6: 180).
    pub delta_t_k: f32,
    /// LNG-low raised below this fraction of the charge (0.2 = 20 %).
    pub low_fraction: f32,
    /// Least LNG supply pressure at the valve that says the tank has LNG,
    /// bar gauge (when the pressure is reported: [`crate::GuardOf::lng_supply`]).
    pub min_supply_bar: f32,
}

impl LngConfig {
    /// Table 6 values with a 5 L charge, LNG-low at 20 %.
    pub const DEFAULT: LngConfig = LngConfig {
        charge_l: 5.0,
        density_kg_per_m3: 430.0,
        latent_j_per_kg: 509.0e3,
        sensible_j_per_kg_k: 2.9e3,
        delta_t_k: 180.0,
        low_fraction: 0.2,
        min_supply_bar: 1.0,
    };

    /// Eq. (25): `M = V rho`, kg (5 L → 2.15 kg).
    pub fn charge_kg(&self) -> f32 {
        self.charge_l * 1e-3 * self.density_kg_per_m3
    }

    /// Eq. (24) per kg: `c_latent + c_sensible dT`, J/kg (1.031e6 J/kg).
    pub fn j_per_kg(&self) -> f32 {
        self.latent_j_per_kg + self.sensible_j_per_kg_k * self.delta_t_k
    }
}

/// Reported seconds-left when the dissipation is (near) zero, s (finite cap).
pub const LNG_SECONDS_CAP: f32 = 1.0e9;
/// Energy bookkeeping unit: centijoule (cJ) per W per 10 ms tick.
const CJ_PER_W_TICK: f32 = 100.0 * crate::params::S_PER_TICK as f32;

/// LNG budget: heat absorbed while the valve is open, integrated exactly in
/// centijoules in a `u32` (FPU-only conversions; 1 kW adds 1000 cJ per 10 ms tick
/// with ±0.5 cJ unbiased rounding; capacity up to 4.29e7 J ≈ 97 L of LNG, saturating).
///
/// Heat absorbed per tick = the model's total loss (eq. 23, `Q = P_sum t`; the guard
/// books a model step's mean loss for each of its ticks with the valve open):
/// the cooler is sized so that the heat sink equals the heat produced (section IV),
/// so while it is open it absorbs the dissipation. This over-estimates LNG use when
/// the cooler absorbs less (conservative for the remaining-LNG report).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LngBudget {
    used_cj: u32,
    capacity_cj: u32,
    low_cj: u32,
    kg_per_cj: f32,
}

impl LngBudget {
    /// Full charge per `cfg`.
    pub fn new(cfg: &LngConfig) -> Self {
        // (f32: the charge in centijoules to 7 digits, the budget's own accuracy
        // is that of eq. 23's latent heat)
        let j_per_kg = cfg.j_per_kg();
        let cap_cj = cfg.charge_kg() * j_per_kg * 100.0;
        LngBudget {
            used_cj: 0,
            capacity_cj: cap_cj as u32,
            low_cj: (cap_cj * cfg.low_fraction) as u32,
            kg_per_cj: 1.0 / (j_per_kg * 100.0),
        }
    }

    /// Adds one 10 ms tick of absorbed heat at `loss_w` (W) when `valve_open`.
    #[inline]
    pub fn update(&mut self, valve_open: bool, loss_w: f32) {
        if valve_open {
            // `as` saturates: NaN → 0, negative → 0 (the model never reports either).
            let cj = (loss_w * CJ_PER_W_TICK + 0.5) as u32;
            self.used_cj = self.used_cj.saturating_add(cj);
        }
    }

    /// Adds one tick of absorbed heat, `cj` centijoules (= W for a 10 ms tick), when open.
    #[inline(always)]
    pub fn update_cj(&mut self, valve_open: bool, cj: u32) {
        if valve_open {
            self.used_cj = self.used_cj.saturating_add(cj);
        }
    }

    /// Adds `open_ticks` ticks of absorbed heat at `cj_per_tick` centijoules each.
    #[inline(always)]
    pub fn update_cj_ticks(&mut self, cj_per_tick: u32, open_ticks: u32) {
        self.used_cj = self.used_cj.saturating_add(cj_per_tick.saturating_mul(open_ticks));
    }

    /// Seconds left at a dissipation of `cj_per_tick` cJ per 10 ms tick (= W), integer
    /// division (resolution 10 ms), capped at [`LNG_SECONDS_CAP`] when below 1 W.
    #[inline(always)]
    pub fn seconds_left_cj(&self, cj_per_tick: u32) -> f32 {
        if cj_per_tick == 0 {
            return LNG_SECONDS_CAP;
        }
        let ticks = self.capacity_cj.saturating_sub(self.used_cj) / cj_per_tick;
        ticks as f32 * crate::params::S_PER_TICK as f32
    }

    /// Heat absorbed so far, cJ (0.01 J).
    pub fn used_cj(&self) -> u32 {
        self.used_cj
    }

    /// Restores the used energy (thermal memory), cJ.
    pub fn set_used_cj(&mut self, cj: u32) {
        self.used_cj = cj;
    }

    /// Remaining heat-sink energy, J.
    pub fn remaining_j(&self) -> f32 {
        self.capacity_cj.saturating_sub(self.used_cj) as f32 * 0.01
    }

    /// Remaining LNG, kg (eq. 24 inverted).
    pub fn remaining_kg(&self) -> f32 {
        self.capacity_cj.saturating_sub(self.used_cj) as f32 * self.kg_per_cj
    }

    /// Seconds of cooling left at the present dissipation `loss_w`, s (capped at
    /// [`LNG_SECONDS_CAP`] when the dissipation is below 1 mW).
    pub fn seconds_left(&self, loss_w: f32) -> f32 {
        let r = self.remaining_j();
        if loss_w > 1e-3 {
            let s = r / loss_w;
            if s < LNG_SECONDS_CAP {
                s
            } else {
                LNG_SECONDS_CAP
            }
        } else {
            LNG_SECONDS_CAP
        }
    }

    /// `true` when nothing is left (the heat absorbed reached the charge's capacity).
    pub fn is_empty(&self) -> bool {
        self.used_cj >= self.capacity_cj
    }

    /// `true` when remaining < the low threshold.
    pub fn is_low(&self) -> bool {
        self.capacity_cj.saturating_sub(self.used_cj) < self.low_cj
    }
}
