//! Reduced-order thermal model: 6 nodes, losses from the actuator signals,
//! exact zero-order-hold step (docs/contracts.md).
//!
//! The state is the absolute node temperature `T` (degC). Because the Laplacian
//! annihilates constants, `Bd_amb = (I - Ad) 1` exactly, so
//! `T(k+1) = T(k) + (Ad - I) (T(k) - T_amb(k)) + Bd p(k)`: the ambient input needs
//! no matrix column. The step is these 66 multiply-adds on `theta = T - T_amb`,
//! followed by the flow-dependent drain <-> loop-oil exchange (operator splitting).

use crate::linalg::expm1m;
use crate::num::Num;
use crate::params::{
    ReducedParams, NODE_BLOCK, NODE_DRAIN, NODE_LOOP_OIL, NODE_PUMP, NODE_WINDING, N_LOSSES,
    N_NODES, S_PER_STEP,
};

// `step_n` destructures the state: pump 2, loop oil 3, block 4, drain 5.
const _: () = assert!(NODE_PUMP == 2 && NODE_LOOP_OIL == 3 && NODE_BLOCK == 4 && NODE_DRAIN == 5);

/// Largest shaft speed the explicit exchange terms are checked for at build time,
/// hrad/s (10 hrad/s = 1000 rad/s ≈ 9550 rpm, above the input range limit).
pub const MAX_HRADS: f64 = 10.0;
/// Largest per-step rate `x` of an explicit exchange term accepted at build time
/// (dimensionless, per step, at [`MAX_HRADS`]): far inside explicit stability
/// (x < 2); the explicit step then differs from the exact two-node relaxation
/// `1 - exp(-x)` by x/2 ≤ 1 % of the exchange rate at that extreme speed (the
/// identified model is this discrete model, so this is a definition, not an error).
pub const MAX_EXPLICIT_RATE: f64 = 0.02;

/// Columns of one discretised row: 6 node temperatures then 5 losses.
pub const N_COLS: usize = N_NODES + N_LOSSES;
const N_AUG: usize = N_COLS;

/// Wire-unit → model-unit scale of current: A → hA (100 A).
pub const HA_PER_A: f64 = 0.01;
/// Wire-unit → model-unit scale of pressure: bar → hbar (10 MPa).
pub const HBAR_PER_BAR: f64 = 0.01;
/// Wire-unit → model-unit scale of speed: rpm → hrad/s (100 rad/s).
pub const HRADS_PER_RPM: f64 = 2.0 * core::f64::consts::PI / 60.0 / 100.0;
/// Model power unit: W per kW.
pub const W_PER_KW: f64 = 1000.0;

/// One step of (validated, finite) inputs in wire units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelInput {
    /// Motor phase current, A rms.
    pub current_a: f32,
    /// Pump port pressure difference `p_A - p_B`, bar.
    pub dp_bar: f32,
    /// Motor speed, rpm (signed).
    pub speed_rpm: f32,
    /// Piston position change since the previous step, mm per step (signed).
    pub dpos_mm: f32,
    /// Ambient temperature, degC.
    pub ambient_c: f32,
    /// LNG valve open over this step (the guard's own command).
    pub lng_open: bool,
}

/// One step of inputs in model units and the model's number type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelInputN<N> {
    /// Motor phase current, hA (100 A).
    pub current_ha: N,
    /// Pump port pressure difference `p_A - p_B`, hbar (10 MPa).
    pub dp_hbar: N,
    /// Motor speed, hrad/s (100 rad/s), signed.
    pub speed_hrads: N,
    /// Piston position change over the step, mm.
    pub dpos_mm: N,
    /// Ambient temperature, degC.
    pub ambient_c: N,
}

/// Why a parameter set cannot be turned into a model of the chosen number type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(any(target_os = "none", feature = "defmt"), derive(defmt::Format))]
pub enum ConfigError {
    /// [`ReducedParams::is_plausible`] failed.
    Implausible,
    /// A discretised coefficient or row sum exceeds the coefficient format.
    CoefficientRange,
    /// A loss constant exceeds the value format.
    ConstantRange,
}

/// Loss and exchange constants in model units (kW from hA, hbar, hrad/s, mm/step).
#[derive(Clone, Copy, Debug)]
struct LossK<N: Num> {
    cu0: N,  // m R0 (1 - 25 alpha), kW/hA^2
    cu1: N,  // m R0 alpha, kW/(hA^2 K)
    fe1: N,  // kW/(hrad/s)
    fe2: N,  // kW/(hrad/s)^2
    fe15: N, // kW/(hrad/s)^1.5
    leak: N, // kW/hbar^2
    k_mu: N, // 1/K
    t_mu: N, // degC
    use_mu: bool,
    mech: N,  // kW/(hbar hrad/s)
    kq: N,    // kW/(hbar hrad/s): D·1e6
    kv: N,    // kW/(hbar mm/step): A·10/h
    ex_k: N,  // exchange exponent per hbar: g_od1 1e7 h (1/C3 + 1/C5)
    ex_w3: N, // -C5/(C3+C5)
    ex_w5: N, // C3/(C3+C5)
    pd_k: N,  // drain-pump exchange rate per sqrt(hrad/s): g_pd1 10 h (1/C2 + 1/C5)
    pd_w5: N, // C2/(C2+C5)
    lb_k: N,  // loop-block exchange rate per sqrt(hrad/s): g_lb1 10 h (1/C3 + 1/C4)
    lb_w3: N, // -C4/(C3+C4)
    lb_w4: N, // C3/(C3+C4)
    pd_w2n: N, // -C5/(C2+C5)
    lng_max: N,   // 1000 g_max h / C3, mK per (K step)
    lng_slope: N, // 1000 g_slope 100 h / C3, mK per (K step hrad/s)
    lng_in: N,    // LNG inlet, degC
    feed_k: N,    // leakage-feed rise over the loop oil, K/hbar
    milli: N,     // -1e-3 (mK → K, heat removed)
    lng_kw: N,    // C3 / (h 1e6): mK per step → kW
    half: N,
    third: N,
    quarter: N,
    one: N,
}

/// The reduced-order model in number type `N` (`f64`, `f32` or [`crate::num::Fx`]).
#[derive(Clone, Copy, Debug)]
pub struct Model<N: Num> {
    temp: [N::State; N_NODES],
    ambient_c: N,
    coef: [[N::Coef; N_COLS]; N_NODES],
    k: LossK<N>,
    last_loss_kw: [N; N_LOSSES],
    last_lng: N,
}

/// Discretised matrices in `f64`: row `i` = `[(Ad - I)_i·, Bd_i·]`, `Bd` per kW.
pub fn discretise(p: &ReducedParams) -> [[f64; N_COLS]; N_NODES] {
    let mut m = [[0.0f64; N_AUG]; N_AUG];
    let node_data = p
        .capacity_j_per_k
        .iter()
        .zip(p.ambient_w_per_k.iter())
        .zip(p.conductance_w_per_k.iter().zip(p.loss_split.iter()));
    for (i, (row, ((c, g_amb), (g_row, split_row)))) in m.iter_mut().zip(node_data).enumerate() {
        let k = S_PER_STEP / c;
        let mut diag = *g_amb;
        for (j, (mij, g)) in row.iter_mut().zip(g_row.iter()).enumerate() {
            if j != i {
                diag += g;
                *mij = g * k;
            }
        }
        if let Some(d) = row.get_mut(i) {
            *d = -diag * k;
        }
        for (mij, share) in row.iter_mut().skip(N_NODES).zip(split_row.iter()) {
            *mij = share * W_PER_KW * k;
        }
    }
    let e = expm1m(&m);
    let mut out = [[0.0; N_COLS]; N_NODES];
    for (o, r) in out.iter_mut().zip(e.iter()) {
        o.copy_from_slice(&r[..N_COLS]);
    }
    out
}

impl<N: Num> Model<N> {
    /// Builds the model once from SI parameters: exact ZOH via the matrix
    /// exponential in `f64`, then conversion to `N`. Starts at 0 degC everywhere.
    pub fn new(p: &ReducedParams) -> Result<Self, ConfigError> {
        if !p.is_plausible() {
            return Err(ConfigError::Implausible);
        }
        let d = discretise(p);
        let mut coef =
            [[N::coef_from_f64(0.0).ok_or(ConfigError::CoefficientRange)?; N_COLS]; N_NODES];
        for (cr, dr) in coef.iter_mut().zip(d.iter()) {
            if dr.iter().map(|x| libm::fabs(*x)).sum::<f64>() >= N::MAX_ROW_SUM {
                return Err(ConfigError::CoefficientRange);
            }
            for (c, x) in cr.iter_mut().zip(dr.iter()) {
                *c = N::coef_from_f64(*x).ok_or(ConfigError::CoefficientRange)?;
            }
        }
        let k_cu = p.phases * p.r0_ohm / (HA_PER_A * HA_PER_A) / W_PER_KW;
        let cap = &p.capacity_j_per_k;
        let (c2, c3, c4, c5) = (cap[NODE_PUMP], cap[NODE_LOOP_OIL], cap[NODE_BLOCK], cap[NODE_DRAIN]);
        let consts = [
            k_cu * (1.0 - 25.0 * p.alpha_r_per_k),
            k_cu * p.alpha_r_per_k,
            p.k_fe1_w_s_per_rad * 100.0 / W_PER_KW,
            p.k_fe2_w_s2_per_rad2 * 1e4 / W_PER_KW,
            p.k_fe15_w_per_rad15 * 1e3 / W_PER_KW,
            p.k_leak_w_per_pa2 * 1e14 / W_PER_KW,
            p.k_mu_per_k,
            p.t_mu_ref_c,
            p.eta_m * p.displacement_m3_per_rad * 1e7 * 100.0 / W_PER_KW,
            p.displacement_m3_per_rad * 1e7 * 100.0 / W_PER_KW,
            p.ram_area_m2 * 1e7 * 1e-3 / S_PER_STEP / W_PER_KW,
            p.g_od1_w_per_k_pa * 1e7 * S_PER_STEP * (1.0 / c3 + 1.0 / c5),
            -c5 / (c3 + c5),
            c3 / (c3 + c5),
            p.g_pd1_w_per_k_sqrt_rad_s * 10.0 * S_PER_STEP * (1.0 / c2 + 1.0 / c5),
            c5 / (c2 + c5),
            c2 / (c2 + c5),
            p.g_lb1_w_per_k_sqrt_rad_s * 10.0 * S_PER_STEP * (1.0 / c3 + 1.0 / c4),
            -c4 / (c3 + c4),
            c3 / (c3 + c4),
            1000.0 * p.lng_max_w_per_k * S_PER_STEP / c3,
            1000.0 * p.lng_slope_w_s_per_k_rad * 100.0 * S_PER_STEP / c3,
            p.lng_inlet_c,
            p.feed_rise_k_per_pa * 1e7,
        ];
        if consts
            .iter()
            .any(|x| !x.is_finite() || libm::fabs(*x) >= 250.0)
        {
            return Err(ConfigError::ConstantRange);
        }
        // The speed-driven exchanges and the LNG term are explicit per step: their
        // per-step rates must stay far below 1 up to `MAX_HRADS` (stability, and the
        // first-order exchange error x^2/2 small). The LNG rate is in mK per K.
        let rate_pd = consts[14] * libm::sqrt(MAX_HRADS);
        let rate_lb = consts[17] * libm::sqrt(MAX_HRADS);
        let rate_lng = consts[20] * 1e-3;
        if rate_pd > MAX_EXPLICIT_RATE || rate_lb > MAX_EXPLICIT_RATE || rate_lng > MAX_EXPLICIT_RATE {
            return Err(ConfigError::CoefficientRange);
        }
        let f = N::from_f64;
        let k = LossK {
            cu0: f(consts[0]),
            cu1: f(consts[1]),
            fe1: f(consts[2]),
            fe2: f(consts[3]),
            fe15: f(consts[4]),
            leak: f(consts[5]),
            k_mu: f(consts[6]),
            t_mu: f(consts[7]),
            use_mu: p.k_mu_per_k != 0.0,
            mech: f(consts[8]),
            kq: f(consts[9]),
            kv: f(consts[10]),
            ex_k: f(consts[11]),
            ex_w3: f(consts[12]),
            ex_w5: f(consts[13]),
            pd_k: f(consts[14]),
            pd_w5: f(consts[16]),
            lb_k: f(consts[17]),
            lb_w3: f(consts[18]),
            lb_w4: f(consts[19]),
            pd_w2n: f(-consts[15]),
            lng_max: f(consts[20]),
            lng_slope: f(consts[21]),
            lng_in: f(consts[22]),
            feed_k: f(consts[23]),
            milli: f(-1e-3),
            lng_kw: f(c3 / (S_PER_STEP * 1e6)),
            half: f(0.5),
            third: f(1.0 / 3.0),
            quarter: f(0.25),
            one: f(1.0),
        };
        Ok(Model {
            temp: [N::state(N::ZERO); N_NODES],
            ambient_c: N::ZERO,
            coef,
            k,
            last_loss_kw: [N::ZERO; N_LOSSES],
            last_lng: N::ZERO,
        })
    }

    /// Sets every node and the ambient to `t_c` (degC, model number type): cold start.
    pub fn set_uniform(&mut self, t_c: N) {
        self.ambient_c = t_c;
        for th in self.temp.iter_mut() {
            *th = N::state(t_c);
        }
    }

    /// Sets every node's absolute temperature (degC) and the ambient it refers to.
    pub fn set_temperatures(&mut self, temps_c: &[f32; N_NODES], ambient_c: f32) {
        let one = self.k.one;
        let s = N::scale_from_f64(1.0);
        let amb = match s {
            Some(s) => N::from_f32_scaled(ambient_c, s),
            None => N::ZERO,
        };
        self.ambient_c = amb;
        for (th, t) in self.temp.iter_mut().zip(temps_c.iter()) {
            let tv = match s {
                Some(s) => N::from_f32_scaled(*t, s),
                None => N::ZERO,
            };
            *th = N::add_product(N::state(N::ZERO), tv, one);
        }
    }

    /// Losses `[copper, iron, leakage, mechanical, throttling]` in kW (eqs. 1, 2, 5-8, 11).
    #[inline(always)]
    pub fn losses_kw(&self, i_ha: N, dp_hbar: N, w_hrads: N, dpos_mm: N) -> [N; N_LOSSES] {
        self.losses_with(i_ha, dp_hbar, w_hrads, dpos_mm, &Magnitudes::of(dp_hbar, w_hrads))
    }

    /// [`Model::losses_kw`] with the input magnitudes already taken (the step shares
    /// them with its exchanges).
    #[inline(always)]
    fn losses_with(&self, i_ha: N, dp_hbar: N, w_hrads: N, dpos_mm: N, m: &Magnitudes<N>) -> [N; N_LOSSES] {
        let k = &self.k;
        let t_w = N::value(self.temp[NODE_WINDING]);
        // eq. (1): m I^2 R0 (1 + alpha (T_w - 25))
        let p_cu = i_ha.mul(i_ha).mul(k.cu0.add(k.cu1.mul(t_w)));
        // eq. (2) with f ∝ w and constant B_m
        let aw = m.aw;
        let p_fe = aw.mul(k.fe1.add(k.fe2.mul(aw)).add(k.fe15.mul(m.sw)));
        // eqs. (5)-(7): K dp^2 / mu(T) (ratio to the reference viscosity)
        let mut p_leak = k.leak.mul(dp_hbar).mul(dp_hbar);
        if k.use_mu {
            let t_d = N::value(self.temp[NODE_DRAIN]);
            p_leak = p_leak.mul(k.k_mu.mul(t_d.sub(k.t_mu)).exp());
        }
        // eq. (8): eta_m (D dp) w
        let p_mech = k.mech.mul(m.adp).mul(aw);
        // eq. (11) generalised: dp (D w - Q_leak) - dp A v, never negative (no heat sink)
        let p_hyd = dp_hbar
            .mul(k.kq.mul(w_hrads).sub(k.kv.mul(dpos_mm)))
            .sub(p_leak)
            .max0();
        [p_cu, p_fe, p_leak, p_mech, p_hyd]
    }

    /// Advances one step of [`S_PER_STEP`] with inputs held (ZOH). Never panics.
    pub fn step(&mut self, u: &ModelInput, s: &InputScales<N>) {
        self.step_n(&ModelInputN {
            current_ha: N::from_f32_scaled(u.current_a, s.ha_per_a),
            dp_hbar: N::from_f32_scaled(u.dp_bar, s.hbar_per_bar),
            speed_hrads: N::from_f32_scaled(u.speed_rpm, s.hrads_per_rpm),
            dpos_mm: N::from_f32_scaled(u.dpos_mm, s.one),
            ambient_c: N::from_f32_scaled(u.ambient_c, s.one),
        }, u.lng_open);
    }

    /// [`Model::step`] with inputs already in model units (the guard's path).
    /// `lng_open`: the LNG valve was open over this step (the guard's own command);
    /// the exchanger then removes `g_lng(w) (T_loop - T_LNG)` from the loop oil.
    #[inline(always)]
    pub fn step_n(&mut self, u: &ModelInputN<N>, lng_open: bool) {
        let amb = u.ambient_c;
        self.ambient_c = amb;
        let dp = u.dp_hbar;
        let mag = Magnitudes::of(dp, u.speed_hrads);
        let p = self.losses_with(u.current_ha, dp, u.speed_hrads, u.dpos_mm, &mag);
        self.last_loss_kw = p;
        let th = &self.temp;
        let x: [N; N_COLS] = [
            N::value(th[0]).sub(amb),
            N::value(th[1]).sub(amb),
            N::value(th[2]).sub(amb),
            N::value(th[3]).sub(amb),
            N::value(th[4]).sub(amb),
            N::value(th[5]).sub(amb),
            p[0],
            p[1],
            p[2],
            p[3],
            p[4],
        ];
        // Drain <-> loop-oil exchange with g = g_od1 |dp|, exact two-node solution on
        // the step's initial state: the difference decays by exp(-x); 1 - exp(-x) by its
        // 4-term series (relative error < x^4/120: 8e-7 at x = 0.1; x ≈ 1e-3 at 60 bar).
        // It is added in the same state update as the ZOH step (operator splitting with
        // both parts evaluated at the step start; first order, like sequential splitting).
        let k = &self.k;
        let Magnitudes { aw, sw, adp } = mag;
        // LNG exchanger, eqs. (20)-(22), while open: conductance g = min(g_max,
        // g_slope |w|) (the smaller capacity rate is the LNG stream above ~30 rpm, the
        // oil stream below). The loop oil loses g h / C3 (T_loop - T_LNG) per step (in
        // mK, scaled by -1e-3). The oil leaving the exchanger is colder than the loop
        // oil by the heat removed over the oil stream's capacity rate, g / (g_slope |w|)
        // (T_loop - T_LNG) (all of the difference when the oil stream is the smaller).
        let (g_lng, cooled) = if lng_open {
            let g = k.lng_slope.mul(aw);
            if g > k.lng_max {
                (k.lng_max, k.lng_max.div_pos(g))
            } else {
                (g, k.one)
            }
        } else {
            (N::ZERO, N::ZERO)
        };
        let t_rel = N::value(th[NODE_LOOP_OIL]).sub(k.lng_in);
        let q_lng = g_lng.mul(t_rel);
        let [_, _, x_pump, x_loop, x_block, x_drain, ..] = x;
        // Drain <-> loop-oil exchange with g = g_od1 |dp| (the leakage flow through the
        // case), exact two-node solution on the step's initial state: the difference
        // decays by exp(-x); 1 - exp(-x) by its 4-term series (relative error < x^4/120:
        // 8e-7 at x = 0.1). The leakage enters the case at the feed temperature: the
        // loop oil, plus the high-pressure port's rise feed_k |dp|, minus the exchanger's
        // cooling. Added in the same state update as the ZOH step (operator splitting,
        // both parts evaluated at the step start).
        let xe = k.ex_k.mul(adp);
        let phi = xe.mul(
            k.one.sub(
                xe.mul(k.half)
                    .mul(k.one.sub(xe.mul(k.third).mul(k.one.sub(xe.mul(k.quarter))))),
            ),
        );
        let feed = x_loop.add(k.feed_k.mul(adp)).sub(cooled.mul(t_rel));
        let q = phi.mul(feed.sub(x_drain));
        // Speed-driven exchanges (drain <-> pump housing, loop oil <-> block), explicit
        // two-node steps with rate x = g1 sqrt|w| h (1/Ca + 1/Cb) (≤ MAX_EXPLICIT_RATE).
        let q_pd = k.pd_k.mul(sw).mul(x_pump.sub(x_drain));
        let q_lb = k.lb_k.mul(sw).mul(x_loop.sub(x_block));
        let [c0, c1, c2, c3, c4, c5] = &self.coef;
        let [t0, t1, t2, t3, t4, t5] = &mut self.temp;
        *t0 = N::accumulate(*t0, c0, &x);
        *t1 = N::accumulate(*t1, c1, &x);
        *t2 = N::accumulate_plus(*t2, c2, &x, &[q_pd], &[k.pd_w2n]);
        *t3 = N::accumulate_plus(*t3, c3, &x, &[q, q_lb, q_lng], &[k.ex_w3, k.lb_w3, k.milli]);
        *t4 = N::accumulate_plus(*t4, c4, &x, &[q_lb], &[k.lb_w4]);
        *t5 = N::accumulate_plus(*t5, c5, &x, &[q, q_pd], &[k.ex_w5, k.pd_w5]);
        self.last_lng = q_lng;
    }

    /// Predicted drain-oil temperature, degC.
    #[inline(always)]
    pub fn drain_c(&self) -> N {
        N::value(self.temp[NODE_DRAIN])
    }

    /// All node temperatures, degC, in contract order.
    pub fn temperatures_c(&self) -> [N; N_NODES] {
        let mut t = [N::ZERO; N_NODES];
        for (o, th) in t.iter_mut().zip(self.temp.iter()) {
            *o = N::value(*th);
        }
        t
    }

    /// Present ambient reference, degC.
    pub fn ambient_c(&self) -> N {
        self.ambient_c
    }

    /// Losses of the last step `[cu, fe, leak, mech, throttle]`, kW.
    pub fn last_losses_kw(&self) -> [N; N_LOSSES] {
        self.last_loss_kw
    }

    /// Heat the LNG exchanger removed from the loop oil over the last step, kW
    /// (0 while the valve is closed); the LNG budget's heat input, eqs. (23)-(25).
    pub fn last_lng_kw(&self) -> N {
        self.last_lng.mul(self.k.lng_kw)
    }

    /// Sum of the last step's losses, kW.
    pub fn last_total_kw(&self) -> N {
        self.last_loss_kw.iter().fold(N::ZERO, |a, p| a.add(*p))
    }
}

/// Magnitudes of one step's inputs, taken once and shared by the losses and the
/// exchanges: `|w|`, `sqrt|w|` (hrad/s, hrad/s^0.5) and `|dp|` (hbar).
#[derive(Clone, Copy, Debug)]
struct Magnitudes<N> {
    aw: N,
    sw: N,
    adp: N,
}

impl<N: Num> Magnitudes<N> {
    #[inline(always)]
    fn of(dp_hbar: N, w_hrads: N) -> Self {
        let aw = w_hrads.abs();
        Magnitudes { aw, sw: aw.sqrt_abs(), adp: dp_hbar.abs() }
    }
}

/// Wire → model unit scales in the number type (built once).
#[derive(Clone, Copy, Debug)]
pub struct InputScales<N: Num> {
    /// A → hA.
    pub ha_per_a: N::Scale,
    /// bar → hbar.
    pub hbar_per_bar: N::Scale,
    /// rpm → hrad/s.
    pub hrads_per_rpm: N::Scale,
    /// Unity (mm, degC).
    pub one: N::Scale,
}

impl<N: Num> InputScales<N> {
    /// The scale of each sample channel, in channel order `[current, p_A, p_B,
    /// speed, position, ambient]` (`validate::CH_*`).
    #[inline(always)]
    pub fn per_channel(&self) -> [N::Scale; 6] {
        [self.ha_per_a, self.hbar_per_bar, self.hbar_per_bar, self.hrads_per_rpm, self.one, self.one]
    }

    /// Builds the scales; `None` only if the number type cannot hold them.
    pub fn new() -> Option<Self> {
        Some(InputScales {
            ha_per_a: N::scale_from_f64(HA_PER_A)?,
            hbar_per_bar: N::scale_from_f64(HBAR_PER_BAR)?,
            hrads_per_rpm: N::scale_from_f64(HRADS_PER_RPM)?,
            one: N::scale_from_f64(1.0)?,
        })
    }
}
