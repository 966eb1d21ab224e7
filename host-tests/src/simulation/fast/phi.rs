//! The φ-functions of exponential integrators for a small matrix A and a
//! step h: E = e^{hA} and Φ_k = h·φ_k(hA) for k = 1, 2, 3, where
//! φ_k(z) = ∫₀¹ e^{(1−θ)z} θ^{k−1}/(k−1)! dθ (φ₁(z) = (e^z − 1)/z, ...).
//!
//! The exact solution of z' = A·z + g₀ + τ·g₁ + τ²/2·g₂ over one step is
//! z(h) = E·z₀ + Φ₁·g₀ + h·Φ₂·g₁ + h²·Φ₃·g₂: with these four matrices a step
//! of the linear thermal network is exact for forcing polynomial in time.
//!
//! Computed by a Taylor series at h/2^s (‖hA‖₁/2^s ≤ 1/2, degree 11:
//! truncation below 2e-16) and s doublings,
//! Φ₁(2h) = (E+I)·Φ₁, Φ₂(2h) = ((E+I)·Φ₂ + Φ₁)/2,
//! Φ₃(2h) = ((E+I)·Φ₃ + Φ₂ + Φ₁/2)/4, E(2h) = E²,
//! which follow from splitting ∫₀^{2h} at h. Doubling is also how a stepper
//! moves to twice the step at the cost of four products.

use super::dense::{identity, lin2, mul_rows, mul_vec, norm1, transpose, zeros, Mat};
use std::mem::MaybeUninit;

/// Degree of the Taylor polynomial of φ₃.
const TAYLOR_DEGREE: usize = 11;
/// Largest ‖hA‖₁ at which the Taylor polynomial is used.
const TAYLOR_NORM: f64 = 0.5;

/// E = e^{hA} and Φ_k = h·φ_k(hA), k = 1..3, for one step h, kept as
/// their transposes (the columns as rows): the step's matrix–vector
/// products read columns ([`super::dense::mul_vec_add_cols`]), and the
/// doubling works on the transposes as well ((X·Y)ᵀ = Yᵀ·Xᵀ, the same
/// products summed in the same order: bit-identical to doubling the
/// matrices and transposing). Four matrices (5.4 kB at 13 nodes) rather
/// than the matrices and their transposes (seven, 9.5 kB, copied into
/// each level's box).
#[derive(Debug, Clone, Copy)]
pub struct Phi<const N: usize> {
    /// Step, s.
    pub h: f64,
    /// (e^{hA})ᵀ.
    pub et: Mat<N>,
    /// The transposes of Φ₁ = h·φ₁(hA) = ∫₀^h e^{sA} ds, Φ₂ = h·φ₂(hA),
    /// Φ₃ = h·φ₃(hA), s.
    pub cols: [Mat<N>; 3],
}

impl<const N: usize> Phi<N> {
    /// The φ-functions of `a` (1/s) for the step `h` (s).
    pub fn new(a: &Mat<N>, h: f64) -> Self {
        let norm = norm1(a) * h;
        if norm == 0.0 {
            // A = 0 (no Jacobian yet): E = I, Φ_k = h/k!·I.
            let id: Mat<N> = identity();
            return Self { h, et: id, cols: [lin2(&id, h, &id, 0.0), lin2(&id, h / 2.0, &id, 0.0), lin2(&id, h / 6.0, &id, 0.0)] };
        }
        let s = if norm > TAYLOR_NORM { (norm / TAYLOR_NORM).log2().ceil() as i32 } else { 0 };
        let h0 = h / 2f64.powi(s);
        let mut phi = Self::taylor(a, h0);
        for _ in 0..s {
            phi = phi.doubled();
        }
        phi
    }

    /// Taylor polynomials at a step with ‖hA‖₁ ≤ 1/2: φ₃ by Horner, then
    /// φ_k = Z·φ_{k+1} + I/k! down to E = Z·φ₁ + I (Z = hA), on the
    /// transposes (Pᵀ·Zᵀ for Z·P).
    fn taylor(a: &Mat<N>, h: f64) -> Self {
        let mut z = transpose(a);
        for row in z.iter_mut() {
            for x in row.iter_mut() {
                *x *= h;
            }
        }
        // 1/(j+3)! for j = 0..=TAYLOR_DEGREE.
        let mut inv_fact = [0.0; TAYLOR_DEGREE + 1];
        let mut f = 6.0;
        for (j, c) in inv_fact.iter_mut().enumerate() {
            *c = 1.0 / f;
            f *= (j + 4) as f64;
        }
        let id: Mat<N> = identity();
        // P·Z + c·I (as lin2(P·Z, 1, I, c)) into `out`, row by row.
        let next = |p: &Mat<N>, c: f64, out: &mut Mat<N>| {
            mul_rows(p, &z, |i, mut r| {
                for (x, e) in r.iter_mut().zip(&id[i]) {
                    *x = *x * 1.0 + e * c;
                }
                out[i] = r;
            })
        };
        // Horner's steps alternate between two matrices (no copies).
        let mut ping = [lin2(&id, inv_fact[TAYLOR_DEGREE], &zeros(), 0.0), zeros()];
        let mut cur = 0;
        for j in (0..TAYLOR_DEGREE).rev() {
            let [a, b] = &mut ping;
            let (src, dst) = if cur == 0 { (&*a, b) } else { (&*b, a) };
            next(src, inv_fact[j], dst);
            cur ^= 1;
        }
        let p3 = &ping[cur];
        let (mut p2, mut p1, mut et) = (zeros(), zeros(), zeros());
        next(p3, 0.5, &mut p2);
        next(&p2, 1.0, &mut p1);
        next(&p1, 1.0, &mut et);
        Self { h, et, cols: [lin2(&p1, h, &id, 0.0), lin2(&p2, h, &id, 0.0), lin2(p3, h, &id, 0.0)] }
    }

    /// The same functions at twice the step (four matrix products).
    pub fn doubled(&self) -> Self {
        let mut d = MaybeUninit::<Self>::uninit();
        // SAFETY: `double_into` writes every field.
        unsafe {
            self.double_into(d.as_mut_ptr());
            d.assume_init()
        }
    }

    /// [`Phi::doubled`] in a new box, its matrices written into the
    /// allocation row by row: a level is 5.4 kB, and a zeroed or copied
    /// box of that size goes through a byte-wise `rep stosb` / `rep movsb`
    /// (glibc above 2 kB), which callgrind counts as 5.4 k instructions;
    /// the products' rows go straight into it (no product matrix zeroed,
    /// returned and copied: ~2.5 k instructions a doubling).
    pub fn doubled_boxed(&self) -> Box<Self> {
        let mut b = Box::<Self>::new_uninit();
        // SAFETY: `double_into` writes every field.
        unsafe {
            self.double_into(b.as_mut_ptr());
            b.assume_init()
        }
    }

    /// Writes Φ₁ᵀ, Φ₂ᵀ, Φ₃ᵀ and Eᵀ at twice the step into `out`: Φ₁(2h) =
    /// (E+I)·Φ₁, Φ₂(2h) = ((E+I)·Φ₂ + Φ₁)/2, Φ₃(2h) = ((E+I)·Φ₃ + Φ₂ +
    /// Φ₁/2)/4, E(2h) = E², on the transposes, row by row (the operations
    /// of the matrices' products and `lin2` combinations, in their order).
    ///
    /// # Safety
    /// `out` is valid for writes of a `Phi<N>` (it may be uninitialised;
    /// every field is written, nothing is read from it).
    unsafe fn double_into(&self, out: *mut Self) {
        let [c1, c2, c3] = &self.cols;
        // E + I, as lin2(E, 1, I, 1) gives it: x·1 + δ·1 is x + 0 off the
        // diagonal (which turns −0 into +0) and x + 1 on it.
        let mut ep = self.et;
        for row in ep.iter_mut() {
            for x in row.iter_mut() {
                *x += 0.0;
            }
        }
        for (i, row) in ep.iter_mut().enumerate() {
            row[i] = self.et[i][i] + 1.0;
        }
        // SAFETY (all writes): rows of fields of `out`, in bounds (i < N).
        let row_of = |m: *mut Mat<N>, i: usize| unsafe { m.cast::<[f64; N]>().add(i) };
        let cols = unsafe { std::ptr::addr_of_mut!((*out).cols) }.cast::<Mat<N>>();
        let (o1, o2, o3) = unsafe { (cols, cols.add(1), cols.add(2)) };
        let et = unsafe { std::ptr::addr_of_mut!((*out).et) };
        unsafe { std::ptr::addr_of_mut!((*out).h).write(2.0 * self.h) };
        mul_rows(c1, &ep, |i, r| unsafe { row_of(o1, i).write(r) });
        mul_rows(c2, &ep, |i, mut r| {
            for (x, y) in r.iter_mut().zip(&c1[i]) {
                *x = *x * 0.5 + y * 0.5;
            }
            unsafe { row_of(o2, i).write(r) }
        });
        mul_rows(c3, &ep, |i, mut r| {
            for ((x, y), w) in r.iter_mut().zip(&c2[i]).zip(&c1[i]) {
                let p = *x * 0.25 + y * 0.25;
                *x = p * 1.0 + w * 0.125;
            }
            unsafe { row_of(o3, i).write(r) }
        });
        mul_rows(&self.et, &self.et, |i, r| unsafe { row_of(et, i).write(r) });
    }

    /// E = e^{hA} (not transposed).
    pub fn e(&self) -> Mat<N> {
        transpose(&self.et)
    }

    /// Φ_k = h·φ_k(hA), k = 1, 2, 3 (not transposed).
    pub fn p(&self, k: usize) -> Mat<N> {
        transpose(&self.cols[k - 1])
    }
}

/// Largest ‖τA‖₁ for which [`solve_linear`] is cheaper than the matrices.
pub const VECTOR_NORM_MAX: f64 = 4.0;

/// z(τ) of z' = A·z + c₀ + c₁·s + c₂·s²/2, z(0) = z₀, by Taylor series of
/// the solution on substeps with ‖δA‖₁ ≤ 1/2 (each term one product A·v;
/// the series stops below 1e-17 of the sum): the action of the
/// φ-functions on vectors, for steps too odd to cache their matrices (a
/// schedule breakpoint, a flow reversal). Cost ~15·‖τA‖₁/0.5
/// matrix–vector products.
pub fn solve_linear<const N: usize>(a: &Mat<N>, tau: f64, z0: &[f64; N], c: [&[f64; N]; 3]) -> [f64; N] {
    let n = ((norm1(a) * tau / TAYLOR_NORM).ceil() as usize).max(1);
    let d = tau / n as f64;
    let mut z = *z0;
    // The forcing and its first two derivatives at the substep's start.
    let (mut f0, mut f1, f2) = (*c[0], *c[1], *c[2]);
    for _ in 0..n {
        // First derivative A·z + f, then each next one A times the last
        // plus the forcing's derivative of that order; the j-th term of
        // the series is d^j/j! times the j-th derivative.
        let mut term = mul_vec(a, &z);
        for i in 0..N {
            term[i] = (term[i] + f0[i]) * d;
        }
        let mut next = z;
        for i in 0..N {
            next[i] += term[i];
        }
        for j in 2..40 {
            let forcing = match j {
                2 => Some(&f1),
                3 => Some(&f2),
                _ => None,
            };
            let mut t = mul_vec(a, &term);
            let fac = d / j as f64;
            // d^(j−1)/(j−1)!: with the factor d/j below, d^j/j! times the forcing's derivative.
            let dd = if j == 2 { d } else { 0.5 * d * d };
            for i in 0..N {
                t[i] = (t[i] + forcing.map_or(0.0, |f| f[i] * dd)) * fac;
            }
            term = t;
            let (tn, zn) = term.iter().zip(&next).fold((0.0f64, 0.0f64), |(p, q), (x, y)| (p.max(x.abs()), q.max(y.abs())));
            for i in 0..N {
                next[i] += term[i];
            }
            if j > 3 && tn <= 1e-17 * zn {
                break;
            }
        }
        z = next;
        for i in 0..N {
            f0[i] += d * f1[i] + 0.5 * d * d * f2[i];
            f1[i] += d * f2[i];
        }
    }
    z
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The vector solution against the matrices: z(h) = E·z₀ + Φ₁·c₀ +
    /// h·Φ₂·c₁ + h²·Φ₃·c₂ for the stiff 3×3 network of `doubling_equals_direct`, at
    /// ‖hA‖₁ from 0.02 to 4 (1e-12 relative).
    #[test]
    fn vector_solution_matches_the_matrices() {
        let a: Mat<3> = [[-2.0, 1.0, 0.5], [0.3, -0.9, 0.1], [0.0, 0.2, -0.05]];
        let (z0, c0, c1, c2) = ([20.0, 30.0, 25.0], [1.0, -0.5, 0.02], [0.1, 0.3, -0.2], [0.05, -0.02, 0.01]);
        for h in [0.007, 0.3, 1.4] {
            let p = Phi::new(&a, h);
            let (e, p1, p2, p3) = (p.e(), p.p(1), p.p(2), p.p(3));
            let got = solve_linear(&a, h, &z0, [&c0, &c1, &c2]);
            for i in 0..3 {
                let want: f64 = (0..3).map(|j| e[i][j] * z0[j] + p1[i][j] * c0[j] + h * p2[i][j] * c1[j] + h * h * p3[i][j] * c2[j]).sum();
                assert!((got[i] - want).abs() < 1e-12 * want.abs(), "h {h}: {got:?} vs {want}");
            }
        }
    }

    /// Scalar closed forms: φ₁(z) = (e^z−1)/z, φ₂ = (e^z−1−z)/z²,
    /// φ₃ = (e^z−1−z−z²/2)/z³, for z from −200 (a stiff node over a long
    /// step: many doublings) to +0.3, to 1e-12 relative (round-off of
    /// the doublings; the closed forms lose digits near z = 0, where the
    /// bound is checked with series values instead).
    #[test]
    fn scalar_phi_functions_match_closed_forms() {
        for (a, h) in [(-4.0, 50.0), (-0.8, 0.25), (-1e-4, 10.0), (0.03, 10.0), (-3.2, 1e-3)] {
            let p = Phi::<1>::new(&[[a]], h);
            let z: f64 = a * h;
            let (e1, e2, e3) = if z.abs() > 1e-2 {
                let ez = z.exp();
                ((ez - 1.0) / z, (ez - 1.0 - z) / (z * z), (ez - 1.0 - z - z * z / 2.0) / (z * z * z))
            } else {
                let s = |k: i32| (0..20).map(|j| z.powi(j) / (1..=(j + k)).map(f64::from).product::<f64>()).sum::<f64>();
                (s(1), s(2), s(3))
            };
            for (got, want, k) in [(p.et[0][0], z.exp(), 0), (p.cols[0][0][0] / h, e1, 1), (p.cols[1][0][0] / h, e2, 2), (p.cols[2][0][0] / h, e3, 3)] {
                assert!((got - want).abs() <= 1e-12 * want.abs(), "z = {z}, phi_{k}: {got} vs {want}");
            }
        }
    }

    /// A non-normal 2×2 matrix (a stiff oil node feeding a slow metal node):
    /// the step of z' = A·z + g₀ + τ·g₁ + τ²/2·g₂ from the φ-functions
    /// against a fine classical RK4 integration of the same ODE (1e-10).
    #[test]
    fn matrix_phi_step_matches_rk4() {
        let a: Mat<2> = [[-3.0, 2.9], [0.02, -0.025]];
        let (g0, g1, g2) = ([1.0, 0.1], [-0.5, 0.02], [0.3, -0.01]);
        let h = 7.0;
        let p = Phi::new(&a, h);
        let (e, p1, p2, p3) = (p.e(), p.p(1), p.p(2), p.p(3));
        let z0 = [20.0, 25.0];
        let mut exact = [0.0; 2];
        for (i, x) in exact.iter_mut().enumerate() {
            *x = (0..2)
                .map(|j| e[i][j] * z0[j] + p1[i][j] * g0[j] + h * p2[i][j] * g1[j] + h * h * p3[i][j] * g2[j])
                .sum();
        }
        let f = |t: f64, z: [f64; 2]| -> [f64; 2] {
            let mut d = [0.0; 2];
            for i in 0..2 {
                d[i] = a[i][0] * z[0] + a[i][1] * z[1] + g0[i] + t * g1[i] + t * t / 2.0 * g2[i];
            }
            d
        };
        let n = 20_000;
        let dt = h / n as f64;
        let mut z = z0;
        for k in 0..n {
            let t = k as f64 * dt;
            let add = |z: [f64; 2], d: [f64; 2], s: f64| [z[0] + s * d[0], z[1] + s * d[1]];
            let k1 = f(t, z);
            let k2 = f(t + dt / 2.0, add(z, k1, dt / 2.0));
            let k3 = f(t + dt / 2.0, add(z, k2, dt / 2.0));
            let k4 = f(t + dt, add(z, k3, dt));
            for i in 0..2 {
                z[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        for i in 0..2 {
            assert!((z[i] - exact[i]).abs() < 1e-10 * exact[i].abs(), "{z:?} vs {exact:?}");
        }
    }

    /// Doubling a step equals computing the functions at the double step.
    #[test]
    fn doubling_equals_direct() {
        let a: Mat<3> = [[-2.0, 1.0, 0.5], [0.3, -0.9, 0.1], [0.0, 0.2, -0.05]];
        let p = Phi::new(&a, 0.8).doubled();
        let q = Phi::new(&a, 1.6);
        for (m, n) in [(p.et, q.et), (p.cols[0], q.cols[0]), (p.cols[1], q.cols[1]), (p.cols[2], q.cols[2])] {
            for i in 0..3 {
                for j in 0..3 {
                    assert!((m[i][j] - n[i][j]).abs() < 1e-13, "{m:?} vs {n:?}");
                }
            }
        }
    }
}
