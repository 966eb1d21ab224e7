//! Test plans (`eha-sim plan`): a bench mission that makes the leading
//! candidates showable, designed on the model calibrated to the user's log.
//!
//! The log's calibration (the physical set, [`super::reference`]) gives the
//! model of this machine and its structure floor per channel as misfit per
//! rise ([`super::projection::channel_floors`]). Every mission of a small
//! family — two or three operating levels (shaft speed, needle drop at that
//! speed, logged ram air where the bench has a fan) held in turn for 150 or
//! 300 s, within the bench's [`Limits`] — is flown by the calibrated model;
//! its log is replayed as the diagnosis will replay it, and the candidates'
//! imprints are projected off the calibration's sensitivities
//! ([`super::projection::Sensitivities`]). The mission chosen lifts the
//! most candidates to an expected ratio r̂ ≥ 2 (the ratio at which a
//! diagnosis must name a cause), then brings the others closest to it,
//! then is D_s-optimal: det(Lᵀ W L)^(1/k), L the k candidates' projected
//! imprints, W = 1/floor² of each point's channel — information about the
//! candidates that the calibration cannot take up, counted against the
//! floor, and small when two candidates leave the same imprint. Its
//! expected imprint ratio per candidate is reported alone and with the
//! other candidates fitted too (separation). With [`Decision::Joint`]
//! the plan is for the planned run diagnosed together with the user's log
//! (one calibration, [`super::multi`]): the projection is off the shared
//! physical set's sensitivities on both logs, D_s on the stacked imprints.
//!
//! This file holds the plan's search ([`plan`]) and what it returns; by
//! topic beside it: `design.rs` (the bench's limits, the operating levels
//! and the family of candidate missions) and `report.rs` (the plan's
//! warning and Markdown, the leading candidates of a diagnosis).

mod design;
mod report;

pub use design::{family, family_three, Design, Level, Limits, DEFAULT_AIR_MPS, DEFAULT_DROP_BAR, DEFAULT_MAX_TEMP_C, DEFAULT_SPEED_RPM, HOLDS_S};
pub use report::{leading, LEADING_MIN_P};

use super::analysis::{evidence_points, fit_points, split_time_s, DiagnoseOptions};
use super::evidence::{floor_for, ChannelFloor};
use super::fit::{fit, FitOptions};
use super::model::{Candidate, Simulator};
use super::adequacy::rms_rise_k;
use super::projection::{channel_floors, row, ProjectedRow, Sensitivities, SHOWABLE_RATIO};
use super::reference::{nuisance_set, ReferenceModel};
use crate::measured::{Channel, MeasuredRun};
use crate::rig::Rig;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

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
    /// Why the diagnosis could not name it on the planned run (its
    /// identifiability rule, [`super::identify::identifiable`]), if so:
    /// then the plan counted it at r̂ 1 whatever its imprint.
    pub refused: Option<String>,
}

/// Why the diagnosis's identifiability rule refuses candidate `c` on the
/// planned run `run` under the physical set (which calibrates each
/// housing's outer transfer), if it does. Checked on the planned run alone,
/// also for [`Decision::Joint`].
fn refused(c: Candidate, run: &MeasuredRun) -> Option<String> {
    super::identify::identifiable(c, run, split_of(run), true).err().map(str::to_string)
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
    /// Each candidate's expected imprint ratio on this mission, alone
    /// (its largest-imprint channel), in the plan's candidate order; 1 where
    /// the diagnosis could not name it on this mission ([`Expected::refused`]).
    pub expected_ratio: Vec<f64>,
}

/// A test plan.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Plan {
    /// The chosen mission.
    pub design: Design,
    /// How the planned run is to be decided (what the plan optimised).
    pub decision: Decision,
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

/// How the planned run will be decided, which is what the plan optimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Decision {
    /// The planned run diagnosed on its own (its own calibration).
    Alone,
    /// The planned run diagnosed together with the user's log
    /// (`eha-sim diagnose log.csv planned.csv`, [`super::multi`]): one
    /// calibration for both, so the projection is off the stacked
    /// sensitivities of both logs and the imprints are both logs' (D_s on
    /// the stacked projected imprints).
    Joint,
}

/// Projects the candidates `cands` (at their magnitudes) on the log `run`
/// of `machine`: the physical set of `run` at the machine's calibrated
/// values (nominal where `run` frees a parameter the user's log did not),
/// floors scaled from the user's log by each channel's rise.
fn project(machine: &Machine, run: &MeasuredRun, cands: &[(Candidate, f64)]) -> Result<Projected, String> {
    let model = ReferenceModel::new(machine.rig.clone(), run).map_err(|e| e.to_string())?;
    let phys = model.physical_set().ok_or("the model has no physical set")?;
    project_on(machine, &*phys, run, split_of(run), PER_CHANNEL, cands)
}

/// [`project`] for the joint decision: the user's `log` and the planned
/// `run` on one table ([`super::multi::joint_reference`]), one physical set
/// shared by both, points per channel per log, held out: both logs'
/// held-out windows.
fn project_joint(machine: &Machine, log: &MeasuredRun, run: &MeasuredRun, cands: &[(Candidate, f64)]) -> Result<Projected, String> {
    let files = ["log".to_string(), "planned".to_string()];
    // as `project` builds one log's model: the rig file's physical tier
    let (rows, joint, _) = super::multi::joint_reference(&machine.rig, &[log, run], &files, DiagnoseOptions::default().train_fraction, super::analysis::Structure::Off)?;
    let phys = joint.physical_set().ok_or("the model has no physical set")?;
    project_on(machine, &*phys, &rows, joint.layout().split_s, 2 * PER_CHANNEL, cands)
}

/// Largest value of a logged temperature channel of `run`, °C.
fn max_logged_c(run: &MeasuredRun) -> f64 {
    Channel::TEMPERATURES.iter().filter_map(|ch| run.get(*ch)).flat_map(|v| v.iter().flatten().copied()).fold(f64::NEG_INFINITY, f64::max)
}

/// The projection of `cands` with the physical set `phys` of the table
/// `run` (split at `split`, `per_channel` evidence points per channel).
fn project_on(machine: &Machine, phys: &dyn Simulator, run: &MeasuredRun, split: f64, per_channel: usize, cands: &[(Candidate, f64)]) -> Result<Projected, String> {
    let nuis: Vec<f64> = phys.nuisance().iter().map(|s| machine.values.iter().find(|(n, _)| *n == s.name).map_or(s.start, |(_, v)| *v)).collect();
    let sens = Sensitivities::new(phys, run, &nuis, evidence_points(run, split, per_channel), split)?;
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
        cands.par_iter().map(|&(c, m)| sens.imprint(phys, &nuis, c, &[m])).collect::<Result<Vec<_>, String>>()?;
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

/// One mission as evaluated: its row, its projection, and why the
/// diagnosis could not name each candidate on it (if so).
type Evaluation = Result<(Evaluated, Projected, Vec<Option<String>>), String>;

/// How a mission is ranked: first by how many candidates it is expected
/// to lift to [`SHOWABLE_RATIO`] (the ratio at which a diagnosis must name
/// a cause), then by how close it brings the others (Σ ln min(r̂, 2)), then
/// by D_s (separation). D_s alone is a product over the candidates'
/// directions: one candidate shown very strongly buys as much as several
/// shown at all (measured on the emulator, 2026-11-29, docs/test-plans.md:
/// for 1709 it chose a mission showing the probe lag at r̂ 7.3 and the
/// hidden churning at 1.00 while the family held one at 2.07 for it, which
/// lifted it to r 7.2 and had it named).
#[derive(Debug, Clone, Copy)]
struct Showing {
    shown: usize,
    closeness: f64,
    d_s: f64,
}

impl Showing {
    fn of(e: &Evaluated) -> Self {
        let shown = e.expected_ratio.iter().filter(|&&r| r >= SHOWABLE_RATIO).count();
        let closeness = e.expected_ratio.iter().map(|r| r.clamp(1.0, SHOWABLE_RATIO).ln()).sum();
        Showing { shown, closeness, d_s: e.d_s }
    }

    fn better_than(&self, o: &Self) -> bool {
        (self.shown, self.closeness, self.d_s).partial_cmp(&(o.shown, o.closeness, o.d_s)).is_some_and(|c| c.is_gt())
    }
}

/// Designs the plan for `log` of a machine described by `rig`, to show
/// and separate `cands` (candidate, magnitude), within `limits`, lasting
/// `duration_s`, for the planned run decided as `decision` says: the best
/// (the most candidates at r̂ ≥ 2, then the others closest to it, then
/// D_s) of the two- and three-level families ([`family`],
/// [`family_three`]).
pub fn plan(rig: &Rig, log: &MeasuredRun, cands: &[(Candidate, f64)], limits: Limits, duration_s: f64, decision: Decision) -> Result<Plan, String> {
    plan_among(rig, log, cands, limits, decision, |ambient_c| {
        let mut d = family(&limits, duration_s, ambient_c);
        d.extend(family_three(&limits, duration_s, ambient_c));
        d
    })
}

/// [`plan`] choosing among the missions `designs` makes for the log's
/// mean ambient (°C), e.g. [`family_three`] or a user's own.
pub fn plan_among(rig: &Rig, log: &MeasuredRun, cands: &[(Candidate, f64)], limits: Limits, decision: Decision, designs: impl FnOnce(f64) -> Vec<Design>) -> Result<Plan, String> {
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
    let designs = designs(ambient_c);
    let evaluated: Vec<Evaluation> = designs
        .par_iter()
        .map(|d| {
            let run = predicted_log(&machine.calibrated, d)?;
            let p = match decision {
                Decision::Alone => project(&machine, &run, cands)?,
                // The limit is the planned run's: the log was flown already.
                Decision::Joint => Projected { max_temp_c: max_logged_c(&run), ..project_joint(&machine, log, &run, cands)? },
            };
            let admissible = p.max_temp_c <= limits.max_temp_c && d.segments.iter().all(|l| limits.contains(l));
            // A candidate the diagnosis could not name on this mission (its
            // identifiability rule) is credited nothing here; the reasons are
            // kept for the chosen mission's report.
            let refusals: Vec<Option<String>> = cands.iter().map(|&(c, _)| refused(c, &run)).collect();
            let expected_ratio = cands
                .iter()
                .zip(&refusals)
                .enumerate()
                .map(|(i, (&(c, _), why))| if why.is_some() { 1.0 } else { row(&p.sens, &p.floors, c, &[], &p.imprints[i], &p.lefts[i]).best.1 })
                .collect();
            Ok((Evaluated { name: d.name.clone(), d_s: p.d_s(), max_temp_c: p.max_temp_c, admissible, expected_ratio }, p, refusals))
        })
        .collect();
    let mut best: Option<(usize, Showing)> = None;
    let mut family_rows = Vec::new();
    let mut projections = Vec::new();
    for (k, e) in evaluated.into_iter().enumerate() {
        match e {
            Ok((ev, p, refusals)) => {
                let key = Showing::of(&ev);
                if ev.admissible && best.as_ref().is_none_or(|b| key.better_than(&b.1)) {
                    best = Some((k, key));
                }
                family_rows.push(ev);
                projections.push(Some((p, refusals)));
            }
            Err(msg) => {
                family_rows.push(Evaluated { name: format!("{} (failed: {msg})", designs[k].name), d_s: 0.0, max_temp_c: f64::NAN, admissible: false, expected_ratio: vec![] });
                projections.push(None);
            }
        }
    }
    let (k, Showing { d_s, .. }) = best.ok_or("no mission of the family is within the limits")?;
    let (p, refusals) = projections[k].take().ok_or("the chosen mission has no projection")?;
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
                refused: refusals[i].clone(),
            }
        })
        .collect();
    let candidates = cands.iter().flat_map(|&(c, m)| named(c, m).into_iter().map(move |(n, v, u)| (c.name().to_string(), n, v, u))).collect();
    Ok(Plan { design: designs[k].clone(), decision, d_s, candidates, expected, family: family_rows, limits, log_floors: machine.floors })
}
