//! Test plans (`eha-sim plan`): a bench mission that makes the leading
//! candidates showable, designed on the model calibrated to the user's log.
//!
//! The log's calibration (the physical set, [`super::reference`]) gives the
//! model of this machine and its structure floor per channel as misfit per
//! rise ([`super::projection::channel_floors`]). Every mission of a small
//! family — two operating levels (shaft speed, needle drop at that speed,
//! logged ram air where the bench has a fan) held alternately for 150 or
//! 300 s, within the bench's [`Limits`] — is flown by the calibrated model;
//! its log is replayed as the diagnosis will replay it, and the candidates'
//! imprints are projected off the calibration's sensitivities
//! ([`super::projection::Sensitivities`]). The mission chosen is
//! D_s-optimal: it maximises det(Lᵀ W L)^(1/k), L the k candidates' projected
//! imprints, W = 1/floor² of each point's channel — information about the
//! candidates that the calibration cannot take up, counted against the
//! floor, and small when two candidates leave the same imprint. Its
//! expected imprint ratio per candidate is reported alone and with the
//! other candidates fitted too (separation).

use super::analysis::{evidence_points, fit_points, split_time_s, DiagnoseOptions};
use super::evidence::{floor_for, ChannelFloor};
use super::fit::{fit, FitOptions};
use super::model::{Candidate, Simulator};
use super::adequacy::rms_rise_k;
use super::projection::{channel_floors, row, ProjectedRow, Sensitivities};
use super::reference::{nuisance_set, ReferenceModel};
use crate::emulator::missions::{EmuMission, EmuScenario};
use crate::hydraulics::NEEDLE_SET_RPM;
use crate::measured::{Channel, MeasuredRun};
use crate::rig::Rig;
use crate::scenario::{Circuit, Mission, PositionRef, Schedule, ValveRule};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
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

/// The mission family within `limits`: every pair of distinct levels among
/// the four corners of the speed × drop envelope and its centre, alternated
/// with each hold time of [`HOLDS_S`]; with a fan, each also with the air
/// toggled between 0 and the largest every second segment (a quarter
/// period out of phase with the levels).
pub fn family(limits: &Limits, duration_s: f64, ambient_c: f64) -> Vec<Design> {
    let (s0, s1) = limits.speed_rpm;
    let (d0, d1) = limits.drop_bar;
    let levels = [(s0, d0), (s0, d1), (s1, d0), (s1, d1), (0.5 * (s0 + s1), 0.5 * (d0 + d1))];
    let airs: Vec<Option<f64>> = match limits.air_mps {
        Some(a) => vec![None, Some(a)],
        None => vec![None],
    };
    let mut out = Vec::new();
    for i in 0..levels.len() {
        for j in i + 1..levels.len() {
            for hold in HOLDS_S {
                for air in &airs {
                    let n = (duration_s / hold).ceil() as usize;
                    let segments = (0..n)
                        .map(|k| {
                            let (s, d) = if k % 2 == 0 { levels[i] } else { levels[j] };
                            let a = air.map_or(0.0, |a| if (k / 2) % 2 == 1 { a } else { 0.0 });
                            Level { speed_rpm: s, drop_bar: d, air_mps: a }
                        })
                        .collect();
                    let name = format!(
                        "{:.0} rpm/{:.0} bar ↔ {:.0} rpm/{:.0} bar every {hold:.0} s{}",
                        levels[i].0,
                        levels[i].1,
                        levels[j].0,
                        levels[j].1,
                        air.map_or(String::new(), |a| format!(", air 0/{a:.0} m/s every {:.0} s", 2.0 * hold))
                    );
                    out.push(Design { name, hold_s: hold, segments, duration_s, ambient_c });
                }
            }
        }
    }
    out
}

/// What the plan expects of one candidate.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Expected {
    /// The candidate against the floor on the planned mission.
    pub planned: ProjectedRow,
    /// Expected ratio on the planned mission with the other leading
    /// candidates fitted along (how well it separates from them).
    pub planned_separated: f64,
    /// The same candidate against the floor on the user's log.
    pub on_log: Option<ProjectedRow>,
}

/// One member of the family as evaluated.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Evaluated {
    /// Description.
    pub name: String,
    /// D_s criterion, det(Lᵀ W L)^(1/k) (dimensionless: imprints over floors).
    pub d_s: f64,
    /// Largest predicted temperature of a logged channel, °C.
    pub max_temp_c: f64,
    /// Within the limits (temperatures included).
    pub admissible: bool,
}

/// A test plan.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Plan {
    /// The chosen mission.
    pub design: Design,
    /// Its D_s criterion.
    pub d_s: f64,
    /// The leading candidates and their magnitudes: (candidate, parameter,
    /// value, unit).
    pub candidates: Vec<(String, String, f64, String)>,
    /// Expected imprint ratios, per candidate.
    pub expected: Vec<Expected>,
    /// Every member of the family, in the order evaluated.
    pub family: Vec<Evaluated>,
    /// The envelope used.
    pub limits: Limits,
    /// The user's log's floor per channel (the calibrated physical set).
    pub log_floors: Vec<ChannelFloor>,
}

/// The machine as calibrated on the user's log.
struct Machine {
    rig: Rig,
    /// The calibrated rig (physical set applied).
    calibrated: Rig,
    /// Calibrated values by parameter name.
    values: Vec<(String, f64)>,
    floors: Vec<ChannelFloor>,
}

/// Calibrates the physical set of the reference model on `log` (one fit on
/// the training window).
fn calibrate(rig: &Rig, log: &MeasuredRun, split: f64, per_channel: usize) -> Result<Machine, String> {
    let model = ReferenceModel::new(rig.clone(), log).map_err(|e| e.to_string())?;
    let phys = model.physical_set().ok_or("the model has no physical set")?;
    let specs = phys.nuisance();
    let nominal: Vec<f64> = specs.iter().map(|s| s.start).collect();
    let pts = fit_points(log, split, per_channel);
    let f = fit(&*phys, log, &pts, Candidate::None, &nominal, None, FitOptions::default()).ok_or("the calibration failed on the log")?;
    let mut theta = crate::calibration::set::nominal();
    for (&k, &v) in nuisance_set(log).iter().zip(&f.nuisance) {
        theta[k] = v;
    }
    let floors = channel_floors(log, &f.series, &pts, split);
    let values = specs.iter().zip(&f.nuisance).map(|(s, v)| (s.name.clone(), *v)).collect();
    Ok(Machine { rig: rig.clone(), calibrated: crate::calibration::apply(rig, &theta), values, floors })
}

/// Training/held-out split of `run`: the diagnosis's, at its default
/// training fraction.
fn split_of(run: &MeasuredRun) -> f64 {
    split_time_s(run, DiagnoseOptions::default().train_fraction)
}

/// Points per channel in the plan's projections (the diagnosis's default).
const PER_CHANNEL: usize = 150;

/// The planned mission flown by the calibrated model, logged as the bench
/// would log it (2 s, the log's channels; ram air when the plan has it).
pub fn predicted_log(calibrated: &Rig, d: &Design) -> Result<MeasuredRun, String> {
    let m = d.mission();
    let mut run = crate::calibration::synthetic::log(calibrated, &m, 2.0, 1, false)?;
    if d.segments.iter().any(|l| l.air_mps > 0.0) {
        let air = run.time_s.iter().map(|&t| Some(m.air_speed_mps.at(t))).collect();
        run.set(Channel::AirSpeedMps, air);
    }
    Ok(run)
}

/// A mission's projection: its sensitivities, the candidates' imprints and
/// what the calibration leaves of them, the floors.
struct Projected {
    sens: Sensitivities,
    floors: Vec<ChannelFloor>,
    imprints: Vec<DVector<f64>>,
    lefts: Vec<DVector<f64>>,
    max_temp_c: f64,
}

/// Projects the candidates `cands` (at their magnitudes) on the log `run`
/// of `machine`: the physical set of `run` at the machine's calibrated
/// values (nominal where `run` frees a parameter the user's log did not),
/// floors scaled from the user's log by each channel's rise.
fn project(machine: &Machine, run: &MeasuredRun, cands: &[(Candidate, f64)]) -> Result<Projected, String> {
    let model = ReferenceModel::new(machine.rig.clone(), run).map_err(|e| e.to_string())?;
    let phys = model.physical_set().ok_or("the model has no physical set")?;
    let nuis: Vec<f64> = phys.nuisance().iter().map(|s| machine.values.iter().find(|(n, _)| *n == s.name).map_or(s.start, |(_, v)| *v)).collect();
    let split = split_of(run);
    let sens = Sensitivities::new(&*phys, run, &nuis, evidence_points(run, split, PER_CHANNEL), split)?;
    let floors: Vec<ChannelFloor> = sens
        .channels()
        .into_iter()
        .filter_map(|ch| {
            let f = machine.floors.iter().find(|f| f.channel == ch.name())?;
            let r = rms_rise_k(run, ch, split);
            Some(ChannelFloor { channel: f.channel.clone(), noise_k: f.noise_k, rise_k: r, misfit_k: f.misfit_k / f.rise_k.max(1e-6) * r })
        })
        .collect();
    let imprints: Vec<DVector<f64>> =
        cands.par_iter().map(|&(c, m)| sens.imprint(&*phys, &nuis, c, &[m])).collect::<Result<Vec<_>, String>>()?;
    let lefts = imprints.iter().map(|s| sens.left(s, &[])).collect();
    let max_temp_c = Channel::TEMPERATURES
        .iter()
        .filter_map(|ch| sens.base.channels.get(ch))
        .flat_map(|v| v.iter().copied())
        .fold(f64::NEG_INFINITY, f64::max);
    Ok(Projected { sens, floors, imprints, lefts, max_temp_c })
}

impl Projected {
    /// det(Lᵀ W L)^(1/k), W = 1/floor² of each point's channel.
    fn d_s(&self) -> f64 {
        let w: Vec<f64> = self
            .sens
            .pts
            .iter()
            .map(|(ch, _)| self.floors.iter().find(|f| f.channel == ch.name()).map_or(0.0, |f| floor_for(f, &self.floors, std::slice::from_ref(&f.channel)).powi(-2)))
            .collect();
        let k = self.lefts.len();
        let m = DMatrix::from_fn(k, k, |a, b| self.lefts[a].iter().zip(self.lefts[b].iter()).zip(&w).map(|((x, y), w)| x * y * w).sum::<f64>());
        m.determinant().max(0.0).powf(1.0 / k.max(1) as f64)
    }
}

/// Designs the plan for `log` of a machine described by `rig`, to show
/// and separate `cands` (candidate, magnitude), within `limits`, lasting
/// `duration_s`.
pub fn plan(rig: &Rig, log: &MeasuredRun, cands: &[(Candidate, f64)], limits: Limits, duration_s: f64) -> Result<Plan, String> {
    if cands.is_empty() {
        return Err("no candidates to plan for".into());
    }
    if let Some(c) = cands.iter().find(|c| c.0 == Candidate::CoulombFriction || c.0 == Candidate::None) {
        return Err(format!("`{}` cannot be excited by a throttle-circuit plan (the cylinder is isolated)", c.0.name()));
    }
    let split = split_of(log);
    let machine = calibrate(rig, log, split, PER_CHANNEL)?;
    let ambient_c = log.get(Channel::AmbientC).map_or(20.0, |v| {
        let x: Vec<f64> = v.iter().flatten().copied().collect();
        x.iter().sum::<f64>() / x.len().max(1) as f64
    });
    let designs = family(&limits, duration_s, ambient_c);
    let evaluated: Vec<Result<(Evaluated, Projected), String>> = designs
        .par_iter()
        .map(|d| {
            let run = predicted_log(&machine.calibrated, d)?;
            let p = project(&machine, &run, cands)?;
            let admissible = p.max_temp_c <= limits.max_temp_c && d.segments.iter().all(|l| limits.contains(l));
            Ok((Evaluated { name: d.name.clone(), d_s: p.d_s(), max_temp_c: p.max_temp_c, admissible }, p))
        })
        .collect();
    let mut best: Option<(usize, f64)> = None;
    let mut family_rows = Vec::new();
    let mut projections = Vec::new();
    for (k, e) in evaluated.into_iter().enumerate() {
        match e {
            Ok((ev, p)) => {
                if ev.admissible && best.is_none_or(|b| ev.d_s > b.1) {
                    best = Some((k, ev.d_s));
                }
                family_rows.push(ev);
                projections.push(Some(p));
            }
            Err(msg) => {
                family_rows.push(Evaluated { name: format!("{} (failed: {msg})", designs[k].name), d_s: 0.0, max_temp_c: f64::NAN, admissible: false });
                projections.push(None);
            }
        }
    }
    let (k, d_s) = best.ok_or("no mission of the family is within the limits")?;
    let p = projections[k].take().ok_or("the chosen mission has no projection")?;
    let on_log = project(&machine, log, cands).ok();
    // The candidates' parameter names and units (one model of the log, not one per name).
    let ext_model = ReferenceModel::new(rig.clone(), log).ok();
    let named = |c: Candidate, m: f64| -> Vec<(String, f64, String)> {
        ext_model.as_ref().map(|r| r.extension_params(c)).unwrap_or_default().iter().map(|s| (s.name.clone(), m, s.unit.clone())).collect()
    };
    let expected = cands
        .iter()
        .enumerate()
        .map(|(i, &(c, m))| {
            let mag = named(c, m);
            let others: Vec<&DVector<f64>> = p.imprints.iter().enumerate().filter(|(j, _)| *j != i).map(|(_, s)| s).collect();
            let sep = p.sens.left(&p.imprints[i], &others);
            let sep_row = row(&p.sens, &p.floors, c, &mag, &p.imprints[i], &sep);
            Expected {
                planned: row(&p.sens, &p.floors, c, &mag, &p.imprints[i], &p.lefts[i]),
                planned_separated: sep_row.best.1,
                on_log: on_log.as_ref().map(|q| row(&q.sens, &q.floors, c, &mag, &q.imprints[i], &q.lefts[i])),
            }
        })
        .collect();
    let candidates = cands.iter().flat_map(|&(c, m)| named(c, m).into_iter().map(move |(n, v, u)| (c.name().to_string(), n, v, u))).collect();
    Ok(Plan { design: designs[k].clone(), d_s, candidates, expected, family: family_rows, limits, log_floors: machine.floors })
}

impl Plan {
    /// A note when no candidate is expected to reach r ≥ 2 on the planned
    /// run: the family cannot make them showable on this machine.
    pub fn warning(&self) -> Option<String> {
        let best = self.expected.iter().map(|e| e.planned.best.1).fold(1.0, f64::max);
        (best < super::projection::SHOWABLE_RATIO).then(|| {
            format!(
                "no candidate is expected to reach r {} on the planned run (largest r̂ {best:.2}): the calibration absorbs their imprints on every mission of the family",
                super::projection::SHOWABLE_RATIO
            )
        })
    }

    /// `plan.md`: the mission's levels, the expected ratios and the family.
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "# Test plan\n\nMission: {} ({} segments, {:.0} s; `mission.csv`). D_s = {:.3} \
             (det of the candidates' projected information against the floor, per candidate).\n\n\
             | segment | start (s) | speed (rpm) | needle drop at that speed (bar) | needle setting at 500 rpm (bar) | ram air (m/s) |\n|---:|---:|---:|---:|---:|---:|\n",
            self.design.name,
            self.design.segments.len(),
            self.design.duration_s,
            self.d_s
        );
        for (k, l) in self.design.segments.iter().enumerate() {
            let _ = writeln!(s, "| {} | {:.0} | {:.0} | {:.1} | {:.2} | {:.1} |", k + 1, k as f64 * self.design.hold_s, l.speed_rpm, l.drop_bar, l.needle_setting_bar(), l.air_mps);
        }
        s.push_str(
            "\nExpected imprint ratio r̂ = √(floor² + left²)/floor on the best channel (left: the candidate's imprint the \
             calibration cannot take up, held out; floor: the user's log's misfit per rise, scaled by the planned rise); \
             a diagnosis must name a cause at r ≥ 2. Separated: with the other candidates fitted along.\n\n\
             | candidate | magnitude | r̂ on the log | r̂ planned | channel | r̂ planned, separated |\n|---|---|---:|---:|---|---:|\n",
        );
        for e in &self.expected {
            let mag: Vec<String> = e.planned.magnitude.iter().map(|(n, v, u)| format!("{n}={v:.3e} {u}")).collect();
            let _ = writeln!(
                s,
                "| `{}` | {} | {} | {:.2} | {} | {:.2} |",
                e.planned.candidate,
                mag.join(", "),
                e.on_log.as_ref().map_or("–".into(), |r| format!("{:.2} ({})", r.best.1, r.best.0)),
                e.planned.best.1,
                e.planned.best.0,
                e.planned_separated
            );
        }
        if let Some(w) = self.warning() {
            let _ = writeln!(s, "\n**Note:** {w}.");
        }
        s.push_str("\nThe family (two levels alternated; D_s, largest predicted temperature, within the limits):\n\n| mission | D_s | max T (°C) | admissible |\n|---|---:|---:|---|\n");
        for f in &self.family {
            let _ = writeln!(s, "| {} | {:.3} | {:.1} | {} |", f.name, f.d_s, f.max_temp_c, if f.admissible { "yes" } else { "no" });
        }
        s
    }
}

/// The leading candidates of a diagnosis a throttle-circuit plan can
/// excite: the `n` most probable, ties (a candidate the log could not admit
/// has probability 0) broken by the Bayes factor against `none`. `causes`
/// is (cause, probability, ln Bayes factor), as `diagnosis.json`'s
/// `probabilities` lists them.
pub fn leading(causes: &[(String, f64, f64)], n: usize) -> Vec<Candidate> {
    let mut c: Vec<(Candidate, f64, f64)> = causes
        .iter()
        .filter_map(|(name, p, bf)| Some((Candidate::from_name(name)?, *p, if bf.is_finite() { *bf } else { f64::NEG_INFINITY })))
        .filter(|(c, _, _)| *c != Candidate::None && *c != Candidate::CoulombFriction)
        .collect();
    c.sort_by(|a, b| b.1.total_cmp(&a.1).then(b.2.total_cmp(&a.2)));
    c.into_iter().take(n).map(|x| x.0).collect()
}
