//! The laminar duct Nusselt number (eq. 13) on a grid of its argument
//! X = Re·Pr·d/L: the cubic through four grid points in Newton's form.

use crate::heat::nu_laminar_x;
use std::cell::Cell;

/// Low bits of X's representation dropped for the laminar grid's index:
/// 16 cells a binade (X's relative spacing 1/32–1/16).
const LAM_SHIFT: u32 = 52 - 4;
/// Cells and points kept by [`LaminarGrid`] (direct-mapped by index): 32
/// binades of X, wider than the 24 from 0.1 to 1e6. (The count moves the
/// cost only, never a value: 1024 slots cost ~4 k instructions more a run.)
const LAM_SLOTS: usize = 512;
/// Below this X the laminar law is evaluated exactly (at X ≤ 0.081 it is
/// its constant, the developing-flow term gone).
const LAM_EXACT_BELOW: f64 = 0.1;

/// A memo slot of [`LaminarGrid`]: (k, Newton coefficients, the node t of
/// X_k−1, X_k, 1/(X_k+1 − X_k)).
type LamCell = Cell<(u64, [f64; 4], f64, f64, f64)>;

/// The laminar duct Nusselt number (eq. 13) as a function of its one
/// argument X = Re·Pr·d/L ([`nu_laminar_x`]: two `cbrt`, ~340 instructions,
/// eight times in a heat balance) on a grid of X: the grid points are the
/// values of X whose representation ends in `LAM_SHIFT` zero bits (16 a
/// binade, uniform within it), and in the cell [X_k, X_k+1] the cubic
/// through the exact values at X_k−1 … X_k+2 (Newton's form, the nodes
/// non-uniform across a binade's edge). Measured within 2.6e-7 relative
/// from X = 0.1 to 1e6 (test below).
#[derive(Debug)]
pub struct LaminarGrid {
    /// (k, Newton coefficients, the node t of X_k−1, X_k, 1/(X_k+1 − X_k)) at slot k mod LAM_SLOTS; k = u64::MAX: empty.
    cells: Box<[LamCell]>,
    /// (k, the law at X_k) at slot k mod LAM_SLOTS; k = u64::MAX: empty.
    points: Box<[Cell<(u64, f64)>]>,
    /// Exact evaluations so far.
    pub evals: Cell<u64>,
}

impl Default for LaminarGrid {
    fn default() -> Self {
        Self::new()
    }
}

impl LaminarGrid {
    /// A grid with the slots the last grid dropped on this thread left
    /// (the law has no parameter: its points are the same for every rig),
    /// or empty ones.
    pub fn new() -> Self {
        if let Some((cells, points)) = LAM_POOL.take() {
            return Self { cells, points, evals: Cell::new(0) };
        }
        let cells = (0..LAM_SLOTS).map(|_| Cell::new((u64::MAX, [0.0; 4], 0.0, 0.0, 0.0))).collect();
        let points = (0..LAM_SLOTS).map(|_| Cell::new((u64::MAX, 0.0))).collect();
        Self { cells, points, evals: Cell::new(0) }
    }

    /// The laminar Nusselt number at X = Re·Pr·d/L, interpolated.
    ///
    /// The kept cell's path only, the rest out of line (`nu_other`), as
    /// in [`super::NuGrid::nu`].
    #[inline]
    pub fn nu(&self, x: f64) -> f64 {
        if (LAM_EXACT_BELOW..1e300).contains(&x) {
            let k = x.to_bits() >> LAM_SHIFT;
            let (kk, a, tm, x0, inv_w) = self.cells[(k as usize) & (LAM_SLOTS - 1)].get();
            if kk == k {
                let t = (x - x0) * inv_w;
                return a[0] + t * (a[1] + (t - 1.0) * (a[2] + (t - tm) * a[3]));
            }
        }
        self.nu_other(x)
    }

    /// [`LaminarGrid::nu`] beyond the kept cells: exact outside the grid's
    /// range, a new cell.
    #[cold]
    #[inline(never)]
    fn nu_other(&self, x: f64) -> f64 {
        if !(LAM_EXACT_BELOW..1e300).contains(&x) {
            return nu_laminar_x(x);
        }
        let k = x.to_bits() >> LAM_SHIFT;
        let slot = &self.cells[(k as usize) & (LAM_SLOTS - 1)];
        let (mut kk, mut a, mut tm, mut x0, mut inv_w) = slot.get();
        if kk != k {
            let at = |j: u64| f64::from_bits(j << LAM_SHIFT);
            let (xm, x1, x2) = (at(k - 1), at(k + 1), at(k + 2));
            x0 = at(k);
            inv_w = 1.0 / (x1 - x0);
            tm = (xm - x0) * inv_w;
            let t2 = (x2 - x0) * inv_w;
            let (fm, f0, f1, f2) = (self.point(k - 1), self.point(k), self.point(k + 1), self.point(k + 2));
            // Divided differences on the nodes 0, 1, tm, t2.
            let d01 = f1 - f0;
            let d1m = (fm - f1) / (tm - 1.0);
            let d01m = (d1m - d01) / tm;
            let dm2 = (f2 - fm) / (t2 - tm);
            let d1m2 = (dm2 - d1m) / (t2 - 1.0);
            let d01m2 = (d1m2 - d01m) / t2;
            a = [f0, d01, d01m, d01m2];
            kk = k;
            slot.set((kk, a, tm, x0, inv_w));
        }
        let t = (x - x0) * inv_w;
        a[0] + t * (a[1] + (t - 1.0) * (a[2] + (t - tm) * a[3]))
    }

    fn point(&self, k: u64) -> f64 {
        let slot = &self.points[(k as usize) & (LAM_SLOTS - 1)];
        let (kk, v) = slot.get();
        if kk == k {
            return v;
        }
        self.evals.set(self.evals.get() + 1);
        let v = nu_laminar_x(f64::from_bits(k << LAM_SHIFT));
        slot.set((k, v));
        v
    }
}

const _: () = assert!(LAM_SLOTS.is_power_of_two(), "slots are indexed by a mask");

/// A dropped [`LaminarGrid`]'s slots.
type LamSlots = (Box<[LamCell]>, Box<[Cell<(u64, f64)>]>);

thread_local! {
    /// The slots of the last [`LaminarGrid`] dropped on this thread, for
    /// the next one: a later run (a bench's, a sweep's) reads the points
    /// and cells the earlier one computed (two `cbrt` a point, ~40 k
    /// instructions a Case 1 run) and skips the allocation.
    static LAM_POOL: Cell<Option<LamSlots>> = const { Cell::new(None) };
}

impl Drop for LaminarGrid {
    fn drop(&mut self) {
        let (cells, points) = (std::mem::take(&mut self.cells), std::mem::take(&mut self.points));
        // (try_with: nothing to keep while the thread's locals are going.)
        let _ = LAM_POOL.try_with(|p| p.set(Some((cells, points))));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The laminar Nusselt number on its grid from X = 0.1 to 1e6 (a
    /// cell's nodes across a binade's edge included) against the law:
    /// within 5e-7 relative (measured 2.52e-7), and exact below X = 0.1.
    #[test]
    fn laminar_nusselt_error_is_bounded() {
        let g = LaminarGrid::new();
        let mut worst: f64 = 0.0;
        for j in 0..70_000 {
            let x = 10f64.powf(-1.0 + j as f64 * 1e-4);
            let (v, e) = (g.nu(x), nu_laminar_x(x));
            worst = worst.max((v / e - 1.0).abs());
        }
        println!("largest relative error {worst:.3e}");
        assert!(worst < 5e-7 && worst > 0.0, "largest relative error {worst:.3e}");
        assert_eq!(g.nu(0.05), nu_laminar_x(0.05));
        assert_eq!(g.nu(0.0), nu_laminar_x(0.0));
    }
}
