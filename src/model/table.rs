//! Piecewise-linear tables over `sqrt(x)`: the flow- and speed-dependent
//! conductances of eqs. (12)-(14) and (20)-(22), sampled once by the reduction tool.

use crate::params::N_TABLE;
use crate::num::Num;

/// Position in a table: index of the left point and the fraction towards the next.
#[derive(Clone, Copy, Debug)]
pub struct At<N> {
    j: usize,
    frac: N,
}

/// Locates `x >= 0` (table unit) on the grid `x_j = x_max (j / (N_TABLE - 1))^2`,
/// given `root_scale = (N_TABLE - 1) / sqrt(x_max)`: `u = sqrt(x) root_scale`, `j = floor(u)`.
/// Beyond the last point the value is held at the last point (fraction 1 of the
/// last interval): a table never extrapolates.
#[inline(always)]
pub fn locate<N: Num>(x: N, root_scale: N, one: N) -> At<N> {
    let u = x.sqrt_abs().mul(root_scale);
    let (i, frac) = u.split_floor();
    let last = N_TABLE - 2;
    match usize::try_from(i) {
        Ok(j) if j <= last => At { j, frac },
        Ok(_) => At { j: last, frac: one },
        Err(_) => At { j: 0, frac: N::ZERO },
    }
}

/// Value of `table` at `at` (linear interpolation).
#[inline(always)]
pub fn value<N: Num>(table: &[N; N_TABLE], at: &At<N>) -> N {
    match (table.get(at.j), table.get(at.j + 1)) {
        (Some(a), Some(b)) => a.add(b.sub(*a).mul(at.frac)),
        _ => N::ZERO,
    }
}

/// Converts an SI table (`f64`, W/K) to the number type in kW/K.
pub fn to_kw<N: Num>(t: &[f64; N_TABLE]) -> [N; N_TABLE] {
    let mut o = [N::ZERO; N_TABLE];
    for (o, x) in o.iter_mut().zip(t.iter()) {
        *o = N::from_f64(x * 1e-3);
    }
    o
}
