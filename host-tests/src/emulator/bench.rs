//! Commissioning benches on emulated machines far from the paper rig: named
//! machine presets ([`machines`]), the user's rig file for each (the paper
//! rig with the nameplate values changed, [`EmuMachine::rig_file`]) and
//! bench-like logs with the drain-port thermocouple ([`bench_set`]):
//! training on two one-at-a-time throttle missions, held out a servo
//! mission and a throttle mix. Every log also carries the machine's true
//! (noise-free, lag-free) drain, the emulator's case-oil node, for scoring.

use super::missions::{draw, EmuScenario};
use super::params::EmuParams;
use super::plant::{Hidden, Plant, N};
use crate::physics::candidates::Candidate;
use crate::measured::{Channel, MeasuredRun};
use crate::rig::Rig;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// A named emulated machine.
#[derive(Debug, Clone)]
pub struct EmuMachine {
    /// Preset name.
    pub name: &'static str,
    /// The machine (no per-log redraw: one machine across its logs).
    pub params: EmuParams,
    /// What differs from the nominal emulator ([`EmuParams::default`]), one
    /// line each.
    pub deviations: &'static [&'static str],
}

/// Deviations of [`big_pump`] from the nominal emulator.
const BIG_PUMP: &[&str] = &[
    "displacement ×1.6 (30.4 cm³/rev)",
    "winding R25 0.074 → 0.048 Ω, torque constant 0.9 → 1.3 N·m/A (a bigger motor)",
    "stator capacity ×1.5, motor housing ×1.4, pump barrel and end cap ×1.6",
    "case oil volume ×1.7, case wetted area ×1.5, rotor radius 30 → 36 mm",
    "port oil ×1.6, port passages 12 → 14 mm",
    "η_m 0.36 → 0.28, leakage gap 13.5 → 14.5 µm (leakage ×1.24), iron loss ×1.4, mechanical loss split 50/30/20 → 40/40/20 (delivered oil/case oil/port plate)",
    "end cap → manifold joint 10 → 16 W/K, manifold → block 14 → 10 W/K",
    "manifold and block passage film areas ×0.7",
    "outer area motor ×1.3, pump barrel and end ×1.5; emissivity 0.92 → 0.80",
];

/// Deviations of [`leaky_heavy`] from the nominal emulator.
const LEAKY_HEAVY: &[&str] = &[
    "displacement ×0.8 (15.2 cm³/rev)",
    "winding R25 0.074 → 0.110 Ω, torque constant 0.9 → 0.62 N·m/A (a faster, smaller motor); stator → housing 24 → 16 W/K",
    "leakage gap 13.5 → 17 µm (leakage ×2.0), η_m 0.36 → 0.45, mechanical loss split 50/30/20 → 30/50/20",
    "case oil volume ×0.6, case wetted area ×0.7",
    "manifold plate ×1.3, main block ×1.4, ball block ×1.5 (capacities)",
    "end cap → manifold joint 10 → 4 W/K (an insulating flange gasket), ball block → main block 4 → 8 W/K",
    "ball passage film area ×1.5; hoses 1.2 m × 10 mm, ξ 4 → 2.0 m × 8 mm, ξ 6",
    "main and ball block outer areas ×0.8; emissivity 0.92 → 0.60",
    "probes slower: surface 12–14 s, oil 9 s, drain thermocouple 5 s",
];

/// A machine with a pump 1.6× the paper's and a bigger motor, other masses,
/// films and losses (`BIG_PUMP`).
pub fn big_pump() -> EmuMachine {
    let mut p = EmuParams::default();
    p.displacement_m3 *= 1.6;
    p.r25_ohm = 0.048;
    p.kt_nm_per_a = 1.3;
    p.c_stator *= 1.5;
    p.c_motor_case *= 1.4;
    p.c_pump.iter_mut().for_each(|c| *c *= 1.6);
    p.v_case *= 1.7;
    p.a_case.iter_mut().for_each(|a| *a *= 1.5);
    p.r_rotor = 0.036;
    p.v_port *= 1.6;
    p.port_duct = [0.014, 0.06, 2.0 * std::f64::consts::PI * 0.014 * 0.06];
    p.eta_m = 0.28;
    p.gap_m = 14.5e-6;
    p.iron_k.iter_mut().for_each(|k| *k *= 1.4);
    p.mech_split = [0.4, 0.4, 0.2];
    p.g_end_manifold = 16.0;
    p.g_manifold_block = 10.0;
    p.plate_duct[2] *= 0.7;
    p.block_duct[2] *= 0.7;
    p.surfaces[0][0] *= 1.3;
    p.surfaces[1][0] *= 1.5;
    p.surfaces[2][0] *= 1.5;
    p.emissivity = 0.80;
    EmuMachine { name: "big-pump", params: p, deviations: BIG_PUMP }
}

/// A machine with a smaller, leakier pump on a faster motor, heavier blocks,
/// an insulated pump flange and slower probes (`LEAKY_HEAVY`).
pub fn leaky_heavy() -> EmuMachine {
    let mut p = EmuParams::default();
    p.displacement_m3 *= 0.8;
    p.r25_ohm = 0.110;
    p.kt_nm_per_a = 0.62;
    p.g_stator_case = 16.0;
    p.gap_m = 17e-6;
    p.eta_m = 0.45;
    p.mech_split = [0.3, 0.5, 0.2];
    p.v_case *= 0.6;
    p.a_case.iter_mut().for_each(|a| *a *= 0.7);
    p.c_manifold *= 1.3;
    p.c_block *= 1.4;
    p.c_ball *= 1.5;
    p.g_end_manifold = 4.0;
    p.g_ball_block = 8.0;
    p.ball_duct[2] *= 1.5;
    p.hose = [2.0, 0.008, 6.0];
    p.surfaces[4][0] *= 0.8;
    p.surfaces[5][0] *= 0.8;
    p.emissivity = 0.60;
    p.sensor_tau = [12.0, 12.0, 14.0, 14.0, 9.0];
    p.drain_tau_s = 5.0;
    EmuMachine { name: "leaky-heavy", params: p, deviations: LEAKY_HEAVY }
}

/// The named machines.
pub fn machines() -> [EmuMachine; 2] {
    [big_pump(), leaky_heavy()]
}

impl EmuMachine {
    /// The user's rig file: the paper rig (`eha-sim rig`) with the nameplate
    /// values of this machine: displacement, winding resistance, torque
    /// constant. Everything else (masses, films, losses) as the paper's.
    pub fn rig_file(&self) -> Rig {
        let mut r = Rig::default();
        r.pump.displacement_cm3 = self.params.displacement_m3 * 1e6;
        r.motor.r25_ohm = self.params.r25_ohm;
        r.motor.torque_constant_nm_per_a = self.params.kt_nm_per_a;
        r
    }
}

/// The emulator's own trace behind [`bench_log`] (same mission draw for
/// the same seed), with the mission: for audits of its internal heat flows.
pub fn bench_trace(machine: &EmuMachine, scenario: EmuScenario, duration_s: f64, seed: u64) -> (super::missions::EmuMission, Vec<super::logger::Row>) {
    trace_with(machine, scenario, duration_s, &mut ChaCha8Rng::seed_from_u64(seed))
}

/// The mission drawn from `rng` and the machine's trace of it at the
/// scenario's log interval (the rng goes on to the logger's noise).
fn trace_with(machine: &EmuMachine, scenario: EmuScenario, duration_s: f64, rng: &mut ChaCha8Rng) -> (super::missions::EmuMission, Vec<super::logger::Row>) {
    let m = draw(scenario, duration_s, rng);
    let trace = Plant { p: &machine.params, m: &m, h: Hidden { effect: Candidate::None, magnitude: 0.0 } }.run(scenario.log_interval_s());
    (m, trace)
}

/// One bench log with the machine's true drain.
#[derive(Debug, Clone)]
pub struct BenchLog {
    /// Name (scenario and seed).
    pub name: String,
    /// The logged run, `t_drain_c` from the drain-port thermocouple.
    pub run: MeasuredRun,
    /// The same run with `t_drain_c` replaced by the true case-oil
    /// temperature at every row (no lag, noise, quantisation or dropout).
    pub truth: MeasuredRun,
}

/// A 1200–1800 s log of `machine` flying `scenario` (profile, ambient and
/// noise from `seed`), with the drain thermocouple.
pub fn bench_log(machine: &EmuMachine, scenario: EmuScenario, duration_s: f64, seed: u64) -> Result<BenchLog, String> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (m, trace) = trace_with(machine, scenario, duration_s, &mut rng);
    let dt = scenario.log_interval_s();
    if trace.iter().any(|r| r.1.iter().any(|v| !v.is_finite())) {
        return Err(format!("emulator diverged on {} {scenario:?}", machine.name));
    }
    let run = super::log_mission_as(&trace, &m, true, &mut rng);
    let name = format!("{}-{scenario:?}-{seed}", machine.name);
    run.validate(&name).map_err(|e| e.to_string())?;
    let mut truth = run.clone();
    let drain: Vec<Option<f64>> = run.time_s.iter().map(|&t| Some(trace[(t / dt).round() as usize].1[N::CaseOil as usize])).collect();
    truth.set(Channel::TDrainC, drain);
    Ok(BenchLog { name, run, truth })
}

/// Training and held-out logs of one machine.
#[derive(Debug, Clone)]
pub struct BenchSet {
    /// Two one-at-a-time throttle missions: speed then needle steps (1800 s),
    /// a soak then idle (1800 s).
    pub train: Vec<BenchLog>,
    /// A servo hold/manoeuvre mission (1200 s) and a throttle mix (1800 s).
    pub holdout: Vec<BenchLog>,
}

/// The bench logs of `machine`; seeds `seed`, `seed + 1`, ...
pub fn bench_set(machine: &EmuMachine, seed: u64) -> Result<BenchSet, String> {
    Ok(BenchSet {
        train: vec![
            bench_log(machine, EmuScenario::SpeedThenNeedleSteps, 1800.0, seed)?,
            bench_log(machine, EmuScenario::SoakThenIdle, 1800.0, seed + 1)?,
        ],
        holdout: holdout_logs(machine, seed)?,
    })
}

/// The logs of `machine` as the commissioning procedure prescribes them
/// (docs/commissioning.md, "Bench procedure"): the speed-then-needle
/// steps and a soak followed by low-speed holds
/// ([`EmuScenario::SoakThenLowSpeedHolds`], which holds the pump below 100
/// rpm so that the case film's speed law is fitted). Held out: the same
/// servo and throttle-mix logs as [`bench_set`] (same seeds, unchanged).
/// Two-log variants that reach the envelope's high-speed, high-load corner
/// ([`commissioning_set_of`]) were measured and not adopted
/// (docs/commissioning-foreign.md, "Training logs over the operating envelope").
pub fn commissioning_set(machine: &EmuMachine, seed: u64) -> Result<BenchSet, String> {
    let b = bench_set(machine, seed)?;
    Ok(BenchSet {
        train: vec![b.train[0].clone(), bench_log(machine, EmuScenario::SoakThenLowSpeedHolds, 1800.0, seed + 1)?],
        holdout: b.holdout,
    })
}

/// [`commissioning_set`] with a third training log, the hot-flow run
/// ([`EmuScenario::WarmThenHotSpeedSteps`], seed `seed + 4`: speed steps at
/// 850–1200 rpm and 40–50 bar with the oil hot, where big-pump's passage
/// flow reaches the duct law's transition). Measured, not the procedure's
/// default: it lowers big-pump's held-out under-prediction and raises
/// leaky-heavy's (docs/commissioning-foreign.md, "The hot-flow run").
pub fn commissioning_set_hot(machine: &EmuMachine, seed: u64) -> Result<BenchSet, String> {
    let mut s = commissioning_set(machine, seed)?;
    s.train.push(bench_log(machine, EmuScenario::WarmThenHotSpeedSteps, 1800.0, seed + 4)?);
    Ok(s)
}

/// A two-log training set of `machine` from the given one-at-a-time
/// scenarios (1800 s each, seeds `seed` and `seed + 1`, the seeds of
/// [`commissioning_set`]'s two logs), held out on [`bench_set`]'s servo and
/// throttle-mix logs. For comparing training procedures on the same
/// held-out logs (docs/commissioning-foreign.md, "Training logs over the
/// operating envelope").
pub fn commissioning_set_of(machine: &EmuMachine, seed: u64, train: [EmuScenario; 2]) -> Result<BenchSet, String> {
    Ok(BenchSet {
        train: vec![bench_log(machine, train[0], 1800.0, seed)?, bench_log(machine, train[1], 1800.0, seed + 1)?],
        holdout: holdout_logs(machine, seed)?,
    })
}

/// The held-out servo (1200 s) and throttle-mix (1800 s) logs of
/// [`bench_set`] drawn with `seed` (seeds `seed + 2`, `seed + 3`). With
/// `seed + 10` in place of the set's seed: a second held-out draw, to check
/// a training procedure chosen on the first.
pub fn holdout_logs(machine: &EmuMachine, seed: u64) -> Result<Vec<BenchLog>, String> {
    Ok(vec![bench_log(machine, EmuScenario::ServoHoldMove, 1200.0, seed + 2)?, bench_log(machine, EmuScenario::ThrottleMix, 1800.0, seed + 3)?])
}
