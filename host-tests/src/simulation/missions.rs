//! Seeded random missions inside the rig's envelope of the paper's cases (the
//! firmware's acceptance suite, `tests/firmware/vs_reference.rs`) and drain-error
//! statistics.

use crate::scenario::{Circuit, Mission, PositionRef, Schedule, ValveRule};

/// Seeds of the random missions of the acceptance suite. The firmware model is a
/// reduction of the rig (`crate::reduce`), fitted to no run, so every mission is
/// unseen; these five are the ones the suite asserts on.
pub const TEST_SEEDS: [u64; 5] = [1, 2, 3, 4, 5];

/// Small deterministic generator (SplitMix64), so missions are reproducible by seed.
#[derive(Debug, Clone)]
pub struct SplitMix(u64);

impl SplitMix {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        SplitMix(seed ^ 0x5DEE_CE66_D1CE_4E5B)
    }
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// A random mission of `duration_s` from `seed`, inside the rig's envelope of the
/// paper's cases: a throttle mission (segments of 60–200 s at 300–700 rpm with a
/// needle setting that gives 0–60 bar at that speed, 20 % idle segments at 0 rpm)
/// or a servo mission (triangle position waves of 5–25 mm at 0.05–0.3 Hz per
/// segment, 20 % rest), ambient 10–30 °C, still air, no LNG.
pub fn random_mission(seed: u64, duration_s: f64) -> Mission {
    let mut r = SplitMix::new(seed);
    let ambient = r.uniform(10.0, 30.0);
    let servo = r.uniform(0.0, 1.0) < 0.3;
    let mut speed: Vec<(f64, f64)> = vec![];
    let mut needle: Vec<(f64, f64)> = vec![];
    let mut pos = vec![];
    let mut t = 0.0;
    let mut first = true;
    while t < duration_s {
        let seg = r.uniform(60.0, 200.0);
        let idle = r.uniform(0.0, 1.0) < 0.2 && !first;
        if servo {
            let amp = r.uniform(0.005, 0.025);
            let f = r.uniform(0.05, 0.3);
            let quarter = 0.25 / f;
            let end = (t + seg).min(duration_s);
            let mut tt = t;
            let mut k = 0usize;
            while tt < end {
                let x = if idle { 0.0 } else { [0.0, amp, 0.0, -amp][k % 4] };
                pos.push((tt, x));
                tt += quarter;
                k += 1;
            }
        } else {
            let rpm = if idle { 0.0 } else { r.uniform(300.0, 700.0) };
            // The setting is the drop at 500 rpm; the drop scales with flow squared.
            let dp_bar = r.uniform(0.0, 60.0);
            let setting = if rpm > 0.0 { dp_bar * (500.0 / rpm).powi(2) } else { 0.0 };
            if let (Some(&(_, ls)), Some(&(_, ln))) = (speed.last(), needle.last()) {
                speed.push((t, ls));
                needle.push((t, ln));
            }
            speed.push((t, rpm));
            needle.push((t, setting));
        }
        first = false;
        t += seg;
    }
    if servo {
        pos.push((duration_s, 0.0));
    }
    Mission {
        name: format!("random-{seed}"),
        circuit: if servo { Circuit::Servo } else { Circuit::Throttle },
        duration_s,
        ambient_c: Schedule::constant(ambient),
        speed_rpm: if servo { Schedule::constant(0.0) } else { Schedule(speed) },
        needle_bar: if servo { Schedule::constant(0.0) } else { Schedule(needle) },
        position: if servo { PositionRef::Profile(Schedule(pos)) } else { PositionRef::Profile(Schedule::constant(0.0)) },
        air_speed_mps: Schedule::constant(0.0),
        valve: ValveRule::None,
    }
}

/// Drain error statistics of one run (prediction − reference), K.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorStats {
    /// max |error|.
    pub max_abs: f64,
    /// RMS error.
    pub rms: f64,
    /// Largest under-prediction (reference − prediction, ≥ 0).
    pub max_under: f64,
    /// Largest over-prediction (≥ 0).
    pub max_over: f64,
}

/// Statistics of an error sequence.
pub fn stats(errs: impl Iterator<Item = f64>) -> ErrorStats {
    let (mut n, mut ss, mut max_abs, mut under, mut over) = (0usize, 0.0, 0.0f64, 0.0f64, 0.0f64);
    for e in errs {
        n += 1;
        ss += e * e;
        max_abs = max_abs.max(e.abs());
        under = under.max(-e);
        over = over.max(e);
    }
    ErrorStats { max_abs, rms: (ss / n.max(1) as f64).sqrt(), max_under: under, max_over: over }
}


/// A 600 s acceptance run by name, as the study examples take it on the command
/// line: `lng` (Fig. 15), `case2`, `c1-<bar>` (Case 1 at that needle drop) or a
/// random-mission seed. `None` for anything else.
pub fn run_by_name(name: &str) -> Option<crate::scenario::Scenario> {
    use crate::scenario::Scenario;
    let d = 600.0;
    match name {
        "lng" => Some(Scenario::Lng { duration_s: d }),
        "case2" => Some(Scenario::Case2 { duration_s: d }),
        a => match a.strip_prefix("c1-") {
            Some(bar) => bar.parse().ok().map(|b| Scenario::Case1 { needle_bar: b, duration_s: d }),
            None => a.parse().ok().map(|s| Scenario::Mission(random_mission(s, d))),
        },
    }
}
