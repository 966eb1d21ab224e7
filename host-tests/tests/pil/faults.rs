//! Fault injection against the real firmware in QEMU: corrupted, truncated,
//! out-of-order and garbage frames are rejected and counted without hanging;
//! a firmware that stops answering is a timeout; an abnormal exit is named.
//!
//! Needs `qemu-system-arm` (CI installs it); without it these tests FAIL with
//! a message saying so, they do not skip.

use std::time::{Duration, Instant};

use eha_guard::protocol::{Reply, ReplyKind, Request};
use eha_sim::pil::{firmware_for_tests, require_qemu, Build, PilError, QemuOptions, QemuSession};

fn sample(seq: u16) -> Request {
    let current_a = eha_sim::pil::drill::motor_current(60.0, 5.0, 1500.0);
    Request { seq, current_a, p_a_bar: 60.0, p_b_bar: 5.0, speed_rpm: 1500.0, position_mm: 10.0, ambient_c: 22.0, valve_fb: None }
}

/// Number of non-empty frames (segments ended by 0x00) in `bytes`, given
/// that the firmware's deframer was idle before them: that is exactly the
/// number of replies the firmware owes.
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

fn exchange(s: &mut QemuSession, bytes: &[u8], step: u64) -> Vec<Reply> {
    s.send(bytes).unwrap_or_else(|e| panic!("{e}"));
    (0..frames_in(bytes)).map(|_| s.recv(step).unwrap_or_else(|e| panic!("{e}"))).collect()
}

#[test]
fn corrupted_truncated_out_of_order_and_garbage_frames_are_rejected_and_counted() {
    let mut s = session(Build::F32);
    let t0 = Instant::now();
    let mut expected_rejects = 0u32;
    let mut seq = 0u16;

    let r = exchange(&mut s, &sample(seq).encode(), 0);
    assert_eq!((r[0].kind, r[0].seq), (ReplyKind::Tick, 0));

    // Every single-bit corruption of the next frame (terminator included; a
    // trailing 0x00 resyncs in case the flip removed or added a delimiter).
    seq += 1;
    let good = sample(seq).encode();
    for bit in 0..good.len() * 8 {
        let mut bad = good.to_vec();
        bad[bit / 8] ^= 1 << (bit % 8);
        bad.push(0);
        let replies = exchange(&mut s, &bad, bit as u64);
        for rep in &replies {
            assert!(matches!(rep.kind, ReplyKind::Reject(_)), "bit {bit}: corrupted frame accepted: {rep:?}");
        }
        expected_rejects += replies.len() as u32;
    }
    // The uncorrupted frame with the same sequence number is accepted: no
    // corrupted copy stepped the guard.
    let r = exchange(&mut s, &good, 1000);
    assert_eq!((r[0].kind, r[0].seq), (ReplyKind::Tick, seq));
    assert_eq!(r[0].counters.rejected(), expected_rejects);

    // Truncation at every length.
    seq += 1;
    let good = sample(seq).encode();
    for cut in 1..good.len() - 1 {
        let mut bad = good[..cut].to_vec();
        bad.push(0);
        let replies = exchange(&mut s, &bad, 2000 + cut as u64);
        assert_eq!(replies.len(), 1);
        assert!(matches!(replies[0].kind, ReplyKind::Reject(_)), "cut {cut}: {:?}", replies[0]);
        expected_rejects += 1;
    }
    let r = exchange(&mut s, &good, 3000);
    assert_eq!(r[0].kind, ReplyKind::Tick);

    // Out of order: a duplicate and an older frame.
    for old in [seq, seq - 1] {
        let r = exchange(&mut s, &sample(old).encode(), 4000);
        assert_eq!(r[0].kind, ReplyKind::Reject(eha_guard::protocol::RejectReason::Sequence));
        expected_rejects += 1;
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
    let replies = exchange(&mut s, &garbage, 5000);
    assert!(replies.iter().all(|r| matches!(r.kind, ReplyKind::Reject(_))));
    expected_rejects += replies.len() as u32;
    seq += 1;
    let r = exchange(&mut s, &sample(seq).encode(), 6000);
    assert_eq!(r[0].kind, ReplyKind::Tick);
    assert_eq!(r[0].counters.rejected(), expected_rejects, "every bad frame counted exactly once");
    assert_eq!(r[0].counters.accepted, 4);

    // A truncated frame right before end of input: the firmware still
    // finishes with its completion marker and exit code 0.
    s.send(&good[..5]).unwrap();
    let end = s.finish(7000).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(end.done.counters.rejected(), expected_rejects);
    assert_eq!(end.done.counters.accepted, 4);
    eprintln!(
        "fault injection: {} rejected frames handled in {:.2} s",
        expected_rejects,
        t0.elapsed().as_secs_f64()
    );
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
    s.send(&sample(0).encode()).unwrap();
    match s.recv(0) {
        Err(PilError::Timeout { tick: 0, .. }) => {}
        other => panic!("expected a timeout, got {other:?}"),
    }
    // Reported within the timeout plus slack, not hanging.
    assert!(t0.elapsed() < Duration::from_secs(5));
}

#[test]
fn firmware_waiting_on_an_unterminated_frame_is_a_timeout() {
    require_qemu();
    let elf = firmware_for_tests(Build::F32);
    let mut opts = QemuOptions::new(Build::F32, &elf);
    opts.icount = false;
    opts.reply_timeout = Duration::from_millis(1500);
    let mut s = QemuSession::spawn(&opts).unwrap();
    let frame = sample(0).encode();
    // All bytes but the delimiter: the firmware rightly waits for more, and
    // the host must report that no answer came rather than wait forever.
    s.send(&frame[..frame.len() - 1]).unwrap();
    let t0 = Instant::now();
    match s.recv(0) {
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
    let _ = s.send(&sample(0).encode());
    match s.recv(0) {
        Err(PilError::Exited { code: Some(3), meaning, .. }) => assert_eq!(meaning, "firmware HardFault"),
        other => panic!("expected HardFault exit code 3, got {other:?}"),
    }
}
