//! [`Num`] for `f32`: the Cortex-M4F instantiation, its state a compensated
//! pair ([`F32State`]) and its square root the same bits on host and target.

use super::{Num, INV_TICKS_F64};

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
