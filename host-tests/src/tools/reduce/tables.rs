//! The reduction's tables (step 4): grid points uniform in `sqrt(q)` over
//! flow or shaft speed and uniform over temperature, and the
//! free-convection fit of the outer surfaces (step 5). Separate because
//! they are the shared helpers of every table the reduction fills.

use eha_guard::model::{N_TABLE, N_TEMP};
use eha_guard::params::{TEMP_TABLE_MIN_C, TEMP_TABLE_STEP_K};

/// Grid point `j` of a table ending at `x_max`: `x_max (j / (N_TABLE - 1))^2`.
pub fn grid(x_max: f64, j: usize) -> f64 {
    let u = j as f64 / (N_TABLE - 1) as f64;
    x_max * u * u
}

pub(super) fn table(x_max: f64, f: impl Fn(f64) -> f64) -> [f64; N_TABLE] {
    let mut t = [0.0; N_TABLE];
    for (j, v) in t.iter_mut().enumerate() {
        *v = f(grid(x_max, j));
    }
    t
}

/// Least-squares fit of `h(ΔT) = c0 + c1 ΔT^(1/4)` to a free-convection law over
/// ΔT ∈ [0.05, 100] K (log-spaced) at [`FIT_AIR_C`](super::FIT_AIR_C); returns `(c0, c1)` with
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

pub(super) fn temp_table(f: impl Fn(f64) -> f64) -> [f64; N_TEMP] {
    let mut t = [0.0; N_TEMP];
    for (j, v) in t.iter_mut().enumerate() {
        *v = f(temp_grid(j));
    }
    t
}
