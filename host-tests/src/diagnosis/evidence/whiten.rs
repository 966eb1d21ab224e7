//! The Kalman whitening of a channel's residual under an AR(1)
//! discrepancy, and the whitened residual's lag-1 autocorrelation.

/// Kalman whitening of one channel's residual under an AR(1) discrepancy of
/// amplitude `amp_k` and time constant `tau_s` plus white noise `noise_k`,
/// at the sample times: a linear, data-independent filter.
#[derive(Debug, Clone)]
pub struct Whitener {
    phi: Vec<f64>,
    gain: Vec<f64>,
    sd: Vec<f64>,
}

impl Whitener {
    /// The filter for samples at `times_s` (increasing).
    pub fn new(times_s: &[f64], amp_k: f64, noise_k: f64, tau_s: f64) -> Self {
        let (s2, r) = (amp_k * amp_k, noise_k * noise_k);
        let (mut phi, mut gain, mut sd) = (Vec::new(), Vec::new(), Vec::new());
        let mut p = s2;
        for (i, t) in times_s.iter().enumerate() {
            let f = if i == 0 { 0.0 } else { (-(t - times_s[i - 1]).max(0.0) / tau_s).exp() };
            let pp = if i == 0 { s2 } else { f * f * p + s2 * (1.0 - f * f) };
            let s = pp + r;
            let k = pp / s;
            p = (1.0 - k) * pp;
            phi.push(f);
            gain.push(k);
            sd.push(s.sqrt());
        }
        Whitener { phi, gain, sd }
    }

    /// Whitened innovations of `y` (each N(0, 1) under the model).
    pub fn whiten(&self, y: &[f64]) -> Vec<f64> {
        let mut x = 0.0;
        y.iter()
            .enumerate()
            .map(|(i, v)| {
                let xp = self.phi[i] * x;
                let nu = v - xp;
                x = xp + self.gain[i] * nu;
                nu / self.sd[i]
            })
            .collect()
    }

    /// Gaussian log-likelihood of `y`.
    pub fn log_lik(&self, y: &[f64]) -> f64 {
        self.log_lik_of_whitened(&self.whiten(y))
    }

    /// Gaussian log-likelihood from the whitened innovations `w` of [`Self::whiten`].
    pub fn log_lik_of_whitened(&self, w: &[f64]) -> f64 {
        self.predictive_of_whitened(w, 0)
    }

    /// Predictive log density of the samples `from..` of `y` given the
    /// samples before them, ln p(y[from..] | y[..from]), nats: the sum of
    /// the Kalman filter's one-step predictive log densities over the later
    /// samples (the filter carries the discrepancy's state across the split;
    /// equal to ln p(y) − ln p(y[..from]) of the dense Gaussian).
    pub fn predictive_log_density(&self, y: &[f64], from: usize) -> f64 {
        self.predictive_of_whitened(&self.whiten(y), from)
    }

    /// [`Self::predictive_log_density`] from the whitened innovations `w`
    /// of [`Self::whiten`] (`from` 0: the whole log-likelihood).
    pub fn predictive_of_whitened(&self, w: &[f64], from: usize) -> f64 {
        let from = from.min(w.len());
        -0.5 * w[from..].iter().map(|x| x * x).sum::<f64>()
            - self.sd[from..w.len()].iter().map(|s| s.ln()).sum::<f64>()
            - 0.5 * (w.len() - from) as f64 * (2.0 * std::f64::consts::PI).ln()
    }
}
/// Lag-1 autocorrelation of `w` (0 for fewer than three values).
pub fn lag1(w: &[f64]) -> f64 {
    if w.len() < 3 {
        return 0.0;
    }
    let m = w.iter().sum::<f64>() / w.len() as f64;
    let v: f64 = w.iter().map(|x| (x - m) * (x - m)).sum();
    if v <= 0.0 {
        return 0.0;
    }
    w.windows(2).map(|p| (p[0] - m) * (p[1] - m)).sum::<f64>() / v
}

/// The fraction of samples that count as independent, n_eff / n =
/// (1 − ρ)/(1 + ρ) for a lag-1 autocorrelation ρ ≥ 0 of the whitened
/// residual (an AR(1) sequence's variance of the mean), 1 for ρ ≤ 0.
pub fn effective_fraction(rho: f64) -> f64 {
    let r = rho.clamp(0.0, 0.999);
    (1.0 - r) / (1.0 + r)
}
