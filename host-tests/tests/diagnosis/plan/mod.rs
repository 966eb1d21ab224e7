//! Test plans (`eha_sim::diagnosis::plan`, `eha-sim plan`): the command's
//! contract (fast tier) and, on the independent rig emulator, whether the
//! planned run lifts effects that the original log left below r = 2 (slow
//! tier).

use eha_sim::diagnosis::emu_sweep::default_cases;
use eha_sim::diagnosis::plan::{leading, plan, Decision, Design, Limits, Plan};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::analysis::Structure;
use eha_sim::diagnosis::{diagnose, Candidate, DiagnoseOptions, Simulator};
use eha_sim::emulator::plant::{Hidden, Plant};
use eha_sim::emulator::{generate, generate_twin, log_mission, logger, EmuCase, EmuTruth};
use eha_sim::measured::{Channel, MeasuredRun};
use eha_sim::rig::Rig;
use eha_sim::scenario::{read_mission_csv, ValveRule};
use rand::SeedableRng;

mod joint;

/// The structure of the single-log diagnoses: the one `EHA_PLAN_STRUCTURE`
/// names (`off`, `full`, `no-case`, `no-case-held`), **`off` when unset** —
/// the tests measured before 2026-11-28 ran so, while `eha-sim diagnose`
/// on one log applies the default [`Structure::NoCaseHeld`] (under which
/// the original logs of 1710 and 1712 stand at r ≥ 2,
/// docs/diagnosis-limits.md). The joint diagnoses
/// (`multi::joint_reference`) take no structure, as the command does with
/// several logs.
fn structure() -> Structure {
    std::env::var("EHA_PLAN_STRUCTURE").ok().map_or(Structure::Off, |v| <Structure as clap::ValueEnum>::from_str(&v, true).expect("EHA_PLAN_STRUCTURE"))
}

/// The reference model of one log as these tests diagnose it: the rig
/// file's under structure `s`.
fn model_of(log: &MeasuredRun, s: Structure) -> ReferenceModel {
    ReferenceModel::new(Rig::default(), log).expect("model").with_structure(log, s)
}

/// The emulator case of `seed` in the original case set (1200 s logs).
fn case(seed: u64) -> EmuCase {
    default_cases(1200.0, 1700).into_iter().find(|c| c.seed == seed).expect("case")
}

/// The planned mission flown by the emulated machine of `truth`, with the
/// case's hidden effect and without (its twin: same mission and noise), and
/// the channel the effect changes most on it (held-out window).
fn fly(d: &Design, c: &EmuCase, truth: &EmuTruth, ambient_c: f64) -> (MeasuredRun, MeasuredRun, Channel) {
    let m = d.emu_mission([ambient_c, 0.3, 0.0]);
    let dt = m.scenario.log_interval_s();
    let with = Plant { p: &truth.params, m: &m, h: Hidden { effect: c.hidden, magnitude: truth.magnitude } }.run(dt);
    let without = Plant { p: &truth.params, m: &m, h: Hidden { effect: Candidate::None, magnitude: 0.0 } }.run(dt);
    let log = |tr: &[logger::Row]| log_mission(tr, &m, &mut rand_chacha::ChaCha8Rng::seed_from_u64(c.seed ^ 0x91A4));
    let split = 0.7 * d.duration_s;
    let affected = Channel::TEMPERATURES
        .into_iter()
        .enumerate()
        .map(|(k, ch)| {
            let e: f64 = with
                .iter()
                .zip(&without)
                .filter(|(a, _)| a.0 >= split)
                .map(|(a, b)| (logger::sensor_readings(&a.1)[k] - logger::sensor_readings(&b.1)[k]).powi(2))
                .sum();
            (ch, e)
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|x| x.0)
        .expect("channels");
    (log(&with), log(&without), affected)
}

/// The six emulator cases of the original set whose 1200 s log left the
/// hidden effect below r = 2 when chosen (docs/test-plans.md).
const SIX: [u64; 6] = [1708, 1710, 1712, 1709, 1700, 1713];

/// Held-out RMSE (K) of `d`'s calibrated baseline on channel `ch`.
fn heldout_k(d: &eha_sim::diagnosis::Diagnosis, ch: Channel) -> f64 {
    d.before.channel(ch.name()).map(|c| c.heldout_rmse_k).expect("channel")
}

/// `d`'s two leading candidates ([`leading`]).
fn leading_of(d: &eha_sim::diagnosis::Diagnosis) -> Vec<Candidate> {
    let causes: Vec<(String, f64, f64)> = d.posterior.causes.iter().map(|c| (c.cause.clone(), c.probability, c.log_bayes_factor)).collect();
    leading(&causes, 2)
}

/// Imprint ratio (calibrated baseline's held-out misfit on `ch`, log over
/// twin), the log's answer, the twin's, and the log's leading candidates
/// ([`leading`], two), and the log's diagnosis.
fn ratio(log: &MeasuredRun, twin: &MeasuredRun, ch: Channel, s: Structure) -> (f64, String, String, Vec<Candidate>, Box<eha_sim::diagnosis::Diagnosis>) {
    let o = DiagnoseOptions::default();
    let d = diagnose(log, &model_of(log, s), &o).expect("diagnosis");
    let t = diagnose(twin, &model_of(twin, s), &o).expect("twin diagnosis");
    for (l, x) in [("log", &d), ("twin", &t)] {
        eprintln!("  {}", summary(l, x));
    }
    (heldout_k(&d, ch) / heldout_k(&t, ch), d.answer().to_string(), t.answer().to_string(), leading_of(&d), Box::new(d))
}

/// One line: answer, set, held-out misfit, posterior and the top of the ranking.
pub fn summary(label: &str, d: &eha_sim::diagnosis::Diagnosis) -> String {
    let p: Vec<String> = d.posterior.causes.iter().take(3).map(|c| format!("{} {:.2} lnB {:.1}", c.cause, c.probability, c.log_bayes_factor)).collect();
    let r: Vec<String> = d
        .ranking
        .iter()
        .take(4)
        .map(|r| format!("{} dBIC {:.0} gain {:.0} % {} pooled {:.3} K{}", r.cause, r.delta_bic, 100.0 * r.heldout_gain, r.gain_channel, r.heldout_rmse_k, if r.qualifies { " qualifies" } else { "" }))
        .collect();
    let ch: Vec<String> = d.before.channels.iter().map(|c| format!("{} {:.3}", c.channel, c.heldout_rmse_k)).collect();
    let top: Vec<String> = d.ranking.iter().find(|r| r.cause != "none").map_or(vec![], |r| r.channel_heldout_k.iter().map(|(c, v)| format!("{c} {v:.3}")).collect());
    let own: Vec<String> = d.posterior.channels.iter().map(|c| format!("{} {:.3}/{:.3}={:.1}", c.channel, c.misfit_k, c.floor_k, c.imprint_ratio)).collect();
    format!(
        "{label}: {} ({} set, held-out {:.3} K [{}], {} runs; {})\n    ranking: {}\n    top candidate held-out [{}]; misfit/floor [{}]",
        d.answer(),
        d.nuisance_set,
        d.before.heldout_rmse_k,
        ch.join(", "),
        d.sims,
        p.join(", "),
        r.join("; "),
        top.join(", "),
        own.join(", ")
    )
}

/// `EHA_PLAN_DUMP=DIR` (by hand): writes `logs` as CSV under
/// `DIR/{seed}-{label}/`, to be diagnosed with the command.
fn dump(seed: u64, label: &str, logs: &[(&str, &MeasuredRun)]) {
    if let Ok(dir) = std::env::var("EHA_PLAN_DUMP") {
        let dir = std::path::Path::new(&dir).join(format!("{seed}-{label}"));
        std::fs::create_dir_all(&dir).expect("dump dir");
        for (n, r) in logs {
            r.write_file(dir.join(format!("{n}.csv"))).expect("dump");
        }
    }
}

/// The candidates at the magnitudes `eha-sim plan` takes when none is
/// given: the model's fit start of each (below the middle of the physical
/// range that the diagnosis's `typical_magnitude` takes; planning for that
/// instead was measured and not kept, docs/test-plans.md; by hand with
/// `EHA_PLAN_MAGNITUDE=typical`).
fn magnitudes(log: &MeasuredRun, cands: &[Candidate]) -> Vec<(Candidate, f64)> {
    let model = ReferenceModel::new(Rig::default(), log).expect("model");
    let middle = std::env::var("EHA_PLAN_MAGNITUDE").is_ok_and(|v| v == "typical");
    cands
        .iter()
        .map(|&c| {
            let spec = &model.extension_params(c)[0];
            (c, if middle { eha_sim::diagnosis::analysis::typical_magnitude(c, spec) } else { spec.start })
        })
        .collect()
}

/// By hand, `EHA_PLAN_MAGNITUDE=truth` (an oracle no user has): the hidden
/// candidate planned for at the magnitude the emulator hid, the others as
/// [`magnitudes`] gives them (a hidden candidate not among the leading
/// ones is not added); otherwise `m` unchanged.
fn at_truth(mut m: Vec<(Candidate, f64)>, hidden: Candidate, magnitude: f64) -> Vec<(Candidate, f64)> {
    if std::env::var("EHA_PLAN_MAGNITUDE").is_ok_and(|v| v == "truth") {
        for (c, v) in m.iter_mut().filter(|(c, _)| *c == hidden) {
            eprintln!("  planned for {} at the hidden {magnitude:.3e} (fit start {v:.3e})", c.name());
            *v = magnitude;
        }
    }
    m
}

fn mean_ambient(log: &MeasuredRun) -> f64 {
    let v: Vec<f64> = log.get(Channel::AmbientC).expect("ambient").iter().flatten().copied().collect();
    v.iter().sum::<f64>() / v.len() as f64
}

/// One case, single-log diagnoses under structure `s`: the original log's
/// ratio, the planned run's ratio, its answer, the plan, the planned run's
/// diagnosis and its twin's answer.
fn planned_case(seed: u64, duration_s: f64, s: Structure) -> (f64, f64, String, Plan, Box<eha_sim::diagnosis::Diagnosis>, String) {
    let c = case(seed);
    let (log, truth) = generate(&c).expect("log");
    let (twin, _) = generate_twin(&c).expect("twin");
    let ch = truth.affected.expect("affected").0;
    let (r0, a0, _, lead, _) = ratio(&log, &twin, ch, s);
    // `EHA_PLAN_ALL=1` (by hand): plan for every candidate a throttle run
    // can excite, not the log's leading two.
    let lead = if std::env::var("EHA_PLAN_ALL").is_ok_and(|v| v == "1") {
        Candidate::EXTENSIONS.iter().copied().filter(|&c| c != Candidate::CoulombFriction).collect()
    } else {
        lead
    };
    let t = std::time::Instant::now();
    let p = plan(&Rig::default(), &log, &at_truth(magnitudes(&log, &lead), c.hidden, truth.magnitude), Limits::for_rig(&Rig::default(), &log), duration_s, Decision::Alone).expect("plan");
    let secs = t.elapsed().as_secs_f64();
    let (plog, ptwin, pch) = fly(&p.design, &c, &truth, mean_ambient(&log));
    dump(seed, "alone", &[("log", &log), ("twin", &twin), ("planned", &plog), ("planned-twin", &ptwin)]);
    let (r1, a1, t1, _, d1) = ratio(&plog, &ptwin, pch, s);
    let hidden = p.expected.iter().find(|e| e.planned.candidate == c.hidden.name());
    let exp = hidden.map(|e| (e.planned.best.1, e.on_log.as_ref().map(|r| r.best.1)));
    // What the plan predicted per channel for the hidden candidate
    // (imprint, left, floor; K), to set beside the flown run and its twin.
    if let Some(e) = hidden {
        let ch: Vec<String> = e.planned.channels.iter().map(|x| format!("{} {:.3}/{:.3}/{:.3}", x.channel, x.imprint_k, x.left_k, x.floor_k)).collect();
        eprintln!("  predicted for {} (imprint/left/floor K): {}", c.hidden.name(), ch.join(", "));
    }
    eprintln!(
        "{seed} {}: original r {r0:.2} on {} ({a0}; leading {lead:?}); plan {:.0} s: {} (D_s {:.3}); expected r̂ for the hidden candidate {exp:?}; planned r {r1:.2} on {} ({a1}; twin {t1})",
        c.hidden.name(),
        ch.name(),
        secs,
        p.design.name,
        p.d_s,
        pch.name()
    );
    (r0, r1, a1, p, d1, t1)
}

/// The command's contract, `eha-sim plan` on a short emulator log (600 s,
/// Case 1, sensor lag hidden), planned for a 120 s probe lag within 500–1500
/// rpm and 10–60 bar: exit 0; `mission.csv` read by the project's mission
/// reader (`scenario::read_mission_csv`) with every row within the limits
/// (the drop at the running speed is the 500 rpm setting × (speed/500)²)
/// and the planned duration; `plan.json`'s chosen mission first of the
/// admissible family by the plan's rule (candidates at r̂ ≥ 2, then
/// Σ ln min(r̂, 2), then D_s), three-level missions among them, every D_s
/// finite, expected ratios ≥ 1. A candidate a
/// throttle plan cannot excite is refused with exit ≠ 0 and a message.
/// The same contract with `--joint` (planned for the joint decision with
/// the log, `plan.json`'s `decision` "Joint"), the lag named without a
/// magnitude: planned for at the model's fit start, 30 s (`plan.json`'s
/// `candidates`, and the printed expectation names it).
#[test]
fn plan_command_writes_a_readable_mission_within_limits() {
    let c = EmuCase { hidden: Candidate::SensorLag, scenario: eha_sim::emulator::missions::EmuScenario::ConstantThrottle, seed: 1704, duration_s: 600.0 };
    let (log, _) = generate(&c).expect("log");
    let dir = std::env::temp_dir().join(format!("plan-contract-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("log.csv");
    log.write_file(&path).expect("write log");
    let run = |extra: &[&str], sub: &str| {
        let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_eha-sim"));
        cmd.args(["plan", "--log"]).arg(&path).args(["--speed-rpm", "500,1500", "--drop-bar", "10,60", "--duration-s", "600", "--out"]).arg(dir.join(sub)).args(extra);
        cmd.output().expect("eha-sim")
    };
    for (sub, joint) in [("out", false), ("out-joint", true)] {
        let t = std::time::Instant::now();
        let mut args = vec!["--candidates", if joint { "sensor-lag" } else { "sensor-lag=120" }];
        if joint {
            args.push("--joint");
        }
        let out = run(&args, sub);
        let stdout = String::from_utf8_lossy(&out.stdout);
        eprintln!("{sub}: {:.1} s: {stdout}{}", t.elapsed().as_secs_f64(), String::from_utf8_lossy(&out.stderr));
        assert!(out.status.success());
        let m = read_mission_csv(&dir.join(sub).join("mission.csv"), ValveRule::None).expect("mission reader");
        assert_eq!(m.duration_s, 600.0);
        for ((t, n), (_, s)) in m.speed_rpm.0.iter().zip(&m.needle_bar.0) {
            let drop = s * (n / 500.0).powi(2);
            // 1e-4 bar: the file's needle column has six decimals.
            assert!((500.0..=1500.0).contains(n) && (10.0 - 1e-4..=60.0 + 1e-4).contains(&drop), "at {t} s: {n} rpm, {drop} bar");
        }
        let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join(sub).join("plan.json")).expect("plan.json")).expect("json");
        assert_eq!(j["decision"], if joint { "Joint" } else { "Alone" });
        let lag_s = if joint { 30.0 } else { 120.0 };
        assert_eq!(j["candidates"][0][2].as_f64(), Some(lag_s), "{}", j["candidates"]);
        // The printed expectation names the magnitude it holds for.
        assert!(stdout.contains(&format!("sensor-lag at sensor_tau_s {lag_s:.3e} s: expected r")), "{stdout}");
        let fam = j["family"].as_array().expect("family");
        assert!(fam.iter().all(|f| f["d_s"].as_f64().is_some_and(f64::is_finite)), "{fam:?}");
        // The chosen mission ranks first: candidates at r̂ ≥ 2, then Σ ln min(r̂, 2), then D_s.
        let key = |f: &serde_json::Value| {
            let r: Vec<f64> = f["expected_ratio"].as_array().expect("expected_ratio").iter().filter_map(|x| x.as_f64()).collect();
            (r.iter().filter(|&&x| x >= 2.0).count(), r.iter().map(|x| x.clamp(1.0, 2.0).ln()).sum::<f64>(), f["d_s"].as_f64().expect("d_s"))
        };
        let chosen = fam.iter().find(|f| f["name"] == j["design"]["name"]).expect("the chosen mission in the family");
        assert_eq!(chosen["d_s"].as_f64(), j["d_s"].as_f64());
        assert!(fam.iter().filter(|f| f["admissible"] == true).all(|f| key(f) <= key(chosen)), "{fam:?}");
        assert!(fam.iter().any(|f| f["name"].as_str().is_some_and(|n| n.contains('→'))), "no three-level mission in the family");
        for e in j["expected"].as_array().expect("expected") {
            assert!(e["planned"]["best"][1].as_f64().is_some_and(|r| r >= 1.0) && e["planned_separated"].as_f64().is_some_and(|r| r >= 1.0), "{e}");
        }
    }
    let bad = run(&["--candidates", "coulomb-friction"], "out");
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(!bad.status.success() && err.contains("coulomb-friction") && err.contains("throttle"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// On the emulator: effects the original 1200 s log left below r = 2,
/// planned for as the command plans (the log's leading candidates, at
/// the model's fit starts ([`magnitudes`]), every throttle candidate when the log admitted none;
/// the hidden one is not told), the planned mission flown by the same
/// machine with the same hidden effect, and its twin without; diagnosed
/// under `--structure off` ([`structure`]).
///
/// Re-measured 2026-11-29 evening (490 s) after the plan's choice changed
/// (the most candidates at r̂ ≥ 2 over the two- and three-level families;
/// all six logs admitted no candidate, so every one was planned for).
/// Original → planned r (answer; twin): 1708 churning 1.91 → **9.69
/// `churning-loss`** (`none`), 1710 conduction 1.93 → 1.18 (`unexplained`;
/// `unexplained`), 1712 draught 1.24 → 0.75 (`none`; `none`), 1709
/// churning 1.31 → **7.23 `churning-loss`** (`none`), 1700 winding 0.46 →
/// 0.99 (`unexplained`; `unexplained`), 1713 draught 0.75 → **4.45**
/// `none` (`unexplained`; a fan-less mission, on which a draught is not
/// nameable). **Lifted 3 of 6, named 2 of 6.** (With D_s over the log's
/// leading two, 2026-11-29 after the reference's fix: none lifted; on
/// 2026-11-28 1708 only, to 2.28, not named.) Asserted as measured: all
/// six below r = 2 on the log, lifted exactly 1708, 1709 and 1713, named
/// 1708 and 1709, no wrong cause on a planned run, no discovery on its
/// twin ([`cases_alone`]).
#[test]
#[ignore]
fn slow_planned_runs_lift_effects_above_the_floor() {
    let (_, below, lifted, msg) = cases_alone(&SIX, structure());
    let ids = |v: &[AloneRow]| v.iter().map(|r| r.0).collect::<Vec<_>>();
    assert_eq!(ids(&below), SIX, "measured set below r 2 changed: {msg}");
    assert_eq!(ids(&lifted), [1708, 1709, 1713], "measured lift changed: {msg}");
    let named: Vec<u64> = lifted.iter().filter(|r| r.3 == case(r.0).hidden.name()).map(|r| r.0).collect();
    assert_eq!(named, [1708, 1709], "measured names changed: {msg}");
}

/// One case planned for alone and decided alone ([`planned_case`]), a
/// by-hand measurement: the seed from `EHA_PLAN_SEED` (default 1709), the
/// plan's duration from `EHA_PLAN_DURATION_S` (default 1200 s), the
/// structure from `EHA_PLAN_STRUCTURE` ([`structure`]); `EHA_PLAN_ALL=1`
/// plans for every candidate a throttle run can excite;
/// `EHA_PLAN_MAGNITUDE=typical` plans for the middle of each physical
/// range ([`magnitudes`]); `EHA_PLAN_DUMP=DIR` writes the four logs ([`dump`]).
#[test]
#[ignore]
fn slow_alone_case() {
    let seed = std::env::var("EHA_PLAN_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1709);
    let dur = std::env::var("EHA_PLAN_DURATION_S").ok().and_then(|s| s.parse().ok()).unwrap_or(1200.0);
    let (r0, r1, a, p, _, t) = planned_case(seed, dur, structure());
    eprintln!("ALONE {seed} {dur}: r {r0:.2} -> {r1:.2} {a} (twin {t}), {}", p.design.name);
}

/// A false discovery found on a planned run's twin, and the rule that
/// removed it. 1709's machine (its planned run of 2400 s under the default
/// structure: 500 rpm at 10 ↔ 100 bar every 300 s) flown **without** its
/// hidden effect: measured 2026-11-29, the global set named
/// `motor-pump-conduction` at P 1.00 (t_motor_c held out 0.825 → 0.255 K,
/// pooled 0.875 → 0.685 K) while t_oil_c stayed 1.18 K off after it — a
/// cause standing in for structure the global set lacks. Since a global
/// cause must also leave the log within the strict rule (else the physical
/// set decides; `diagnosis::analysis`), the answer is `none` on the
/// physical set (pooled held out 0.558 K). Asserted: no cause named, the
/// physical set answering, its pooled misfit as measured ±0.05 K.
#[test]
#[ignore = "slow tier: one emulator diagnosis of a 2400 s log, ~1.5 min"]
fn slow_planned_twin_of_1709_names_no_cause() {
    use eha_sim::diagnosis::plan::Level;
    let c = case(1709);
    let (log, truth) = generate(&c).expect("log");
    let (a, b) = (Level { speed_rpm: 500.0, drop_bar: 10.0, air_mps: 0.0 }, Level { speed_rpm: 500.0, drop_bar: 100.0, air_mps: 0.0 });
    let segments = (0..8).map(|k| if k % 2 == 0 { a } else { b }).collect();
    let ambient_c = mean_ambient(&log);
    let d = Design { name: "500 rpm/10 bar ↔ 500 rpm/100 bar every 300 s".into(), hold_s: 300.0, segments, duration_s: 2400.0, ambient_c };
    let (_, twin, _) = fly(&d, &c, &truth, ambient_c);
    let t = diagnose(&twin, &model_of(&twin, Structure::NoCaseHeld), &DiagnoseOptions::default()).expect("twin diagnosis");
    eprintln!("{}", summary("planned twin", &t));
    let answer = t.answer().to_string();
    assert!(["none", "unexplained"].contains(&answer.as_str()), "false discovery: {answer}");
    assert_eq!(t.nuisance_set, "physical", "the global cause is confirmed or refused by the physical set");
    assert!((t.before.heldout_rmse_k - 0.558).abs() <= 0.05, "pooled held out {:.3} K (measured 0.558)", t.before.heldout_rmse_k);
}

/// One row of [`cases_alone`]: seed, r on the original log, r on the
/// planned run, its answer, the mission, the planned twin's answer.
type AloneRow = (u64, f64, f64, String, String, String);

/// The cases `seeds` planned for alone and diagnosed alone under
/// structure `s`: every row, those below r = 2 on the original log, those
/// of them lifted to r ≥ 2, and the rows printed. Asserts what holds
/// whatever the ratios: no wrong cause on a planned run, no discovery on
/// its twin.
fn cases_alone(seeds: &[u64], s: Structure) -> (Vec<AloneRow>, Vec<AloneRow>, Vec<AloneRow>, String) {
    let mut rows = Vec::new();
    for &seed in seeds {
        let (r0, r1, answer, p, _, twin) = planned_case(seed, 1200.0, s);
        rows.push((seed, r0, r1, answer, p.design.name.clone(), twin));
    }
    let below: Vec<AloneRow> = rows.iter().filter(|r| r.1 < 2.0).cloned().collect();
    let lifted: Vec<AloneRow> = below.iter().filter(|r| r.2 >= 2.0).cloned().collect();
    let msg = format!("{rows:?}");
    eprintln!("{} of {} below r 2 lifted to ≥ 2: {msg}", lifted.len(), below.len());
    for r in &rows {
        assert!(["none", "unexplained", case(r.0).hidden.name()].contains(&r.3.as_str()), "wrong cause on the planned run: {msg}");
        assert!(["none", "unexplained"].contains(&r.5.as_str()), "false discovery on a planned run's twin: {msg}");
    }
    (rows, below, lifted, msg)
}

/// [`slow_planned_runs_lift_effects_above_the_floor`] with the single-log
/// diagnoses under the command's default structure
/// ([`Structure::NoCaseHeld`]). Re-measured 2026-11-29 evening (339 s)
/// after the plan's choice changed (the most candidates at r̂ ≥ 2 over the
/// two- and three-level families; every candidate when the log admitted
/// none, as all six logs here do). Original → planned r (answer; twin):
/// 1708 2.35 (`none`, a miss at r ≥ 2) → 2.35 **`churning-loss`**
/// (`unexplained`), 1710 2.28 (a miss) → 0.19, 1712 2.38 (a miss) →
/// 0.47, 1709 0.80 → **7.23 `churning-loss`** (`none`), 1700 0.79 → 1.18,
/// 1713 0.80 → **6.51** `unexplained` (`unexplained`). Of the three below
/// r = 2 on the log two are lifted (1709, 1713) and one named (1709).
/// (With D_s alone over the log's leading two, before: 1708 → 3.66 named,
/// 1710 0.61, 1712 1.01, 1709 0.63, 1700 0.96, 1713 1.57: none of the
/// three lifted.) Asserted as measured: 1709, 1700 and 1713 below, 1709
/// and 1713 lifted, 1708 and 1709 named, no wrong cause, no false
/// discovery.
#[test]
#[ignore]
fn slow_planned_runs_default_structure() {
    let (rows, below, lifted, msg) = cases_alone(&SIX, Structure::NoCaseHeld);
    let seeds = |v: &[AloneRow]| v.iter().map(|r| r.0).collect::<Vec<_>>();
    assert_eq!(seeds(&below), [1709, 1700, 1713], "measured set below r 2 changed: {msg}");
    assert_eq!(seeds(&lifted), [1709, 1713], "measured lift changed: {msg}");
    let named: Vec<u64> = rows.iter().filter(|r| r.3 == case(r.0).hidden.name()).map(|r| r.0).collect();
    assert_eq!(named, [1708, 1709], "measured names changed: {msg}");
}

/// The same for one case with a planned run twice as long (2400 s),
/// under `off` (the tests' `structure()`). Re-measured 2026-11-29 evening
/// (97 s) after the plan's choice changed (the most candidates at r̂ ≥ 2,
/// three-level missions searched, every candidate planned for when the
/// log admitted none): the plan is 500 rpm/10 bar → 1250 rpm/55 bar →
/// 2000 rpm/10 bar every 150 s (churning r̂ 1.12; no candidate reaches 2
/// on any mission of the 2400 s family, churning at most 1.25), and 1708
/// (churning, r 1.91 on its log) stands at **r 1.99**, named
/// **`churning-loss`** (right, just below r = 2), twin `unexplained`.
/// Before, with D_s over the log's leading two, the plan was 500 rpm/10
/// bar ↔ 2000 rpm/10 bar every 300 s (churning r̂ 1.11 there) and the run
/// stood at r 6.25, named: the r̂ of a 2400 s mission does not predict
/// which lifts (docs/test-plans.md). Asserted as measured: r within
/// 1.5–2.5, named, twin not a discovery.
#[test]
#[ignore]
fn slow_planned_run_twice_as_long() {
    let (r0, r1, answer, p, _, twin) = planned_case(1708, 2400.0, structure());
    eprintln!("1708, 2400 s plan: r {r0:.2} -> {r1:.2} ({answer}; twin {twin}), {}", p.design.name);
    assert!((1.5..=2.5).contains(&r1), "measured r changed: {r1:.2} (measured 1.99)");
    assert_eq!(answer, "churning-loss", "measured outcome changed (named at r 1.99)");
    assert!(["none", "unexplained"].contains(&twin.as_str()), "false discovery on the twin: {twin}");
}

/// [`slow_planned_run_twice_as_long`] with the single-log diagnoses under
/// the command's default structure ([`Structure::NoCaseHeld`]).
/// Re-measured 2026-11-29 evening (89 s) after the plan's choice changed:
/// the original 1708 log is a miss at r 2.35 (`none`, no candidate
/// admitted, so every candidate is planned for); the plan is the same
/// three-level mission as under `off`, and the planned run stands at
/// **r 1.49**, `unexplained`, twin `unexplained`: **not lifted** where the
/// old plan (500 rpm/10 bar ↔ 2000 rpm/10 bar every 300 s, for the log's
/// leading churning and lag) had lifted it to r 8.04 (`unexplained` too:
/// churning passed every check, its evidence lost to the discrepancy).
/// A measured regression of the new rule on a case above the floor on
/// its log, kept because on the cases below it the rule lifts 3 of 5
/// where the old lifted 0 of 3 (docs/test-plans.md). Asserted as
/// measured: r < 2, no cause named, twin not a discovery.
#[test]
#[ignore]
fn slow_planned_run_twice_as_long_default_structure() {
    let (r0, r1, answer, p, _, twin) = planned_case(1708, 2400.0, Structure::NoCaseHeld);
    eprintln!("1708, 2400 s plan, no-case-held: r {r0:.2} -> {r1:.2} ({answer}; twin {twin}), {}", p.design.name);
    assert!(r1 < 2.0, "measured r changed: {r1:.2} (measured 1.49)");
    assert!(["none", "unexplained"].contains(&answer.as_str()), "measured answer changed (unexplained at r 1.49): {answer}");
    assert!(["none", "unexplained"].contains(&twin.as_str()), "false discovery on the twin: {twin}");
}

/// By hand (prints, asserts nothing): what the two- and three-level
/// families can show of one case's hidden effect. For the seed in
/// `EHA_PLAN_SEED` (default 1709), under `EHA_PLAN_STRUCTURE`, the plan
/// for every throttle candidate at its fit start ([`magnitudes`]) is evaluated on
/// both families ([`family`], [`family_three`]); each design's expected
/// ratio for the hidden candidate is printed, and the design of each family
/// with the largest one (an oracle's choice: the hidden cause is told) is
/// flown by the machine with and without the effect and diagnosed alone:
/// the bound of what the family can lift. `EHA_PLAN_FLY=0`: the
/// families' tables only (a `ROW` line per admissible design: seed,
/// family, D_s, every candidate's expected ratio, the mission).
#[test]
#[ignore]
fn slow_family_bound_case() {
    use eha_sim::diagnosis::plan::{family, family_three, plan_among};
    let seed = std::env::var("EHA_PLAN_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1709);
    let dur = std::env::var("EHA_PLAN_DURATION_S").ok().and_then(|s| s.parse().ok()).unwrap_or(1200.0);
    let s = structure();
    let c = case(seed);
    let (log, truth) = generate(&c).expect("log");
    let (twin, _) = generate_twin(&c).expect("twin");
    let (r0, a0, _, _, _) = ratio(&log, &twin, truth.affected.expect("affected").0, s);
    let cands: Vec<Candidate> = Candidate::EXTENSIONS.iter().copied().filter(|&k| k != Candidate::CoulombFriction).collect();
    let hidden = cands.iter().position(|&k| k == c.hidden).expect("a throttle candidate");
    let limits = Limits::for_rig(&Rig::default(), &log);
    type Family = fn(&Limits, f64, f64) -> Vec<Design>;
    let families: [(&str, Family); 2] = [("two-level", family), ("three-level", family_three)];
    for (label, fam) in families {
        let t = std::time::Instant::now();
        let mut designs = Vec::new();
        let p = plan_among(&Rig::default(), &log, &magnitudes(&log, &cands), limits, Decision::Alone, |a| {
            designs = fam(&limits, dur, a);
            designs.clone()
        })
        .expect("plan");
        let mut rows: Vec<(f64, usize)> = p.family.iter().enumerate().filter(|(_, e)| e.admissible).map(|(k, e)| (e.expected_ratio[hidden], k)).collect();
        rows.sort_by(|a, b| b.0.total_cmp(&a.0));
        for (r, k) in rows.iter().take(5) {
            eprintln!("  {seed} {label}: r̂ {r:.2} {}", p.family[*k].name);
        }
        for e in p.family.iter().filter(|e| e.admissible) {
            let r: Vec<String> = e.expected_ratio.iter().map(|r| format!("{r:.3}")).collect();
            eprintln!("ROW {seed} {label} {:.4e} {} | {}", e.d_s, r.join(" "), e.name);
        }
        let Some(&(rhat, k)) = rows.first() else { continue };
        if std::env::var("EHA_PLAN_FLY").is_ok_and(|v| v == "0") {
            continue;
        }
        let (plog, ptwin, pch) = fly(&designs[k], &c, &truth, mean_ambient(&log));
        let (r1, a1, t1, _, _) = ratio(&plog, &ptwin, pch, s);
        eprintln!(
            "BOUND {seed} {} {label} ({} designs, {} admissible, {:.0} s): log r {r0:.2} ({a0}); best r̂ {rhat:.2}: {}; flown r {r1:.2} on {} ({a1}; twin {t1})",
            c.hidden.name(),
            p.family.len(),
            rows.len(),
            t.elapsed().as_secs_f64(),
            p.family[k].name,
            pch.name()
        );
    }
}

/// The original emulator set's throttle cases below r = 2 on their log
/// under the command's default structure (docs/diagnosis-numbers.md:
/// 1700 and 1701 winding, 1709 churning, 1711 conduction, 1713 draught;
/// the Coulomb cases 1706 and 1707 need a servo run, which a throttle plan
/// cannot give), each planned for as the command plans (the log's leading
/// candidates: every throttle candidate here, as none of the five logs
/// admitted one; the most candidates at r̂ ≥ 2 over the two- and
/// three-level families), flown, and decided alone.
///
/// Measured 2026-11-29 (480 s), original → planned r (answer; twin):
/// 1700 0.79 → 1.18 (`none`; `unexplained`), 1701 0.89 → 1.00 (`none`;
/// `none`), 1709 0.80 → **7.23 `churning-loss`** (`none`; 500 rpm/10 bar
/// ↔ 2000 rpm/10 bar every 300 s), 1711 0.91 → **2.72** `none` (`none`;
/// the same mission: conduction qualifies on ΔBIC 70 and 67 % on
/// t_pump_c but the pooled held-out gain is 19.9 %, under the 20 % bar),
/// 1713 0.80 → **6.51** `unexplained` (`unexplained`; 500/10 → 500/100 →
/// 1250 rpm/55 bar every 300 s, no fan: a draught is not identifiable
/// without a logged air span, and every fan mission leaves it at r̂ ≤ 1.10).
/// **Lifted 3 of 5, named 1 of 5**: the acceptance's "lifted, and then
/// named" for at least half is not met. The winding's law is not
/// showable by any mission of either family (r̂ ≤ 1.11). Asserted as
/// measured: all five below, lifted exactly 1709, 1711 and 1713, named
/// 1709 only, no wrong cause, no false discovery ([`cases_alone`]).
/// Planned for the middle of each cause's physical range instead
/// (`EHA_PLAN_MAGNITUDE=typical`, 2026-11-29, 284 s): 1700 → 0.74, 1701 →
/// 1.22, 1709 → **8.40** `unexplained` (500/10 → 500/100 → 2000 rpm/10 bar
/// every 300 s; the calibration takes the churning up on the training
/// window, its fit goes to 3e-7), 1711 → **2.97** `unexplained`, 1713 →
/// **6.51** `unexplained`, twins `unexplained` but 1701's: lifted 3, named
/// 0; the hidden candidate's r̂ nearer the flown r (1709 2.58, 1711 3.58,
/// 1713 4.01 against 2.07, 1.15, 2.01 at the fit starts). Not kept.
/// Planned for the hidden magnitude instead (`EHA_PLAN_MAGNITUDE=truth`,
/// an oracle, [`at_truth`]; 2026-11-29, 255 s): 1700 → 1.18, 1701 → 1.00,
/// 1709 → **8.40** `unexplained` (the middle magnitudes' mission), 1711 →
/// **2.72** `none` (the fit starts' mission), 1713 → 0.42 `unexplained`
/// (a fan mission at r̂ 2.05: the draught makes the twin's free
/// convection forced, and the twin misfits more): lifted 2, named 0.
/// `EHA_PLAN_SEEDS` (comma-separated) runs another list, and
/// `EHA_PLAN_MAGNITUDE=typical` or `truth` plans for the middle of each
/// physical range ([`magnitudes`]) or the hidden magnitude ([`at_truth`]);
/// either asserts only what holds whatever the ratios.
#[test]
#[ignore = "slow tier: five emulator cases planned, flown and diagnosed with their twins, ~8 min"]
fn slow_planned_runs_below_the_floor_default_structure() {
    let custom = std::env::var("EHA_PLAN_SEEDS").ok();
    let seeds: Vec<u64> = custom.as_deref().map_or(vec![1700, 1701, 1709, 1711, 1713], |v| v.split(',').map(|x| x.parse().expect("seed")).collect());
    let (rows, below, lifted, msg) = cases_alone(&seeds, Structure::NoCaseHeld);
    let ids = |v: &[AloneRow]| v.iter().map(|r| r.0).collect::<Vec<_>>();
    let named: Vec<u64> = lifted.iter().filter(|r| r.3 == case(r.0).hidden.name()).map(|r| r.0).collect();
    eprintln!("BELOW {} rows, {} below r 2 on the log, lifted {:?}, lifted and named {named:?}", rows.len(), below.len(), ids(&lifted));
    if custom.is_none() && std::env::var("EHA_PLAN_MAGNITUDE").is_err() {
        assert_eq!(ids(&below), [1700, 1701, 1709, 1711, 1713], "measured set below r 2 changed: {msg}");
        assert_eq!(ids(&lifted), [1709, 1711, 1713], "measured lift changed: {msg}");
        assert_eq!(named, [1709], "measured names changed: {msg}");
    }
}
