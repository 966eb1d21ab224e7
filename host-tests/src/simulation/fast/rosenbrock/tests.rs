//! Order and accuracy of the tableaux, the cube-root factor.

use super::*;

/// [`super::cbrt_factor`] within 1e-13 of `f64::cbrt` from 1e-300 to
/// 1e300 (log-spaced, 60 001 points) and exact beyond.
#[test]
fn cbrt_factor_is_the_cube_root() {
    let mut worst = 0.0f64;
    for j in 0..=60_000 {
        let x = 10f64.powf(-300.0 + j as f64 * 1e-2);
        let (a, b) = (super::cbrt_factor(x), x.cbrt());
        worst = worst.max((a / b - 1.0).abs());
    }
    assert!(worst < 1e-13, "{worst:e}");
    for x in [0.0, 1e-310, f64::INFINITY] {
        assert_eq!(super::cbrt_factor(x), x.cbrt());
    }
    assert!(super::cbrt_factor(f64::NAN).is_nan());
}

/// Convergence order on y' = −y + sin t (exact solution known): halving
/// a fixed step must cut the error at t = 2 by ~2⁴ (order 4; 12–20
/// accepted around 16). A wrong tableau coefficient breaks the order.
#[test]
fn rodas4_is_fourth_order_on_a_nonstiff_problem() {
    // y' = -y + sin(t) exact: y = Ce^{-t} + (sin t - cos t)/2.
    let run = |h: f64| {
        let mut r = Rosenbrock::<1>::new(1.0, [1.0], [1.0], h);
        let mut y = [1.0];
        // tolerances so loose that no step is rejected or enlarged:
        // fixed steps h by integrating interval by interval.
        let n = (2.0 / h).round() as usize;
        for k in 0..n {
            r.h = h;
            r.integrate(|t, y, d| d[0] = -y[0] + t.sin(), k as f64 * h, &mut y, (k + 1) as f64 * h, |_, _, _| {}).expect("ok");
        }
        let t: f64 = 2.0;
        let c = 1.0 + 0.5;
        (y[0] - (c * (-t).exp() + (t.sin() - t.cos()) / 2.0)).abs()
    };
    let (e1, e2) = (run(0.1), run(0.05));
    let ratio = e1 / e2;
    assert!((12.0..20.0).contains(&ratio), "errors {e1:e} {e2:e}, ratio {ratio}");
}

/// The conversion from the Butcher-like form, checked on RODAS3: PETSc's
/// (α, Γ, b) table gives KPP's (a, c, m) (a₃₁ = a₄₁ = 2, a₄₃ = 1,
/// c₂₁ = 4, c₃₁ = 1, c₃₂ = −1, c₄₁ = 1, c₄₂ = −1, c₄₃ = −8/3,
/// m = (2, 0, 1, 1), γ = (1/2, 3/2, 0, 0), α = (0, 0, 1, 1)).
#[test]
fn butcher_form_converts_to_kpp_form() {
    let alpha = [[0.0; 4], [0.0; 4], [1.0, 0.0, 0.0, 0.0], [0.75, -0.25, 0.5, 0.0]];
    let gam = [[0.5, 0.0, 0.0, 0.0], [1.0, 0.5, 0.0, 0.0], [-0.25, -0.25, 0.5, 0.0], [1.0 / 12.0, 1.0 / 12.0, -2.0 / 3.0, 0.5]];
    let t = Tableau::from_butcher(alpha, gam, [5.0 / 6.0, -1.0 / 6.0, -1.0 / 6.0, 0.5], [0.75, -0.25, 0.5, 0.0], 3.0);
    let close = |a: f64, b: f64| (a - b).abs() < 1e-13;
    assert!(close(t.a[2][0], 2.0) && close(t.a[3][0], 2.0) && close(t.a[3][2], 1.0) && close(t.a[1][0], 0.0), "{:?}", t.a);
    let c = [(1, 0, 4.0), (2, 0, 1.0), (2, 1, -1.0), (3, 0, 1.0), (3, 1, -1.0), (3, 2, -8.0 / 3.0)];
    assert!(c.iter().all(|&(i, j, v)| close(t.c[i][j], v)), "{:?}", t.c);
    assert!([2.0, 0.0, 1.0, 1.0].iter().zip(&t.m).all(|(a, b)| close(*a, *b)), "{:?}", t.m);
    assert!([0.5, 1.5, 0.0, 0.0].iter().zip(&t.gamma).all(|(a, b)| close(*a, *b)) && [0.0, 0.0, 1.0, 1.0].iter().zip(&t.alpha).all(|(a, b)| close(*a, *b)));
}

/// ROS34PW2 is a W-method: with the Jacobian of the first step kept for
/// the whole run (stale on a nonlinear problem) it stays third order on
/// y' = −y² + sin t: halving the step cuts the error by ~2³ (6–10).
#[test]
fn ros34pw2_keeps_third_order_with_a_stale_jacobian() {
    let run = |h: f64| {
        let mut r = Rosenbrock::<1>::with_method(Tableau::ros34pw2(), u32::MAX, 1.0, [1.0], [1.0], h);
        let mut y = [1.0];
        let n = (4.0 / h).round() as usize;
        for k in 0..n {
            r.h = h;
            r.integrate(|t, y, d| d[0] = -y[0] * y[0] + t.sin(), k as f64 * h, &mut y, (k + 1) as f64 * h, |_, _, _| {}).expect("ok");
        }
        y[0]
    };
    let exact = {
        // Reference by RODAS4 at a tiny tolerance.
        let mut r = Rosenbrock::<1>::new(1e-13, [1e-13], [1.0], 1e-4);
        let mut y = [1.0];
        r.integrate(|t, y, d| d[0] = -y[0] * y[0] + t.sin(), 0.0, &mut y, 4.0, |_, _, _| {}).expect("ok");
        y[0]
    };
    let (e1, e2) = ((run(0.1) - exact).abs(), (run(0.05) - exact).abs());
    assert!((6.0..10.0).contains(&(e1 / e2)), "errors {e1:e} {e2:e}, ratio {}", e1 / e2);
}

/// Adaptive integration of a stiff forced system (λ = −5000 1/s, the
/// check-valve time scale): y' = −5000·(y − sin t) + cos t has the
/// solution y = sin t from y(0) = 0. At tolerances 1e-6 the error at
/// t = 10 s stays below 1e-6, and the steps are set by the forcing,
/// not by the stiff eigenvalue (an explicit method would need
/// 10 s / 0.4 ms = 25 000 steps; measured here: 93).
#[test]
fn rodas4_adaptive_on_a_stiff_forced_problem() {
    let mut r = Rosenbrock::<1>::new(1e-6, [1e-6], [1.0], 1e-4);
    let mut y = [0.0];
    r.integrate(|t, y, d| d[0] = -5000.0 * (y[0] - t.sin()) + t.cos(), 0.0, &mut y, 10.0, |_, _, _| {}).expect("ok");
    println!("{:?}, error {:.2e}", r.stats, (y[0] - 10f64.sin()).abs());
    assert!((y[0] - 10f64.sin()).abs() < 1e-6, "y = {} vs {}", y[0], 10f64.sin());
    assert!(r.stats.steps < 1000, "{:?}", r.stats);
}
