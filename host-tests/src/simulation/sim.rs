//! Offline simulation runs: a scenario in, time series of every channel out
//! (the shared measured-data columns plus the model's internal channels).

use crate::network::{Node, NODES};
use crate::fast::{FastOptions, FastPlant};
use crate::plant::{Control, Plant, RuleEval, SimError, Snapshot, Stats};
use crate::rig::Rig;
use crate::scenario::Scenario;
use std::io::Write;
use std::path::Path;

/// Options of an offline run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimOptions {
    /// Output sample interval, s.
    pub output_interval_s: f64,
    /// Interval at which the scenario's valve rule is evaluated, s.
    pub control_interval_s: f64,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self { output_interval_s: 1.0, control_interval_s: 0.1 }
    }
}

/// Columns of the shared measured-data format, in its order.
pub const MEASURED_COLUMNS: [&str; 14] = [
    "time_s",
    "speed_rpm",
    "current_a",
    "p_a_bar",
    "p_b_bar",
    "ambient_c",
    "position_mm",
    "t_motor_c",
    "t_pump_c",
    "t_block_c",
    "t_ballvalve_c",
    "t_oil_c",
    "lng_valve",
    "air_speed_mps",
];

/// About how many channels [`each_channel`] gives (the measured columns, the
/// other nodes, 11 losses, 8 more): a capacity, so one allocation.
const CHANNEL_COUNT_HINT: usize = 13 + NODES.len() + 19;

/// Every channel of a snapshot as (name, value): the measured-format
/// channels first (without `time_s`), then the internal ones.
pub fn channels(s: &Snapshot) -> Vec<(&'static str, f64)> {
    let mut v = Vec::with_capacity(CHANNEL_COUNT_HINT);
    each_channel(s, |name, x| v.push((name, x)));
    v
}

/// [`channels`] one by one, in the same order, without collecting them
/// (a run's outputs push them straight into their columns).
pub fn each_channel(s: &Snapshot, mut f: impl FnMut(&'static str, f64)) {
    let op = &s.op;
    for (name, x) in [
        ("speed_rpm", op.omega * 60.0 / (2.0 * std::f64::consts::PI)),
        ("current_a", op.current_a),
        ("p_a_bar", op.p_a * 1e-5),
        ("p_b_bar", op.p_b * 1e-5),
        ("ambient_c", op.ambient_c),
        ("position_mm", op.x * 1e3),
        ("t_motor_c", s.temp(Node::Motor)),
        ("t_pump_c", s.temp(Node::Pump)),
        ("t_block_c", s.temp(Node::MainBlock)),
        ("t_ballvalve_c", s.temp(Node::BallBlock)),
        ("t_oil_c", s.temp(Node::Sensor)),
        ("lng_valve", if s.lng_open { 1.0 } else { 0.0 }),
        ("air_speed_mps", op.air_mps),
    ] {
        f(name, x);
    }
    for n in NODES {
        if !matches!(n, Node::Motor | Node::Pump | Node::MainBlock | Node::BallBlock | Node::Sensor) {
            f(n.channel(), s.temp(n));
        }
    }
    for (name, x) in s.losses.channels() {
        f(name, x);
    }
    for (name, x) in s.losses.friction_split_channels() {
        f(name, x);
    }
    for (name, x) in [
        ("p_total_w", s.losses.total()),
        ("e_loss_j", s.e_loss_j),
        ("e_ambient_j", s.e_amb_j),
        ("e_lng_j", s.e_lng_j),
        ("e_stored_j", s.stored_j),
        ("lng_used_kg", s.lng_used_kg),
        ("velocity_mm_s", op.v * 1e3),
        ("q_path_l_min", op.q_path * 6e4),
    ] {
        f(name, x);
    }
}

/// Result of an offline run.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOutput {
    /// Scenario name.
    pub name: String,
    /// Output times, s.
    pub time_s: Vec<f64>,
    /// Channels, in [`channels`] order.
    pub columns: Vec<(String, Vec<f64>)>,
    /// Solver statistics.
    pub stats: Stats,
    /// Times at which the LNG valve opened (s).
    pub valve_open_times_s: Vec<f64>,
    /// Times at which the LNG valve closed (s).
    pub valve_close_times_s: Vec<f64>,
}

impl SimOutput {
    /// A channel by name.
    pub fn get(&self, name: &str) -> Option<&[f64]> {
        if name == "time_s" {
            return Some(&self.time_s);
        }
        self.columns.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_slice())
    }

    /// Last value of a channel.
    pub fn last(&self, name: &str) -> Option<f64> {
        self.get(name).and_then(|v| v.last().copied())
    }

    /// Maximum of a channel.
    pub fn max(&self, name: &str) -> Option<f64> {
        self.get(name).map(|v| v.iter().copied().fold(f64::NEG_INFINITY, f64::max))
    }

    /// Value of a channel interpolated at `t`.
    pub fn at(&self, name: &str, t: f64) -> Option<f64> {
        let v = self.get(name)?;
        interpolate(&self.time_s, v, self.time_s.partition_point(|&x| x <= t), t)
    }

    /// Channel `name` interpolated at every time of `times` (ascending), as
    /// [`SimOutput::at`] gives each, in one pass: the diagnosis samples every
    /// replay at every logged row, where a name lookup and a binary search
    /// per row cost a tenth of the run.
    pub fn sample(&self, name: &str, times: &[f64]) -> Option<Vec<f64>> {
        let v = self.get(name)?;
        let ts = &self.time_s;
        // i = the number of output times <= t, as `at`'s binary search gives.
        let mut i = 0;
        times
            .iter()
            .map(|&t| {
                if i > 0 && ts[i - 1] > t {
                    // Not ascending: start the walk again.
                    i = 0;
                }
                while i < ts.len() && ts[i] <= t {
                    i += 1;
                }
                interpolate(ts, v, i, t)
            })
            .collect()
    }

    /// Write the run as CSV: the shared measured-data columns first (so any
    /// reader of that format can read it), then the internal channels as
    /// extra columns, with `# key: value` metadata.
    pub fn write_csv(&self, path: &Path, meta: &[(&str, String)]) -> std::io::Result<()> {
        let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
        for (k, v) in meta {
            writeln!(f, "# {k}: {v}")?;
        }
        let mut w = csv::Writer::from_writer(f);
        let mut header = vec!["time_s".to_string()];
        header.extend(self.columns.iter().map(|(n, _)| n.clone()));
        w.write_record(&header)?;
        for (i, t) in self.time_s.iter().enumerate() {
            let mut row = vec![format!("{t:.3}")];
            for (name, col) in &self.columns {
                let x = col.get(i).copied().unwrap_or(f64::NAN);
                row.push(if name == "lng_valve" { format!("{x:.0}") } else { format!("{x:.6}") });
            }
            w.write_record(&row)?;
        }
        w.flush()?;
        Ok(())
    }
}

/// Linear interpolation of `v` (sampled at `ts`) at `t`, where `i` is the
/// number of `ts` at or before `t`; held at the ends.
pub(crate) fn interpolate(ts: &[f64], v: &[f64], i: usize, t: f64) -> Option<f64> {
    match (i.checked_sub(1).and_then(|j| ts.get(j).zip(v.get(j))), ts.get(i).zip(v.get(i))) {
        (Some((ta, a)), Some((tb, b))) => Some(a + (b - a) * (t - ta) / (tb - ta)),
        (Some((_, a)), None) => Some(*a),
        (None, Some((_, b))) => Some(*b),
        (None, None) => None,
    }
}

/// Run `scenario` on `rig` and sample every channel.
pub fn simulate(rig: &Rig, scenario: &Scenario, opt: &SimOptions) -> Result<SimOutput, SimError> {
    simulate_rtol(rig, scenario, opt, crate::plant::RTOL)
}

/// [`simulate`] with the solver's relative tolerance `rtol`.
pub fn simulate_rtol(rig: &Rig, scenario: &Scenario, opt: &SimOptions, rtol: f64) -> Result<SimOutput, SimError> {
    let mut plant = Plant::new(rig, scenario)?;
    plant.set_rtol(rtol);
    run_plant(plant, scenario, opt)
}

/// [`simulate`] on the multirate fast path ([`crate::fast`]) with its
/// accuracy for the scenario ([`FastOptions::for_scenario`]: within
/// 0.01 K of the tight BDF solution on the paper's cases and the random
/// missions, `docs/reference-speed.md`).
pub fn simulate_fast(rig: &Rig, scenario: &Scenario, opt: &SimOptions) -> Result<SimOutput, SimError> {
    simulate_fast_with(rig, scenario, opt, FastOptions::for_scenario(scenario))
}

/// [`simulate_fast`] with explicit accuracy settings.
pub fn simulate_fast_with(rig: &Rig, scenario: &Scenario, opt: &SimOptions, fo: FastOptions) -> Result<SimOutput, SimError> {
    run_plant(FastPlant::with_options(rig, scenario, fo)?, scenario, opt)
}

/// Which integrator runs the reference model.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Solver {
    /// diffsol's adaptive BDF ([`Plant`]), rtol [`crate::plant::RTOL`]: the
    /// reference itself.
    #[default]
    Bdf,
    /// The multirate scheme ([`FastPlant`]): within 0.01 K of the BDF at
    /// rtol 1e-9 on missions, 5-6x faster (`docs/reference-speed.md`). Not
    /// faster on replays of logged inputs.
    Fast,
}

/// [`simulate`] with the chosen integrator.
pub fn simulate_with(rig: &Rig, scenario: &Scenario, opt: &SimOptions, solver: Solver) -> Result<SimOutput, SimError> {
    match solver {
        Solver::Bdf => simulate(rig, scenario, opt),
        Solver::Fast => simulate_fast(rig, scenario, opt),
    }
}

/// Independent runs in parallel on rayon's work-stealing pool (the global
/// pool: `RAYON_NUM_THREADS` threads, one per core by default; or the pool
/// the caller `install`s), in the order given.
pub fn simulate_batch(jobs: &[(Rig, Scenario)], opt: &SimOptions, solver: Solver) -> Vec<Result<SimOutput, SimError>> {
    use rayon::prelude::*;
    jobs.par_iter().map(|(rig, sc)| simulate_with(rig, sc, opt, solver)).collect()
}

/// The diagnosis's replay: [`simulate_rtol`] that fails with
/// [`SimError::StepBudget`] after `step_limit` solver steps
/// ([`Plant::set_step_limit`]), with the error control of a replay fitted
/// to logged temperatures ([`Plant::set_replay_tolerances`]).
pub fn simulate_budget(rig: &Rig, scenario: &Scenario, opt: &SimOptions, rtol: f64, step_limit: Option<u64>) -> Result<SimOutput, SimError> {
    let mut plant = Plant::new(rig, scenario)?;
    plant.set_replay_tolerances(true);
    plant.set_rtol(rtol);
    plant.set_step_limit(step_limit);
    run_plant(plant, scenario, opt)
}

/// What [`run_plant`] needs of an integrator: the BDF [`Plant`] and the
/// multirate [`FastPlant`] run the same callbacks.
trait Runner {
    fn time_s(&self) -> f64;
    fn valve_rule(&self) -> RuleEval;
    fn stats(&self) -> Stats;
    fn run_dyn(&mut self, dt_s: f64, t_end: f64, on_step: &mut dyn FnMut(&Snapshot) -> Result<Control, SimError>) -> Result<(), SimError>;
}

impl Runner for Plant {
    fn time_s(&self) -> f64 {
        Plant::time_s(self)
    }
    fn valve_rule(&self) -> RuleEval {
        Plant::valve_rule(self)
    }
    fn stats(&self) -> Stats {
        Plant::stats(self)
    }
    fn run_dyn(&mut self, dt_s: f64, t_end: f64, on_step: &mut dyn FnMut(&Snapshot) -> Result<Control, SimError>) -> Result<(), SimError> {
        self.run(dt_s, t_end, on_step)
    }
}

impl Runner for FastPlant {
    fn time_s(&self) -> f64 {
        FastPlant::time_s(self)
    }
    fn valve_rule(&self) -> RuleEval {
        FastPlant::valve_rule(self)
    }
    fn stats(&self) -> Stats {
        FastPlant::stats(self)
    }
    fn run_dyn(&mut self, dt_s: f64, t_end: f64, on_step: &mut dyn FnMut(&Snapshot) -> Result<Control, SimError>) -> Result<(), SimError> {
        self.run(dt_s, t_end, on_step)
    }
}

fn run_plant(mut plant: impl Runner, scenario: &Scenario, opt: &SimOptions) -> Result<SimOutput, SimError> {
    let name = match scenario.mission() {
        Some(m) => m.name,
        None => match scenario {
            Scenario::Replay(r) => r.name.clone(),
            _ => "run".into(),
        },
    };
    let t0 = plant.time_s();
    let t_end = t0 + scenario.duration_s() - if matches!(scenario, Scenario::Replay(_)) { t0 } else { 0.0 };
    let dt = opt.control_interval_s.min(opt.output_interval_s);
    let every = (opt.output_interval_s / dt).round().max(1.0) as u64;
    let mut out = SimOutput {
        name,
        time_s: vec![],
        columns: vec![],
        stats: Stats::default(),
        valve_open_times_s: vec![],
        valve_close_times_s: vec![],
    };
    let mut k: u64 = 0;
    let mut last_open = false;
    let rule = plant.valve_rule();
    plant.run_dyn(dt, t_end, &mut |s| {
        let cmd = rule.command(s);
        if k.is_multiple_of(every) || s.t >= t_end - 1e-9 {
            if out.columns.is_empty() {
                // The first output names the columns as it fills them (one
                // pass over the channels, no list of them).
                let n = ((t_end - s.t) / opt.output_interval_s).max(0.0) as usize + 2;
                out.columns.reserve_exact(CHANNEL_COUNT_HINT);
                out.time_s.reserve(n);
                each_channel(s, |name, v| {
                    let mut col = Vec::with_capacity(n);
                    col.push(v);
                    out.columns.push((name.to_string(), col));
                });
            } else {
                let mut cols = out.columns.iter_mut();
                each_channel(s, |_, v| {
                    if let Some((_, col)) = cols.next() {
                        col.push(v);
                    }
                });
            }
            out.time_s.push(s.t);
        }
        if let Some(open) = cmd {
            if open && !last_open {
                out.valve_open_times_s.push(s.t);
            }
            if !open && last_open {
                out.valve_close_times_s.push(s.t);
            }
            last_open = open;
        }
        k += 1;
        Ok(Control { lng_valve: cmd, stop: false })
    })?;
    out.stats = plant.stats();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `sample` is `at` in one pass: the same floating-point operations, so
    /// equal to the bit, before the first output, between, on and after the
    /// last, and for times that are not ascending.
    #[test]
    fn sample_equals_at_at_every_time() {
        let out = SimOutput {
            name: "t".into(),
            time_s: vec![0.0, 0.5, 1.5, 4.0],
            columns: vec![("x".into(), vec![1.0, -2.0, 3.5, 0.25])],
            stats: Stats::default(),
            valve_open_times_s: vec![],
            valve_close_times_s: vec![],
        };
        let times = [-1.0, 0.0, 0.1, 0.5, 0.75, 1.5, 3.9, 4.0, 9.0, 0.2, 2.0];
        let got = out.sample("x", &times).expect("channel");
        for (t, g) in times.iter().zip(&got) {
            assert_eq!(g.to_bits(), out.at("x", *t).expect("value").to_bits(), "t = {t}");
        }
        assert!(out.sample("y", &times).is_none());
    }
}
