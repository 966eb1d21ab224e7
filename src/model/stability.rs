//! Checks of the discretisation a parameter block brings, run on the target at
//! init: the model's own Jacobian at the nominal point (central differences of
//! [`Model::derivative`]), `Phi` against it, and the stability of the linearised
//! step `M = I + Phi J` (a thermal network must not amplify a deviation).

use super::{ConfigError, Model, ModelInputN, HBAR_PER_BAR, HRADS_PER_RPM, N_PHI, N_STATES, S_PER_STEP};
use crate::params::PHI_STATES;
use crate::num::Num;

/// Nominal operating point of the Jacobian: 500 rpm, 30 bar across the pump
/// (port A 35 bar, B at the 5 bar case pressure), no piston motion, 20 degC air,
/// every node at [`NOMINAL_NODE_C`]. The reduction tool linearises here too.
pub fn nominal_input<N: Num>() -> ModelInputN<N> {
    ModelInputN {
        current_ha: N::ZERO,
        p_a_hbar: N::from_f32((35.0 * HBAR_PER_BAR) as f32),
        p_b_hbar: N::from_f32((5.0 * HBAR_PER_BAR) as f32),
        speed_hrads: N::from_f32((500.0 * HRADS_PER_RPM) as f32),
        dpos_mm: N::ZERO,
        ambient_c: N::from_f32(NOMINAL_AIR_C),
    }
}

/// Air temperature of the nominal point, degC.
pub const NOMINAL_AIR_C: f32 = 20.0;
/// Node temperature of the nominal point, degC.
pub const NOMINAL_NODE_C: f32 = 40.0;
/// Half-width of the on-target central differences, K: wide enough for the
/// fixed-point value resolution (2^-16 K/s on a rate), narrow against the
/// curvature of the outer convection (|dT|^(1/4) at 20 K).
const DT_K: f32 = 2.0;
/// Squarings of `M`: the check looks at `M^(2^10)`, 102.4 s of model steps.
const SQUARINGS: u32 = 10;
/// Largest allowed row sum of `|M^1024|`: a deviation may not grow by more than
/// 0.1 % over 102.4 s (an unstable mode with a growth rate above 1e-5/s fails);
/// the f32 squarings and the Jacobian's differences are good to about 1e-4.
const MAX_GAIN: f32 = 1.001;
/// Largest allowed `|Phi - h phi1(h J)|` per entry, s: above the differences'
/// own error in every number type (fixed point is the coarsest; measured in
/// docs/firmware.md, "Parameter block"), and below what a `Phi` computed for a
/// rig with one coupling 2e-5/s different shows (`h^2/2 · 2e-5/s` = 1e-7 s).
pub const PHI_TOL_S: f32 = 1e-7;

impl<N: Num> Model<N> {
    /// Jacobian of [`Model::derivative`] at the nominal point, 1/s (f32).
    pub fn nominal_jacobian_f32(&self) -> [[f32; N_PHI]; N_PHI] {
        let u = nominal_input::<N>();
        let mut j = [[0.0f32; N_PHI]; N_PHI];
        for col in 0..rolled(N_PHI) {
            let mut tp = [N::from_f32(NOMINAL_NODE_C); N_STATES];
            let mut tm = tp;
            let state = PHI_STATES.get(col).copied().unwrap_or(usize::MAX);
            if let (Some(p), Some(m)) = (tp.get_mut(state), tm.get_mut(state)) {
                *p = N::from_f32(NOMINAL_NODE_C + DT_K);
                *m = N::from_f32(NOMINAL_NODE_C - DT_K);
            }
            let fp = self.derivative(&tp, &u, false);
            let fm = self.derivative(&tm, &u, false);
            for row in 0..rolled(N_PHI) {
                let state = PHI_STATES.get(row).copied().unwrap_or(usize::MAX);
                let d = match (fp.get(state), fm.get(state)) {
                    (Some(a), Some(b)) => (a.to_f32() - b.to_f32()) / (2.0 * DT_K),
                    _ => f32::NAN,
                };
                set(&mut j, row, col, d);
            }
        }
        j
    }

    /// `Ok` when `phi` (the block's `Phi`, s) is `h phi1(h J)` of this model's
    /// own Jacobian `J` within [`PHI_TOL_S`] (series to `(hJ)^2`: `|hJ| < 0.01`
    /// here, the rest is below 1e-9 s) and the linearised step `M = I + Phi J`
    /// does not amplify (`max row sum |M^1024| <= 1.001`). Else
    /// [`ConfigError::Unstable`].
    #[inline(never)]
    pub fn check_stability(&self, phi: &[[f32; N_PHI]; N_PHI]) -> Result<(), ConfigError> {
        let j = self.nominal_jacobian_f32();
        // (a NaN fails both)
        if phi_mismatch_s(phi, &j) <= PHI_TOL_S && step_gain(phi, &j) <= MAX_GAIN {
            Ok(())
        } else {
            Err(ConfigError::Unstable)
        }
    }
}

/// Largest `|Phi - h phi1(h J)|` entry, s (what [`Model::check_stability`]
/// bounds by [`PHI_TOL_S`]); NaN if any entry is NaN.
pub fn phi_mismatch_s(phi: &[[f32; N_PHI]; N_PHI], j: &[[f32; N_PHI]; N_PHI]) -> f32 {
    let h = S_PER_STEP as f32;
    let j2 = mat_mul(j, j);
    let mut worst = 0.0f32;
    for r in 0..rolled(N_PHI) {
        for c in 0..rolled(N_PHI) {
            let eye = if r == c { 1.0 } else { 0.0 };
            let e = (at(phi, r, c) - h * (eye + h * at(j, r, c) * 0.5 + h * h * at(&j2, r, c) / 6.0)).abs();
            worst = nan_max(worst, e);
        }
    }
    worst
}

/// Largest row sum of `|M^1024|`, `M = I + Phi J`: the most a deviation can grow
/// over 1024 linearised model steps; NaN if any entry is NaN.
pub fn step_gain(phi: &[[f32; N_PHI]; N_PHI], j: &[[f32; N_PHI]; N_PHI]) -> f32 {
    let mut m = mat_mul(phi, j);
    for r in 0..rolled(N_PHI) {
        let d = at(&m, r, r) + 1.0;
        set(&mut m, r, r, d);
    }
    for _ in 0..SQUARINGS {
        m = mat_mul(&m, &m);
    }
    let mut gain = 0.0f32;
    for r in 0..rolled(N_PHI) {
        let mut sum = 0.0f32;
        for c in 0..rolled(N_PHI) {
            sum += at(&m, r, c).abs();
        }
        gain = nan_max(gain, sum);
    }
    gain
}

/// `max(a, b)` that keeps a NaN (`f32::max` would drop it).
fn nan_max(a: f32, b: f32) -> f32 {
    if b > a || b.is_nan() {
        b
    } else {
        a
    }
}

/// Trip count of the checks' loops, opaque to the optimiser: this code runs once
/// at init, so its loops stay rolled (about 2 KiB less flash than unrolled).
#[inline(always)]
fn rolled(n: usize) -> usize {
    core::hint::black_box(n)
}

/// `m[r][c]`, NaN outside the matrix (fails every check).
#[inline(always)]
fn at(m: &[[f32; N_PHI]; N_PHI], r: usize, c: usize) -> f32 {
    m.get(r).and_then(|row| row.get(c)).copied().unwrap_or(f32::NAN)
}

/// `m[r][c] = x` (nothing outside the matrix).
#[inline(always)]
fn set(m: &mut [[f32; N_PHI]; N_PHI], r: usize, c: usize, x: f32) {
    if let Some(e) = m.get_mut(r).and_then(|row| row.get_mut(c)) {
        *e = x;
    }
}

/// `a b` for 6×6 matrices.
#[inline(never)]
fn mat_mul(a: &[[f32; N_PHI]; N_PHI], b: &[[f32; N_PHI]; N_PHI]) -> [[f32; N_PHI]; N_PHI] {
    let mut o = [[0.0f32; N_PHI]; N_PHI];
    for r in 0..rolled(N_PHI) {
        for c in 0..rolled(N_PHI) {
            let mut s = 0.0f32;
            for k in 0..rolled(N_PHI) {
                s += at(a, r, k) * at(b, k, c);
            }
            set(&mut o, r, c, s);
        }
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::num::Fx;
    use crate::model::DEFAULT_CONSTS;
    extern crate std;
    use std::println;

    /// The compiled-in constants pass in every number type; the measured `Phi`
    /// mismatch (against the on-target Jacobian by ±2 K differences) and the
    /// step gain are printed for docs/firmware.md. The tolerance `PHI_TOL_S`
    /// must hold with a margin of at least 3× in every number type (the fixed-point
    /// differences are the coarsest).
    #[test]
    fn default_block_is_stable_in_every_number_type() {
        let phi = DEFAULT_CONSTS.phi;
        let m32 = Model::<f32>::for_linearisation(&DEFAULT_CONSTS).unwrap();
        let m64 = Model::<f64>::for_linearisation(&DEFAULT_CONSTS).unwrap();
        let mfx = Model::<Fx>::for_linearisation(&DEFAULT_CONSTS).unwrap();
        for (name, mis, gain) in [
            ("f32", phi_mismatch_s(&phi, &m32.nominal_jacobian_f32()), step_gain(&phi, &m32.nominal_jacobian_f32())),
            ("f64", phi_mismatch_s(&phi, &m64.nominal_jacobian_f32()), step_gain(&phi, &m64.nominal_jacobian_f32())),
            ("fx", phi_mismatch_s(&phi, &mfx.nominal_jacobian_f32()), step_gain(&phi, &mfx.nominal_jacobian_f32())),
        ] {
            println!("{name}: Phi mismatch {mis:e} s, gain |M^1024| {gain}");
            assert!(mis * 3.0 <= PHI_TOL_S, "{name}: mismatch {mis:e}");
            assert!(gain <= MAX_GAIN, "{name}: gain {gain}");
        }
        assert!(m32.check_stability(&phi).is_ok());
        assert!(mfx.check_stability(&phi).is_ok());
    }

    /// A block whose `Phi` belongs to another rig (the loop-oil/main-block
    /// conductance 1.5× the one `Phi` was computed for) is refused.
    #[test]
    fn phi_of_another_rig_is_refused() {
        let mut c = DEFAULT_CONSTS;
        for g in c.g_loop.iter_mut() {
            *g *= 1.5;
        }
        assert_eq!(Model::<f32>::from_consts(&c).err(), Some(ConfigError::Unstable));
        assert!(Model::<f32>::from_consts(&DEFAULT_CONSTS).is_ok());
    }

    /// The gain check sees growth: a node with a positive rate of 1e-4/s grows
    /// by e^(1024·0.1·1e-4) = 1.0103 over 1024 steps (> 1.001), while the
    /// default's decaying Jacobian stays at or below 1.
    #[test]
    fn gain_check_sees_an_unstable_step() {
        let h = S_PER_STEP as f32;
        let mut phi = [[0.0f32; N_PHI]; N_PHI];
        let mut j = [[0.0f32; N_PHI]; N_PHI];
        for i in 0..N_PHI {
            phi[i][i] = h;
            j[i][i] = -1e-4;
        }
        assert!(step_gain(&phi, &j) <= 1.0);
        j[2][2] = 1e-4;
        let g = step_gain(&phi, &j);
        assert!((g - 1.0103).abs() < 1e-3, "{g}");
        assert!(g > MAX_GAIN);
    }
}
