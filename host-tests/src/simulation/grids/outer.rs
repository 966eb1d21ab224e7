//! The outer surfaces' heat flows (free convection and ram air, eqs. 15/16,
//! radiation, eq. 19) on the wall temperature's grid: a fine line and a
//! coarse cubic away from the air (the module documentation of
//! [`super`] says why and how well).

use super::{cubic_through, floor_i64, horner};
#[cfg(test)]
use crate::network::q_outer_exposed;
use crate::network::Shape;
use crate::rig::Rig;
use std::cell::Cell;

/// Outer surfaces (see [`crate::network::surfaces`]).
const SURFACES: usize = 5;

/// One surface's cell: the air state it belongs to, its index k and the
/// exact heat flows at k·step and (k+1)·step.
#[derive(Debug, Clone, Copy, Default)]
struct GridCell {
    /// Bits of (area, air temperature, air speed, ram share).
    key: [u64; 4],
    /// `key` seen (the call that saw it was exact).
    seen: bool,
    /// `k`, `q_lo` and `q_hi` hold a cell.
    built: bool,
    k: f64,
    q_lo: f64,
    q_hi: f64,
}

/// One surface's cell of the coarse grid: the air state it belongs to, its
/// index k, the exact heat flows at (k−1 … k+2)·coarse step and the cubic
/// through them in powers of u = x − k.
#[derive(Debug, Clone, Copy, Default)]
struct CoarseCell {
    key: [u64; 4],
    built: bool,
    k: f64,
    q: [f64; 4],
    c: [f64; 4],
}

/// Spacing of the outer surfaces' coarse grid, in fine steps.
pub const OUTER_COARSE_FACTOR: f64 = 5.0;

/// Distance from the air temperature beyond which a wall's heat flow is the
/// cubic on the coarse grid (every one of the cubic's four points at least
/// this far from the air, on the same side), K. Free convection goes as
/// |ΔT|^(5/4)–|ΔT|^(4/3): smooth away from ΔT = 0, where the cubic's error
/// (fourth derivative ∝ |ΔT|^(−11/4)) is largest; from 1.5 K on a 0.5 K
/// grid, measured in the test below within that of the fine line.
pub const OUTER_COARSE_FROM_K: f64 = 1.5;

/// The grid of the five outer surfaces (one cell each on the fine and on
/// the coarse grid, kept between calls).
#[derive(Debug)]
pub struct OuterGrid {
    step_k: f64,
    cells: [Cell<GridCell>; SURFACES],
    coarse: [Cell<CoarseCell>; SURFACES],
    /// Exact evaluations of the correlations so far (cells built, air changes).
    pub evals: Cell<u64>,
}

impl OuterGrid {
    /// A grid of `step_k` kelvin (> 0).
    pub fn new(step_k: f64) -> Self {
        Self { step_k, cells: Default::default(), coarse: Default::default(), evals: Cell::new(0) }
    }

    /// The grid's spacing, K.
    pub fn step_k(&self) -> f64 {
        self.step_k
    }

    /// Heat flow of surface `i` (the index in `surfaces`) from the wall at
    /// `t_wall` to the air, W: [`q_outer_exposed`](crate::network::q_outer_exposed) interpolated on the grid.
    #[allow(clippy::too_many_arguments)] // q_outer_exposed's arguments and the surface's index
    pub fn q(&self, i: usize, rig: &Rig, area: f64, shape: Shape, t_wall: f64, t_air: f64, air_mps: f64, ram_share: f64) -> f64 {
        // (A macro, not a closure: the closure's captures were stored at
        // every call, ~16 instructions, for the few calls that fill a cell.)
        macro_rules! exact {
            ($t:expr) => {
                self.exact(rig, area, shape, $t, t_air, air_mps, ram_share)
            };
        }
        let x = t_wall / self.step_k;
        let Some(cell) = self.cells.get(i) else { return exact!(t_wall) };
        if x.is_nan() || x.abs() >= 1e12 {
            return exact!(t_wall);
        }
        let key = [area.to_bits(), t_air.to_bits(), air_mps.to_bits(), ram_share.to_bits()];
        let mut c = cell.get();
        if !c.seen || c.key != key {
            cell.set(GridCell { key, seen: true, ..GridCell::default() });
            return exact!(t_wall);
        }
        // Far from the air: the cubic through four points of the coarse grid.
        let step_c = self.step_k * OUTER_COARSE_FACTOR;
        // SAFETY: |x| < 1e12 and not NaN (above), and t_wall / step_c ≈ x / 5.
        let kc = unsafe { floor_i64(t_wall / step_c) } as f64;
        let (lo, hi) = ((kc - 1.0) * step_c, (kc + 2.0) * step_c);
        if lo - t_air >= OUTER_COARSE_FROM_K || t_air - hi >= OUTER_COARSE_FROM_K {
            let slot = &self.coarse[i];
            let mut cc = slot.get();
            if !cc.built || cc.key != key || cc.k != kc {
                // Points of the former cell that are points of this one, kept.
                let old = cc;
                let q: [f64; 4] = std::array::from_fn(|j| {
                    let kj = kc - 1.0 + j as f64;
                    let d = kj - (old.k - 1.0);
                    if old.built && old.key == key && (0.0..4.0).contains(&d) {
                        old.q[d as usize]
                    } else {
                        exact!(kj * step_c)
                    }
                });
                cc = CoarseCell { key, built: true, k: kc, q, c: cubic_through(q) };
                slot.set(cc);
            }
            return horner(&cc.c, t_wall / step_c - kc);
        }
        // SAFETY: |x| < 1e12 and not NaN (above).
        let k = unsafe { floor_i64(x) } as f64;
        if !c.built || k != c.k {
            let at = |k: f64| exact!(k * self.step_k);
            let (q_lo, q_hi) = match c.built {
                true if k == c.k + 1.0 => (c.q_hi, at(k + 1.0)),
                true if k == c.k - 1.0 => (at(k), c.q_lo),
                _ => (at(k), at(k + 1.0)),
            };
            c = GridCell { key, seen: true, built: true, k, q_lo, q_hi };
            cell.set(c);
        }
        c.q_lo + (x - k) * (c.q_hi - c.q_lo)
    }

    /// [`q_outer_exposed`](crate::network::q_outer_exposed), counted, through the per-thread table of the
    /// values computed before (`outer_memo`: the same bits). Out of line (a cell's fill, ~250 calls
    /// a fast Case 1 run against ~600 reads of kept cells): inlined, its
    /// code had moved with the builds' inlining decisions, ±6 k instructions
    /// of `OuterGrid::q` between builds of the same source.
    #[cold]
    #[inline(never)]
    #[allow(clippy::too_many_arguments)] // q_outer_exposed's arguments
    fn exact(&self, rig: &Rig, area: f64, shape: Shape, t: f64, t_air: f64, air_mps: f64, ram_share: f64) -> f64 {
        self.evals.set(self.evals.get() + 1);
        crate::simulation::outer_memo::q_outer_exposed_kept(rig, area, shape, t, t_air, air_mps, ram_share)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::network::surfaces;

    /// Against the exact correlations on every surface of the default rig,
    /// walls from 2 K below to 60 K above a 20 °C air, still and at 15 m/s:
    /// within the bounds of the module documentation (at 0.1 K, measured
    /// 4.20e-4 W more than a kelvin from the air, 3.98e-3 W within it; the
    /// coarse cubic 6.5e-5 W from 2 K on), and exact on a change of the air.
    #[test]
    fn interpolation_error_is_bounded() {
        let rig = Rig::default();
        let g = OuterGrid::new(0.1);
        let (mut worst, mut near, mut far): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for (air, ram) in [(0.0, false), (15.0, true)] {
            for (i, (_, area, shape, share)) in surfaces(&rig).into_iter().enumerate() {
                let share = if ram { share } else { 1.0 };
                for j in 0..6200 {
                    let t = 18.0 + j as f64 * 0.01013;
                    let q = g.q(i, &rig, area, shape, t, 20.0, air, share);
                    let e = q_outer_exposed(&rig, area, shape, t, 20.0, air, share);
                    if (t - 20.0).abs() > 1.0 {
                        worst = worst.max((q - e).abs());
                        if (t - 20.0).abs() > OUTER_COARSE_FROM_K + 0.1 * OUTER_COARSE_FACTOR {
                            far = far.max((q - e).abs());
                        }
                    } else {
                        near = near.max((q - e).abs());
                    }
                }
            }
        }
        println!("largest interpolation error {worst:.3e} W, within a kelvin of the air {near:.3e} W, on the coarse cubic {far:.3e} W");
        assert!(worst < 5e-4 && worst > 0.0, "largest interpolation error {worst:.3e} W");
        assert!(near < 5e-3, "largest interpolation error within a kelvin of the air {near:.3e} W");
        assert!(far < 1e-4 && far > 0.0, "largest interpolation error of the coarse cubic {far:.3e} W");
        let (_, area, shape, share) = surfaces(&rig)[0];
        // (black_box: constant-folded, the correlation's powi differs in the last bit)
        let (tw, ta) = std::hint::black_box((31.0, 21.0));
        let (q, e) = (g.q(0, &rig, area, shape, tw, ta, 0.0, share), q_outer_exposed(&rig, area, shape, tw, ta, 0.0, share));
        assert_eq!(q, e, "a new air state is exact");
    }
}
