//! Thermal equilibrium of the reference model at a held operating point:
//! where a long run is heading (so that runs beyond 600 s are checked too).
//!
//! The hydraulic state is frozen at the given instant and the twelve node
//! temperatures are solved for zero net heat flow by Newton's method with a
//! forward-difference Jacobian (the node balances are smooth; convection and
//! radiation are the only strong non-linearities).

use crate::model::{Model, T0};
use crate::network::N_NODES;
use nalgebra::{DMatrix, DVector};

/// Net heat-flow rates dT/dt (K/s) of the nodes at temperatures `temps`,
/// with the hydraulic part of the state `y` held and time `t`.
fn rates(model: &Model, t: f64, y: &[f64], temps: &[f64]) -> Vec<f64> {
    let mut yy = y.to_vec();
    yy[T0..T0 + N_NODES].copy_from_slice(temps);
    let op = model.op_point(t, &yy);
    let l = model.losses(t, &op, temps);
    let mut dt = vec![0.0; N_NODES];
    let _ = model.thermal(&op, &l, temps, &mut dt);
    dt
}

/// Equilibrium temperatures (°C, node order) of `model` at the operating
/// point of state `y` at time `t`, starting from the state's temperatures.
/// `None` if Newton does not converge to 1e-9 K/s within 50 iterations or
/// the equilibrium is not finite.
pub fn thermal_equilibrium(model: &Model, t: f64, y: &[f64]) -> Option<[f64; N_NODES]> {
    let mut x: Vec<f64> = y[T0..T0 + N_NODES].to_vec();
    for _ in 0..50 {
        let f0 = rates(model, t, y, &x);
        if f0.iter().all(|r| r.abs() < 1e-9) {
            let mut out = [0.0; N_NODES];
            out.copy_from_slice(&x);
            return out.iter().all(|v| v.is_finite()).then_some(out);
        }
        let mut j = DMatrix::zeros(N_NODES, N_NODES);
        for k in 0..N_NODES {
            let mut xp = x.clone();
            xp[k] += 1e-4;
            let fk = rates(model, t, y, &xp);
            for i in 0..N_NODES {
                j[(i, k)] = (fk[i] - f0[i]) / 1e-4;
            }
        }
        let dx = j.lu().solve(&DVector::from_vec(f0))?;
        // damped step: at most 50 K per node per iteration
        let scale = dx.iter().fold(1.0f64, |s, d| s.min(50.0 / d.abs().max(1e-300)));
        for (xi, d) in x.iter_mut().zip(dx.iter()) {
            *xi -= scale * d;
        }
    }
    None
}
