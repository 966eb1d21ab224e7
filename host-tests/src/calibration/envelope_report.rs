//! The commissioning report's training-envelope section: the cells the
//! training logs cover ([`super::envelope`]), each held-out and validation
//! log's firmware drain error inside and outside them, and where the
//! margin is not validated (docs/commissioning.md, "The training
//! envelope").

use super::check::ReducedCheck;
use super::region::Region;
use super::commission::Commissioning;
use super::envelope::{Envelope, Side, DP_CELL_BAR, DP_EDGE_BAR, MIN_DWELL_S, SPEED_CELL_RPM, SPEED_EDGE_RPM};
use std::fmt::Write as _;

/// Start of the line saying that the margin is not validated where a log
/// reads low outside the training envelope.
pub const NOT_VALIDATED: &str = "the margin is not validated in";

/// The operating region of `g` as text: `949–1141 rpm × Δp 35–53 bar`.
fn region_text(g: &Region) -> String {
    format!("{:.0}–{:.0} rpm × Δp {:.0}–{:.0} bar", g.speed_rpm.0, g.speed_rpm.1, g.dp_bar.0, g.dp_bar.1)
}

/// The line saying the margin is not validated where `check` (a held-out
/// log, the block's margin counted) reads low outside `env`: when its
/// under-prediction outside is positive and larger than inside. `None`
/// otherwise.
pub fn not_validated(env: &Envelope, check: &ReducedCheck) -> Option<String> {
    let (inside, outside) = env.split(&check.cells);
    let out = outside.max_under_k?;
    let g = outside.low.as_ref()?;
    (out > inside.max_under_k.unwrap_or(0.0).max(0.0)).then(|| {
        let r = region_text(g);
        format!(
            "{NOT_VALIDATED} {r}: log `{}` spends {:.0} s there (t {:.0}–{:.0} s) and reads {out:.2} K low with the {:.2} K margin; add a bench run that holds {r} to the training logs (measured on the emulator, training there did not by itself remove such a miss: the margin's validation then scores it, docs/commissioning-foreign.md)",
            check.log, outside.low_dwell_s, g.t_s.0, g.t_s.1, check.margin_k
        )
    })
}

/// The [`not_validated`] lines of `c`'s held-out logs (the block's margin
/// counted): the report's and the command line's.
pub fn not_validated_lines(c: &Commissioning) -> Vec<String> {
    c.holdout_with_margin.iter().filter_map(|r| not_validated(&c.envelope, r)).collect()
}

/// A table row of `check` split by `env`.
fn row(s: &mut String, env: &Envelope, kind: &str, check: &ReducedCheck) {
    let (i, o) = env.split(&check.cells);
    let f = |x: Option<f64>| x.map_or("–".into(), |v| format!("{v:.3}"));
    let pair = |d: &Side| format!("{} / {}", f(d.max_abs_k), f(d.max_under_k));
    let low = o.low.as_ref().filter(|_| o.max_under_k.is_some_and(|u| u > 0.0)).map_or("–".into(), |g| format!("{}, t {:.0}–{:.0} s", region_text(g), g.t_s.0, g.t_s.1));
    let _ = writeln!(s, "| {} | {kind} | {:.2} | {:.0} of {:.0} | {} | {} | {low} |", check.log, check.margin_k, o.dwell_s, i.dwell_s + o.dwell_s, pair(&i), pair(&o));
}

/// Writes the section: the envelope, the split table, the lines of
/// [`not_validated`] for the held-out logs.
pub fn envelope_section(s: &mut String, c: &Commissioning) {
    let env = &c.envelope;
    let _ = writeln!(
        s,
        "## Training envelope\n\nCells of {SPEED_CELL_RPM:.0} rpm × {DP_CELL_BAR:.0} bar (|speed| × |p_a − p_b|, edges at {SPEED_EDGE_RPM:.0} + k × {SPEED_CELL_RPM:.0} rpm and {DP_EDGE_BAR:.0} + k × {DP_CELL_BAR:.0} bar) where the training logs dwell ≥ {MIN_DWELL_S:.0} s: {}.\n",
        env.describe()
    );
    let _ = writeln!(s, "Firmware drain against the measured drain inside and outside the envelope (held out: with the block's margin; folds: the margin's validation, margin 0, scored part only):\n\n| log | kind | margin K | s outside (of total) | inside: max \\|e\\| / under K | outside: max \\|e\\| / under K | where it reads low outside |\n|---|---|---:|---:|---:|---:|---|");
    for r in &c.holdout_with_margin {
        row(s, env, "held out", r);
    }
    for r in c.margin.iter().flat_map(|m| &m.folds) {
        row(s, env, "fold", r);
    }
    let lines = not_validated_lines(c);
    if lines.is_empty() {
        let _ = writeln!(s, "\nNo held-out log reads lower outside the envelope than inside it with the margin counted.\n");
    } else {
        let _ = writeln!(s);
        for l in &lines {
            let _ = writeln!(s, "- **{l}.**");
        }
        let _ = writeln!(s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::envelope::CellErrors;
    use crate::measured::{Channel, MeasuredRun};

    /// A held-out check with the margin `margin_k` whose drain errors are
    /// `cells`.
    fn check(cells: CellErrors, margin_k: f64) -> ReducedCheck {
        ReducedCheck { margin_k, cells, ..ReducedCheck::for_test("mix.csv", None) }
    }

    #[test]
    fn the_line_names_the_region_the_time_and_the_miss_only_when_outside_reads_lower() {
        // Trained 300 s at 700 rpm × 20 bar.
        let mut r = MeasuredRun::new((0..300).map(f64::from).collect());
        r.set(Channel::SpeedRpm, vec![Some(700.0); 300]);
        r.set(Channel::PABar, vec![Some(22.0); 300]);
        r.set(Channel::PBBar, vec![Some(2.0); 300]);
        let env = Envelope::of_runs([&r]);
        // Inside 0.05 K low; outside at 970–1028 rpm × 45 bar, 0.4 K low at t 10–19 s.
        let rows: Vec<_> = (0..40).map(|k| (f64::from(k), if k < 10 { 700.0 } else { 950.0 + f64::from(k) * 2.0 }, if k < 10 { 20.0 } else { 45.0 }, 50.0)).collect();
        let under: Vec<f64> = (0..40).map(|k| if k < 10 { 0.05 } else if k < 20 { 0.4 } else { -0.1 }).collect();
        let c = check(CellErrors::from_ticks(&rows, &under, 1.0, false), 0.8);
        let l = not_validated(&env, &c).expect("outside reads lower than inside");
        assert!(l.starts_with(NOT_VALIDATED), "{l}");
        // The 850–1050 rpm × 45–55 bar cell holds ticks 10–39 (30 s).
        assert!(l.contains("970–988 rpm × Δp 45–45 bar: log `mix.csv` spends 30 s there (t 10–19 s) and reads 0.40 K low with the 0.80 K margin"), "{l}");
        // Reading lower inside than outside: no line.
        let under: Vec<f64> = (0..40).map(|k| if k < 10 { 0.5 } else { 0.4 }).collect();
        assert_eq!(not_validated(&env, &check(CellErrors::from_ticks(&rows, &under, 1.0, false), 0.8)), None);
        // Not low anywhere: no line.
        let under = vec![-0.2; 40];
        assert_eq!(not_validated(&env, &check(CellErrors::from_ticks(&rows, &under, 1.0, false), 0.8)), None);
    }
}
