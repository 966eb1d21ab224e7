//! The oil's kinematic viscosity (the Walther line) on a temperature grid:
//! the cubic through four grid points, its cells memoised by index.

use super::{cubic_through, floor_i64, horner};
use crate::fluid::Oil;
use std::cell::Cell;

/// Spacing of the viscosity's grid in units of the outer surfaces' one.
pub const NU_GRID_FACTOR: f64 = 10.0;

/// Cells kept by [`NuGrid`]: a 256-step span (256 K at 1 K), wider than
/// the spread of the oil nodes' temperatures, so two nodes never take
/// turns at one slot. (A slot holds what its cell's points give, so the
/// count moves the cost only, never a value: 1024 slots cost ~6 k
/// instructions more a run to allocate and empty.)
const NU_SLOTS: usize = 256;

/// A memo slot of [`NuGrid`]: (cell index k, cubic coefficients in u = x − k).
type NuCell = Cell<(i64, [f64; 4])>;

/// The oil's kinematic viscosity on a temperature grid: in the cell
/// [k, k+1]·step_k, the cubic through the exact values at the four grid
/// points k−1 … k+2 (Lagrange; continuous, exact at the points), its
/// coefficients kept in slots by k (direct-mapped) and the points in a
/// second table, so that a new cell costs one exact evaluation where the
/// oil moves on by a cell. A change of the oil's grade points empties the
/// slots. (A call is ~25 instructions: the bit-keyed memo of
/// `Oil::nu_m2_per_s` took ~50 for a repeated temperature and ~450 for a
/// new one.)
#[derive(Debug)]
pub struct NuGrid {
    step_k: f64,
    per_step: f64,
    grade: Cell<(u64, u64)>,
    /// (k, cubic coefficients in u = x − k) at slot k mod NU_SLOTS; k = i64::MIN: empty.
    cells: Box<[NuCell]>,
    /// (k, ν(k·step_k)) at slot k mod NU_SLOTS; k = i64::MIN: empty.
    points: Box<[Cell<(i64, f64)>]>,
    /// Exact evaluations so far.
    pub evals: Cell<u64>,
}

impl NuGrid {
    /// A grid of `step_k` kelvin (> 0): the slots the last grid of the
    /// same step dropped on this thread left (their values are the grid
    /// points' of an oil's grade, kept with the grade), or empty ones.
    pub fn new(step_k: f64) -> Self {
        if let Some((bits, grade, cells, points)) = NU_POOL.take() {
            if bits == step_k.to_bits() {
                return Self { step_k, per_step: 1.0 / step_k, grade: Cell::new(grade), cells, points, evals: Cell::new(0) };
            }
        }
        let cells = (0..NU_SLOTS).map(|_| Cell::new((i64::MIN, [0.0; 4]))).collect();
        let points = (0..NU_SLOTS).map(|_| Cell::new((i64::MIN, 0.0))).collect();
        Self { step_k, per_step: 1.0 / step_k, grade: Cell::new((u64::MAX, u64::MAX)), cells, points, evals: Cell::new(0) }
    }

    /// Kinematic viscosity of `oil` at `t_c`, m²/s: [`Oil::nu_m2_per_s`]
    /// interpolated on the grid.
    ///
    /// The kept cell's path only, the rest out of line (`nu_other`): with
    /// the cell's fill inlined, every call saved and restored six registers
    /// (~1 700 calls a fast Case 1 run).
    #[inline]
    pub fn nu(&self, oil: &Oil, t_c: f64) -> f64 {
        let x = t_c * self.per_step;
        // (NaN fails the comparison.)
        if x.abs() < 1e12 && self.grade.get() == (oil.nu40_cst.to_bits(), oil.nu100_cst.to_bits()) {
            // SAFETY: |x| < 1e12 (NaN fails the test).
            let k = unsafe { floor_i64(x) };
            let (kk, c) = self.cells[(k as usize) & (NU_SLOTS - 1)].get();
            if kk == k {
                return horner(&c, x - k as f64);
            }
        }
        self.nu_other(oil, t_c)
    }

    /// [`NuGrid::nu`] beyond the kept cells: exact beyond ±1e12 cells (and
    /// at NaN), a new oil's grade, a new cell.
    #[cold]
    #[inline(never)]
    fn nu_other(&self, oil: &Oil, t_c: f64) -> f64 {
        let x = t_c * self.per_step;
        if x.is_nan() || x.abs() >= 1e12 {
            return oil.nu_m2_per_s(t_c);
        }
        let grade = (oil.nu40_cst.to_bits(), oil.nu100_cst.to_bits());
        if self.grade.get() != grade {
            // A new grid's slots are empty already (`new`): cleared only
            // for a second oil (~5 k instructions a run saved).
            if self.grade.replace(grade) != (u64::MAX, u64::MAX) {
                self.cells.iter().for_each(|s| s.set((i64::MIN, [0.0; 4])));
                self.points.iter().for_each(|s| s.set((i64::MIN, 0.0)));
            }
        }
        // SAFETY: |x| < 1e12 and not NaN (above).
        let k = unsafe { floor_i64(x) };
        let u = x - k as f64;
        let slot = &self.cells[(k as usize) & (NU_SLOTS - 1)];
        let (kk, mut c) = slot.get();
        if kk != k {
            c = cubic_through([self.point(oil, k - 1), self.point(oil, k), self.point(oil, k + 1), self.point(oil, k + 2)]);
            slot.set((k, c));
        }
        horner(&c, u)
    }

    fn point(&self, oil: &Oil, k: i64) -> f64 {
        let slot = &self.points[(k as usize) & (NU_SLOTS - 1)];
        let (kk, v) = slot.get();
        if kk == k {
            return v;
        }
        self.evals.set(self.evals.get() + 1);
        let v = oil.nu_m2_per_s(k as f64 * self.step_k);
        slot.set((k, v));
        v
    }
}

const _: () = assert!(NU_SLOTS.is_power_of_two(), "slots are indexed by a mask");

/// A dropped [`NuGrid`]'s step's bits, grade and slots.
type NuSlots = (u64, (u64, u64), Box<[NuCell]>, Box<[Cell<(i64, f64)>]>);

thread_local! {
    /// The slots of the last [`NuGrid`] dropped on this thread, for the
    /// next one of the same step: the grid points are functions of the
    /// grade and the step alone, so a later run (a bench's, a sweep's)
    /// reads the values the earlier one computed (~20 k instructions of
    /// `log10` and `pow` a Case 1 run) and its allocation.
    static NU_POOL: Cell<Option<NuSlots>> = const { Cell::new(None) };
}

impl Drop for NuGrid {
    fn drop(&mut self) {
        let (cells, points) = (std::mem::take(&mut self.cells), std::mem::take(&mut self.points));
        // (try_with: nothing to keep while the thread's locals are going.)
        let _ = NU_POOL.try_with(|p| p.set(Some((self.step_k.to_bits(), self.grade.get(), cells, points))));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::Rig;

    /// The viscosity on the 1 K grid (cubic) from −20 to 150 °C, against
    /// the Walther line: within 1.5e-5 relative (measured 1.07e-5, in the
    /// cold; the line between points 0.1 K apart had 2.16e-5), and the grid
    /// points exact.
    #[test]
    fn viscosity_error_is_bounded() {
        let oil = Rig::default().oil;
        let g = NuGrid::new(0.1 * NU_GRID_FACTOR);
        let mut worst: f64 = 0.0;
        for j in 0..17_000 {
            let t = -20.0 + j as f64 * 0.010_003;
            let (v, e) = (g.nu(&oil, t), oil.nu_m2_per_s(t));
            worst = worst.max((v / e - 1.0).abs());
        }
        println!("largest relative error {worst:.3e}");
        assert!(worst < 1.5e-5 && worst > 0.0, "largest relative error {worst:.3e}");
        let (v, e) = (g.nu(&oil, 40.0), oil.nu_m2_per_s(40.0));
        assert!((v / e - 1.0).abs() < 1e-12, "a grid point: {v} against {e}");
    }
}
