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

impl<N> At<N> {
    /// `true` below the table's second point (`x < x_max / (N_TABLE - 1)^2`).
    #[inline(always)]
    pub fn in_first_interval(&self) -> bool {
        self.j == 0
    }
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

/// [`locate`] that extrapolates past the last point along the last interval
/// (`frac > 1`) instead of holding the end value: for a table whose law is close to
/// linear in `sqrt(x)` at its end (the case gap's film, `Nu ∝ Ta^0.241 ∝ x^0.48`).
/// `last` is `N_TABLE - 2` in the number type.
#[inline(always)]
pub fn locate_ext<N: Num>(x: N, root_scale: N, last: N) -> At<N> {
    let u = x.sqrt_abs().mul(root_scale);
    let (i, frac) = u.split_floor();
    match usize::try_from(i) {
        Ok(j) if j <= N_TABLE - 2 => At { j, frac },
        Ok(_) => At { j: N_TABLE - 2, frac: u.sub(last) },
        Err(_) => At { j: 0, frac: N::ZERO },
    }
}

/// Value of `table` at `at` (linear interpolation).
#[inline(always)]
pub fn value<N: Num, const K: usize>(table: &[N; K], at: &At<N>) -> N {
    match (table.get(at.j), table.get(at.j + 1)) {
        (Some(a), Some(b)) => a.add(b.sub(*a).mul(at.frac)),
        _ => N::ZERO,
    }
}

/// Locates `u` (grid units: 0 at the first point, 1 per step) on a uniform grid of
/// `K` points; below the first point and above the last the end value holds.
#[inline(always)]
pub fn locate_uniform<N: Num, const K: usize>(u: N, one: N) -> At<N> {
    let (i, frac) = u.split_floor();
    let last = K - 2;
    match usize::try_from(i) {
        Ok(j) if j <= last => At { j, frac },
        Ok(_) => At { j: last, frac: one },
        Err(_) => At { j: 0, frac: N::ZERO },
    }
}

/// Value of column `m` of the interleaved tables `rows` at `at`.
#[inline(always)]
pub fn value_col<N: Num, const M: usize, const K: usize>(rows: &[[N; M]; K], at: &At<N>, m: usize) -> N {
    match (rows.get(at.j).and_then(|r| r.get(m)), rows.get(at.j + 1).and_then(|r| r.get(m))) {
        (Some(a), Some(b)) => a.add(b.sub(*a).mul(at.frac)),
        _ => N::ZERO,
    }
}

/// Values of the `M` interleaved tables of `rows` (point by point) at `at`.
#[inline(always)]
pub fn values<N: Num, const M: usize, const K: usize>(rows: &[[N; M]; K], at: &At<N>) -> [N; M] {
    let mut o = [N::ZERO; M];
    if let (Some(a), Some(b)) = (rows.get(at.j), rows.get(at.j + 1)) {
        for ((o, a), b) in o.iter_mut().zip(a.iter()).zip(b.iter()) {
            *o = a.add(b.sub(*a).mul(at.frac));
        }
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Grid `x_j = x_max (j/31)^2` with `t_j = j`: interpolation in sqrt(x), the
    /// last point held beyond the range, negative and NaN inputs at the first.
    #[test]
    fn locate_and_interpolate() {
        let mut t = [0.0f64; N_TABLE];
        for (j, v) in t.iter_mut().enumerate() {
            *v = j as f64;
        }
        let x_max = 4.0;
        let root_scale = (N_TABLE - 1) as f64 / libm::sqrt(x_max);
        let at = |x: f64| value(&t, &locate(x, root_scale, 1.0));
        // exactly on grid point 10 and half way (in sqrt) between 10 and 11
        let x10 = x_max * (10.0f64 / 31.0).powi(2);
        let x105 = x_max * (10.5f64 / 31.0).powi(2);
        assert!((at(x10) - 10.0).abs() < 1e-12);
        assert!((at(x105) - 10.5).abs() < 1e-12);
        assert!((at(x_max) - 31.0).abs() < 1e-12);
        assert_eq!(at(10.0 * x_max), 31.0);
        assert_eq!(at(0.0), 0.0);
        assert_eq!(at(f64::NAN), 0.0);
        // sqrt_abs: a negative input reads the table at |x| (flows are magnitudes)
        assert!((at(-x10) - 10.0).abs() < 1e-12);
    }

    /// The uniform grid: interpolation between points, the end values held
    /// outside, the interleaved tables read at one position.
    #[test]
    fn uniform_grid_holds_its_ends() {
        let rows: [[f64; 2]; 4] = [[0.0, 10.0], [1.0, 20.0], [2.0, 30.0], [3.0, 40.0]];
        let at = |u: f64| values(&rows, &locate_uniform::<f64, 4>(u, 1.0));
        assert_eq!(at(1.5), [1.5, 25.0]);
        assert_eq!(at(-2.0), [0.0, 10.0]);
        assert_eq!(at(7.0), [3.0, 40.0]);
        assert_eq!(at(f64::NAN), [0.0, 10.0]);
    }
}
