//! The effective sample fraction n_eff/n of a residual, the power on the
//! likelihood that the re-statements try: from its whitened Ljung–Box p
//! (an AR(1) read from the statistic's excess) or from the discrepancy's
//! length scale.

use crate::diagnosis::evidence::{effective_fraction, DISCREPANCY_TAU_S};
use crate::diagnosis::stats::chi2_sf;

/// The χ² quantile with survival probability `p` and `k` degrees of
/// freedom (bisection on [`chi2_sf`]; `p` ≤ 1e-300 gives the search's top).
fn chi2_isf(p: f64, k: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1e5);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if chi2_sf(m, k) > p {
            lo = m;
        } else {
            hi = m;
        }
    }
    0.5 * (lo + hi)
}

/// The effective sample fraction n_eff/n of a residual of `n` points
/// whose Ljung–Box statistic over `lags` lags has p value `p`: the
/// statistic's excess over its white-noise mean, Q − lags ≈ n·Σρ_k², is
/// read as an AR(1) whose Σρ^(2k) = ρ²/(1 − ρ²) matches it, and n_eff/n =
/// (1 − ρ)/(1 + ρ) ([`effective_fraction`]). 1 for a residual the test
/// finds white (Q ≤ lags); a white residual's chance excess reads as
/// correlation (at n = 150 a 1σ excess, √(2·lags), gives 0.67), so the
/// fraction errs low.
pub fn fraction_from_ljung_box(p: f64, n: usize, lags: usize) -> f64 {
    let q = chi2_isf(p, lags as f64);
    let s = (q - lags as f64).max(0.0) / n.max(1) as f64;
    effective_fraction((s / (1.0 + s)).sqrt())
}

/// The effective sample fraction if the whitening removed none of the
/// discrepancy's correlation: an Ornstein–Uhlenbeck process of time
/// constant τ ([`DISCREPANCY_TAU_S`]) has integrated autocorrelation time
/// 2τ, so samples `dt_s` apart count as dt/(2τ) independent ones (at most 1).
pub fn fraction_from_length_scale(dt_s: f64) -> f64 {
    (dt_s / (2.0 * DISCREPANCY_TAU_S)).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An AR(1) sequence of lag-1 correlation 0.5 has n_eff/n = 1/3; read
    /// back from its own Ljung–Box p (2000 points, 20 lags) it comes out
    /// within 0.06 (the statistic sums the first 20 ρ_k², which an AR(1)
    /// of 0.5 has all but exhausted; the rest is the estimate's scatter at
    /// 2000 points). A white sequence reads at least what a 3σ chance
    /// excess of its statistic gives (0.82; measured 0.84 on this draw).
    #[test]
    fn effective_fraction_from_the_ljung_box_p_of_an_ar1() {
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut gauss = || {
            let mut u = || {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                (rng >> 11) as f64 / (1u64 << 53) as f64
            };
            let (a, b) = (u().max(1e-300), u());
            (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
        };
        let n = 2000;
        let (mut x, mut ar, mut white) = (0.0, Vec::new(), Vec::new());
        for _ in 0..n {
            x = 0.5 * x + (0.75f64).sqrt() * gauss();
            ar.push(Some(x));
            white.push(Some(gauss()));
        }
        let p = crate::diagnosis::stats::ljung_box(&ar, 20).p_value;
        let f = fraction_from_ljung_box(p, n, 20);
        assert!((f - 1.0 / 3.0).abs() < 0.06, "AR(1) 0.5: n_eff/n {f}");
        let p = crate::diagnosis::stats::ljung_box(&white, 20).p_value;
        let fw = fraction_from_ljung_box(p, n, 20);
        // A white series' Q exceeds its mean by chance, which the back-out
        // reads as correlation: at a 3σ excess (3·√(2·20)) n_eff/n is 0.82.
        let s3 = 3.0 * 40f64.sqrt() / n as f64;
        let bound = effective_fraction((s3 / (1.0 + s3)).sqrt());
        assert!(fw >= bound && fw <= 1.0, "white: {fw} (3σ bound {bound})");
    }
}
