//! `eha-sim commission` end to end: outputs, exit codes, bad-log errors.

use eha_sim::calibration::synthetic::{log, mission, other_rig_file, other_rig_truth, Kind};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_eha-sim"))
}

/// The other-rig missions of `commission.rs` through the command line,
/// 900 s each (the contract, not the accuracy: half the 1800 s of
/// `commission.rs`; 24 s on a quiet machine, 39 s with the 1800 s
/// logs measured beside another job): the reduced
/// model holds the 0.2 K bound, so it exits 0 and writes rig.toml,
/// params.rs, report.md, the held-out PNG and `firmware-params.bin`, which
/// `commission --check` accepts.
#[test]
fn commission_cli_writes_outputs_and_a_block_that_checks() {
    let dir = std::env::temp_dir().join(format!("eha-commission-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let truth = other_rig_truth();
    for (name, kind, seed) in [("a.csv", Kind::PressureSteps, 31), ("b.csv", Kind::SpeedSteps, 32), ("d.csv", Kind::CoolingSteps, 34), ("c.csv", Kind::SoakThenMixed, 33)] {
        log(&truth, &mission(kind, 900.0, seed), 2.0, seed, true).expect("log").write_file(dir.join(name)).expect("write");
    }
    std::fs::write(dir.join("rig.toml"), other_rig_file().to_toml()).expect("rig");
    let out = dir.join("out");
    let o = bin()
        .args(["commission", "--rig"]).arg(dir.join("rig.toml"))
        .arg("--train").arg(dir.join("a.csv")).arg(dir.join("b.csv")).arg(dir.join("d.csv"))
        .arg("--holdout").arg(dir.join("c.csv"))
        .arg("--out").arg(&out)
        .output().expect("run");
    let err = String::from_utf8_lossy(&o.stderr);
    eprintln!("{}\n{err}", String::from_utf8_lossy(&o.stdout));
    assert_eq!(o.status.code(), Some(0), "the reduced model holds: {err}");
    for f in ["rig.toml", "params.rs", "report.md", "holdout-c.png", "firmware-params.bin"] {
        assert!(out.join(f).exists(), "{f} written");
    }
    let chk = bin().args(["commission", "--check"]).arg(out.join("firmware-params.bin")).output().expect("run");
    eprintln!("{}{}", String::from_utf8_lossy(&chk.stdout), String::from_utf8_lossy(&chk.stderr));
    assert_eq!(chk.status.code(), Some(0), "the written block passes the firmware's boot checks");
    let report = std::fs::read_to_string(out.join("report.md")).expect("report");
    assert!(report.contains("Headline") && report.contains("c.csv"), "headline on the held-out log");
    // The drain margin from the split of the training missions, with its cost.
    assert!(report.contains("## Drain margin") && report.contains("Margin **") && report.contains("valve open s"), "margin section in the report");
    // ... and the block carries it (`drain_margin_k`, what the guard adds to
    // its estimate): the report's margin, printed to 0.01 K, is the block's.
    let num_after = |text: &str, key: &str| -> f64 {
        let rest = &text[text.find(key).unwrap_or_else(|| panic!("`{key}` in {text}")) + key.len()..];
        rest.split_whitespace().next().and_then(|w| w.trim_matches('*').parse().ok()).unwrap_or_else(|| panic!("a number after `{key}`"))
    };
    let in_report = num_after(&report, "Margin **");
    let in_block = num_after(&String::from_utf8_lossy(&chk.stdout), "drain margin ");
    assert!(in_report > 0.0 && (in_block - in_report).abs() <= 0.006, "block margin {in_block} K, report {in_report} K");
    // The training envelope and the held-out log's error inside/outside it.
    assert!(report.contains("## Training envelope") && report.contains("rpm") && report.contains("| c.csv | held out |"), "envelope section in the report");
    let params = std::fs::read_to_string(out.join("params.rs")).expect("params");
    assert!(params.contains("pub const DEFAULT: ReducedParams"), "params.rs renders the firmware parameters");
    // A bad value: file:line:column from the reader, exit 2.
    let text = std::fs::read_to_string(dir.join("a.csv")).expect("a");
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let k = lines.iter().position(|l| !l.starts_with('#')).expect("header") + 3;
    let mut cells: Vec<String> = lines[k].split(',').map(String::from).collect();
    cells[1] = "fast".into();
    lines[k] = cells.join(",");
    std::fs::write(dir.join("bad.csv"), lines.join("\n") + "\n").expect("bad");
    let o = bin()
        .args(["commission", "--rig"]).arg(dir.join("rig.toml"))
        .arg("--train").arg(dir.join("bad.csv"))
        .arg("--holdout").arg(dir.join("c.csv"))
        .arg("--out").arg(&out)
        .output().expect("run");
    let err = String::from_utf8_lossy(&o.stderr);
    eprintln!("{err}");
    assert_eq!(o.status.code(), Some(2), "bad input");
    assert!(err.contains(&format!("bad.csv:{}", k + 1)), "file:line in {err}");
    let _ = std::fs::remove_dir_all(&dir);
}
