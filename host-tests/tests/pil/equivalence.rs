//! The product application in QEMU (the PIL image) answers exactly like the
//! same application on the host (SIL, the shared in-memory board), tick by
//! tick, for both numeric builds.
//!
//! Open loop here (the closed-loop scenarios are in `scenarios.rs`): the
//! drill sequence of `eha_sim::pil::drill` (60,000 ticks at the firmware's
//! 10 ms step, valve open/close, lost frames, non-finite and out-of-range
//! samples), so the fault paths are compared too.
//!
//! Tolerance: none. Both builds must be bit-identical. For the fixed-point
//! build that is the requirement. For f32 it is what we measure and keep:
//! the firmware and the host run the same Rust code under IEEE-754 binary32
//! with round-to-nearest, no fused multiply-add contraction (Rust does not
//! contract), and a software square root (no libm/FPU difference), so there
//! is no source of rounding difference; a mismatch would point at a real
//! defect (UB, a target-dependent code path), which is what this guards.

use std::time::Instant;

use eha_guard::product::wire::TickReply;
use eha_sim::pil::report::compare;
use eha_sim::pil::sil::SilTarget;
use eha_sim::pil::{firmware_for_tests, require_qemu, run_drill, Build, QemuOptions, QemuSession};

const STEPS: u32 = eha_sim::pil::drill::STEPS;

fn run_qemu(build: Build, samples: &[Option<eha_guard::protocol::Request>]) -> (Vec<TickReply>, f64) {
    require_qemu();
    let elf = firmware_for_tests(build);
    let mut opts = QemuOptions::new(build, &elf);
    opts.icount = false;
    let mut s = QemuSession::spawn(&opts).unwrap_or_else(|e| panic!("{e}"));
    let t0 = Instant::now();
    let replies: Vec<TickReply> = run_drill(&mut s, samples).unwrap_or_else(|e| panic!("{e}")).into_iter().map(|o| o.reply).collect();
    let secs = t0.elapsed().as_secs_f64();
    let end = s.finish(samples.len() as u64).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(end.done.counters.accepted, samples.len() as u32 - 13);
    assert_eq!(end.done.counters.missing, 3 + 10);
    (replies, secs)
}

fn check(build: Build) {
    let samples = eha_sim::pil::drill::requests();
    let (fw, secs) = run_qemu(build, &samples);
    let mut sil = SilTarget::new(build);
    let host: Vec<TickReply> = run_drill(&mut sil, &samples).unwrap().into_iter().map(|o| o.reply).collect();
    let c = compare(&fw, &host);
    let valve_steps = fw.iter().filter(|r| r.out.valve_open).count();
    let faults = fw.last().map_or(eha_guard::Faults::NONE, |r| r.out.faults);
    eprintln!(
        "{}: {} ticks in {:.2} s = {:.0} round trips/s; identical {}/{}; max drain diff {:.3e} K; valve open {} steps; final faults {:#x}; peak drain {:.2} C",
        build.name(),
        fw.len(),
        secs,
        fw.len() as f64 / secs,
        c.identical,
        c.ticks,
        c.max_drain_diff_k,
        valve_steps,
        faults,
        fw.iter().map(|r| r.out.drain_c).fold(f32::MIN, f32::max),
    );
    let first_fault = fw.iter().position(|r| r.out.faults.intersects(eha_guard::faults::LATCHED));
    let first_open = fw.iter().position(|r| r.out.valve_open);
    let drains: Vec<String> = fw.iter().step_by(5000).map(|r| format!("{:.2}", r.out.drain_c)).collect();
    eprintln!("  first fault at step {first_fault:?}, first valve open at {first_open:?}, drain every 50 s: {}", drains.join(" "));
    assert_eq!(c.ticks, STEPS as usize);
    assert_eq!(c.identical, c.ticks, "first difference at step {:?}: fw {:?} vs sil {:?}", c.first_difference, c.first_difference.map(|k| fw[k]), c.first_difference.map(|k| host[k]));
    // The sequence exercised what it is meant to: faults were raised and the valve opened.
    assert!(!faults.is_empty(), "the injected bad samples must have latched a fault");
    // ... and, before any fault, the valve opened on temperature and closed again.
    let ff = first_fault.expect("a fault");
    let opened = first_open.expect("the valve opened");
    assert!(opened < ff && fw[opened..ff].iter().any(|r| !r.out.valve_open), "valve must open and close normally before the faults");
}

#[test]
fn f32_firmware_in_qemu_equals_host_sil_bit_for_bit() {
    check(Build::F32);
}

#[test]
fn fixed_point_firmware_in_qemu_equals_host_sil_bit_for_bit() {
    check(Build::Fixed);
}
