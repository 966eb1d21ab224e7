//! Golden output of one deterministic firmware run, diffed like rtic's
//! `ci/expected/*.run`: the f32 firmware in QEMU on the drill sequence of
//! `eha_sim::pil::drill`.
//!
//! The transcript holds the tick replies every 10 s and at every change of valve,
//! alarm or faults (4 decimals), the final counters and the decoded defmt
//! log; no instruction counts (those are checked against budgets by
//! `eha-sim fw-budget`, so a compiler update does not force a re-bless). After an intended change of the firmware,
//! regenerate with `PIL_BLESS=1 cargo test --profile fast -p eha-sim --test pil golden`
//! and review the diff in git.

use std::path::PathBuf;

use eha_sim::pil::report::open_loop_transcript;
use eha_sim::pil::{drill, firmware_for_tests, require_qemu, run_open_loop, Build, QemuOptions};

#[test]
fn f32_drill_matches_golden_output() {
    require_qemu();
    let elf = firmware_for_tests(Build::F32);
    let q = QemuOptions::new(Build::F32, &elf);
    let run = run_open_loop(&q, &drill::requests()).unwrap_or_else(|e| panic!("{e:#}"));
    let got = open_loop_transcript(&run, eha_guard::params::S_PER_TICK, 1000);
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/pil/expected/pil_drill_f32.run");
    if std::env::var_os("PIL_BLESS").is_some() {
        std::fs::write(&path, &got).unwrap();
        eprintln!("blessed {}", path.display());
        return;
    }
    let want = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (create it with PIL_BLESS=1)", path.display()));
    if got != want {
        let actual = path.with_extension("run.actual");
        let _ = std::fs::write(&actual, &got);
        let first = got.lines().zip(want.lines()).position(|(a, b)| a != b);
        panic!(
            "PIL output differs from {} (first differing line {:?}); actual output written to {}; diff them, and bless with PIL_BLESS=1 if the change is intended",
            path.display(),
            first.map(|i| i + 1),
            actual.display()
        );
    }
    eprintln!("golden output matches ({} lines, wall {:.2} s)", got.lines().count(), run.wall.as_secs_f64());
}
