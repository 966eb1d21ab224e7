//! SI parameters of the reduced-order thermal model (design side, `f64`).
//!
//! Everything here is plain SI (J/K, W/K, ohm, m^3/rad, ...) so that an
//! identification procedure in `host-tests` can set every field from `f64`
//! values and regenerate [`DEFAULT`] with plain literals. The firmware never
//! steps with these numbers directly: [`crate::model::Model::new`] turns them
//! once into discretised coefficients of the firmware's number type.
//!
//! Node order (fixed, see `docs/contracts.md`): `0 winding, 1 motor housing,
//! 2 pump housing, 3 loop oil, 4 valve block, 5 drain oil`.
//! Loss order: `0 copper, 1 iron, 2 leakage, 3 mechanical, 4 throttling`.

/// Number of thermal states (nodes) of the reduced model.
pub const N_NODES: usize = 6;
/// Number of loss inputs (copper, iron, leakage, mechanical, throttling).
pub const N_LOSSES: usize = 5;

/// Node index: motor winding (copper + stator teeth).
pub const NODE_WINDING: usize = 0;
/// Node index: motor housing (measurement Point 1).
pub const NODE_MOTOR: usize = 1;
/// Node index: pump housing (measurement Point 3).
pub const NODE_PUMP: usize = 2;
/// Node index: circulating (loop) oil.
pub const NODE_LOOP_OIL: usize = 3;
/// Node index: valve block metal (Points 4 + 5 lumped).
pub const NODE_BLOCK: usize = 4;
/// Node index: drain oil in the pump case (the protected temperature).
pub const NODE_DRAIN: usize = 5;

/// Sample tick: 10 ms (100 Hz), s. `Guard::step` is called once per tick; inputs are
/// validated and the losses and exchange drivers accumulated every tick.
pub const S_PER_TICK: f64 = 0.01;
/// Ticks per model step (multi-rate step, docs/firmware.md): the thermal model is
/// advanced once every `TICKS_PER_STEP` ticks with the tick-averaged inputs.
/// 10 ticks = 100 ms: the fastest thermal time constant of the model (the drain oil,
/// 296 J/K against ≈ 7 W/K at 60 bar / 500 rpm: ≈ 40 s) is 400 model steps.
pub const TICKS_PER_STEP: u32 = 10;
/// Model step: `TICKS_PER_STEP` × [`S_PER_TICK`] = 100 ms, s. Every discretised
/// coefficient (the exact ZOH matrices, the explicit exchange rates) assumes it.
pub const S_PER_STEP: f64 = 0.1;
const _: () = assert!(TICKS_PER_STEP >= 1 && TICKS_PER_STEP <= 64);
const _: () = assert!(S_PER_STEP == S_PER_TICK * TICKS_PER_STEP as f64);

/// Reduced-order model parameters, SI units, `f64`.
///
/// Continuous model (contracts.md): `C dT/dt = -(L + diag(g_amb)) T + E p + g_amb T_amb`
/// with `L` the graph Laplacian of [`ReducedParams::conductance_w_per_k`],
/// `E` = [`ReducedParams::loss_split`] and the losses `p` of eqs. (1)-(11).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReducedParams {
    /// Heat capacity of each node, J/K (must be > 0).
    pub capacity_j_per_k: [f64; N_NODES],
    /// Symmetric node-to-node conductance, W/K; diagonal ignored. Includes the
    /// constant drain <-> loop-oil conductance `g_od0` at `[3][5]`/`[5][3]`.
    pub conductance_w_per_k: [[f64; N_NODES]; N_NODES],
    /// Conductance of each node to ambient (free convection + radiation), W/K.
    pub ambient_w_per_k: [f64; N_NODES],
    /// Share of each loss (column) deposited in each node (row), dimensionless;
    /// each column sums to 1 so that energy is conserved.
    pub loss_split: [[f64; N_LOSSES]; N_NODES],
    /// Number of motor phases `m` in eq. (1).
    pub phases: f64,
    /// Phase resistance at 25 degC `R0`, ohm (eq. 1).
    pub r0_ohm: f64,
    /// Temperature coefficient of the winding resistance, 1/K (0 = constant R).
    pub alpha_r_per_k: f64,
    /// Iron loss, hysteresis-like term: `P = k_fe1 |w|`, W/(rad/s) (eq. 2, f ∝ w).
    pub k_fe1_w_s_per_rad: f64,
    /// Iron loss, eddy term: `P = k_fe2 w^2`, W/(rad/s)^2 (eq. 2).
    pub k_fe2_w_s2_per_rad2: f64,
    /// Iron loss, excess term: `P = k_fe15 |w|^1.5`, W/(rad/s)^1.5 (eq. 2).
    pub k_fe15_w_per_rad15: f64,
    /// Leakage loss coefficient `P_leak = K_leak dp^2 mu_ratio`, W/Pa^2 (eqs. 5-7).
    pub k_leak_w_per_pa2: f64,
    /// Viscosity-temperature exponent: `mu_ratio = exp(k_mu (T_drain - T_ref))`, 1/K
    /// (0 when viscosity is held constant, as in the reference baseline).
    pub k_mu_per_k: f64,
    /// Reference temperature of the viscosity ratio, degC.
    pub t_mu_ref_c: f64,
    /// Pump mechanical loss coefficient `eta_m` (eq. 8: `P = eta_m D |dp| |w|`), dimensionless.
    pub eta_m: f64,
    /// Pump displacement per radian, m^3/rad (19 cm^3/rev / 2 pi).
    pub displacement_m3_per_rad: f64,
    /// Effective ram area of the double-rod cylinder, m^2 (Table 3: 1526.81 mm^2).
    pub ram_area_m2: f64,
    /// Constant drain <-> loop-oil conductance `g_od0`, W/K (also in the matrix; kept
    /// here so identification can set it in one place, see [`ReducedParams::with_g_od0`]).
    pub g_od0_w_per_k: f64,
    /// Flow-dependent drain <-> loop-oil conductance `g_od1 |dp|`, W/(K Pa)
    /// (leakage advection, applied as an exact two-node exchange per step).
    pub g_od1_w_per_k_pa: f64,
    /// Speed-dependent drain <-> pump-housing conductance `g_pd1 sqrt|w|`,
    /// W/(K (rad/s)^0.5): forced convection of the case oil by the rotating group
    /// (eqs. 13-14: laminar Nu ∝ (Re Pr d/L)^(1/3), between that and the turbulent
    /// Re^0.8 the square root is the cheap middle); it vanishes when the pump stops.
    /// Added to the constant entry `[2][5]` as an explicit two-node exchange per step.
    pub g_pd1_w_per_k_sqrt_rad_s: f64,
    /// Speed-dependent loop-oil <-> valve-block conductance `g_lb1 sqrt|w|`,
    /// W/(K (rad/s)^0.5): the duct film coefficient grows with the circulating flow
    /// `D |w|` (eqs. 13-14).
    pub g_lb1_w_per_k_sqrt_rad_s: f64,
    /// LNG exchanger conductance at full circulation, `eps C_LNG`, W/K (eqs. 20-22:
    /// the LNG stream is the smaller capacity rate; see [`ReducedParams::lng_w_per_k`]).
    pub lng_max_w_per_k: f64,
    /// LNG exchanger conductance per rad/s at low speed, where the oil stream
    /// `rho c_p D |w|` is the smaller capacity rate, W/(K rad/s).
    pub lng_slope_w_s_per_k_rad: f64,
    /// LNG inlet temperature (Table 6: -162 degC), degC.
    pub lng_inlet_c: f64,
    /// Temperature rise of the leakage feed over the loop oil per unit `|dp|`, K/Pa:
    /// the leakage leaves from the high-pressure port, which the mechanical loss has
    /// heated by `f eta_m |dp| / (rho c_p)` (eq. 8 over the circulating flow).
    pub feed_rise_k_per_pa: f64,
}

impl ReducedParams {
    /// Conductance of the LNG exchanger while open at shaft speed `w_rad_s`, W/K:
    /// `min(lng_max, lng_slope |w|)` — eqs. (20)-(22) with the effectiveness held at
    /// its value for the nominal flows; the heat removed from the loop oil is this
    /// times `T_loop - lng_inlet_c`.
    pub fn lng_w_per_k(&self, w_rad_s: f64) -> f64 {
        let g = self.lng_slope_w_s_per_k_rad * libm::fabs(w_rad_s);
        if g < self.lng_max_w_per_k {
            g
        } else {
            self.lng_max_w_per_k
        }
    }

    /// Returns a copy with `g_od0` written into both the field and the matrix entries.
    pub const fn with_g_od0(mut self, g_w_per_k: f64) -> Self {
        self.g_od0_w_per_k = g_w_per_k;
        self.conductance_w_per_k[NODE_LOOP_OIL][NODE_DRAIN] = g_w_per_k;
        self.conductance_w_per_k[NODE_DRAIN][NODE_LOOP_OIL] = g_w_per_k;
        self
    }

    /// Physical plausibility check: capacities > 0, conductances >= 0 and symmetric,
    /// split columns sum to 1 within 1e-9, all finite. `true` when usable.
    pub fn is_plausible(&self) -> bool {
        let caps = self
            .capacity_j_per_k
            .iter()
            .all(|c| c.is_finite() && *c > 0.0);
        let amb = self
            .ambient_w_per_k
            .iter()
            .all(|g| g.is_finite() && *g >= 0.0);
        let mut sym = true;
        for (i, row) in self.conductance_w_per_k.iter().enumerate() {
            for (j, g) in row.iter().enumerate() {
                let gt = self.conductance_w_per_k.get(j).and_then(|r| r.get(i));
                if i != j && (!g.is_finite() || *g < 0.0 || gt != Some(g)) {
                    sym = false;
                }
            }
        }
        let mut col_sum = [0.0f64; N_LOSSES];
        let mut split = true;
        for row in self.loss_split.iter() {
            for (s, x) in col_sum.iter_mut().zip(row.iter()) {
                if !x.is_finite() || *x < 0.0 {
                    split = false;
                }
                *s += x;
            }
        }
        if col_sum.iter().any(|s| (s - 1.0).abs() > 1e-9) {
            split = false;
        }
        let scalars = [
            self.phases,
            self.r0_ohm,
            self.alpha_r_per_k,
            self.k_fe1_w_s_per_rad,
            self.k_fe2_w_s2_per_rad2,
            self.k_fe15_w_per_rad15,
            self.k_leak_w_per_pa2,
            self.k_mu_per_k,
            self.t_mu_ref_c,
            self.eta_m,
            self.displacement_m3_per_rad,
            self.ram_area_m2,
            self.g_od0_w_per_k,
            self.g_od1_w_per_k_pa,
            self.g_pd1_w_per_k_sqrt_rad_s,
            self.g_lb1_w_per_k_sqrt_rad_s,
            self.lng_max_w_per_k,
            self.lng_slope_w_s_per_k_rad,
            self.lng_inlet_c,
            self.feed_rise_k_per_pa,
        ]
        .iter()
        .all(|x| x.is_finite());
        let non_negative = [
            self.g_od1_w_per_k_pa,
            self.g_pd1_w_per_k_sqrt_rad_s,
            self.g_lb1_w_per_k_sqrt_rad_s,
            self.lng_max_w_per_k,
            self.lng_slope_w_s_per_k_rad,
        ]
        .iter()
        .all(|x| *x >= 0.0);
        caps && amb && sym && split && scalars && non_negative
    }
}

/// Default parameters, identified from the reference simulation (`eha_sim::identify`,
/// docs/identification.md): loss coefficients reduced from `Rig::default()`
/// (R constant, iron eq. 2 with f = p w / 2 pi, K_leak = gap conductance at 40 degC,
/// eta_m, D, A; LNG exchanger eqs. 20-22 at 300 rpm); capacities, conductances, ambient
/// conductances, the mechanical and throttling splits, g_od1, g_pd1, g_lb1 and the feed
/// rise fitted by Levenberg-Marquardt on log-parameters to the drain temperature of the
/// training runs (Case 1 at 10/30/50 bar, Case 2, random missions [6, 9, 19, 22, 24, 29], and the
/// drain-thermostat LNG runs of `LNG_TRAINING`).
/// No conservative bias applied (training under-prediction within budget).
/// THIS CONSTANT IS REGENERATED BY THE IDENTIFICATION TOOL: keep plain literals.
pub const DEFAULT: ReducedParams = ReducedParams {
    capacity_j_per_k: [3079.8361793868903, 33451.35598778382, 10269.831889029729, 2981.7121267106995, 81624.17558988974, 296.1952580597654],
    conductance_w_per_k: [
        [0.0, 15.000505282525731, 0.0, 0.0, 0.0, 0.0],
        [15.000505282525731, 0.0, 0.004957867005760049, 0.0, 0.0, 0.0],
        [0.0, 0.004957867005760049, 0.0, 3.3606150367622787, 0.0, 0.26967942292228864],
        [0.0, 0.0, 3.3606150367622787, 0.0, 8.81131394313296, 0.09952120137410797],
        [0.0, 0.0, 0.0, 8.81131394313296, 0.0, 0.0],
        [0.0, 0.0, 0.26967942292228864, 0.09952120137410797, 0.0, 0.0],
    ],
    ambient_w_per_k: [0.0, 3.5751339534778723, 7.113408811134203, 0.0, 0.010906509580101392, 0.0],
    loss_split: [
        [1.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 0.70987551636462, 0.999724656433377],
        [0.0, 0.0, 0.0, 0.0, 0.00027534356662295423],
        [0.0, 0.0, 1.0, 0.29012448363538, 0.0],
    ],
    phases: 3.0,
    r0_ohm: 0.074,
    alpha_r_per_k: 0.0,
    k_fe1_w_s_per_rad: 0.37433242615213785,
    k_fe2_w_s2_per_rad2: 0.0015887161595118564,
    k_fe15_w_per_rad15: 0.008414188516295527,
    k_leak_w_per_pa2: 3.357993172582738e-13,
    k_mu_per_k: 0.0,
    t_mu_ref_c: 40.0,
    eta_m: 0.49826,
    displacement_m3_per_rad: 3.023943918746011e-6,
    ram_area_m2: 0.00152681,
    g_od0_w_per_k: 0.09952120137410797,
    g_od1_w_per_k_pa: 6.269003909744255e-7,
    g_pd1_w_per_k_sqrt_rad_s: 0.4380786213812423,
    g_lb1_w_per_k_sqrt_rad_s: 3.848199452970729,
    lng_max_w_per_k: 15.08143111783885,
    lng_slope_w_s_per_k_rad: 5.068734252292159,
    lng_inlet_c: -162.0,
    feed_rise_k_per_pa: 5.669537874889348e-10,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_plausible_and_displacement_matches_table2() {
        assert!(DEFAULT.is_plausible());
        // 19 cm^3/rev = 19e-6 m^3 / (2 pi rad); 1e-15 relative is f64 literal rounding.
        let d = 19e-6 / (2.0 * core::f64::consts::PI);
        assert!((DEFAULT.displacement_m3_per_rad - d).abs() < 1e-15);
        assert_eq!(DEFAULT.conductance_w_per_k[3][5], DEFAULT.g_od0_w_per_k);
    }

    #[test]
    fn implausible_split_is_rejected() {
        let mut p = DEFAULT;
        p.loss_split[0][0] = 0.9; // copper column now sums to 0.9: energy not conserved
        assert!(!p.is_plausible());
        let mut q = DEFAULT;
        q.capacity_j_per_k[5] = 0.0;
        assert!(!q.is_plausible());
    }
}
