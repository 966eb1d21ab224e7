//! Number types of the model: one generic code path, three instantiations.
//!
//! * `f64` — design/reference instantiation for host tests.
//! * `f32` (libm) — Cortex-M4F build. The state is a compensated pair
//!   ([`F32State`]): per-step increments of slow nodes are ~1e-5 K, only a few
//!   f32 ulps at 40 degC (ulp 3.8e-6 K); a plain f32 state would stagnate up to
//!   ~0.2 K away from equilibrium (|dx| < ulp/2 with time constants of 1e5 steps).
//! * [`Fx`] (`fixed` crate) — FPU-less Cortex-M3 build (feature `fixed-point`).
//!
//! Model units are chosen so that every quantity is O(1..100) and fits the
//! fixed-point range: temperature degC (or K), power kW, current hA (100 A),
//! pressure hbar (10 MPa), speed hrad/s (100 rad/s), position mm.

use fixed::types::{I0F32, I2F30, I9F23, I9F55};

/// Arithmetic the model needs from its number type. All methods are total
/// (no panics): the fixed-point instantiation saturates at its documented range.
pub trait Num: Copy + PartialOrd + core::fmt::Debug {
    /// Discretised matrix coefficient type (entries of `Ad - I` and `Bd`).
    type Coef: Copy + core::fmt::Debug;
    /// High-precision state accumulator type.
    type State: Copy + core::fmt::Debug;
    /// Input scale factor type (wire unit → model unit).
    type Scale: Copy + core::fmt::Debug;
    /// Zero.
    const ZERO: Self;
    /// Largest allowed Σ|coefficient| of one discretised row (fixed point: keeps the
    /// `i64` accumulation free of overflow; floating point: unbounded).
    const MAX_ROW_SUM: f64;
    /// Conversion at init (saturating for fixed point).
    fn from_f64(x: f64) -> Self;
    /// Coefficient conversion at init; `None` when `x` is outside the coefficient range.
    fn coef_from_f64(x: f64) -> Option<Self::Coef>;
    /// Scale conversion at init; `None` when outside the scale range.
    fn scale_from_f64(x: f64) -> Option<Self::Scale>;
    /// Wire value (finite, validated) times scale → model unit. Saturating.
    fn from_f32_scaled(x: f32, s: Self::Scale) -> Self;
    /// To `f32` (wire units for outputs).
    fn to_f32(self) -> f32;
    /// To `f64` (tests, diagnostics).
    fn to_f64(self) -> f64;
    /// Sum (saturating for fixed point).
    fn add(self, o: Self) -> Self;
    /// Difference (saturating for fixed point).
    fn sub(self, o: Self) -> Self;
    /// Product (saturating for fixed point).
    fn mul(self, o: Self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `max(self, 0)`.
    fn max0(self) -> Self;
    /// Square root of `|self|`.
    fn sqrt_abs(self) -> Self;
    /// `exp(self)` (only used when the viscosity exponent is non-zero).
    fn exp(self) -> Self;
    /// State accumulator holding `x`.
    fn state(x: Self) -> Self::State;
    /// Present value of a state accumulator.
    fn value(s: Self::State) -> Self;
    /// `s + Σ c_k v_k`: the discretised state update row.
    fn accumulate<const K: usize>(s: Self::State, c: &[Self::Coef; K], v: &[Self; K]) -> Self::State;
    /// `s + a b` at full accumulator precision.
    fn add_product(s: Self::State, a: Self, b: Self) -> Self::State;
}

impl Num for f64 {
    type Coef = f64;
    type State = f64;
    type Scale = f64;
    const ZERO: Self = 0.0;
    const MAX_ROW_SUM: f64 = f64::INFINITY;
    fn from_f64(x: f64) -> Self { x }
    fn coef_from_f64(x: f64) -> Option<f64> { x.is_finite().then_some(x) }
    fn scale_from_f64(x: f64) -> Option<f64> { x.is_finite().then_some(x) }
    fn from_f32_scaled(x: f32, s: f64) -> Self { x as f64 * s }
    fn to_f32(self) -> f32 { self as f32 }
    fn to_f64(self) -> f64 { self }
    fn add(self, o: Self) -> Self { self + o }
    fn sub(self, o: Self) -> Self { self - o }
    fn mul(self, o: Self) -> Self { self * o }
    fn abs(self) -> Self { libm::fabs(self) }
    fn max0(self) -> Self { if self > 0.0 { self } else { 0.0 } }
    fn sqrt_abs(self) -> Self { libm::sqrt(libm::fabs(self)) }
    fn exp(self) -> Self { libm::exp(self) }
    fn state(x: Self) -> f64 { x }
    fn value(s: f64) -> Self { s }
    fn accumulate<const K: usize>(s: f64, c: &[f64; K], v: &[f64; K]) -> f64 {
        s + c.iter().zip(v.iter()).fold(0.0, |a, (c, v)| a + c * v)
    }
    fn add_product(s: f64, a: f64, b: f64) -> f64 { s + a * b }
}

/// Compensated `f32` state: value `hi` plus the rounding residue `lo` (|lo| <= ulp(hi)/2).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct F32State {
    /// Rounded value, degC.
    pub hi: f32,
    /// Residue not yet representable in `hi`, K.
    pub lo: f32,
}

#[inline(always)]
fn two_sum(s: F32State, d: f32) -> F32State {
    let y = d + s.lo;
    let t = s.hi + y;
    F32State { hi: t, lo: y - (t - s.hi) }
}

/// Square root of a non-negative finite `f32` without libm's bit-by-bit routine:
/// reciprocal square root by the 0x5f375a86 seed and three Newton steps (relative
/// error < 2e-7, i.e. at f32 rounding; ~15 FPU instructions), times `x`. `sqrt(0) = 0`.
#[inline(always)]
fn sqrt_f32(x: f32) -> f32 {
    let mut y = f32::from_bits(0x5f37_5a86u32.wrapping_sub(x.to_bits() >> 1));
    let h = 0.5 * x;
    y *= 1.5 - h * y * y;
    y *= 1.5 - h * y * y;
    y *= 1.5 - h * y * y;
    x * y
}

impl Num for f32 {
    type Coef = f32;
    type State = F32State;
    type Scale = f32;
    const ZERO: Self = 0.0;
    const MAX_ROW_SUM: f64 = f64::INFINITY;
    fn from_f64(x: f64) -> Self { x as f32 }
    fn coef_from_f64(x: f64) -> Option<f32> { x.is_finite().then_some(x as f32) }
    fn scale_from_f64(x: f64) -> Option<f32> { x.is_finite().then_some(x as f32) }
    #[inline(always)]
    fn from_f32_scaled(x: f32, s: f32) -> Self { x * s }
    fn to_f32(self) -> f32 { self }
    fn to_f64(self) -> f64 { self as f64 }
    #[inline(always)]
    fn add(self, o: Self) -> Self { self + o }
    #[inline(always)]
    fn sub(self, o: Self) -> Self { self - o }
    #[inline(always)]
    fn mul(self, o: Self) -> Self { self * o }
    #[inline(always)]
    fn abs(self) -> Self { libm::fabsf(self) }
    #[inline(always)]
    fn max0(self) -> Self { if self > 0.0 { self } else { 0.0 } }
    #[inline(always)]
    fn sqrt_abs(self) -> Self { sqrt_f32(libm::fabsf(self)) }
    fn exp(self) -> Self { libm::expf(self) }
    fn state(x: Self) -> F32State { F32State { hi: x, lo: 0.0 } }
    #[inline(always)]
    fn value(s: F32State) -> Self { s.hi }
    #[inline(always)]
    fn accumulate<const K: usize>(s: F32State, c: &[f32; K], v: &[f32; K]) -> F32State {
        let d = c.iter().zip(v.iter()).fold(0.0f32, |a, (c, v)| a + c * v);
        two_sum(s, d)
    }
    #[inline(always)]
    fn add_product(s: F32State, a: f32, b: f32) -> F32State { two_sum(s, a * b) }
}

/// Fixed-point model value: Q9.23 in an `i32` (`I9F23`): range [-256, 256),
/// resolution 2^-23 ≈ 1.19e-7. Used for temperatures (degC / K), powers (kW),
/// current (hA), pressure (hbar), speed (hrad/s), position (mm).
pub type Fx = I9F23;
/// Fixed-point coefficient of `Ad - I` and `Bd`: Q0.32 in an `i32` (`I0F32`):
/// range [-0.5, 0.5), resolution 2^-32 ≈ 2.3e-10 (relative 5e-5 on a 5e-6 entry).
pub type FxCoef = I0F32;
/// Fixed-point state accumulator: Q9.55 in an `i64` (`I9F55`): range [-256, 256) K,
/// resolution 2^-55 ≈ 2.8e-17 K; `coef × value` (Q0.32 × Q9.23) lands on it exactly.
pub type FxState = I9F55;
/// Fixed-point input scale: Q2.30 in an `i32` (`I2F30`): range [-2, 2), resolution 9.3e-10.
pub type FxScale = I2F30;

#[inline(always)]
fn sat_i32(x: i64) -> i32 {
    if x > i32::MAX as i64 {
        i32::MAX
    } else if x < i32::MIN as i64 {
        i32::MIN
    } else {
        x as i32
    }
}

/// `x · s` with `x` an `f32` and `s` a Q2.30 scale, to Q9.23 bits, integer-only
/// (no soft-float, no panic): `x = ±m 2^(e-150)`, so `x s 2^23 = ±m s 2^(e-157)`.
/// Rounds half up; saturates at the Q9.23 range; NaN gives 0, ±inf saturates.
#[inline(always)]
fn f32_times_q30_to_q23(x: f32, s_raw: i32) -> i32 {
    let b = x.to_bits();
    let e = ((b >> 23) & 0xff) as i32;
    let frac = b & 0x007f_ffff;
    if e == 0xff {
        if frac != 0 {
            return 0;
        }
        return if (b >> 31 != 0) == (s_raw < 0) { i32::MAX } else { i32::MIN };
    }
    let m = if e == 0 { frac } else { frac | 0x0080_0000 } as i64;
    let p = m * s_raw as i64; // |p| < 2^24 · 2^31
    let sh = e - 157;
    let mag = if sh >= 0 {
        if sh > 8 || p.unsigned_abs() >= (1u64 << (62 - sh)) {
            if p < 0 { i64::MIN } else { i64::MAX }
        } else {
            p << sh
        }
    } else if sh > -63 {
        (p + (1i64 << (-sh - 1))) >> -sh
    } else {
        0
    };
    let v = if b >> 31 != 0 { mag.saturating_neg() } else { mag };
    sat_i32(v)
}

impl Num for Fx {
    type Coef = FxCoef;
    type State = FxState;
    type Scale = FxScale;
    const ZERO: Self = Fx::ZERO;
    const MAX_ROW_SUM: f64 = 1.0;
    fn from_f64(x: f64) -> Self {
        // checked (NaN → None) instead of saturating_from_num, which panics on NaN.
        Fx::checked_from_num(x).unwrap_or(if x > 0.0 { Fx::MAX } else if x < 0.0 { Fx::MIN } else { Fx::ZERO })
    }
    fn coef_from_f64(x: f64) -> Option<FxCoef> { FxCoef::checked_from_num(x) }
    fn scale_from_f64(x: f64) -> Option<FxScale> { FxScale::checked_from_num(x) }
    #[inline(always)]
    fn from_f32_scaled(x: f32, s: FxScale) -> Self {
        Fx::from_bits(f32_times_q30_to_q23(x, s.to_bits()))
    }
    fn to_f32(self) -> f32 { self.to_num::<f32>() }
    fn to_f64(self) -> f64 { self.to_num::<f64>() }
    #[inline(always)]
    fn add(self, o: Self) -> Self { self.saturating_add(o) }
    #[inline(always)]
    fn sub(self, o: Self) -> Self { self.saturating_sub(o) }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let p = self.to_bits() as i64 * o.to_bits() as i64;
        Fx::from_bits(sat_i32((p + (1 << 22)) >> 23))
    }
    #[inline(always)]
    fn abs(self) -> Self { self.saturating_abs() }
    #[inline(always)]
    fn max0(self) -> Self { if self > Fx::ZERO { self } else { Fx::ZERO } }
    fn sqrt_abs(self) -> Self { self.saturating_abs().checked_sqrt().unwrap_or(Fx::ZERO) }
    fn exp(self) -> Self { Fx::from_bits(f32_times_q30_to_q23(libm::expf(self.to_num::<f32>()), 1 << 30)) }
    fn state(x: Self) -> FxState { FxState::from_bits((x.to_bits() as i64) << 32) }
    #[inline(always)]
    fn value(s: FxState) -> Self {
        // Round to nearest Q9.23 (add half an LSB before taking the high word).
        let b = s.to_bits();
        Fx::from_bits(sat_i32(b.saturating_add(1 << 31) >> 32))
    }
    #[inline(always)]
    fn accumulate<const K: usize>(s: FxState, c: &[FxCoef; K], v: &[Self; K]) -> FxState {
        // |Σ c| < 0.5 is checked at init, so |Σ c v| < 2^31 · 2^31: no i64 overflow.
        let d = c
            .iter()
            .zip(v.iter())
            .fold(0i64, |a, (c, v)| a.wrapping_add(c.to_bits() as i64 * v.to_bits() as i64));
        FxState::from_bits(s.to_bits().saturating_add(d))
    }
    #[inline(always)]
    fn add_product(s: FxState, a: Self, b: Self) -> FxState {
        // Q9.23 × Q9.23 = Q18.46; shift left 9 to Q.55 (saturating).
        let p = a.to_bits() as i64 * b.to_bits() as i64;
        let p55 = p.saturating_mul(1 << 9);
        FxState::from_bits(s.to_bits().saturating_add(p55))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_scaled_input_resolution() {
        // 340.5 A → 3.405 hA: error bounded by Q20.12 (2.4e-4 A → 2.4e-6 hA) + Q2.30 scale.
        let s = Fx::scale_from_f64(0.01).unwrap();
        let x = Fx::from_f32_scaled(340.5, s).to_f64();
        assert!((x - 3.405).abs() < 5e-6, "{x}");
        // 6000 rpm → 6.2832 hrad/s with scale 2 pi / 6000.
        let s = Fx::scale_from_f64(2.0 * core::f64::consts::PI / 6000.0).unwrap();
        let w = Fx::from_f32_scaled(6000.0, s).to_f64();
        assert!((w - 2.0 * core::f64::consts::PI).abs() < 1e-5, "{w}");
    }

    #[test]
    fn fixed_state_keeps_sub_lsb_increments() {
        // 1e5 increments of 1e-8 K (below the Q9.23 LSB 1.19e-7) must add up to 1e-3 K.
        let mut s = Fx::state(Fx::from_f64(40.0));
        let c = [FxCoef::from_num(1e-8)];
        let v = [Fx::from_f64(1.0)];
        for _ in 0..100_000 {
            s = Fx::accumulate(s, &c, &v);
        }
        let got = Fx::value(s).to_f64() - 40.0;
        assert!((got - 1e-3).abs() < 1e-5, "{got}");
    }

    #[test]
    fn f32_state_keeps_sub_ulp_increments() {
        // 1e5 increments of 1e-6 K at 40 degC (ulp 3.8e-6) must add up to 0.1 K.
        let mut s = f32::state(40.0);
        for _ in 0..100_000 {
            s = f32::accumulate(s, &[1e-6f32], &[1.0f32]);
        }
        let got = f32::value(s) as f64 - 40.0;
        assert!((got - 0.1).abs() < 1e-5, "{got}");
    }

    #[test]
    fn fast_sqrt_matches_libm() {
        // 1e-6 .. 1e4 covers |w| in hrad/s; 3e-7 relative is ~2 f32 ulps.
        let mut x = 1e-6f32;
        while x < 1e4 {
            let r = f32::sqrt_abs(x) as f64;
            let e = libm::sqrt(x as f64);
            assert!(((r - e) / e).abs() < 3e-7, "sqrt({x}) = {r} vs {e}");
            x *= 1.37;
        }
        assert_eq!(f32::sqrt_abs(0.0), 0.0);
    }

    #[test]
    fn fixed_input_conversion_matches_f64_and_saturates() {
        // Against f64 rounding of x·s to Q9.23 over many magnitudes and both signs:
        // the scale itself is Q2.30 (error ≤ 4.7e-10 relative to 1), so allow 1 LSB + that.
        for &sc in &[0.01f64, 1.0, 1.047e-3, -0.5, 1.9] {
            let s = Fx::scale_from_f64(sc).unwrap();
            let sq = s.to_num::<f64>();
            let mut x = 1e-9f32;
            while x < 1e7 {
                for &xv in &[x, -x] {
                    let got = Fx::from_f32_scaled(xv, s).to_bits() as i64;
                    let exact = (xv as f64 * sq * 8_388_608.0).round().clamp(i32::MIN as f64, i32::MAX as f64) as i64;
                    assert!((got - exact).abs() <= 1, "x {xv} s {sc}: {got} vs {exact}");
                }
                x *= 3.7;
            }
        }
        let one = Fx::scale_from_f64(1.0).unwrap();
        assert_eq!(Fx::from_f32_scaled(f32::NAN, one), Fx::ZERO);
        assert_eq!(Fx::from_f32_scaled(f32::INFINITY, one), Fx::MAX);
        assert_eq!(Fx::from_f32_scaled(f32::NEG_INFINITY, one), Fx::MIN);
        assert_eq!(Fx::from_f32_scaled(1e30, one), Fx::MAX);
        assert_eq!(Fx::from_f32_scaled(0.0, one), Fx::ZERO);
    }

    #[test]
    fn fixed_saturates_instead_of_wrapping() {
        let big = Fx::from_f64(200.0);
        assert!(big.mul(big) > Fx::from_f64(255.0));
        assert!(Fx::from_f64(-200.0).mul(big) < Fx::from_f64(-255.0));
    }
}
