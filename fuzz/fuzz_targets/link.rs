//! Frame decoder and link: `Link::push_bytes` with a real f32 guard behind
//! it, and the request/reply/COBS decoders (see `src/link.rs`).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    eha_guard_fuzz::link::run(data);
});
