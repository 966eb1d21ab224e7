//! A plan for the reader: its warning when no mission makes the
//! candidates showable, its Markdown, and the leading candidates of a
//! diagnosis that a plan is asked for. Separate because it is output,
//! not the search.

use super::Plan;
use crate::diagnosis::model::Candidate;
use std::fmt::Write as _;

impl Plan {
    /// A note when no candidate is expected to reach r ≥ 2 on the planned
    /// run: the family cannot make them showable on this machine.
    pub fn warning(&self) -> Option<String> {
        let best = self.expected.iter().map(|e| e.planned.best.1).fold(1.0, f64::max);
        (best < crate::diagnosis::projection::SHOWABLE_RATIO).then(|| {
            format!(
                "no candidate is expected to reach r {} on the planned run (largest r̂ {best:.2}): the calibration absorbs their imprints on every mission of the family",
                crate::diagnosis::projection::SHOWABLE_RATIO
            )
        })
    }

    /// `plan.md`: the mission's levels, the expected ratios and the family.
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "# Test plan\n\nMission: {} ({} segments, {:.0} s; `mission.csv`). D_s = {:.3} \
             (det of the candidates' projected information against the floor, per candidate). {}\n\n\
             | segment | start (s) | speed (rpm) | needle drop at that speed (bar) | needle setting at 500 rpm (bar) | ram air (m/s) |\n|---:|---:|---:|---:|---:|---:|\n",
            self.design.name,
            self.design.segments.len(),
            self.design.duration_s,
            self.d_s,
            match self.decision {
                super::Decision::Alone => "Planned for the planned run diagnosed on its own.",
                super::Decision::Joint => {
                    "Planned for the joint decision: diagnose the planned run together with the log \
                     (`eha-sim diagnose LOG planned.csv`, one calibration for both); r̂ planned is on both logs' held-out windows."
                }
            }
        );
        for (k, l) in self.design.segments.iter().enumerate() {
            let _ = writeln!(s, "| {} | {:.0} | {:.0} | {:.1} | {:.2} | {:.1} |", k + 1, k as f64 * self.design.hold_s, l.speed_rpm, l.drop_bar, l.needle_setting_bar(), l.air_mps);
        }
        s.push_str(
            "\nExpected imprint ratio r̂ = √(floor² + left²)/floor on the best channel (left: the candidate's imprint the \
             calibration cannot take up, held out; floor: the user's log's misfit per rise, scaled by the planned rise); \
             a diagnosis must name a cause at r ≥ 2. Separated: with the other candidates fitted along.\n\n\
             | candidate | magnitude | r̂ on the log | r̂ planned | channel | r̂ planned, separated |\n|---|---|---:|---:|---|---:|\n",
        );
        for e in &self.expected {
            let mag: Vec<String> = e.planned.magnitude.iter().map(|(n, v, u)| format!("{n}={v:.3e} {u}")).collect();
            let _ = writeln!(
                s,
                "| `{}` | {} | {} | {:.2} | {} | {:.2} |",
                e.planned.candidate,
                mag.join(", "),
                e.on_log.as_ref().map_or("–".into(), |r| format!("{:.2} ({})", r.best.1, r.best.0)),
                e.planned.best.1,
                e.planned.best.0,
                e.planned_separated
            );
        }
        if let Some(w) = self.warning() {
            let _ = writeln!(s, "\n**Note:** {w}.");
        }
        s.push_str("\nThe family (two levels alternated; D_s, largest predicted temperature, within the limits):\n\n| mission | D_s | max T (°C) | admissible |\n|---|---:|---:|---|\n");
        for f in &self.family {
            let _ = writeln!(s, "| {} | {:.3} | {:.1} | {} |", f.name, f.d_s, f.max_temp_c, if f.admissible { "yes" } else { "no" });
        }
        s
    }
}

/// The leading candidates of a diagnosis a throttle-circuit plan can
/// excite: the `n` most probable, ties (a candidate the log could not admit
/// has probability 0) broken by the Bayes factor against `none`. `causes`
/// is (cause, probability, ln Bayes factor), as `diagnosis.json`'s
/// `probabilities` lists them.
pub fn leading(causes: &[(String, f64, f64)], n: usize) -> Vec<Candidate> {
    let mut c: Vec<(Candidate, f64, f64)> = causes
        .iter()
        .filter_map(|(name, p, bf)| Some((Candidate::from_name(name)?, *p, if bf.is_finite() { *bf } else { f64::NEG_INFINITY })))
        .filter(|(c, _, _)| *c != Candidate::None && *c != Candidate::CoulombFriction)
        .collect();
    c.sort_by(|a, b| b.1.total_cmp(&a.1).then(b.2.total_cmp(&a.2)));
    c.into_iter().take(n).map(|x| x.0).collect()
}
