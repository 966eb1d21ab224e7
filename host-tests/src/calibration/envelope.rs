//! The training envelope: the operating region the training logs cover,
//! as cells of a fixed grid over |pump speed| × |port pressure difference|,
//! and the firmware's drain error on a log split inside and outside it
//! (docs/commissioning.md, "The training envelope"). Reporting only: the
//! block, its margin and every fit are unchanged by it.
//!
//! The grid is [`SPEED_CELL_RPM`] × [`DP_CELL_BAR`], about 6 × 6 cells
//! over the rig's range (0–1250 rpm, 0–60 bar): two of the bench
//! procedure's steps per cell (speed 400–1200 rpm and needle 10–50 bar,
//! each stepped every 3–4 min, ~100 rpm and ~5 bar a step), so the firmware
//! counts as validated between adjacent trained steps but not beyond them.
//! The edges sit off the procedure's values (speed at 50 + 200 k rpm, Δp at
//! 5 + 10 k bar), so a hold at 700 rpm or 20 bar lies inside a cell: with
//! edges on such values the sensor noise split a hold's dwell between two
//! cells, neither reaching the threshold. Measured and not kept: 100 rpm ×
//! 5 bar cells (centred on the multiples) left leaky-heavy's held-out
//! throttle mix 1798 of 1800 s outside (its speed and Δp are drawn
//! together, and rarely land on the training's cross of one-at-a-time
//! steps), so inside-against-outside said nothing. A cell is covered when
//! the training logs together dwell in it at least [`MIN_DWELL_S`].

use super::region::{Region, TickRow};
use super::log::CalLog;
use crate::measured::{Channel, MeasuredRun};
use std::collections::BTreeMap;

/// Width of a grid cell in |pump speed|, rpm (two of the procedure's speed steps).
pub const SPEED_CELL_RPM: f64 = 200.0;

/// Where the speed cells' edges sit, rpm: at `SPEED_EDGE_RPM + k ×
/// SPEED_CELL_RPM` (the first cell is 0–50 rpm).
pub const SPEED_EDGE_RPM: f64 = 50.0;

/// Width of a grid cell in |p_a − p_b|, bar (two of the procedure's needle steps).
pub const DP_CELL_BAR: f64 = 10.0;

/// Where the pressure cells' edges sit, bar: at `DP_EDGE_BAR + k ×
/// DP_CELL_BAR` (the first cell is 0–5 bar).
pub const DP_EDGE_BAR: f64 = 5.0;

/// Dwell the training logs need in a cell for it to count as covered, s:
/// about 1.5 case-oil time constants (37–41 s measured on the emulator
/// machines) plus the drain thermocouple's lag (3–5 s), so the drain has
/// answered the operating point; a sweep passing through a cell does not
/// cover it.
pub const MIN_DWELL_S: f64 = 60.0;

/// Longest gap between two log rows credited as dwell, s (a longer gap is
/// a hole in the log, not time spent at the earlier row's point).
pub const MAX_ROW_GAP_S: f64 = 10.0;

/// A grid cell: cell `k` of a width `w` with edges at `e + j w` spans
/// `e + (k − 1) w` to `e + k w` (cell 0 from 0 to `e`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub struct Cell {
    /// Speed index ([`SPEED_CELL_RPM`], [`SPEED_EDGE_RPM`]).
    pub speed: u32,
    /// Pressure index ([`DP_CELL_BAR`], [`DP_EDGE_BAR`]).
    pub dp: u32,
}

/// The cell of `speed_rpm` (rpm) and `dp_bar` (bar), signs ignored; `None`
/// when either is not finite.
pub fn cell_of(speed_rpm: f64, dp_bar: f64) -> Option<Cell> {
    (speed_rpm.is_finite() && dp_bar.is_finite())
        .then(|| Cell { speed: index(speed_rpm, SPEED_CELL_RPM, SPEED_EDGE_RPM), dp: index(dp_bar, DP_CELL_BAR, DP_EDGE_BAR) })
}

/// The cell index of `x` on a grid of width `w` with edges at `e + k w`.
fn index(x: f64, w: f64, e: f64) -> u32 {
    ((x.abs() + w - e) / w).floor() as u32
}

/// The lower edge of cell `k` of width `w`, edges at `e + j w` (≥ 0).
fn edge(k: u32, w: f64, e: f64) -> f64 {
    (e + (f64::from(k) - 1.0) * w).max(0.0)
}

/// The operating region the training logs cover.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Envelope {
    /// Seconds the training logs spend in each cell they visit, s.
    pub dwell_s: BTreeMap<Cell, f64>,
    /// Range of the drain temperature over the training rows (the oil
    /// temperature for logs without `t_drain_c`), °C; `None` without any.
    pub drain_c: Option<(f64, f64)>,
}

impl Envelope {
    /// The envelope of the training `logs`' rows.
    pub fn of_logs(logs: &[CalLog]) -> Self {
        Self::of_runs(logs.iter().map(|l| &l.run))
    }

    /// The envelope of `runs`' rows: each row with finite speed, `p_a` and
    /// `p_b` credits its cell with the time to the next row (at most
    /// [`MAX_ROW_GAP_S`]); other rows are skipped.
    pub fn of_runs<'a>(runs: impl IntoIterator<Item = &'a MeasuredRun>) -> Self {
        let mut e = Envelope::default();
        for r in runs {
            let col = |ch| r.get(ch).unwrap_or(&[]);
            let (n, pa, pb) = (col(Channel::SpeedRpm), col(Channel::PABar), col(Channel::PBBar));
            for i in 0..r.len().saturating_sub(1) {
                let (Some(Some(n)), Some(Some(a)), Some(Some(b))) = (n.get(i), pa.get(i), pb.get(i)) else { continue };
                let dt = r.time_s[i + 1] - r.time_s[i];
                if let (Some(c), true) = (cell_of(*n, a - b), dt.is_finite() && dt > 0.0) {
                    *e.dwell_s.entry(c).or_default() += dt.min(MAX_ROW_GAP_S);
                }
            }
            let t = if r.get(Channel::TDrainC).is_some_and(|v| v.iter().flatten().any(|x| x.is_finite())) { col(Channel::TDrainC) } else { col(Channel::TOilC) };
            for &x in t.iter().flatten().filter(|x| x.is_finite()) {
                e.drain_c = Some(e.drain_c.map_or((x, x), |(lo, hi)| (lo.min(x), hi.max(x))));
            }
        }
        e
    }

    /// Whether `c` is covered: dwelt in at least [`MIN_DWELL_S`].
    pub fn covers(&self, c: Cell) -> bool {
        self.dwell_s.get(&c).is_some_and(|&s| s >= MIN_DWELL_S)
    }

    /// The covered cells, in order.
    pub fn covered(&self) -> Vec<Cell> {
        self.dwell_s.keys().copied().filter(|&c| self.covers(c)).collect()
    }

    /// Compact text: per pressure band, the covered speed ranges (adjacent
    /// cells merged), e.g. `Δp 15–25 bar: 250–1250 rpm`; then the drain range.
    pub fn describe(&self) -> String {
        let mut rows: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
        for c in self.covered() {
            rows.entry(c.dp).or_default().push(c.speed);
        }
        let mut parts: Vec<String> = rows
            .iter()
            .map(|(&dp, speeds)| {
                let mut runs: Vec<(u32, u32)> = Vec::new();
                for &s in speeds {
                    match runs.last_mut() {
                        Some(r) if r.1 + 1 == s => r.1 = s,
                        _ => runs.push((s, s)),
                    }
                }
                let sp = runs.iter().map(|&(a, b)| format!("{:.0}–{:.0}", edge(a, SPEED_CELL_RPM, SPEED_EDGE_RPM), edge(b + 1, SPEED_CELL_RPM, SPEED_EDGE_RPM))).collect::<Vec<_>>().join(", ");
                format!("Δp {}–{} bar: {sp} rpm", edge(dp, DP_CELL_BAR, DP_EDGE_BAR), edge(dp + 1, DP_CELL_BAR, DP_EDGE_BAR))
            })
            .collect();
        if parts.is_empty() {
            parts.push(format!("no cell dwelt in for {MIN_DWELL_S:.0} s"));
        }
        let drain = self.drain_c.map_or("no drain or oil temperature".into(), |(a, b)| format!("drain {a:.1}–{b:.1} °C"));
        format!("{}; {drain}", parts.join("; "))
    }

    /// `errors` split by this envelope: inside (covered cells) and outside.
    pub fn split(&self, errors: &CellErrors) -> (Side, Side) {
        let (inside, outside): (Vec<_>, Vec<_>) = errors.0.iter().partition(|(c, _)| self.covers(**c));
        (Side::of(&inside), Side::of(&outside))
    }
}

/// The firmware's drain error against the measured drain in one cell.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CellError {
    /// Time the replay spends in the cell, s.
    pub dwell_s: f64,
    /// Of it, time scored against the measured drain, s.
    pub scored_s: f64,
    /// Largest |estimate − measured| drain there, K (0 when not scored).
    pub max_abs_k: f64,
    /// Largest under-prediction (measured − estimate) there, K (−∞ when
    /// not scored).
    pub max_under_k: f64,
    /// The ticks within half of `max_under_k` (when it is positive): where
    /// the cell reads low.
    pub low: Option<Region>,
}

/// The firmware's drain error of one check per grid cell.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CellErrors(pub BTreeMap<Cell, CellError>);

impl CellErrors {
    /// From one replay's ticks `rows` (t s, |speed| rpm, |Δp| bar,
    /// reference drain °C), each `dt_s` long, and the under-prediction of
    /// the measured drain at each (K, −∞ or NaN where not scored).
    /// Ticks with a non-finite speed or Δp are skipped.
    pub fn from_ticks(rows: &[TickRow], under: &[f64], dt_s: f64, servo: bool) -> Self {
        let mut m: BTreeMap<Cell, CellError> = BTreeMap::new();
        let cells: Vec<Option<Cell>> = rows.iter().map(|r| cell_of(r.1, r.2)).collect();
        for (c, &u) in cells.iter().zip(under) {
            let Some(c) = c else { continue };
            let e = m.entry(*c).or_insert(CellError { dwell_s: 0.0, scored_s: 0.0, max_abs_k: 0.0, max_under_k: f64::NEG_INFINITY, low: None });
            e.dwell_s += dt_s;
            if u.is_finite() {
                e.scored_s += dt_s;
                e.max_abs_k = e.max_abs_k.max(u.abs());
                e.max_under_k = e.max_under_k.max(u);
            }
        }
        for ((c, &u), r) in cells.iter().zip(under).zip(rows) {
            let Some(e) = c.and_then(|c| m.get_mut(&c)) else { continue };
            if e.max_under_k > 0.0 && u >= 0.5 * e.max_under_k {
                e.low.get_or_insert(Region::empty(servo)).widen(r);
            }
        }
        CellErrors(m)
    }
}

/// One side (inside or outside the envelope) of a check's drain errors.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Side {
    /// Time spent on this side, s.
    pub dwell_s: f64,
    /// Of it, time scored against the measured drain, s.
    pub scored_s: f64,
    /// Largest |estimate − measured| drain, K (`None`: nothing scored).
    pub max_abs_k: Option<f64>,
    /// Largest under-prediction of the measured drain, K (`None`: nothing scored).
    pub max_under_k: Option<f64>,
    /// Where this side reads low: the cells whose under-prediction is at
    /// least half of `max_under_k` (when positive), their ticks within half
    /// of each cell's largest.
    pub low: Option<Region>,
    /// Time spent in those cells, s.
    pub low_dwell_s: f64,
}

impl Side {
    fn of(cells: &[(&Cell, &CellError)]) -> Self {
        let scored: Vec<&CellError> = cells.iter().map(|c| c.1).filter(|e| e.scored_s > 0.0).collect();
        let max_abs_k = scored.iter().map(|e| e.max_abs_k).reduce(f64::max);
        let max_under_k = scored.iter().map(|e| e.max_under_k).reduce(f64::max);
        let (mut low, mut low_dwell_s) = (None::<Region>, 0.0);
        for e in cells.iter().map(|c| c.1) {
            let (Some(top), Some(g)) = (max_under_k, &e.low) else { continue };
            if top > 0.0 && e.max_under_k >= 0.5 * top {
                low_dwell_s += e.dwell_s;
                low.get_or_insert(Region::empty(g.servo)).join(g);
            }
        }
        Side { dwell_s: cells.iter().map(|c| c.1.dwell_s).sum(), scored_s: scored.iter().map(|e| e.scored_s).sum(), max_abs_k, max_under_k, low, low_dwell_s }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run sampled every 1 s over `n` rows with speed, p_a, p_b and drain
    /// from `f(t)`.
    fn run(n: usize, f: impl Fn(f64) -> (Option<f64>, Option<f64>, Option<f64>, Option<f64>)) -> MeasuredRun {
        let t: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let rows: Vec<_> = t.iter().map(|&t| f(t)).collect();
        let mut r = MeasuredRun::new(t);
        r.set(Channel::SpeedRpm, rows.iter().map(|x| x.0).collect());
        r.set(Channel::PABar, rows.iter().map(|x| x.1).collect());
        r.set(Channel::PBBar, rows.iter().map(|x| x.2).collect());
        r.set(Channel::TDrainC, rows.iter().map(|x| x.3).collect());
        r
    }

    #[test]
    fn known_dwell_gives_known_cells_signs_ignored_and_bad_rows_skipped() {
        // 0–300 s at 700 rpm, Δp +20 bar (10 s of empty speed and one NaN
        // p_a row inside); 300–330 s at 1000 rpm, 40 bar (a pass: 30 s);
        // 330–599 s at −420 rpm, Δp −30 bar (reversed pump, 269 s: the last
        // row has no next row to credit).
        let r = run(600, |t| {
            let (n, pa, pb) = if t < 300.0 { (700.0, 25.0, 5.0) } else if t < 330.0 { (1000.0, 45.0, 5.0) } else { (-420.0, 5.0, 35.0) };
            let n = (!(100.0..110.0).contains(&t)).then_some(n);
            let pa = if t == 120.0 { f64::NAN } else { pa };
            let drain = if t == 50.0 { Some(f64::NAN) } else { (t != 60.0).then_some(20.0 + t / 20.0) };
            (n, Some(pa), Some(pb), drain)
        });
        let e = Envelope::of_runs([&r]);
        let a = Cell { speed: 4, dp: 2 };
        let b = Cell { speed: 5, dp: 4 };
        let c = Cell { speed: 2, dp: 3 };
        assert_eq!(e.dwell_s.len(), 3);
        assert!((e.dwell_s[&a] - 289.0).abs() < 1e-9, "{:?}", e.dwell_s);
        assert!((e.dwell_s[&b] - 30.0).abs() < 1e-9);
        assert!((e.dwell_s[&c] - 269.0).abs() < 1e-9);
        assert_eq!(e.covered(), vec![c, a], "the 30 s pass does not cover its cell");
        assert_eq!(e.drain_c, Some((20.0, 20.0 + 599.0 / 20.0)));
        assert_eq!(e.describe(), "Δp 15–25 bar: 650–850 rpm; Δp 25–35 bar: 250–450 rpm; drain 20.0–50.0 °C");
        assert_eq!((cell_of(49.0, 4.9), cell_of(50.0, 5.0)), (Some(Cell { speed: 0, dp: 0 }), Some(Cell { speed: 1, dp: 1 })));
        assert_eq!(cell_of(-750.0, -22.0), cell_of(750.0, 22.0));
        assert_eq!(cell_of(f64::NAN, 1.0), None);
    }

    #[test]
    fn empty_logs_give_an_empty_envelope() {
        let e = Envelope::of_runs(std::iter::empty());
        assert!(e.covered().is_empty() && e.drain_c.is_none());
        assert_eq!(e.describe(), "no cell dwelt in for 60 s; no drain or oil temperature");
        let e = Envelope::of_runs([&MeasuredRun::new(Vec::new()), &run(1, |_| (Some(700.0), Some(20.0), Some(0.0), None))]);
        assert!(e.dwell_s.is_empty() && e.drain_c.is_none());
        // No error rows: both sides empty.
        let (i, o) = e.split(&CellErrors::default());
        assert_eq!((i.dwell_s, o.max_under_k, o.low), (0.0, None, None));
    }

    #[test]
    fn errors_split_inside_and_outside_the_envelope() {
        let e = Envelope::of_runs([&run(200, |_| (Some(700.0), Some(25.0), Some(5.0), Some(30.0)))]);
        // 100 ticks of 1 s inside reading 0.1 K low, 50 outside (1000 rpm,
        // 45 bar) reading up to 0.6 K low at t 120–129 s, 5 not scored,
        // 2 with a NaN speed (skipped).
        let mut rows = Vec::new();
        let mut under = Vec::new();
        for k in 0..157 {
            let t = f64::from(k);
            let (n, dp, u) = match k {
                0..100 => (700.0, 20.0, 0.1),
                100..150 => (1000.0, 45.0, if (120..130).contains(&k) { 0.6 } else { 0.2 }),
                150..155 => (1000.0, 45.0, f64::NEG_INFINITY),
                _ => (f64::NAN, 45.0, 5.0),
            };
            rows.push((t, n, dp, 50.0));
            under.push(u);
        }
        let ce = CellErrors::from_ticks(&rows, &under, 1.0, false);
        let (i, o) = e.split(&ce);
        assert_eq!((i.dwell_s, i.scored_s, i.max_under_k), (100.0, 100.0, Some(0.1)));
        assert_eq!((o.dwell_s, o.scored_s, o.max_under_k, o.max_abs_k), (55.0, 50.0, Some(0.6), Some(0.6)));
        let g = o.low.expect("outside reads low");
        assert_eq!((g.t_s, g.speed_rpm, g.dp_bar, o.low_dwell_s), ((120.0, 129.0), (1000.0, 1000.0), (45.0, 45.0), 55.0));
    }
}
