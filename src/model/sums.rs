//! The tick accumulation: each 10 ms tick's losses and flows summed raw, and
//! their means over the ticks of a model step.

use super::*;

/// Sums over the ticks of the present model step: raw per-tick terms (their
/// constants are applied at the step by [`Sums::means`]); `ambient` is the last tick's.
#[derive(Clone, Copy, Debug)]
pub(super) struct Sums<N> {
    pub(super) leak_kw: N,
    pub(super) mech_kw: N,
    pub(super) line_kw: N,
    pub(super) needle_kw: N,
    pub(super) act_kw: N,
    pub(super) copper_kw: N,
    /// `sign(dp w) |I| |w|` (shaft power from the current, cross-check).
    pub(super) shaft_kw: N,
    /// `dp w` (hydraulic power of the displacement, cross-check).
    pub(super) hyd_kw: N,
    pub(super) leak_lps: N,
    pub(super) pump_lps: N,
    pub(super) abs_pump_lps: N,
    pub(super) abs_thr_lps: N,
    pub(super) abs_act_lps: N,
    pub(super) abs_speed: N,
    /// The pump's viscous friction `k_mv w^2`, kW (extended eq. 8; its constant is
    /// applied per tick: `w^2` summed over a step would leave the fixed-point range
    /// at 6000 rpm).
    pub(super) visc_kw: N,
    pub(super) dp: N,
    pub(super) ambient: N,
    pub(super) ticks: u32,
}

impl<N: Num> Sums<N> {
    pub(super) const ZERO: Self = Sums {
        leak_kw: N::ZERO,
        mech_kw: N::ZERO,
        line_kw: N::ZERO,
        needle_kw: N::ZERO,
        act_kw: N::ZERO,
        copper_kw: N::ZERO,
        shaft_kw: N::ZERO,
        hyd_kw: N::ZERO,
        leak_lps: N::ZERO,
        pump_lps: N::ZERO,
        abs_pump_lps: N::ZERO,
        abs_thr_lps: N::ZERO,
        abs_act_lps: N::ZERO,
        abs_speed: N::ZERO,
        visc_kw: N::ZERO,
        dp: N::ZERO,
        ambient: N::ZERO,
        ticks: 0,
    };
}

impl<N: Num> Sums<N> {
    /// Means of the raw tick sums in physical model units (kW, L/s), `f = 1 / ticks`:
    /// the per-tick constants are applied here once per step.
    #[inline(always)]
    pub(super) fn means(&self, f: N, k: &Consts<N>) -> Self {
        Sums {
            leak_kw: self.leak_kw.mul(f.mul(k.k_lp)),
            mech_kw: self.mech_kw.mul(f.mul(k.k_mech)),
            line_kw: self.line_kw.mul(f),
            needle_kw: self.needle_kw.mul(f.mul(k.half)),
            act_kw: self.act_kw.mul(f.mul(k.k_act)),
            copper_kw: self.copper_kw.mul(f.mul(k.k_cu)),
            shaft_kw: self.shaft_kw.mul(f.mul(k.k_sh)),
            hyd_kw: self.hyd_kw.mul(f.mul(k.k_hyd)),
            leak_lps: self.leak_lps.mul(f.mul(k.k_lf_half)),
            pump_lps: self.pump_lps.mul(f),
            abs_pump_lps: self.abs_pump_lps.mul(f),
            abs_thr_lps: self.abs_thr_lps.mul(f),
            abs_act_lps: self.abs_act_lps.mul(f.mul(k.k_a)),
            abs_speed: self.abs_speed.mul(f),
            visc_kw: self.visc_kw.mul(f),
            dp: self.dp.mul(f),
            ambient: self.ambient,
            ticks: self.ticks,
        }
    }
}

impl<N: Num> Sums<N> {
    /// Adds one tick's raw loss and flow terms (see [`Model::tick_n`]); `true` when
    /// [`TICKS_PER_STEP`] ticks are summed.
    #[inline(always)]
    /// `k_mv_t`, `k_lf_t`: the viscous friction coefficient and the leakage flow
    /// conductance at the oil's present viscosity (the shaft torque's sign, the
    /// pump's delivery below).
    pub(super) fn add_tick(&mut self, k: &Consts<N>, k_mv_t: N, k_lf_t: N, u: &ModelInputN<N>) -> bool {
        let s = self;
        // Raw per-tick terms; their constants are applied once at the model step
        // (`Sums::means`).
        let dpa = u.p_a_hbar.sub(k.p_case);
        let dpb = u.p_b_hbar.sub(k.p_case);
        let dp = u.p_a_hbar.sub(u.p_b_hbar);
        let aw = u.speed_hrads.abs();
        // eqs. (5)-(7): each port leaks K (p - p_case) into the case; heat K dp^2.
        s.leak_kw = s.leak_kw.add(dpa.mul(dpa).add(dpb.mul(dpb)));
        // 2 max(0, x) = x + |x|: the leaking ports' pressure excess (x2)
        s.leak_lps = s.leak_lps.add(dpa.add(dpa.abs()).add(dpb).add(dpb.abs()));
        // eq. (8): |dp| |w|
        s.mech_kw = s.mech_kw.add(dp.abs().mul(aw));
        // pump delivery A-ward past the leakage of the high-pressure port (A when
        // dp >= 0, else B; the low port's leakage is made up by its check valve),
        // piston flow, throttled remainder (eqs. 5-7, 10-11): the path flow of a
        // throttle circuit, ~0 in a servo hold. (Port A's leakage taken in either
        // direction left a reverse servo hold's pump flow as throttled flow: the
        // leakage's heat booked twice, 10-22 W.)
        let q_geo = k.k_q.mul(u.speed_hrads);
        let q_pump = if dp < N::ZERO { q_geo.add(k_lf_t.mul(dpb)) } else { q_geo.sub(k_lf_t.mul(dpa)) };
        let q_act = k.k_a.mul(u.dpos_mm);
        let q_thr = q_pump.sub(q_act);
        let aq_thr = q_thr.abs();
        let line = q_thr.mul(q_thr).mul(k.r1.add(k.r2.mul(aq_thr)));
        let x = k.k_dpq.mul(dp).mul(q_thr).sub(line);
        s.line_kw = s.line_kw.add(line);
        s.needle_kw = s.needle_kw.add(x.add(x.abs())); // 2 max(0, dp q - line)
        // eq. (11) and the piston's viscous seal friction
        s.act_kw = s.act_kw.add(k.w_dp.mul(dp).mul(dp).add(k.w_dx.mul(u.dpos_mm).mul(u.dpos_mm)));
        // eq. (1): I^2 (dissipation total only)
        s.copper_kw = s.copper_kw.add(u.current_ha.mul(u.current_ha));
        // Cross-check terms: shaft power Kt |I| w with the sign of the shaft torque
        // the model expects, D dp + sign(w) T_f (the current's sign is not
        // measured; at low pressure the friction torque T_f of the extended eq. 8
        // can outweigh D dp, and a load driving the pump then still needs a
        // driving torque), and the hydraulic power D dp w; their difference is the
        // shaft's loss (eq. 8 in the model).
        let iw = u.current_ha.abs().mul(u.speed_hrads);
        let t_f = k.k_mech.mul(dp.abs()).add(k.k_m0).add(k_mv_t.mul(aw));
        let t_shaft = k.k_hyd.mul(dp).add(if u.speed_hrads < N::ZERO { N::ZERO.sub(t_f) } else { t_f });
        s.shaft_kw = s.shaft_kw.add(if t_shaft < N::ZERO { N::ZERO.sub(iw) } else { iw });
        s.hyd_kw = s.hyd_kw.add(dp.mul(u.speed_hrads));
        s.pump_lps = s.pump_lps.add(q_pump);
        s.abs_pump_lps = s.abs_pump_lps.add(q_pump.abs());
        s.abs_thr_lps = s.abs_thr_lps.add(aq_thr);
        s.abs_act_lps = s.abs_act_lps.add(u.dpos_mm.abs());
        s.abs_speed = s.abs_speed.add(aw);
        s.visc_kw = s.visc_kw.add(k.k_mv.mul(aw).mul(aw));
        s.dp = s.dp.add(dp);
        s.ambient = u.ambient_c;
        s.ticks += 1;
        s.ticks >= TICKS_PER_STEP
    }
}
