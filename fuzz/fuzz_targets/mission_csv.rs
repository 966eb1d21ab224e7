//! The mission CSV reader (`scenario::read_mission_str`, the text form of
//! `read_mission_csv`): any text must give a mission or an error, never a
//! panic or a hang. An accepted mission is evaluated at a few times.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| eha_sim::reader_checks::check_mission(data));
