//! Sensor cross-check (analytic redundancy): the shaft's mechanical loss from the
//! port pressures and the speed (eq. 8, what the model heats with) against the same
//! loss from the motor current (shaft power `Kt |I| |w|` minus the hydraulic power
//! `D dp w`), compared as means over windows of model steps.
//!
//! On consistent sensors both are eq. 8 (the reference plant's current is exactly
//! `|D dp + sign(w) eta_m D |dp|| / Kt`): the closed-loop acceptance runs disagree
//! by at most 0.19 W per 0.5 s window (Case 2's servo; 0.072 W on the throttle runs). The bound, 5 W, is what the estimate's own
//! error budget can absorb, not a sensor tolerance: a sustained mechanical-loss
//! error of 1 W moves the drain estimate by up to 0.075 K after 600 s (Case 1 at
//! 20 bar, the most sensitive acceptance point; 0.053 K/W at 60 bar), and the
//! estimate has 0.5 - 0.072 = 0.43 K of its under-prediction bound left, so an
//! undetected disagreement must stay below 0.43 / 0.075 = 5.7 W. Above the bound
//! the guard heats with the larger of the two estimates and, after
//! `persist_windows` such windows in a row, latches SENSOR_DISAGREE
//! (docs/firmware.md: what it can and cannot see).

use crate::num::Num;

/// Cross-check settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrossCheckConfig {
    /// Window of means, 10 ms ticks, counted in model steps (rounded up): 50 = 0.5 s.
    pub window_ticks: u32,
    /// Consecutive disagreeing windows that latch SENSOR_DISAGREE (2 = 1 s); 0 never
    /// latches (the larger loss is still used while the estimates disagree).
    pub persist_windows: u32,
    /// Bound on the window-mean disagreement of the two loss estimates, W (module
    /// docs: from the estimate's error budget).
    pub bound_w: f32,
}

impl CrossCheckConfig {
    /// 0.5 s windows, latched after 2 in a row (1 s: the fault campaign's
    /// detection rule), 5 W.
    pub const DEFAULT: CrossCheckConfig = CrossCheckConfig {
        window_ticks: 50,
        persist_windows: 2,
        bound_w: 5.0,
    };
}

/// State of the cross-check (number type of the model).
#[derive(Clone, Copy, Debug)]
pub struct CrossCheck<N> {
    /// Model steps per window.
    steps: u32,
    /// `1 / steps`.
    inv: N,
    /// Bound, kW.
    bound: N,
    persist: u32,
    /// Model steps in the present window.
    n: u32,
    /// Window mean of (current-based - pressure-based loss) so far, kW.
    acc: N,
    /// Consecutive disagreeing windows.
    run: u32,
    /// The last complete window disagreed.
    disagree: bool,
    /// The model step in progress has ticks whose channels were substituted
    /// (a clear mid-step): it and its window are dropped.
    tainted: bool,
}

/// What one model step of the cross-check found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Window not complete, or nothing changed.
    None,
    /// A window ended; `true` when it disagreed.
    Window(bool),
    /// The disagreement has persisted: latch SENSOR_DISAGREE.
    Latch,
}

impl<N: Num> CrossCheck<N> {
    /// `None` when the bound or the window does not fit the number type, or the
    /// window is empty.
    pub fn new(cfg: &CrossCheckConfig, ticks_per_step: u32) -> Option<Self> {
        let steps = cfg.window_ticks.div_ceil(ticks_per_step.max(1));
        let b = cfg.bound_w * 1e-3;
        if steps == 0 || !b.is_finite() || !(0.0..250.0).contains(&b) {
            return None;
        }
        Some(CrossCheck {
            steps,
            inv: N::from_exact(1.0 / steps as f32, 1.0 / steps as f64),
            bound: N::from_exact(b, cfg.bound_w as f64 * 1e-3),
            persist: cfg.persist_windows,
            n: 0,
            acc: N::ZERO,
            run: 0,
            disagree: false,
            tainted: false,
        })
    }

    /// One model step with its two loss estimates (kW). `usable`: the step's
    /// current, pressures and speed are measured, not worst-case substitutes; a
    /// window with an unusable step is dropped (the disagreement state holds).
    #[inline(always)]
    pub fn step(&mut self, from_pressure: N, from_current: N, usable: bool) -> Verdict {
        if !usable | core::mem::replace(&mut self.tainted, false) {
            self.n = 0;
            self.acc = N::ZERO;
            return Verdict::None;
        }
        self.acc = self.acc.add(from_current.sub(from_pressure).mul(self.inv));
        self.n += 1;
        if self.n < self.steps {
            return Verdict::None;
        }
        self.window_end()
    }

    #[cold]
    #[inline(never)]
    fn window_end(&mut self) -> Verdict {
        // NaN compares false: counted as agreeing (the model's own NaN handling
        // opens the valve); the inputs are validated finite.
        let d = self.acc.abs() > self.bound;
        self.n = 0;
        self.acc = N::ZERO;
        self.disagree = d;
        self.run = if d { self.run.saturating_add(1) } else { 0 };
        if d && self.persist != 0 && self.run == self.persist {
            Verdict::Latch
        } else {
            Verdict::Window(d)
        }
    }

    /// The last complete window disagreed.
    pub fn disagrees(&self) -> bool {
        self.disagree
    }

    /// The model step in progress mixes substituted and measured ticks (the
    /// channels were cleared mid-step): its window is dropped at the step's end,
    /// as a window with an unusable step is. Without it, the worst-case current
    /// of the ticks before a clear made one window disagree by kilowatts.
    pub fn taint_step(&mut self) {
        self.tainted = true;
    }

    /// Restarts the count of disagreeing windows (after a clear: a disagreement that
    /// goes on latches again after the full time).
    pub fn restart_count(&mut self) {
        self.run = 0;
    }
}
