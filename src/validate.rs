//! Input validation (range, rate of change, non-finite) and the worst-case
//! substitution used by the fail-safe path.
//!
//! Nothing is clamped silently: a channel that fails a check is reported as a
//! fault bit and, while the fault is latched, replaced by its *worst-case* value
//! (maximum loss), so the thermal estimate keeps rising conservatively.

use crate::guard::Sample;

/// Channel bit: motor current.
pub const CH_CURRENT: u8 = 1 << 0;
/// Channel bit: port A pressure.
pub const CH_P_A: u8 = 1 << 1;
/// Channel bit: port B pressure.
pub const CH_P_B: u8 = 1 << 2;
/// Channel bit: motor speed.
pub const CH_SPEED: u8 = 1 << 3;
/// Channel bit: piston position.
pub const CH_POSITION: u8 = 1 << 4;
/// Channel bit: ambient temperature.
pub const CH_AMBIENT: u8 = 1 << 5;
/// All six channels.
pub const CH_ALL: u8 = 0x3f;

/// Plausible ranges and per-step (10 ms) rates of the inputs, wire units.
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
    /// Max |change| of current per step, A.
    pub current_a_per_step: f32,
    /// Max |change| of a port pressure per step, bar.
    pub pressure_bar_per_step: f32,
    /// Max |change| of speed per step, rpm.
    pub speed_rpm_per_step: f32,
    /// Max |change| of position per step, mm (0.5 m/s piston speed).
    pub position_mm_per_step: f32,
    /// Max |change| of ambient per step, K.
    pub ambient_c_per_step: f32,
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
        current_a_per_step: 200.0,
        pressure_bar_per_step: 150.0,
        speed_rpm_per_step: 3000.0,
        position_mm_per_step: 5.0,
        ambient_c_per_step: 1.0,
    };
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
    /// Channels that failed any check (`CH_*` bits).
    pub bad: u8,
}

#[inline(always)]
fn check_one(x: f32, lo: f32, hi: f32, prev: Option<f32>, rate: f32, bit: u8, c: &mut Check) {
    if !x.is_finite() {
        c.non_finite = true;
        c.bad |= bit;
    } else if !(x >= lo && x <= hi) {
        c.range = true;
        c.bad |= bit;
    } else if let Some(p) = prev {
        let d = x - p;
        if !(d <= rate && d >= -rate) {
            c.rate = true;
            c.bad |= bit;
        }
    }
}

/// Checks a sample against `lim`. `prev` is the previous sample and `prev_ok`
/// the channels of it that were valid (rate is only checked against valid values).
pub fn check(s: &Sample, prev: &Sample, prev_ok: u8, lim: &InputLimits) -> Check {
    let mut c = Check::default();
    let pv = |bit: u8, v: f32| if prev_ok & bit != 0 { Some(v) } else { None };
    let l = lim;
    check_one(s.current_a, -l.current_a_max, l.current_a_max, pv(CH_CURRENT, prev.current_a), l.current_a_per_step, CH_CURRENT, &mut c);
    check_one(s.p_a_bar, l.pressure_bar_min, l.pressure_bar_max, pv(CH_P_A, prev.p_a_bar), l.pressure_bar_per_step, CH_P_A, &mut c);
    check_one(s.p_b_bar, l.pressure_bar_min, l.pressure_bar_max, pv(CH_P_B, prev.p_b_bar), l.pressure_bar_per_step, CH_P_B, &mut c);
    check_one(s.speed_rpm, -l.speed_rpm_max, l.speed_rpm_max, pv(CH_SPEED, prev.speed_rpm), l.speed_rpm_per_step, CH_SPEED, &mut c);
    check_one(s.position_mm, l.position_mm_min, l.position_mm_max, pv(CH_POSITION, prev.position_mm), l.position_mm_per_step, CH_POSITION, &mut c);
    check_one(s.ambient_c, l.ambient_c_min, l.ambient_c_max, pv(CH_AMBIENT, prev.ambient_c), l.ambient_c_per_step, CH_AMBIENT, &mut c);
    c
}

/// Model inputs for one step after worst-case substitution of the `bad` channels.
///
/// Worst case = maximum heat: current at its maximum; a bad pressure gives the
/// full pressure span with the sign that makes `dp·w` positive (all pump power
/// throttled); a bad speed gives the maximum speed with the sign of `dp`; a bad
/// position gives zero piston work (`dpos = 0`: nothing leaves as work); a bad
/// ambient gives the maximum ambient. Valid channels are used as they are.
/// `prev_pos_mm` is the last valid position (`None` → no derivative, `dpos = 0`).
pub fn substitute(s: &Sample, bad: u8, prev_pos_mm: Option<f32>, lim: &InputLimits) -> crate::model::ModelInput {
    let current_a = if bad & CH_CURRENT != 0 { lim.current_a_max } else { s.current_a };
    let speed_ok = bad & CH_SPEED == 0;
    let p_bad = bad & (CH_P_A | CH_P_B) != 0;
    let dp_bar = if p_bad {
        let span = lim.pressure_bar_max - lim.pressure_bar_min;
        if speed_ok && s.speed_rpm < 0.0 { -span } else { span }
    } else {
        s.p_a_bar - s.p_b_bar
    };
    let speed_rpm = if speed_ok {
        s.speed_rpm
    } else if dp_bar < 0.0 {
        -lim.speed_rpm_max
    } else {
        lim.speed_rpm_max
    };
    let dpos_mm = match prev_pos_mm {
        Some(p) if bad & CH_POSITION == 0 => s.position_mm - p,
        _ => 0.0,
    };
    let ambient_c = if bad & CH_AMBIENT != 0 { lim.ambient_c_max } else { s.ambient_c };
    crate::model::ModelInput { current_a, dp_bar, speed_rpm, dpos_mm, ambient_c }
}
