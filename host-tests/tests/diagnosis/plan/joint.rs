//! Test plans decided jointly: the original log and the planned run
//! diagnosed together (`eha-sim diagnose log.csv planned.csv`, one
//! calibration), planned alone or for the joint decision (`--joint`).

use super::*;

/// The joint diagnosis of `logs` (one machine) under structure `s`, as
/// `eha-sim diagnose a.csv b.csv --structure S` makes it: one calibration
/// for every log.
fn diagnose_joint(logs: &[&MeasuredRun], s: Structure) -> eha_sim::diagnosis::Diagnosis {
    use eha_sim::diagnosis::multi::{joint_reference, options_for};
    let o = options_for(&DiagnoseOptions::default(), logs.len());
    let files: Vec<String> = (1..=logs.len()).map(|k| format!("log {k}")).collect();
    let (rows, joint, _) = joint_reference(&Rig::default(), logs, &files, o.train_fraction, s).expect("joint model");
    diagnose(&rows, &joint, &o).expect("joint diagnosis")
}

/// One case decided jointly: the original log and the planned run of
/// `duration_s` diagnosed together (one calibration), and the joint twin
/// (the original's twin and the planned run's twin) likewise. Returns the
/// joint imprint ratio r (the joint baseline's held-out misfit on the
/// effect's channel — the planned run's, where the imprint is largest —
/// pooled over both logs' held-out windows, log pair over twin pair), the
/// joint answer and the joint twin's answer.
fn joint_case(seed: u64, duration_s: f64, decision: Decision, s: Structure) -> (f64, String, String) {
    let c = case(seed);
    let (log, truth) = generate(&c).expect("log");
    let (twin, _) = generate_twin(&c).expect("twin");
    let ch = truth.affected.expect("affected").0;
    let o = DiagnoseOptions::default();
    let d0 = diagnose(&log, &model_of(&log, s), &o).expect("diagnosis");
    let lead = leading_of(&d0);
    let p = plan(&Rig::default(), &log, &magnitudes(&log, &lead), Limits::for_rig(&Rig::default(), &log), duration_s, decision).expect("plan");
    let exp: Vec<String> = p.expected.iter().map(|e| format!("{} r̂ {:.2} on {} (log {:.2})", e.planned.candidate, e.planned.best.1, e.planned.best.0, e.on_log.as_ref().map_or(f64::NAN, |r| r.best.1))).collect();
    eprintln!("  plan ({:?}): {} (D_s {:.3}); expected {}", p.decision, p.design.name, p.d_s, exp.join(", "));
    let (plog, ptwin, pch) = fly(&p.design, &c, &truth, mean_ambient(&log));
    dump(seed, &format!("{duration_s:.0}-{:?}", p.decision), &[("log", &log), ("twin", &twin), ("planned", &plog), ("planned-twin", &ptwin)]);
    let dj = diagnose_joint(&[&log, &plog], s);
    let tj = diagnose_joint(&[&twin, &ptwin], s);
    for (l, x) in [("original", &d0), ("joint", &dj), ("joint twin", &tj)] {
        eprintln!("  {}", summary(l, x));
    }
    let r = heldout_k(&dj, pch) / heldout_k(&tj, pch);
    eprintln!(
        "{seed} {}: leading {lead:?}; plan {}; effect's channel {} (original's {}); joint r {r:.2} ({}; joint twin {})",
        c.hidden.name(),
        p.design.name,
        pch.name(),
        ch.name(),
        dj.answer(),
        tj.answer()
    );
    (r, dj.answer().to_string(), tj.answer().to_string())
}

/// One case of [`slow_planned_runs_lift_effects_above_the_floor`] decided
/// jointly ([`joint_case`]), a by-hand measurement one case at a time: the
/// seed from `EHA_PLAN_SEED` (default 1708), the plan's duration from
/// `EHA_PLAN_DURATION_S` (default 1200 s), planned for the joint decision
/// when `EHA_PLAN_JOINT=1` ([`Decision::Joint`]), else for the planned run
/// alone; `EHA_PLAN_DUMP=DIR` writes the four logs as CSV.
#[test]
#[ignore]
fn slow_joint_case() {
    let seed = std::env::var("EHA_PLAN_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1708);
    let dur = std::env::var("EHA_PLAN_DURATION_S").ok().and_then(|s| s.parse().ok()).unwrap_or(1200.0);
    let decision = if std::env::var("EHA_PLAN_JOINT").is_ok_and(|v| v == "1") { Decision::Joint } else { Decision::Alone };
    let (r, a, t) = joint_case(seed, dur, decision, structure());
    eprintln!("JOINT {seed} {dur}: r {r:.2} {a} (twin {t})");
}

/// 1708 (churning, r 2.35 on its log under the default structure and
/// answered `none` there: a miss at r ≥ 2) with a 1200 s run planned for
/// it alone and both logs diagnosed together under the default structure,
/// as `eha-sim diagnose log.csv planned.csv` does. Re-measured 2026-11-29
/// evening after the plan's choice changed (every candidate planned for,
/// the log admitting none; the mission 500 rpm/10 bar → 2000 rpm/10 bar →
/// 500 rpm/100 bar every 300 s, churning r̂ 2.16): joint r 1.63,
/// `churning-loss` named (right), the joint twin `unexplained`. (The old
/// plan, 2000 rpm/10 bar ↔ 1250 rpm/55 bar: joint r 5.58, named, twin
/// `none`.) Tolerance on r ±0.5 (the ratios moved by up to 0.3 with the
/// code merged between the plan tables' measurements).
#[test]
#[ignore = "slow tier: four emulator diagnoses, ~1 min"]
fn slow_planned_run_decided_together_default_structure() {
    let (r, a, t) = joint_case(1708, 1200.0, Decision::Alone, Structure::NoCaseHeld);
    assert_eq!(a, "churning-loss", "r {r:.2}");
    assert!(["none", "unexplained"].contains(&t.as_str()), "false discovery on the joint twin: {t}");
    assert!((r - 1.63).abs() <= 0.5, "joint r {r:.2}, measured 1.63");
}

/// The six cases of [`slow_planned_runs_lift_effects_above_the_floor`]
/// decided jointly ([`joint_case`], 1200 s plans made for `decision`):
/// (seed, joint r, joint answer, joint twin's answer). Asserts what holds
/// whatever the ratios: no wrong cause on a joint log, no discovery on a
/// joint twin.
fn six_joint(decision: Decision) -> Vec<(u64, f64, String, String)> {
    let mut rows = Vec::new();
    for s in SIX {
        let (r, a, t) = joint_case(s, 1200.0, decision, structure());
        rows.push((s, r, a, t));
    }
    let msg = format!("{rows:?}");
    eprintln!("{decision:?}: {msg}");
    for (s, _, a, t) in &rows {
        assert!(["none", "unexplained", case(*s).hidden.name()].contains(&a.as_str()), "wrong cause on a joint log: {msg}");
        assert!(["none", "unexplained"].contains(&t.as_str()), "false discovery on a joint twin: {msg}");
    }
    rows
}

/// The six cases decided jointly — the original log and the planned run
/// (planned for the planned run alone, the same missions as
/// [`slow_planned_runs_lift_effects_above_the_floor`]) diagnosed together,
/// one calibration; r against the joint twin (the original's twin and the
/// planned run's twin together). **Measured miss**: joint r 1708 1.86
/// (`unexplained`), 1710 0.63 (`unexplained`), 1712 0.50 (`none`), 1709
/// 0.74 (`unexplained`), 1700 2.01 (`unexplained`), 1713 1.22 (`none`);
/// twins `none`, `none`, `none`, `unexplained`, `unexplained`, `none`. One
/// case lifted to r ≥ 2 (1700, at the edge) and not named; no wrong cause,
/// no false discovery. Where the candidate's evidence is large (1700
/// winding ln BF 185, 1710 conduction 52) its fit fails the pooled
/// held-out check (pooled RMSE no better than the baseline's).
/// Re-measured case by case on 2026-11-28 under the touched-channel rule
/// ([`slow_joint_case`]): the same answers, 1708's joint r 1.81, the
/// others to the digit. Asserted as
/// measured: none named at r ≥ 2, at most one lifted (1700's 2.01 sits on
/// the line: the ratio moves with both calibrated baselines' last digits).
/// 558 s at load ~4. Re-run on 2026-11-29 after the reference's fix
/// (b36ffe3), 367 s, passing: joint r 1708 1.85 (`churning-loss`, right
/// below r = 2), 1710 0.72, 1712 1.22, 1709 1.83, 1700 1.15, 1713 0.92;
/// none lifted; twins `none` ×4, `unexplained` ×2. Re-run on 2026-11-29
/// evening after the plan's choice changed (the plans of
/// [`slow_planned_runs_lift_effects_above_the_floor`]), 415 s, passing:
/// joint r 1708 **3.67** (`none`: a miss at r ≥ 2), 1710 1.20, 1712 1.06,
/// 1709 0.18 (alone the same planned run stands at 7.23 and is named:
/// with the original log in the calibration its imprint is taken up),
/// 1700 1.30, 1713 1.89; twins `none` ×4, `unexplained` ×2.
#[test]
#[ignore]
fn slow_planned_runs_decided_jointly() {
    let rows = six_joint(Decision::Alone);
    let lifted: Vec<_> = rows.iter().filter(|r| r.1 >= 2.0).collect();
    let msg = format!("{rows:?}");
    assert!(lifted.len() <= 1, "measured miss changed (1708 only, r 3.67): {msg}");
    assert!(lifted.iter().all(|r| r.2 != case(r.0).hidden.name()), "measured miss changed (none named at r ≥ 2): {msg}");
}

/// The six cases with plans made for the joint decision
/// ([`Decision::Joint`]: D_s on the stacked projected imprints of the log
/// and the planned run) and decided jointly. Measured: joint r 1708 1.60
/// (**`churning-loss`**, named right: ΔBIC 855, t_pump_c −50 %, pooled
/// −32 %, ln BF 84.9), 1710 0.63 (`unexplained`; the same mission as
/// planned alone), 1712 0.82 (`none`), 1709 1.36 (`unexplained`: churning
/// ΔBIC 752, t_pump_c −76 %, pooled only −14 %), 1700 1.38
/// (`unexplained`), 1713 1.02 (`none`); twins `none`, `none`, `none`,
/// `unexplained`, `unexplained`, `none`. **Measured miss**: none lifted to
/// r ≥ 2 (the acceptance asks half); one right name below r = 2; no wrong
/// cause, no false discovery. Re-measured case by case on 2026-11-28
/// under the touched-channel rule ([`slow_joint_case`], same missions,
/// same answers): 1708 1.60 `churning-loss` to the digit, 1709 1.30
/// (churning ΔBIC 585, t_pump_c −75 %, pooled −12 %), 1712 0.89, 1700
/// 1.62, 1710 and 1713 to the digit. 939 s at load ~5 when first
/// measured. Re-run on
/// 2026-11-29 after the reference's fix (b36ffe3), 397 s, passing: joint r
/// 1708 1.77 (`churning-loss`), 1710 0.68, 1712 1.02, 1709 0.71, 1700
/// 0.87, 1713 0.84; twins `none` ×4, `unexplained` ×2.
/// Re-run on 2026-11-29 evening after the plan's choice changed (the most
/// candidates at r̂ ≥ 2 over the two- and three-level families, D_s on
/// the stacked imprints the last tie-break; every candidate planned for),
/// 528 s: joint r 1708 **2.95** (`none`: a miss at r ≥ 2), 1710 0.66,
/// 1712 0.89, 1709 0.88, 1700 0.82, 1713 **3.05 `forced-convection`**
/// (named right: the original AirSteps log gives the joint table the air
/// span a draught needs); twins `none` ×4, `unexplained` ×2. Asserted as
/// measured: lifted exactly 1708 and 1713, named 1713 only.
#[test]
#[ignore]
fn slow_jointly_planned_runs_decided_jointly() {
    let rows = six_joint(Decision::Joint);
    let msg = format!("{rows:?}");
    let lifted: Vec<u64> = rows.iter().filter(|r| r.1 >= 2.0).map(|r| r.0).collect();
    assert_eq!(lifted, [1708, 1713], "measured lift changed: {msg}");
    let named: Vec<u64> = rows.iter().filter(|r| r.2 == case(r.0).hidden.name()).map(|r| r.0).collect();
    assert_eq!(named, [1713], "measured names changed: {msg}");
}
