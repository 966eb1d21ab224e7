//! Input validation (non-finite, range, rate of change) and the worst-case
//! substitution used by the fail-safe path.
//!
//! Each wire channel is first tested for NaN/inf on its bits, then converted once
//! to the model's number type and unit (hA, hbar, hrad/s, mm, degC); range and rate
//! checks run on the converted values, so the fixed-point build needs no soft-float.
//! Nothing is clamped silently: a channel that fails a check is reported as a fault
//! bit and, while the fault is latched, replaced by its *worst-case* value (maximum
//! loss), so the thermal estimate keeps rising conservatively.

use crate::faults::ChannelSet;
use crate::interface::Sample;
use crate::model::{InputScales, ModelInputN};
use crate::num::Num;

/// Plausible ranges and per-tick (10 ms) rates of the inputs, wire units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InputLimits {
    /// Max |current|, A rms (Table 2: 340.5 A). Also the worst-case substitute.
    pub current_a_max: f32,
    /// Min port pressure, bar (gauge; slight vacuum allowed).
    pub pressure_bar_min: f32,
    /// Max port pressure, bar (relief setting).
    pub pressure_bar_max: f32,
    /// Max |speed|, rpm.
    pub speed_rpm_max: f32,
    /// Min piston position, mm (stroke ±50 mm, Table 2, plus margin).
    pub position_mm_min: f32,
    /// Max piston position, mm.
    pub position_mm_max: f32,
    /// Min ambient, degC.
    pub ambient_c_min: f32,
    /// Max ambient, degC. Also the worst-case ambient substitute.
    pub ambient_c_max: f32,
    /// Max |change| of current per tick, A.
    pub current_a_per_tick: f32,
    /// Max |change| of a port pressure per tick, bar.
    pub pressure_bar_per_tick: f32,
    /// Max |change| of speed per tick, rpm.
    pub speed_rpm_per_tick: f32,
    /// Max |change| of position per tick, mm (0.5 m/s piston speed).
    pub position_mm_per_tick: f32,
    /// Max |change| of ambient per tick, K.
    pub ambient_c_per_tick: f32,
}

impl InputLimits {
    /// Defaults from Tables 2-3 and the rig: 340.5 A, -5..350 bar, 6000 rpm, ±55 mm,
    /// -60..85 degC; rates: 200 A, 150 bar, 3000 rpm, 5 mm, 1 K per 10 ms.
    pub const DEFAULT: InputLimits = InputLimits {
        current_a_max: 340.5,
        pressure_bar_min: -5.0,
        pressure_bar_max: 350.0,
        speed_rpm_max: 6000.0,
        position_mm_min: -55.0,
        position_mm_max: 55.0,
        ambient_c_min: -60.0,
        ambient_c_max: 85.0,
        current_a_per_tick: 200.0,
        pressure_bar_per_tick: 150.0,
        speed_rpm_per_tick: 3000.0,
        position_mm_per_tick: 5.0,
        ambient_c_per_tick: 1.0,
    };
}

/// The six channels in model units, order `[current hA, p_A hbar, p_B hbar,
/// speed hrad/s, position mm, ambient degC]` (channel `i` of a [`ChannelSet`]).
pub type Channels<N> = [N; 6];

/// [`InputLimits`] converted once to model units.
#[derive(Clone, Copy, Debug)]
pub struct LimitsN<N: Num> {
    lo: Channels<N>,
    hi: Channels<N>,
    rate: Channels<N>,
}

impl<N: Num> LimitsN<N> {
    /// The limits over `ticks` ticks: the rates times `ticks` (small counts:
    /// below the STALE count, so the products stay far inside the number
    /// type's range).
    pub fn rate_over(&self, ticks: u32) -> Self {
        let n = N::from_f32(ticks as f32);
        LimitsN { lo: self.lo, hi: self.hi, rate: self.rate.map(|r| r.mul(n)) }
    }

    /// Converts `l`; `None` when a limit does not fit the number type (|x| ≥ 250).
    pub fn new(l: &InputLimits, sc: &InputScales<N>) -> Option<Self> {
        let ok = |x: f32| x.is_finite() && x.abs() < 250.0;
        let cv = |x: f32, s: N::Scale| N::from_f32_scaled(x, s);
        let lo = [
            -l.current_a_max,
            l.pressure_bar_min,
            l.pressure_bar_min,
            -l.speed_rpm_max,
            l.position_mm_min,
            l.ambient_c_min,
        ];
        let hi = [
            l.current_a_max,
            l.pressure_bar_max,
            l.pressure_bar_max,
            l.speed_rpm_max,
            l.position_mm_max,
            l.ambient_c_max,
        ];
        let rt = [
            l.current_a_per_tick,
            l.pressure_bar_per_tick,
            l.pressure_bar_per_tick,
            l.speed_rpm_per_tick,
            l.position_mm_per_tick,
            l.ambient_c_per_tick,
        ];
        let s = sc.per_channel();
        // (the f64 unit constants rounded at compile time: no f64 on the target)
        const S32: [f32; 6] = [
            crate::model::HA_PER_A as f32,
            crate::model::HBAR_PER_BAR as f32,
            crate::model::HBAR_PER_BAR as f32,
            crate::model::HRADS_PER_RPM as f32,
            1.0,
            1.0,
        ];
        let mut out = LimitsN {
            lo: [N::ZERO; 6],
            hi: [N::ZERO; 6],
            rate: [N::ZERO; 6],
        };
        for ((((o_lo, o_hi), o_rt), (a, b)), (c, (sc, k))) in out
            .lo
            .iter_mut()
            .zip(out.hi.iter_mut())
            .zip(out.rate.iter_mut())
            .zip(lo.iter().zip(hi.iter()))
            .zip(rt.iter().zip(s.iter().zip(S32.iter())))
        {
            let k = *k;
            if !(ok(a * k) && ok(b * k) && ok(c * k) && a <= b && *c >= 0.0) {
                return None;
            }
            *o_lo = cv(*a, *sc);
            *o_hi = cv(*b, *sc);
            *o_rt = cv(*c, *sc);
        }
        Some(out)
    }
}

/// Result of checking one sample: which fault classes and which channels failed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Check {
    /// Some channel is NaN or infinite.
    pub non_finite: bool,
    /// Some channel is outside its plausible range.
    pub range: bool,
    /// Some channel changed faster than its rate limit.
    pub rate: bool,
    /// Channels that failed any check.
    pub bad: ChannelSet,
}

/// Converts a sample to model units; returns the values and the channels
/// whose `f32` is NaN or infinite (tested on the bits: exponent all ones).
#[inline(always)]
pub fn convert<N: Num>(s: &Sample, sc: &InputScales<N>) -> (Channels<N>, ChannelSet) {
    let raw = [
        s.current_a,
        s.p_a_bar,
        s.p_b_bar,
        s.speed_rpm,
        s.position_mm,
        s.ambient_c,
    ];
    let scale = sc.per_channel();
    let mut v = [N::ZERO; 6];
    let mut nonfinite = ChannelSet::NONE;
    for (i, ((o, x), k)) in v.iter_mut().zip(raw.iter()).zip(scale.iter()).enumerate() {
        if x.to_bits() & 0x7f80_0000 == 0x7f80_0000 {
            nonfinite |= ChannelSet::channel(i);
        } else {
            *o = N::from_f32_scaled(*x, *k);
        }
    }
    (v, nonfinite)
}

/// The fast path of the per-tick validation: converts a sample (non-finite values
/// become values that fail the range test, [`Num::from_sample`]) and checks every
/// channel's range and its rate against `prev` in one combined test, without
/// classifying. Returns the channels and `true` when all twelve tests pass. Only
/// meaningful when every previous value is valid (`prev_ok == ChannelSet::ALL`); on `false`
/// the caller classifies the sample with [`convert`] and [`check`] (the distinct
/// fault bits and channel bits), which give the same verdict.
#[inline(always)]
pub fn convert_check<N: Num>(
    s: &Sample,
    prev: &Channels<N>,
    sc: &InputScales<N>,
    lim: &LimitsN<N>,
) -> (Channels<N>, bool) {
    let x = [
        N::from_sample(s.current_a, sc.ha_per_a),
        N::from_sample(s.p_a_bar, sc.hbar_per_bar),
        N::from_sample(s.p_b_bar, sc.hbar_per_bar),
        N::from_sample(s.speed_rpm, sc.hrads_per_rpm),
        N::from_sample(s.position_mm, sc.one),
        N::from_sample(s.ambient_c, sc.one),
    ];
    let mut ok = true;
    for ((((x, p), lo), hi), r) in x
        .iter()
        .zip(prev.iter())
        .zip(lim.lo.iter())
        .zip(lim.hi.iter())
        .zip(lim.rate.iter())
    {
        // Non-short-circuit `&`: straight-line code; NaN fails every comparison.
        ok &= (*x >= *lo) & (*x <= *hi) & (x.sub(*p).abs() <= *r);
    }
    (x, ok)
}

/// Model inputs of a tick whose sample passed [`convert_check`] with every channel
/// valid and no channel latched bad: the port pressures, `dpos = x - x_prev`.
#[inline(always)]
pub fn direct<N: Num>(v: &Channels<N>, prev: &Channels<N>) -> ModelInputN<N> {
    let [i, pa, pb, w, x, amb] = *v;
    let [_, _, _, _, x_prev, _] = *prev;
    ModelInputN {
        current_ha: i,
        p_a_hbar: pa,
        p_b_hbar: pb,
        speed_hrads: w,
        dpos_mm: x.sub(x_prev),
        ambient_c: amb,
    }
}

#[inline(always)]
#[allow(clippy::too_many_arguments)]
// `!(d.abs() <= r)` is deliberate: a NaN difference (not reachable) counts as a fault.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn check_one<N: Num>(
    x: N,
    p: N,
    lo: N,
    hi: N,
    r: N,
    bit: ChannelSet,
    skip: ChannelSet,
    prev_ok: ChannelSet,
    c: &mut Check,
) {
    if skip.intersects(bit) {
        return;
    }
    if !(x >= lo && x <= hi) {
        c.range = true;
        c.bad |= bit;
    } else if prev_ok.intersects(bit) {
        let d = x.sub(p);
        if !(d.abs() <= r) {
            c.rate = true;
            c.bad |= bit;
        }
    }
}

/// Checks converted channels: range, then rate against `prev` for the channels in
/// `prev_ok` (rate is only checked against valid previous values). Written out per
/// channel (no loop) so that it compiles to straight-line code.
#[inline(always)]
pub fn check<N: Num>(
    v: &Channels<N>,
    nonfinite: ChannelSet,
    prev: &Channels<N>,
    prev_ok: ChannelSet,
    lim: &LimitsN<N>,
) -> Check {
    let mut c = Check {
        non_finite: !nonfinite.is_empty(),
        bad: nonfinite,
        ..Check::default()
    };
    let [x0, x1, x2, x3, x4, x5] = *v;
    let [p0, p1, p2, p3, p4, p5] = *prev;
    let [l0, l1, l2, l3, l4, l5] = lim.lo;
    let [h0, h1, h2, h3, h4, h5] = lim.hi;
    let [r0, r1, r2, r3, r4, r5] = lim.rate;
    let (nf, ok) = (nonfinite, prev_ok);
    check_one(x0, p0, l0, h0, r0, ChannelSet::CURRENT, nf, ok, &mut c);
    check_one(x1, p1, l1, h1, r1, ChannelSet::P_A, nf, ok, &mut c);
    check_one(x2, p2, l2, h2, r2, ChannelSet::P_B, nf, ok, &mut c);
    check_one(x3, p3, l3, h3, r3, ChannelSet::SPEED, nf, ok, &mut c);
    check_one(x4, p4, l4, h4, r4, ChannelSet::POSITION, nf, ok, &mut c);
    check_one(x5, p5, l5, h5, r5, ChannelSet::AMBIENT, nf, ok, &mut c);
    c
}

/// Model inputs for one tick after worst-case substitution of the `bad` channels.
///
/// Worst case = maximum heat: current at its maximum; a bad pressure gives both
/// ports the full pressure range (one at the maximum, the other at the minimum)
/// with the sign that makes `dp·w` positive (all pump power throttled, maximum
/// leakage); a bad speed gives the maximum speed with the sign of `dp`; a bad
/// position gives zero piston work (`dpos = 0`: nothing leaves as work); a bad
/// ambient gives the maximum ambient. Valid channels are used as they are.
/// `prev_pos` is the last valid position (`None` → no derivative, `dpos = 0`).
#[inline(always)]
pub fn substitute<N: Num>(
    v: &Channels<N>,
    bad: ChannelSet,
    prev_pos: Option<N>,
    lim: &LimitsN<N>,
) -> ModelInputN<N> {
    let [i, pa, pb, w, x, amb] = *v;
    let [_, _, _, _, _, amb_max] = lim.hi;
    let [i_max, p_max, _, w_max, _, _] = lim.hi;
    let [_, p_min, _, _, _, _] = lim.lo;
    let current = if bad.intersects(ChannelSet::CURRENT) { i_max } else { i };
    let speed_ok = !bad.intersects(ChannelSet::SPEED);
    let (pa, pb) = if bad.intersects(ChannelSet::P_A | ChannelSet::P_B) {
        if speed_ok && w < N::ZERO {
            (p_min, p_max)
        } else {
            (p_max, p_min)
        }
    } else {
        (pa, pb)
    };
    let dp = pa.sub(pb);
    let speed = if speed_ok {
        w
    } else if dp < N::ZERO {
        N::ZERO.sub(w_max)
    } else {
        w_max
    };
    let dpos = match prev_pos {
        Some(p) if !bad.intersects(ChannelSet::POSITION) => x.sub(p),
        _ => N::ZERO,
    };
    let ambient = if bad.intersects(ChannelSet::AMBIENT) { amb_max } else { amb };
    ModelInputN {
        current_ha: current,
        p_a_hbar: pa,
        p_b_hbar: pb,
        speed_hrads: speed,
        dpos_mm: dpos,
        ambient_c: ambient,
    }
}
