//! The reduced model's number units and its constants in them: the
//! conversions from SI (hbar, L, kW, hA, hrad/s), the constants derived once
//! from [`super::ModelConsts`] ([`Consts`]), and the `1/n` tables of partial
//! model steps.

use crate::params::{N_DUCTS, N_OUTER, N_STATES, TICKS_PER_STEP};

/// Pa per hbar.
pub(super) const PA_PER_HBAR: f64 = 1e7;
/// L per m^3.
pub(super) const L_PER_M3: f64 = 1e3;
/// kW per W.
pub(super) const KW_PER_W: f64 = 1e-3;
/// Temperature unit of the radiation term's mean wall-air temperature, K.
pub(super) const RAD_T_K: f64 = 300.0;
/// Longest transport delay of the exchanger's effect, model steps (the history is a `u32`).
pub(super) const MAX_DELAY_STEPS: i32 = 31;

/// Constants in model units (built once).
#[derive(Clone, Copy, Debug)]
pub(super) struct Consts<N> {
    // tick: flows L/s, powers kW from hA, hbar, hrad/s, mm per tick
    pub(super) p_case: N,    // hbar
    pub(super) k_lf: N,      // leak flow, L/s per hbar
    pub(super) k_lp: N,      // leak power, kW per hbar^2
    pub(super) k_mech: N,    // kW per (hbar hrad/s)
    pub(super) k_q: N,       // pump flow, L/s per hrad/s
    pub(super) k_a: N,       // piston flow, L/s per mm/tick
    pub(super) k_dpq: N,     // kW per (hbar L/s)
    pub(super) r1: N,        // kW per (L/s)^2
    pub(super) r2: N,        // kW per (L/s)^3
    pub(super) w_dp: N,      // actuator heat weights: act = k_act (w_dp dp^2 + w_dx dx^2), kW
    pub(super) w_dx: N,
    pub(super) k_act: N,
    pub(super) k_lf_half: N, // k_lf / 2
    pub(super) k_cu: N,      // copper, kW per hA^2
    pub(super) k_sh: N,      // shaft power Kt I w, kW per (hA hrad/s)
    pub(super) k_hyd: N,     // hydraulic power D dp w, kW per (hbar hrad/s)
    pub(super) fe1: N,       // iron, kW per hrad/s
    pub(super) fe2: N,       // kW per (hrad/s)^2
    pub(super) fe15: N,      // kW per (hrad/s)^1.5
    // step
    pub(super) inv_ticks: N, // 1 / TICKS_PER_STEP
    pub(super) q_scale: N,   // (N_TABLE-1) / sqrt(q_max), per sqrt(L/s)
    pub(super) w_scale: N,   // (N_TABLE-1) / sqrt(w_max), per sqrt(hrad/s)
    pub(super) rc0: N,       // rho c_p at 0 degC, kJ/(L K)
    pub(super) rc1: N,       // d(rho c_p)/dT, kJ/(L K^2)
    pub(super) rc2: N,       // curvature of rho c_p, kJ/(L K^3)
    pub(super) inv_v_case: N, // 1/L
    pub(super) inv_v_loop: N, // 1/L
    pub(super) inv_n: [N; TICKS_PER_STEP as usize + 1], // 1/n for partial steps (inv_n[0] = 0)
    pub(super) count: [N; TICKS_PER_STEP as usize + 1], // n
    pub(super) v_port: N,    // L
    pub(super) v_ball: N,    // L
    pub(super) inv_v_ring: N, // 1 / (V_loop + 2 V_port + V_ball), 1/L
    pub(super) inv_c: [N; N_STATES], // 1/C of the metal states, K/kJ (oil nodes unused)
    pub(super) f_out: N,     // share of the viscous and pressure friction into the delivered oil
    pub(super) f_case: N,    // share into the case oil
    pub(super) k_m0: N,      // pump no-load friction, kW per hrad/s
    pub(super) k_mv: N,      // pump viscous friction at 40 degC, kW per (hrad/s)^2
    pub(super) alpha: N,     // oil expansion, 1/K
    pub(super) g_case_slope: N, // relative slope of the case film with the case-oil temperature, 1/K
    pub(super) t_film: N,    // FILM_PROPERTY_C, degC
    pub(super) alpha_t0: N,  // alpha 273.15
    pub(super) lng_in: N,    // degC
    pub(super) t_scale: N,   // 1 / TEMP_TABLE_STEP_K, 1/K
    pub(super) inv_stride: N, // 1 / COARSE_STRIDE
    pub(super) re_q: [N; N_DUCTS], // ducts' Re / 1e4 per L/s at 40 degC
    pub(super) g_wall: [N; 2], // walls behind the loop's and the ball passage's films, kW/K
    pub(super) re_lam: N,    // 0.23: Re = 2300, the end of the laminar range, / 1e4
    pub(super) inv_span: N,  // 1 / 0.77: the transition's width in Re / 1e4
    pub(super) re3: N,       // 3: Re = 3e4, / 1e4
    pub(super) inv_span3: N, // 1 / 7: from Re = 3e4 to 1e5, / 1e4
    pub(super) t_min: N,     // TEMP_TABLE_MIN_C, degC
    pub(super) tab_last: N,  // N_TABLE - 2 (the last interval's left point, grid units)
    pub(super) ga: [N; N_OUTER],   // outer, kW/K
    pub(super) gb: [N; N_OUTER],   // outer, kW/K^1.25
    pub(super) gr: [N; N_OUTER],   // outer radiation 4 eps sigma A (300 K)^3, kW/K per (T_m / 300 K)^3
    pub(super) h: N,         // s
    pub(super) inv_h: N,     // 1/s
    pub(super) half: N,
    pub(super) per_rad_t: N,   // 1 / 300 K
    pub(super) rad_offset: N,  // 273.15 / 300
    pub(super) one: N,
}

/// `1/n` for partial model steps of `n` ticks (`[0]` = 0), f64 and rounded to f32.
/// (Evaluated at compile time: an index out of range would fail the build.)
pub(super) const INV_N_F64: [f64; TICKS_PER_STEP as usize + 1] = inv_n_f64();
#[allow(clippy::indexing_slicing)]
pub(super) const INV_N_F32: [f32; TICKS_PER_STEP as usize + 1] = {
    let mut o = [0.0f32; TICKS_PER_STEP as usize + 1];
    let mut j = 0;
    while j < o.len() {
        o[j] = INV_N_F64[j] as f32;
        j += 1;
    }
    o
};

#[allow(clippy::indexing_slicing)]
const fn inv_n_f64() -> [f64; TICKS_PER_STEP as usize + 1] {
    let mut o = [0.0f64; TICKS_PER_STEP as usize + 1];
    let mut j = 1;
    while j < o.len() {
        o[j] = 1.0 / j as f64;
        j += 1;
    }
    o
}
