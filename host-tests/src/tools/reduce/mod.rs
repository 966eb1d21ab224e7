//! Reduction of the reference model to the firmware's reduced-order model
//! ([`eha_guard::model::ReducedParams`]): every parameter is computed from the rig, none
//! is fitted (docs/reduction.md).
//!
//! 1. **States.** The reference's 12 thermal nodes: the motor's winding and
//!    housing have no thermal path to the pump side (the `motor-pump-conduction`
//!    extension is off in the baseline), so they leave the state; the inlet and
//!    outlet port passages, the ball-valve oil and the sensor pocket (≤ 0.085 kJ/K
//!    against ≈ 0.26 kW/K of circulation, time constants ≈ 0.3 s) become
//!    quasi-steady links of the oil ring. Six states remain: pump housing, case
//!    (drain) oil, loop oil, main block, ball-valve block, actuator body.
//! 2. **Capacities** from the rig's masses and specific heats; the oil's from its
//!    volumes with `rho c_p(T)` evaluated in the firmware.
//! 3. **Losses** (eqs. 1-11): the same coefficients as the reference (gap
//!    conductance at 40 °C, `eta_m`, the outlet share, the throttle path's laminar and
//!    local resistances, the actuator's leakage and seal friction, R, iron terms).
//! 4. **Conductances** (eqs. 12-14, 18, 20-22): the reference's correlations with
//!    oil properties at 40 °C, tabulated over flow (or shaft speed for the case oil)
//!    on [`N_TABLE`](eha_guard::model::N_TABLE) points uniform in `sqrt(q)`.
//! 5. **Outer surfaces** (eqs. 15, 16, 19): the free-convection coefficient of each
//!    surface fitted as `h = c0 + c1 |ΔT|^(1/4)` over ΔT ∈ [0.05, 100] K at 20 °C air
//!    ([`fit_free_convection`]); radiation `eps sigma A` exact, linearised in the
//!    firmware about the mean of wall and air. Ram air is not an input.
//! 6. **Discretisation**: the nominal Jacobian `A` of the reduced model itself at
//!    500 rpm, 30 bar, all nodes at 40 °C in 20 °C air, by central differences
//!    ([`nominal_jacobian`]); the firmware builds `Phi = h phi1(h A)` from it.
//!
//! This file holds steps 1-5 ([`reduce_without_jacobian`]) and the whole
//! reduction; by topic beside it: `tables.rs` (the grids over flow and
//! temperature, the free-convection fit), `jacobian.rs` (step 6's nominal
//! Jacobian and the rest cooling bound) and `render.rs` (the parameter
//! block as Rust source).

mod jacobian;
mod render;
mod tables;

pub use jacobian::{nominal_input, nominal_jacobian, rest_cooling, REST_AIR_C};
pub use render::{array_fields, render_default_consts_rs, render_params_rs, scalar_fields, splice_params_rs};
pub use tables::{fit_free_convection, grid, temp_grid};
use tables::{table, temp_table};

use crate::heat;
use crate::network::{self, Shape};
use crate::rig::Rig;
use eha_guard::model::{Model, ReducedParams, N_NODES, N_OUTER, N_PHI};
use eha_guard::params::{COARSE_STRIDE, N_COARSE};
use std::f64::consts::PI;

/// Shaft speed of the last table point, rpm (the guard's speed range limit).
pub const TABLE_MAX_RPM: f64 = 6000.0;
pub use eha_guard::params::FILM_PROPERTY_C;
/// Air temperature of the free-convection fit, °C.
pub const FIT_AIR_C: f64 = 20.0;

/// The reduced parameters of `rig` (steps 1-5); the Jacobian is left at zero.
pub fn reduce_without_jacobian(rig: &Rig) -> ReducedParams {
    let oil = &rig.oil;
    let p = &rig.pump;
    let b = &rig.blocks;
    let a = &rig.actuator;
    let m = &rig.motor;
    let ms = rig.nuisance.metal_capacity_scale;
    let t40 = FILM_PROPERTY_C;
    let rho = oil.rho(t40, 0.0) * rig.nuisance.oil_capacity_scale;
    let rho_slope = (oil.rho(t40 + 1.0, 0.0) - oil.rho(t40 - 1.0, 0.0)) / 2.0 * rig.nuisance.oil_capacity_scale;
    let nu = oil.nu_m2_per_s(t40);
    let d = rig.displacement_m3_per_rad();
    let w_max = TABLE_MAX_RPM * PI / 30.0;
    let q_max = d * w_max;
    let duct = |q: f64, dd: f64, len: f64, scale: f64| network::duct_conductance(rig, q, dd, len, scale, t40, nu);
    // the case gap (Taylor-Couette): Nu depends on the Taylor number (w / nu)^2 only, so
    // the table over speed at 40 degC read at w nu(40)/nu(T) is exact in nu; its k(T)
    // by the relative slope below
    let g_case = table(w_max, |w| network::case_film_w_per_k(rig, w, t40, nu));
    let w_nom = 500.0 * PI / 30.0;
    let gc = |t: f64| network::case_film_w_per_k(rig, w_nom, t, nu);
    let case_film_slope = (gc(t40 + 1.0) - gc(t40 - 1.0)) / (2.0 * gc(t40));
    let g_port = table(q_max, |q| duct(q, p.port_d_m, p.port_len_m, p.port_area_scale));
    let g_loop = table(q_max, |q| network::block_path(rig, duct(q, b.loop_d_m, b.loop_len_m, b.loop_area_scale), b.main_area_m2));
    let g_ball = table(q_max, |q| network::block_path(rig, duct(q, b.ball_d_m, b.ball_len_m, 1.0), b.ball_area_m2));
    // the ducts' transition (eqs. 13-14 blended) on the coarse temperature grid: the
    // laminar table's law at Re = 2300 and the film at Re = 1e4 with the oil's
    // properties at that temperature; Re per flow at 40 degC
    let ducts = [
        (p.port_d_m, p.port_len_m, p.port_area_scale, None),
        (b.loop_d_m, b.loop_len_m, b.loop_area_scale, Some(b.main_area_m2)),
        (b.ball_d_m, b.ball_len_m, 1.0, Some(b.ball_area_m2)),
    ];
    let re_per_flow = ducts.map(|(dd, _, _, _)| 4.0 / (PI * dd * nu) / 1e4);
    // the films alone: the firmware blends them and puts the block wall in series after
    let wall = |g: f64, _block: Option<f64>| g;
    let wall_of = |area: f64| heat::g_plane_wall(b.steel_k, (area / 6.0).sqrt(), b.wall_m);
    let duct_wall_w_per_k = [wall_of(b.main_area_m2), wall_of(b.ball_area_m2)];
    let coarse = |f: &dyn Fn(f64) -> f64| {
        let mut t = [0.0; N_COARSE];
        for (j, v) in t.iter_mut().enumerate() {
            *v = f(temp_grid(j * COARSE_STRIDE));
        }
        t
    };
    let re2300 = |k: usize| {
        let (dd, len, sc, block) = ducts[k];
        coarse(&|t| wall(duct(2300.0 * PI * dd * oil.nu_m2_per_s(t) / 4.0, dd, len, sc), block))
    };
    // the turbulent anchors (Re = 1e4, 3e4, 1e5) with the oil's properties at T
    let re_turb = |k: usize, re: f64| {
        let (dd, len, sc, block) = ducts[k];
        coarse(&|t| {
            let nu_t = oil.nu_m2_per_s(t);
            wall(network::duct_conductance(rig, re * PI * dd * nu_t / 4.0, dd, len, sc, t, nu_t), block)
        })
    };
    let rho_cp40 = rho * oil.cp(t40);
    let t_ref = 100.0;
    let g_lng = table(q_max, |q| rig.lng.exchanger_w(rho_cp40 * q, t_ref) / (t_ref - rig.lng.inlet_c));
    // the oil's viscosity line: leakage conductance ∝ 1/mu, viscous friction ∝ mu,
    // the gap's Taylor number ∝ 1/nu^2
    let mu40 = oil.mu_pa_s(t40);
    let leak_ratio = temp_table(|t| mu40 / oil.mu_pa_s(t));
    let visc_ratio = temp_table(|t| oil.mu_pa_s(t) / mu40);
    let tc_speed_ratio = temp_table(|t| nu / oil.nu_m2_per_s(t));
    // outer surfaces of the pump, main block, ball block, actuator
    let side = |area: f64| (area / 6.0).sqrt();
    let surfaces = [
        (p.area_m2, Shape::Cylinder(p.diameter_m)),
        (b.main_area_m2, Shape::Cube(side(b.main_area_m2))),
        (b.ball_area_m2, Shape::Cube(side(b.ball_area_m2))),
        (a.area_m2, Shape::Cylinder(a.diameter_m)),
    ];
    let mut outer_w_per_k = [0.0; N_OUTER];
    let mut outer_quarter = [0.0; N_OUTER];
    let mut outer_rad = [0.0; N_OUTER];
    let os = rig.nuisance.outer_scale;
    for (i, (area, shape)) in surfaces.iter().enumerate() {
        let (c0, c1) = fit_free_convection(|dt| network::h_outer(rig, *shape, FIT_AIR_C + dt, FIT_AIR_C, 0.0));
        outer_w_per_k[i] = c0 * area * os;
        outer_quarter[i] = c1 * area * os;
        outer_rad[i] = heat::SIGMA_W_PER_M2_K4 * rig.outside.emissivity * area * os;
    }
    // the main block's bench mounting (to a bench at the air temperature) is a
    // constant conductance like free convection's c0 term
    outer_w_per_k[1] += b.mount_w_per_k;
    let line = &rig.hydraulics.path;
    let la = line.area_m2();
    let fe = &m.iron;
    let c = fe.pole_pairs / (2.0 * PI);
    ReducedParams {
        pump_j_per_k: p.mass_kg * ms * p.cp,
        main_block_j_per_k: b.main_mass_kg * ms * b.cp,
        ball_block_j_per_k: b.ball_mass_kg * ms * b.cp,
        actuator_j_per_k: a.body_mass_kg * ms * a.body_cp,
        case_oil_m3: p.case_oil_m3,
        loop_oil_m3: b.loop_oil_m3 + b.sensor_oil_m3,
        port_oil_m3: p.port_oil_m3,
        ball_oil_m3: b.ball_oil_m3,
        rho_kg_per_m3: rho,
        rho_slope_kg_per_m3_k: rho_slope,
        cp20_j_per_kg_k: oil.cp20_j_per_kg_k,
        cp_slope_j_per_kg_k2: oil.cp_slope_j_per_kg_k2,
        displacement_m3_per_rad: d,
        eta_m: p.eta_m,
        no_load_torque_nm: p.no_load_torque_nm,
        viscous_w_s2_per_rad2: p.viscous_torque_coeff * mu40 * d,
        mech_to_outlet: p.friction_pairs.shares().0,
        mech_to_case: p.friction_pairs.shares().1,
        case_film_slope_per_k: case_film_slope,
        expansion_per_k: oil.expansion_per_k,
        k_leak_m3_per_s_pa: p.gaps.conductance(mu40),
        case_pressure_pa: rig.hydraulics.accumulator_pa,
        line_r1_pa_s_per_m3: 128.0 * nu * rho * line.length_m / (PI * line.diameter_m.powi(4)),
        line_r2_pa_s2_per_m6: rho * line.local_loss_coeff / (2.0 * la * la),
        ram_area_m2: a.ram_area_m2,
        act_leak_m3_per_s_pa: a.leak_m3_per_s_pa,
        act_friction_n_s_per_m: a.viscous_friction_n_s_per_m,
        phases: m.phases,
        r_ohm: m.r25_ohm,
        torque_constant_nm_per_a: m.torque_constant_nm_per_a,
        pole_pairs: fe.pole_pairs,
        k_fe1_w_s_per_rad: fe.k_h * fe.b_peak_t * fe.b_peak_t * c,
        k_fe2_w_s2_per_rad2: fe.k_c * fe.b_peak_t * fe.b_peak_t * c * c,
        k_fe15_w_per_rad15: fe.k_e * (fe.b_peak_t * c).powf(1.5),
        speed_table_max_rad_s: w_max,
        flow_table_max_m3_per_s: q_max,
        g_case_w_per_k: g_case,
        leak_ratio,
        visc_ratio,
        tc_speed_ratio,
        re_per_flow,
        duct_wall_w_per_k,
        g_port_re2300_w_per_k: re2300(0),
        g_port_re1e4_w_per_k: re_turb(0, 1e4),
        g_port_re3e4_w_per_k: re_turb(0, 3e4),
        g_port_re1e5_w_per_k: re_turb(0, 1e5),
        g_loop_re2300_w_per_k: re2300(1),
        g_loop_re1e4_w_per_k: re_turb(1, 1e4),
        g_loop_re3e4_w_per_k: re_turb(1, 3e4),
        g_loop_re1e5_w_per_k: re_turb(1, 1e5),
        g_ball_re2300_w_per_k: re2300(2),
        g_ball_re1e4_w_per_k: re_turb(2, 1e4),
        g_ball_re3e4_w_per_k: re_turb(2, 3e4),
        g_ball_re1e5_w_per_k: re_turb(2, 1e5),
        g_port_w_per_k: g_port,
        g_loop_block_w_per_k: g_loop,
        g_ball_block_w_per_k: g_ball,
        g_lng_w_per_k: g_lng,
        lng_inlet_c: rig.lng.inlet_c,
        outer_w_per_k,
        outer_quarter_w_per_k125: outer_quarter,
        outer_rad_w_per_k4: outer_rad,
        nominal_jacobian_per_s: [[0.0; N_PHI]; N_PHI],
        phi_step_s: eha_guard::model::etd_matrix(&[[0.0; N_PHI]; N_PHI], eha_guard::params::S_PER_STEP),
        rest_rate_per_s: [0.0; N_NODES],
        rest_mode: [0.0; N_NODES],
        // a rig file has no validation logs: commissioning sets the margin
        drain_margin_k: 0.0,
    }
}

/// Why the firmware's six-state model cannot carry `rig`'s structure, or
/// `None` when it can: the optional pump-as-built structure
/// ([`crate::rig::Pump::split`], [`Rig::joints`]). The parameter block has no
/// word for it; the words it would need are named.
pub fn unsupported_structure(rig: &Rig) -> Option<&'static str> {
    if rig.joints.is_some() {
        Some(
            "the rig has metal joints from the pump housing (`joints`: pump → motor flange, pump → manifold/main block); \
             the firmware's six states have no conductance between the pump housing and the motor or the main block. \
             It would need two parameter-block words, `g_pump_motor_w_per_k` and `g_pump_main_block_w_per_k` \
             (f32, W/K, a conduction link in the pump and main-block (and motor) heat balances), in a new block format version",
        )
    } else if rig.pump.split.is_some() {
        Some(
            "the rig splits the pump into internals and housing (`pump.split`); the firmware's six states have one pump node",
        )
    } else {
        None
    }
}

/// The whole reduction (steps 1-6). `None` if the rig gives parameters the firmware
/// model rejects, or has a structure the six states do not carry
/// ([`unsupported_structure`] says which).
pub fn reduce(rig: &Rig) -> Option<ReducedParams> {
    if unsupported_structure(rig).is_some() {
        return None;
    }
    let p = rediscretise(&reduce_without_jacobian(rig))?;
    Model::<f64>::new(&p).ok()?;
    Some(p)
}

/// `p` with its nominal Jacobian and `Phi` (re)computed (step 6; also after
/// changing physical parameters by hand); `None` if the firmware model
/// rejects `p`.
pub fn rediscretise(p: &ReducedParams) -> Option<ReducedParams> {
    let mut q = *p;
    q.nominal_jacobian_per_s = nominal_jacobian(&q)?;
    q.phi_step_s = eha_guard::model::etd_matrix(&q.nominal_jacobian_per_s, eha_guard::params::S_PER_STEP);
    (q.rest_rate_per_s, q.rest_mode) = rest_cooling(&q)?;
    Some(q)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rig with the pump's metal joints is refused with the reason and the
    /// parameter-block words it would need; the split pump alone with its
    /// own reason; the rig file and the calibration's block wall (an
    /// existing word) reduce.
    #[test]
    fn joints_are_refused_with_the_words_they_need() {
        let rig = Rig::default();
        assert!(unsupported_structure(&rig).is_none());
        let mut walled = rig.clone();
        walled.blocks.wall_m /= 50.0;
        assert!(reduce(&walled).is_some(), "the block wall is carried by duct_wall_w_per_k");
        let built = rig.clone().with_pump_as_built();
        let why = unsupported_structure(&built).expect("joints refused");
        assert!(why.contains("g_pump_main_block_w_per_k") && why.contains("g_pump_motor_w_per_k"), "{why}");
        assert!(reduce(&built).is_none());
        let mut split = built.clone();
        split.joints = None;
        assert!(unsupported_structure(&split).is_some_and(|w| w.contains("pump.split")));
    }
}
