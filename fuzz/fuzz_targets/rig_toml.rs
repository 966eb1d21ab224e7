//! The rig TOML loader (`Rig::from_toml_str`) and the `--set` override parser
//! (`Rig::set_override`, on the input's first line): errors, never a panic or
//! a hang. An accepted rig must write back to TOML that loads again.
#![no_main]
use eha_sim::rig::Rig;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(rig) = Rig::from_toml_str(&text, "fuzz.toml") {
        let back = Rig::from_toml_str(&rig.to_toml(), "rt.toml");
        assert!(back.is_ok(), "an accepted rig must round-trip: {back:?}");
    }
    let first = text.lines().next().unwrap_or("");
    let mut rig = Rig::default();
    let _ = rig.set_override(first);
});
