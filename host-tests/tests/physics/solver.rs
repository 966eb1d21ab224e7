//! The stiff solver (diffsol BDF with the plant's finite-difference
//! Jacobian) against analytic solutions, to a relative error of 1e-6
//! (issue acceptance; the solver runs at rtol 1e-9 so that the bound tests
//! the integration and not the tolerance setting).

use eha_sim::plant::integrate;

// The spec bound (1e-6) is what the issue demands; the measured errors are
// 300-40 000 times smaller, so each test also has a regression bound at 2-3x
// its measured error (a change of the BDF order/step control or of the
// Jacobian that costs accuracy shows here first).
/// Regression bound of the RC node: measured rel. error 3.00e-9, 2.7×.
const REG_RC: f64 = 8e-9;
/// Regression bounds of the two-node network: measured rel. errors 4.51e-10
/// (oil) and 2.67e-11 (metal), 2.2× each.
const REG_TWO_NODE: [f64; 2] = [1e-9, 6e-11];

/// One RC node heated by P and cooled to ambient through G:
/// T(t) = T_a + P/G + (T_0 − T_a − P/G)·exp(−G·t/C).
#[test]
fn rc_node_matches_exponential() {
    let (c, g, p, ta, t0) = (9200.0, 3.5, 150.0, 16.0, 16.0);
    let t_end = 3000.0;
    let y = integrate(|_t, x, d| d[0] = (p - g * (x[0] - ta)) / c, &[t0], &[50.0], t_end, 1e-9, 1e-9).expect("solves");
    let exact = ta + p / g + (t0 - ta - p / g) * (-g * t_end / c).exp();
    let rel = (y[0] - exact).abs() / exact;
    println!("RC node: T = {:.9} °C, exact {exact:.9} °C, rel. error {rel:.2e}", y[0]);
    // Spec (issue): 1e-6.
    assert!(rel < 1e-6, "T = {} vs {exact} (rel {rel:e})", y[0]);
    // Regression: 2-3x the measured REG_RC.
    assert!(rel < REG_RC, "rel. error {rel:.2e} > regression bound {REG_RC:.0e}");
}

/// Two nodes (oil C1 heated by P, metal C2 to ambient) with a stiff ratio
/// C1/C2 = 1/100: the exact solution by eigen-decomposition of the 2×2
/// system matrix.
#[test]
fn two_node_network_matches_eigen_solution() {
    let (c1, c2, g12, g2a, p) = (2500.0, 250_000.0, 30.0, 4.0, 900.0);
    // x = temperature rise over ambient; dx/dt = A x + b.
    let a = [[-g12 / c1, g12 / c1], [g12 / c2, -(g12 + g2a) / c2]];
    let b = [p / c1, 0.0];
    let rhs = |_t: f64, x: &[f64], d: &mut [f64]| {
        d[0] = a[0][0] * x[0] + a[0][1] * x[1] + b[0];
        d[1] = a[1][0] * x[0] + a[1][1] * x[1] + b[1];
    };
    let t_end = 1800.0;
    let y = integrate(rhs, &[0.0, 0.0], &[50.0, 50.0], t_end, 1e-9, 1e-9).expect("solves");
    // Steady state x* = −A⁻¹ b; x(t) = x* + Σ c_i v_i e^{λ_i t} with x(0) = 0.
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let xs = [-(a[1][1] * b[0] - a[0][1] * b[1]) / det, -(-a[1][0] * b[0] + a[0][0] * b[1]) / det];
    let tr = a[0][0] + a[1][1];
    let disc = (tr * tr / 4.0 - det).sqrt();
    let (l1, l2) = (tr / 2.0 + disc, tr / 2.0 - disc);
    // Eigenvectors (a01, λ − a00).
    let v1 = [a[0][1], l1 - a[0][0]];
    let v2 = [a[0][1], l2 - a[0][0]];
    // Solve c1 v1 + c2 v2 = −x*.
    let d = v1[0] * v2[1] - v2[0] * v1[1];
    let k1 = (-xs[0] * v2[1] + v2[0] * xs[1]) / d;
    let k2 = (-v1[0] * xs[1] + xs[0] * v1[1]) / d;
    for i in 0..2 {
        let exact = xs[i] + k1 * v1[i] * (l1 * t_end).exp() + k2 * v2[i] * (l2 * t_end).exp();
        let rel = (y[i] - exact).abs() / exact.abs();
        println!("two-node, node {i}: {:.9} K, exact {exact:.9} K, rel. error {rel:.2e}", y[i]);
        // Spec (issue): 1e-6.
        assert!(rel < 1e-6, "node {i}: {} vs {exact} (rel {rel:e})", y[i]);
        // Regression: 2-3x the measured.
        assert!(rel < REG_TWO_NODE[i], "node {i}: rel. error {rel:.2e} > regression bound {:.0e}", REG_TWO_NODE[i]);
    }
}
