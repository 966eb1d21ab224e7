//! Fault injection against the PIL image in QEMU: corrupted, truncated,
//! out-of-order and garbage frames are rejected and counted without hanging;
//! a firmware that stops answering is a timeout; an abnormal exit is named.
//!
//! Needs `qemu-system-arm` (CI installs it); without it these tests FAIL with
//! a message saying so, they do not skip.

use std::time::{Duration, Instant};

use eha_guard::protocol::Request;
use eha_sim::pil::{firmware_for_tests, require_qemu, Build, PilError, QemuOptions, QemuSession, Target};

fn sample(seq: u16) -> Request {
    // (the viscous friction at 40 degC: these tests are about frames, not heat)
    let current_a = eha_sim::pil::drill::motor_current(60.0, 5.0, 1500.0, 40.0);
    let sample = eha_guard::Sample { current_a, p_a_bar: 60.0, p_b_bar: 5.0, speed_rpm: 1500.0, position_mm: 10.0, ambient_c: 22.0 };
    Request { seq, sample, reports: eha_guard::Reports::default() }
}

/// Number of non-empty frames (segments ended by 0x00) in `bytes`, given
/// that the firmware's deframer was idle before them: each is counted once,
/// accepted or rejected.
fn frames_in(bytes: &[u8]) -> usize {
    let mut n = 0;
    let mut open = false;
    for &b in bytes {
        if b == 0 {
            if open {
                n += 1;
            }
            open = false;
        } else {
            open = true;
        }
    }
    n
}

fn session(build: Build) -> QemuSession {
    require_qemu();
    let elf = firmware_for_tests(build);
    let mut opts = QemuOptions::new(build, &elf);
    opts.icount = false;
    opts.reply_timeout = Duration::from_secs(10);
    QemuSession::spawn(&opts).unwrap_or_else(|e| panic!("{e}"))
}

/// One tick with `bytes`: (the sample it used, frames rejected so far).
fn tick(s: &mut QemuSession, bytes: &[u8], step: u64) -> (Option<u16>, u16) {
    let r = s.tick(bytes, step).unwrap_or_else(|e| panic!("{e}")).reply;
    (r.fresh.then_some(r.sample_seq), r.rejected)
}

#[test]
fn corrupted_truncated_out_of_order_and_garbage_frames_are_rejected_and_counted() {
    let mut s = session(Build::F32);
    let t0 = Instant::now();
    let mut expected_rejects = 0u16;
    let mut seq = 0u16;

    assert_eq!(tick(&mut s, &sample(seq).encode(), 0).0, Some(0));

    // Every single-bit corruption of the next frame (terminator included; a
    // trailing 0x00 resyncs in case the flip removed or added a delimiter).
    seq += 1;
    let good = sample(seq).encode();
    for bit in 0..good.len() * 8 {
        let mut bad = good.to_vec();
        bad[bit / 8] ^= 1 << (bit % 8);
        bad.push(0);
        let (used, rejected) = tick(&mut s, &bad, bit as u64);
        assert_eq!(used, None, "bit {bit}: corrupted frame used");
        expected_rejects += frames_in(&bad) as u16;
        assert_eq!(rejected, expected_rejects, "bit {bit}");
    }
    // The uncorrupted frame with the same sequence number is used: no
    // corrupted copy was accepted.
    assert_eq!(tick(&mut s, &good, 1000), (Some(seq), expected_rejects));

    // Truncation at every length.
    seq += 1;
    let good = sample(seq).encode();
    for cut in 1..good.len() - 1 {
        let mut bad = good[..cut].to_vec();
        bad.push(0);
        let (used, rejected) = tick(&mut s, &bad, 2000 + cut as u64);
        expected_rejects += 1;
        assert_eq!((used, rejected), (None, expected_rejects), "cut {cut}");
    }
    assert_eq!(tick(&mut s, &good, 3000).0, Some(seq));

    // Out of order: a duplicate and an older frame.
    for old in [seq, seq - 1] {
        expected_rejects += 1;
        assert_eq!(tick(&mut s, &sample(old).encode(), 4000), (None, expected_rejects));
    }

    // Garbage (deterministic LCG bytes), then a good frame.
    let mut x: u32 = 12345;
    let garbage: Vec<u8> = (0..5000)
        .map(|_| {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
            (x >> 16) as u8
        })
        .chain([0])
        .collect();
    for (k, part) in garbage.chunks(500).enumerate() {
        let (used, _) = tick(&mut s, part, 5000 + k as u64);
        assert_eq!(used, None);
    }
    expected_rejects += frames_in(&garbage) as u16;
    seq += 1;
    assert_eq!(tick(&mut s, &sample(seq).encode(), 6000), (Some(seq), expected_rejects), "every bad frame counted exactly once");

    // A truncated frame right before end of input: the firmware still
    // finishes with its completion marker and exit code 0.
    let _ = s.tick(&good[..5], 7000).unwrap_or_else(|e| panic!("{e}"));
    let end = s.finish(7001).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(end.done.counters.accepted, 4);
    eprintln!("fault injection: {expected_rejects} rejected frames handled in {:.2} s", t0.elapsed().as_secs_f64());
}

#[test]
fn firmware_that_never_answers_is_a_timeout_not_a_pass() {
    require_qemu();
    let elf = firmware_for_tests(Build::F32);
    let mut opts = QemuOptions::new(Build::F32, &elf);
    opts.icount = false;
    opts.reply_timeout = Duration::from_millis(1500);
    // `-S`: the CPU never starts, exactly like a firmware hung before its loop.
    opts.extra_args = vec!["-S".into()];
    let mut s = QemuSession::spawn(&opts).unwrap();
    let t0 = Instant::now();
    match s.tick(&sample(0).encode(), 0) {
        Err(PilError::Timeout { tick: 0, .. }) => {}
        other => panic!("expected a timeout, got {other:?}"),
    }
    // Reported within the timeout plus slack, not hanging.
    assert!(t0.elapsed() < Duration::from_secs(5));
}

#[test]
fn firmware_waiting_on_an_unfinished_chunk_is_a_timeout() {
    require_qemu();
    let elf = firmware_for_tests(Build::F32);
    let mut opts = QemuOptions::new(Build::F32, &elf);
    opts.icount = false;
    opts.reply_timeout = Duration::from_millis(1500);
    let mut s = QemuSession::spawn(&opts).unwrap();
    // A chunk header that promises more bytes than follow: the firmware
    // rightly waits for them, and the host must report that no answer came
    // rather than wait forever.
    s.send_raw(&[40, 0, 1, 2, 3]).unwrap();
    let t0 = Instant::now();
    match s.recv_tick(0) {
        Err(PilError::Timeout { .. }) => {}
        other => panic!("expected a timeout, got {other:?}"),
    }
    let waited = t0.elapsed();
    assert!(waited >= Duration::from_millis(1400) && waited < Duration::from_secs(5), "waited {waited:?}");
}

#[test]
fn hardfault_exit_code_is_reported() {
    require_qemu();
    let elf = firmware_for_tests(Build::F32);
    // Hard-float M4F code on a Cortex-M3 without FPU: the first FP
    // instruction faults; the firmware's HardFault handler exits with 3.
    let mut opts = QemuOptions::new(Build::F32, &elf);
    opts.machine = "mps2-an385".into();
    opts.cpu = "cortex-m3".into();
    opts.icount = false;
    let mut s = QemuSession::spawn(&opts).unwrap();
    match s.tick(&sample(0).encode(), 0) {
        Err(PilError::Exited { code: Some(3), meaning, .. }) => assert_eq!(meaning, "firmware HardFault"),
        other => panic!("expected HardFault exit code 3, got {other:?}"),
    }
}
