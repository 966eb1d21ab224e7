//! Uncertainty bands (`eha-sim uq`): Monte Carlo over the rig's
//! documented uncertain parameters ([`crate::rig::Uncertain`], `[[uncertain]]` in
//! the rig file), Latin hypercube in the log of each factor, the samples run in
//! parallel (rayon). For Case 1 (600 s, the needle at `needle_bar`, still air)
//! it gives the 5/50/95 % band of every output channel over time, and for the
//! paper's numbers (Table 4, Table 5's still-air shell, Fig. 15's valve
//! opening, the LNG sizing from the model's dissipation; Table 5 with ram air
//! on request) where each lies against its 90 % band.

use crate::cooling::{size, Lng};
use crate::rig::{Rig, Uncertain};
use crate::scenario::Scenario;
use crate::sim::{simulate, SimOptions, SimOutput};
use anyhow::{anyhow, Context, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

mod report;
pub use report::*;

/// Duration of the Case 1 run, s (Table 4's 600 s).
pub const DURATION_S: f64 = 600.0;
/// Output interval of the bands, s.
pub const OUTPUT_S: f64 = 1.0;
/// Mission time of the LNG sizing, s (the one that gives the paper's 2.30 L at
/// its 1.5 kW: `paper::power_loss_at_60bar_...`).
pub const LNG_MISSION_S: f64 = 680.0;
/// Quantiles of the bands.
pub const QUANTILES: [f64; 3] = [0.05, 0.5, 0.95];

/// Latin hypercube: `n` points in `dims` dimensions, each coordinate in (0, 1)
/// with exactly one point per stratum `[k/n, (k+1)/n)` of every dimension
/// (strata permuted independently per dimension, a uniform point inside each).
pub fn latin_hypercube(n: usize, dims: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut pts = vec![vec![0.0; dims]; n];
    for d in 0..dims {
        let mut perm: Vec<usize> = (0..n).collect();
        // Fisher–Yates
        for i in (1..n).rev() {
            let j = rng.random_range(0..=i);
            perm.swap(i, j);
        }
        for (p, k) in pts.iter_mut().zip(perm) {
            p[d] = (k as f64 + rng.random::<f64>()) / n as f64;
        }
    }
    pts
}

/// The factor of `u` in (0, 1) on `range`: log-uniform between its low and high.
pub fn factor(u: &Uncertain, x: f64) -> f64 {
    (u.low.ln() + x * (u.high.ln() - u.low.ln())).exp()
}

/// `base` with every key of every uncertain group scaled by its factor
/// (`factors` in [`Rig::uncertain`] order).
pub fn apply_factors(base: &toml::Value, rig: &Rig, factors: &[f64]) -> Result<Rig> {
    let mut doc = base.clone();
    for (u, f) in rig.uncertain.iter().zip(factors) {
        for key in &u.keys {
            let mut cur = &mut doc;
            for part in key.split('.') {
                cur = cur.get_mut(part).ok_or_else(|| anyhow!("uncertain `{}`: no key `{key}` in the rig", u.name))?;
            }
            let v = cur.as_float().ok_or_else(|| anyhow!("uncertain `{}`: `{key}` is not a number", u.name))?;
            *cur = toml::Value::Float(v * f);
        }
    }
    let out: Rig = doc.try_into().context("sampled rig")?;
    out.validate()?;
    Ok(out)
}

/// The sampled rigs: `n` Latin-hypercube samples of `rig`'s uncertain groups,
/// with their factors.
pub fn sample_rigs(rig: &Rig, n: usize, seed: u64) -> Result<Vec<(Vec<f64>, Rig)>> {
    if rig.uncertain.is_empty() {
        return Err(anyhow!("the rig file has no [[uncertain]] parameters: nothing to sample"));
    }
    let base = toml::Value::try_from(rig).context("rig to TOML")?;
    latin_hypercube(n, rig.uncertain.len(), seed)
        .into_iter()
        .map(|x| {
            let f: Vec<f64> = rig.uncertain.iter().zip(&x).map(|(u, x)| factor(u, *x)).collect();
            let r = apply_factors(&base, rig, &f)?;
            Ok((f, r))
        })
        .collect()
}

/// What one sample gives.
#[derive(Debug, Clone)]
pub struct SampleResult {
    /// Every channel of the Case 1 run at every output time (channel order of
    /// the run).
    pub out: SimOutput,
    /// The paper numbers of this sample, [`PAPER_NUMBERS`] order (NaN where
    /// not computed).
    pub numbers: Vec<f64>,
}

/// The paper's numbers that `uq` places against their bands: (name, paper
/// value, unit). The last six are Table 5 with ram air (`--table5`).
pub const PAPER_NUMBERS: [(&str, f64, &str); 13] = [
    ("Table 4 inlet", 53.00, "°C"),
    ("Table 4 outlet", 54.17, "°C"),
    ("Table 4 drain", 59.67, "°C"),
    ("Table 5 shell, still air", 25.38, "°C"),
    ("Fig. 15 valve opening (oil at 40 °C)", 110.0, "s"),
    ("LNG volume for 680 s (eqs. 23-25)", 2.30, "L"),
    ("Table 5 shell 15 m/s", 24.78, "°C"),
    ("Table 5 shell 30 m/s", 24.32, "°C"),
    ("Table 5 shell 50 m/s", 23.82, "°C"),
    ("Table 5 drain 15 m/s", 59.14, "°C"),
    ("Table 5 drain 30 m/s", 58.84, "°C"),
    ("Table 5 drain 50 m/s", 58.57, "°C"),
    ("Table 5 shell fall 0 -> 50 m/s", 1.56, "K"),
];

/// Case 1 at `needle_bar` for [`DURATION_S`] with ram air `air_mps`.
pub fn case1(rig: &Rig, needle_bar: f64, air_mps: f64) -> Result<SimOutput> {
    let mut m = Scenario::Case1 { needle_bar, duration_s: DURATION_S }.mission().ok_or_else(|| anyhow!("case 1 has a mission"))?;
    m.air_speed_mps = crate::scenario::Schedule::constant(air_mps);
    Ok(simulate(rig, &Scenario::Mission(m), &SimOptions { output_interval_s: OUTPUT_S, control_interval_s: OUTPUT_S })?)
}

/// The time a channel first passes `level` upwards (linear between samples),
/// s; the run's end when it never does.
fn crossing(out: &SimOutput, channel: &str, level: f64) -> f64 {
    let y = out.get(channel).unwrap_or(&[]);
    out.time_s
        .windows(2)
        .zip(y.windows(2))
        .find(|(_, y)| y[0] < level && y[1] >= level)
        .map_or(DURATION_S, |(t, y)| t[0] + (level - y[0]) / (y[1] - y[0]) * (t[1] - t[0]))
}

/// One sample: Case 1 in still air (every channel; Table 4, the still-air
/// shell, the 40 °C crossing, the LNG volume from the run's mean dissipation)
/// and, with `table5`, the three ram-air runs.
pub fn run_sample(rig: &Rig, needle_bar: f64, table5: bool) -> Result<SampleResult> {
    let out = case1(rig, needle_bar, 0.0)?;
    let g = |n: &str| out.last(n).unwrap_or(f64::NAN);
    let p = out.get("p_total_w").unwrap_or(&[]);
    let energy: f64 = out.time_s.windows(2).zip(p.windows(2)).map(|(t, p)| 0.5 * (p[0] + p[1]) * (t[1] - t[0])).sum();
    let lng = size(&Lng::default(), energy / DURATION_S, LNG_MISSION_S, 2.0);
    let mut numbers = vec![g("t_inlet_c"), g("t_outlet_c"), g("t_drain_c"), g("t_pump_c"), crossing(&out, "t_loop_oil_c", 40.0), lng.volume_m3 * 1e3];
    if table5 {
        let mut shells = vec![];
        let mut drains = vec![];
        for v in [15.0, 30.0, 50.0] {
            let o = case1(rig, needle_bar, v)?;
            shells.push(o.last("t_pump_c").unwrap_or(f64::NAN));
            drains.push(o.last("t_drain_c").unwrap_or(f64::NAN));
        }
        numbers.extend(&shells);
        numbers.extend(&drains);
        numbers.push(g("t_pump_c") - shells[2]);
    } else {
        numbers.extend([f64::NAN; 7]);
    }
    Ok(SampleResult { out, numbers })
}

/// Quantile `q` of `v` (sorted in place; linear between order statistics).
pub fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    let x = q * (v.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x - x.floor());
    let a = v[i];
    let b = v.get(i + 1).copied().unwrap_or(a);
    a + f * (b - a)
}

/// One paper number against its band.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PaperCheck {
    /// What it is.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// The paper's value.
    pub paper: f64,
    /// The nominal rig's value.
    pub nominal: f64,
    /// 5 %, 50 %, 95 % of the samples.
    pub band: [f64; 3],
    /// Whether the paper's value lies inside the 90 % band.
    pub inside: bool,
    /// How far outside: paper − 95 % above the band, paper − 5 % below it
    /// (0 inside).
    pub outside_by: f64,
    /// Width of the 90 % band.
    pub width: f64,
}

/// Everything `uq` computes.
#[derive(Debug, Clone)]
pub struct Uq {
    /// The samples' factors ([`Rig::uncertain`] order).
    pub factors: Vec<Vec<f64>>,
    /// Output times, s.
    pub time_s: Vec<f64>,
    /// Per channel: name and its (5 %, 50 %, 95 %) at every time.
    pub bands: Vec<(String, Vec<[f64; 3]>)>,
    /// The paper numbers against their bands (computed ones only).
    pub checks: Vec<PaperCheck>,
    /// The nominal rig's Case 1 run.
    pub nominal: SimOutput,
}

/// Options of a [`run`].
#[derive(Debug, Clone, Copy)]
pub struct UqOptions {
    /// Samples (≥ 1).
    pub samples: usize,
    /// Seed of the Latin hypercube.
    pub seed: u64,
    /// Needle setting of Case 1, bar.
    pub needle_bar: f64,
    /// Also Table 5 with ram air (three more runs per sample).
    pub table5: bool,
}

impl Default for UqOptions {
    fn default() -> Self {
        UqOptions { samples: 200, seed: 34, needle_bar: 60.0, table5: false }
    }
}

/// Runs the samples in parallel (`progress` is called once per finished
/// sample) and computes the bands and the paper checks.
pub fn run(rig: &Rig, o: &UqOptions, progress: &(dyn Fn() + Sync)) -> Result<Uq> {
    let rigs = sample_rigs(rig, o.samples.max(1), o.seed)?;
    let nominal = run_sample(rig, o.needle_bar, o.table5)?;
    let results: Vec<Result<SampleResult>> = rigs
        .par_iter()
        .map(|(_, r)| {
            let s = run_sample(r, o.needle_bar, o.table5);
            progress();
            s
        })
        .collect();
    let results: Vec<SampleResult> = results.into_iter().collect::<Result<_>>()?;
    let time_s = nominal.out.time_s.clone();
    let mut bands = vec![];
    for (name, _) in &nominal.out.columns {
        let series: Vec<&[f64]> = results.iter().filter_map(|s| s.out.get(name)).collect();
        let mut b = Vec::with_capacity(time_s.len());
        for i in 0..time_s.len() {
            let mut v: Vec<f64> = series.iter().filter_map(|s| s.get(i).copied()).filter(|x| x.is_finite()).collect();
            b.push(QUANTILES.map(|q| quantile(&mut v, q)));
        }
        bands.push((name.clone(), b));
    }
    let mut checks = vec![];
    for (k, (name, paper, unit)) in PAPER_NUMBERS.iter().enumerate() {
        let mut v: Vec<f64> = results.iter().map(|s| s.numbers[k]).filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            continue;
        }
        let band = QUANTILES.map(|q| quantile(&mut v, q));
        let outside_by = if *paper > band[2] {
            paper - band[2]
        } else if *paper < band[0] {
            paper - band[0]
        } else {
            0.0
        };
        checks.push(PaperCheck {
            name: (*name).into(),
            unit: (*unit).into(),
            paper: *paper,
            nominal: nominal.numbers[k],
            band,
            inside: outside_by == 0.0,
            outside_by,
            width: band[2] - band[0],
        });
    }
    Ok(Uq { factors: rigs.into_iter().map(|(f, _)| f).collect(), time_s, bands, checks, nominal: nominal.out })
}
