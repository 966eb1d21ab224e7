//! Speed plausibility: the speed channel against sources that do not scale
//! with it. The torque cross-check ([`crate::crosscheck`]) cannot see a
//! speed sensor error: both its loss estimates scale with the measured
//! speed, and the pump heats with the true one (5 of 150 campaign runs
//! failed on it: stuck at zero, reading half, drifting to zero, the true
//! drain 57–62 °C with the valve shut). Three rules, each over 0.5 s windows
//! and latched after two in a row (1 s), or after a stated time:
//!
//! * **Electrical frequency** (optional input, the motor drive's commutation
//!   frequency, `f_e = pole pairs x rev/s`): the window means of
//!   `60 |f_e| / pole pairs` and of `|speed|` must agree within 5 % + 30 rpm.
//!   With it every speed-sensor fault of the campaign is seen.
//! * **Piston flow** (servo use): the piston cannot move more oil than the
//!   pump delivers: over a window `sum A |dx| <= 1.1 (sum D |w| + leakage at
//!   the ports' pressures) + D x 30 rpm`. One-sided: a speed reading low while
//!   the piston moves is seen; a throttling duty (flow through a valve, the
//!   piston still) is not tested by it.
//! * **Stall under load** (no electrical frequency): the motor drawing more
//!   than 10 times its no-load current (the friction torque `T0 / Kt`; 4 A on
//!   the paper rig) with the speed reading below 30 rpm for 2 s. Residual
//!   risk, stated: an actuator that holds a load at standstill for longer
//!   trips it (a false SENSOR_DISAGREE: valve open, derate) — such a duty
//!   needs the electrical frequency, which replaces this rule.
//!
//! A latch is SENSOR_DISAGREE with the speed channel bad: the speed's worst
//! case (the top of its range) from then on, valve open, alarm until a clear
//! ([`crate::GuardOf::check_speed`]). Arithmetic in `f32` wire units (the
//! product builds have an FPU; a handful of operations per tick).

use crate::model::{ModelConsts, HRADS_PER_RPM};
use crate::interface::Sample;

/// Speed-check settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedCheckConfig {
    /// Window, 10 ms ticks (50 = 0.5 s).
    pub window_ticks: u32,
    /// Disagreeing windows in a row that latch (2 = 1 s).
    pub persist_windows: u32,
    /// Relative tolerance of the electrical-frequency rule.
    pub ref_rel: f32,
    /// Absolute tolerance of the electrical-frequency rule, rpm.
    pub ref_abs_rpm: f32,
    /// Relative margin of the piston-flow rule.
    pub flow_margin: f32,
    /// The stall rule's "near zero" speed, rpm (also the piston-flow rule's
    /// floor, as a pump flow).
    pub stall_rpm: f32,
    /// The stall rule's current, as a multiple of the no-load current.
    pub stall_current_x: f32,
    /// The stall rule's time, ticks (200 = 2 s).
    pub stall_ticks: u32,
}

impl SpeedCheckConfig {
    /// 0.5 s windows latched after 2; 5 % + 30 rpm; 10 % flow margin; stall
    /// below 30 rpm above 10 x the no-load current for 2 s.
    pub const DEFAULT: SpeedCheckConfig = SpeedCheckConfig {
        window_ticks: 50,
        persist_windows: 2,
        ref_rel: 0.05,
        ref_abs_rpm: 30.0,
        flow_margin: 0.1,
        stall_rpm: 30.0,
        stall_current_x: 10.0,
        stall_ticks: 200,
    };
}

/// State of the speed check.
#[derive(Clone, Copy, Debug)]
pub struct SpeedCheck {
    cfg: SpeedCheckConfig,
    /// rpm per Hz of the electrical frequency.
    rpm_per_hz: f32,
    /// Pump flow per rpm, L/s.
    q_per_rpm: f32,
    /// Piston flow per mm of motion per tick, L/s.
    q_per_mm: f32,
    /// Port leakage per bar, L/s.
    leak_per_bar: f32,
    /// The stall rule's current, A.
    stall_current_a: f32,
    n: u32,
    n_ref: u32,
    sum_ref: f32,
    sum_meas: f32,
    sum_piston: f32,
    sum_pump: f32,
    run_ref: u32,
    run_flow: u32,
    stall: u32,
    prev_pos: Option<f32>,
}

impl SpeedCheck {
    /// From the model constants (pole pairs, displacement, piston area,
    /// leakage, no-load and torque constant); `None` when they give no
    /// usable scale (the bounds table keeps them in range).
    pub fn new(cfg: &SpeedCheckConfig, c: &ModelConsts<f32>) -> Option<Self> {
        let rpm_per_hz = 60.0 / c.pole_pairs;
        // no-load current: the friction torque T0 over Kt (k_m0 / k_sh, in 100 A)
        let stall_current_a = cfg.stall_current_x * 100.0 * c.k_m0 / c.k_sh;
        let q_per_rpm = c.k_q * HRADS_PER_RPM as f32;
        let ok = [rpm_per_hz, q_per_rpm, c.k_a, stall_current_a].iter().all(|x| x.is_finite() && *x > 0.0) && cfg.window_ticks > 0;
        ok.then_some(SpeedCheck {
            cfg: *cfg,
            rpm_per_hz,
            q_per_rpm,
            q_per_mm: c.k_a,
            leak_per_bar: c.k_lf * 0.01,
            stall_current_a,
            n: 0,
            n_ref: 0,
            sum_ref: 0.0,
            sum_meas: 0.0,
            sum_piston: 0.0,
            sum_pump: 0.0,
            run_ref: 0,
            run_flow: 0,
            stall: 0,
            prev_pos: None,
        })
    }

    /// One tick with sample `s` (wire units) and the electrical frequency,
    /// if reported; `true`: the speed channel is implausible (latch).
    /// Samples with a non-finite channel are skipped (the validation latches
    /// them).
    pub fn tick(&mut self, s: &Sample, elec_hz: Option<f32>) -> bool {
        let finite = [s.current_a, s.p_a_bar, s.p_b_bar, s.speed_rpm, s.position_mm].iter().all(|x| x.is_finite());
        if !finite {
            self.prev_pos = None;
            return false;
        }
        let w = s.speed_rpm.abs();
        let reference = elec_hz.filter(|f| f.is_finite()).map(|f| f.abs() * self.rpm_per_hz);
        if let Some(r) = reference {
            self.sum_ref += r;
            self.sum_meas += w;
            self.n_ref += 1;
            self.stall = 0;
        } else if w < self.cfg.stall_rpm && s.current_a > self.stall_current_a {
            self.stall = self.stall.saturating_add(1);
            if self.stall >= self.cfg.stall_ticks {
                return true;
            }
        } else {
            self.stall = 0;
        }
        if let Some(p) = self.prev_pos {
            self.sum_piston += self.q_per_mm * (s.position_mm - p).abs();
            self.sum_pump += self.q_per_rpm * w + self.leak_per_bar * (s.p_a_bar.abs() + s.p_b_bar.abs());
        }
        self.prev_pos = Some(s.position_mm);
        self.n += 1;
        if self.n < self.cfg.window_ticks {
            return false;
        }
        self.window_end()
    }

    #[cold]
    #[inline(never)]
    fn window_end(&mut self) -> bool {
        let n = self.n as f32;
        let ref_bad = self.n_ref == self.n && (self.sum_ref - self.sum_meas).abs() > self.cfg.ref_rel * self.sum_ref + self.cfg.ref_abs_rpm * n;
        let floor = self.q_per_rpm * self.cfg.stall_rpm * n;
        let flow_bad = self.sum_piston > (1.0 + self.cfg.flow_margin) * self.sum_pump + floor;
        self.run_ref = if ref_bad { self.run_ref + 1 } else { 0 };
        self.run_flow = if flow_bad { self.run_flow + 1 } else { 0 };
        self.n = 0;
        self.n_ref = 0;
        self.sum_ref = 0.0;
        self.sum_meas = 0.0;
        self.sum_piston = 0.0;
        self.sum_pump = 0.0;
        let p = self.cfg.persist_windows.max(1);
        self.run_ref >= p || self.run_flow >= p
    }

    /// Starts counting again (after a clear).
    pub fn restart(&mut self) {
        self.run_ref = 0;
        self.run_flow = 0;
        self.stall = 0;
    }
}
