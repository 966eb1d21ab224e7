//! Host tests of the thermal records and the boot restore.

use super::*;
extern crate std;

#[test]
fn crc32_check_value() {
    // The standard CRC-32 check value of "123456789" is 0xCBF43926.
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
}

/// The word-wise record CRC is the CRC-32 of the record's bytes before
/// its `crc` field (the format's definition).
#[test]
fn record_crc_is_the_crc32_of_its_bytes() {
    let mut r = ThermalRecord::new([1.5, -2.25, 40.0, 61.75, 0.0, f32::MIN_POSITIVE], 21.0, 123_456, 0x8000_0001, 0xDEAD_BEEF);
    r.seq_flags = 0x0102_0304;
    r.rtc_s = 77;
    let mut bytes = std::vec::Vec::new();
    for w in [r.lng_used_cj, r.tick, r.magic] {
        bytes.extend_from_slice(&w.to_le_bytes());
    }
    bytes.extend_from_slice(&r.version.to_le_bytes());
    bytes.extend_from_slice(&r.reserved.to_le_bytes());
    bytes.extend_from_slice(&r.faults.to_le_bytes());
    for t in r.temps_c {
        bytes.extend_from_slice(&t.to_le_bytes());
    }
    for w in [r.ambient_c.to_bits(), r.seq_flags, r.rtc_s] {
        bytes.extend_from_slice(&w.to_le_bytes());
    }
    assert_eq!(bytes.len(), RECORD_BYTES - 4);
    assert_eq!(r.body_crc(), crc32(&bytes));
}

#[test]
fn record_has_no_padding() {
    // 4 + 4 + 4 + 2 + 2 + 4 + 6*4 + 4 + 4 + 4 + 4 = 60 bytes of fields.
    assert_eq!(core::mem::size_of::<ThermalRecord>(), RECORD_BYTES);
}
