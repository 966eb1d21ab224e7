//! Operating profiles of the emulated rig: what the operator does (shaft
//! speed and needle setting on the throttle circuit, the position command on
//! the servo circuit, the ram-air fan), drawn from a seed. The families are
//! those of the paper (Case 1 throttle runs, Case 2 servo runs) and of the
//! diagnosis tests (speed and load steps, hold/manoeuvre servo duty).

use rand::Rng;

/// Operating scenario of an emulated log.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum EmuScenario {
    /// Case 1: constant 500 rpm, needle set for 20, 40 or 60 bar.
    ConstantThrottle,
    /// One speed (800–1200 rpm), needle alternating between 10–30 and
    /// 70–100 bar every 120–240 s.
    LoadCycles,
    /// Speed steps 1000–2000 rpm every 100–250 s at 5–25 bar.
    SpeedSteps,
    /// Needle drop 70–100 bar, speed steps 500–1200 rpm every 120–240 s.
    PressureSpeedSteps,
    /// Case 1 at 40–60 bar with logged ram air alternating 0 / 10–25 m/s
    /// every 150–300 s.
    AirSteps,
    /// Servo: segments of 120–240 s alternating between holding 25–40 mm
    /// against the spring and manoeuvring (15–25 mm triangles, half-period
    /// 1.0–1.6 s) about the centre. Logged at 0.1 s.
    ServoHoldMove,
    /// An identification run, as a thermal engineer designs one to
    /// commission a machine: shaft speed (500–2000 rpm), needle drop
    /// (10–100 bar) and logged ram air (0 or 5–25 m/s) each stepped on its
    /// own schedule (every 60–240 s), so that no two inputs move together.
    IdentRun,
    /// A bench's one-at-a-time throttle run: speed steps (400–1200 rpm every
    /// 150–250 s) at a needle set for 20 bar for the first half, then needle
    /// steps (10–50 bar every 150–250 s) at 700 rpm.
    SpeedThenNeedleSteps,
    /// A long soak (600–800 rpm at 40–55 bar) for 60 % of the run, then
    /// idle (300 rpm, needle open to 5 bar).
    SoakThenIdle,
    /// A throttle mix: speed (400–1200 rpm) and needle (10–60 bar) drawn
    /// afresh together at every step, every 90–200 s.
    ThrottleMix,
    /// The commissioning procedure's second throttle run
    /// (docs/commissioning.md): a soak (600–800 rpm at 40–55 bar) for half
    /// the run, then holds of 150–250 s alternating between a low speed
    /// (20–90 rpm, needle set for 30–50 bar: the pump making up little more
    /// than its leakage, as in a servo's hold) and idle (300 rpm, needle
    /// open to 5 bar), starting low. The low holds give the case film's
    /// speed law a drain record near rest.
    SoakThenLowSpeedHolds,
    /// The commissioning procedure's hot-flow run (docs/commissioning-foreign.md):
    /// a warm-up at 1150 rpm with the needle set for 50 bar for the first
    /// sixth of the run, then speed steps (850–1200 rpm every 150–250 s)
    /// at one needle setting drawn for 40–50 bar. One input moves at a
    /// time; the oil runs hot through the passages at the flows where the
    /// duct films turn turbulent (Re 3000–6000 on a 25–30 cm³/rev pump).
    WarmThenHotSpeedSteps,
    /// A one-at-a-time throttle run over the operating envelope's speed
    /// axis at both ends of its load axis: speed steps (400–1200 rpm every
    /// 150–250 s) at a needle set for 20 bar for the first half, then the
    /// same steps at a needle set for 50 bar. Only the speed moves within a
    /// half; the four corners of 400–1200 rpm × 20–50 bar are visited.
    SpeedStepsAtTwoNeedles,
    /// A one-at-a-time throttle run along the envelope's low-load and
    /// high-speed edges: speed steps (400–1200 rpm every 150–250 s) at a
    /// needle set for 20 bar for the first half, then needle steps (10–60
    /// bar every 150–250 s) at 1100 rpm ([`EmuScenario::SpeedThenNeedleSteps`]
    /// with its needle steps moved from 700 rpm to the high speed).
    SpeedThenHighSpeedNeedleSteps,
    /// [`EmuScenario::SoakThenLowSpeedHolds`] with the soak at the
    /// envelope's hot corner: 1000–1200 rpm with the needle set for 45–55
    /// bar for half the run (the oil heats to the temperatures a long high
    /// load gives), then the same low-speed holds alternating with idle.
    HotSoakThenLowSpeedHolds,
}

impl EmuScenario {
    /// Whether the servo circuit is used (piston moving, position logged).
    pub fn is_servo(self) -> bool {
        self == EmuScenario::ServoHoldMove
    }

    /// Whether the ram air is logged.
    pub fn logs_air(self) -> bool {
        matches!(self, EmuScenario::AirSteps | EmuScenario::IdentRun)
    }

    /// Logger interval, s: 0.1 s for servo runs (the format's interval for
    /// moving runs), 2 s otherwise.
    pub fn log_interval_s(self) -> f64 {
        if self.is_servo() { 0.1 } else { 2.0 }
    }
}

/// A drawn operating profile.
#[derive(Debug, Clone, PartialEq)]
pub struct EmuMission {
    /// Scenario.
    pub scenario: EmuScenario,
    /// Duration, s.
    pub duration_s: f64,
    /// Ambient: mean °C, drift amplitude K, drift phase rad (period 2400 s:
    /// the laboratory air conditioning).
    pub ambient: [f64; 3],
    /// Shaft speed steps (start time s, rpm) for the throttle circuit.
    pub speed: Vec<(f64, f64)>,
    /// Needle target drop steps (start time s, bar): the needle opening is
    /// set for this drop at the step's nominal pump flow.
    pub dp_bar: Vec<(f64, f64)>,
    /// Position command, piecewise linear (time s, m), servo circuit.
    pub x_ref: Vec<(f64, f64)>,
    /// Logged ram-air steps (start time s, m/s).
    pub air: Vec<(f64, f64)>,
}

/// Value of a step schedule at `t` with a 2 s linear ramp after each step
/// (the drive and the operator do not step instantly).
pub fn step_at(s: &[(f64, f64)], t: f64) -> f64 {
    let i = s.partition_point(|p| p.0 <= t);
    if i == 0 {
        return s.first().map_or(0.0, |p| p.1);
    }
    let (t0, v) = s[i - 1];
    let prev = if i >= 2 { s[i - 2].1 } else { v };
    let f = ((t - t0) / 2.0).clamp(0.0, 1.0);
    prev + (v - prev) * f
}

/// Value of a piecewise-linear profile at `t` (held at the ends).
pub fn linear_at(s: &[(f64, f64)], t: f64) -> f64 {
    let i = s.partition_point(|p| p.0 <= t);
    match (i.checked_sub(1).and_then(|j| s.get(j)), s.get(i)) {
        (Some(a), Some(b)) if b.0 > a.0 => a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0),
        (Some(a), _) => a.1,
        (None, Some(b)) => b.1,
        (None, None) => 0.0,
    }
}

/// Steps every `lo..hi` s until `d`, values from `value`.
fn steps(rng: &mut impl Rng, d: f64, lo: f64, hi: f64, mut value: impl FnMut(&mut dyn FnMut(f64, f64) -> f64, usize) -> f64) -> Vec<(f64, f64)> {
    let (mut out, mut t) = (Vec::new(), 0.0);
    while t < d {
        let v = value(&mut |a, b| rng.random_range(a..b), out.len());
        out.push((t, v));
        t += rng.random_range(lo..hi);
    }
    out
}

/// A mission's ambient (`EmuMission::ambient`): mean 15–27 °C, a
/// 0.2–0.8 K swing of 40 min period at a random phase.
pub fn draw_ambient(rng: &mut impl Rng) -> [f64; 3] {
    [rng.random_range(15.0..27.0), rng.random_range(0.2..0.8), rng.random_range(0.0..std::f64::consts::TAU)]
}

/// Draws the profile of `scenario` for `duration_s` seconds.
pub fn draw(scenario: EmuScenario, duration_s: f64, rng: &mut impl Rng) -> EmuMission {
    let d = duration_s;
    let ambient = draw_ambient(rng);
    let mut m = EmuMission { scenario, duration_s, ambient, speed: vec![(0.0, 500.0)], dp_bar: vec![(0.0, 60.0)], x_ref: vec![], air: vec![(0.0, 0.0)] };
    match scenario {
        EmuScenario::ConstantThrottle => m.dp_bar = vec![(0.0, [20.0, 40.0, 60.0][rng.random_range(0..3)])],
        EmuScenario::LoadCycles => {
            m.speed = vec![(0.0, rng.random_range(800.0..1200.0))];
            let high0 = rng.random_bool(0.5);
            m.dp_bar = steps(rng, d, 120.0, 240.0, |r, k| if (k % 2 == 0) == high0 { r(70.0, 100.0) } else { r(10.0, 30.0) });
        }
        EmuScenario::SpeedSteps => {
            m.speed = steps(rng, d, 100.0, 250.0, |r, _| r(1000.0, 2000.0));
            m.dp_bar = vec![(0.0, rng.random_range(5.0..25.0))];
        }
        EmuScenario::PressureSpeedSteps => {
            m.speed = steps(rng, d, 120.0, 240.0, |r, _| r(500.0, 1200.0));
            m.dp_bar = vec![(0.0, rng.random_range(70.0..100.0))];
        }
        EmuScenario::AirSteps => {
            m.dp_bar = vec![(0.0, rng.random_range(40.0..60.0))];
            let on0 = rng.random_bool(0.5);
            m.air = steps(rng, d, 150.0, 300.0, |r, k| if (k % 2 == 0) == on0 { r(10.0, 25.0) } else { 0.0 });
        }
        EmuScenario::IdentRun => {
            m.speed = steps(rng, d, 60.0, 240.0, |r, _| r(500.0, 2000.0));
            m.dp_bar = steps(rng, d, 60.0, 240.0, |r, _| r(10.0, 100.0));
            m.air = steps(rng, d, 60.0, 240.0, |r, _| if r(0.0, 1.0) < 0.35 { 0.0 } else { r(5.0, 25.0) });
        }
        EmuScenario::SpeedThenNeedleSteps | EmuScenario::SpeedThenHighSpeedNeedleSteps => {
            // the needle steps at 700 rpm up to 50 bar, or at 1100 rpm up to 60 bar
            let (needle_rpm, dp_max) = if scenario == EmuScenario::SpeedThenHighSpeedNeedleSteps { (1100.0, 60.0) } else { (700.0, 50.0) };
            let half = 0.5 * d;
            m.speed = steps(rng, half, 150.0, 250.0, |r, _| r(400.0, 1200.0));
            m.dp_bar = vec![(0.0, 20.0)];
            let needle = steps(rng, d - half, 150.0, 250.0, |r, _| r(10.0, dp_max));
            m.speed.push((half, needle_rpm));
            m.dp_bar.extend(needle.into_iter().map(|(t, v)| (half + t, v)));
        }
        EmuScenario::SoakThenIdle => {
            let soak = 0.6 * d;
            m.speed = vec![(0.0, rng.random_range(600.0..800.0)), (soak, 300.0)];
            m.dp_bar = vec![(0.0, rng.random_range(40.0..55.0)), (soak, 5.0)];
        }
        EmuScenario::SpeedStepsAtTwoNeedles => {
            let half = 0.5 * d;
            m.speed = steps(rng, half, 150.0, 250.0, |r, _| r(400.0, 1200.0));
            let high = steps(rng, d - half, 150.0, 250.0, |r, _| r(400.0, 1200.0));
            m.speed.extend(high.into_iter().map(|(t, v)| (half + t, v)));
            m.dp_bar = vec![(0.0, 20.0), (half, 50.0)];
        }
        EmuScenario::SoakThenLowSpeedHolds | EmuScenario::HotSoakThenLowSpeedHolds => {
            let soak = 0.5 * d;
            let (w, dp) = if scenario == EmuScenario::HotSoakThenLowSpeedHolds { ((1000.0, 1200.0), (45.0, 55.0)) } else { ((600.0, 800.0), (40.0, 55.0)) };
            m.speed = vec![(0.0, rng.random_range(w.0..w.1))];
            m.dp_bar = vec![(0.0, rng.random_range(dp.0..dp.1))];
            let holds = steps(rng, d - soak, 150.0, 250.0, |_, _| 0.0);
            for (k, &(t, _)) in holds.iter().enumerate() {
                let (w, dp) = if k % 2 == 0 { (rng.random_range(20.0..90.0), rng.random_range(30.0..50.0)) } else { (300.0, 5.0) };
                m.speed.push((soak + t, w));
                m.dp_bar.push((soak + t, dp));
            }
        }
        EmuScenario::WarmThenHotSpeedSteps => {
            let warm = d / 6.0;
            let dp = rng.random_range(40.0..50.0);
            let speeds = steps(rng, d - warm, 150.0, 250.0, |r, _| r(850.0, 1200.0));
            m.speed = std::iter::once((0.0, 1150.0)).chain(speeds.into_iter().map(|(t, v)| (warm + t, v))).collect();
            m.dp_bar = vec![(0.0, 50.0), (warm, dp)];
        }
        EmuScenario::ThrottleMix => {
            let times = steps(rng, d, 90.0, 200.0, |_, _| 0.0);
            m.speed = times.iter().map(|&(t, _)| (t, rng.random_range(400.0..1200.0))).collect();
            m.dp_bar = times.iter().map(|&(t, _)| (t, rng.random_range(10.0..60.0))).collect();
        }
        EmuScenario::ServoHoldMove => {
            let (mut pts, mut t, mut hold) = (vec![(0.0, 0.0)], 0.0, rng.random_bool(0.5));
            while t < d {
                let t_seg = (t + rng.random_range(120.0..240.0)).min(d + 10.0);
                if hold {
                    let x = rng.random_range(0.025..0.040) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
                    pts.extend([(t + 2.0, x), (t_seg - 2.0, x), (t_seg, 0.0)]);
                    t = t_seg;
                } else {
                    while t < t_seg {
                        let (a, h) = (rng.random_range(0.015..0.025), rng.random_range(1.0..1.6));
                        pts.extend([(t + 0.5 * h, a), (t + 1.5 * h, -a), (t + 2.0 * h, 0.0)]);
                        t += 2.0 * h;
                    }
                }
                hold = !hold;
            }
            m.x_ref = pts;
            m.speed = vec![(0.0, 0.0)];
            m.dp_bar = vec![(0.0, 0.0)];
        }
    }
    m
}

impl EmuMission {
    /// Ambient air temperature at `t`, °C.
    pub fn ambient_c(&self, t: f64) -> f64 {
        let [a, amp, ph] = self.ambient;
        a + amp * (2.0 * std::f64::consts::PI * t / 2400.0 + ph).sin()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedules_ramp_and_interpolate() {
        let s = [(0.0, 10.0), (100.0, 20.0)];
        assert_eq!(step_at(&s, 50.0), 10.0);
        assert!((step_at(&s, 101.0) - 15.0).abs() < 1e-12);
        assert_eq!(step_at(&s, 200.0), 20.0);
        let p = [(0.0, 0.0), (2.0, 4.0)];
        assert!((linear_at(&p, 1.0) - 2.0).abs() < 1e-12);
        assert_eq!(linear_at(&p, 5.0), 4.0);
    }

    /// An identification run steps speed, load and logged air on three
    /// schedules of their own (no shared step time), within their ranges.
    #[test]
    fn identification_run_moves_inputs_independently() {
        use rand::SeedableRng;
        let m = draw(EmuScenario::IdentRun, 1800.0, &mut rand_chacha::ChaCha8Rng::seed_from_u64(3));
        assert!(m.speed.len() >= 8 && m.dp_bar.len() >= 8 && m.air.len() >= 8);
        assert!(m.speed.iter().all(|s| (500.0..2000.0).contains(&s.1)));
        assert!(m.dp_bar.iter().all(|s| (10.0..100.0).contains(&s.1)));
        assert!(m.air.iter().any(|s| s.1 == 0.0) && m.air.iter().any(|s| s.1 >= 5.0));
        let shared = m.speed[1..].iter().filter(|s| m.dp_bar.iter().chain(&m.air).any(|o| o.0 == s.0)).count();
        assert_eq!(shared, 0, "a speed step coincides with another input's step");
        assert!(EmuScenario::IdentRun.logs_air() && !EmuScenario::IdentRun.is_servo());
    }

    /// The envelope variants of the procedure's first training log move one
    /// input at a time (speed and needle share only the start and the
    /// half-way switch) within their ranges; the hot soak keeps the
    /// low-speed holds (which, as the procedure's, set speed and needle
    /// together at each hold).
    #[test]
    fn envelope_training_runs_move_one_input_at_a_time() {
        use rand::SeedableRng;
        let d = 1800.0;
        for sc in [EmuScenario::SpeedStepsAtTwoNeedles, EmuScenario::SpeedThenHighSpeedNeedleSteps, EmuScenario::HotSoakThenLowSpeedHolds] {
            let m = draw(sc, d, &mut rand_chacha::ChaCha8Rng::seed_from_u64(3600));
            let shared = m.speed.iter().filter(|s| m.dp_bar.iter().any(|p| p.0 == s.0)).filter(|s| s.0 != 0.0 && s.0 != 0.5 * d).count();
            let one_at_a_time = sc == EmuScenario::HotSoakThenLowSpeedHolds || shared == 0;
            assert!(one_at_a_time, "{sc:?}: {shared} steps move speed and needle together");
            assert!(m.speed.iter().all(|s| (0.0..=1200.0).contains(&s.1)) && m.dp_bar.iter().all(|p| (5.0..=60.0).contains(&p.1)), "{sc:?}");
        }
        let m = draw(EmuScenario::SpeedStepsAtTwoNeedles, d, &mut rand_chacha::ChaCha8Rng::seed_from_u64(1));
        assert_eq!(m.dp_bar, vec![(0.0, 20.0), (900.0, 50.0)]);
        let m = draw(EmuScenario::SpeedThenHighSpeedNeedleSteps, d, &mut rand_chacha::ChaCha8Rng::seed_from_u64(1));
        assert!(m.speed.iter().filter(|s| s.0 >= 900.0).all(|s| s.1 == 1100.0));
        let m = draw(EmuScenario::HotSoakThenLowSpeedHolds, d, &mut rand_chacha::ChaCha8Rng::seed_from_u64(1));
        assert!((1000.0..1200.0).contains(&m.speed[0].1) && (45.0..55.0).contains(&m.dp_bar[0].1));
        assert!(m.speed.iter().any(|s| s.1 < 100.0), "no low-speed hold");
    }
}
