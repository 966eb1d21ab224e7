//! The strict measured-data reader (`MeasuredRun::from_str_named`): any text
//! must give a run or an error, never a panic or a hang. An accepted run must
//! satisfy the format's rules (`validate`) and survive a write/read round trip.
#![no_main]
use eha_sim::measured::MeasuredRun;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
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
});
