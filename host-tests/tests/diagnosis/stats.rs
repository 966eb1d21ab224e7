//! Residual statistics of the diagnosis against known values.

use eha_sim::diagnosis::stats::{bias, bic, chi2_sf, cross_correlation, ljung_box, max_abs, rmse};
use rand::{Rng, SeedableRng};

fn white(n: usize, seed: u64) -> Vec<f64> {
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let (u1, u2): (f64, f64) = (r.random::<f64>().max(1e-300), r.random());
            (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
        })
        .collect()
}

#[test]
fn error_metrics_skip_missing_samples() {
    let r = [Some(1.0), None, Some(-3.0), Some(2.0)];
    assert!((rmse(&r).unwrap() - (14.0f64 / 3.0).sqrt()).abs() < 1e-12);
    assert!((bias(&r).unwrap() - 0.0).abs() < 1e-12);
    assert_eq!(max_abs(&r), Some(3.0));
    assert_eq!(rmse(&[None, None]), None);
}

#[test]
fn chi_square_survival_matches_tables() {
    // Textbook critical values: P(χ²_k > x) = 0.05 at x = 3.841 (k=1),
    // 18.307 (k=10), 31.410 (k=20); 0.01 at 37.566 (k=20). Tables give 3-4
    // digits, hence 2e-4 absolute.
    for (x, k, p) in [(3.841, 1.0, 0.05), (18.307, 10.0, 0.05), (31.410, 20.0, 0.05), (37.566, 20.0, 0.01)] {
        assert!((chi2_sf(x, k) - p).abs() < 2e-4, "x={x} k={k}: {}", chi2_sf(x, k));
    }
    // k = 2: exact exp(−x/2).
    assert!((chi2_sf(5.0, 2.0) - (-2.5f64).exp()).abs() < 1e-12);
}

#[test]
fn ljung_box_accepts_white_noise_and_rejects_ar1() {
    let e = white(2000, 7);
    let w: Vec<Option<f64>> = e.iter().map(|x| Some(*x)).collect();
    let lb = ljung_box(&w, 20);
    // White noise: p is uniform; p < 0.01 for this seed would be a 1 % event.
    assert!(lb.p_value > 0.01, "{lb:?}");
    // AR(1) with φ = 0.5: ρ1 ≈ 0.5, Q ≈ n Σρ² ≈ 2000·(1/3) ≫ χ²₂₀ quantiles.
    let mut y = vec![0.0; e.len()];
    for i in 1..e.len() {
        y[i] = 0.5 * y[i - 1] + e[i];
    }
    let a: Vec<Option<f64>> = y.iter().map(|x| Some(*x)).collect();
    let lb = ljung_box(&a, 20);
    assert!(lb.p_value < 1e-10 && lb.q > 500.0, "{lb:?}");
}

#[test]
fn cross_correlation_finds_the_lag_of_a_delayed_copy() {
    let u = white(1000, 3);
    // r[i] = u[i-5]: a regressor leading the residual by 5 samples.
    let r: Vec<Option<f64>> = (0..u.len()).map(|i| if i >= 5 { Some(u[i - 5]) } else { None }).collect();
    let cc = cross_correlation(&r, &u, 10);
    let (k, peak) = cc.iter().enumerate().fold((0, 0.0f64), |b, (k, v)| if v.abs() > b.1.abs() { (k, *v) } else { b });
    assert_eq!(k, 5);
    assert!((peak - 1.0).abs() < 1e-9);
    assert!(cc[0].abs() < 0.1, "independent at lag 0: {}", cc[0]);
}

#[test]
fn bic_penalises_parameters_by_log_n() {
    // Same RSS, one more parameter: BIC rises by exactly ln n.
    assert!((bic(10.0, 100, 3) - bic(10.0, 100, 2) - (100f64).ln()).abs() < 1e-12);
    // Halving the RSS at n = 100 lowers BIC by 100 ln 2 ≈ 69.3.
    assert!((bic(10.0, 100, 2) - bic(5.0, 100, 2) - 100.0 * 2f64.ln()).abs() < 1e-9);
}
