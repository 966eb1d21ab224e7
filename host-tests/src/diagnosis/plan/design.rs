//! The missions a plan chooses from: the bench's [`Limits`], an operating
//! [`Level`], a [`Design`] (levels held alternately) as a model mission, a
//! CSV schedule or an emulator mission, and the [`family`] searched.
//! Separate because it is the design space, not the search.

use crate::emulator::missions::{EmuMission, EmuScenario};
use crate::hydraulics::NEEDLE_SET_RPM;
use crate::measured::{Channel, MeasuredRun};
use crate::rig::Rig;
use crate::scenario::{Circuit, Mission, PositionRef, Schedule, ValveRule};
use std::fmt::Write as _;


/// The bench's envelope for a plan.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Limits {
    /// Shaft speed range, rpm.
    pub speed_rpm: (f64, f64),
    /// Needle drop range at the running speed, bar.
    pub drop_bar: (f64, f64),
    /// Largest logged ram-air speed, m/s; `None`: the bench has no fan
    /// (the log has no `air_speed_mps` column).
    pub air_mps: Option<f64>,
    /// Largest temperature any logged channel may reach in the calibrated
    /// model's prediction, °C.
    pub max_temp_c: f64,
}

/// Default speed range of a plan, rpm: the emulator benches' envelope,
/// capped at the rig's speed limit.
pub const DEFAULT_SPEED_RPM: (f64, f64) = (500.0, 2000.0);
/// Default needle drop range, bar (capped at half the relief pressure).
pub const DEFAULT_DROP_BAR: (f64, f64) = (10.0, 100.0);
/// Default largest ram air, m/s.
pub const DEFAULT_AIR_MPS: f64 = 20.0;
/// Default temperature limit of the predicted channels, °C (mineral
/// hydraulic oil).
pub const DEFAULT_MAX_TEMP_C: f64 = 80.0;

impl Limits {
    /// The defaults within `rig`'s speed limit and relief pressure; a fan
    /// when `log` logs ram air.
    pub fn for_rig(rig: &Rig, log: &MeasuredRun) -> Self {
        let fan = log.get(Channel::AirSpeedMps).is_some();
        Limits {
            speed_rpm: (DEFAULT_SPEED_RPM.0, DEFAULT_SPEED_RPM.1.min(rig.motor.max_speed_rpm)),
            drop_bar: (DEFAULT_DROP_BAR.0, DEFAULT_DROP_BAR.1.min(0.5 * rig.hydraulics.relief_crack_pa / 1e5)),
            air_mps: fan.then_some(DEFAULT_AIR_MPS),
            max_temp_c: DEFAULT_MAX_TEMP_C,
        }
    }

    /// Whether `l` lies within the envelope.
    pub fn contains(&self, l: &Level) -> bool {
        let within = |v: f64, (a, b): (f64, f64)| v >= a - 1e-9 && v <= b + 1e-9;
        within(l.speed_rpm, self.speed_rpm) && within(l.drop_bar, self.drop_bar) && l.air_mps >= 0.0 && l.air_mps <= self.air_mps.unwrap_or(0.0) + 1e-9
    }
}

/// One operating level of a bench mission.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Level {
    /// Shaft speed, rpm.
    pub speed_rpm: f64,
    /// Needle drop at this speed's pump flow, bar (the operator sets the
    /// needle for it).
    pub drop_bar: f64,
    /// Logged ram air, m/s.
    pub air_mps: f64,
}

impl Level {
    /// The needle setting of the mission format: its drop at the 500 rpm
    /// reference flow, bar (the drop scales with the flow squared).
    pub fn needle_setting_bar(&self) -> f64 {
        self.drop_bar * (NEEDLE_SET_RPM / self.speed_rpm).powi(2)
    }
}

/// A throttle-circuit bench mission: levels held for `hold_s` each.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Design {
    /// Short description.
    pub name: String,
    /// Hold time of each segment, s.
    pub hold_s: f64,
    /// The levels, one per segment.
    pub segments: Vec<Level>,
    /// Duration, s.
    pub duration_s: f64,
    /// Ambient air, °C (held constant in the prediction).
    pub ambient_c: f64,
}

impl Design {
    /// Segment start times, s.
    fn starts(&self) -> impl Iterator<Item = (f64, &Level)> {
        self.segments.iter().enumerate().map(|(k, l)| (k as f64 * self.hold_s, l))
    }

    /// The mission for the reference model (steps as double points).
    pub fn mission(&self) -> Mission {
        let (mut speed, mut needle, mut air) = (Vec::new(), Vec::new(), Vec::new());
        let mut prev: Option<&Level> = None;
        for (t, l) in self.starts() {
            for v in prev.into_iter().chain([l]) {
                speed.push((t, v.speed_rpm));
                needle.push((t, v.needle_setting_bar()));
                air.push((t, v.air_mps));
            }
            prev = Some(l);
        }
        Mission {
            name: self.name.clone(),
            circuit: Circuit::Throttle,
            duration_s: self.duration_s,
            ambient_c: Schedule::constant(self.ambient_c),
            speed_rpm: Schedule(speed),
            needle_bar: Schedule(needle),
            position: PositionRef::Profile(Schedule::constant(0.0)),
            air_speed_mps: Schedule(air),
            valve: ValveRule::None,
        }
    }

    /// The mission CSV (`eha-sim simulate --mission`'s format: header
    /// `time_s,speed_rpm,needle_bar,position_mm,ambient_c,air_speed_mps`;
    /// a step is two rows at one time; `needle_bar` is the setting at the
    /// 500 rpm reference flow).
    pub fn csv(&self) -> String {
        let mut s = String::from("# bench mission planned by `eha-sim plan`: throttle circuit; needle_bar = the needle's drop at 500 rpm\n");
        let _ = writeln!(s, "# (the drop at the running speed is needle_bar·(speed/500)²); the hold levels are in plan.md");
        s.push_str("time_s,speed_rpm,needle_bar,position_mm,ambient_c,air_speed_mps\n");
        let mut prev: Option<&Level> = None;
        let row = |s: &mut String, t: f64, l: &Level| {
            let _ = writeln!(s, "{t:.1},{:.1},{:.6},,{:.2},{:.2}", l.speed_rpm, l.needle_setting_bar(), self.ambient_c, l.air_mps);
        };
        for (t, l) in self.starts() {
            if let Some(p) = prev {
                row(&mut s, t, p);
            }
            row(&mut s, t, l);
            prev = Some(l);
        }
        if let Some(p) = prev {
            row(&mut s, self.duration_s, p);
        }
        s
    }

    /// The same mission as the emulator's operator flies it
    /// ([`crate::emulator`]: needle set for the drop at the running speed,
    /// 2 s ramps), with ambient `ambient` (mean °C, drift K, phase rad).
    pub fn emu_mission(&self, ambient: [f64; 3]) -> EmuMission {
        let fan = self.segments.iter().any(|l| l.air_mps > 0.0);
        EmuMission {
            // A throttle scenario that logs the air when the plan uses the fan.
            scenario: if fan { EmuScenario::IdentRun } else { EmuScenario::ThrottleMix },
            duration_s: self.duration_s,
            ambient,
            speed: self.starts().map(|(t, l)| (t, l.speed_rpm)).collect(),
            dp_bar: self.starts().map(|(t, l)| (t, l.drop_bar)).collect(),
            x_ref: vec![],
            air: self.starts().map(|(t, l)| (t, l.air_mps)).collect(),
        }
    }
}

/// Hold times of the family, s.
pub const HOLDS_S: [f64; 2] = [150.0, 300.0];

/// The five operating levels of the families (speed rpm, drop bar): the
/// envelope's four corners and its centre; and the air settings (none, or
/// toggled up to the largest when the bench has a fan).
fn levels_and_airs(limits: &Limits) -> ([(f64, f64); 5], Vec<Option<f64>>) {
    let (s0, s1) = limits.speed_rpm;
    let (d0, d1) = limits.drop_bar;
    let airs = match limits.air_mps {
        Some(a) => vec![None, Some(a)],
        None => vec![None],
    };
    ([(s0, d0), (s0, d1), (s1, d0), (s1, d1), (0.5 * (s0 + s1), 0.5 * (d0 + d1))], airs)
}

/// The mission holding `order`'s levels in turn for `hold` s each, with the
/// air (if any) toggled between 0 and `air` every second segment (a
/// quarter period out of phase with two levels).
fn cycled(order: &[(f64, f64)], hold: f64, air: Option<f64>, duration_s: f64, ambient_c: f64) -> Design {
    let n = (duration_s / hold).ceil() as usize;
    let segments = (0..n)
        .map(|m| {
            let (s, d) = order[m % order.len()];
            let a = air.map_or(0.0, |a| if (m / 2) % 2 == 1 { a } else { 0.0 });
            Level { speed_rpm: s, drop_bar: d, air_mps: a }
        })
        .collect();
    let names: Vec<String> = order.iter().map(|(s, d)| format!("{s:.0} rpm/{d:.0} bar")).collect();
    let levels = if order.len() == 2 { names.join(" ↔ ") } else { format!("{} → …", names.join(" → ")) };
    let air = air.map_or(String::new(), |a| format!(", air 0/{a:.0} m/s every {:.0} s", 2.0 * hold));
    Design { name: format!("{levels} every {hold:.0} s{air}"), hold_s: hold, segments, duration_s, ambient_c }
}

/// The mission family within `limits`: every pair of distinct levels among
/// the four corners of the speed × drop envelope and its centre,
/// alternated with each hold time of [`HOLDS_S`]; with a fan, each also
/// with the air toggled between 0 and the largest every second segment (a
/// quarter period out of phase with the levels).
pub fn family(limits: &Limits, duration_s: f64, ambient_c: f64) -> Vec<Design> {
    let (levels, airs) = levels_and_airs(limits);
    let mut out = Vec::new();
    for i in 0..levels.len() {
        for j in i + 1..levels.len() {
            for hold in HOLDS_S {
                for &air in &airs {
                    out.push(cycled(&[levels[i], levels[j]], hold, air, duration_s, ambient_c));
                }
            }
        }
    }
    out
}

/// The three-level family within `limits`: every triple of distinct levels
/// among the same five as [`family`] (the envelope's corners and centre),
/// held in turn in both orders with each hold time of [`HOLDS_S`]; with a
/// fan, each also with the air toggled as in [`family`]. A third level lets
/// a mission visit one speed at two oil temperatures (reached through the
/// other two levels), which two alternating levels settle into one cycle.
pub fn family_three(limits: &Limits, duration_s: f64, ambient_c: f64) -> Vec<Design> {
    let (levels, airs) = levels_and_airs(limits);
    let mut out = Vec::new();
    for i in 0..levels.len() {
        for j in i + 1..levels.len() {
            for k in j + 1..levels.len() {
                for order in [[i, j, k], [i, k, j]] {
                    for hold in HOLDS_S {
                        for &air in &airs {
                            out.push(cycled(&order.map(|o| levels[o]), hold, air, duration_s, ambient_c));
                        }
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The families' sizes (pairs and ordered triples of five levels, two
    /// holds, ×2 with a fan) and their schedules: two levels alternate,
    /// three are held in turn, the air toggles every second segment.
    #[test]
    fn families_hold_their_levels_in_turn() {
        let mut l = Limits { speed_rpm: (500.0, 2000.0), drop_bar: (10.0, 100.0), air_mps: None, max_temp_c: 80.0 };
        assert_eq!((family(&l, 1200.0, 20.0).len(), family_three(&l, 1200.0, 20.0).len()), (20, 40));
        l.air_mps = Some(20.0);
        let (two, three) = (family(&l, 1200.0, 20.0), family_three(&l, 1200.0, 20.0));
        assert_eq!((two.len(), three.len()), (40, 80));
        let d = &two[1];
        assert_eq!(d.name, "500 rpm/10 bar ↔ 500 rpm/100 bar every 150 s, air 0/20 m/s every 300 s");
        let speeds_drops_airs: Vec<(f64, f64, f64)> = d.segments.iter().map(|s| (s.speed_rpm, s.drop_bar, s.air_mps)).collect();
        assert_eq!(speeds_drops_airs.len(), 8);
        assert_eq!(&speeds_drops_airs[..4], [(500.0, 10.0, 0.0), (500.0, 100.0, 0.0), (500.0, 10.0, 20.0), (500.0, 100.0, 20.0)]);
        let t = &three[0];
        assert_eq!(t.name, "500 rpm/10 bar → 500 rpm/100 bar → 2000 rpm/10 bar → … every 150 s");
        let drops: Vec<f64> = t.segments.iter().map(|s| s.drop_bar).collect();
        assert_eq!(drops, [10.0, 100.0, 10.0, 10.0, 100.0, 10.0, 10.0, 100.0]);
        assert_eq!(t.segments[2].speed_rpm, 2000.0);
    }
}
