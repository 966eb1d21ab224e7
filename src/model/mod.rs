//! Reduced-order thermal model of the EHA's pump side: six slow nodes, the
//! quasi-steady oil ring, losses of eqs. (1)-(11) from the controller's signals,
//! conductances of eqs. (12)-(19) and the LNG exchanger of eqs. (20)-(22).
//!
//! Multi-rate: [`Model::tick_n`] takes one 10 ms tick of inputs and sums its
//! losses and flows; every [`TICKS_PER_STEP`] ticks [`Model::update`] advances the
//! temperatures by one model step of [`S_PER_STEP`] with the tick means.
//!
//! Reduction of the reference network (docs/firmware.md):
//! * the motor (winding, housing) has no thermal path to the pump side in the
//!   reference, so it is not a state; copper and iron losses enter only the
//!   dissipation total of the LNG budget (eq. 23);
//! * the pump's inlet and outlet port passages and the ball-valve passage hold
//!   ≈ 0.08 kJ/K each against a circulating ≈ 0.26 kW/K: they are quasi-steady
//!   links of the ring, solved in flow order each step, moving at the ring's rate;
//!   the loop node keeps the ring's energy (what the links store is taken from it);
//! * the drain is fed from the high-pressure port; the exchanger's cooling reaches
//!   that port after the transport time of the port passages, `(C_in + C_out) / (m c_p)`.
//!
//! Time stepping: exponential Euler (exact zero-order hold of the linear part) for
//! the fast, strongly coupled [`crate::params::PHI_STATES`] (pump housing, case
//! oil, loop oil): `T(k+1) = T(k) + Phi F(T(k), u(k))`, `Phi = h phi1(h A)` from the
//! matrix exponential of the nominal Jacobian `A` over them (computed on the host);
//! explicit Euler for the slow blocks and actuator ([`crate::params::EULER_STATES`]).
//!
//! The oil's viscosity follows its Walther line: the leakage, the viscous friction
//! and the case gap's Taylor number are read from tables over the case-oil
//! temperature, the ducts' films blend into their transitional range (eqs. 13-14)
//! as the hot oil's Reynolds number passes 2300 (docs/reduction.md).

pub mod bounds;
pub mod consts;
#[cfg(test)]
mod consts_tests;
mod default_consts;
pub mod physics_checks;
mod init;
mod input;
mod readout;
mod rhs;
mod ring;
pub mod stability;
mod sums;
pub mod table;
mod units;

use crate::linalg::expm1m;
use crate::num::Num;
pub use consts::{ModelConsts, Word};
pub use default_consts::DEFAULT_CONSTS;
pub use crate::params::{
    ReducedParams, N_NODES, N_OUTER, N_PHI, N_STATES, N_TABLE, N_TEMP, NODE_ACTUATOR, NODE_BALL_BLOCK, NODE_DRAIN, NODE_LOOP,
    NODE_MAIN_BLOCK, NODE_PUMP, OUTER_NODES, S_PER_STEP, S_PER_TICK, TICKS_PER_STEP,
};
pub use input::{InputScales, ModelInputN, HA_PER_A, HBAR_PER_BAR, HRADS_PER_RPM};
use ring::{Ring, RingIn};
use sums::Sums;
use units::{Consts, INV_N_F32, INV_N_F64, KW_PER_W, L_PER_M3, MAX_DELAY_STEPS, PA_PER_HBAR, RAD_T_K};

/// Why a parameter set cannot be turned into a model of the chosen number type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigError {
    /// [`ReducedParams::is_plausible`] failed.
    Implausible,
    /// A discretised coefficient or row sum exceeds the coefficient format.
    CoefficientRange,
    /// A constant exceeds the value format.
    ConstantRange,
    /// The discretised model amplifies a temperature deviation
    /// ([`Model::check_stability`]), or its `Phi` does not belong to its own
    /// Jacobian.
    Unstable,
    /// A word outside its physical range ([`bounds::BOUNDS`]; the word's
    /// index in field order).
    OutOfBounds(u16),
    /// A word derived from others (`k_lf_half`, `k_lp`, `k_hyd`,
    /// `alpha_t0`) differs from its derivation.
    Inconsistent,
    /// The model does not heat its drain oil at the stated minimum rate
    /// under the reference load ([`Model::check_physics`]).
    NoHeating,
    /// The block's cooling bound at rest claims faster cooling than its own
    /// model ([`Model::check_physics`]).
    RestBound,
}

/// The reduced-order model in number type `N` (`f64`, `f32` or [`crate::num::Fx`]).
///
/// `repr(C)`, hot fields first: the tick's sums and constants, the states and the
/// step's scalars sit in the first kilobyte (a Cortex-M4 `vldr` reaches 1020 bytes
/// from its base; a field past that costs an address computation per load), the
/// tables after them.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct Model<N: Num> {
    sums: Sums<N>,
    /// The viscous friction coefficient at the case oil of the last step, kW per
    /// (hrad/s)^2: the tick's estimate of the shaft's friction torque (the sign of
    /// the shaft power, cross-check) follows the oil's viscosity.
    k_mv_t: N,
    /// The leakage flow conductance at the case oil of the last step, L/s per hbar:
    /// the tick's pump delivery `D w - K (p_A - p_case)` (in hot oil the leakage is
    /// several times its 40 degC value and takes a tenth of the flow).
    k_lf_t: N,
    k: Consts<N>,
    temp: [N::State; N_STATES],
    phi: [[N::Coef; N_PHI]; N_PHI],
    /// Quasi-steady link temperatures of the last step: inlet, outlet, ball oil, degC.
    links: [N; 3],
    /// Ring rate of the last step, K/s.
    ring_rate: N,
    /// Exchanger credit of the past steps, bit k = step k ago.
    lng_hist: u32,
    ambient_c: N,
    /// Outer conductances of [`OUTER_NODES`], kW/K, refreshed one per step.
    outer_g: [N; N_OUTER],
    /// The oil's temperature factors ([`Slow`]), refreshed in the same round.
    slow: Slow<N>,
    last_total_kw: N,
    last_lng_kw: N,
    last_heat_kw: N,
    last_outer_kw: N,
    last_losses_kw: [N; N_LOSSES],
    /// Mechanical loss of the last step from the pressures (eq. 8) and from the
    /// current (shaft minus hydraulic power), kW, before any `loss_max`.
    last_mech_pair_kw: (N, N),
    /// Take the larger of the two mechanical-loss estimates (sensor disagreement).
    loss_max: bool,
    outer_phase: u8,
    g_case: [N; N_TABLE],
    g_port: [N; N_TABLE],
    g_loop: [N; N_TABLE],
    g_ball: [N; N_TABLE],
    g_lng: [N; N_TABLE],
    /// The ducts' films at Re = 2300, 1e4, 3e4 and 1e5 on the coarse temperature grid.
    g_trans: [[N; crate::params::N_RE * crate::params::N_DUCTS]; crate::params::N_COARSE],
    /// Temperature tables at the case oil: leakage, viscous friction, gap speed
    /// factor ([`ModelConsts::leak_ratio`] ...), point by point.
    t_tab: [[N; 3]; N_TEMP],
}

/// The oil's temperature factors the step uses, refreshed round robin
/// ([`Model::update`]).
#[derive(Clone, Copy, Debug)]
struct Slow<N> {
    /// At the case oil: leakage, viscous friction, case-gap speed
    /// ([`Model::oil_factors`]).
    case: [N; 3],
    /// `nu(40) / nu(T)` at the loop oil and at the ball-valve passage's oil
    /// ([`Model::duct_factors`]).
    duct: [N; 2],
}

/// Number of loss groups reported by [`Model::last_losses_kw`].
pub const N_LOSSES: usize = 6;

/// `Phi = h phi1(h A) = integral_0^h exp(A s) ds`, from the exponential of the
/// augmented matrix `[[A h, I h], [0, 0]]` (upper-right block).
pub fn etd_matrix(a: &[[f64; N_PHI]; N_PHI], h: f64) -> [[f64; N_PHI]; N_PHI] {
    const M: usize = 2 * N_PHI;
    let mut aug = [[0.0f64; M]; M];
    for (i, (row, arow)) in aug.iter_mut().zip(a.iter()).enumerate() {
        for (x, v) in row.iter_mut().zip(arow.iter()) {
            *x = v * h;
        }
        if let Some(x) = row.get_mut(N_PHI + i) {
            *x = h;
        }
    }
    let e = expm1m(&aug);
    let mut phi = [[0.0; N_PHI]; N_PHI];
    for (prow, erow) in phi.iter_mut().zip(e.iter()) {
        for (p, x) in prow.iter_mut().zip(erow.iter().skip(N_PHI)) {
            *p = *x;
        }
    }
    phi
}

impl<N: Num> Model<N> {
    /// Builds the model from SI parameters (host: [`consts::derive`] in `f64`,
    /// then [`Model::from_consts`]). Starts at 0 degC.
    pub fn new(p: &ReducedParams) -> Result<Self, ConfigError> {
        Self::from_consts(&consts::derive(p)?)
    }

    /// Builds the model from its constants in model units (`f64` or `f32` words).
    /// Starts at 0 degC.
    pub fn from_consts<S: Word>(c: &ModelConsts<S>) -> Result<Self, ConfigError> {
        let mut m = core::mem::MaybeUninit::<Self>::uninit();
        // SAFETY: `init_in` writes the whole value when it returns Ok.
        unsafe { Self::init_in(m.as_mut_ptr(), c).map(|()| m.assume_init()) }
    }

    /// [`Model::from_consts`] written in place at `dst` (the firmware builds its
    /// state in a static, so the boot stack holds no copy of the model). Checks
    /// the values ([`ModelConsts::check_values`]), the number format and the
    /// stability of the discretisation ([`Model::check_stability`]). On `Err`,
    /// `dst` may be partly written and must not be used.
    ///
    /// # Safety
    /// `dst` must be valid for writes of a `Model<N>`.
    #[inline(never)]
    pub unsafe fn init_in<S: Word>(dst: *mut Self, c: &ModelConsts<S>) -> Result<(), ConfigError> {
        // SAFETY: as this function's.
        unsafe { Self::init_values_in(dst, c)? };
        let phi_s = c.phi.map(|r| r.map(Word::to_f32));
        // SAFETY: written by `init_values_in`.
        unsafe {
            (*dst).check_stability(&phi_s)?;
            let rest = (c.rest_rate.map(Word::to_f32), c.rest_mode.map(Word::to_f32));
            (*dst).check_physics(&rest.0, &rest.1)
        }
    }

    /// The model of `c` without the stability check of `Phi`: for the
    /// reduction tool, which needs the model's Jacobian before `Phi` exists.
    pub fn for_linearisation<S: Word>(c: &ModelConsts<S>) -> Result<Self, ConfigError> {
        let mut m = core::mem::MaybeUninit::<Self>::uninit();
        // SAFETY: `init_values_in` writes the whole value when it returns Ok.
        unsafe { Self::init_values_in(m.as_mut_ptr(), c).map(|()| m.assume_init()) }
    }

    /// Recomputes every [`Slow`] factor at the case oil `t_case` and the loop oil
    /// `t_loop` (start, restore).
    fn refresh_slow(&mut self, t_case: N, t_loop: N) {
        self.slow.duct = self.duct_factors(t_loop, None);
        self.refresh_case(t_case);
    }

    /// Sets every state, the ring links and the ambient to `t_c` (degC): cold start.
    pub fn set_uniform(&mut self, t_c: N) {
        self.ambient_c = t_c;
        for th in self.temp.iter_mut() {
            *th = N::state(t_c);
        }
        self.links = [t_c; 3];
        self.ring_rate = N::ZERO;
        self.outer_g = self.outer_all(&[t_c; N_STATES], t_c);
        self.refresh_slow(t_c, t_c);
    }

    /// Sets every node's temperature (degC, node order) and the ambient from `f32`
    /// (warm restore, thermal memory); the ring links start at the loop temperature.
    pub fn set_temperatures(&mut self, temps_c: &[f32; N_NODES], ambient_c: f32) {
        let conv = |x: f32| match N::scale_from_f64(1.0) {
            Some(s) => N::from_f32_scaled(x, s),
            None => N::ZERO,
        };
        self.ambient_c = conv(ambient_c);
        for (th, t) in self.temp.iter_mut().zip(temps_c.iter()) {
            *th = N::state(conv(*t));
        }
        let t_case = temps_c.get(NODE_DRAIN).map_or(self.ambient_c, |t| conv(*t));
        let tl = temps_c.get(NODE_LOOP).map_or(self.ambient_c, |t| conv(*t));
        self.links = [tl; 3];
        self.ring_rate = N::ZERO;
        self.outer_g = self.outer_all(&self.temperatures_c(), self.ambient_c);
        self.refresh_slow(t_case, tl);
    }

    /// Accumulates one 10 ms tick (losses of eqs. 5-11 and the flows at this tick's
    /// inputs). Returns `true` when [`TICKS_PER_STEP`] ticks are summed: the caller
    /// then calls [`Model::update`].
    #[inline(always)]
    pub fn tick_n(&mut self, u: &ModelInputN<N>) -> bool {
        self.sums.add_tick(&self.k, self.k_mv_t, self.k_lf_t, u)
    }

    /// One model step of [`S_PER_STEP`] with the means of the accumulated ticks.
    /// `lng_ticks`: ticks of this step over which the exchanger ran (the guard's own
    /// valve, no fault latched); its heat is credited for that share of the step.
    /// Never panics; without accumulated ticks it does nothing.
    pub fn update(&mut self, lng_ticks: u32) {
        let ticks = self.sums.ticks;
        if ticks == 0 {
            return;
        }
        let k = &self.k;
        let inv = k.inv_n.get(ticks as usize).copied().unwrap_or(k.inv_ticks);
        let on = lng_ticks.min(ticks);
        let share = inv.mul(k.count.get(on as usize).copied().unwrap_or(k.one));
        let mut m = self.sums.means(inv, &self.k);
        let t = self.temperatures_c();
        // (`slow.case`, `k_mv_t`, `k_lf_t`: the oil's factors at this step's case oil,
        // set at the end of the last step)
        let from_current = m.shaft_kw.sub(m.hyd_kw);
        // the model's whole pump friction: pressure term plus no-load and viscous
        // (the latter at the case oil's viscosity)
        let aw = m.abs_speed;
        let speed_kw = aw.mul(k.k_m0).add(m.visc_kw.mul(self.slow.case[1]));
        let model_kw = m.mech_kw.add(speed_kw);
        self.last_mech_pair_kw = (model_kw, from_current);
        if self.loss_max && from_current > model_kw {
            m.mech_kw = from_current.sub(speed_kw);
        }
        self.sums = Sums::ZERO;
        self.ambient_c = m.ambient;
        self.lng_hist = (self.lng_hist << 1) | u32::from(2 * on >= ticks && on > 0);
        // Slowly varying factors are refreshed round robin, one per step: each outer
        // surface's conductance and the ducts' Reynolds factors, each every 0.6 s,
        // in which the metal and loop temperatures move by hundredths of a kelvin.
        let i = self.outer_phase as usize % (N_OUTER + 1);
        if let (Some(g), Some(n)) = (self.outer_g.get_mut(i), OUTER_NODES.get(i)) {
            let tw = t.get(*n).copied().unwrap_or(m.ambient);
            *g = Self::outer_conductance_of(&self.k, i, tw, m.ambient);
        } else {
            self.slow.duct = self.duct_factors(t.get(NODE_LOOP).copied().unwrap_or(N::ZERO), self.links.get(2).copied());
        }
        self.outer_phase = self.outer_phase.wrapping_add(1);
        let r = self.rhs(&t, &m, &self.slow, self.lng_hist, share, Some(self.links), self.ring_rate, &self.outer_g);
        self.links = r.links;
        self.ring_rate = r.ring_rate;
        self.last_total_kw = r.total_kw;
        self.last_lng_kw = r.lng_kw;
        self.last_heat_kw = r.heat_kw;
        self.last_outer_kw = r.outer_kw;
        self.last_losses_kw = r.losses_kw;
        // `PHI_STATES` (pump housing, case oil, loop oil) by `Phi`, the slow
        // states by explicit Euler (`EULER_STATES`)
        let [p0, p1, p2] = &self.phi;
        let [s0, s1, s2, s3, s4, s5] = &mut self.temp;
        let [r0, r1, r2, r3, r4, r5] = r.rates;
        let rp = [r0, r1, r2];
        *s0 = N::accumulate(*s0, p0, &rp);
        *s1 = N::accumulate(*s1, p1, &rp);
        *s2 = N::accumulate(*s2, p2, &rp);
        let h = self.k.h;
        *s3 = N::add_product(*s3, h, r3);
        *s4 = N::add_product(*s4, h, r4);
        *s5 = N::add_product(*s5, h, r5);
        // the oil's factors at the new case oil, every step: the next step's heat
        // balance and, from the next tick on, the ticks' viscous friction (the
        // shaft torque's sign and the cross-check, which compares it with the
        // current within watts: the viscosity moves 4 %/K at 0 degC) and the pump's
        // delivery past its leakage
        let t_case = N::value(*s1);
        self.refresh_case(t_case);
    }

    /// The oil's factors at the case oil `t_case` ([`Model::oil_factors`]) and the
    /// ticks' viscous friction and leakage coefficients from them.
    #[inline(always)]
    fn refresh_case(&mut self, t_case: N) {
        self.slow.case = self.oil_factors(t_case);
        self.k_mv_t = self.k.k_mv.mul(self.slow.case[1]);
        self.k_lf_t = self.k.k_lf.mul(self.slow.case[0]);
    }

    /// Right-hand side `dT/dt` (K/s, state order) at temperatures `t` with every tick
    /// at inputs `u`, the ring in steady flow (links stored nothing, no transport lag):
    /// the function whose Jacobian at the nominal point is `A` (reduction tool).
    #[inline(never)]
    pub fn derivative(&self, t: &[N; N_STATES], u: &ModelInputN<N>, lng_open: bool) -> [N; N_STATES] {
        let mut sums = Sums::ZERO;
        let f = self.oil_factors(t.get(NODE_DRAIN).copied().unwrap_or(N::ZERO));
        let _ = sums.add_tick(&self.k, self.k.k_mv.mul(f[1]), self.k.k_lf.mul(f[0]), u);
        let m = sums.means(self.k.one, &self.k);
        let share = if lng_open { self.k.one } else { N::ZERO };
        let og = self.outer_all(t, m.ambient);
        let slow = Slow { case: f, duct: self.duct_factors(t.get(NODE_LOOP).copied().unwrap_or(N::ZERO), None) };
        self.rhs(t, &m, &slow, u32::from(lng_open), share, None, N::ZERO, &og).rates
    }

    /// Advances one model step with every tick at the same inputs (tests, tools).
    pub fn step(&mut self, u: &ModelInputN<N>, lng_open: bool) {
        while !self.tick_n(u) {}
        self.update(if lng_open { TICKS_PER_STEP } else { 0 });
    }

}
