//! Step 6 of the reduction and the cooling bound: the nominal operating
//! point, the Jacobian of the reduced model there (from which the firmware
//! builds `Phi`) and the bound on cooling at rest (step 7, the comparison
//! theorem for cooperative systems). Separate because it works on the
//! finished parameters, not on the rig.

use super::FIT_AIR_C;
use eha_guard::model::{Model, ReducedParams, ModelInputN, HBAR_PER_BAR, HRADS_PER_RPM, N_NODES, N_PHI, N_STATES};
use eha_guard::params::PHI_STATES;

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
