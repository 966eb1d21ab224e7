//! Residual statistics of the diagnosis: error metrics in K, the Ljung–Box
//! whiteness test, normalised cross-correlation with physical regressors
//! over lags, and the Bayesian information criterion.

/// Root-mean-square of the present residuals, K. `None` when all are missing.
pub fn rmse(r: &[Option<f64>]) -> Option<f64> {
    let (s, n) = r.iter().flatten().fold((0.0, 0usize), |(s, n), x| (s + x * x, n + 1));
    (n > 0).then(|| (s / n as f64).sqrt())
}

/// Mean of the present residuals (simulated minus measured), K.
pub fn bias(r: &[Option<f64>]) -> Option<f64> {
    let (s, n) = r.iter().flatten().fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    (n > 0).then(|| s / n as f64)
}

/// Largest absolute present residual, K.
pub fn max_abs(r: &[Option<f64>]) -> Option<f64> {
    r.iter().flatten().map(|x| x.abs()).fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))))
}

/// Sample autocorrelation of `x` at lags 1..=`max_lag` (mean removed).
/// Missing samples are skipped pairwise; the normalisation is the variance
/// of the present samples (Box & Jenkins estimator).
pub fn autocorrelation(x: &[Option<f64>], max_lag: usize) -> Vec<f64> {
    let present: Vec<f64> = x.iter().flatten().copied().collect();
    let n = present.len() as f64;
    if n < 2.0 {
        return vec![0.0; max_lag];
    }
    let mean = present.iter().sum::<f64>() / n;
    let var = present.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
    (1..=max_lag)
        .map(|k| {
            let s: f64 = (k..x.len())
                .filter_map(|i| Some((x[i]? - mean) * (x[i - k]? - mean)))
                .sum();
            if var > 0.0 { s / var } else { 0.0 }
        })
        .collect()
}

/// Result of the Ljung–Box portmanteau test on a residual series.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LjungBox {
    /// Q = n(n+2) Σ_{k=1}^{h} ρ̂_k²/(n−k).
    pub q: f64,
    /// Number of lags h (= degrees of freedom).
    pub lags: usize,
    /// P(χ²_h > Q): small means the residuals are not white.
    pub p_value: f64,
}

/// Ljung–Box test (Ljung & Box 1978) of `x` over `lags` lags.
pub fn ljung_box(x: &[Option<f64>], lags: usize) -> LjungBox {
    let n = x.iter().flatten().count() as f64;
    let rho = autocorrelation(x, lags);
    let q = n * (n + 2.0) * rho.iter().enumerate().map(|(k, r)| r * r / (n - (k + 1) as f64).max(1.0)).sum::<f64>();
    LjungBox { q, lags, p_value: chi2_sf(q, lags as f64) }
}

/// Survival function of the χ² distribution with `k` degrees of freedom,
/// P(X > x) = Q(k/2, x/2), by the regularised incomplete gamma function.
pub fn chi2_sf(x: f64, k: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    gamma_q(k / 2.0, x / 2.0)
}

/// ln Γ(x) by the Lanczos approximation (g = 7, n = 9), |error| < 1e-13.
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + 7.5;
    let a = C[0] + (1..9).map(|i| C[i] / (x + i as f64)).sum::<f64>();
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised upper incomplete gamma Q(a, x): series for x < a+1,
/// Lentz continued fraction otherwise (Numerical Recipes §6.2).
fn gamma_q(a: f64, x: f64) -> f64 {
    let lg = ln_gamma(a);
    if x < a + 1.0 {
        let (mut sum, mut term, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..1000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * (-x + a * x.ln() - lg).exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..1000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (-x + a * x.ln() - lg).exp() * h
    }
}

/// Normalised cross-correlation of residual `r` with regressor `u` at lags
/// `0..=max_lag` (u leading r by `lag` samples): corr(r\[i\], u\[i−lag\]) over
/// the pairs where both are present, each series mean-removed.
pub fn cross_correlation(r: &[Option<f64>], u: &[f64], max_lag: usize) -> Vec<f64> {
    cross_correlation_every(r, u, max_lag, 1)
}

/// [`cross_correlation`] at every `step`-th lag only (lags 0, step,
/// 2·step, … ≤ `max_lag`; `step` 0 counts as 1).
pub fn cross_correlation_every(r: &[Option<f64>], u: &[f64], max_lag: usize, step: usize) -> Vec<f64> {
    // The pairs of each lag are walked in place (a 30-minute log at 0.1 s
    // has 1200 lags of 18 k pairs per channel and regressor; collecting
    // them cost more than the diagnosis's model runs).
    (0..=max_lag).step_by(step.max(1)).map(|lag| pearson_of(|| (lag..r.len()).filter_map(move |i| Some((r[i]?, u[i - lag]))))).collect()
}

/// Pearson correlation of the pairs, 0 when either side is constant.
pub fn pearson(pairs: &[(f64, f64)]) -> f64 {
    pearson_of(|| pairs.iter().copied())
}

/// [`pearson`] of the pairs `pairs()` yields (called once per pass, three
/// passes), with the same operations in the same order.
fn pearson_of<I: Iterator<Item = (f64, f64)>>(pairs: impl Fn() -> I) -> f64 {
    let n = pairs().count() as f64;
    if n < 3.0 {
        return 0.0;
    }
    let (mx, my) = pairs().fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (x, y) in pairs() {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx).powi(2);
        syy += (y - my).powi(2);
    }
    if sxx <= 0.0 || syy <= 0.0 { 0.0 } else { sxy / (sxx * syy).sqrt() }
}

/// Bayesian information criterion for Gaussian residuals:
/// BIC = n ln(RSS/n) + k ln n, with `n` residuals, sum of squares `rss`
/// (K²) and `k` fitted parameters. Lower is better.
pub fn bic(rss: f64, n: usize, k: usize) -> f64 {
    let n = n as f64;
    n * (rss.max(1e-300) / n).ln() + k as f64 * n.ln()
}

/// Errors of one channel, K (simulated − measured).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ChannelMetrics {
    /// Channel name.
    pub channel: String,
    /// RMSE on the training window, K.
    pub train_rmse_k: f64,
    /// RMSE on the held-out window, K.
    pub heldout_rmse_k: f64,
    /// Mean residual over the run, K.
    pub bias_k: f64,
    /// Largest absolute residual over the run, K.
    pub max_error_k: f64,
    /// Ljung–Box test of the residuals over the run.
    pub ljung_box: LjungBox,
}

/// Errors of one model over every measured temperature channel.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Metrics {
    /// Per channel.
    pub channels: Vec<ChannelMetrics>,
    /// Pooled RMSE over all channels, training window, K.
    pub train_rmse_k: f64,
    /// Pooled RMSE over all channels, held-out window, K.
    pub heldout_rmse_k: f64,
}

impl Metrics {
    /// The metrics of channel `name`.
    pub fn channel(&self, name: &str) -> Option<&ChannelMetrics> {
        self.channels.iter().find(|c| c.channel == name)
    }
}

/// Peak cross-correlation of one channel's residual with one regressor.
#[derive(Debug, Clone, serde::Serialize)]
pub struct XCorr {
    /// Residual channel.
    pub channel: String,
    /// Regressor name.
    pub regressor: String,
    /// Correlation at lag 0.
    pub rho0: f64,
    /// Largest |correlation| over the lags (signed).
    pub peak_rho: f64,
    /// Lag of the peak, s (regressor leading the residual).
    pub peak_lag_s: f64,
}
