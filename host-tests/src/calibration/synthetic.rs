//! Logs generated from a rig with the reference model (for the calibration
//! and commissioning tests and examples): a few mission kinds, the sensors
//! of the measured-data format with σ = 0.1 K noise, 12-bit quantisation,
//! ~1 % dropped rows and ~0.5 % empty cells, optionally a drain-port
//! thermocouple; and a synthetic "other EHA".

use crate::data::acquisition::quantise;
use crate::measured::{Channel, MeasuredRun};
use crate::rig::Rig;
use crate::scenario::{Circuit, Mission, PositionRef, Scenario, Schedule, ValveRule};
use crate::sim::{simulate, SimOptions};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Mission kinds of the generated logs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    /// One speed and one needle setting for the whole run (one operating point).
    Constant {
        /// Shaft speed, rpm.
        rpm: f64,
        /// Needle setting, bar at the 500 rpm reference flow.
        bar: f64,
    },
    /// Needle steps between 5 and 30 bar every 150–300 s at 700 rpm. (The
    /// needle settings of every kind keep the drop below ~150 bar on a pump
    /// of 1.5× displacement: above the 210 bar relief the replay, which
    /// sends the whole delivery through the throttle path, is not valid.)
    PressureSteps,
    /// Speed steps 300–1500 rpm every 150–300 s at a 6 bar needle.
    SpeedSteps,
    /// Needle steps between 20 and 40 bar every 150–300 s at 700 rpm with
    /// the LNG exchanger in the circuit, its valve on the bench thermostat
    /// at the drain thermocouple (the exchanger's heat in the logs; the
    /// `lng_valve` column is logged).
    CoolingSteps,
    /// A high-pressure soak (needle 36–40 bar, 600 rpm) for 60 % of the
    /// run, then random speed (300–1200 rpm) / needle (3–10 bar) segments
    /// of 90–180 s and a stop for the last 120 s (the held-out kind).
    SoakThenMixed,
}

/// Piecewise-constant schedule through `(t, v)` steps.
fn steps(pts: &[(f64, f64)]) -> Schedule {
    let mut s = Vec::new();
    for (k, &(t, v)) in pts.iter().enumerate() {
        if k > 0 {
            s.push((t, pts[k - 1].1));
        }
        s.push((t, v));
    }
    Schedule(s)
}

/// The mission of `kind`, `duration_s` long, drawn from `seed`.
pub fn mission(kind: Kind, duration_s: f64, seed: u64) -> Mission {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let amb = rng.random_range(15.0..25.0);
    let seg = |lo: (f64, f64), hi: (f64, f64), rng: &mut ChaCha8Rng| {
        let (mut t, mut sp, mut nb) = (0.0, vec![], vec![]);
        while t < duration_s {
            sp.push((t, rng.random_range(lo.0..hi.0)));
            nb.push((t, rng.random_range(lo.1..hi.1)));
            t += rng.random_range(150.0..300.0);
        }
        (sp, nb)
    };
    let (speed, needle) = match kind {
        Kind::Constant { rpm, bar } => (vec![(0.0, rpm)], vec![(0.0, bar)]),
        Kind::PressureSteps => {
            let (_, nb) = seg((700.0, 5.0), (700.1, 30.0), &mut rng);
            (vec![(0.0, 700.0)], nb)
        }
        Kind::SpeedSteps => {
            let (sp, _) = seg((300.0, 6.0), (1500.0, 6.1), &mut rng);
            (sp, vec![(0.0, 6.0)])
        }
        Kind::CoolingSteps => {
            let (_, nb) = seg((700.0, 20.0), (700.1, 40.0), &mut rng);
            (vec![(0.0, 700.0)], nb)
        }
        Kind::SoakThenMixed => {
            let soak = 0.6 * duration_s;
            let (mut sp, mut nb) = (vec![(0.0, 600.0)], vec![(0.0, rng.random_range(36.0..40.0))]);
            let mut t = soak;
            while t < duration_s - 120.0 {
                sp.push((t, rng.random_range(300.0..1200.0)));
                nb.push((t, rng.random_range(3.0..10.0)));
                t += rng.random_range(90.0..180.0);
            }
            sp.push((duration_s - 120.0, 0.0));
            (sp, nb)
        }
    };
    Mission {
        name: format!("{kind:?}-{seed}"),
        circuit: Circuit::Throttle,
        duration_s,
        ambient_c: Schedule::constant(amb),
        speed_rpm: steps(&speed),
        needle_bar: steps(&needle),
        position: PositionRef::Profile(Schedule::constant(0.0)),
        air_speed_mps: Schedule::constant(0.0),
        valve: if kind == Kind::CoolingSteps { ValveRule::Drain } else { ValveRule::None },
    }
}

/// Noise-free model outputs and the noisy log of `rig` flying `m`, sampled
/// every `sample_s` (seeded noise, quantisation and dropouts); with a
/// `t_drain_c` column when `drain`, and the `lng_valve` command when the
/// mission has an LNG exchanger.
pub fn log(rig: &Rig, m: &Mission, sample_s: f64, seed: u64, drain: bool) -> Result<MeasuredRun, String> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xCA11);
    let opts = SimOptions { output_interval_s: sample_s, control_interval_s: sample_s.min(0.5) };
    let out = simulate(rig, &Scenario::Mission(m.clone()), &opts).map_err(|e| e.to_string())?;
    let keep: Vec<usize> = (0..out.time_s.len()).filter(|&i| i == 0 || !rng.random_bool(0.01)).collect();
    let mut run = MeasuredRun::new(keep.iter().map(|&i| out.time_s[i]).collect());
    run.push_meta("rig", "synthetic");
    run.push_meta("note", "generated by eha_sim::calibration::synthetic");
    let chans = [
        Channel::SpeedRpm,
        Channel::CurrentA,
        Channel::PABar,
        Channel::PBBar,
        Channel::AmbientC,
        Channel::TMotorC,
        Channel::TPumpC,
        Channel::TBlockC,
        Channel::TBallvalveC,
        Channel::TOilC,
        Channel::TDrainC,
    ];
    let lng = m.valve != ValveRule::None;
    for ch in chans.into_iter().chain(lng.then_some(Channel::LngValve)) {
        if ch == Channel::TDrainC && !drain {
            continue;
        }
        let v = out.get(ch.name()).ok_or_else(|| format!("no output {}", ch.name()))?;
        let col = keep
            .iter()
            .map(|&i| {
                if ch.is_temperature() {
                    let g: f64 = crate::data::acquisition::gauss(&mut rng);
                    let y = quantise(v[i] + 0.1 * g);
                    (!rng.random_bool(0.005)).then_some(y)
                } else {
                    Some(v[i])
                }
            })
            .collect();
        run.set(ch, col);
    }
    run.validate("synthetic").map_err(|e| e.to_string())?;
    Ok(run)
}

/// A synthetic EHA that is not the paper's, as its team would describe it
/// in their rig file: 1.5× displacement, other housing masses and areas.
pub fn other_rig_file() -> Rig {
    let mut r = Rig::default();
    r.pump.displacement_cm3 *= 1.5;
    r.pump.mass_kg = 28.0;
    r.pump.area_m2 = 0.14;
    r.pump.diameter_m = 0.14;
    r.motor.mass_kg = 60.0;
    r.motor.area_m2 = 0.42;
    r.blocks.main_mass_kg = 120.0;
    r.blocks.main_area_m2 = 0.30;
    r.blocks.ball_mass_kg = 22.0;
    r.blocks.ball_area_m2 = 0.07;
    r.pump.case_oil_m3 = 0.22e-3;
    r
}

/// The true machine behind [`other_rig_file`]: films 30 % off, and
/// per-node deviations that no global multiplier represents (each housing's
/// outer transfer, capacity and loss coefficient off by its own factor).
pub fn other_rig_truth() -> Rig {
    let mut r = other_rig_file();
    r.blocks.loop_area_scale *= 0.7;
    r.pump.port_area_scale *= 1.3;
    r.pump.case_inner_area_m2 *= 1.3;
    r.motor.area_m2 *= 0.8;
    r.pump.area_m2 *= 1.35;
    r.blocks.main_area_m2 *= 0.75;
    r.blocks.ball_area_m2 *= 1.2;
    r.motor.mass_kg *= 1.15;
    r.pump.mass_kg *= 0.8;
    r.blocks.main_mass_kg *= 1.25;
    r.blocks.ball_mass_kg *= 0.85;
    r.blocks.loop_oil_m3 *= 1.2;
    r.pump.eta_m *= 0.75;
    r.pump.gaps.piston_gap_m *= 1.15;
    r.pump.gaps.slipper_gap_m *= 1.15;
    r.pump.gaps.port_gap_m *= 1.15;
    r.motor.r25_ohm *= 1.1;
    r.motor.iron.k_h *= 1.5;
    r.motor.iron.k_c *= 1.5;
    r.motor.iron.k_e *= 1.5;
    r
}
