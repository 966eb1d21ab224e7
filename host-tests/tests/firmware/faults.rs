//! The fault campaign (`eha-sim faults`, `eha_sim::faults`) as a test: every
//! sensor, transport, memory and actuator fault, each during the Fig. 15 LNG
//! case and one random mission, in closed loop with the reference plant.
//!
//! Pass rule per fault and scenario (issue "No silent protection failure"):
//! the guard latches a fault and opens the valve within 1 s of the fault
//! becoming observable, or its drain estimate never under-predicts the true
//! drain by more than 1 K and the true drain never exceeds 42 °C while the
//! valve is closed. Faults the design cannot meet are listed in
//! [`KNOWN_FAILING`] with the reason, not removed: the test fails when a
//! listed fault starts passing (update the list and the README) or an
//! unlisted one fails. The table is written to `out/faults/`.

use eha_sim::faults::{campaign, table, write};

const SPEED_UNSEEN: &str = "a speed sensor error is invisible to the torque cross-check: both loss estimates (from the current and from the port pressures) scale with the measured speed, and the pump's heat with the true speed; a second speed source (the motor drive's commutation frequency) would be needed";

const POWER_UNSEEN: &str = "the guard is off for the 60 s of the power loss while the 60 bar load heats the drain (25.1 to 29.9 °C with the normally-open valve open); the restore without a clock reading adds the write policy's margin `rise_k` to the saved record and reads 3.0 K low at power-up (issue 34: in oil below 40 °C the viscous friction is 1.3–2.1 times its 40 °C value, so the unseen heating outgrew the margin); a clock running through the power loss or a margin scaled to the longest unpowered time under load would be needed";

/// (fault, scenario, why the design cannot meet the pass rule). Re-measured
/// with the oil on its viscosity line (issue 34): speed/gain-x0.5 on the LNG
/// case now passes (its under-prediction stays below 1 K), speed/stuck-last and
/// speed/drift on random-1 and the power loss on the LNG case fail.
const KNOWN_FAILING: &[(&str, &str, &str)] = &[
    ("speed/stuck-last", "random-1", SPEED_UNSEEN),
    ("speed/stuck-zero", "lng", SPEED_UNSEEN),
    ("speed/stuck-zero", "random-1", SPEED_UNSEEN),
    ("speed/gain-x0.5", "random-1", SPEED_UNSEEN),
    ("speed/drift", "lng", SPEED_UNSEEN),
    ("speed/drift", "random-1", SPEED_UNSEEN),
    ("power-loss", "lng", POWER_UNSEEN),
];

#[test]
fn fault_campaign_passes_except_the_listed_design_limits() {
    let rows = campaign().expect("campaign runs");
    let md = table(&rows);
    println!("{md}");
    let out = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../out/faults");
    write(&out, &rows).expect("write out/faults");
    let mut problems = Vec::new();
    for r in &rows {
        let listed = KNOWN_FAILING.iter().find(|(f, s, _)| *f == r.fault && *s == r.scenario);
        match (r.pass, listed) {
            (true, Some((_, _, why))) => problems.push(format!("{} / {} now passes (listed as failing: {why})", r.fault, r.scenario)),
            (false, None) => problems.push(format!(
                "{} / {} fails: detected {} after {:?} s, max under {:.3} K, max true drain with the valve closed {:.2} °C",
                r.fault, r.scenario, r.detected, r.detect_s, r.max_under_k, r.max_true_drain_closed_c
            )),
            _ => {}
        }
    }
    for (f, s, _) in KNOWN_FAILING {
        if !rows.iter().any(|r| r.fault == *f && r.scenario == *s) {
            problems.push(format!("{f} / {s} is listed but not in the campaign"));
        }
    }
    let failing = rows.iter().filter(|r| !r.pass).count();
    println!("{} runs, {failing} failing ({} listed)", rows.len(), KNOWN_FAILING.len());
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
