//! The missions of the synthetic runs: a seeded mission per scenario
//! (speed and needle steps, soaks, servo triangles), drawn from the case's
//! own random stream so a seed gives the same run.

use super::{SynthCase, SynthScenario};
use crate::scenario::{Circuit, Mission, PositionRef, Schedule, ValveRule};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

pub(super) fn mission(c: &SynthCase, rng: &mut ChaCha8Rng) -> Mission {
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
                amplitude_m: rng.random_range(0.030..0.040),
                freq_hz: rng.random_range(0.2..0.25),
                offset_m: 0.0,
            },
            ..base
        },
        SynthScenario::ThrottleSteps => {
            // Four segments, each a random speed (300–1200 rpm) and needle
            // pressure drop (10–100 bar at that speed), stepping at random
            // times.
            let mut ts: Vec<f64> = (0..3).map(|_| rng.random_range(0.1..0.9) * d).collect();
            ts.sort_by(f64::total_cmp);
            ts.push(d);
            let segs: Vec<(f64, f64)> = ts.iter().map(|&t| (t, 0.0)).collect();
            let (sp, nb) = steps(&segs, rng, (300.0, 1200.0), (10.0, 100.0));
            Mission { speed_rpm: sp, needle_bar: nb, ..base }
        }
        SynthScenario::ServoProfile => {
            // Duty segments of 120–240 s alternate between brisk motion
            // (20–40 mm, half-period 2–3 s; faster triangles alias at the
            // 0.5 s logging: with 1.5 s half-periods the replay test missed
            // 0.31 K on t_oil_c) and slow small moves (5–12 mm, half-period
            // 3–6 s).
            let (mut pts, mut t, mut brisk) = (vec![(0.0, 0.0)], 0.0, rng.random_bool(0.5));
            while t < d {
                let t_seg = t + rng.random_range(120.0..240.0);
                while t < t_seg.min(d) {
                    let (a, h) = if brisk {
                        (rng.random_range(0.020..0.040), rng.random_range(2.0..3.0))
                    } else {
                        (rng.random_range(0.005..0.012), rng.random_range(3.0..6.0))
                    };
                    t = triangle(&mut pts, t, 0.0, a, h);
                }
                brisk = !brisk;
            }
            servo_mission(pts, base)
        }
        SynthScenario::ServoHoldMove => {
            let (mut pts, mut t, mut hold) = (vec![(0.0, 0.0)], 0.0, rng.random_bool(0.5));
            while t < d {
                let t_seg = (t + rng.random_range(120.0..240.0)).min(d);
                if hold {
                    // 2 s ramp out, hold, 2 s ramp back to the centre.
                    let x = rng.random_range(0.025..0.040) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
                    pts.extend([(t + 2.0, x), ((t_seg - 2.0).max(t + 2.0), x), (t_seg.max(t + 4.0), 0.0)]);
                    t = t_seg.max(t + 4.0);
                } else {
                    while t < t_seg {
                        let (a, h) = (rng.random_range(0.015..0.025), rng.random_range(1.0..1.6));
                        t = triangle(&mut pts, t, 0.0, a, h);
                    }
                }
                hold = !hold;
            }
            servo_mission(pts, base)
        }
        SynthScenario::ServoGust => {
            let (mut pts, mut t, mut gusty) = (vec![(0.0, 0.0)], 0.0, rng.random_bool(0.5));
            while t < d {
                let t_seg = (t + rng.random_range(120.0..240.0)).min(d);
                // 3 s move to the segment's trim, then calm or gusts about it.
                let x1 = rng.random_range(-0.025..0.025);
                pts.push((t + 3.0, x1));
                t += 3.0;
                while t < t_seg {
                    if gusty {
                        let (a, h) = (rng.random_range(0.010..0.018), rng.random_range(0.7..1.2));
                        t = triangle(&mut pts, t, x1, a, h);
                    } else {
                        t = t_seg;
                        pts.push((t, x1));
                    }
                }
                gusty = !gusty;
            }
            servo_mission(pts, base)
        }
        SynthScenario::SpeedSweep => {
            let (mut ends, mut t) = (vec![], 0.0);
            while t < d {
                t = (t + rng.random_range(100.0..250.0)).min(d);
                ends.push((t, 0.0));
            }
            let (sp, nb) = steps(&ends, rng, (1000.0, 2000.0), (5.0, 25.0));
            Mission { speed_rpm: sp, needle_bar: nb, ..base }
        }
        SynthScenario::LoadCycles => {
            let n = rng.random_range(800.0..1200.0);
            let (mut sp, mut nb, mut t, mut high) = (vec![], vec![], 0.0, rng.random_bool(0.5));
            while t < d {
                let t1 = (t + rng.random_range(120.0..240.0)).min(d);
                let p = if high { rng.random_range(70.0..100.0) } else { rng.random_range(10.0..30.0) };
                let setting = needle_setting(p, n);
                sp.extend([(t, n), (t1, n)]);
                nb.extend([(t, setting), (t1, setting)]);
                (t, high) = (t1, !high);
            }
            Mission { speed_rpm: Schedule(sp), needle_bar: Schedule(nb), ..base }
        }
        SynthScenario::PressureSpeedSteps => {
            let p = rng.random_range(70.0..100.0);
            let (mut sp, mut nb, mut t) = (vec![], vec![], 0.0);
            while t < d {
                let t1 = (t + rng.random_range(120.0..240.0)).min(d);
                let n: f64 = rng.random_range(500.0..1200.0);
                let setting = needle_setting(p, n);
                sp.extend([(t, n), (t1, n)]);
                nb.extend([(t, setting), (t1, setting)]);
                t = t1;
            }
            Mission { speed_rpm: Schedule(sp), needle_bar: Schedule(nb), ..base }
        }
        SynthScenario::AirSteps => {
            let (mut air, mut t, mut on) = (vec![], 0.0, rng.random_bool(0.5));
            while t < d {
                let t1 = (t + rng.random_range(150.0..300.0)).min(d);
                let v = if on { rng.random_range(10.0..25.0) } else { 0.0 };
                air.extend([(t, v), (t1, v)]);
                (t, on) = (t1, !on);
            }
            Mission {
                needle_bar: Schedule::constant(rng.random_range(40.0..60.0)),
                air_speed_mps: Schedule(air),
                ..base
            }
        }
    }
}

/// One triangle of the position reference about `centre` (m): up by
/// `a` (m) at `t + h/2`, down to `centre − a` at `t + 3h/2`, back to the
/// centre at `t + 2h` (`h` the half-period, s). Returns its end time, s.
fn triangle(pts: &mut Vec<(f64, f64)>, t: f64, centre: f64, a: f64, h: f64) -> f64 {
    pts.extend([(t + h / 2.0, centre + a), (t + 1.5 * h, centre - a), (t + 2.0 * h, centre)]);
    t + 2.0 * h
}

/// A servo-circuit mission following the piecewise-linear position
/// reference `pts` (time s, position m), the rest as `base`.
fn servo_mission(pts: Vec<(f64, f64)>, base: Mission) -> Mission {
    Mission {
        circuit: Circuit::Servo,
        speed_rpm: Schedule::constant(0.0),
        needle_bar: Schedule::constant(0.0),
        position: PositionRef::Profile(Schedule(pts)),
        ..base
    }
}

/// Needle setting (its drop at the 500 rpm flow, bar) that gives a drop of
/// `dp` bar at `n` rpm: the needle is an orifice
/// (`eha_sim::hydraulics::needle_k`), so the drop scales with n².
fn needle_setting(dp: f64, n: f64) -> f64 {
    dp * (500.0 / n).powi(2)
}

/// Speed and needle schedules of piecewise-constant segments ending at
/// `ends` (times, s): each segment draws a speed (rpm) in `speed` and a
/// needle pressure drop at that speed (bar) in `dp`. The needle is an
/// orifice set at the 500 rpm flow (`eha_sim::hydraulics::needle_k`), so
/// its setting is dp·(500/n)²; this keeps the pressure below the relief
/// valves at every speed.
fn steps(ends: &[(f64, f64)], rng: &mut ChaCha8Rng, speed: (f64, f64), dp: (f64, f64)) -> (Schedule, Schedule) {
    let (mut sp, mut nb, mut t0) = (vec![], vec![], 0.0);
    for &(t1, _) in ends {
        let (n, p) = (rng.random_range(speed.0..speed.1), rng.random_range(dp.0..dp.1));
        let setting = needle_setting(p, n);
        sp.extend([(t0, n), (t1, n)]);
        nb.extend([(t0, setting), (t1, setting)]);
        t0 = t1;
    }
    (Schedule(sp), Schedule(nb))
}
