//! The failure-mode table (`docs/failure-modes.md`), generated from the
//! campaign's results (committed as `docs/data/faults.json`; `eha-sim docs`
//! renders it, CI checks it): for each fault, how the
//! guard detects it, what it does then, how long that takes, and the runs
//! that show it; then every listed design limit with its measured margin.
//! No number in it is typed by hand.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::{FaultResult, DETECT_S, MAX_CLOSED_C, MAX_UNDER_K};

/// The most frequent value of `it` (ties: the first seen).
fn most_common<'a>(it: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let mut n: Vec<(&str, usize)> = Vec::new();
    for v in it {
        match n.iter_mut().find(|(k, _)| *k == v) {
            Some((_, c)) => *c += 1,
            None => n.push((v, 1)),
        }
    }
    let best = n.iter().map(|(_, c)| *c).max()?;
    n.into_iter().find(|(_, c)| *c == best).map(|(k, _)| k)
}

fn run_name(r: &FaultResult) -> String {
    format!("{} / {} ({:.0} s)", r.scenario, r.start, r.start_s)
}

/// The generated part of `docs/failure-modes.md` for `rows` (the
/// campaign's results, committed as `docs/data/faults.json`).
pub fn document(rows: &[FaultResult]) -> String {
    let mut s = String::new();
    let cases: std::collections::BTreeSet<&str> = rows.iter().map(|r| r.fault.as_str()).collect();
    let scen: std::collections::BTreeSet<&str> = rows.iter().map(|r| r.scenario.as_str()).collect();
    let starts: std::collections::BTreeSet<&str> = rows.iter().map(|r| r.start.as_str()).collect();
    let pass = rows.iter().filter(|r| r.pass).count();
    let limited: Vec<&FaultResult> = rows.iter().filter(|r| !r.pass && r.limit.is_some()).collect();
    let failing = rows.len() - pass - limited.len();
    let _ = writeln!(
        s,
        "**{} runs**: {} cases (faults and input variants) × {} scenarios ({}) × up to {} start times ({}); \
         **{pass} pass**, {} are listed design limits, {failing} fail unlisted.\n",
        rows.len(),
        cases.len(),
        scen.len(),
        scen.iter().copied().collect::<Vec<_>>().join(", "),
        starts.len(),
        starts.iter().copied().collect::<Vec<_>>().join(", "),
        limited.len()
    );
    let _ = writeln!(
        s,
        "Pass rule: whenever the guard is not protecting (a latched fault with the valve commanded open, or the \
         estimate untrusted: alarm and derate held), its drain estimate is at most {MAX_UNDER_K} K below the true \
         drain and the true drain at most {MAX_CLOSED_C} °C while the valve is physically closed; a protected \
         detection within {DETECT_S} s exempts the time before it. *Detected by*: the fault-word bits that came up \
         first (most runs); *then*: the outputs at that moment; *time to detect*: from the fault becoming \
         observable, over the runs that detected it.\n"
    );
    let _ = writeln!(s, "| fault | runs | pass | detected by | then | time to detect | worst run (under-prediction unprotected) |");
    let _ = writeln!(s, "|---|---:|---:|---|---|---:|---|");
    let mut by: BTreeMap<&str, Vec<&FaultResult>> = BTreeMap::new();
    for r in rows {
        by.entry(r.fault.as_str()).or_default().push(r);
    }
    for (f, rs) in &by {
        let n = rs.len();
        let p = rs.iter().filter(|r| r.pass).count();
        let l = rs.iter().filter(|r| !r.pass && r.limit.is_some()).count();
        let det: Vec<&&FaultResult> = rs.iter().filter(|r| r.detected).collect();
        let bits = most_common(det.iter().filter_map(|r| r.detect_bits.as_deref())).unwrap_or("not detected");
        let act = most_common(det.iter().filter_map(|r| r.action.as_deref())).unwrap_or("none needed");
        let times: Vec<f64> = det.iter().filter_map(|r| r.detect_s).collect();
        let t = if times.is_empty() {
            "–".to_string()
        } else {
            let lo = times.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = times.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if (hi - lo).abs() < 0.005 {
                format!("{lo:.2} s")
            } else {
                format!("{lo:.2}–{hi:.2} s")
            }
        };
        let det_note = if det.len() < n { format!(" ({} of {n} runs)", det.len()) } else { String::new() };
        let worst = rs.iter().max_by(|a, b| a.max_under_k.total_cmp(&b.max_under_k));
        let w = worst.map_or("–".into(), |r| format!("{}: {:.2} K", run_name(r), r.max_under_k));
        let pass_s = if l > 0 { format!("{p} (+{l} limit)") } else { format!("{p}") };
        let _ = writeln!(s, "| {f} | {n} | {pass_s} | {bits}{det_note} | {act} | {t} | {w} |");
    }
    let _ = writeln!(s, "\n## Listed design limits\n");
    if limited.is_empty() {
        let _ = writeln!(s, "None: every run passes.");
    } else {
        // one block per fault: its reason once, then its failing runs with
        // the margin by which each misses the rule
        let mut by: BTreeMap<&str, Vec<&FaultResult>> = BTreeMap::new();
        for r in &limited {
            by.entry(r.fault.as_str()).or_default().push(r);
        }
        for (f, rs) in by {
            let reason = rs.first().and_then(|r| r.limit.as_deref()).unwrap_or("");
            let _ = writeln!(s, "**{f}** ({} runs): {reason}.\n", rs.len());
            let _ = writeln!(s, "| run | under-prediction, unprotected (bound {MAX_UNDER_K} K) | true drain, valve closed (bound {MAX_CLOSED_C} °C) | detected |");
            let _ = writeln!(s, "|---|---:|---:|---|");
            for r in rs {
                let _ = writeln!(
                    s,
                    "| {} | {:.2} K | {} | {} |",
                    run_name(r),
                    r.max_under_k,
                    r.max_true_drain_closed_c.map_or("–".into(), |c| format!("{c:.2} °C")),
                    match (&r.detect_bits, r.detect_s) {
                        (Some(b), Some(t)) => format!("{b} after {t:.2} s"),
                        _ => "no".into(),
                    }
                );
            }
            let _ = writeln!(s);
        }
    }
    if failing > 0 {
        let _ = writeln!(s, "\n## Failing runs (not listed)\n");
        for r in rows.iter().filter(|r| !r.pass && r.limit.is_none()) {
            let _ = writeln!(s, "- {} — {}: under-prediction {:.2} K, drain closed {:?} °C", r.fault, run_name(r), r.max_under_k, r.max_true_drain_closed_c);
        }
    }
    s
}

