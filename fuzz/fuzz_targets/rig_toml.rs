//! The rig TOML loader (`Rig::from_toml_str`) and the `--set` override parser
//! (`Rig::set_override`, on the input's first line): errors, never a panic or
//! a hang. An accepted rig must write back to TOML that loads again.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| eha_sim::reader_checks::check_rig(data));
