//! The thermal record: its CRC catches any single-bit corruption, and the
//! boot rules (cold, warm, corrupt) on what a record holds.

use eha_guard::faults;
use eha_guard::memory::{RecordStatus, Restore, ThermalRecord, RECORD_BYTES};
use eha_guard::{GuardConfig, GuardOf};
use proptest::prelude::*;

use crate::protection_props::{nominal, ulp32};

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn record_roundtrip_and_single_bit_corruption(
        temps in proptest::array::uniform6(-40.0f32..200.0), amb in -40.0f32..80.0,
        used in any::<u32>(), faults_w in any::<u32>(), step in any::<u32>(), bit in 0usize..(RECORD_BYTES * 8),
    ) {
        let r = ThermalRecord::new(temps, amb, used, faults_w, step);
        prop_assert_eq!(r.classify(), RecordStatus::Valid);
        let bytes = record_bytes(&r);
        let mut b = bytes;
        b[bit / 8] ^= 1 << (bit % 8);
        let c = record_from_bytes(&b);
        // Padding-free layout: bytes 48..52 are `seq_flags`, 52..56 the RTC stamp, 56..60 the CRC; every bit counts.
        prop_assert_eq!(c.classify(), RecordStatus::Corrupt, "flip of bit {} undetected", bit);
    }
}

fn record_bytes(r: &ThermalRecord) -> [u8; RECORD_BYTES] {
    r.to_le_bytes()
}

fn record_from_bytes(b: &[u8; RECORD_BYTES]) -> ThermalRecord {
    ThermalRecord::from_le_bytes(b)
}

#[test]
fn boot_rules_cold_warm_corrupt() {
    let cfg = GuardConfig::DEFAULT;
    // Cold: starts at the first ambient sample (16 degC), valve closed.
    let mut g = GuardOf::<f32>::new(&cfg, Restore::from_record(&ThermalRecord::EMPTY));
    let o = g.tick(&nominal());
    crate::plant::follow(&g);
    assert!(
        (o.drain_c - 16.0).abs() < 0.01 && !o.valve_open,
        "cold: {o:?}"
    );
    // Regression bound: the first tick reports the start estimate itself (no model
    // step yet): measured exactly 16.0, bound one f32 ulp.
    assert!((o.drain_c - 16.0).abs() <= ulp32(16.0), "cold: {o:?}");
    // Warm: 45 degC record restored although the ambient is 16 degC → valve opens.
    let rec = ThermalRecord::new(
        [50.0, 45.0, 46.0, 44.0, 30.0, 45.0],
        20.0,
        1_000_000,
        0,
        123,
    );
    let mut g = GuardOf::<f32>::new(&cfg, Restore::from_record(&rec));
    g.valve_feedback(true);
    let o = g.tick(&nominal());
    crate::plant::follow(&g);
    assert!(
        (o.drain_c - 45.0).abs() < 0.05 && o.valve_open && !o.faults.intersects(faults::LATCHED | faults::NO_VALVE_FEEDBACK),
        "warm: {o:?}"
    );
    // Regression bound: the restored drain node itself, measured exactly 45.0.
    assert!((o.drain_c - 45.0).abs() <= ulp32(45.0), "warm: {o:?}");
    // Snapshot → record → restore round trip keeps every node within 1e-4 K. (The
    // valve state is not in the record: after a reset the valve output restarts
    // closed, so the restored guard's first step takes no exchanger credit, while
    // `g` keeps its open valve; comparing their next outputs would compare that.)
    let snap = g.snapshot();
    assert_eq!(snap.classify(), RecordStatus::Valid);
    let g2 = GuardOf::<f32>::new(&cfg, Restore::from_record(&snap));
    let snap2 = g2.snapshot();
    for (a, b) in snap.temps_c.iter().zip(snap2.temps_c.iter()) {
        assert!((a - b).abs() < 1e-4, "{a} vs {b}");
        // Regression bound: the f32 round trip measures exactly 0; one ulp.
        assert!((a - b).abs() <= ulp32(*a), "{a} vs {b}: regression bound 1 ulp (measured 0)");
    }
    // Corrupt: conservative 60 degC start, valve open, MEMORY_CORRUPT latched, LNG empty.
    let mut bad = rec;
    bad.temps_c[5] = 20.0;
    assert_eq!(bad.classify(), RecordStatus::Corrupt);
    let mut g = GuardOf::<f32>::new(&cfg, Restore::from_record(&bad));
    let o = g.tick(&nominal());
    crate::plant::follow(&g);
    assert!(
        (o.drain_c - 60.0).abs() < 0.05 && o.valve_open,
        "corrupt: {o:?}"
    );
    // Regression bound: the conservative start itself, measured exactly 60.0.
    assert!((o.drain_c - 60.0).abs() <= ulp32(60.0), "corrupt: {o:?}");
    assert!(o.faults.intersects(faults::MEMORY_CORRUPT) && o.lng_remaining_kg == 0.0);
}
