//! The parameter block as the firmware reads it at boot (`params_block::view`,
//! then the model's value and stability checks, then the guard). Two modes,
//! by the first byte: raw bytes (the header and CRC checks), or the paper
//! rig's words with fuzzed words patched in and a correct CRC (so that the
//! value and stability checks see arbitrary constants). Never panics; a block
//! the model refuses gives CONFIG with the valve open; an accepted one gives
//! finite outputs or a latched fault.
#![no_main]
use eha_guard::model::consts::N_WORDS;
use eha_guard::model::ModelConsts;
use eha_guard::model::DEFAULT_CONSTS;
use eha_guard::params_block::{encode, view, BLOCK_LEN};
use eha_guard::{faults, GuardConfig, GuardOf, Restore, Sample};
use libfuzzer_sys::fuzz_target;

#[repr(C, align(8))]
struct Flash([u8; BLOCK_LEN]);

fuzz_target!(|data: &[u8]| {
    let Some((&mode, rest)) = data.split_first() else { return };
    let mut flash = Flash([0xFF; BLOCK_LEN]);
    if mode & 1 == 0 {
        let n = rest.len().min(BLOCK_LEN);
        flash.0[..n].copy_from_slice(&rest[..n]);
    } else {
        let mut words: Vec<f32> = Vec::with_capacity(N_WORDS);
        DEFAULT_CONSTS.for_each(|x| words.push(x));
        for chunk in rest.chunks_exact(5) {
            let i = usize::from(chunk[0]) * 7 % N_WORDS;
            words[i] = f32::from_le_bytes([chunk[1], chunk[2], chunk[3], chunk[4]]);
        }
        let mut it = words.into_iter();
        let c = ModelConsts::from_words(|| it.next().unwrap_or(f32::NAN));
        flash.0 = encode(&c, "fuzz");
    }
    let Ok(Some(c)) = view(&flash.0) else { return };
    let cfg = GuardConfig { model: c, ..GuardConfig::DEFAULT };
    let mut g = GuardOf::<f32>::new(&cfg, Restore::Cold);
    let refused = g.faults().intersects(faults::CONFIG);
    let s = Sample { current_a: 40.0, p_a_bar: 60.0, p_b_bar: 5.0, speed_rpm: 500.0, position_mm: 0.0, ambient_c: 25.0 };
    for _ in 0..50 {
        let o = g.tick(&s);
        if refused {
            assert!(o.valve_open && o.faults.intersects(faults::CONFIG), "refused block: {o:?}");
        } else {
            assert!(o.drain_c.is_finite() || !o.faults.is_empty(), "accepted block, non-finite estimate without a fault: {o:?}");
        }
    }
});
