//! Cross-log check of the emulator misses (docs/diagnosis-limits.md, "Why
//! effects above the floor are missed"): calibrate the physical set on one log of an
//! emulated machine, with and without the hidden effect's own candidate,
//! and predict a second log of the same machine in another scenario. Does a
//! second log separate what the calibration set absorbs on one?
//!
//! `cargo run --profile fast -p eha-sim --example cross_log` (~25 s on two
//! cores); prints one Markdown row per pair.

use eha_sim::diagnosis::analysis::{fit_from, fit_points};
use eha_sim::diagnosis::fit::{fit, FitOptions};
use eha_sim::diagnosis::stats::rmse;
use eha_sim::diagnosis::model::{SimSeries, Simulator};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::{Candidate, DiagnoseOptions};
use eha_sim::emulator::missions::EmuScenario::{self, *};
use eha_sim::emulator::{generate, generate_on_machine, EmuCase};
use eha_sim::measured::{Channel, MeasuredRun};
use eha_sim::rig::Rig;
use rayon::prelude::*;

/// RMS of the measured-minus-simulated residuals of `channels` in `run`, K.
fn rmse_over(run: &MeasuredRun, s: &SimSeries, channels: &[Channel]) -> f64 {
    let r: Vec<Option<f64>> = channels
        .iter()
        .filter_map(|&ch| Some(run.get(ch)?.iter().zip(s.channels.get(&ch)?).map(|(m, y)| m.map(|m| y - m))))
        .flatten()
        .collect();
    rmse(&r).unwrap_or(f64::NAN)
}

fn main() {
    let pairs: Vec<(&str, EmuScenario, EmuScenario, u64)> = vec![
        ("winding-resistance-temperature", PressureSpeedSteps, LoadCycles, 1700),
        ("winding-resistance-temperature", LoadCycles, PressureSpeedSteps, 1701),
        ("sensor-lag", ConstantThrottle, SpeedSteps, 1704),
        ("churning-loss", SpeedSteps, PressureSpeedSteps, 1708),
        ("churning-loss", PressureSpeedSteps, SpeedSteps, 1709),
        ("motor-pump-conduction", LoadCycles, SpeedSteps, 1711),
        ("forced-convection", ConstantThrottle, LoadCycles, 1712),
        ("forced-convection", AirSteps, SpeedSteps, 1713),
    ];
    // 13 Jacobians of the 19-parameter physical set: converged fits.
    let opts = FitOptions { max_sims: 260, ..FitOptions::default() };
    let dopts = DiagnoseOptions { fit: opts, ..DiagnoseOptions::default() };
    let rows: Vec<String> = pairs
        .par_iter()
        .map(|&(h, a, b, seed)| {
            let hid = Candidate::from_name(h).expect("emulator case");
            let ca = EmuCase { hidden: hid, scenario: a, seed, duration_s: 1200.0 };
            let cb = EmuCase { hidden: hid, scenario: b, seed: seed + 50, duration_s: 1200.0 };
            let (ra, ta) = generate(&ca).expect("emulator case");
            let (rb, tb) = generate_on_machine(&cb, &ta).expect("emulator case");
            let ma = ReferenceModel::new(Rig::default(), &ra).expect("emulator case");
            let mb = ReferenceModel::new(Rig::default(), &rb).expect("emulator case");
            let sa = ma.physical_set().expect("emulator case");
            let sb = mb.physical_set().expect("emulator case");
            // The whole of log A trains (no held-out window).
            let pts = fit_points(&ra, f64::INFINITY, 150);
            let nom: Vec<f64> = sa.nuisance().iter().map(|p| p.start).collect();
            let base = fit(&*sa, &ra, &pts, Candidate::None, &nom, None, opts).expect("emulator case");
            let c1 = fit_from(&*sa, &ra, &pts, hid, &base, &dopts);
            let c2 = fit(&*sa, &ra, &pts, hid, &nom, None, opts);
            let cand = [c1, c2].into_iter().flatten().min_by(|x, y| x.rss.total_cmp(&y.rss)).expect("emulator case");
            // Map A's calibrated values onto B's set by name (B's extra ones at the rig file).
            let names_a: Vec<String> = sa.nuisance().iter().map(|p| p.name.clone()).collect();
            let to_b = |v: &[f64]| -> Vec<f64> {
                sb.nuisance().iter().map(|p| names_a.iter().position(|n| *n == p.name).map_or(p.start, |k| v[k])).collect()
            };
            let yb0 = sb.simulate(&to_b(&base.nuisance), Candidate::None, &[]).expect("emulator case");
            let yb1 = sb.simulate(&to_b(&cand.nuisance), hid, &cand.ext).expect("emulator case");
            let ch = tb.affected.map(|x| x.0).expect("emulator case");
            let (e0, e1) = (rmse_over(&rb, &yb0, &[ch]), rmse_over(&rb, &yb1, &[ch]));
            let (p0, p1) = (rmse_over(&rb, &yb0, &Channel::TEMPERATURES), rmse_over(&rb, &yb1, &Channel::TEMPERATURES));
            format!(
                "| {h} | {a:?} → {b:?} ({seed}) | train rss {:.1} → {:.1} | ext {:?} (truth {:.3e}) | {} {:.2} → {:.2} ({:.0} %) | pooled {:.2} → {:.2} ({:.0} %) |",
                base.rss,
                cand.rss,
                cand.ext,
                ta.magnitude,
                ch.name(),
                e0,
                e1,
                100.0 * (1.0 - e1 / e0),
                p0,
                p1,
                100.0 * (1.0 - p1 / p0)
            )
        })
        .collect();
    for r in rows {
        println!("{r}");
    }
}
