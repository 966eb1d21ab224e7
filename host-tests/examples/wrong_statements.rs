//! The stated probabilities of the stored emulator sweeps (docs/data/),
//! counted as the reliability table counts them
//! (`diagnosis::emu_tables::statements`): every statement at P ≥ 0.99 that
//! is wrong, with the log's imprint ratio r, its answer, whether any
//! candidate passed the held-out checks (prior > 0) and the hidden effect's
//! own candidate's ln Bayes factor against `none`; then the re-statement
//! "the gate's rejection as an observation with miss rate 1" (a rejected
//! candidate keeps its prior, no Bayes factor; `none` + `unexplained` then
//! 0.5 / (0.5 + Σ priors)) on the logs where no candidate passed: its
//! "no cause" statements, stated → observed, per set.
//!
//! `cargo run --profile fast -p eha-sim --example wrong_statements` (reads
//! the JSON only, < 1 s).

use eha_sim::diagnosis::emu_result::EmuResult;
use eha_sim::diagnosis::emu_tables::statements;
use eha_sim::diagnosis::report::ProbabilityJson;
use std::collections::BTreeMap;

/// Whether `p` names a candidate (not `none` nor `unexplained`).
fn candidate(p: &ProbabilityJson) -> bool {
    p.cause != "none" && p.cause != "unexplained"
}

fn main() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/data");
    let read = |f: &str| std::fs::read_to_string(dir.join(f)).expect("stored sweep");
    let ratios: BTreeMap<String, f64> = serde_json::from_str(&read("imprint-ratios-no-case-held.json")).expect("ratios");
    let sets = [
        ("1700s/2700s", "emulator-sweep-hidden-no-case-held.json"),
        ("1800–1817", "emulator-sweep-1800.json"),
        ("2800–2817", "emulator-sweep-2800.json"),
    ];
    for (label, file) in sets {
        let rows: Vec<EmuResult> = serde_json::from_str(&read(file)).expect("records");
        println!("{label} ({file}):");
        // (stated, right, right with r < 2 as no cause) of the re-statement
        let mut bound: Vec<(f64, bool, bool)> = Vec::new();
        for r in &rows {
            let ratio = r.twin.as_ref().map(|t| t.ratio()).or_else(|| ratios.get(&r.case.seed.to_string()).copied());
            let mut logs = vec![(r.case.seed.to_string(), r.case.hidden.name(), ratio, &r.probabilities, r.answer.as_str())];
            if let Some(t) = r.twin.as_ref().filter(|t| !t.twin_probabilities.is_empty()) {
                logs.push((format!("{}'s twin", r.case.seed), "none", None, &t.twin_probabilities, t.twin_answer.as_str()));
            }
            for (name, truth, ratio, probs, answer) in logs {
                let truth_st = if truth == "none" { "no cause" } else { truth };
                let faint = ratio.is_some_and(|x| x < 2.0);
                let admitted = probs.iter().any(|p| candidate(p) && p.prior > 0.0);
                for (s, p) in statements(probs) {
                    if p >= 0.99 && s != truth_st {
                        let own = probs.iter().find(|p| p.cause == truth).map_or(f64::NAN, |p| p.log_bayes_factor);
                        println!(
                            "  {name:>12} hidden {truth:<31} r {} | states {s} at P {p:.4} | answer {answer} | a candidate admitted: {admitted} | own candidate ln B {own:.1} | {}",
                            ratio.map_or("–".to_string(), |x| format!("{x:.2}")),
                            if faint { "right by the judging rule (r < 2)" } else { "wrong by the judging rule too" }
                        );
                    }
                }
                if !admitted {
                    let rejected: f64 = probs.iter().filter(|p| candidate(p)).count() as f64 / 12.0;
                    let ok = truth == "none";
                    bound.push((0.5 / (0.5 + rejected), ok, ok || faint));
                }
            }
        }
        let n = bound.len() as f64;
        println!(
            "  miss rate 1 re-statement: {} \"no cause\" statements at {:.2}, observed {:.0} % ({:.0} % with r < 2 as no cause)",
            bound.len(),
            bound.first().map_or(f64::NAN, |b| b.0),
            100.0 * bound.iter().filter(|b| b.1).count() as f64 / n,
            100.0 * bound.iter().filter(|b| b.2).count() as f64 / n
        );
    }
}
