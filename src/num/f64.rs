//! [`Num`] for `f64`: the design and reference instantiation (host tests).

use super::{Num, INV_TICKS_F64};

// Every method `#[inline]` on the host (not on the firmware targets, whose
// image size the hint could move): the host tests' reduced-model replays
// (`eha_sim::calibration::replay`) called them out of line, ~12 % of a
// commissioning's CPU. Inlining changes no result (no FMA contraction).
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
    #[cfg_attr(not(target_os = "none"), inline)]
    fn from_f64(x: f64) -> Self {
        x
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn from_sample(x: f32, s: f64) -> Self {
        x as f64 * s
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn acc(a: f64, x: f64) -> f64 {
        a + x
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn acc_mean(a: f64) -> f64 {
        a * INV_TICKS_F64
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn coef_from_f64(x: f64) -> Option<f64> {
        x.is_finite().then_some(x)
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn from_f32(x: f32) -> Self {
        x as f64
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn from_exact(_x32: f32, x64: f64) -> Self {
        x64
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn coef_from_f32(x: f32) -> Option<f64> {
        x.is_finite().then_some(x as f64)
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn scale_from_f64(x: f64) -> Option<f64> {
        x.is_finite().then_some(x)
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn from_f32_scaled(x: f32, s: f64) -> Self {
        x as f64 * s
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn to_f32(self) -> f32 {
        self as f32
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn to_f64(self) -> f64 {
        self
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn add(self, o: Self) -> Self {
        self + o
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn sub(self, o: Self) -> Self {
        self - o
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn mul(self, o: Self) -> Self {
        self * o
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn abs(self) -> Self {
        libm::fabs(self)
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn max0(self) -> Self {
        if self > 0.0 {
            self
        } else {
            0.0
        }
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn sqrt_abs(self) -> Self {
        libm::sqrt(libm::fabs(self))
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn exp(self) -> Self {
        libm::exp(self)
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn div_pos(self, d: Self) -> Self {
        if d > 0.0 {
            self / d
        } else {
            0.0
        }
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn state(x: Self) -> f64 {
        x
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn value(s: f64) -> Self {
        s
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn dot<const K: usize>(c: &[f64; K], v: &[f64; K]) -> f64 {
        c.iter().zip(v.iter()).fold(0.0, |a, (c, v)| a + c * v)
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn dot_value(d: f64) -> f64 {
        d
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn apply<const M: usize>(s: f64, d: f64, a: &[f64; M], b: &[f64; M]) -> f64 {
        s + d + a.iter().zip(b.iter()).fold(0.0, |acc, (a, b)| acc + a * b)
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn add_product(s: f64, a: f64, b: f64) -> f64 {
        s + a * b
    }
    #[cfg_attr(not(target_os = "none"), inline)]
    fn round_times(self, k: i32) -> i32 {
        libm::round(self * k as f64) as i32
    }
    #[cfg_attr(not(target_os = "none"), inline)]
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
