//! The mission CSV reader (`scenario::read_mission_str`, the text form of
//! `read_mission_csv`): any text must give a mission or an error, never a
//! panic or a hang. An accepted mission is evaluated at a few times.
#![no_main]
use eha_sim::scenario::{read_mission_str, ValveRule};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(m) = read_mission_str(&text, "fuzz.csv", "fuzz", ValveRule::None) {
        assert!(!m.ambient_c.0.is_empty());
        for t in [-1.0, 0.0, 0.5 * m.duration_s, m.duration_s, m.duration_s + 1.0] {
            let _ = m.ambient_c.at(t);
            let _ = m.speed_rpm.at(t);
            let _ = m.needle_bar.at(t);
            let _ = m.position.at(t);
            let _ = m.air_speed_mps.at(t);
        }
    }
});
