//! Temperature grids for the multirate plant's heat balances: the outer
//! surfaces' heat flows ([`OuterGrid`]) and the oil's viscosity
//! ([`NuGrid`]), interpolated between their exact values at multiples of
//! a grid step.
//!
//! Why, the outer surfaces (free convection and ram air, eqs. 15/16,
//! radiation, eq. 19): the five surfaces' correlations (`pow`, `cbrt` of the Rayleigh and
//! Prandtl numbers) were ~30 % of a heat balance, evaluated anew at every
//! thermal step while a wall moves by millikelvins per step. Interpolated,
//! a heat balance evaluates them only when a wall enters a new cell.
//!
//! The interpolant is a function of the wall temperature alone (the grid
//! points are exact values at k·step_k, whatever the order of the calls):
//! a run is reproducible and its error bounded, not an accumulated drift.
//! Linear interpolation of a convex q(T) overestimates it by at most
//! max|q''|·step_k²/8 (W); at 0.1 K on the rig's surfaces, measured in the
//! test below: 4.2e-4 W more than a kelvin from the air temperature,
//! 4.0e-3 W within a kelvin of it (free convection q ∝ |ΔT|^5/4 has no
//! bounded q'' at ΔT = 0; there q itself is a few milliwatts). Against
//! heat capacities of kJ/K that is below a µK/s. A change of the air state
//! (ambient, ram air) gives the exact value for that call and a grid from
//! the next call with the same air on (a ramped ambient stays exact).
//! A wall whose cubic's four points are all [`OUTER_COARSE_FROM_K`] or more
//! from the air takes the cubic through them on a grid five times coarser
//! (0.5 K; q is smooth there): measured 6.5e-5 W from 2 K on, within the
//! fine line's 4.2e-4 W; on Case 1, where the walls warm by tenths of a
//! kelvin per thermal step and each step's walls were two new exact points,
//! 281 → 148 exact evaluations.
//!
//! The viscosity: a `log10` and two `pow` for every new temperature, 6 of
//! them in a heat balance (the ports, the loop, the ball valve, the case
//! oil's films and leakage), 14 % of one. The Walther line is smooth, so
//! it is interpolated by the cubic through four grid points on a grid ten
//! times coarser than the outer surfaces' ([`NU_GRID_FACTOR`]): relative
//! error of order step⁴ times the fourth derivative of ν over ν, measured
//! 1.07e-5 at 1 K from −20 to 150 °C (test below; largest in the cold,
//! where the line is steepest), against 2.2e-5 for the line between points
//! 0.1 K apart. Where the oil warms by kelvins per thermal step (Case 1)
//! each new 0.1 K cell was a new exact point: 365 exact viscosities for
//! Case 1's 600 s on the 0.1 K line, 47 on the 1 K cubic.
//!
//! Only the fast plant sets a grid; the BDF plant's heat balances, and
//! with them the oracle's outputs, are the exact correlations.

mod laminar;
mod nu;
mod outer;

pub use laminar::LaminarGrid;
pub use nu::{NuGrid, NU_GRID_FACTOR};
pub use outer::{OuterGrid, OUTER_COARSE_FACTOR, OUTER_COARSE_FROM_K};

/// The cubic through (−1, v[0]), (0, v[1]), (1, v[2]), (2, v[3]) in powers
/// of u (Lagrange on four uniform points).
fn cubic_through(v: [f64; 4]) -> [f64; 4] {
    let [vm, v0, v1, v2] = v;
    [v0, -vm / 3.0 - v0 / 2.0 + v1 - v2 / 6.0, (vm + v1) / 2.0 - v0, (v2 - vm) / 6.0 + (v0 - v1) / 2.0]
}

/// The cubic with coefficients `c` (powers of u) at `u`.
fn horner(c: &[f64; 4], u: f64) -> f64 {
    c[0] + u * (c[1] + u * (c[2] + u * c[3]))
}

/// ⌊x⌋ for |x| < 2⁶³ (a truncation and a correction: `f64::floor` is a
/// library call on the baseline x86-64 target). The truncation unchecked
/// (one `cvttsd2si`; `as` adds the saturation and NaN fix-ups, ~5
/// instructions in each of ~2 700 calls a fast Case 1 run).
///
/// # Safety
/// `x` is finite and |x| < 2⁶³ (the callers pass |x| < 1e12).
unsafe fn floor_i64(x: f64) -> i64 {
    // SAFETY: the caller's precondition.
    let k: i64 = unsafe { x.to_int_unchecked() };
    if (k as f64) > x {
        k - 1
    } else {
        k
    }
}
