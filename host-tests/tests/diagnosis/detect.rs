//! `diagnose --detectability` against the structure floor
//! (`eha_sim::diagnosis::projection`): known answers on a toy model whose
//! projections are exact, and the physics of a constant-throttle log of the
//! independent rig emulator.

use eha_sim::diagnosis::evidence::ChannelFloor;
use eha_sim::diagnosis::projection::{channel_floors, floor_detectability, FloorDetectability};
use eha_sim::diagnosis::reference::ReferenceModel;
use eha_sim::diagnosis::{Candidate, ParamSpec, SimSeries, Simulator};
use eha_sim::emulator::missions::EmuScenario::ConstantThrottle;
use eha_sim::emulator::{generate, EmuCase};
use eha_sim::measured::{Channel, MeasuredRun};
use eha_sim::rig::Rig;

/// A linear toy machine: the pump and motor temperatures are first-order
/// (τ 300 s) responses to heats driven by the logged speed ω (krpm): the
/// pump gets g_p·ω, the motor g_m·ω (the two calibration parameters).
/// Candidates: `churning-loss` adds k·ω^2.5 to the pump; `forced-convection`
/// adds the same shape scaled by 2 (collinear with churning by
/// construction); `sensor-lag` adds k·ω to the motor only, delayed by a
/// second 600 s lag (another shape).
struct Toy {
    time_s: Vec<f64>,
    omega: Vec<f64>,
}

impl Toy {
    fn lag(&self, q: &[f64], tau: f64) -> Vec<f64> {
        let mut y = 0.0;
        let mut out = Vec::with_capacity(q.len());
        for (i, v) in q.iter().enumerate() {
            if i > 0 {
                let f = (-(self.time_s[i] - self.time_s[i - 1]) / tau).exp();
                y = f * y + (1.0 - f) * v;
            }
            out.push(y);
        }
        out
    }
}

impl Simulator for Toy {
    fn nuisance(&self) -> Vec<ParamSpec> {
        vec![ParamSpec::new("g_pump", "K", 10.0, 1.0, 100.0), ParamSpec::new("g_motor", "K", 5.0, 0.5, 50.0)]
    }
    fn extension_params(&self, c: Candidate) -> Vec<ParamSpec> {
        match c {
            Candidate::ChurningLoss | Candidate::ForcedConvection | Candidate::SensorLag => vec![ParamSpec::new("k", "K", 1.0, 0.01, 100.0)],
            _ => vec![],
        }
    }
    fn simulate(&self, n: &[f64], c: Candidate, ext: &[f64]) -> Result<SimSeries, String> {
        let k = ext.first().copied().unwrap_or(0.0);
        let w25: Vec<f64> = self.omega.iter().map(|w| w.powf(2.5)).collect();
        let extra = |scale: f64| -> Vec<f64> { w25.iter().map(|x| scale * k * x).collect() };
        let mut qp: Vec<f64> = self.omega.iter().map(|w| n[0] * w).collect();
        let mut qm: Vec<f64> = self.omega.iter().map(|w| n[1] * w).collect();
        match c {
            Candidate::ChurningLoss => qp.iter_mut().zip(extra(1.0)).for_each(|(q, e)| *q += e),
            Candidate::ForcedConvection => qp.iter_mut().zip(extra(2.0)).for_each(|(q, e)| *q += e),
            Candidate::SensorLag => {
                let slow = self.lag(&self.omega.iter().map(|w| k * w).collect::<Vec<_>>(), 600.0);
                qm.iter_mut().zip(slow).for_each(|(q, e)| *q += e);
            }
            _ => {}
        }
        let mut s = SimSeries::default();
        s.channels.insert(Channel::TPumpC, self.lag(&qp, 300.0).iter().map(|y| 20.0 + y).collect());
        s.channels.insert(Channel::TMotorC, self.lag(&qm, 300.0).iter().map(|y| 20.0 + y).collect());
        Ok(s)
    }
}

/// The toy's log (noise-free: the calibrated model itself) with speed `omega(t)`.
fn toy(omega: impl Fn(f64) -> f64) -> (Toy, MeasuredRun, f64) {
    let t: Vec<f64> = (0..600).map(|i| 2.0 * i as f64).collect();
    let toy = Toy { omega: t.iter().map(|&t| omega(t)).collect(), time_s: t.clone() };
    let mut run = MeasuredRun::new(t.clone());
    let y = toy.simulate(&[10.0, 5.0], Candidate::None, &[]).expect("toy");
    for ch in [Channel::TPumpC, Channel::TMotorC] {
        run.set(ch, y.channels[&ch].iter().map(|v| Some(*v)).collect());
    }
    run.set(Channel::AmbientC, vec![Some(20.0); t.len()]);
    (toy, run, 0.7 * 1198.0)
}

/// Floors from a 0.2 K misfit on both channels (noise 0.1 K).
fn floors(run: &MeasuredRun, split: f64) -> Vec<ChannelFloor> {
    [Channel::TPumpC, Channel::TMotorC]
        .iter()
        .map(|ch| ChannelFloor { channel: ch.name().into(), noise_k: 0.1, rise_k: eha_sim::diagnosis::adequacy::rms_rise_k(run, *ch, split), misfit_k: 0.2 })
        .collect()
}

fn toy_detect(omega: impl Fn(f64) -> f64) -> FloorDetectability {
    let (toy, run, split) = toy(omega);
    let pts: Vec<(Channel, usize)> = [Channel::TPumpC, Channel::TMotorC].iter().flat_map(|&ch| (0..run.len()).map(move |i| (ch, i))).collect();
    let f = floors(&run, split);
    floor_detectability(&toy, &run, &[10.0, 5.0], pts, split, f).expect("detectability")
}

fn best(fd: &FloorDetectability, c: &str, k: usize) -> (String, f64, f64) {
    let r = fd.rows.iter().filter(|r| r.candidate == c).nth(k).unwrap_or_else(|| panic!("{c} row {k}"));
    let left = r.channels.iter().map(|c| c.left_k).fold(0.0, f64::max);
    (r.best.0.clone(), r.best.1, left)
}

/// Known answers, exact on the linear toy:
/// - at constant speed a speed-dependent pump loss (k·ω^2.5) has the shape
///   of the pump's calibrated heat (g_p·ω): the calibration takes it all
///   up, whatever its size — left < 1e-6 K and r̂ = 1 at 1, 4 and 16 times
///   (imprints up to ~16 K);
/// - with speed steps (1 ↔ 2 krpm every 200 s) the same loss is not a
///   multiple of ω any more: r̂ ≥ 2 from 4× on (the typical 1 K·krpm^-2.5
///   on a ~4 K imprint);
/// - two candidates with collinear signatures (the draught of the toy is
///   the churning shape ×2) are at 0° (< 0.1°) in the confusability matrix;
///   a candidate on the other channel with another shape is at > 45°.
#[test]
fn detectability_by_projection_gives_the_known_answers() {
    let constant = toy_detect(|_| 1.5);
    for k in 0..3 {
        let (_, r, left) = best(&constant, "churning-loss", k);
        assert!(left < 1e-6 && (r - 1.0).abs() < 1e-9, "constant speed, row {k}: left {left:.2e} K, r̂ {r}");
    }
    let steps = toy_detect(|t| if (t / 200.0).floor() as i64 % 2 == 0 { 1.0 } else { 2.0 });
    let (ch, r4, left) = best(&steps, "churning-loss", 1);
    eprintln!("steps: churning 4× r̂ {r4:.2} on {ch}, left {left:.3} K; {}", steps.summary());
    assert_eq!(ch, "t_pump_c");
    assert!(r4 >= 2.0, "speed steps: churning at 4× r̂ {r4:.2}");
    let c = &steps.confusability;
    let ix = |n: &str| c.candidates.iter().position(|x| x == n).unwrap_or_else(|| panic!("{n}"));
    let (ch_, fc, lag) = (ix("churning-loss"), ix("forced-convection"), ix("sensor-lag"));
    assert!(c.angle_deg[ch_][fc] < 0.1, "collinear pair at {:.3}°", c.angle_deg[ch_][fc]);
    assert!(c.angle_deg[ch_][lag] > 45.0, "churning/lag at {:.1}°", c.angle_deg[ch_][lag]);
    assert!(steps.confusable_pairs().iter().any(|p| p.0 == "churning-loss" && p.1 == "forced-convection"));
}

/// The projection on a Case 1 log of the emulator (seed 1714, nothing
/// hidden) around the rig file's values of the physical set, against its
/// floor from the rig-file baseline: Coulomb friction acts on the piston
/// only, which does not move on the throttle circuit, so its imprint and
/// what is left are zero and r̂ = 1 at every size; the other candidates
/// leave finite ratios ≥ 1 and every angle is within 0–90°.
#[test]
fn detectability_follows_the_physics_of_a_constant_throttle_log() {
    let case = EmuCase { hidden: Candidate::None, scenario: ConstantThrottle, seed: 1714, duration_s: 1200.0 };
    let (run, _) = generate(&case).expect("emulated log");
    let model = ReferenceModel::new(Rig::default(), &run).expect("model");
    let physical = model.physical_set().expect("physical set");
    let nominal: Vec<f64> = physical.nuisance().iter().map(|p| p.start).collect();
    let base = physical.simulate(&nominal, Candidate::None, &[]).expect("baseline");
    let split = run.time_s[0] + 0.7 * (run.time_s[run.len() - 1] - run.time_s[0]);
    let pts = eha_sim::diagnosis::analysis::evidence_points(&run, split, 150);
    let fit_pts = eha_sim::diagnosis::analysis::fit_points(&run, split, 150);
    let floors = channel_floors(&run, &base, &fit_pts, split);
    let t = std::time::Instant::now();
    let fd = floor_detectability(&*physical, &run, &nominal, pts, split, floors).expect("detectability");
    eprintln!("{:.1} s\n{}", t.elapsed().as_secs_f64(), fd.markdown());
    assert_eq!(fd.rows.len(), 18, "6 candidates × 3 magnitudes");
    for r in fd.rows.iter().filter(|r| r.candidate == "coulomb-friction") {
        assert!(r.channels.iter().all(|c| c.imprint_k < 1e-9 && c.left_k < 1e-9) && r.best.1 == 1.0, "{r:?}");
    }
    for r in &fd.rows {
        assert!(r.best.1.is_finite() && r.best.1 >= 1.0, "{r:?}");
    }
    for row in &fd.confusability.angle_deg {
        assert!(row.iter().all(|a| a.is_nan() || (0.0..=90.0).contains(a)), "{row:?}");
    }
}
