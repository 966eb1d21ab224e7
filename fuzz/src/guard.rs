//! Structured guard fuzzing: the input bytes are read as a boot header and a
//! list of operations on one guard (`arbitrary::Unstructured`, weighted by a
//! selector byte so that valid, rate-limited ramps dominate).
//!
//! Header: a config variant (1 in 4: fuzzed stale/clear/dwell/threshold/LNG
//! knobs, otherwise `GuardConfig::DEFAULT`), the boot rule (cold; a sealed
//! thermal record near the valve/alarm thresholds with a fuzzed LNG use; a raw
//! record through `Restore::from_record`; a corrupt record) and the start
//! point of the six channels inside their ranges.
//!
//! Operations (selector byte, out of 256; a fault operation runs only while
//! the input has [`FAULT_CREDIT`] more unlatched than latched ticks, else it
//! is replaced by a short valid ramp):
//! * 0..=191 `Ramp`: 1..=64 valid ticks, per-channel slope up to 0.9 × the
//!   rate limit of `InputLimits`, reflected 0.5 % inside the range (the same
//!   generator as the stable proptest `valid_inputs_with_injected_faults_keep_invariants`);
//!   then a maintenance `clear_faults` attempt when a fault is latched;
//! * `Missing` 1..=8 ticks, `NonFinite` (NaN/±inf in one channel), `Range`
//!   (one channel outside its range), `Rate` (a step of 1.1–3 × the rate limit
//!   that persists), `Clear` (explicit attempt, may be refused), `Refill` (LNG),
//!   `Feedback` (valve read-back: none, following the command, or stuck
//!   open/closed), `Actuator` (valve pin error), `Reboot` (snapshot → `Restore::from_record`
//!   → new guard, a warm reset), `Raw` (six arbitrary `f32` for one tick).
//!
//! Checked at every tick: no panic (overflow checks and debug assertions are
//! on in the fuzz build), finite outputs, a latched fault implies the valve
//! open, derate = alarm or ACTUATOR or NV_FAILED, LNG remaining within [0, full charge].

use crate::stats;
use eha_guard::faults;
use eha_guard::memory::{Restore, ThermalRecord};
use eha_guard::num::Num;
use eha_guard::protection::LngBudget;
use eha_guard::validate::InputLimits;
use eha_guard::{GuardConfig, GuardOf, Output, Sample};
use libfuzzer_sys::arbitrary::Unstructured;
use std::sync::atomic::Ordering::Relaxed;
use std::sync::OnceLock;

/// Most guard ticks per input (keeps one execution short: 4 s of guard time).
pub const MAX_TICKS: u32 = 400;

/// A fault operation runs only when the input has had at least this many more
/// unlatched than latched ticks so far; otherwise it becomes a short valid
/// ramp. A latched fault costs at least `clear_valid_ticks` (100) latched
/// ticks before the maintenance clear succeeds, so this keeps at least about
/// half of all ticks on the unlatched path (see the `EHA_FUZZ_STATS` report).
pub const FAULT_CREDIT: i64 = 100;

#[derive(Clone, Copy)]
struct Chan {
    lo: f32,
    hi: f32,
    rate: f32,
}

fn channels(l: &InputLimits) -> [Chan; 6] {
    let p = Chan { lo: l.pressure_bar_min, hi: l.pressure_bar_max, rate: l.pressure_bar_per_tick };
    [
        Chan { lo: -l.current_a_max, hi: l.current_a_max, rate: l.current_a_per_tick },
        p,
        p,
        Chan { lo: -l.speed_rpm_max, hi: l.speed_rpm_max, rate: l.speed_rpm_per_tick },
        Chan { lo: l.position_mm_min, hi: l.position_mm_max, rate: l.position_mm_per_tick },
        Chan { lo: l.ambient_c_min, hi: l.ambient_c_max, rate: l.ambient_c_per_tick },
    ]
}

impl Chan {
    /// The range inset by 0.5 % of its width on each side.
    fn inset(&self) -> (f32, f32) {
        let m = 0.005 * (self.hi - self.lo);
        (self.lo + m, self.hi - m)
    }
}

fn to_sample(x: &[f32; 6]) -> Sample {
    let [current_a, p_a_bar, p_b_bar, speed_rpm, position_mm, ambient_c] = *x;
    Sample { current_a, p_a_bar, p_b_bar, speed_rpm, position_mm, ambient_c }
}

fn byte(u: &mut Unstructured<'_>) -> u8 {
    u.arbitrary::<u8>().unwrap_or(0)
}

fn frac(u: &mut Unstructured<'_>) -> f32 {
    f32::from(byte(u)) / 255.0
}

fn f32_raw(u: &mut Unstructured<'_>) -> f32 {
    f32::from_bits(u.arbitrary::<u32>().unwrap_or(0))
}

/// One guard under test plus the bookkeeping of the checks.
struct Run<N: Num> {
    g: GuardOf<N>,
    cfg: GuardConfig<'static>,
    full_kg: f32,
    ticks: u32,
    /// Unlatched minus latched ticks so far in this input.
    credit: i64,
    stats: bool,
    /// Valve-position feedback fed before every tick.
    fb: Feedback,
}

/// What the valve read-back reports (set by the `Feedback` operation).
#[derive(Clone, Copy, PartialEq)]
enum Feedback {
    /// No read-back wired (the guard takes the command as the position).
    None,
    /// A healthy valve: the read-back follows the last command.
    Follows,
    /// A valve stuck in one position.
    Stuck(bool),
}

impl<N: Num> Run<N> {
    fn check(&mut self, o: &Output, what: &str) {
        assert!(
            o.drain_c.is_finite() && o.lng_remaining_kg.is_finite() && o.lng_seconds_left.is_finite(),
            "{what}: non-finite output {o:?}"
        );
        if o.faults.intersects(faults::LATCHED) {
            assert!(o.valve_open, "{what}: latched fault {:#x} but valve closed: {o:?}", o.faults);
        }
        // derate: the alarm, a valve that does not follow its command, or a
        // failed non-volatile save; never without one of them
        let derate = o.alarm || o.faults.intersects(faults::ACTUATOR | faults::NV_FAILED);
        assert_eq!(o.derate, derate, "{what}: derate must follow the alarm, ACTUATOR or NV_FAILED: {o:?}");
        assert!(
            o.lng_remaining_kg >= 0.0 && o.lng_remaining_kg <= self.full_kg,
            "{what}: LNG {} kg outside [0, {}]: {o:?}",
            o.lng_remaining_kg,
            self.full_kg
        );
        assert!(o.lng_seconds_left >= 0.0, "{what}: negative LNG seconds left: {o:?}");
    }

    fn tick(&mut self, s: Option<&Sample>, valid: bool) {
        match self.fb {
            Feedback::None => {}
            Feedback::Follows => {
                let open = self.g.output().valve_open;
                self.g.valve_feedback(open);
            }
            Feedback::Stuck(open) => self.g.valve_feedback(open),
        }
        let o = match s {
            Some(s) => self.g.tick(s),
            None => self.g.tick_missing(),
        };
        self.check(&o, "tick");
        self.ticks += 1;
        self.credit += if !o.faults.intersects(faults::LATCHED) { 1 } else { -1 };
        if self.stats {
            stats::TICKS.fetch_add(1, Relaxed);
            if !o.faults.intersects(faults::LATCHED) {
                stats::UNLATCHED.fetch_add(1, Relaxed);
            }
            if valid {
                stats::VALID_TICKS.fetch_add(1, Relaxed);
            }
            if o.valve_open {
                stats::VALVE_OPEN_TICKS.fetch_add(1, Relaxed);
            }
        }
    }

    fn clear(&mut self) {
        let before = self.g.faults() & faults::LATCHED;
        if self.g.clear_faults().cleared() {
            // Maintenance that clears the faults also repairs a stuck valve.
            if matches!(self.fb, Feedback::Stuck(_)) {
                self.fb = Feedback::Follows;
            }
            // Only CONFIG survives a successful clear.
            let after = self.g.faults() & faults::LATCHED;
            assert!((after & !faults::CONFIG).is_empty(), "clear_faults returned true but {after:#x} still latched");
            if self.stats && !(before & !faults::CONFIG).is_empty() {
                stats::CLEARS.fetch_add(1, Relaxed);
            }
        }
    }
}

fn config(u: &mut Unstructured<'_>, variant: u8) -> GuardConfig<'static> {
    let mut cfg = GuardConfig::DEFAULT;
    if variant & 3 == 3 {
        cfg.stale_ticks = 1 + u32::from(byte(u) % 20);
        cfg.clear_valid_ticks = u32::from(byte(u)) * 2;
        cfg.valve.dwell_ticks = u32::from(byte(u)) * 4;
        cfg.valve.open_c = 20.0 + 0.25 * f32::from(byte(u));
        cfg.valve.close_c = cfg.valve.open_c - 0.02 * f32::from(byte(u));
        cfg.alarm.alarm_c = 20.0 + 0.25 * f32::from(byte(u));
        cfg.alarm.clear_c = cfg.alarm.alarm_c - 0.02 * f32::from(byte(u));
        // 0 .. 0.51 L: a charge that runs out within an input.
        cfg.lng.charge_l = 0.002 * f32::from(byte(u));
        cfg.lng.low_fraction = frac(u);
    }
    cfg
}

fn restore(u: &mut Unstructured<'_>, variant: u8) -> Restore {
    match (variant >> 2) & 3 {
        0 | 1 => Restore::Cold,
        2 => {
            // A sealed record near the thresholds (15..79 degC), nodes spread by
            // up to ±2.5 K, a fuzzed LNG use and latched faults.
            let base = 15.0 + 0.25 * f32::from(byte(u));
            let mut temps = [0.0f32; 6];
            for t in temps.iter_mut() {
                *t = base + 0.02 * f32::from(byte(u) as i8);
            }
            let amb = -20.0 + 0.25 * f32::from(byte(u));
            let used = u.arbitrary::<u32>().unwrap_or(0);
            let fb = u.arbitrary::<u32>().unwrap_or(0) & (faults::LATCHED | eha_guard::Faults::channels(eha_guard::ChannelSet::ALL)).bits();
            let fb = if byte(u) & 1 == 0 { 0 } else { fb };
            Restore::from_record(&ThermalRecord::new(temps, amb, used, fb, 0))
        }
        _ => {
            // Whatever bits no-init RAM holds: mostly Absent or Corrupt.
            let mut r = ThermalRecord::new([0.0; 6], 0.0, 0, 0, 0);
            let sealed = byte(u) & 1 == 0;
            for t in r.temps_c.iter_mut() {
                *t = f32_raw(u);
            }
            r.ambient_c = f32_raw(u);
            r.lng_used_cj = u.arbitrary().unwrap_or(0);
            r.faults = u.arbitrary().unwrap_or(0);
            if sealed {
                r = ThermalRecord::new(r.temps_c, r.ambient_c, r.lng_used_cj, r.faults, 0);
            } else {
                r.magic ^= u.arbitrary::<u32>().unwrap_or(0);
                r.crc ^= u.arbitrary::<u32>().unwrap_or(0);
            }
            Restore::from_record(&r)
        }
    }
}

/// Runs one input through a guard of number type `N`. `cold` caches the
/// cold-booted guard of the default config (building the model's matrix
/// exponential costs more than a short input): that case starts from a clone.
pub fn run<N: Num>(data: &[u8], label: &'static str, cold: &OnceLock<GuardOf<N>>) {
    let stats = stats::enabled(label);
    if stats {
        stats::EXECS.fetch_add(1, Relaxed);
    }
    let mut u = Unstructured::new(data);
    let variant = byte(&mut u);
    let cfg = config(&mut u, variant);
    let boot = restore(&mut u, variant);
    let full_kg = LngBudget::new(&cfg.lng).remaining_kg();
    let g = if variant & 3 != 3 && boot == Restore::Cold {
        cold.get_or_init(|| GuardOf::<N>::new(&cfg, Restore::Cold)).clone()
    } else {
        GuardOf::<N>::new(&cfg, boot)
    };
    let mut r = Run { g, cfg, full_kg, ticks: 0, credit: 0, stats, fb: Feedback::None };
    let ch = channels(&cfg.limits);
    let mut x = [0.0f32; 6];
    for (x, c) in x.iter_mut().zip(ch) {
        let (lo, hi) = c.inset();
        *x = lo + frac(&mut u) * (hi - lo);
    }
    let mut slope = [0.0f32; 6];
    while !u.is_empty() && r.ticks < MAX_TICKS {
        let sel = byte(&mut u);
        match sel {
            _ if is_fault_op(sel) && r.credit < FAULT_CREDIT => {
                // Not enough unlatched ticks yet for another fault: a short ramp
                // on the present slopes instead (no bytes consumed).
                ramp(&mut r, &mut x, &mut slope, &ch, 1 + u32::from(sel % 32));
            }
            0..=191 => {
                // Ramp: valid, rate-limited ticks.
                let n = 1 + u32::from(byte(&mut u) % 64);
                for s in slope.iter_mut() {
                    *s = 0.9 * f32::from(byte(&mut u) as i8) / 128.0;
                }
                ramp(&mut r, &mut x, &mut slope, &ch, n);
            }
            192..=203 => {
                fault_op(&r);
                for _ in 0..=(byte(&mut u) % 8) {
                    r.tick(None, false);
                }
            }
            204..=209 => {
                fault_op(&r);
                let mut y = x;
                let k = usize::from(byte(&mut u) % 6);
                y[k] = match byte(&mut u) % 3 {
                    0 => f32::NAN,
                    1 => f32::INFINITY,
                    _ => f32::NEG_INFINITY,
                };
                r.tick(Some(&to_sample(&y)), false);
            }
            210..=215 => {
                fault_op(&r);
                let mut y = x;
                let k = usize::from(byte(&mut u) % 6);
                let c = ch[k];
                let excess = (0.001 + frac(&mut u)) * (c.hi - c.lo);
                y[k] = if byte(&mut u) & 1 == 0 { c.hi + excess } else { c.lo - excess };
                r.tick(Some(&to_sample(&y)), false);
            }
            216..=221 => {
                fault_op(&r);
                let k = usize::from(byte(&mut u) % 6);
                let c = ch[k];
                let factor = 1.1 + 1.9 * frac(&mut u);
                let dir = if x[k] > 0.5 * (c.lo + c.hi) { -1.0 } else { 1.0 };
                let (lo, hi) = c.inset();
                x[k] = (x[k] + dir * factor * c.rate).clamp(lo, hi);
                r.tick(Some(&to_sample(&x)), false);
            }
            222..=231 => r.clear(),
            232..=234 => {
                let cfg = r.cfg.lng;
                r.g.refill_lng(&cfg);
            }
            235..=237 => {
                // Valve read-back: none, healthy, or stuck (a stuck valve is a
                // fault operation: it latches ACTUATOR once it disagrees).
                r.fb = match byte(&mut u) % 4 {
                    0 => Feedback::None,
                    1 => Feedback::Follows,
                    k if r.credit >= FAULT_CREDIT => {
                        fault_op(&r);
                        Feedback::Stuck(k == 3)
                    }
                    _ => Feedback::Follows,
                };
            }
            238..=239 => {
                fault_op(&r);
                r.g.report_actuator_fault();
                let f = r.g.faults();
                assert!(f.intersects(faults::ACTUATOR), "actuator fault not latched: {f:#x}");
            }
            240..=245 => {
                // Warm reset: the snapshot goes through the boot rule.
                let rec = r.g.snapshot();
                let boot = Restore::from_record(&rec);
                assert!(
                    !matches!(boot, Restore::Cold),
                    "a snapshot must never look like a cold boot: {rec:?}"
                );
                r.g = GuardOf::<N>::new(&r.cfg, boot);
            }
            _ => {
                fault_op(&r);
                let mut y = [0.0f32; 6];
                for v in y.iter_mut() {
                    *v = f32_raw(&mut u);
                }
                r.tick(Some(&to_sample(&y)), false);
            }
        }
    }
}

/// Operations that can latch a fault (the missing burst only from
/// `stale_ticks` on, but it is counted as one).
fn is_fault_op(sel: u8) -> bool {
    matches!(sel, 192..=221 | 238..=239 | 246..=255)
}

/// `n` valid ticks: every channel moves by its slope × its rate limit,
/// reflected at the inset range; then a maintenance `clear_faults` attempt
/// when a fault is latched.
fn ramp<N: Num>(r: &mut Run<N>, x: &mut [f32; 6], slope: &mut [f32; 6], ch: &[Chan; 6], n: u32) {
    for _ in 0..n {
        for ((x, s), c) in x.iter_mut().zip(slope.iter_mut()).zip(ch) {
            let (lo, hi) = c.inset();
            let mut y = *x + *s * c.rate;
            if y > hi {
                y = 2.0 * hi - y;
                *s = -*s;
            } else if y < lo {
                y = 2.0 * lo - y;
                *s = -*s;
            }
            *x = y.clamp(lo, hi);
        }
        r.tick(Some(&to_sample(x)), true);
    }
    if r.g.faults().intersects(faults::LATCHED) {
        r.clear();
    }
}

fn fault_op<N: Num>(r: &Run<N>) {
    if r.stats {
        stats::FAULT_OPS.fetch_add(1, Relaxed);
    }
}
