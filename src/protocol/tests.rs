//! Unit tests of the wire protocol: CRC check value, COBS round trip against
//! a reference encoder, frame encode/decode, the sequence rule and the link.

extern crate std;
use super::*;

fn req(seq: u16) -> Request {
    Request {
        seq,
        sample: Sample { current_a: 12.5, p_a_bar: 80.0, p_b_bar: 3.25, speed_rpm: -1500.0, position_mm: 42.0, ambient_c: 21.0 },
        reports: Reports::default(),
    }
}

#[test]
fn crc_check_value() {
    assert_eq!(crc16(b"123456789"), 0x29B1);
    assert_eq!(crc16(b""), 0xFFFF);
    // the word-at-a-time CRC is the byte-at-a-time one at every length
    // and alignment
    let data: std::vec::Vec<u8> = (0..64u32).map(|k| (k.wrapping_mul(0x9E37_79B9) >> 13) as u8).collect();
    for start in 0..4 {
        for end in start..data.len() {
            let bytes = &data[start..end];
            let bytewise = bytes.iter().fold(0xFFFF, |c, b| super::framing::crc16_byte(c, *b));
            assert_eq!(crc16(bytes), bytewise, "{start}..{end}");
        }
    }
}

#[test]
fn cobs_known_vectors() {
    // Vectors from the COBS paper / Wikipedia.
    let cases: &[(&[u8], &[u8])] = &[
        (&[0x00], &[0x01, 0x01]),
        (&[0x00, 0x00], &[0x01, 0x01, 0x01]),
        (&[0x11, 0x22, 0x00, 0x33], &[0x03, 0x11, 0x22, 0x02, 0x33]),
        (&[0x11, 0x22, 0x33, 0x44], &[0x05, 0x11, 0x22, 0x33, 0x44]),
        (&[0x11, 0x00, 0x00, 0x00], &[0x02, 0x11, 0x01, 0x01, 0x01]),
    ];
    for (raw, enc) in cases {
        let mut out: Vec<u8, 16> = Vec::new();
        cobs_encode(raw, &mut out).unwrap();
        assert_eq!(&out[..], *enc);
        let mut dec: Vec<u8, 16> = Vec::new();
        cobs_decode(enc, &mut dec).unwrap();
        assert_eq!(&dec[..], *raw);
    }
}

#[test]
fn cobs_long_run() {
    // 254 non-zero bytes need the 0xFF code block.
    let raw: [u8; 300] = core::array::from_fn(|i| (i % 255) as u8 + 1);
    let mut out: Vec<u8, 310> = Vec::new();
    cobs_encode(&raw, &mut out).unwrap();
    assert!(!out.contains(&0));
    let mut dec: Vec<u8, 310> = Vec::new();
    cobs_decode(&out, &mut dec).unwrap();
    assert_eq!(&dec[..], &raw[..]);
}

#[test]
fn request_round_trip_and_size() {
    let r = req(7);
    let wire = r.encode();
    assert_eq!(wire.last(), Some(&0));
    assert_eq!(wire.iter().filter(|&&b| b == 0).count(), 1);
    let mut d = Deframer::new();
    let mut got = None;
    for &b in wire.iter() {
        if let Some(p) = d.push(b) {
            got = Some(Request::from_payload(p.unwrap()).unwrap());
        }
    }
    assert_eq!(got, Some(r));
}

#[test]
fn request_valve_feedback_flags() {
    // None / shut / open round-trip through the flags byte (offset 27).
    for fb in [None, Some(false), Some(true)] {
        let r = Request { reports: Reports { valve_fb: fb, ..Reports::default() }, ..req(3) };
        let p = r.to_payload();
        assert_eq!(p.len(), REQUEST_LEN);
        assert_eq!(p[27], match fb { None => 0, Some(false) => 1, Some(true) => 3 });
        assert_eq!(Request::from_payload(&p), Ok(r));
    }
    // Reserved bits, or "open" without "reported", are rejected; a flag
    // for an optional field that is not there is a length error.
    for flags in [2u8, 0x10, 0x80, 0xff, 0x06] {
        let mut p = req(3).to_payload();
        p[27] = flags;
        assert_eq!(Request::from_payload(&p), Err(DecodeError::Kind), "flags {flags:#x}");
    }
    for flags in [FLAG_ELEC_HZ, FLAG_LNG_SUPPLY, FLAG_ELEC_HZ | FLAG_LNG_SUPPLY] {
        let mut p = req(3).to_payload();
        p[27] = flags;
        assert_eq!(Request::from_payload(&p), Err(DecodeError::Length), "flags {flags:#x}");
    }
    // The optional fields round-trip, each alone and both.
    for (hz, lng) in [(Some(33.5), None), (None, Some(4.5)), (Some(-12.0), Some(0.0))] {
        let r = Request { reports: Reports { elec_hz: hz, lng_supply_bar: lng, valve_fb: Some(true) }, ..req(4) };
        let p = r.to_payload();
        assert_eq!(p.len(), REQUEST_LEN + 4 * usize::from(hz.is_some()) + 4 * usize::from(lng.is_some()));
        assert_eq!(Request::from_payload(&p), Ok(r));
    }
    // A version-1 frame (kind 0x01) is refused.
    let mut p = req(3).to_payload();
    p[0] = 0x01;
    assert_eq!(Request::from_payload(&p), Err(DecodeError::Kind));
}

#[test]
fn deframer_refuses_damaged_frames_and_recovers() {
    let wire = req(1).encode();
    let mut d = Deframer::new();
    // every single-bit flip: refused (or split into refused pieces), never accepted
    for bit in 0..wire.len() * 8 {
        let mut bad = wire.to_vec();
        bad[bit / 8] ^= 1 << (bit % 8);
        bad.push(0);
        for &b in &bad {
            if let Some(r) = d.push(b) {
                assert!(r.is_err(), "bit {bit}: accepted");
            }
        }
        assert!(!d.pending());
    }
    // truncation at every length
    for cut in 1..wire.len() - 1 {
        let mut bytes = wire[..cut].to_vec();
        bytes.push(0);
        let got: std::vec::Vec<bool> = bytes.iter().filter_map(|&b| d.push(b).map(|r| r.is_ok())).collect();
        assert_eq!(got, [false], "cut {cut}");
    }
    // overflow: refused once, then the next frame is accepted
    let mut bytes = [0x55u8; 500].to_vec();
    bytes.push(0);
    bytes.extend_from_slice(&wire);
    let got: std::vec::Vec<Result<std::vec::Vec<u8>, DecodeError>> =
        bytes.iter().filter_map(|&b| d.push(b).map(|r| r.map(|p| p.to_vec()))).collect();
    assert_eq!(got.len(), 2);
    assert_eq!(got[0], Err(DecodeError::Overflow));
    assert_eq!(Request::from_payload(got[1].as_ref().unwrap()), Ok(req(1)));
    // empty frames are ignored
    assert!([0u8, 0, 0].iter().all(|&b| d.push(b).is_none()));
}

/// The one-pass encoder gives the bytes of the reference COBS encoder over
/// payload + CRC, for every payload length up to the largest.
#[test]
fn frame_equals_the_reference_encoding() {
    for n in 0..=MAX_PAYLOAD {
        let payload: std::vec::Vec<u8> = (0..n).map(|i| [0u8, 1, 0xFF, 7][i % 4] ^ (i as u8)).collect();
        for lead in [false, true] {
            let mut raw: Vec<u8, MAX_RAW> = Vec::new();
            raw.extend_from_slice(&payload).unwrap();
            raw.extend_from_slice(&crc16(&payload).to_le_bytes()).unwrap();
            let mut want: Vec<u8, MAX_WIRE> = Vec::new();
            if lead {
                want.push(0).unwrap();
            }
            cobs_encode(&raw, &mut want).unwrap();
            want.push(0).unwrap();
            assert_eq!(&framing::frame(&payload, lead)[..], &want[..], "n {n} lead {lead}");
        }
    }
}

/// What a deframer makes of a byte stream: each frame's payload, or its
/// refusal as damaged framing or as a CRC mismatch (the two counters the
/// product keeps).
fn deframe_all(bytes: &[u8], whole: bool) -> std::vec::Vec<Result<std::vec::Vec<u8>, bool>> {
    let mut d = Deframer::new();
    let mut got = std::vec::Vec::new();
    let mut keep = |r: Result<&[u8], DecodeError>| got.push(r.map(|p| p.to_vec()).map_err(|e| e == DecodeError::Crc));
    if whole {
        let mut rest = bytes;
        while !rest.is_empty() {
            let (n, r) = d.feed(rest);
            assert!(n > 0 && n <= rest.len());
            if let Some(r) = r {
                keep(r);
            }
            rest = &rest[n..];
        }
    } else {
        for &b in bytes {
            if let Some(r) = d.push(b) {
                keep(r);
            }
        }
    }
    got
}

proptest::proptest! {
    /// The whole-frame decoder and the byte-wise one agree on any stream:
    /// valid frames, frames with bytes changed, zeros dropped in or taken
    /// out, garbage and over-long runs.
    #[test]
    fn whole_frame_and_bytewise_decoding_agree(
        seqs in proptest::collection::vec(0u16..4, 1..4),
        edits in proptest::collection::vec((0usize..200, 0u8..=255), 0..6),
        garbage in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..80),
    ) {
        let mut bytes = std::vec::Vec::new();
        for s in &seqs {
            bytes.extend_from_slice(&req(*s).encode());
        }
        for (at, v) in &edits {
            let at = at % bytes.len();
            bytes[at] = *v;
        }
        bytes.extend_from_slice(&garbage);
        bytes.push(0);
        let whole = deframe_all(&bytes, true);
        proptest::prop_assert_eq!(&whole, &deframe_all(&bytes, false));
        proptest::prop_assert_eq!(&whole, &reference_deframe(&bytes));
    }
}

/// [`deframe_all`] by the reference COBS decoder: split at the zeros, decode
/// each non-empty piece, refuse it as framing when it does not decode or is
/// shorter than a CRC and a byte or longer than any frame, as CRC when the
/// CRC differs.
fn reference_deframe(bytes: &[u8]) -> std::vec::Vec<Result<std::vec::Vec<u8>, bool>> {
    let mut got = std::vec::Vec::new();
    let end = bytes.iter().rposition(|b| *b == 0).map_or(0, |z| z + 1);
    for piece in bytes[..end].split(|b| *b == 0).filter(|p| !p.is_empty()) {
        let mut raw: Vec<u8, 1024> = Vec::new();
        let r = match cobs_decode(piece, &mut raw) {
            Some(()) if raw.len() >= 3 && raw.len() <= MAX_RAW => {
                let (body, c) = raw.split_at(raw.len() - 2);
                if u16::from_le_bytes([c[0], c[1]]) == crc16(body) {
                    Ok(body.to_vec())
                } else {
                    Err(true)
                }
            }
            _ => Err(false),
        };
        got.push(r);
    }
    got
}
