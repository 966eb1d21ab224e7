//! Fixed-point instantiation of [`Num`] (feature `fixed-point` builds use it as the
//! firmware number type; host tests use it always). Formats are named once here.

use super::Num;
use fixed::types::{I2F30, I9F23, I9F55};

/// Fixed-point model value: Q9.23 in an `i32` (`I9F23`): range [-256, 256),
/// resolution 2^-23 ≈ 1.19e-7. Used for temperatures (degC / K), powers (kW),
/// current (hA), pressure (hbar), speed (hrad/s), position (mm).
pub type Fx = I9F23;
/// Fixed-point coefficient of the model step's exact-ZOH matrix `Phi` (seconds,
/// h = 0.1 s): Q2.30 in an `i32` (`I2F30`): range [-2, 2), resolution 2^-30 ≈
/// 9.3e-10. The largest entries are the diagonal, ≈ h = 0.1 s: 20× headroom. With
/// the default parameters the direct couplings (≥ 1e-6 s) are resolved to < 4e-4
/// relative, the weakest one (≈ 1.1e-8 s, pump → ball-valve block) to ≈ 4 %; the
/// second-order entries between nodes without a direct link (< 1.3e-9 s) round to
/// 0 or 1 LSB.
pub type FxCoef = I2F30;
/// Fixed-point state accumulator: Q9.55 in an `i64` (`I9F55`): range [-256, 256) K,
/// resolution 2^-55 ≈ 2.8e-17 K; `coef × value` (Q2.30 × Q9.23 = Q.53) is shifted
/// left by 2 onto it exactly (saturating).
pub type FxState = I9F55;
/// Tick accumulator of a Q9.23 value: the sum of the raw bits in an `i64` (at most
/// `TICKS_PER_STEP` × 2^31, no overflow).
pub type FxAcc = i64;

/// `2^28 / TICKS_PER_STEP`, rounded: the mean of an [`FxAcc`] is `(a · INV) >> 28`
/// (|a| ≤ M 2^31, so |a · INV| ≤ 2^59.1: no overflow; relative error ≤ 2e-8 for M = 10).
const INV_TICKS_Q28: i64 =
    ((1i64 << 28) + crate::params::TICKS_PER_STEP as i64 / 2) / crate::params::TICKS_PER_STEP as i64;
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
/// Rounds half up; saturates at the Q9.23 range; NaN gives `nan`, ±inf saturates.
#[inline(always)]
fn f32_times_q30_to_q23(x: f32, s_raw: i32, nan: i32) -> i32 {
    let b = x.to_bits();
    let e = ((b >> 23) & 0xff) as i32;
    let frac = b & 0x007f_ffff;
    if e == 0xff {
        if frac != 0 {
            return nan;
        }
        return if (b >> 31 != 0) == (s_raw < 0) {
            i32::MAX
        } else {
            i32::MIN
        };
    }
    let m = if e == 0 { frac } else { frac | 0x0080_0000 } as i64;
    let p = m * s_raw as i64; // |p| < 2^24 · 2^31
    let sh = e - 157;
    let mag = if sh >= 0 {
        if sh > 8 || p.unsigned_abs() >= (1u64 << (62 - sh)) {
            if p < 0 {
                i64::MIN
            } else {
                i64::MAX
            }
        } else {
            p << sh
        }
    } else if sh > -63 {
        (p + (1i64 << (-sh - 1))) >> -sh
    } else {
        0
    };
    let v = if b >> 31 != 0 {
        mag.saturating_neg()
    } else {
        mag
    };
    sat_i32(v)
}

/// Integer square root `floor(sqrt(n))` by Newton's method from a power-of-two guess
/// above the root (monotone decreasing, ≤ 6 iterations for 32-bit `n`).
#[inline(always)]
fn isqrt_u32(n: u32) -> u32 {
    let bits = 32 - n.leading_zeros();
    let mut x = 1u32 << bits.div_ceil(2).min(16);
    loop {
        let Some(nz) = core::num::NonZeroU32::new(x) else {
            return 0;
        };
        let y = (x + n / nz) >> 1;
        if y >= x {
            return x;
        }
        x = y;
    }
}

// SAFETY: the fixed-point types are plain integers: zero bits are 0.
unsafe impl Num for Fx {
    type Coef = FxCoef;
    type State = FxState;
    type Dot = i64;
    type Scale = FxScale;
    type Acc = FxAcc;
    const ZERO: Self = Fx::ZERO;
    const ACC_ZERO: FxAcc = 0;
    /// Σ|c| < 3.9 keeps `Σ c_bits v_bits` (< 3.9 · 2^30 · 2^31 plus rounding) inside `i64`.
    const MAX_ROW_SUM: f64 = 3.9;
    const FLOAT: bool = false;
    fn from_f64(x: f64) -> Self {
        // checked (NaN → None) instead of saturating_from_num, which panics on NaN.
        Fx::checked_from_num(x).unwrap_or(if x > 0.0 {
            Fx::MAX
        } else if x < 0.0 {
            Fx::MIN
        } else {
            Fx::ZERO
        })
    }
    fn coef_from_f64(x: f64) -> Option<FxCoef> {
        FxCoef::checked_from_num(x)
    }
    fn from_f32(x: f32) -> Self {
        // exact widening: the same value, the same saturation rule
        Self::from_f64(f64::from(x))
    }
    fn from_exact(_x32: f32, x64: f64) -> Self {
        Self::from_f64(x64)
    }
    fn coef_from_f32(x: f32) -> Option<FxCoef> {
        FxCoef::checked_from_num(x)
    }
    fn scale_from_f64(x: f64) -> Option<FxScale> {
        FxScale::checked_from_num(x)
    }
    #[inline(always)]
    fn from_f32_scaled(x: f32, s: FxScale) -> Self {
        Fx::from_bits(f32_times_q30_to_q23(x, s.to_bits(), 0))
    }
    #[inline(always)]
    fn from_sample(x: f32, s: FxScale) -> Self {
        // NaN → the format minimum (below every range limit, |limit| < 250); ±inf
        // saturates to MAX/MIN (outside every range too). Integer-only.
        Fx::from_bits(f32_times_q30_to_q23(x, s.to_bits(), i32::MIN))
    }
    #[inline(always)]
    fn acc(a: FxAcc, x: Self) -> FxAcc {
        a.wrapping_add(x.to_bits() as i64)
    }
    #[inline(always)]
    fn acc_mean(a: FxAcc) -> Self {
        let m = a.wrapping_mul(INV_TICKS_Q28);
        Fx::from_bits(sat_i32((m + (1 << 27)) >> 28))
    }
    fn to_f32(self) -> f32 {
        self.to_num::<f32>()
    }
    fn to_f64(self) -> f64 {
        self.to_num::<f64>()
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self.saturating_add(o)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self.saturating_sub(o)
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let p = self.to_bits() as i64 * o.to_bits() as i64;
        Fx::from_bits(sat_i32((p + (1 << 22)) >> 23))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.saturating_abs()
    }
    #[inline(always)]
    fn max0(self) -> Self {
        if self > Fx::ZERO {
            self
        } else {
            Fx::ZERO
        }
    }
    #[inline(always)]
    fn sqrt_abs(self) -> Self {
        // sqrt(v 2^-23) 2^23 = sqrt(v 2^23): normalise v << s (s odd, so 23 - s is even)
        // into 32 bits, take a 16-bit integer root with hardware udiv, shift back.
        // Relative error ≤ 2^-15 for |x| ≥ 2^-15 (vs ~340 instructions for fixed's
        // bit-by-bit `sqrt`).
        let v = self.to_bits().unsigned_abs();
        if v == 0 {
            return Fx::ZERO;
        }
        let lz = v.leading_zeros() as i32;
        let s = if lz % 2 == 1 { lz } else { lz - 1 };
        let n = if s >= 0 { v << s } else { v >> 1 };
        let r = isqrt_u32(n);
        let e = (23 - s) / 2;
        let out = if e >= 0 { r << e } else { r >> -e };
        Fx::from_bits(out as i32)
    }
    fn div_pos(self, d: Self) -> Self {
        if d > Fx::ZERO {
            self.checked_div(d).unwrap_or(Fx::MAX)
        } else {
            Fx::ZERO
        }
    }
    fn exp(self) -> Self {
        Fx::from_bits(f32_times_q30_to_q23(
            libm::expf(self.to_num::<f32>()),
            1 << 30,
            0,
        ))
    }
    fn state(x: Self) -> FxState {
        FxState::from_bits((x.to_bits() as i64) << 32)
    }
    #[inline(always)]
    fn value(s: FxState) -> Self {
        // Round to nearest Q9.23 (add half an LSB before taking the high word).
        let b = s.to_bits();
        Fx::from_bits(sat_i32(b.saturating_add(1 << 31) >> 32))
    }
    #[inline(always)]
    fn dot<const K: usize>(c: &[FxCoef; K], v: &[Self; K]) -> i64 {
        // Σ|c| < MAX_ROW_SUM is checked at init, so |Σ c v| (Q.53) < 2^63: no i64
        // overflow; then Q.53 → Q.55 by a saturating shift.
        let d = c.iter().zip(v.iter()).fold(0i64, |a, (c, v)| {
            a.wrapping_add(c.to_bits() as i64 * v.to_bits() as i64)
        });
        if d > (i64::MAX >> 2) {
            i64::MAX
        } else if d < (i64::MIN >> 2) {
            i64::MIN
        } else {
            d << 2
        }
    }
    #[inline(always)]
    fn dot_value(d: i64) -> Self {
        Fx::from_bits(sat_i32(d.saturating_add(1 << 31) >> 32))
    }
    #[inline(always)]
    fn apply<const M: usize>(s: FxState, d: i64, a: &[Self; M], b: &[Self; M]) -> FxState {
        let s = FxState::from_bits(s.to_bits().saturating_add(d));
        a.iter()
            .zip(b.iter())
            .fold(s, |s, (a, b)| Self::add_product(s, *a, *b))
    }
    #[inline(always)]
    fn add_product(s: FxState, a: Self, b: Self) -> FxState {
        // Q9.23 × Q9.23 = Q18.46; shift left 9 to Q.55 (saturating).
        let p = a.to_bits() as i64 * b.to_bits() as i64;
        let p55 = p.saturating_mul(1 << 9);
        FxState::from_bits(s.to_bits().saturating_add(p55))
    }
    #[inline(always)]
    fn round_times(self, k: i32) -> i32 {
        let p = self.to_bits() as i64 * k as i64;
        sat_i32((p + (1 << 22)) >> 23)
    }
    #[inline(always)]
    fn split_floor(self) -> (i32, Self) {
        let b = self.to_bits();
        if b < 0 {
            (0, Fx::ZERO)
        } else {
            (b >> 23, Fx::from_bits(b & 0x007f_ffff))
        }
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
        // 1e5 increments of ≈ 1e-8 K (below the Q9.23 LSB 1.19e-7) must add up to
        // 1e5 times the coefficient (1e-8 is 10.7 Q2.30 LSBs: 11 LSBs = 1.02e-8).
        let mut s = Fx::state(Fx::from_f64(40.0));
        let c = [FxCoef::from_num(1e-8)];
        let expect = 1e5 * c[0].to_num::<f64>();
        assert!((expect - 1e-3).abs() < 5e-5, "{expect}");
        let v = [Fx::from_f64(1.0)];
        for _ in 0..100_000 {
            s = Fx::accumulate(s, &c, &v);
        }
        let got = Fx::value(s).to_f64() - 40.0;
        assert!((got - expect).abs() < 1e-6, "{got} vs {expect}");
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
                    let exact = (xv as f64 * sq * 8_388_608.0)
                        .round()
                        .clamp(i32::MIN as f64, i32::MAX as f64)
                        as i64;
                    assert!((got - exact).abs() <= 1, "x {xv} s {sc}: {got} vs {exact}");
                }
                x *= 3.7;
            }
        }
        let one = Fx::scale_from_f64(1.0).unwrap();
        assert_eq!(Fx::from_f32_scaled(f32::NAN, one), Fx::ZERO);
        // Validation's conversion: NaN below every range limit, the rest as above.
        assert_eq!(Fx::from_sample(f32::NAN, one), Fx::MIN);
        assert_eq!(Fx::from_sample(-f32::NAN, one), Fx::MIN);
        assert_eq!(Fx::from_sample(f32::INFINITY, one), Fx::MAX);
        assert_eq!(Fx::from_sample(12.5, one), Fx::from_f32_scaled(12.5, one));
        assert_eq!(Fx::from_f32_scaled(f32::INFINITY, one), Fx::MAX);
        assert_eq!(Fx::from_f32_scaled(f32::NEG_INFINITY, one), Fx::MIN);
        assert_eq!(Fx::from_f32_scaled(1e30, one), Fx::MAX);
        assert_eq!(Fx::from_f32_scaled(0.0, one), Fx::ZERO);
    }

    #[test]
    fn fixed_sqrt_relative_error() {
        // 2^-15 relative (16-bit integer root) for |x| in [1e-3, 255]; exact at 0.
        let mut x = 1e-3f64;
        while x < 255.0 {
            let r = Fx::from_f64(x).sqrt_abs().to_f64();
            let e = libm::sqrt(Fx::from_f64(x).to_f64());
            assert!(((r - e) / e).abs() < 3.1e-5, "sqrt({x}) = {r} vs {e}");
            let rn = Fx::from_f64(-x).sqrt_abs().to_f64();
            assert_eq!(rn, r);
            x *= 1.13;
        }
        assert_eq!(Fx::ZERO.sqrt_abs(), Fx::ZERO);
        assert!((Fx::MIN.sqrt_abs().to_f64() - 16.0).abs() < 1e-3);
        for n in [0u32, 1, 2, 3, 4, 15, 16, 17, 65535, 65536, u32::MAX] {
            let r = isqrt_u32(n) as u64;
            assert!(
                r * r <= n as u64 && (r + 1) * (r + 1) > n as u64,
                "isqrt({n}) = {r}"
            );
        }
    }

    #[test]
    fn fixed_saturates_instead_of_wrapping() {
        let big = Fx::from_f64(200.0);
        assert!(big.mul(big) > Fx::from_f64(255.0));
        assert!(Fx::from_f64(-200.0).mul(big) < Fx::from_f64(-255.0));
    }
}
