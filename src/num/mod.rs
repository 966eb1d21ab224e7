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

mod f32;
mod f64;
mod fx;
pub use f32::F32State;
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

/// `1 / TICKS_PER_STEP` in `f64` (the mean of a step's tick sums).
const INV_TICKS_F64: f64 = 1.0 / crate::params::TICKS_PER_STEP as f64;

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
