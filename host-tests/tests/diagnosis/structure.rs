//! The physical tier with the commissioning's structure
//! (`ReferenceModel::with_structure`, `DiagnoseOptions::structure`): the
//! pump's `eta_m` from the motor current by the commissioning's own
//! function, `pump_friction` held, the structural freedoms freed, and the
//! housing probes read towards the air by the calibration's probe model.
//! Fast tier: model construction and two replays of a 1200 s emulator log
//! (~1 s). Its effect on the floor and on the r >= 2 cases:
//! docs/diagnosis-limits.md, "The structure option and why `no-case-held`
//! is the default".

use eha_sim::calibration::commission::{eta_m_balance, eta_m_from_current, EtaMBalance};
use eha_sim::calibration::set::{FRICTION_CASE, PROBE_SURFACE, STRUCTURAL};
use eha_sim::diagnosis::analysis::Structure;
use eha_sim::calibration::CalLog;
use eha_sim::diagnosis::reference::{nuisance_set, ReferenceModel, HELD_OIL};
use eha_sim::diagnosis::{Candidate, Simulator};
use eha_sim::emulator::missions::EmuScenario::{self, ConstantThrottle, SpeedSteps};
use eha_sim::emulator::{generate, EmuCase};
use eha_sim::measured::{Channel, MeasuredRun};
use eha_sim::rig::Rig;

fn log(scenario: EmuScenario, seed: u64) -> MeasuredRun {
    generate(&EmuCase { hidden: Candidate::None, scenario, seed, duration_s: 1200.0 }).expect("emulator log").0
}

fn names(s: &dyn Simulator) -> Vec<String> {
    s.nuisance().into_iter().map(|p| p.name).collect()
}

/// A loaded throttle log (1714): `eta_m` is the commissioning's value to
/// the last bit (one implementation), the set loses `pump_friction` and
/// gains the six structural parameters (four housing probes logged); off,
/// the set is the log's own. A speed-step log at one low load (1716): the
/// balance's eta_m is implausible, nothing changes and the model says why.
#[test]
fn structure_takes_eta_from_the_current_and_frees_the_structural_set() {
    let run = log(ConstantThrottle, 1714);
    let rig = Rig::default();
    let want = eta_m_from_current(&rig, &[CalLog::new("log", run.clone(), 1).expect("log")]).expect("current under load");
    let on = ReferenceModel::new(rig.clone(), &run).expect("model").with_structure(&run, true);
    assert_eq!(on.eta_m_from_current(), Some(want));
    let set = names(&*on.physical_set().expect("physical"));
    assert!(!set.iter().any(|n| n == "pump_friction"), "{set:?}");
    for n in STRUCTURAL {
        assert!(set.iter().any(|s| s == n), "{n} not freed: {set:?}");
    }
    let off = ReferenceModel::new(rig.clone(), &run).expect("model").with_structure(&run, false);
    assert_eq!(off.eta_m_from_current(), None);
    let base: Vec<String> = nuisance_set(&run).into_iter().map(|k| eha_sim::calibration::PARAMS[k].name.to_string()).collect();
    assert_eq!(names(&*off.physical_set().expect("physical")), base);
    assert!(base.iter().any(|n| n == "pump_friction"));

    // Speed steps at one low load (1716): 596 loaded rows, but the balance
    // gives eta_m -0.079 (measured), outside the plausible range, so the
    // structure is not applied and the refusal says why.
    let quiet = log(SpeedSteps, 1716);
    let balance = eta_m_balance(&rig, &[CalLog::new("log", quiet.clone(), 1).expect("log")]);
    match balance {
        EtaMBalance::Fitted { eta_m, rows } => assert!(rows > 500 && eta_m < 0.0, "{balance:?}"),
        EtaMBalance::NoLoadedRows => panic!("1716 has loaded rows"),
    }
    let m = ReferenceModel::new(rig, &quiet).expect("model").with_structure(&quiet, true);
    assert_eq!(m.eta_m_from_current(), None, "implausible eta_m: not applied");
    assert!(m.structure_refusal().is_some_and(|r| r.contains("outside the plausible")), "{:?}", m.structure_refusal());
    assert_eq!(on.structure_refusal(), None);
    let b: Vec<String> = nuisance_set(&quiet).into_iter().map(|k| eha_sim::calibration::PARAMS[k].name.to_string()).collect();
    assert_eq!(names(&*m.physical_set().expect("physical")), b);
}

/// The `no-case` variant on the same loaded log (1714): the same `eta_m`
/// and the full variant's set without `friction_case` and
/// `probe_surface_pump` (the two a drain thermocouple would separate),
/// `friction_speed` and the other three housing probes still freed.
#[test]
fn structure_no_case_leaves_out_the_case_share_and_the_pump_probe() {
    let run = log(ConstantThrottle, 1714);
    let full = ReferenceModel::new(Rig::default(), &run).expect("model").with_structure(&run, Structure::Full);
    let nc = ReferenceModel::new(Rig::default(), &run).expect("model").with_structure(&run, Structure::NoCase);
    assert_eq!(nc.eta_m_from_current(), full.eta_m_from_current());
    let want: Vec<String> = names(&*full.physical_set().expect("physical")).into_iter().filter(|n| n != FRICTION_CASE && n != PROBE_SURFACE[1]).collect();
    let got = names(&*nc.physical_set().expect("physical"));
    assert_eq!(got, want);
    assert_eq!(got.len() + 2, names(&*full.physical_set().expect("physical")).len());
}

/// The `no-case-held` variant on the same loaded log (1714): the `no-case`
/// set without `cap_loop_oil` and `probe_oil` (held at the rig file,
/// `HELD_OIL`), the same `eta_m`; on the low-load speed-step log (1716)
/// nothing changes, as with every variant.
#[test]
fn structure_no_case_held_holds_the_loop_oil_and_the_oil_probe() {
    let run = log(ConstantThrottle, 1714);
    let nc = ReferenceModel::new(Rig::default(), &run).expect("model").with_structure(&run, Structure::NoCase);
    let held = ReferenceModel::new(Rig::default(), &run).expect("model").with_structure(&run, Structure::NoCaseHeld);
    assert_eq!(held.eta_m_from_current(), nc.eta_m_from_current());
    let want: Vec<String> = names(&*nc.physical_set().expect("physical")).into_iter().filter(|n| !HELD_OIL.contains(&n.as_str())).collect();
    let got = names(&*held.physical_set().expect("physical"));
    assert_eq!(got, want);
    assert_eq!(got.len() + 2, names(&*nc.physical_set().expect("physical")).len(), "both held parameters were in the no-case set");

    let quiet = log(SpeedSteps, 1716);
    let m = ReferenceModel::new(Rig::default(), &quiet).expect("model").with_structure(&quiet, Structure::NoCaseHeld);
    assert_eq!(m.eta_m_from_current(), None);
    let b: Vec<String> = nuisance_set(&quiet).into_iter().map(|k| eha_sim::calibration::PARAMS[k].name.to_string()).collect();
    assert_eq!(names(&*m.physical_set().expect("physical")), b);
}

/// The pump probe's parameter at θ = e^0.1 reads t_pump_c 10 % of metal −
/// ambient towards the air at every row where the housing is 5 K above
/// it (fraction within 0.01 plus the logged ambient's 0.1 K of the
/// difference: the probe acts on the replay's ambient, the check divides
/// by the logged cell), and leaves the other channels alone.
#[test]
fn structure_probe_reads_towards_the_air() {
    let run = log(ConstantThrottle, 1714);
    let m = ReferenceModel::new(Rig::default(), &run).expect("model").with_structure(&run, true);
    let p = m.physical_set().expect("physical");
    let specs = p.nuisance();
    let nom: Vec<f64> = specs.iter().map(|s| s.start).collect();
    let mut moved = nom.clone();
    let k = specs.iter().position(|s| s.name == "probe_surface_pump").expect("pump probe freed");
    moved[k] = 0.1f64.exp();
    let a = p.simulate(&nom, Candidate::None, &[]).expect("replay");
    let b = p.simulate(&moved, Candidate::None, &[]).expect("replay");
    let amb = run.get(Channel::AmbientC).expect("ambient");
    let (va, vb) = (&a.channels[&Channel::TPumpC], &b.channels[&Channel::TPumpC]);
    let mut checked = 0;
    for i in 0..run.len() {
        let Some(t_air) = amb[i] else { continue };
        // The replay's ambient is the logged one interpolated (0.05 K noise):
        // judge the fraction where the housing is well above the air.
        if va[i] - t_air > 5.0 {
            let f = (va[i] - vb[i]) / (va[i] - t_air);
            assert!((f - 0.1).abs() < 0.01 + 0.1 * 0.1 / (va[i] - t_air), "row {i}: fraction {f:.4}");
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked} rows with the housing 5 K above the air");
    for ch in [Channel::TMotorC, Channel::TBlockC, Channel::TOilC] {
        assert_eq!(a.channels[&ch], b.channels[&ch], "{}", ch.name());
    }
}
