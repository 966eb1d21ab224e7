//! Several logs of one machine diagnosed at once: one calibration vector
//! shared by every log, each log replayed with its own inputs and circuit,
//! one ranking and one posterior.
//!
//! The diagnosis ([`super::diagnose`]) works on one table of rows and a
//! time that splits it into a training and a held-out window. The logs are
//! laid out on such a table ([`combine`]): first every log's training rows
//! (the first `train_fraction` of each log), then every log's held-out rows,
//! on one time axis with a gap of [`LOG_GAP_S`] between segments. The gap is
//! 5 discrepancy time constants, so the evidence's AR(1) discrepancy
//! (`evidence::DISCREPANCY_TAU_S`, 120 s) carries e^-5 < 1 % of its
//! correlation from one log into the next: the logs' structure errors are
//! independent. [`MultiModel`] runs every log's model with the same
//! parameter vector and places each log's series on that table.

use super::analysis::{metrics, split_time_s, DiagnoseOptions, Diagnosis, Metrics};
use super::model::{Candidate, ParamSpec, SimSeries, Simulator};
use crate::measured::MeasuredRun;
use rayon::prelude::*;
use std::sync::Arc;

/// Gap between two logs' segments on the combined time axis, s (5 × the
/// evidence's 120 s discrepancy time constant).
pub const LOG_GAP_S: f64 = 600.0;

/// Where each row of the combined table comes from.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Per combined row: (log index, row in that log).
    pub rows: Vec<(usize, usize)>,
    /// Rows per log.
    pub log_rows: Vec<usize>,
    /// Each log's own split time (its held-out window starts there), s of
    /// that log's time.
    pub log_splits_s: Vec<f64>,
    /// The combined table's split time ([`split_time_s`] of it), s.
    pub split_s: f64,
}

impl Layout {
    /// Log `log`'s rows of the combined series `v`, in that log's order.
    pub fn gather<T: Copy + Default>(&self, v: &[T], log: usize) -> Vec<T> {
        let mut out = vec![T::default(); self.log_rows[log]];
        for (c, &(i, k)) in self.rows.iter().enumerate() {
            if i == log {
                out[k] = v[c];
            }
        }
        out
    }
}

/// The logs `runs` of one machine on one table (see the module doc):
/// every log's rows before its own split (`train_fraction` of its span, at
/// most 0.7, as [`split_time_s`]) first, then every log's rows from its
/// split on. The channels are the union of the logs' (missing where a log
/// lacks one); the combined table's [`split_time_s`] at `train_fraction`
/// falls between the two blocks (checked). Errors: fewer than two logs, a
/// log without rows.
pub fn combine(runs: &[&MeasuredRun], train_fraction: f64) -> Result<(MeasuredRun, Layout), String> {
    if runs.len() < 2 {
        return Err(format!("combining logs needs at least two, got {}", runs.len()));
    }
    if let Some(i) = runs.iter().position(|r| r.len() < 2) {
        return Err(format!("log {} has fewer than two rows", i + 1));
    }
    let f = train_fraction.min(0.7);
    let log_splits_s: Vec<f64> = runs.iter().map(|r| split_time_s(r, f)).collect();
    // One block of segments (training or held-out rows of every log), from
    // relative time `t`; returns the rows, their times and the end time.
    let block = |held: bool, mut t: f64| -> (Vec<(usize, usize)>, Vec<f64>, f64) {
        let (mut rows, mut times) = (Vec::new(), Vec::new());
        for (i, r) in runs.iter().enumerate() {
            let idx: Vec<usize> = (0..r.len()).filter(|&k| (r.time_s[k] >= log_splits_s[i]) == held).collect();
            let Some(&first) = idx.first() else { continue };
            if !times.is_empty() {
                t += LOG_GAP_S;
            }
            for &k in &idx {
                rows.push((i, k));
                times.push(t + r.time_s[k] - r.time_s[first]);
            }
            t = *times.last().unwrap_or(&t);
        }
        (rows, times, t)
    };
    let (mut rows, mut times, a) = block(false, 0.0);
    let (held_rows, held_times, b) = block(true, 0.0);
    // The gap x between the blocks puts the combined split f·(a + x + b)
    // inside it: a < f(a + x + b) and f(a + x + b) < a + x.
    let lb1 = a / f - a - b;
    let lb2 = (f * (a + b) - a) / (1.0 - f);
    let x = LOG_GAP_S.max(lb1).max(lb2) + LOG_GAP_S;
    rows.extend(held_rows);
    times.extend(held_times.iter().map(|t| a + x + t));
    let mut run = MeasuredRun::new(times);
    let chans: std::collections::BTreeSet<_> = runs.iter().flat_map(|r| r.channels.keys().copied()).collect();
    for ch in chans {
        run.set(ch, rows.iter().map(|&(i, k)| runs[i].get(ch).and_then(|v| v[k])).collect());
    }
    let split_s = split_time_s(&run, f);
    let n_train = rows.iter().zip(&run.time_s).filter(|(_, t)| **t < split_s).count();
    let n_train_logs: usize = runs.iter().zip(&log_splits_s).map(|(r, s)| r.time_s.iter().filter(|t| *t < s).count()).sum();
    if n_train != n_train_logs {
        return Err(format!("combined split at {split_s:.1} s does not separate the logs' windows ({n_train} vs {n_train_logs} training rows)"));
    }
    let log_rows = runs.iter().map(|r| r.len()).collect();
    Ok((run, Layout { rows, log_rows, log_splits_s, split_s }))
}

/// The options of a joint diagnosis of `logs` logs: `o` with
/// [`DiagnoseOptions::points_per_channel`] per log (the fit and evidence
/// points are thinned over the combined table: each log keeps the
/// resolution it has alone).
pub fn options_for(o: &DiagnoseOptions, logs: usize) -> DiagnoseOptions {
    DiagnoseOptions { points_per_channel: o.points_per_channel * logs.max(1), ..*o }
}

/// One model per log sharing one parameter vector: [`Simulator::simulate`]
/// runs every log's model with the same nuisance and candidate values (in
/// parallel) and places each log's series on the combined table of
/// [`combine`]. The nuisance set and candidate parameters are the first
/// log's; [`MultiModel::new`] checks that every log's are the same.
pub struct MultiModel<'a> {
    logs: Vec<Box<dyn Simulator + 'a>>,
    layout: Arc<Layout>,
}

impl<'a> MultiModel<'a> {
    /// The logs' models `logs` (in the order of `layout`'s log indices).
    /// Errors when their nuisance sets differ by name (in either tier).
    pub fn new(logs: Vec<Box<dyn Simulator + 'a>>, layout: Layout) -> Result<Self, String> {
        if logs.len() != layout.log_rows.len() {
            return Err(format!("{} models for {} logs", logs.len(), layout.log_rows.len()));
        }
        let names = |s: &dyn Simulator| s.nuisance().iter().map(|p| p.name.clone()).collect::<Vec<_>>();
        let first = names(&*logs[0]);
        let first_phys = logs[0].physical_set().map(|p| names(&*p));
        for (i, m) in logs.iter().enumerate().skip(1) {
            if names(&**m) != first || m.physical_set().map(|p| names(&*p)) != first_phys {
                return Err(format!("log {} calibrates other parameters than log 1", i + 1));
            }
        }
        Ok(MultiModel { logs, layout: Arc::new(layout) })
    }

    /// The layout of the combined table.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }
}

impl Simulator for MultiModel<'_> {
    fn nuisance(&self) -> Vec<ParamSpec> {
        self.logs[0].nuisance()
    }

    fn extension_params(&self, c: Candidate) -> Vec<ParamSpec> {
        self.logs[0].extension_params(c)
    }

    fn simulate(&self, nuisance: &[f64], c: Candidate, ext: &[f64]) -> Result<SimSeries, String> {
        let per_log: Vec<SimSeries> =
            self.logs.par_iter().enumerate().map(|(i, m)| m.simulate(nuisance, c, ext).map_err(|e| format!("log {}: {e}", i + 1))).collect::<Result<_, _>>()?;
        // A channel or internal series some log's model lacks is NaN on
        // that log's rows (a residual there fails the fit's finiteness check).
        let place = |get: &dyn Fn(&SimSeries) -> Option<&Vec<f64>>| -> Vec<f64> {
            self.layout.rows.iter().map(|&(i, k)| get(&per_log[i]).map_or(f64::NAN, |v| v[k])).collect()
        };
        let mut s = SimSeries::default();
        let chans: std::collections::BTreeSet<_> = per_log.iter().flat_map(|p| p.channels.keys().copied()).collect();
        for ch in chans {
            s.channels.insert(ch, place(&|p: &SimSeries| p.channels.get(&ch)));
        }
        let internals: std::collections::BTreeSet<String> = per_log.iter().flat_map(|p| p.internals.keys().cloned()).collect();
        for name in internals {
            let v = place(&|p: &SimSeries| p.internals.get(&name));
            s.internals.insert(name, v);
        }
        Ok(s)
    }

    fn physical_set(&self) -> Option<Box<dyn Simulator + '_>> {
        let logs: Option<Vec<Box<dyn Simulator + '_>>> = self.logs.iter().map(|m| m.physical_set()).collect();
        Some(Box::new(MultiModel { logs: logs?, layout: self.layout.clone() }))
    }

    fn nuisance_set_name(&self) -> &'static str {
        self.logs[0].nuisance_set_name()
    }
}

/// The reference model of one machine's logs `runs` on `rig`: the logs on
/// one table ([`combine`] at `train_fraction`), one replay model per log
/// calibrating the parameters the logs share
/// ([`super::reference::nuisance_set_of`]), with the physical tier's
/// `structure` as one log's diagnosis takes it, the electrical balance
/// taken once over every log's current
/// ([`super::reference::structure_balance`],
/// [`ReferenceModel::with_structure_taken`](super::reference::ReferenceModel::with_structure_taken)).
/// The third part: why the structure
/// asked for was not applied (`None`: applied, or not asked). Errors name
/// the log (`files`).
pub fn joint_reference(
    rig: &crate::rig::Rig,
    runs: &[&MeasuredRun],
    files: &[String],
    train_fraction: f64,
    structure: super::analysis::Structure,
) -> Result<(MeasuredRun, MultiModel<'static>, Option<String>), String> {
    let (rows, layout) = combine(runs, train_fraction)?;
    let free = super::reference::nuisance_set_of(&rows, runs);
    let mut models: Vec<Box<dyn Simulator>> = Vec::with_capacity(runs.len());
    let taken = (structure != super::analysis::Structure::Off).then(|| super::reference::structure_balance(rig, runs));
    let mut refusal = None;
    for (k, run) in runs.iter().enumerate() {
        let name = files.get(k).cloned().unwrap_or_else(|| format!("log {}", k + 1));
        let m = super::reference::ReferenceModel::new(rig.clone(), run).map_err(|e| format!("{name}: {e}"))?;
        let m = m.with_nuisance_set(free.clone());
        let m = match &taken {
            Some(t) => m.with_structure_taken(&rows, structure, t),
            None => m,
        };
        refusal = m.structure_refusal().map(String::from);
        models.push(Box::new(m));
    }
    Ok((rows, MultiModel::new(models, layout)?, refusal))
}

/// Each log's part of the joint diagnosis `d` of `runs` laid out by
/// `layout`: the joint diagnosis seen on that log alone — `series`,
/// `nominal`, `before`, `after` and `split_time_s` are the log's (its rows,
/// its own training and held-out windows); the answer, ranking, posterior
/// and parameters the joint ones (for plots).
pub fn log_parts(d: &Diagnosis, runs: &[&MeasuredRun], layout: &Layout, o: &DiagnoseOptions) -> Vec<Diagnosis> {
    runs.iter()
        .enumerate()
        .map(|(i, run)| {
            let series = d.series.clone().map(|s| SimSeries {
                channels: s.channels.iter().map(|(ch, v)| (*ch, layout.gather(v, i))).collect(),
                internals: s.internals.iter().map(|(n, v)| (n.clone(), layout.gather(v, i))).collect(),
            });
            let split = layout.log_splits_s[i];
            let m = |s: &SimSeries| -> Metrics { metrics(run, s, split, o.ljung_box_lags) };
            let mut di = d.clone();
            di.nominal = m(&series[0]);
            di.before = m(&series[1]);
            di.after = m(&series[2]);
            di.split_time_s = split;
            di.series = series;
            di
        })
        .collect()
}

/// Writes a joint diagnosis: `report.md` (with the per-log section),
/// `diagnosis.json` (with its `logs` key) and each log's PNGs under
/// `log-1/`, `log-2/`, … in `out`; `files` names the logs.
pub fn write_outputs(d: &Diagnosis, parts: &[Diagnosis], runs: &[&MeasuredRun], files: &[String], out: &std::path::Path) -> std::io::Result<()> {
    use super::report::{report_markdown_logs, DiagnosisJson, LogJson};
    std::fs::create_dir_all(out)?;
    let mut pngs = Vec::new();
    for (i, (p, run)) in parts.iter().zip(runs).enumerate() {
        let sub = format!("log-{}", i + 1);
        std::fs::create_dir_all(out.join(&sub))?;
        let names = super::plot::write_plots(p, run, &out.join(&sub)).map_err(|e| std::io::Error::other(e.to_string()))?;
        pngs.extend(names.iter().map(|n| format!("{sub}/{n}")));
    }
    let logs: Vec<LogJson> = parts.iter().zip(runs).zip(files).map(|((p, r), f)| LogJson::of(f, r.len(), p)).collect();
    std::fs::write(out.join("report.md"), report_markdown_logs(d, &files.join("` + `"), &pngs, &logs))?;
    let mut j = DiagnosisJson::from_diagnosis(d);
    j.logs = logs;
    std::fs::write(out.join("diagnosis.json"), serde_json::to_string_pretty(&j).map_err(std::io::Error::other)? + "\n")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measured::Channel;

    fn log(n: usize, dt: f64, t0: f64, value: f64) -> MeasuredRun {
        let mut r = MeasuredRun::new((0..n).map(|k| t0 + dt * k as f64).collect());
        r.set(Channel::TPumpC, (0..n).map(|k| Some(value + k as f64)).collect());
        r
    }

    /// Two logs of different lengths and sampling: each contributes its
    /// first 70 % to the training block and the rest to the held-out block,
    /// every row exactly once, and the combined split falls between the
    /// blocks; a channel one log lacks is missing on its rows.
    #[test]
    fn combine_keeps_each_logs_windows_and_every_row_once() {
        let a = log(100, 2.0, 50.0, 0.0);
        let mut b = log(31, 10.0, 0.0, 1000.0);
        b.set(Channel::TOilC, vec![Some(5.0); 31]);
        let (c, l) = combine(&[&a, &b], 0.7).expect("combine");
        assert_eq!(c.len(), 131);
        let mut seen = l.rows.clone();
        seen.sort();
        seen.dedup();
        assert_eq!(seen.len(), 131);
        for (row, &(i, k)) in l.rows.iter().enumerate() {
            let own = [&a, &b][i];
            let train_here = c.time_s[row] < l.split_s;
            assert_eq!(train_here, own.time_s[k] < l.log_splits_s[i], "row {row} ({i}, {k})");
            assert_eq!(c.get(Channel::TPumpC).unwrap()[row], own.get(Channel::TPumpC).unwrap()[k]);
            assert_eq!(c.get(Channel::TOilC).unwrap()[row].is_some(), i == 1);
        }
        assert!(c.time_s.windows(2).all(|w| w[1] > w[0]), "times increase");
        assert_eq!(l.gather(c.get(Channel::TPumpC).unwrap(), 1), b.get(Channel::TPumpC).unwrap().to_vec());
        assert!(combine(&[&a], 0.7).is_err());
    }
}
