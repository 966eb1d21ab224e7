//! Several logs of one machine diagnosed together
//! (`eha_sim::diagnosis::multi`): the shared-parameter plumbing on a toy
//! machine whose two parameters only the two logs together determine, the
//! command line with several files, and (slow tier, 6–7 min each at load
//! ~20) two emulator logs of one machine with a hidden effect and without.

use eha_sim::diagnosis::fit::{fit, FitOptions};
use eha_sim::diagnosis::multi::{combine, joint_reference, log_parts, options_for, write_outputs, MultiModel};
use eha_sim::diagnosis::report::DiagnosisJson;
use eha_sim::diagnosis::{diagnose, Candidate, DiagnoseOptions, ParamSpec, SimSeries, Simulator};
use eha_sim::measured::{Channel, MeasuredRun};

use crate::plan::summary;

/// A toy machine: the pump temperature is a first-order (τ 300 s) response
/// to a heat g1·ω + g2·ω² (ω the logged speed, krpm; g1, g2 in K: the two
/// calibration parameters). At one constant speed a log determines only
/// g1·ω + g2·ω², not g1 and g2: two logs at two speeds determine both.
struct Toy {
    time_s: Vec<f64>,
    omega: Vec<f64>,
}

impl Simulator for Toy {
    fn nuisance(&self) -> Vec<ParamSpec> {
        vec![ParamSpec::new("g1", "K", 8.0, 1.0, 100.0), ParamSpec::new("g2", "K", 8.0, 1.0, 100.0)]
    }
    fn extension_params(&self, _c: Candidate) -> Vec<ParamSpec> {
        vec![]
    }
    fn simulate(&self, n: &[f64], _c: Candidate, _ext: &[f64]) -> Result<SimSeries, String> {
        let (mut y, mut out) = (0.0, Vec::with_capacity(self.omega.len()));
        for (i, w) in self.omega.iter().enumerate() {
            if i > 0 {
                let f = (-(self.time_s[i] - self.time_s[i - 1]) / 300.0).exp();
                y = f * y + (1.0 - f) * (n[0] * w + n[1] * w * w);
            }
            out.push(20.0 + y);
        }
        let mut s = SimSeries::default();
        s.channels.insert(Channel::TPumpC, out);
        Ok(s)
    }
}

/// A toy log at constant speed `omega` krpm, `n` rows at `dt` s, made by the
/// toy itself at g1 = 10, g2 = 5 K (noise-free).
fn toy_log(omega: f64, n: usize, dt: f64) -> (Toy, MeasuredRun) {
    let t: Vec<f64> = (0..n).map(|i| dt * i as f64).collect();
    let toy = Toy { omega: vec![omega; n], time_s: t.clone() };
    let mut run = MeasuredRun::new(t);
    let y = toy.simulate(&[10.0, 5.0], Candidate::None, &[]).expect("toy");
    run.set(Channel::TPumpC, y.channels[&Channel::TPumpC].iter().map(|v| Some(*v)).collect());
    run.set(Channel::AmbientC, vec![Some(20.0); n]);
    run.set(Channel::SpeedRpm, vec![Some(1000.0 * omega); n]);
    (toy, run)
}

/// The joint model runs every log with the same parameter vector and places
/// each log's series on its rows; a fit on the joint table recovers both
/// toy parameters (within 1 %), which neither log determines alone (each
/// alone fits its own data to < 0.01 K with g1, g2 off by > 10 % from the
/// start the fit begins at, since it cannot tell them apart). Then the whole
/// joint diagnosis: one answer (`none`: noise-free data of the model
/// itself), `diagnosis.json` with one `logs` entry per log, each log's own
/// held-out window and errors.
#[test]
fn logs_share_one_parameter_vector_and_one_answer() {
    let (toy_a, a) = toy_log(1.0, 400, 3.0);
    let (toy_b, b) = toy_log(2.0, 300, 2.0);
    let (rows, layout) = combine(&[&a, &b], 0.7).expect("combine");
    let joint = MultiModel::new(vec![Box::new(toy_a), Box::new(toy_b)], layout.clone()).expect("joint model");
    // Plumbing: each log's rows of the joint series are that log's own run.
    let s = joint.simulate(&[12.0, 3.0], Candidate::None, &[]).expect("joint run");
    let own = Toy { omega: vec![2.0; 300], time_s: b.time_s.clone() }.simulate(&[12.0, 3.0], Candidate::None, &[]).expect("b");
    assert_eq!(layout.gather(&s.channels[&Channel::TPumpC], 1), own.channels[&Channel::TPumpC]);
    // The shared fit: every row of both logs, from g1 = g2 = 8.
    let pts: Vec<(Channel, usize)> = (0..rows.len()).map(|i| (Channel::TPumpC, i)).collect();
    let f = fit(&joint, &rows, &pts, Candidate::None, &[8.0, 8.0], None, FitOptions::default()).expect("joint fit");
    assert!((f.nuisance[0] / 10.0 - 1.0).abs() < 0.01 && (f.nuisance[1] / 5.0 - 1.0).abs() < 0.01, "fitted {:?} (truth 10, 5)", f.nuisance);
    // One log alone: fitted to its data, parameters not determined.
    let (toy_a, a2) = toy_log(1.0, 400, 3.0);
    let pts_a: Vec<(Channel, usize)> = (0..a2.len()).map(|i| (Channel::TPumpC, i)).collect();
    let fa = fit(&toy_a, &a2, &pts_a, Candidate::None, &[8.0, 8.0], None, FitOptions::default()).expect("fit a");
    assert!((fa.rss / fa.n as f64).sqrt() < 0.01, "log a alone fits its data");
    assert!((fa.nuisance[0] / 10.0 - 1.0).abs() > 0.1, "log a alone cannot tell g1 from g2: {:?}", fa.nuisance);

    // The whole joint diagnosis.
    let o = DiagnoseOptions::default();
    let d = diagnose(&rows, &joint, &o).expect("joint diagnosis");
    assert_eq!(d.answer(), "none");
    let parts = log_parts(&d, &[&a, &b], joint.layout(), &o);
    assert_eq!(parts.len(), 2);
    for (p, run) in parts.iter().zip([&a, &b]) {
        let split = eha_sim::diagnosis::analysis::split_time_s(run, 0.7);
        assert_eq!(p.split_time_s, split);
        assert!(p.before.heldout_rmse_k < 0.01, "held out {:.4} K", p.before.heldout_rmse_k);
    }
    let out = std::env::temp_dir().join(format!("diag-multi-{}", std::process::id()));
    write_outputs(&d, &parts, &[&a, &b], &["a.csv".into(), "b.csv".into()], &out).expect("outputs");
    let j: DiagnosisJson = serde_json::from_str(&std::fs::read_to_string(out.join("diagnosis.json")).unwrap()).unwrap();
    assert_eq!(j.logs.iter().map(|l| (l.file.as_str(), l.rows)).collect::<Vec<_>>(), [("a.csv", 400), ("b.csv", 300)]);
    assert_eq!(j.logs[0].channels.len(), 1);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("## Logs") && report.contains("log-2/temperatures.png"), "{report}");
    assert!(out.join("log-1/temperatures.png").exists() && out.join("log-2/residuals.png").exists());
    let _ = std::fs::remove_dir_all(&out);
}

/// `diagnose a.csv b.csv`: every file is read before any model runs, and a
/// bad second file is an error naming it, its line and column (exit 2).
#[test]
fn several_files_on_the_command_line_each_checked() {
    let dir = std::env::temp_dir().join(format!("diag-multi-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("good.csv");
    let bad = dir.join("second.csv");
    std::fs::write(&good, "time_s,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c,t_oil_c\n0,500,10,60,1,16,20\n1,500,10,60,1,16,20.1\n").unwrap();
    std::fs::write(&bad, "time_s,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c,t_oil_c\n0,500,10,60,1,16,20\n1,500,10,60,1,16,oops\n").unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_eha-sim"))
        .arg("diagnose")
        .arg(&good)
        .arg(&bad)
        .arg("--out")
        .arg(dir.join("o"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("second.csv:3") && err.contains("t_oil_c"), "{err}");
    assert!(!dir.join("o/diagnosis.json").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The joint diagnosis of `logs` (one machine) with the reference model,
/// as `eha-sim diagnose a.csv b.csv` makes it.
fn diagnose_together(logs: &[&MeasuredRun]) -> eha_sim::diagnosis::Diagnosis {
    let o = options_for(&DiagnoseOptions::default(), logs.len());
    let files: Vec<String> = (1..=logs.len()).map(|k| format!("log {k}")).collect();
    let (rows, joint, refusal) = joint_reference(&eha_sim::rig::Rig::default(), logs, &files, o.train_fraction, o.structure).expect("joint model");
    eprintln!("  joint structure {:?}: {}", o.structure, refusal.as_deref().unwrap_or("applied"));
    let d = diagnose(&rows, &joint, &o).expect("joint diagnosis");
    for p in log_parts(&d, logs, joint.layout(), &o) {
        let ch: Vec<String> =
            p.before.channels.iter().map(|c| format!("{} {:.2}", c.channel, c.heldout_rmse_k)).collect();
        eprintln!("  joint, one log: held-out {:.3} -> {:.3} K; {}", p.before.heldout_rmse_k, p.after.heldout_rmse_k, ch.join(", "));
    }
    d
}

/// One log's diagnosis as `eha-sim diagnose log.csv` makes it (the
/// default structure where the log's current allows it).
fn diagnose_alone(log: &MeasuredRun) -> eha_sim::diagnosis::Diagnosis {
    let o = DiagnoseOptions::default();
    let model = eha_sim::diagnosis::reference::ReferenceModel::new(eha_sim::rig::Rig::default(), log).expect("model").with_structure(log, o.structure);
    eprintln!("  alone structure {:?}: {}", o.structure, model.structure_refusal().unwrap_or("applied"));
    diagnose(log, &model, &o).expect("diagnosis")
}

/// Two emulator logs of one machine (the machine of seed 1704, a dead-end
/// oil pocket hidden, τ ≈ 200 s): its Case 1 log and the same machine
/// flown through speed steps (seed 1705's mission, noise and dropouts).
/// The joint diagnosis is at least as right as each log alone: it names
/// `sensor-lag` when either log alone does, and never another cause.
/// Measured: each alone and together `sensor-lag` at P 1.00 (pooled
/// held-out 0.239 -> 0.172 K, 0.746 -> 0.547 K, together 0.526 -> 0.299 K).
/// With the default structure as the command takes it (2026-11-29): the
/// Case 1 log alone with it (`sensor-lag`, held-out 0.480 K), the speed
/// steps alone and the pair without it (their electrical balance gives
/// `eta_m` −0.150 and −0.118: refused), each `sensor-lag` at P 1.00.
#[test]
#[ignore = "slow tier: three emulator diagnoses, minutes"]
fn slow_two_logs_of_one_emulated_machine_with_a_lag_are_at_least_as_right_together() {
    two_logs_of_one_machine(Candidate::SensorLag, (1704, 1705));
}

/// The effect-free pair: the machine of seed 1714 (nothing hidden) at
/// Case 1 and through seed 1716's speed steps gives no discovery together,
/// nor a wrong cause. Measured: `none` alone (0.149, 0.267 K) and together
/// (P 1.00, 0.296 K). With the default structure as the command takes it
/// (2026-11-29): the Case 1 log alone with it, the speed steps alone
/// without it (`eta_m` 0.001 refused), the pair with it (the two logs'
/// load together separates the friction terms): `none` at P 1.00 each
/// (0.155, 0.281 and 0.333 K; `churning-loss` ln B 25.6 together, not
/// admitted).
#[test]
#[ignore = "slow tier: three emulator diagnoses, minutes"]
fn slow_two_effect_free_logs_of_one_emulated_machine_give_no_discovery() {
    two_logs_of_one_machine(Candidate::None, (1714, 1716));
}

fn two_logs_of_one_machine(hidden: Candidate, seeds: (u64, u64)) {
    use eha_sim::emulator::missions::EmuScenario::{ConstantThrottle, SpeedSteps};
    use eha_sim::emulator::{generate, generate_on_machine, EmuCase};
    let case = |hidden: Candidate, scenario, seed| EmuCase { hidden, scenario, seed, duration_s: 1200.0 };
    {
        let (a, truth) = generate(&case(hidden, ConstantThrottle, seeds.0)).expect("log a");
        let (b, _) = generate_on_machine(&case(hidden, SpeedSteps, seeds.1), &truth).expect("log b");
        let (da, db) = rayon::join(|| diagnose_alone(&a), || diagnose_alone(&b));
        let dj = diagnose_together(&[&a, &b]);
        for (l, d) in [("a alone", &da), ("b alone", &db), ("together", &dj)] {
            eprintln!("{} {}", hidden.name(), summary(l, d));
        }
        let right = |d: &eha_sim::diagnosis::Diagnosis| d.posterior.named().is_some() && d.cause == hidden;
        let wrong = |d: &eha_sim::diagnosis::Diagnosis| d.posterior.named().is_some() && d.cause != hidden;
        assert!(!wrong(&dj), "joint: wrong cause {}", dj.answer());
        if hidden == Candidate::None {
            assert!(dj.posterior.named().is_none(), "effect-free pair: false discovery {}", dj.answer());
        } else if right(&da) || right(&db) {
            assert!(right(&dj), "named alone ({} / {}) but not together ({})", da.answer(), db.answer(), dj.answer());
        }
    }
}
