//! The strict measured-data reader (`MeasuredRun::from_str_named`): any text
//! must give a run or an error, never a panic or a hang. An accepted run must
//! satisfy the format's rules (`validate`) and survive a write/read round trip.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| eha_sim::reader_checks::check_measured(data));
