//! [`derive`]: the reduced model's constants from its SI parameters (host
//! side, `f64`) — the unit conversions of eqs. (1)-(22) into model units,
//! the tables over temperature, flow and speed, and the derived words the
//! target checks for consistency.

use super::{ModelConsts, MAX_ABS};
use crate::model::{ConfigError, HA_PER_A, KW_PER_W, L_PER_M3, PA_PER_HBAR, RAD_T_K};
use crate::params::{ReducedParams, N_COARSE, N_DUCTS, N_RE, N_TABLE, S_PER_TICK};

/// Derives the model constants from SI parameters (host side, `f64`): the unit
/// conversions of eqs. (1)-(22) into model units. `Err` if the parameters are
/// implausible or a constant leaves the value format.
pub fn derive(p: &ReducedParams) -> Result<ModelConsts<f64>, ConfigError> {
    if !p.is_plausible() {
        return Err(ConfigError::Implausible);
    }
    let d = p.displacement_m3_per_rad;
    let kl = p.k_leak_m3_per_s_pa;
    // rho c_p = (r0 + r1 T)(c0 + c1 T) with T in degC
    let (r1, c1) = (p.rho_slope_kg_per_m3_k, p.cp_slope_j_per_kg_k2);
    let (r0, c0) = (p.rho_kg_per_m3 - 40.0 * r1, p.cp20_j_per_kg_k - 20.0 * c1);
    let rc0 = r0 * c0 * 1e-6;
    let rc1 = (r0 * c1 + r1 * c0) * 1e-6;
    let rc2 = r1 * c1 * 1e-6;
    let q_max = p.flow_table_max_m3_per_s * L_PER_M3;
    let w_max = p.speed_table_max_rad_s * 0.01;
    let n1 = (N_TABLE - 1) as f64;
    let v_ring = (p.loop_oil_m3 + 2.0 * p.port_oil_m3 + p.ball_oil_m3) * L_PER_M3;
    let caps_kj = [
        p.pump_j_per_k,
        0.0,
        0.0,
        p.main_block_j_per_k,
        p.ball_block_j_per_k,
        p.actuator_j_per_k,
    ];
    let inv_c = caps_kj.map(|c| if c > 0.0 { 1e3 / c } else { 0.0 });
    let k_lf = kl * PA_PER_HBAR * L_PER_M3;
    let k_al = p.act_leak_m3_per_s_pa * PA_PER_HBAR * PA_PER_HBAR * KW_PER_W;
    let k_fr = p.act_friction_n_s_per_m * (1e-3 / S_PER_TICK) * (1e-3 / S_PER_TICK) * KW_PER_W;
    // Actuator heat per tick `k_al dp^2 + k_fr dx^2` as `k_act (w_dp dp^2 + w_dx dx^2)`
    // with the larger coefficient factored out (both weights <= 1).
    let k_act = if k_al > k_fr { k_al } else { k_fr };
    let (w_dp, w_dx) = if k_act > 0.0 { (k_al / k_act, k_fr / k_act) } else { (0.0, 0.0) };
    let kw = |t: &[f64; N_TABLE]| t.map(|g| g * KW_PER_W);
    let c = ModelConsts {
        p_case: p.case_pressure_pa / PA_PER_HBAR,
        k_lf,
        k_lf_half: k_lf * 0.5,
        k_lp: kl * PA_PER_HBAR * PA_PER_HBAR * KW_PER_W,
        k_mech: p.eta_m * d * PA_PER_HBAR * 100.0 * KW_PER_W,
        k_q: d * 100.0 * L_PER_M3,
        k_a: p.ram_area_m2 * 1e-3 / S_PER_TICK * L_PER_M3,
        k_dpq: PA_PER_HBAR / L_PER_M3 * KW_PER_W,
        r1: p.line_r1_pa_s_per_m3 / (L_PER_M3 * L_PER_M3) * KW_PER_W,
        r2: p.line_r2_pa_s2_per_m6 / (L_PER_M3 * L_PER_M3 * L_PER_M3) * KW_PER_W,
        w_dp,
        w_dx,
        k_act,
        k_cu: p.phases * p.r_ohm / (HA_PER_A * HA_PER_A) * KW_PER_W,
        k_sh: p.torque_constant_nm_per_a / HA_PER_A * 100.0 * KW_PER_W,
        k_hyd: d * PA_PER_HBAR * 100.0 * KW_PER_W,
        fe1: p.k_fe1_w_s_per_rad * 100.0 * KW_PER_W,
        fe2: p.k_fe2_w_s2_per_rad2 * 1e4 * KW_PER_W,
        fe15: p.k_fe15_w_per_rad15 * 1e3 * KW_PER_W,
        q_scale: n1 / libm::sqrt(q_max),
        w_scale: n1 / libm::sqrt(w_max),
        rc0,
        rc1,
        rc2,
        inv_v_case: 1.0 / (p.case_oil_m3 * L_PER_M3),
        inv_v_loop: 1.0 / (p.loop_oil_m3 * L_PER_M3),
        v_port: p.port_oil_m3 * L_PER_M3,
        v_ball: p.ball_oil_m3 * L_PER_M3,
        inv_v_ring: 1.0 / v_ring,
        f_out: p.mech_to_outlet,
        f_case: p.mech_to_case,
        k_m0: p.no_load_torque_nm * 100.0 * KW_PER_W,
        k_mv: p.viscous_w_s2_per_rad2 * 1e4 * KW_PER_W,
        alpha: p.expansion_per_k,
        g_case_slope: p.case_film_slope_per_k,
        alpha_t0: p.expansion_per_k * 273.15,
        lng_in: p.lng_inlet_c,
        pole_pairs: p.pole_pairs,
        drain_margin_k: p.drain_margin_k,
        inv_c,
        ga: p.outer_w_per_k.map(|x| x * KW_PER_W),
        gb: p.outer_quarter_w_per_k125.map(|x| x * KW_PER_W),
        // radiation 4 eps sigma A T_m^3 with T_m in units of 300 K (so the
        // coefficient keeps its resolution in fixed point)
        gr: p.outer_rad_w_per_k4.map(|x| x * (4.0 * RAD_T_K * RAD_T_K * RAD_T_K * KW_PER_W)),
        g_case: kw(&p.g_case_w_per_k),
        g_port: kw(&p.g_port_w_per_k),
        g_loop: kw(&p.g_loop_block_w_per_k),
        g_ball: kw(&p.g_ball_block_w_per_k),
        g_lng: kw(&p.g_lng_w_per_k),
        leak_ratio: p.leak_ratio,
        visc_ratio: p.visc_ratio,
        tc_speed: p.tc_speed_ratio,
        re_q: p.re_per_flow.map(|x| x / L_PER_M3),
        g_wall: p.duct_wall_w_per_k.map(|x| x * KW_PER_W),
        g_trans: {
            let mut t = [[0.0; N_RE * N_DUCTS]; N_COARSE];
            let films = p.duct_films();
            for (j, row) in t.iter_mut().enumerate() {
                for (o, col) in row.iter_mut().zip(films.iter().flatten()) {
                    *o = col.get(j).copied().unwrap_or(0.0) * KW_PER_W;
                }
            }
            t
        },
        rest_rate: p.rest_rate_per_s,
        rest_mode: p.rest_mode,
        phi: p.phi_step_s,
    };
    let mut ok = true;
    c.for_each(|x| ok &= x.is_finite() && libm::fabs(x) < MAX_ABS as f64);
    if ok {
        Ok(c)
    } else {
        Err(ConfigError::ConstantRange)
    }
}
