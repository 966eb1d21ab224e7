//! What a floor projection says, in words: the candidates a log can
//! show and from which size, the confusable pairs, the one-line summary
//! and the Markdown section of `report.md`.

use super::{FloorDetectability, ProjectedRow, CONFUSABLE_DEG, SHOWABLE_RATIO};
use std::fmt::Write as _;

impl FloorDetectability {
    /// Per candidate, the smallest magnitude tried whose expected ratio
    /// reaches [`SHOWABLE_RATIO`] (with its channel), or `None`.
    pub fn showable(&self) -> Vec<(String, Option<&ProjectedRow>)> {
        let mut out: Vec<(String, Option<&ProjectedRow>)> = Vec::new();
        for r in &self.rows {
            match out.iter_mut().find(|(c, _)| *c == r.candidate) {
                Some((_, first @ None)) if r.best.1 >= SHOWABLE_RATIO => *first = Some(r),
                Some(_) => {}
                None => out.push((r.candidate.clone(), (r.best.1 >= SHOWABLE_RATIO).then_some(r))),
            }
        }
        out
    }

    /// Pairs whose projected imprints are closer than [`CONFUSABLE_DEG`].
    pub fn confusable_pairs(&self) -> Vec<(String, String, f64)> {
        let c = &self.confusability;
        let mut out = Vec::new();
        for i in 0..c.candidates.len() {
            for j in i + 1..c.candidates.len() {
                let a = c.angle_deg[i][j];
                if a < CONFUSABLE_DEG {
                    out.push((c.candidates[i].clone(), c.candidates[j].clone(), a));
                }
            }
        }
        out
    }

    /// One line: what this log can show, from which size, and what it
    /// confuses.
    pub fn summary(&self) -> String {
        let (mut shown, mut hidden) = (Vec::new(), Vec::new());
        for (c, r) in self.showable() {
            match r {
                Some(r) => {
                    let mag = r.magnitude.first().map_or(String::new(), |(_, v, u)| format!(" from {v:.3e} {u}"));
                    shown.push(format!("{c}{mag} (r̂ {:.1} on {})", r.best.1, r.best.0));
                }
                None => hidden.push(c),
            }
        }
        let pairs: Vec<String> = self.confusable_pairs().iter().map(|(a, b, d)| format!("{a}/{b} ({d:.0}°)")).collect();
        format!(
            "against the structure floor, this log can show (expected r ≥ {SHOWABLE_RATIO}): {}; at no size tried: {}; confusable (< {CONFUSABLE_DEG}°): {}",
            if shown.is_empty() { "nothing".into() } else { shown.join(", ") },
            if hidden.is_empty() { "–".into() } else { hidden.join(", ") },
            if pairs.is_empty() { "–".into() } else { pairs.join(", ") }
        )
    }

    /// The Markdown section of `report.md`.
    pub fn markdown(&self) -> String {
        let mut s = String::from(
            "\n## What this log can show against its structure floor\n\n\
             Each candidate's imprint (the calibrated model with it on, minus without) projected off the span of the \
             calibration parameters' sensitivities (fitted on the training window, priors as ridge); what is left on the \
             held-out window is compared per channel with the floor of that channel when the candidate is judged. \
             Expected imprint ratio r̂ = √(floor² + left²)/floor; a cause must be named at r ≥ 2. Linearised: an estimate, \
             not a bound.\n\n\
             | candidate | magnitude | effect's channel | imprint (K) | left (K) | floor (K) | r̂ |\n|---|---|---|---:|---:|---:|---:|\n",
        );
        for r in &self.rows {
            let mag: Vec<String> = r.magnitude.iter().map(|(n, v, u)| format!("{n}={v:.3e} {u}")).collect();
            let Some(c) = r.channels.iter().find(|c| c.channel == r.best.0) else { continue };
            let _ = writeln!(s, "| `{}` | {} | {} | {:.3} | {:.3} | {:.3} | {:.2} |", r.candidate, mag.join(", "), c.channel, c.imprint_k, c.left_k, c.floor_k, c.ratio);
        }
        let c = &self.confusability;
        let _ = write!(s, "\nAngles between the projected imprints (largest magnitude tried; 0° = the log cannot tell them apart):\n\n| |");
        for n in &c.candidates {
            let _ = write!(s, " {n} |");
        }
        let _ = write!(s, "\n|---|{}\n", "---:|".repeat(c.candidates.len()));
        for (i, n) in c.candidates.iter().enumerate() {
            let _ = write!(s, "| {n} |");
            for a in &c.angle_deg[i] {
                let _ = if a.is_nan() { write!(s, " – |") } else { write!(s, " {a:.0}° |") };
            }
            s.push('\n');
        }
        let _ = writeln!(s, "\n{}.", self.summary());
        s
    }
}
