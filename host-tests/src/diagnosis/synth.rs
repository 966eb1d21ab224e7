//! Seeded generator of synthetic "measured" runs with one hidden effect:
//! the reference simulation with one extension switched on (magnitude drawn
//! from a realistic range), nuisance multipliers perturbed by ±10–20 %,
//! optionally per-node capacities and conductances the baseline does not
//! know, then sensor noise (σ = 0.1 K), 12-bit quantisation and dropped
//! samples. Used by the diagnosis tests and the `diagnose-sweep` command.

use super::model::Candidate;
use crate::measured::{Channel, MeasuredRun};
use crate::rig::Rig;
use crate::scenario::{Circuit, Mission, PositionRef, Schedule, Scenario, ValveRule};
use crate::sim::{simulate, SimOptions};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Operating scenario of a synthetic run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SynthScenario {
    /// Case 1 throttle circuit, 500 rpm, needle valve at 20–60 bar.
    Case1Pressure,
    /// Servo circuit: closed-loop sine tracking (amplitude, frequency drawn).
    Servo,
    /// Throttle mission with speed and needle-pressure steps.
    ThrottleSteps,
}

/// How far the generating rig is from the diagnosis baseline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mismatch {
    /// Only the four nuisance multipliers are perturbed (±10–20 %).
    Nuisance,
    /// Also every node's mass and the winding/sensor conductances are
    /// changed individually (×0.7…1.4), which the global multipliers of the
    /// baseline cannot represent.
    Structure,
}

/// One synthetic case.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SynthCase {
    /// The hidden effect (`None` for a clean run).
    pub hidden: Candidate,
    /// Scenario.
    pub scenario: SynthScenario,
    /// Nuisance physics of the generator.
    pub mismatch: Mismatch,
    /// Seed of every random draw.
    pub seed: u64,
    /// Run duration, s.
    pub duration_s: f64,
    /// Logger sample interval, s.
    pub sample_s: f64,
}

/// What the generator did (never shown to the diagnosis).
#[derive(Debug, Clone)]
pub struct Truth {
    /// Hidden effect magnitude (extension parameter; 1 for the switch).
    pub magnitude: f64,
    /// Generating rig.
    pub rig: Rig,
    /// The channel the hidden effect changes most (RMS difference between
    /// the generator with and without the effect over the last 30 % of the
    /// run), with that RMS difference, K. `None` for clean runs.
    pub affected: Option<(Channel, f64)>,
}

/// Realistic magnitude range of each extension (its parameter's unit in
/// `eha_sim::rig::Extensions`).
pub fn magnitude_range(c: Candidate) -> (f64, f64) {
    match c {
        // copper: 3.9e-3 1/K; alloys and winding hot spots 3e-3…4.3e-3
        Candidate::WindingResistanceTemperature => (3.0e-3, 4.3e-3),
        // dead-end pocket (Figs. 9–10): minutes
        Candidate::SensorLag => (60.0, 240.0),
        // piston-seal Coulomb friction of a 1527 mm² ram, N
        Candidate::CoulombFriction => (300.0, 800.0),
        // churning ∝ ω^2.5, a few 10 W at 1500 rpm (ω^2.5 ≈ 3.2e5)
        Candidate::ChurningLoss => (1.0e-4, 2.5e-4),
        // flange conduction, W/K
        Candidate::MotorPumpConduction => (3.0, 8.0),
        // unlogged fan / draught, m/s
        Candidate::ForcedConvection => (3.0, 8.0),
        Candidate::ViscosityTemperature | Candidate::None => (1.0, 1.0),
    }
}

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

fn perturb(rng: &mut ChaCha8Rng) -> f64 {
    let m = rng.random_range(0.10..0.20);
    if rng.random_bool(0.5) { 1.0 + m } else { 1.0 - m }
}

fn mission(c: &SynthCase, rng: &mut ChaCha8Rng) -> Mission {
    let d = c.duration_s;
    let amb = rng.random_range(14.0..28.0);
    let base = Mission {
        name: format!("synth-{:?}-{}", c.scenario, c.seed),
        circuit: Circuit::Throttle,
        duration_s: d,
        ambient_c: Schedule::constant(amb),
        speed_rpm: Schedule::constant(500.0),
        needle_bar: Schedule::constant(60.0),
        position: PositionRef::Profile(Schedule::constant(0.0)),
        air_speed_mps: Schedule::constant(0.0),
        valve: ValveRule::None,
    };
    match c.scenario {
        SynthScenario::Case1Pressure => Mission { needle_bar: Schedule::constant([20.0, 40.0, 60.0][rng.random_range(0..3)]), ..base },
        SynthScenario::Servo => Mission {
            circuit: Circuit::Servo,
            speed_rpm: Schedule::constant(0.0),
            needle_bar: Schedule::constant(0.0),
            position: PositionRef::Sine {
                amplitude_m: rng.random_range(0.015..0.025),
                freq_hz: rng.random_range(0.15..0.3),
                offset_m: 0.0,
            },
            ..base
        },
        SynthScenario::ThrottleSteps => {
            // Four segments, each a random speed (500–2000 rpm) and needle
            // pressure (10–60 bar), stepping at random times.
            let mut ts: Vec<f64> = (0..3).map(|_| rng.random_range(0.1..0.9) * d).collect();
            ts.sort_by(f64::total_cmp);
            let (mut sp, mut nb) = (vec![], vec![]);
            let mut t_prev = 0.0;
            for k in 0..4 {
                let (s, p) = (rng.random_range(500.0..2000.0), rng.random_range(10.0..60.0));
                if k > 0 {
                    sp.push((t_prev, s));
                    nb.push((t_prev, p));
                } else {
                    sp.push((0.0, s));
                    nb.push((0.0, p));
                }
                let t_end = if k < 3 { ts[k] } else { d };
                sp.push((t_end, s));
                nb.push((t_end, p));
                t_prev = t_end;
            }
            Mission { speed_rpm: Schedule(sp), needle_bar: Schedule(nb), ..base }
        }
    }
}

/// The generating rig of `c`: default rig, nuisance (and structure)
/// perturbed, the hidden extension on at a drawn magnitude.
pub fn truth_rig(c: &SynthCase, rng: &mut ChaCha8Rng) -> (Rig, f64) {
    let mut r = Rig::default();
    r.nuisance.outer_scale *= perturb(rng);
    r.nuisance.inner_scale *= perturb(rng);
    r.nuisance.metal_capacity_scale *= perturb(rng);
    r.nuisance.oil_capacity_scale *= perturb(rng);
    if c.mismatch == Mismatch::Structure {
        let mut f = || rng.random_range(0.7..1.4);
        r.motor.mass_kg *= f();
        r.pump.mass_kg *= f();
        r.blocks.main_mass_kg *= f();
        r.blocks.ball_mass_kg *= f();
        r.actuator.body_mass_kg *= f();
        r.motor.winding_to_housing_w_per_k *= f();
    }
    let (lo, hi) = magnitude_range(c.hidden);
    let m = if hi > lo { rng.random_range(lo..hi) } else { lo };
    let e = &mut r.ext;
    match c.hidden {
        Candidate::WindingResistanceTemperature => e.winding_resistance_temperature = Some(m),
        Candidate::ViscosityTemperature => e.viscosity_temperature = true,
        Candidate::SensorLag => e.sensor_lag = Some(m),
        Candidate::CoulombFriction => e.coulomb_friction = Some(m),
        Candidate::ChurningLoss => e.churning_loss = Some(m),
        Candidate::MotorPumpConduction => e.motor_pump_conduction = Some(m),
        Candidate::ForcedConvection => e.forced_convection = Some(m),
        Candidate::None => {}
    }
    (r, m)
}

/// 12-bit quantisation of a temperature over the sensor span 0…200 °C
/// (LSB 0.049 K).
pub fn quantise(t_c: f64) -> f64 {
    let lsb = 200.0 / 4095.0;
    ((t_c / lsb).round() * lsb).clamp(0.0, 200.0)
}

/// Generates the measured run of case `c`.
pub fn generate(c: &SynthCase) -> Result<(MeasuredRun, Truth), String> {
    let mut rng = ChaCha8Rng::seed_from_u64(c.seed);
    let m = mission(c, &mut rng);
    let (rig, magnitude) = truth_rig(c, &mut rng);
    let opts = SimOptions { output_interval_s: c.sample_s, control_interval_s: c.sample_s.min(0.5) };
    let scenario = Scenario::Mission(m);
    let out = simulate(&rig, &scenario, &opts).map_err(|e| e.to_string())?;
    let affected = if c.hidden == Candidate::None {
        None
    } else {
        let mut off = rig.clone();
        off.ext = Default::default();
        let o2 = simulate(&off, &scenario, &opts).map_err(|e| e.to_string())?;
        let t_split = out.time_s[0] + 0.7 * (out.time_s[out.time_s.len() - 1] - out.time_s[0]);
        Channel::TEMPERATURES
            .into_iter()
            .filter_map(|ch| {
                let (a, b) = (out.get(ch.name())?, o2.get(ch.name())?);
                let d: Vec<f64> = (0..a.len()).filter(|&i| out.time_s[i] >= t_split).map(|i| (a[i] - b[i]).powi(2)).collect();
                Some((ch, (d.iter().sum::<f64>() / d.len().max(1) as f64).sqrt()))
            })
            .max_by(|x, y| x.1.total_cmp(&y.1))
    };
    // Logger: a few whole rows dropped (1 %), a few single cells empty (0.5 %).
    let keep: Vec<usize> = (0..out.time_s.len()).filter(|&i| i == 0 || !rng.random_bool(0.01)).collect();
    let mut run = MeasuredRun::new(keep.iter().map(|&i| out.time_s[i]).collect());
    run.push_meta("rig", "synthetic");
    run.push_meta("note", "generated by eha_sim::diagnosis::synth");
    let servo = c.scenario == SynthScenario::Servo;
    for ch in Channel::ALL {
        if ch == Channel::LngValve || ch == Channel::AirSpeedMps || (ch == Channel::PositionMm && !servo) {
            continue;
        }
        let Some(v) = out.get(ch.name()) else { continue };
        let col: Vec<Option<f64>> = keep
            .iter()
            .map(|&i| {
                let x = v[i];
                if ch.is_temperature() {
                    let drop = rng.random_bool(0.005);
                    let y = quantise(x + 0.1 * gauss(&mut rng));
                    (!drop).then_some(y)
                } else {
                    Some(x)
                }
            })
            .collect();
        run.set(ch, col);
    }
    run.validate("synthetic").map_err(|e| e.to_string())?;
    Ok((run, Truth { magnitude, rig, affected }))
}
