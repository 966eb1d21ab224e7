//! One calibration replay (`CalLog::simulate`, the reference plant at the
//! replay tolerance) of a synthetic 30 min log, for instruction counts of a
//! change to the reference's right-hand side (docs/commissioning-time.md):
//!
//! ```sh
//! cargo build --profile fast -p eha-sim --example replay_count
//! valgrind --tool=callgrind --toggle-collect='eha_sim::calibration::log::CalLog::simulate' target/fast/examples/replay_count
//! ```
//!
//! `REPS` (default 1): replays of the log.
use eha_sim::calibration::synthetic::{log, mission, other_rig_file, other_rig_truth, Kind};
use eha_sim::calibration::CalLog;

fn main() {
    let reps: usize = std::env::var("REPS").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    let run = log(&other_rig_truth(), &mission(Kind::PressureSteps, 1800.0, 31), 2.0, 31, true).expect("log");
    let l = CalLog::new("PressureSteps-31", run, 120).expect("cal log");
    let rig = other_rig_file();
    let mut sum = 0.0;
    for _ in 0..reps {
        let s = l.simulate(&rig).expect("replay");
        sum += l.residuals(&s).iter().map(|x| x * x).sum::<f64>();
    }
    println!("{reps} replays, sum of squared residuals {sum:.17e}");
}
