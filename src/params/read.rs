//! What is read off a parameter block besides its fields: the viscosity
//! table interpolated as the firmware reads it, the ducts' film tables as
//! one array, the oil's volumetric heat capacity, and the plausibility check
//! every block passes before the firmware uses it.

use super::{ReducedParams, FILM_PROPERTY_C, N_COARSE, N_DUCTS, N_RE, N_TEMP, TEMP_TABLE_MIN_C, TEMP_TABLE_STEP_K};

impl ReducedParams {
    /// `mu(T) / mu(40 degC)` of the case oil at `t_c`, degC: the linear
    /// interpolation of [`Self::visc_ratio`] on its grid, the end values
    /// held, as the firmware reads it. Host tests draw a consistent motor
    /// current with it (the pump's viscous friction, extended eq. 8).
    pub fn visc_ratio_at(&self, t_c: f64) -> f64 {
        let u = (t_c - TEMP_TABLE_MIN_C) / TEMP_TABLE_STEP_K;
        let u = if u > 0.0 { u } else { 0.0 };
        let last = N_TEMP - 2;
        // (u >= 0: the cast truncates to the floor)
        let j = u as usize;
        let (j, f) = if j > last { (last, 1.0) } else { (j, u - j as f64) };
        let (a, b) = (self.visc_ratio.get(j).copied().unwrap_or(1.0), self.visc_ratio.get(j + 1).copied().unwrap_or(1.0));
        a + (b - a) * f
    }

    /// The ducts' films over the coarse temperature grid, `[duct][Re of DUCT_RE]`.
    pub fn duct_films(&self) -> [[&[f64; N_COARSE]; N_RE]; N_DUCTS] {
        [
            [&self.g_port_re2300_w_per_k, &self.g_port_re1e4_w_per_k, &self.g_port_re3e4_w_per_k, &self.g_port_re1e5_w_per_k],
            [&self.g_loop_re2300_w_per_k, &self.g_loop_re1e4_w_per_k, &self.g_loop_re3e4_w_per_k, &self.g_loop_re1e5_w_per_k],
            [&self.g_ball_re2300_w_per_k, &self.g_ball_re1e4_w_per_k, &self.g_ball_re3e4_w_per_k, &self.g_ball_re1e5_w_per_k],
        ]
    }

    /// Oil volumetric heat capacity at `t_c`, J/(m^3 K) (density and specific heat
    /// both linear in temperature).
    pub fn rho_cp(&self, t_c: f64) -> f64 {
        (self.rho_kg_per_m3 + self.rho_slope_kg_per_m3_k * (t_c - 40.0)) * (self.cp20_j_per_kg_k + self.cp_slope_j_per_kg_k2 * (t_c - 20.0))
    }

    /// Physical plausibility: capacities and volumes > 0, conductances and
    /// coefficients >= 0, everything finite. `true` when usable.
    pub fn is_plausible(&self) -> bool {
        let pos = [
            self.pump_j_per_k,
            self.main_block_j_per_k,
            self.ball_block_j_per_k,
            self.actuator_j_per_k,
            self.case_oil_m3,
            self.loop_oil_m3,
            self.port_oil_m3,
            self.ball_oil_m3,
            self.rho_kg_per_m3,
            self.cp20_j_per_kg_k,
            self.speed_table_max_rad_s,
            self.flow_table_max_m3_per_s,
        ]
        .iter()
        .all(|x| x.is_finite() && *x > 0.0);
        let non_neg = [
            self.displacement_m3_per_rad,
            self.eta_m,
            self.no_load_torque_nm,
            self.viscous_w_s2_per_rad2,
            self.mech_to_outlet,
            self.mech_to_case,
            self.expansion_per_k,
            self.k_leak_m3_per_s_pa,
            self.line_r1_pa_s_per_m3,
            self.line_r2_pa_s2_per_m6,
            self.ram_area_m2,
            self.act_leak_m3_per_s_pa,
            self.act_friction_n_s_per_m,
            self.phases,
            self.r_ohm,
            self.torque_constant_nm_per_a,
            self.pole_pairs,
            self.k_fe1_w_s_per_rad,
            self.k_fe2_w_s2_per_rad2,
            self.k_fe15_w_per_rad15,
            self.drain_margin_k,
        ]
        .iter()
        .chain(self.g_case_w_per_k.iter())
        .chain(self.g_port_w_per_k.iter())
        .chain(self.g_loop_block_w_per_k.iter())
        .chain(self.g_ball_block_w_per_k.iter())
        .chain(self.g_lng_w_per_k.iter())
        .chain(self.re_per_flow.iter())
        .chain(self.duct_wall_w_per_k.iter())
        .chain(self.duct_films().iter().flat_map(|d| d.iter().flat_map(|c| c.iter())))
        .chain(self.outer_w_per_k.iter())
        .chain(self.outer_quarter_w_per_k125.iter())
        .chain(self.outer_rad_w_per_k4.iter())
        .all(|x| x.is_finite() && *x >= 0.0);
        // The quasi-steady links divide by their conductance at zero flow.
        let links = self.g_port_w_per_k.first().is_some_and(|g| *g > 0.0)
            && self.g_ball_block_w_per_k.first().is_some_and(|g| *g > 0.0);
        let finite = [
            self.cp_slope_j_per_kg_k2,
            self.case_film_slope_per_k,
            self.case_pressure_pa,
            self.rho_slope_kg_per_m3_k,
            self.lng_inlet_c,
        ]
        .iter()
        .chain(self.nominal_jacobian_per_s.iter().flatten())
        .chain(self.phi_step_s.iter().flatten())
        .all(|x| x.is_finite());
        let rest = self.rest_rate_per_s.iter().all(|r| r.is_finite() && *r >= 0.0)
            && self.rest_mode.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v));
        let split = self.mech_to_outlet + self.mech_to_case <= 1.0;
        // the temperature tables: positive, and 1 at 40 degC where they are referred
        let t40 = ((FILM_PROPERTY_C - TEMP_TABLE_MIN_C) / TEMP_TABLE_STEP_K) as usize;
        let temp_tables = [&self.leak_ratio, &self.visc_ratio, &self.tc_speed_ratio]
            .iter()
            .all(|t| t.iter().all(|x| x.is_finite() && *x > 0.0) && t.get(t40).is_some_and(|x| (x - 1.0).abs() < 1e-9));
        let cp_pos = self.rho_cp(-60.0) > 0.0 && self.rho_cp(150.0) > 0.0;
        pos && non_neg && links && finite && split && cp_pos && rest && temp_tables
    }
}
