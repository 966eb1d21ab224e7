//! Identifiability of the calibration set from the scaled Jacobian
//! (residuals / σ_d with respect to ln θ): singular values, linearised
//! posterior standard deviations with the prior, strongly correlated pairs;
//! and the excitation check of each log (one operating point).

/// Start of the warning that no training log has more than one operating
/// point; `commission` refuses to write a flashable block then.
pub const NO_EXCITATION: &str = "WARNING: no training log has more than one operating point";

/// Start of the warning that no training log moves shaft speed and load
/// independently (`commission`): the calibration then rests on one-at-a-time
/// excitations, which let the set absorb structure into values that hold
/// only for them (docs/commissioning.md, "Why the identification run").
pub const NO_JOINT_EXCITATION: &str = "WARNING: no training log moves shaft speed and load independently";

use super::log::CalLog;
use super::set::PARAMS;
use crate::measured::Channel;
use nalgebra::{DMatrix, DVector};

/// Identifiability of the parameters `idx` at one point.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct Identifiability {
    /// Parameter names, in column order.
    pub names: Vec<String>,
    /// Singular values of the scaled data Jacobian, largest first.
    pub singular_values: Vec<f64>,
    /// Posterior standard deviation of ln θ (prior included, times √s²).
    pub sd_ln: Vec<f64>,
    /// Posterior over prior standard deviation, without the s² inflation:
    /// near 1 = the data add nothing to the prior.
    pub posterior_over_prior: Vec<f64>,
    /// Pairs with |posterior correlation| ≥ the threshold: (a, b, ρ).
    pub correlated: Vec<(String, String, f64)>,
}

/// Identifiability from the scaled data Jacobian `j` (columns = `idx`,
/// derivatives in ln θ), the prior widths `prior_ln` (σ in ln θ of every
/// [`PARAMS`] entry, indexed as it), residual variance
/// factor `s2` (≥ 1) and the correlation threshold.
pub fn identifiability(j: &DMatrix<f64>, idx: &[usize], prior_ln: &[f64], s2: f64, corr_threshold: f64) -> Identifiability {
    let p = idx.len();
    let names: Vec<String> = idx.iter().map(|&k| PARAMS[k].name.to_string()).collect();
    if p == 0 {
        return Identifiability { names, ..Default::default() };
    }
    let mut sv: Vec<f64> = j.clone().svd(false, false).singular_values.iter().copied().collect();
    sv.sort_by(|a, b| b.total_cmp(a));
    let prior = DVector::from_iterator(p, idx.iter().map(|&k| prior_ln[k]));
    let mut h = j.transpose() * j;
    for i in 0..p {
        h[(i, i)] += 1.0 / (prior[i] * prior[i]);
    }
    let c = h.clone().try_inverse().unwrap_or_else(|| DMatrix::from_diagonal(&prior.map(|s| s * s)));
    let sd0: Vec<f64> = (0..p).map(|i| c[(i, i)].max(0.0).sqrt()).collect();
    let posterior_over_prior = (0..p).map(|i| sd0[i] / prior[i]).collect();
    let sd_ln = sd0.iter().map(|s| s * s2.sqrt()).collect();
    let mut correlated = Vec::new();
    for a in 0..p {
        for b in a + 1..p {
            let rho = c[(a, b)] / (sd0[a] * sd0[b]).max(1e-300);
            if rho.abs() >= corr_threshold {
                correlated.push((names[a].clone(), names[b].clone(), rho));
            }
        }
    }
    Identifiability { names, singular_values: sv, sd_ln, posterior_over_prior, correlated }
}

/// Relative spread (5th–95th percentile over the 95th percentile of |x|) of
/// an input column; 0 for a constant or absent column.
pub fn spread(run: &crate::measured::MeasuredRun, f: impl Fn(usize) -> Option<f64>) -> f64 {
    let mut v: Vec<f64> = (0..run.len()).filter_map(f).collect();
    if v.len() < 3 {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    let (lo, hi) = (q(0.05), q(0.95));
    let top = lo.abs().max(hi.abs());
    if top <= 1e-9 { 0.0 } else { (hi - lo) / top }
}

/// Spread below which an input counts as held at one value.
pub const ONE_POINT_SPREAD: f64 = 0.2;

/// A log's operating inputs, row by row: speed (rpm, signed), |Δp| (bar)
/// and current (A), `None` where a cell is empty.
struct Inputs {
    speed: Vec<Option<f64>>,
    pa: Vec<Option<f64>>,
    pb: Vec<Option<f64>>,
    current: Vec<Option<f64>>,
}

impl Inputs {
    fn of(run: &crate::measured::MeasuredRun) -> Self {
        let col = |c: Channel| run.get(c).map(|v| v.to_vec()).unwrap_or_default();
        Inputs { speed: col(Channel::SpeedRpm), pa: col(Channel::PABar), pb: col(Channel::PBBar), current: col(Channel::CurrentA) }
    }
    fn speed(&self, i: usize) -> Option<f64> {
        self.speed.get(i).copied().flatten()
    }
    fn dp(&self, i: usize) -> Option<f64> {
        Some((self.pa.get(i).copied().flatten()? - self.pb.get(i).copied().flatten()?).abs())
    }
    fn current(&self, i: usize) -> Option<f64> {
        self.current.get(i).copied().flatten()
    }
}

/// Spreads ([`spread`]) of speed, pressure drop and current of a log.
fn spreads(run: &crate::measured::MeasuredRun) -> (f64, f64, f64) {
    let x = Inputs::of(run);
    (spread(run, |i| x.speed(i)), spread(run, |i| x.dp(i)), spread(run, |i| x.current(i)))
}

/// Whether a log holds speed, pressure drop and current each within
/// [`ONE_POINT_SPREAD`] of one value.
pub fn one_point(run: &crate::measured::MeasuredRun) -> bool {
    let (s_speed, s_dp, s_cur) = spreads(run);
    s_speed.max(s_dp).max(s_cur) < ONE_POINT_SPREAD
}

/// Whether every log has one operating point ([`one_point`]).
pub fn all_one_point(logs: &[CalLog]) -> bool {
    !logs.is_empty() && logs.iter().all(|l| one_point(&l.run))
}

/// Warnings for logs whose shaft speed, pressure drop and current all stay
/// within [`ONE_POINT_SPREAD`] of one value (one operating point), and when
/// no log has any such excitation.
pub fn excitation_warnings(logs: &[CalLog]) -> Vec<String> {
    let mut w = Vec::new();
    let mut all_flat = true;
    for l in logs {
        let (s_speed, s_dp, s_cur) = spreads(&l.run);
        if s_speed.max(s_dp).max(s_cur) < ONE_POINT_SPREAD {
            w.push(format!(
                "WARNING: log `{}` has one operating point (speed, pressure drop and current each vary by < {:.0} %: {:.0} / {:.0} / {:.0} %): losses that scale differently with speed and pressure cannot be told apart",
                l.name,
                100.0 * ONE_POINT_SPREAD,
                100.0 * s_speed,
                100.0 * s_dp,
                100.0 * s_cur
            ));
        } else {
            all_flat = false;
        }
    }
    if all_flat && !logs.is_empty() {
        w.push(format!("{NO_EXCITATION}: the loss coefficients (pump friction, leakage, iron loss, winding resistance) are not separable; run speed steps and pressure steps (docs/commissioning.md)"));
    }
    w
}

/// |Correlation| of shaft speed and pressure drop above which they count as
/// moving together (a speed step at one needle setting moves the pressure
/// drop with the square of the flow).
pub const JOINT_MAX_CORRELATION: f64 = 0.7;

/// Spreads of |speed| and |Δp| ([`spread`]) and their Pearson correlation
/// over the rows where both are logged.
pub fn speed_load_excitation(run: &crate::measured::MeasuredRun) -> (f64, f64, f64) {
    let x = Inputs::of(run);
    let pairs: Vec<(f64, f64)> = (0..run.len()).filter_map(|i| Some((x.speed(i)?.abs(), x.dp(i)?))).collect();
    let n = pairs.len().max(1) as f64;
    let (mx, my) = pairs.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0 / n, a.1 + p.1 / n));
    let (sxy, sxx, syy) = pairs.iter().fold((0.0, 0.0, 0.0), |a, p| {
        let (dx, dy) = (p.0 - mx, p.1 - my);
        (a.0 + dx * dy, a.1 + dx * dx, a.2 + dy * dy)
    });
    let rho = if sxx > 0.0 && syy > 0.0 { sxy / (sxx * syy).sqrt() } else { 1.0 };
    (spread(run, |i| x.speed(i).map(f64::abs)), spread(run, |i| x.dp(i)), rho)
}

/// Whether a log moves shaft speed and pressure drop independently: each
/// spreads by at least [`ONE_POINT_SPREAD`] and |ρ| < [`JOINT_MAX_CORRELATION`].
pub fn independent_speed_and_load(run: &crate::measured::MeasuredRun) -> bool {
    let (s_speed, s_dp, rho) = speed_load_excitation(run);
    s_speed >= ONE_POINT_SPREAD && s_dp >= ONE_POINT_SPREAD && rho.abs() < JOINT_MAX_CORRELATION
}

/// Shaft speed below which the churned case film has blended out (about
/// [`crate::network::CASE_CHURN_ONSET_RAD_S`]), rpm.
pub const CASE_FILM_LOW_RPM: f64 = 100.0;

/// Shaft speed above which the churned case film has blended in, rpm.
pub const CASE_FILM_HIGH_RPM: f64 = 300.0;

/// Time the drain-logged training set must spend below
/// [`CASE_FILM_LOW_RPM`] and above [`CASE_FILM_HIGH_RPM`] (each) to
/// separate the case film's floor from its churned level, s.
pub const CASE_FILM_MIN_S: f64 = 120.0;

/// Seconds the logs carrying `t_drain_c` spend below [`CASE_FILM_LOW_RPM`]
/// and above [`CASE_FILM_HIGH_RPM`] (|speed|, each row weighted by the time
/// to the next).
pub fn drain_time_low_and_high_speed_s(logs: &[CalLog]) -> (f64, f64) {
    let (mut low, mut high) = (0.0, 0.0);
    for l in logs.iter().filter(|l| l.has(Channel::TDrainC)) {
        let x = Inputs::of(&l.run);
        let t = &l.run.time_s;
        for i in 0..t.len().saturating_sub(1) {
            let Some(w) = x.speed(i).map(f64::abs) else { continue };
            let dt = t[i + 1] - t[i];
            if w < CASE_FILM_LOW_RPM {
                low += dt;
            } else if w > CASE_FILM_HIGH_RPM {
                high += dt;
            }
        }
    }
    (low, high)
}

/// Whether the logs carrying `t_drain_c` show the case film both near rest
/// and at speed ([`CASE_FILM_MIN_S`] each): otherwise the churned film's
/// level and the gap's floor are seen only in their product
/// (`set::CASE_CHURN`, `film_case`), and the fit picks between basins by
/// the last digit (measured on the emulator's big-pump, trained above
/// 300 rpm: film ×1.9 with churn ×13, or film ×6.1 with churn ×4.5).
pub fn case_film_speed_range(logs: &[CalLog]) -> bool {
    let (low, high) = drain_time_low_and_high_speed_s(logs);
    low >= CASE_FILM_MIN_S && high >= CASE_FILM_MIN_S
}

/// Reynolds number of the main-block passage's flow above which the duct
/// film's transition blend (eqs. 13/14, 2300–10⁴) carries enough of the
/// turbulent law for its level to show: at 3000 the turbulent end is 9 %
/// of the blend's weight and 40–50 % of the film (oil Pr 200–400).
pub const DUCT_TRANSITION_RE: f64 = 3000.0;

/// Time the training logs must spend with the passage's flow above
/// [`DUCT_TRANSITION_RE`] for the turbulent level (`set::DUCT_TURBULENT`)
/// to be fitted, s: a few of the block's film time constants after each
/// speed step, not one excursion.
pub const DUCT_TRANSITION_MIN_S: f64 = 300.0;

/// Seconds the logs carrying the main block's surface sensor and the oil
/// probe spend with the main-block passage's Reynolds number above
/// [`DUCT_TRANSITION_RE`], and the largest Reynolds number they reach:
/// the pump's delivery D·|ω| (the rig file's displacement, the logged
/// speed) through the passage (`blocks.loop_d_m`), ν at the logged oil
/// temperature (`t_oil_c`) on the rig's viscosity line. Each row weighted
/// by the time to the next.
pub fn duct_transition_time_s(logs: &[CalLog], rig: &crate::rig::Rig) -> (f64, f64) {
    let d = rig.blocks.loop_d_m;
    let disp = rig.displacement_m3_per_rad();
    let (mut secs, mut top) = (0.0, 0.0f64);
    for l in logs.iter().filter(|l| l.has(Channel::TBlockC) && l.has(Channel::TOilC)) {
        let x = Inputs::of(&l.run);
        let oil = l.run.get(Channel::TOilC).unwrap_or_default();
        let t = &l.run.time_s;
        for i in 0..t.len().saturating_sub(1) {
            let (Some(w), Some(Some(t_oil))) = (x.speed(i), oil.get(i)) else { continue };
            let q = disp * w.abs() * std::f64::consts::PI / 30.0;
            let re = crate::heat::reynolds(q, d, rig.oil.nu_m2_per_s(*t_oil));
            top = top.max(re);
            if re > DUCT_TRANSITION_RE {
                secs += t[i + 1] - t[i];
            }
        }
    }
    (secs, top)
}

/// Whether the training logs run the main-block passage's flow through the
/// duct law's transition ([`duct_transition_time_s`] ≥
/// [`DUCT_TRANSITION_MIN_S`]): otherwise the turbulent level acts on
/// nothing the logs see, and is held at the rig file.
pub fn duct_transition_range(logs: &[CalLog], rig: &crate::rig::Rig) -> bool {
    duct_transition_time_s(logs, rig).0 >= DUCT_TRANSITION_MIN_S
}
