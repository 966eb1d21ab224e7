//! Seeded generator of synthetic "measured" runs with one hidden effect:
//! the reference simulation with one extension switched on (magnitude drawn
//! from a realistic range), nuisance multipliers perturbed by ±10–20 %,
//! optionally per-node capacities and conductances the baseline does not
//! know, then sensor noise (σ = 0.1 K), 12-bit quantisation and dropped
//! samples. Used by the diagnosis tests and the `diagnose-sweep` command.

mod mission;

use super::model::Candidate;
use mission::mission;
use crate::data::acquisition::{gauss, quantise};
pub use crate::physics::candidates::magnitude_range;
use crate::measured::{Channel, MeasuredRun};
use crate::rig::Rig;
use crate::scenario::Scenario;
use crate::sim::{simulate, SimOptions};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Operating scenario of a synthetic run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SynthScenario {
    /// Case 1 throttle circuit, 500 rpm, needle valve at 20–60 bar.
    Case1Pressure,
    /// Servo circuit: closed-loop sine tracking, amplitude 30–40 mm (of the
    /// ±50 mm stroke) at 0.2–0.25 Hz (paper Case 2: 20 mm at 0.2 Hz).
    Servo,
    /// Throttle mission with speed and needle-pressure steps.
    ThrottleSteps,
    /// Servo mission: triangular position profile whose amplitude and
    /// half-period change every cycle, in duty segments of 120–240 s that
    /// alternate between brisk motion (20–40 mm, half-period 2–3 s) and
    /// slow small moves (5–12 mm, 3–6 s).
    ServoProfile,
    /// Throttle mission: speed steps 1000–2000 rpm every 100–250 s at low
    /// needle pressure (5–25 bar), the regime where speed losses dominate.
    SpeedSweep,
    /// Throttle mission with load cycles: one speed (800–1200 rpm), the
    /// needle pressure stepping between a low (10–30 bar) and a high
    /// (70–100 bar) level every 120–240 s. Current, leakage (∝ Δp²/μ) and
    /// motor heating change in steps while the oil warms up: the load
    /// changes that separate effects scaling with current, pressure or
    /// temperature from a different conductance or capacity.
    LoadCycles,
    /// Servo mission that separates the seal-friction heat from the load:
    /// duty segments of 120–240 s alternate between *holding* a deflection
    /// of 25–40 mm against the spring (the aerodynamic load of a trimmed
    /// surface: 40–64 bar, high current and leakage, the piston still) and
    /// *manoeuvring* about the centre (triangles of 15–25 mm, half-period
    /// 1.0–1.6 s: piston speed 0.02–0.05 m/s at low pressure). Copper and
    /// leakage heat are high while the piston stands, the friction heat
    /// F·|v| only while it moves, so the two cannot stand in for each other
    /// through a conductance or a capacity (in `ServoProfile` both grow with
    /// the stroke). Logged at 0.1 s (the format's interval for sinusoidal
    /// runs): the replay takes the piston speed from the logged position.
    ServoHoldMove,
    /// Servo mission of a trimmed surface in gusts: duty segments of
    /// 120–240 s, each at its own trim deflection (−25…25 mm, held against
    /// the spring), alternately calm (the piston still at the trim) and
    /// gusty (the position loop rejecting gusts: triangles of 10–18 mm about
    /// the trim, half-period 0.7–1.2 s, piston speed 0.02–0.05 m/s). The
    /// load losses follow the trim, the friction heat F·|v| the gusts, and
    /// the two are drawn independently. Logged at 0.1 s. (First drawn with
    /// 4–8 mm gusts about trims of ±35 mm: 0.01–0.03 m/s left an imprint of
    /// 0.18–0.24 K on t_oil_c, which the calibration took up: both Coulomb
    /// cases named `none`.)
    ServoGust,
    /// Throttle mission at high pressure with speed steps: the needle set
    /// for a drop of 70–100 bar (drawn once) at every speed, the shaft
    /// speed stepping between 500 and 1200 rpm every 120–240 s. The heat
    /// Δp·D·ω steps with the speed while the leakage part (∝ Δp²/μ) does
    /// not, and the oil warms by tens of kelvin, so a leakage that grows as
    /// the oil thins shows against the speed steps. (Also drawn at 50–80 bar
    /// and 400–900 rpm: viscosity was then named `none` in the nuisance case,
    /// 46 % on t_oil_c and 3 % pooled.)
    PressureSpeedSteps,
    /// Case 1 (500 rpm, needle 40–60 bar) with logged ram-air steps: the
    /// air speed over the housings (`air_speed_mps`, logged) alternates
    /// between still air and 10–25 m/s every 150–300 s (Table 5 ram air).
    AirSteps,
}

impl SynthScenario {
    /// Every scenario.
    pub const ALL: [SynthScenario; 10] = [
        SynthScenario::Case1Pressure,
        SynthScenario::Servo,
        SynthScenario::ThrottleSteps,
        SynthScenario::ServoProfile,
        SynthScenario::SpeedSweep,
        SynthScenario::LoadCycles,
        SynthScenario::AirSteps,
        SynthScenario::ServoHoldMove,
        SynthScenario::ServoGust,
        SynthScenario::PressureSpeedSteps,
    ];

    /// Whether the run logs `air_speed_mps` (the ram air of the mission;
    /// never the hidden forced convection).
    pub fn logs_air(self) -> bool {
        self == SynthScenario::AirSteps
    }

    /// Whether the run is a servo mission (piston moving, position logged).
    pub fn is_servo(self) -> bool {
        matches!(
            self,
            SynthScenario::Servo | SynthScenario::ServoProfile | SynthScenario::ServoHoldMove | SynthScenario::ServoGust
        )
    }

    /// Logger interval of this scenario for a requested interval
    /// `sample_s`, s: servo runs at most 0.5 s (slower logging would alias
    /// the position, whose derivative drives the replay), the hold/move
    /// and gust missions (half-periods down to 0.7 s) at most 0.1 s.
    pub fn log_interval_s(self, sample_s: f64) -> f64 {
        match self {
            SynthScenario::ServoHoldMove | SynthScenario::ServoGust => sample_s.min(0.1),
            s if s.is_servo() => sample_s.min(0.5),
            _ => sample_s,
        }
    }

    /// Whether `hidden` can act at all in this scenario: Coulomb friction
    /// needs a moving piston (servo circuit); churning (∝ ω^2.5) needs the
    /// high shaft speeds of the throttle missions with speed steps. Other
    /// pairs are physically valid in every scenario.
    pub fn can_show(self, hidden: Candidate) -> bool {
        match hidden {
            Candidate::CoulombFriction => self.is_servo(),
            Candidate::ChurningLoss => {
                matches!(self, SynthScenario::ThrottleSteps | SynthScenario::SpeedSweep | SynthScenario::PressureSpeedSteps)
            }
            _ => true,
        }
    }
}

/// How far the generating rig is from the diagnosis baseline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mismatch {
    /// Only the four nuisance multipliers are perturbed (±10–20 %).
    Nuisance,
    /// Also every node's mass and the winding/sensor conductances are
    /// changed individually (×0.8…1.25), which the global multipliers of the
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

fn perturb(rng: &mut ChaCha8Rng) -> f64 {
    let m = rng.random_range(0.10..0.20);
    if rng.random_bool(0.5) { 1.0 + m } else { 1.0 - m }
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
        let mut f = || rng.random_range(0.8..1.25);
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
        Candidate::SensorLag => e.sensor_lag = Some(m),
        Candidate::CoulombFriction => e.coulomb_friction = Some(m),
        Candidate::ChurningLoss => e.churning_loss = Some(m),
        Candidate::MotorPumpConduction => e.motor_pump_conduction = Some(m),
        Candidate::ForcedConvection => e.forced_convection = Some(m),
        Candidate::None => {}
    }
    (r, m)
}


/// Generates the measured run of case `c`.
pub fn generate(c: &SynthCase) -> Result<(MeasuredRun, Truth), String> {
    let mut rng = ChaCha8Rng::seed_from_u64(c.seed);
    let m = mission(c, &mut rng);
    let (rig, magnitude) = truth_rig(c, &mut rng);
    let servo = c.scenario.is_servo();
    let sample = c.scenario.log_interval_s(c.sample_s);
    let opts = SimOptions { output_interval_s: sample, control_interval_s: sample.min(0.5) };
    let air = m.air_speed_mps.clone();
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
    for ch in Channel::ALL {
        if ch == Channel::LngValve || (ch == Channel::PositionMm && !servo) {
            continue;
        }
        // The logger sees the ram air of the mission, never the hidden
        // draught (the simulated `air_speed_mps` output includes it).
        let logged_air: Vec<f64>;
        let v = if ch == Channel::AirSpeedMps {
            if !c.scenario.logs_air() {
                continue;
            }
            logged_air = out.time_s.iter().map(|&t| air.at(t)).collect();
            &logged_air[..]
        } else {
            let Some(v) = out.get(ch.name()) else { continue };
            v
        };
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
