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
//!    on [`N_TABLE`] points uniform in `sqrt(q)`.
//! 5. **Outer surfaces** (eqs. 15, 16, 19): the free-convection coefficient of each
//!    surface fitted as `h = c0 + c1 |ΔT|^(1/4)` over ΔT ∈ [0.05, 100] K at 20 °C air
//!    ([`fit_free_convection`]); radiation `eps sigma A` exact, linearised in the
//!    firmware about the mean of wall and air. Ram air is not an input.
//! 6. **Discretisation**: the nominal Jacobian `A` of the reduced model itself at
//!    500 rpm, 30 bar, all nodes at 40 °C in 20 °C air, by central differences
//!    ([`nominal_jacobian`]); the firmware builds `Phi = h phi1(h A)` from it.

use crate::heat;
use crate::network::{self, Shape};
use crate::rig::Rig;
use eha_guard::model::{Model, ReducedParams, ModelInputN, HBAR_PER_BAR, HRADS_PER_RPM, N_NODES, N_OUTER, N_PHI, N_STATES, N_TABLE, N_TEMP};
use eha_guard::params::{COARSE_STRIDE, N_COARSE, PHI_STATES, TEMP_TABLE_MIN_C, TEMP_TABLE_STEP_K};
use std::f64::consts::PI;

/// Shaft speed of the last table point, rpm (the guard's speed range limit).
pub const TABLE_MAX_RPM: f64 = 6000.0;
pub use eha_guard::params::FILM_PROPERTY_C;
/// Air temperature of the free-convection fit, °C.
pub const FIT_AIR_C: f64 = 20.0;

/// Grid point `j` of a table ending at `x_max`: `x_max (j / (N_TABLE - 1))^2`.
pub fn grid(x_max: f64, j: usize) -> f64 {
    let u = j as f64 / (N_TABLE - 1) as f64;
    x_max * u * u
}

fn table(x_max: f64, f: impl Fn(f64) -> f64) -> [f64; N_TABLE] {
    let mut t = [0.0; N_TABLE];
    for (j, v) in t.iter_mut().enumerate() {
        *v = f(grid(x_max, j));
    }
    t
}

/// Least-squares fit of `h(ΔT) = c0 + c1 ΔT^(1/4)` to a free-convection law over
/// ΔT ∈ [0.05, 100] K (log-spaced) at [`FIT_AIR_C`]; returns `(c0, c1)` with
/// `c0 >= 0` (refitted as `c1 ΔT^(1/4)` alone when the two-term fit gives `c0 < 0`).
pub fn fit_free_convection(h: impl Fn(f64) -> f64) -> (f64, f64) {
    let (mut s11, mut s12, mut s22, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut dt = 0.05;
    while dt <= 100.0 {
        let y = h(dt);
        let x = dt.powf(0.25);
        s11 += 1.0;
        s12 += x;
        s22 += x * x;
        b1 += y;
        b2 += y * x;
        dt *= 1.05;
    }
    let det = s11 * s22 - s12 * s12;
    let c0 = (b1 * s22 - b2 * s12) / det;
    if c0 >= 0.0 {
        (c0, (s11 * b2 - s12 * b1) / det)
    } else {
        // h must stay positive down to dT -> 0: the one-term law c1 dT^(1/4)
        (0.0, b2 / s22)
    }
}

/// Temperature of point `j` of the tables over temperature, degC.
pub fn temp_grid(j: usize) -> f64 {
    TEMP_TABLE_MIN_C + TEMP_TABLE_STEP_K * j as f64
}

fn temp_table(f: impl Fn(f64) -> f64) -> [f64; N_TEMP] {
    let mut t = [0.0; N_TEMP];
    for (j, v) in t.iter_mut().enumerate() {
        *v = f(temp_grid(j));
    }
    t
}

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

/// Nominal operating point of the Jacobian: 500 rpm, 30 bar across the pump
/// (port A 35 bar, B at the 5 bar case pressure), no piston motion, 20 °C air.
pub fn nominal_input() -> ModelInputN<f64> {
    ModelInputN {
        current_ha: 0.0,
        p_a_hbar: 35.0 * HBAR_PER_BAR,
        p_b_hbar: 5.0 * HBAR_PER_BAR,
        speed_hrads: 500.0 * HRADS_PER_RPM,
        dpos_mm: 0.0,
        ambient_c: FIT_AIR_C,
    }
}

/// Jacobian of the reduced model's right-hand side at [`nominal_input`] with every
/// state at 40 °C over the states of `Phi`, 1/s: central differences of ±2 K, the
/// steps of the firmware's own check of `Phi` (`model::stability`), so that the two
/// agree where the tables over temperature have a point at 40 °C (a kink: a
/// tangent there is not defined, a secant over ±2 K is).
pub fn nominal_jacobian(p: &ReducedParams) -> Option<[[f64; N_PHI]; N_PHI]> {
    let model = Model::<f64>::for_linearisation(&eha_guard::model::consts::derive(p).ok()?).ok()?;
    let u = nominal_input();
    let t0 = [40.0; N_STATES];
    let h = 2.0;
    let mut a = [[0.0; N_PHI]; N_PHI];
    for (j, &sj) in PHI_STATES.iter().enumerate() {
        let (mut tp, mut tm) = (t0, t0);
        tp[sj] += h;
        tm[sj] -= h;
        let fp = model.derivative(&tp, &u, false);
        let fm = model.derivative(&tm, &u, false);
        for (i, &si) in PHI_STATES.iter().enumerate() {
            a[i][j] = (fp[si] - fm[si]) / (2.0 * h);
        }
    }
    Some(a)
}

/// Air temperatures at which the rest cooling bound is checked, °C: the
/// radiation's slope and the oil's `rho c_p` (the oil nodes' capacity) vary
/// with temperature; the bound's rate is the slowest over these (the
/// coldest air, -55 °C, has the weakest radiation).
pub const REST_AIR_C: [f64; 4] = [-55.0, 0.0, 20.0, 70.0];

/// Cooling bound at rest (step 7, [`ReducedParams::rest_rate_per_s`]): the
/// firmware model's Jacobian with the pump stopped and no power (ports at the
/// case pressure), every node at the air temperature (the outer free
/// convection `c1 |dT|^(5/4)` has zero slope there: its linear part `c0` only)
/// and the radiation at its slope at the air temperature (`T^4` is convex:
/// the tangent at the air is below the chord); negative off-diagonals
/// (numerical noise) raised to 0. That matrix `J` is Metzler and, node by
/// node, cools no faster than the model does at any temperature above the air
/// (the left-out curvature only adds cooling), so by the comparison theorem
/// for cooperative systems the model's excess over the air stays below
/// `c v e^(-r t)` once it starts below `c v` (`v > 0`, `J v <= -r v`). Nodes
/// that exchange no heat at rest (any air temperature) form separate groups,
/// each with its own `v` (Perron vector, max 1) and rate
/// `r = min_i -(J v)_i / v_i` over the group's rows and over [`REST_AIR_C`].
/// `None` if the bound does not exist (no positive `v` or no decay).
pub fn rest_cooling(p: &ReducedParams) -> Option<([f64; N_NODES], [f64; N_NODES])> {
    let c = eha_guard::model::consts::derive(p).ok()?;
    let model = Model::<f64>::for_linearisation(&c).ok()?;
    let jac = |air: f64| {
        let u = ModelInputN { current_ha: 0.0, p_a_hbar: c.p_case, p_b_hbar: c.p_case, speed_hrads: 0.0, dpos_mm: 0.0, ambient_c: air };
        let h = 1e-3;
        let mut a = [[0.0; N_STATES]; N_STATES];
        for j in 0..N_STATES {
            let (mut tp, mut tm) = ([air; N_STATES], [air; N_STATES]);
            tp[j] += h;
            tm[j] -= h;
            let (fp, fm) = (model.derivative(&tp, &u, false), model.derivative(&tm, &u, false));
            for i in 0..N_STATES {
                let d = (fp[i] - fm[i]) / (2.0 * h);
                a[i][j] = if i != j { d.max(0.0) } else { d };
            }
        }
        a
    };
    let jacs = REST_AIR_C.map(jac);
    let group = coupled_groups(&jacs);
    let v = perron_by_group(&jac(FIT_AIR_C), &group)?;
    let mut rate = [f64::INFINITY; N_STATES];
    for a in &jacs {
        for i in 0..N_STATES {
            let r = -(0..N_STATES).map(|k| a[i][k] * v[k]).sum::<f64>() / v[i];
            for k in 0..N_STATES {
                if group[k] == group[i] {
                    rate[k] = rate[k].min(r);
                }
            }
        }
    }
    let (mut r6, mut v6) = ([0.0; N_NODES], [0.0; N_NODES]);
    r6.copy_from_slice(&rate[..N_NODES]);
    v6.copy_from_slice(&v[..N_NODES]);
    rate.iter().all(|r| *r > 0.0 && r.is_finite()).then_some((r6, v6))
}

/// Group index of each node: nodes joined by a coupling in any of `jacs`
/// (couplings below 1e-9 of the largest diagonal are difference noise).
fn coupled_groups(jacs: &[[[f64; N_STATES]; N_STATES]]) -> [usize; N_STATES] {
    let tol = 1e-9 * jacs.iter().flat_map(|a| (0..N_STATES).map(move |i| a[i][i].abs())).fold(0.0, f64::max);
    let linked = |i: usize, k: usize| jacs.iter().any(|a| a[i][k] > tol || a[k][i] > tol);
    let mut group = [usize::MAX; N_STATES];
    for start in 0..N_STATES {
        if group[start] != usize::MAX {
            continue;
        }
        let mut stack = vec![start];
        group[start] = start;
        while let Some(i) = stack.pop() {
            for (k, g) in group.iter_mut().enumerate() {
                if *g == usize::MAX && linked(i, k) {
                    *g = start;
                    stack.push(k);
                }
            }
        }
    }
    group
}

/// The Perron vector of `a` within each group (power iteration on
/// `I + dt a` by squaring), max 1 in each group; `None` unless every entry
/// is positive. One vector for groups that exchange no heat would give the
/// slower group's nodes all the weight and the other's none.
fn perron_by_group(a: &[[f64; N_STATES]; N_STATES], group: &[usize; N_STATES]) -> Option<[f64; N_STATES]> {
    let mut v = [0.0; N_STATES];
    for g in 0..N_STATES {
        let idx: Vec<usize> = (0..N_STATES).filter(|i| group[*i] == g).collect();
        if idx.is_empty() {
            continue;
        }
        let n = idx.len();
        let dt = 0.5 / idx.iter().map(|i| a[*i][*i].abs()).fold(1e-12, f64::max);
        let mut m: Vec<Vec<f64>> = idx.iter().map(|i| idx.iter().map(|k| dt * a[*i][*k] + if i == k { 1.0 } else { 0.0 }).collect()).collect();
        for _ in 0..60 {
            let sq: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|k| (0..n).map(|l| m[i][l] * m[l][k]).sum()).collect()).collect();
            let top = sq.iter().flatten().fold(0.0, |x: f64, y| x.max(y.abs()));
            if !(top > 0.0 && top.is_finite()) {
                return None;
            }
            m = sq.into_iter().map(|r| r.into_iter().map(|x| x / top).collect()).collect();
        }
        let sums: Vec<f64> = m.iter().map(|r| r.iter().sum()).collect();
        let top = sums.iter().fold(0.0, |x: f64, y| x.max(*y));
        for (i, s) in idx.iter().zip(&sums) {
            v[*i] = s / top;
        }
    }
    v.iter().all(|x| *x > 1e-6 && *x <= 1.0).then_some(v)
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

fn lit(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

fn row(r: &[f64]) -> String {
    format!("[{}]", r.iter().map(|x| lit(*x)).collect::<Vec<_>>().join(", "))
}

/// The scalar fields of `p` by name, in `DEFAULT`'s order (the renderer writes
/// them; the acceptance test compares them with the reduction).
pub fn scalar_fields(p: &ReducedParams) -> [(&'static str, f64); 38] {
    [
        ("pump_j_per_k", p.pump_j_per_k),
        ("main_block_j_per_k", p.main_block_j_per_k),
        ("ball_block_j_per_k", p.ball_block_j_per_k),
        ("actuator_j_per_k", p.actuator_j_per_k),
        ("case_oil_m3", p.case_oil_m3),
        ("loop_oil_m3", p.loop_oil_m3),
        ("port_oil_m3", p.port_oil_m3),
        ("ball_oil_m3", p.ball_oil_m3),
        ("rho_kg_per_m3", p.rho_kg_per_m3),
        ("rho_slope_kg_per_m3_k", p.rho_slope_kg_per_m3_k),
        ("cp20_j_per_kg_k", p.cp20_j_per_kg_k),
        ("cp_slope_j_per_kg_k2", p.cp_slope_j_per_kg_k2),
        ("displacement_m3_per_rad", p.displacement_m3_per_rad),
        ("eta_m", p.eta_m),
        ("no_load_torque_nm", p.no_load_torque_nm),
        ("viscous_w_s2_per_rad2", p.viscous_w_s2_per_rad2),
        ("mech_to_outlet", p.mech_to_outlet),
        ("mech_to_case", p.mech_to_case),
        ("case_film_slope_per_k", p.case_film_slope_per_k),
        ("expansion_per_k", p.expansion_per_k),
        ("k_leak_m3_per_s_pa", p.k_leak_m3_per_s_pa),
        ("case_pressure_pa", p.case_pressure_pa),
        ("line_r1_pa_s_per_m3", p.line_r1_pa_s_per_m3),
        ("line_r2_pa_s2_per_m6", p.line_r2_pa_s2_per_m6),
        ("ram_area_m2", p.ram_area_m2),
        ("act_leak_m3_per_s_pa", p.act_leak_m3_per_s_pa),
        ("act_friction_n_s_per_m", p.act_friction_n_s_per_m),
        ("phases", p.phases),
        ("r_ohm", p.r_ohm),
        ("torque_constant_nm_per_a", p.torque_constant_nm_per_a),
        ("pole_pairs", p.pole_pairs),
        ("k_fe1_w_s_per_rad", p.k_fe1_w_s_per_rad),
        ("k_fe2_w_s2_per_rad2", p.k_fe2_w_s2_per_rad2),
        ("k_fe15_w_per_rad15", p.k_fe15_w_per_rad15),
        ("speed_table_max_rad_s", p.speed_table_max_rad_s),
        ("flow_table_max_m3_per_s", p.flow_table_max_m3_per_s),
        ("lng_inlet_c", p.lng_inlet_c),
        ("drain_margin_k", p.drain_margin_k),
    ]
}

/// The table and array fields of `p` by name, in `DEFAULT`'s order.
pub fn array_fields(p: &ReducedParams) -> [(&'static str, &[f64]); 25] {
    [
        ("g_case_w_per_k", &p.g_case_w_per_k),
        ("leak_ratio", &p.leak_ratio),
        ("visc_ratio", &p.visc_ratio),
        ("tc_speed_ratio", &p.tc_speed_ratio),
        ("re_per_flow", &p.re_per_flow),
        ("duct_wall_w_per_k", &p.duct_wall_w_per_k),
        ("g_port_re2300_w_per_k", &p.g_port_re2300_w_per_k),
        ("g_port_re1e4_w_per_k", &p.g_port_re1e4_w_per_k),
        ("g_port_re3e4_w_per_k", &p.g_port_re3e4_w_per_k),
        ("g_port_re1e5_w_per_k", &p.g_port_re1e5_w_per_k),
        ("g_loop_re2300_w_per_k", &p.g_loop_re2300_w_per_k),
        ("g_loop_re1e4_w_per_k", &p.g_loop_re1e4_w_per_k),
        ("g_loop_re3e4_w_per_k", &p.g_loop_re3e4_w_per_k),
        ("g_loop_re1e5_w_per_k", &p.g_loop_re1e5_w_per_k),
        ("g_ball_re2300_w_per_k", &p.g_ball_re2300_w_per_k),
        ("g_ball_re1e4_w_per_k", &p.g_ball_re1e4_w_per_k),
        ("g_ball_re3e4_w_per_k", &p.g_ball_re3e4_w_per_k),
        ("g_ball_re1e5_w_per_k", &p.g_ball_re1e5_w_per_k),
        ("g_port_w_per_k", &p.g_port_w_per_k),
        ("g_loop_block_w_per_k", &p.g_loop_block_w_per_k),
        ("g_ball_block_w_per_k", &p.g_ball_block_w_per_k),
        ("g_lng_w_per_k", &p.g_lng_w_per_k),
        ("outer_w_per_k", &p.outer_w_per_k),
        ("outer_quarter_w_per_k125", &p.outer_quarter_w_per_k125),
        ("outer_rad_w_per_k4", &p.outer_rad_w_per_k4),
    ]
}

/// The `DEFAULT` constant of `src/params.rs` (doc comment and item) for `p`.
pub fn render_params_rs(p: &ReducedParams) -> String {
    let mut s = String::new();
    s.push_str("/// Default parameters, reduced from the reference rig `Rig::default()` by\n");
    s.push_str("/// `eha_sim::reduce` (docs/reduction.md): nothing is fitted to simulation output.\n");
    s.push_str("/// THIS CONSTANT IS REGENERATED BY `cargo run --release -p eha-sim --example reduce`:\n");
    s.push_str("/// keep plain literals.\n");
    s.push_str("pub const DEFAULT: ReducedParams = ReducedParams {\n");
    for (name, v) in scalar_fields(p) {
        s.push_str(&format!("    {name}: {},\n", lit(v)));
    }
    for (name, t) in array_fields(p) {
        s.push_str(&format!("    {name}: {},\n", row(t)));
    }
    s.push_str("    nominal_jacobian_per_s: [\n");
    for r in &p.nominal_jacobian_per_s {
        s.push_str(&format!("        {},\n", row(r)));
    }
    s.push_str("    ],\n");
    s.push_str("    phi_step_s: [\n");
    for r in &p.phi_step_s {
        s.push_str(&format!("        {},\n", row(r)));
    }
    s.push_str("    ],\n");
    s.push_str(&format!("    rest_rate_per_s: {},\n", row(&p.rest_rate_per_s)));
    s.push_str(&format!("    rest_mode: {},\n", row(&p.rest_mode)));
    s.push_str("};\n");
    s
}

/// The whole text of `src/model/default_consts.rs`: `DEFAULT_CONSTS`, the model
/// constants of `p` in model units as `f32` words (the compiled-in parameter
/// block of the firmware), `Err` if the firmware model rejects `p`.
pub fn render_default_consts_rs(p: &ReducedParams) -> Result<String, eha_guard::model::ConfigError> {
    let c = eha_guard::model::consts::derive(p)?.to_f32();
    eha_guard::model::Model::<f32>::from_consts(&c)?;
    let mut s = String::new();
    s.push_str("//! The compiled-in model constants: `crate::params::DEFAULT` in model units,\n");
    s.push_str("//! `f32` words (`model::consts::derive(&DEFAULT)?.to_f32()`), so that the\n");
    s.push_str("//! firmware needs no `f64` arithmetic. GENERATED by\n");
    s.push_str("//! `cargo run --release -p eha-sim --example reduce`; a test checks it against\n");
    s.push_str("//! `DEFAULT` bit for bit.\n\n");
    s.push_str("use crate::model::ModelConsts;\n\n");
    s.push_str("/// Model constants of [`crate::params::DEFAULT`] (the paper rig), `f32` words.\n");
    s.push_str(&format!("pub const DEFAULT_CONSTS: ModelConsts<f32> = {c:#?};\n"));
    Ok(s)
}

/// Replaces the `DEFAULT` item (from its doc comment to the closing `};`) in the
/// text of `src/params.rs` with `rendered`. `None` if the item is not found.
pub fn splice_params_rs(file: &str, rendered: &str) -> Option<String> {
    let item = file.find("pub const DEFAULT: ReducedParams")?;
    let mut start = item;
    let mut lines: Vec<&str> = file[..item].split_inclusive('\n').collect();
    while let Some(l) = lines.last() {
        if l.trim_start().starts_with("///") {
            start -= l.len();
            lines.pop();
        } else {
            break;
        }
    }
    let end = item + file[item..].find("\n};\n")? + 4;
    Some(format!("{}{}{}", &file[..start], rendered, &file[end..]))
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
