//! The checks a reader input must pass, shared by the fuzz targets (`fuzz/`,
//! nightly) and their stable fallback (`reader_props`, `cargo test`): every
//! input gives a value or an error, never a panic, and what a reader accepts
//! must satisfy the format's rules and round-trip. They panic on a violation
//! (that is how both harnesses see it).

use crate::measured::MeasuredRun;
use crate::rig::Rig;
use crate::scenario::{read_mission_str, ValveRule};

/// The measured-data reader: an accepted run validates and round-trips.
pub fn check_measured(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    if let Ok(run) = MeasuredRun::from_str_named("fuzz.csv", &text) {
        run.validate("fuzz.csv").expect("an accepted run must validate");
        let mut out = Vec::new();
        run.write(&mut out).expect("an accepted run must be writable");
        let text2 = String::from_utf8(out).expect("writer emits UTF-8");
        let back = MeasuredRun::from_str_named("rt.csv", &text2).expect("written run must read back");
        assert_eq!(back.time_s, run.time_s);
        assert_eq!(back.channels, run.channels);
    }
}

/// The mission reader: an accepted mission can be evaluated and every
/// value it yields is finite.
pub fn check_mission(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    if let Ok(m) = read_mission_str(&text, "fuzz.csv", "fuzz", ValveRule::None) {
        assert!(!m.ambient_c.0.is_empty());
        assert!(m.duration_s.is_finite());
        for t in [-1.0, 0.0, 0.5 * m.duration_s, m.duration_s, m.duration_s + 1.0] {
            let (x, v_x) = m.position.at(t);
            let v = [m.ambient_c.at(t), m.speed_rpm.at(t), m.needle_bar.at(t), x, v_x, m.air_speed_mps.at(t)];
            assert!(v.iter().all(|x| x.is_finite()), "accepted mission yields a non-finite value at {t} s: {v:?}");
        }
    }
}

/// The rig loader and the override parser (first line).
pub fn check_rig(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    if let Ok(rig) = Rig::from_toml_str(&text, "fuzz.toml") {
        let back = Rig::from_toml_str(&rig.to_toml(), "rt.toml");
        assert!(back.is_ok(), "an accepted rig must round-trip: {back:?}");
    }
    let first = text.lines().next().unwrap_or("");
    let mut rig = Rig::default();
    let _ = rig.set_override(first);
}
