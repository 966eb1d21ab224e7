//! The Rosenbrock tableaux: RODAS4 and ROS34PW2, and the conversion from
//! the Butcher-like form the literature lists them in.

use super::S_MAX;

/// A Rosenbrock tableau in the form above (a, c strictly lower triangular).
#[derive(Debug, Clone, Copy)]
pub struct Tableau {
    /// Stages.
    pub s: usize,
    /// Stage abscissae α_i.
    pub alpha: [f64; S_MAX],
    /// γ_i = Σ_j γ_ij (γ₁ = γ, the diagonal).
    pub gamma: [f64; S_MAX],
    /// a_ij, i > j.
    pub a: [[f64; S_MAX]; S_MAX],
    /// c_ij, i > j.
    pub c: [[f64; S_MAX]; S_MAX],
    /// Solution weights.
    pub m: [f64; S_MAX],
    /// Error weights.
    pub e: [f64; S_MAX],
    /// Order of the error estimate plus one (the step-size exponent).
    pub elo: f64,
}

/// RODAS4 (Hairer & Wanner 1996): 6 stages, order 4(3), L-stable.
pub const RODAS4: Tableau = {
    let a7 = 1.221224509226641;
    let a8 = 6.019134481288629;
    let a9 = 12.53708332932087;
    let a10 = -0.687886036105895;
    Tableau {
        s: 6,
        alpha: [0.0, 0.386, 0.21, 0.63, 1.0, 1.0],
        gamma: [0.25, -0.1043, 0.1035, -0.03620000000000023, 0.0, 0.0],
        a: [
            [0.0; 6],
            [1.544, 0.0, 0.0, 0.0, 0.0, 0.0],
            [0.9466785280815826, 0.2557011698983284, 0.0, 0.0, 0.0, 0.0],
            [3.314825187068521, 2.896124015972201, 0.9986419139977817, 0.0, 0.0, 0.0],
            [a7, a8, a9, a10, 0.0, 0.0],
            [a7, a8, a9, a10, 1.0, 0.0],
        ],
        c: [
            [0.0; 6],
            [-5.6688, 0.0, 0.0, 0.0, 0.0, 0.0],
            [-2.430093356833875, -0.2063599157091915, 0.0, 0.0, 0.0, 0.0],
            [-0.1073529058151375, -9.594562251023355, -20.47028614809616, 0.0, 0.0, 0.0],
            [7.496443313967647, -10.24680431464352, -33.99990352819905, 11.7089089320616, 0.0, 0.0],
            [8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136, -6.058818238834054, 0.0],
        ],
        m: [a7, a8, a9, a10, 1.0, 1.0],
        e: [0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        elo: 4.0,
    }
};

impl Tableau {
    /// The tableau of a method given as (α, Γ, b, b̂) with
    /// (I − hγ_ii·J)·k_i = h·f(y + Σ α_ij k_j) + h·J·Σ_{j<i} γ_ij k_j,
    /// y₁ = y + Σ b_j k_j (the Butcher-like form of Hairer & Wanner (7.4),
    /// as PETSc's TSRosW tables list them): a = α·Γ⁻¹, c = diag(1/γ) − Γ⁻¹,
    /// m = b·Γ⁻¹, e = (b − b̂)·Γ⁻¹ (Hairer & Wanner (7.17)).
    #[allow(clippy::needless_range_loop)] // triangular index arithmetic reads plainer with indices
    pub fn from_butcher<const S: usize>(alpha: [[f64; S]; S], gam: [[f64; S]; S], b: [f64; S], bh: [f64; S], elo: f64) -> Self {
        // Γ⁻¹ of the lower triangular Γ by forward substitution.
        let mut gi = [[0.0; S]; S];
        for j in 0..S {
            for i in j..S {
                let s: f64 = (j..i).map(|k| gam[i][k] * gi[k][j]).sum();
                gi[i][j] = (if i == j { 1.0 } else { 0.0 } - s) / gam[i][i];
            }
        }
        let mut t = Tableau { s: S, alpha: [0.0; S_MAX], gamma: [0.0; S_MAX], a: [[0.0; S_MAX]; S_MAX], c: [[0.0; S_MAX]; S_MAX], m: [0.0; S_MAX], e: [0.0; S_MAX], elo };
        for i in 0..S {
            t.alpha[i] = (0..i).map(|j| alpha[i][j]).sum();
            t.gamma[i] = (0..=i).map(|j| gam[i][j]).sum();
            for j in 0..i {
                t.a[i][j] = (0..S).map(|k| alpha[i][k] * gi[k][j]).sum();
                t.c[i][j] = -gi[i][j];
            }
            t.m[i] = (0..S).map(|k| b[k] * gi[k][i]).sum();
            t.e[i] = (0..S).map(|k| (b[k] - bh[k]) * gi[k][i]).sum();
        }
        t
    }

    /// ROS34PW2 (Rang & Angermann, BIT 45, 2005), coefficients as PETSc's
    /// TSROSWRA34PW2 lists them: 4 stages, order 3 (embedded 2) for any
    /// Jacobian approximation, L-stable, stiffly accurate.
    #[allow(clippy::excessive_precision)] // the coefficients as published, 17 digits
    pub fn ros34pw2() -> Self {
        let g = 4.3586652150845900e-01;
        let alpha = [
            [0.0, 0.0, 0.0, 0.0],
            [8.7173304301691801e-01, 0.0, 0.0, 0.0],
            [8.4457060015369423e-01, -1.1299064236484185e-01, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ];
        let gam = [
            [g, 0.0, 0.0, 0.0],
            [-8.7173304301691801e-01, g, 0.0, 0.0],
            [-9.0338057013044082e-01, 5.4180672388095326e-02, g, 0.0],
            [2.4212380706095346e-01, -1.2232505839045147e+00, 5.4526025533510214e-01, g],
        ];
        let b = [2.4212380706095346e-01, -1.2232505839045147e+00, 1.5452602553351020e+00, 4.3586652150845900e-01];
        let bh = [3.7810903145819369e-01, -9.6042292212423178e-02, 5.0000000000000000e-01, 2.1793326075422950e-01];
        Self::from_butcher(alpha, gam, b, bh, 3.0)
    }
}
