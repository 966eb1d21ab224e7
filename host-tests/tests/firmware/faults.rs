//! The fault campaign (`eha-sim faults`, `eha_sim::faults`) as tests: the
//! product application on the in-memory board in closed loop with the
//! reference plant, every sensor, transport, memory, command and actuator
//! fault in three scenarios at up to three start times (early, after the
//! valve first opened, hot).
//!
//! Pass rule: whenever the guard is not protecting (a latched
//! fault with the valve commanded open, or the estimate untrusted), its
//! estimate is at most 1 K below the true drain and the true drain at most
//! 42 °C with the valve closed; a protected detection within 1 s exempts
//! the time before it. A failing run must be a listed design limit
//! (`eha_sim::faults::limits::KNOWN_LIMITS`, with its reason).
//!
//! Fast tier: a representative subset (about 20 runs, one per kind of fault,
//! the hot starts and the faults of the product loop's safety review). Slow tier: the whole
//! campaign (751 runs, ~1.5 min on two cores), which also checks that every
//! listed limit still fails somewhere, that with the drive's electrical
//! frequency no speed fault fails, and that `docs/failure-modes.md` is the
//! table generated from this run.

use eha_sim::faults::limits::KNOWN_LIMITS;
use eha_sim::faults::{campaign, fast_campaign, modes, table, unlisted_failures, write, FaultResult};

fn report(rows: &[FaultResult], dir: &str) {
    println!("{}", table(rows));
    let out = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(dir);
    write(&out, rows).expect("write the results");
    let pass = rows.iter().filter(|r| r.pass).count();
    let limited = rows.iter().filter(|r| !r.pass && r.limit.is_some()).count();
    println!("{} runs: {pass} pass, {limited} listed design limits", rows.len());
}

#[test]
fn fault_campaign_subset_passes_except_the_listed_design_limits() {
    let rows = fast_campaign().expect("campaign runs");
    report(&rows, "out/faults-fast");
    let bad = unlisted_failures(&rows);
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    // the subset's faults of the safety review are not limits: they pass
    for f in ["clear-spam", "corrupt-start-clear", "flash-write-fail", "flash-read-fail", "power-loss", "warm-reset", "no-valve-feedback", "lng-empty-physical+supply"] {
        assert!(rows.iter().filter(|r| r.fault == f).all(|r| r.pass), "{f}: {:?}", rows.iter().find(|r| r.fault == f));
    }
}

#[test]
#[ignore = "slow tier: the whole fault campaign (751 runs)"]
fn slow_fault_campaign_passes_except_the_listed_design_limits() {
    let rows = campaign().expect("campaign runs");
    report(&rows, "out/faults");
    let mut problems = unlisted_failures(&rows);
    for l in KNOWN_LIMITS {
        let covers = |r: &&FaultResult| r.fault == l.fault && l.scenario.is_none_or(|s| s == r.scenario) && l.start.is_none_or(|s| s == r.start);
        if !rows.iter().filter(covers).any(|r| !r.pass) {
            problems.push(format!("{} ({:?}, {:?}) is listed as a design limit but every run of it passes: remove it", l.fault, l.scenario, l.start));
        }
    }
    // with the second speed source no speed fault fails
    for r in rows.iter().filter(|r| r.fault.starts_with("speed/") && !r.fault.contains("+no-elec")) {
        if !r.pass {
            problems.push(format!("{} / {} / {} fails with the electrical frequency", r.fault, r.scenario, r.start));
        }
    }
    // the committed results (docs/data/faults.json, which docs/failure-modes.md
    // is rendered from) give this run's table
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/data/faults.json");
    let committed: Vec<FaultResult> = serde_json::from_str(&std::fs::read_to_string(&data).unwrap_or_default()).unwrap_or_default();
    let this_run: Vec<FaultResult> = serde_json::from_str(&eha_sim::faults::data_json(&rows).expect("serialises")).expect("parses");
    if modes::document(&committed) != modes::document(&this_run) {
        problems.push("docs/data/faults.json is not this run's: commit it with `eha-sim faults --from out/faults/faults.json`".into());
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
