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

mod fx;
pub use fx::{Fx, FxCoef, FxScale, FxState};

/// Arithmetic the model needs from its number type. All methods are total
/// (no panics): the fixed-point instantiation saturates at its documented range.
///
/// # Safety
/// The all-zero bit pattern must be a valid value of `Self` and of its
/// associated types (`Coef`, `State`, `Scale`): the guard's core is built in
/// place over zeroed memory (`GuardOf::new_in`). True for `f32`, `f64` and
/// the fixed-point types here (plain numbers).
pub unsafe trait Num: Copy + PartialOrd + core::fmt::Debug {
    /// Discretised matrix coefficient type (entries of the exact-ZOH matrix `Phi`).
    type Coef: Copy + core::fmt::Debug;
    /// High-precision state accumulator type.
    type State: Copy + core::fmt::Debug;
    /// Un-rounded row increment `Σ c v` (floating point: the value type; fixed
    /// point: the state's Q9.55 in an `i64`).
    type Dot: Copy + core::fmt::Debug;
    /// Input scale factor type (wire unit → model unit).
    type Scale: Copy + core::fmt::Debug;
    /// Tick accumulator of a model value (sum over the ticks of one model step
    /// without overflow: floating point, or a wider integer for fixed point).
    type Acc: Copy + core::fmt::Debug;
    /// Zero.
    const ZERO: Self;
    /// Empty tick accumulator.
    const ACC_ZERO: Self::Acc;
    /// Largest allowed Σ|coefficient| of one discretised row (fixed point: keeps the
    /// `i64` accumulation free of overflow; floating point: unbounded).
    const MAX_ROW_SUM: f64;
    /// Floating point (`f32`, `f64`); `false`: fixed point.
    const FLOAT: bool;
    /// Conversion at init (saturating for fixed point).
    fn from_f64(x: f64) -> Self;
    /// Coefficient conversion at init; `None` when `x` is outside the coefficient range.
    fn coef_from_f64(x: f64) -> Option<Self::Coef>;
    /// Conversion of a parameter-block word (saturating for fixed point; no `f64`).
    fn from_f32(x: f32) -> Self;
    /// A constant of the model's structure given in both precisions (`x32` is
    /// `x64` rounded): each type takes the one it can hold without `f64`
    /// arithmetic on an FPU-single target (`f32` takes `x32`).
    fn from_exact(x32: f32, x64: f64) -> Self;
    /// Coefficient conversion of a parameter-block word; `None` outside the range.
    fn coef_from_f32(x: f32) -> Option<Self::Coef>;
    /// Scale conversion at init; `None` when outside the scale range.
    fn scale_from_f64(x: f64) -> Option<Self::Scale>;
    /// Wire value (finite, validated) times scale → model unit. Saturating.
    fn from_f32_scaled(x: f32, s: Self::Scale) -> Self;
    /// [`Num::from_f32_scaled`] for validation: a non-finite `x` gives a value that
    /// fails every range check (NaN or ±inf for floating point; for fixed point NaN
    /// gives the format's minimum, ±inf saturates), so that one combined range test
    /// catches non-finite samples too (`validate::convert_check`).
    fn from_sample(x: f32, s: Self::Scale) -> Self;
    /// `a + x`: adds one tick's value to an accumulator.
    fn acc(a: Self::Acc, x: Self) -> Self::Acc;
    /// The mean of [`crate::params::TICKS_PER_STEP`] accumulated ticks, `a / M`
    /// (saturating for fixed point).
    fn acc_mean(a: Self::Acc) -> Self;
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
    /// `self / d` for `d > 0` (callers guarantee it); zero when `d` is zero or the
    /// quotient does not exist, saturating for fixed point. Never panics.
    fn div_pos(self, d: Self) -> Self;
    /// State accumulator holding `x`.
    fn state(x: Self) -> Self::State;
    /// Present value of a state accumulator.
    fn value(s: Self::State) -> Self;
    /// Un-rounded increment `Σ c_k v_k` of one discretised row.
    fn dot<const K: usize>(c: &[Self::Coef; K], v: &[Self; K]) -> Self::Dot;
    /// A [`Num::dot`] increment rounded to the value type.
    fn dot_value(d: Self::Dot) -> Self;
    /// `s + d + Σ a_m b_m` with one rounding step into the state.
    fn apply<const M: usize>(s: Self::State, d: Self::Dot, a: &[Self; M], b: &[Self; M]) -> Self::State;
    /// `s + Σ c_k v_k`: the discretised state update row.
    #[inline(always)]
    fn accumulate<const K: usize>(
        s: Self::State,
        c: &[Self::Coef; K],
        v: &[Self; K],
    ) -> Self::State {
        Self::apply(s, Self::dot(c, v), &[], &[])
    }
    /// `s + a b` at full accumulator precision.
    fn add_product(s: Self::State, a: Self, b: Self) -> Self::State;
    /// `round(self · k)` as an integer (saturating; NaN → 0).
    fn round_times(self, k: i32) -> i32;
    /// `(floor(x), x - floor(x))` for finite `x >= 0`; `(0, 0)` for negative or NaN
    /// input; saturates the integer part at `i32::MAX` (fraction then 0).
    fn split_floor(self) -> (i32, Self);
}

/// `1 / TICKS_PER_STEP` in `f64`.
const INV_TICKS_F64: f64 = 1.0 / crate::params::TICKS_PER_STEP as f64;

// SAFETY: zero bits are 0.0 for f64 and its associated types (f64).
unsafe impl Num for f64 {
    type Coef = f64;
    type State = f64;
    type Dot = f64;
    type Scale = f64;
    type Acc = f64;
    const ZERO: Self = 0.0;
    const ACC_ZERO: f64 = 0.0;
    const MAX_ROW_SUM: f64 = f64::INFINITY;
    const FLOAT: bool = true;
    fn from_f64(x: f64) -> Self {
        x
    }
    fn from_sample(x: f32, s: f64) -> Self {
        x as f64 * s
    }
    fn acc(a: f64, x: f64) -> f64 {
        a + x
    }
    fn acc_mean(a: f64) -> f64 {
        a * INV_TICKS_F64
    }
    fn coef_from_f64(x: f64) -> Option<f64> {
        x.is_finite().then_some(x)
    }
    fn from_f32(x: f32) -> Self {
        x as f64
    }
    fn from_exact(_x32: f32, x64: f64) -> Self {
        x64
    }
    fn coef_from_f32(x: f32) -> Option<f64> {
        x.is_finite().then_some(x as f64)
    }
    fn scale_from_f64(x: f64) -> Option<f64> {
        x.is_finite().then_some(x)
    }
    fn from_f32_scaled(x: f32, s: f64) -> Self {
        x as f64 * s
    }
    fn to_f32(self) -> f32 {
        self as f32
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn add(self, o: Self) -> Self {
        self + o
    }
    fn sub(self, o: Self) -> Self {
        self - o
    }
    fn mul(self, o: Self) -> Self {
        self * o
    }
    fn abs(self) -> Self {
        libm::fabs(self)
    }
    fn max0(self) -> Self {
        if self > 0.0 {
            self
        } else {
            0.0
        }
    }
    fn sqrt_abs(self) -> Self {
        libm::sqrt(libm::fabs(self))
    }
    fn exp(self) -> Self {
        libm::exp(self)
    }
    fn div_pos(self, d: Self) -> Self {
        if d > 0.0 {
            self / d
        } else {
            0.0
        }
    }
    fn state(x: Self) -> f64 {
        x
    }
    fn value(s: f64) -> Self {
        s
    }
    fn dot<const K: usize>(c: &[f64; K], v: &[f64; K]) -> f64 {
        c.iter().zip(v.iter()).fold(0.0, |a, (c, v)| a + c * v)
    }
    fn dot_value(d: f64) -> f64 {
        d
    }
    fn apply<const M: usize>(s: f64, d: f64, a: &[f64; M], b: &[f64; M]) -> f64 {
        s + d + a.iter().zip(b.iter()).fold(0.0, |acc, (a, b)| acc + a * b)
    }
    fn add_product(s: f64, a: f64, b: f64) -> f64 {
        s + a * b
    }
    fn round_times(self, k: i32) -> i32 {
        libm::round(self * k as f64) as i32
    }
    fn split_floor(self) -> (i32, Self) {
        if self >= 0.0 && self < i32::MAX as f64 {
            let i = libm::floor(self);
            (i as i32, self - i)
        } else if self >= i32::MAX as f64 {
            (i32::MAX, 0.0)
        } else {
            (0, 0.0)
        }
    }
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
    F32State {
        hi: t,
        lo: y - (t - s.hi),
    }
}

/// Correctly rounded square root of a non-negative `f32` (IEEE 754 `sqrt`).
/// On the Cortex-M4F one `vsqrt.f32` instruction; elsewhere libm's `sqrtf`, which is
/// also correctly rounded, so the host and the target give the same bits (the
/// processor-in-the-loop equivalence test relies on it).
#[inline(always)]
fn sqrt_f32(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_os = "none", target_abi = "eabihf"))]
    {
        let mut bits = x.to_bits();
        // SAFETY: `s15` is declared clobbered; `vsqrt.f32` has no other effect (the FPU
        // is enabled by cortex-m-rt on eabihf targets).
        unsafe {
            core::arch::asm!(
                "vmov s15, {b}",
                "vsqrt.f32 s15, s15",
                "vmov {b}, s15",
                b = inout(reg) bits,
                out("s15") _,
                options(pure, nomem, nostack),
            );
        }
        f32::from_bits(bits)
    }
    #[cfg(not(all(target_arch = "arm", target_os = "none", target_abi = "eabihf")))]
    {
        libm::sqrtf(x)
    }
}

// SAFETY: zero bits are 0.0 / an all-zero F32State (plain f32 fields).
unsafe impl Num for f32 {
    type Coef = f32;
    type State = F32State;
    type Dot = f32;
    type Scale = f32;
    type Acc = f32;
    const ZERO: Self = 0.0;
    const ACC_ZERO: f32 = 0.0;
    const MAX_ROW_SUM: f64 = f64::INFINITY;
    const FLOAT: bool = true;
    // (inlined: called with compile-time constants, so the conversion folds
    // and no f64 soft-float routine is linked)
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn from_sample(x: f32, s: f32) -> Self {
        x * s
    }
    #[inline(always)]
    fn acc(a: f32, x: f32) -> f32 {
        a + x
    }
    #[inline(always)]
    fn acc_mean(a: f32) -> f32 {
        a * INV_TICKS_F64 as f32
    }
    #[inline(always)]
    fn coef_from_f64(x: f64) -> Option<f32> {
        x.is_finite().then_some(x as f32)
    }
    #[inline(always)]
    fn from_f32(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn from_exact(x32: f32, _x64: f64) -> Self {
        x32
    }
    #[inline(always)]
    fn coef_from_f32(x: f32) -> Option<f32> {
        x.is_finite().then_some(x)
    }
    #[inline(always)]
    fn scale_from_f64(x: f64) -> Option<f32> {
        x.is_finite().then_some(x as f32)
    }
    #[inline(always)]
    fn from_f32_scaled(x: f32, s: f32) -> Self {
        x * s
    }
    fn to_f32(self) -> f32 {
        self
    }
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self + o
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self - o
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        self * o
    }
    #[inline(always)]
    fn abs(self) -> Self {
        libm::fabsf(self)
    }
    #[inline(always)]
    fn max0(self) -> Self {
        if self > 0.0 {
            self
        } else {
            0.0
        }
    }
    #[inline(always)]
    fn sqrt_abs(self) -> Self {
        sqrt_f32(libm::fabsf(self))
    }
    fn exp(self) -> Self {
        libm::expf(self)
    }
    #[inline(always)]
    fn div_pos(self, d: Self) -> Self {
        if d > 0.0 {
            self / d
        } else {
            0.0
        }
    }
    fn state(x: Self) -> F32State {
        F32State { hi: x, lo: 0.0 }
    }
    #[inline(always)]
    fn value(s: F32State) -> Self {
        s.hi
    }
    #[inline(always)]
    fn dot<const K: usize>(c: &[f32; K], v: &[f32; K]) -> f32 {
        c.iter().zip(v.iter()).fold(0.0f32, |a, (c, v)| a + c * v)
    }
    #[inline(always)]
    fn dot_value(d: f32) -> f32 {
        d
    }
    #[inline(always)]
    fn apply<const M: usize>(s: F32State, d: f32, a: &[f32; M], b: &[f32; M]) -> F32State {
        let d = a.iter().zip(b.iter()).fold(d, |acc, (a, b)| acc + a * b);
        two_sum(s, d)
    }
    #[inline(always)]
    fn add_product(s: F32State, a: f32, b: f32) -> F32State {
        two_sum(s, a * b)
    }
    #[inline(always)]
    fn round_times(self, k: i32) -> i32 {
        let y = self * k as f32;
        // `as` saturates and maps NaN to 0; round half away from zero.
        (if y >= 0.0 { y + 0.5 } else { y - 0.5 }) as i32
    }
    #[inline(always)]
    fn split_floor(self) -> (i32, Self) {
        if (0.0..2.0e9).contains(&self) {
            // truncation is the floor for non-negative values
            let i = self as i32;
            (i, self - i as f32)
        } else if self >= 2.0e9 {
            (i32::MAX, 0.0)
        } else {
            (0, 0.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
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
}
