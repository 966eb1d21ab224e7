//! A plan for the reader: its warning when no mission makes the
//! candidates showable, its Markdown, and the leading candidates of a
//! diagnosis that a plan is asked for. Separate because it is output,
//! not the search.

use super::Plan;
use crate::diagnosis::model::Candidate;
use std::fmt::Write as _;

impl Plan {
    /// A note when no candidate the diagnosis could name on the planned run
    /// is expected to reach r ≥ 2 there: the family cannot make them
    /// showable on this machine.
    pub fn warning(&self) -> Option<String> {
        let best = self.expected.iter().filter(|e| e.refused.is_none()).map(|e| e.planned.best.1).fold(1.0, f64::max);
        (best < crate::diagnosis::projection::SHOWABLE_RATIO).then(|| {
            format!(
                "no candidate is expected to reach r {} on the planned run (largest r̂ {best:.2}): the calibration absorbs their imprints on every mission of the family, or the diagnosis could not name them there",
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
             | candidate | magnitude | r̂ on the log | r̂ planned | channel | r̂ planned, separated | nameable on the planned run |\n|---|---|---:|---:|---|---:|---|\n",
        );
        for e in &self.expected {
            let mag: Vec<String> = e.planned.magnitude.iter().map(|(n, v, u)| format!("{n}={v:.3e} {u}")).collect();
            let _ = writeln!(
                s,
                "| `{}` | {} | {} | {:.2} | {} | {:.2} | {} |",
                e.planned.candidate,
                mag.join(", "),
                e.on_log.as_ref().map_or("–".into(), |r| format!("{:.2} ({})", r.best.1, r.best.0)),
                e.planned.best.1,
                e.planned.best.0,
                e.planned_separated,
                e.refused.as_ref().map_or("yes".into(), |w| format!("no: {w}"))
            );
        }
        if let Some(w) = self.warning() {
            let _ = writeln!(s, "\n**Note:** {w}.");
        }
        let names: Vec<&str> = self.expected.iter().map(|e| e.planned.candidate.as_str()).collect();
        let _ = write!(
            s,
            "\nThe family (two or three levels in turn; chosen: the most candidates at r̂ ≥ 2, then the others closest to it, then D_s; \
             r̂ per candidate in the order {}; largest predicted temperature; within the limits):\n\n| mission | r̂ | D_s | max T (°C) | admissible |\n|---|---|---:|---:|---|\n",
            names.join(", ")
        );
        for f in &self.family {
            let r: Vec<String> = f.expected_ratio.iter().map(|r| format!("{r:.2}")).collect();
            let _ = writeln!(s, "| {} | {} | {:.3} | {:.1} | {} |", f.name, r.join(" / "), f.d_s, f.max_temp_c, if f.admissible { "yes" } else { "no" });
        }
        s
    }
}

/// Probability below which no candidate leads: a log whose candidates all
/// stay under it admitted none, and a plan is made for every candidate.
pub const LEADING_MIN_P: f64 = 0.05;

/// The leading candidates of a diagnosis a throttle-circuit plan can
/// excite: the `n` most probable, ties (a candidate the log could not admit
/// has probability 0) broken by the Bayes factor against `none`; **every**
/// such candidate when none reaches [`LEADING_MIN_P`]: the Bayes factors of
/// candidates the log could not admit do not point at the cause (measured
/// on the original emulator set's five throttle logs below r = 2: the
/// hidden cause first by them on one, 2026-11-29). `causes` is (cause,
/// probability, ln Bayes factor), as `diagnosis.json`'s `probabilities`
/// lists them.
pub fn leading(causes: &[(String, f64, f64)], n: usize) -> Vec<Candidate> {
    let mut c: Vec<(Candidate, f64, f64)> = causes
        .iter()
        .filter_map(|(name, p, bf)| Some((Candidate::from_name(name)?, *p, if bf.is_finite() { *bf } else { f64::NEG_INFINITY })))
        .filter(|(c, _, _)| *c != Candidate::None && *c != Candidate::CoulombFriction)
        .collect();
    c.sort_by(|a, b| b.1.total_cmp(&a.1).then(b.2.total_cmp(&a.2)));
    let led = c.first().is_some_and(|x| x.1 >= LEADING_MIN_P);
    c.into_iter().take(if led { n } else { usize::MAX }).map(|x| x.0).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A log that admitted a candidate leads with it (and the next by
    /// probability, then Bayes factor); one that admitted none leads
    /// nowhere: every throttle candidate, never Coulomb friction or `none`.
    #[test]
    fn leading_takes_every_candidate_when_the_log_admitted_none() {
        let row = |n: &str, p: f64, b: f64| (n.to_string(), p, b);
        let admitted = [row("none", 0.3, 0.0), row("sensor-lag", 0.7, 9.0), row("churning-loss", 0.0, 4.0), row("forced-convection", 0.0, 5.0), row("coulomb-friction", 0.0, 8.0)];
        assert_eq!(leading(&admitted, 2), [Candidate::SensorLag, Candidate::ForcedConvection]);
        let none = [row("none", 1.0, 0.0), row("winding-resistance-temperature", 0.0, 7.0), row("churning-loss", 0.0, 1.0), row("sensor-lag", 0.0, 2.0), row("motor-pump-conduction", 0.0, 0.5), row("forced-convection", 0.0, -1.0), row("coulomb-friction", 0.0, 9.0)];
        let all = leading(&none, 2);
        assert_eq!(all.len(), 5, "{all:?}");
        assert!(!all.contains(&Candidate::CoulombFriction) && !all.contains(&Candidate::None));
    }
}
