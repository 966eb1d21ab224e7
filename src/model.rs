//! Reduced-order thermal model: 6 nodes, losses from the actuator signals,
//! multi-rate exact zero-order-hold step (docs/firmware.md).
//!
//! **Multi-rate.** Every 10 ms tick ([`Model::tick_n`]) the tick's leakage and
//! throttling losses (the throttling floor `max0` per tick), `I^2`, `|dp| |w|` and
//! the exchange drivers `|dp|`, `|w|` are summed. Every
//! [`crate::params::TICKS_PER_STEP`] ticks ([`Model::update`]) the state advances one
//! model step of [`S_PER_STEP`] (100 ms) with the tick-averaged inputs held (ZOH):
//! copper loss from the mean `I^2` and the winding temperature at the model step,
//! iron loss and `sqrt|w|` from the mean `|w|`, the LNG credit over the given
//! number of the step's ticks, the last tick's ambient.
//!
//! The state is the absolute node temperature `T` (degC). Because the Laplacian
//! annihilates constants, `Bd_amb = (I - Ad) 1` exactly, so
//! `T(k+1) = T(k) + (Ad - I) (T(k) - T_amb(k)) + Bd p(k)`: the ambient input needs
//! no matrix column. The step is these 66 multiply-adds on `theta = T - T_amb`,
//! plus the input-dependent exchanges as powers held over the step, to second
//! order in h (midpoint-extrapolated temperatures; the product takes
//! `theta + delta/2`, `delta = h C^-1 q`).

use crate::linalg::expm1m;
use crate::num::Num;
use crate::params::{
    ReducedParams, NODE_BLOCK, NODE_DRAIN, NODE_LOOP_OIL, NODE_PUMP, NODE_WINDING, N_LOSSES,
    N_NODES, S_PER_STEP, S_PER_TICK, TICKS_PER_STEP,
};

// `step_n` destructures the state: pump 2, loop oil 3, block 4, drain 5.
const _: () = assert!(NODE_PUMP == 2 && NODE_LOOP_OIL == 3 && NODE_BLOCK == 4 && NODE_DRAIN == 5);

/// Largest shaft speed the explicit exchange terms are checked for at build time,
/// hrad/s (10 hrad/s = 1000 rad/s ≈ 9550 rpm, above the input range limit).
pub const MAX_HRADS: f64 = 10.0;
/// Largest pressure difference the explicit leakage-feed exchange is checked for at
/// build time, hbar (4 hbar = 400 bar, above the 355 bar worst-case span).
pub const MAX_HBAR: f64 = 4.0;
/// Largest per-model-step rate `x` of an explicit exchange term accepted at build time
/// (dimensionless, per 100 ms model step, at [`MAX_HRADS`] / [`MAX_HBAR`]): the same
/// bound on `g (1/Ca + 1/Cb)` (2 /s) as 0.02 per step of the former 10 ms
/// single-rate model, so the identification searches the same parameter space. Far
/// inside the stability of the explicit step with midpoint extrapolation (x < 1);
/// at the bound the explicit step differs from the exact two-node relaxation
/// `1 - exp(-x)` by x/2 = 10 % of the exchange rate, at that unphysical extreme speed
/// (the identified model's rates there are ≈ 0.005-0.01; the identified model is this
/// discrete model, so this is a definition, not an error).
pub const MAX_EXPLICIT_RATE: f64 = 0.2;

/// Nodes that exchange input-dependent heat (pump housing, loop oil, valve block,
/// drain).
pub const EXCHANGE_NODES: [usize; 4] = [NODE_PUMP, NODE_LOOP_OIL, NODE_BLOCK, NODE_DRAIN];
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

/// One tick of (validated, finite) inputs in wire units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelInput {
    /// Motor phase current, A rms.
    pub current_a: f32,
    /// Pump port pressure difference `p_A - p_B`, bar.
    pub dp_bar: f32,
    /// Motor speed, rpm (signed).
    pub speed_rpm: f32,
    /// Piston position change since the previous tick, mm per tick (signed).
    pub dpos_mm: f32,
    /// Ambient temperature, degC.
    pub ambient_c: f32,
    /// LNG valve open over this tick (the guard's own command).
    pub lng_open: bool,
}

/// One tick of inputs in model units and the model's number type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelInputN<N> {
    /// Motor phase current, hA (100 A).
    pub current_ha: N,
    /// Pump port pressure difference `p_A - p_B`, hbar (10 MPa).
    pub dp_hbar: N,
    /// Motor speed, hrad/s (100 rad/s), signed.
    pub speed_hrads: N,
    /// Piston position change over the tick, mm.
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

/// Loss and exchange constants in model units (kW from hA, hbar, hrad/s, mm/tick, K).
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
    mech: N,      // kW/(hbar hrad/s)
    kq: N,        // kW/(hbar hrad/s): D·1e6
    kv: N,        // kW/(hbar mm/tick): A·10/h_tick
    ex_g: N,      // drain <-> leakage feed, kW/(K hbar): g_od1 1e7 / 1e3
    pd_g: N,      // drain <-> pump housing, kW/(K (hrad/s)^0.5): g_pd1 10 / 1e3
    lb_g: N,      // loop oil <-> block, kW/(K (hrad/s)^0.5): g_lb1 10 / 1e3
    lng_max: N,   // LNG exchanger, kW/K: g_max / 1e3
    lng_slope: N, // LNG exchanger at low speed, kW/(K hrad/s): g_slope 100 / 1e3
    lng_in: N,    // LNG inlet, degC
    feed_k: N,    // leakage-feed rise over the loop oil, K/hbar
    half: N,
    one: N,
    /// `1000 h / C` of the [`EXCHANGE_NODES`]: K per step per kW exchanged.
    ex_in: [N; 4],
}

/// Per-tick sums over the ticks of the present model step (reset by [`Model::update`]).
#[derive(Clone, Copy, Debug)]
struct TickSums<N: Num> {
    /// Current squared, hA^2 (copper loss at the model step's winding temperature).
    i2: N::Acc,
    /// Leakage loss, kW.
    leak: N::Acc,
    /// `|dp| |w|`, hbar hrad/s (mechanical loss times `eta_m D` at the model step).
    mech: N::Acc,
    /// Throttling loss, kW, floored at 0 per tick.
    hyd: N::Acc,
    /// `|dp|`, hbar (drain <-> leakage-feed exchange).
    adp: N::Acc,
    /// `|w|`, hrad/s (iron loss, speed-driven exchanges, LNG conductance).
    aw: N::Acc,
    /// Ticks with the LNG exchanger credited ([`Model::step_n`] only; the guard
    /// counts them itself).
    lng: u32,
    /// Ticks accumulated.
    n: u32,
}

impl<N: Num> TickSums<N> {
    const EMPTY: Self = TickSums {
        i2: N::ACC_ZERO,
        leak: N::ACC_ZERO,
        mech: N::ACC_ZERO,
        hyd: N::ACC_ZERO,
        adp: N::ACC_ZERO,
        aw: N::ACC_ZERO,
        lng: 0,
        n: 0,
    };
}

/// The reduced-order model in number type `N` (`f64`, `f32` or [`crate::num::Fx`]).
#[derive(Clone, Copy, Debug)]
pub struct Model<N: Num> {
    temp: [N::State; N_NODES],
    ambient_c: N,
    coef: [[N::Coef; N_COLS]; N_NODES],
    k: LossK<N>,
    /// Leakage coefficient with the viscosity ratio of the last model step, kW/hbar^2.
    leak_eff: N,
    sums: TickSums<N>,
    last_loss_kw: [N; N_LOSSES],
    last_drivers: [N; 3],
    last_lng: N,
    /// `n / TICKS_PER_STEP` for n = 0 ..= TICKS_PER_STEP (credited LNG fraction).
    lng_frac: [N; TICKS_PER_STEP as usize + 1],
    /// Pump, loop-oil, block and drain temperatures at the last model step's start
    /// (midpoint extrapolation of the exchanges), degC.
    prev_ex: [N; 4],
}

/// Discretised matrices in `f64` for the model step [`S_PER_STEP`]: row `i` =
/// `[(Ad - I)_i·, Bd_i·]`, `Bd` per kW of each loss (split over the nodes).
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
            p.ram_area_m2 * 1e7 * 1e-3 / S_PER_TICK / W_PER_KW,
            p.g_od1_w_per_k_pa * 1e7 / W_PER_KW,
            p.g_pd1_w_per_k_sqrt_rad_s * 10.0 / W_PER_KW,
            p.g_lb1_w_per_k_sqrt_rad_s * 10.0 / W_PER_KW,
            p.lng_max_w_per_k / W_PER_KW,
            p.lng_slope_w_s_per_k_rad * 100.0 / W_PER_KW,
            p.lng_inlet_c,
            p.feed_rise_k_per_pa * 1e7,
        ];
        if consts
            .iter()
            .any(|x| !x.is_finite() || libm::fabs(*x) >= 250.0)
        {
            return Err(ConfigError::ConstantRange);
        }
        // The input-dependent exchanges are explicit per model step: their per-step
        // rates x = g h (1/Ca + 1/Cb) must stay far below 1 up to `MAX_HBAR` /
        // `MAX_HRADS` (stability, and the explicit exchange error x/2 small).
        let h = S_PER_STEP;
        let rates = [
            p.g_od1_w_per_k_pa * 1e7 * MAX_HBAR * h * (1.0 / c3 + 1.0 / c5),
            p.g_pd1_w_per_k_sqrt_rad_s * 10.0 * libm::sqrt(MAX_HRADS) * h * (1.0 / c2 + 1.0 / c5),
            p.g_lb1_w_per_k_sqrt_rad_s * 10.0 * libm::sqrt(MAX_HRADS) * h * (1.0 / c3 + 1.0 / c4),
            p.lng_max_w_per_k * h / c3,
        ];
        if rates.iter().any(|r| !r.is_finite() || *r > MAX_EXPLICIT_RATE) {
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
            ex_g: f(consts[11]),
            pd_g: f(consts[12]),
            lb_g: f(consts[13]),
            lng_max: f(consts[14]),
            lng_slope: f(consts[15]),
            lng_in: f(consts[16]),
            feed_k: f(consts[17]),
            half: f(0.5),
            one: f(1.0),
            ex_in: [
                f(W_PER_KW * h / c2),
                f(W_PER_KW * h / c3),
                f(W_PER_KW * h / c4),
                f(W_PER_KW * h / c5),
            ],
        };
        let mut m = Model {
            temp: [N::state(N::ZERO); N_NODES],
            ambient_c: N::ZERO,
            coef,
            k,
            leak_eff: k.leak,
            sums: TickSums::EMPTY,
            last_loss_kw: [N::ZERO; N_LOSSES],
            last_drivers: [N::ZERO; 3],
            last_lng: N::ZERO,
            lng_frac: [N::ZERO; TICKS_PER_STEP as usize + 1],
            prev_ex: [N::ZERO; 4],
        };
        for (i, fr) in m.lng_frac.iter_mut().enumerate() {
            *fr = f(i as f64 / TICKS_PER_STEP as f64);
        }
        m.state_was_set();
        Ok(m)
    }

    /// After the state was set (not stepped): no history for the midpoint
    /// extrapolation, the leakage coefficient at the new drain temperature.
    fn state_was_set(&mut self) {
        for (p, n) in self.prev_ex.iter_mut().zip(EXCHANGE_NODES.iter()) {
            *p = self.temp.get(*n).map_or(N::ZERO, |t| N::value(*t));
        }
        self.refresh_leak();
    }

    /// Leakage coefficient for the next ticks: `K dp^2 / mu(T)` with the viscosity
    /// ratio at the present drain temperature (eqs. 5-7), held over a model step.
    fn refresh_leak(&mut self) {
        let k = &self.k;
        self.leak_eff = if k.use_mu {
            let t_d = N::value(self.temp[NODE_DRAIN]);
            k.leak.mul(k.k_mu.mul(t_d.sub(k.t_mu)).exp())
        } else {
            k.leak
        };
    }

    /// Sets every node and the ambient to `t_c` (degC, model number type): cold start.
    /// Ticks already accumulated are kept.
    pub fn set_uniform(&mut self, t_c: N) {
        self.ambient_c = t_c;
        for th in self.temp.iter_mut() {
            *th = N::state(t_c);
        }
        self.state_was_set();
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
        self.state_was_set();
    }

    /// Losses `[copper, iron, leakage, mechanical, throttling]` in kW (eqs. 1, 2, 5-8,
    /// 11) of a model step whose ticks all have these inputs, at the present node
    /// temperatures; `dpos_mm` is the position change over one tick.
    pub fn losses_kw(&self, i_ha: N, dp_hbar: N, w_hrads: N, dpos_mm: N) -> [N; N_LOSSES] {
        let k = &self.k;
        let (adp, aw) = (dp_hbar.abs(), w_hrads.abs());
        let t_w = N::value(self.temp[NODE_WINDING]);
        let p_leak = self.leak_eff.mul(dp_hbar).mul(dp_hbar);
        [
            i_ha.mul(i_ha).mul(k.cu0.add(k.cu1.mul(t_w))),
            aw.mul(k.fe1.add(k.fe2.mul(aw)).add(k.fe15.mul(aw.sqrt_abs()))),
            p_leak,
            k.mech.mul(adp.mul(aw)),
            dp_hbar
                .mul(k.kq.mul(w_hrads).sub(k.kv.mul(dpos_mm)))
                .sub(p_leak)
                .max0(),
        ]
    }

    /// One 10 ms tick with inputs in wire units: [`Model::tick_n`], then
    /// [`Model::update`] when the model step is complete. Returns `true` when the
    /// model advanced. Never panics.
    pub fn step(&mut self, u: &ModelInput, s: &InputScales<N>) -> bool {
        self.step_n(
            &ModelInputN {
                current_ha: N::from_f32_scaled(u.current_a, s.ha_per_a),
                dp_hbar: N::from_f32_scaled(u.dp_bar, s.hbar_per_bar),
                speed_hrads: N::from_f32_scaled(u.speed_rpm, s.hrads_per_rpm),
                dpos_mm: N::from_f32_scaled(u.dpos_mm, s.one),
                ambient_c: N::from_f32_scaled(u.ambient_c, s.one),
            },
            u.lng_open,
        )
    }

    /// [`Model::step`] with inputs already in model units: [`Model::tick_n`], the
    /// tick counted as credited with the LNG exchanger when `lng_open`, and
    /// [`Model::update`] with that count when the model step is complete.
    #[inline(always)]
    pub fn step_n(&mut self, u: &ModelInputN<N>, lng_open: bool) -> bool {
        self.sums.lng += lng_open as u32;
        let full = self.tick_n(u);
        if full {
            self.update(self.sums.lng);
        }
        full
    }

    /// Accumulates one 10 ms tick: its leakage and throttling losses (the throttling
    /// floored at 0 for this tick), `I^2`, `|dp| |w|`, the drivers `|dp|` and `|w|`;
    /// the ambient of the tick is kept (the model step uses the last tick's). Returns
    /// `true` when [`crate::params::TICKS_PER_STEP`] ticks are accumulated: the caller
    /// must then call [`Model::update`] before the next tick.
    #[inline(always)]
    #[must_use]
    pub fn tick_n(&mut self, u: &ModelInputN<N>) -> bool {
        let k = &self.k;
        let dp = u.dp_hbar;
        let w = u.speed_hrads;
        let (adp, aw) = (dp.abs(), w.abs());
        let i = u.current_ha;
        // eqs. (5)-(7): K dp^2 / mu(T) (viscosity ratio held over the model step)
        let p_leak = self.leak_eff.mul(dp).mul(dp);
        // eq. (11) generalised: dp (D w - Q_leak) - dp A v, never negative (no heat sink)
        let p_hyd = dp.mul(k.kq.mul(w).sub(k.kv.mul(u.dpos_mm))).sub(p_leak).max0();
        let s = &mut self.sums;
        s.i2 = N::acc(s.i2, i.mul(i));
        s.leak = N::acc(s.leak, p_leak);
        s.mech = N::acc(s.mech, adp.mul(aw));
        s.hyd = N::acc(s.hyd, p_hyd);
        s.adp = N::acc(s.adp, adp);
        s.aw = N::acc(s.aw, aw);
        self.ambient_c = u.ambient_c;
        s.n += 1;
        s.n >= TICKS_PER_STEP
    }

    /// Ticks accumulated since the last model step (0 right after [`Model::update`]).
    pub fn pending_ticks(&self) -> u32 {
        self.sums.n
    }

    /// Advances one model step of [`S_PER_STEP`] with the tick-averaged inputs of the
    /// accumulated ticks held (exact ZOH for the linear part) and the last tick's
    /// ambient, plus the explicit input-dependent exchanges, with the LNG exchanger
    /// credited over `lng_ticks` of the step's ticks; clears the tick sums. Never
    /// panics.
    pub fn update(&mut self, lng_ticks: u32) {
        let s = core::mem::replace(&mut self.sums, TickSums::EMPTY);
        let mean = N::acc_mean;
        let amb = self.ambient_c;
        let (adp, aw) = (mean(s.adp), mean(s.aw));
        let sw = aw.sqrt_abs();
        self.last_drivers = [adp, sw, aw];
        let k = &self.k;
        let th = &self.temp;
        // eq. (1): m I^2 R0 (1 + alpha (T_w - 25)), with the mean of I^2
        let t_w = N::value(th[NODE_WINDING]);
        // eq. (2) with f ∝ w and constant B_m, at the step's mean |w|
        let p_fe = aw.mul(k.fe1.add(k.fe2.mul(aw)).add(k.fe15.mul(sw)));
        let p = [
            mean(s.i2).mul(k.cu0.add(k.cu1.mul(t_w))),
            p_fe,
            mean(s.leak),
            k.mech.mul(mean(s.mech)),
            mean(s.hyd),
        ];
        self.last_loss_kw = p;
        // LNG exchanger, eqs. (20)-(22), over the credited fraction `f` of the ticks:
        // conductance g = min(g_max, g_slope |w|) (the smaller capacity rate is the LNG
        // stream above ~30 rpm, the oil stream below), |w| the step's mean; the loop oil
        // loses f g (T_loop - T_LNG). The oil leaving the exchanger is colder than the
        // loop oil by the heat removed over the oil stream's capacity rate, g / (g_slope
        // |w|) (T_loop - T_LNG) (all of the difference when the oil stream is the
        // smaller), for the same fraction f.
        let f = self.lng_frac.get(lng_ticks as usize).copied().unwrap_or(k.one);
        let (g_lng, cooled) = if f > N::ZERO {
            let g = k.lng_slope.mul(aw);
            if g > k.lng_max {
                (k.lng_max.mul(f), k.lng_max.div_pos(g).mul(f))
            } else {
                (g.mul(f), f)
            }
        } else {
            (N::ZERO, N::ZERO)
        };
        // The exchange powers are held over the step at their value at the step's
        // midpoint, the temperatures extrapolated from the last step (second order:
        // T + (T - T_prev)/2; a step-start value would lag by h/2 · dT/dt, ≈ 5e-3 K on
        // the drain heating at 0.1 K/s).
        let t_now = [
            N::value(th[NODE_PUMP]),
            N::value(th[NODE_LOOP_OIL]),
            N::value(th[NODE_BLOCK]),
            N::value(th[NODE_DRAIN]),
        ];
        let mut t_mid = t_now;
        for (m, p) in t_mid.iter_mut().zip(self.prev_ex.iter()) {
            *m = m.add(k.half.mul(m.sub(*p)));
        }
        self.prev_ex = t_now;
        let [x_pump, x_loop, x_block, x_drain] = t_mid.map(|t| t.sub(amb));
        let t_rel = x_loop.add(amb.sub(k.lng_in));
        let q_lng = g_lng.mul(t_rel);
        // Drain <- leakage feed, g = g_od1 |dp| (the leakage flow through the case, |dp|
        // the step's mean): the leakage enters the case at the feed temperature, the
        // loop oil plus the high-pressure port's rise feed_k |dp|, minus the
        // exchanger's cooling.
        let feed = x_loop.add(k.feed_k.mul(adp)).sub(cooled.mul(t_rel));
        let q_ex = k.ex_g.mul(adp).mul(feed.sub(x_drain));
        // Speed-driven exchanges (drain <-> pump housing, loop oil <-> block), sqrt|w|
        // the step's mean of the ticks' sqrt|w|.
        let q_pd = k.pd_g.mul(sw).mul(x_pump.sub(x_drain));
        let q_lb = k.lb_g.mul(sw).mul(x_loop.sub(x_block));
        // The exchange powers (kW), held over the step, change their nodes by
        // δ = h C^-1 q. Exponential Euler would add h φ1(hA) C^-1 q; to second order
        // in h that is δ + (Ad - I) δ/2, so the matrix product takes θ + δ/2 (a
        // steady state of the continuous model is then a fixed point of the step to
        // O(h^2); with δ alone, h/2 A δ is missing and the slow metal nodes
        // integrate it: 4e-3 K against the RK4 reference instead of 3e-5 K).
        let [e2, e3, e4, e5] = k.ex_in;
        let d2 = e2.mul(N::ZERO.sub(q_pd));
        let d3 = e3.mul(N::ZERO.sub(q_ex).sub(q_lb).sub(q_lng));
        let d4 = e4.mul(q_lb);
        let d5 = e5.mul(q_ex.add(q_pd));
        let h = k.half;
        let x: [N; N_COLS] = [
            N::value(th[0]).sub(amb),
            N::value(th[1]).sub(amb),
            t_now[0].sub(amb).add(h.mul(d2)),
            t_now[1].sub(amb).add(h.mul(d3)),
            t_now[2].sub(amb).add(h.mul(d4)),
            t_now[3].sub(amb).add(h.mul(d5)),
            p[0],
            p[1],
            p[2],
            p[3],
            p[4],
        ];
        let one = k.one;
        let [c0, c1, c2, c3, c4, c5] = &self.coef;
        let [t0, t1, t2, t3, t4, t5] = &mut self.temp;
        *t0 = N::accumulate(*t0, c0, &x);
        *t1 = N::accumulate(*t1, c1, &x);
        *t2 = N::apply(*t2, N::dot(c2, &x), &[d2], &[one]);
        *t3 = N::apply(*t3, N::dot(c3, &x), &[d3], &[one]);
        *t4 = N::apply(*t4, N::dot(c4, &x), &[d4], &[one]);
        *t5 = N::apply(*t5, N::dot(c5, &x), &[d5], &[one]);
        self.last_lng = q_lng;
        self.refresh_leak();
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

    /// Losses of the last model step `[cu, fe, leak, mech, throttle]` (means over its
    /// ticks), kW.
    pub fn last_losses_kw(&self) -> [N; N_LOSSES] {
        self.last_loss_kw
    }

    /// Exchange drivers of the last model step (means over its ticks): `[|dp| hbar,
    /// sqrt|w| (hrad/s)^0.5, |w| hrad/s]`.
    pub fn last_drivers(&self) -> [N; 3] {
        self.last_drivers
    }

    /// Heat the LNG exchanger removed from the loop oil over the last model step, kW
    /// (0 while the valve is closed).
    pub fn last_lng_kw(&self) -> N {
        self.last_lng
    }

    /// Sum of the last model step's losses (mean over its ticks), kW.
    pub fn last_total_kw(&self) -> N {
        self.last_loss_kw.iter().fold(N::ZERO, |a, p| a.add(*p))
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
