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

use crate::fluid::Oil;
use crate::heat::nu_laminar_x;
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
        super::outer_memo::q_outer_exposed_kept(rig, area, shape, t, t_air, air_mps, ram_share)
    }
}

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
    /// in [`NuGrid::nu`].
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
