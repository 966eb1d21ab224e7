//! A representative subset of the fault campaign (`eha_sim::faults`) with the
//! PIL image in QEMU (f32, the product application in lockstep over
//! semihosting) instead of the host application: input faults on the three
//! channels that carry the pump's heat (current reading low, a port
//! pressure stuck at zero, a non-finite speed), a speed sensor reading half,
//! and corrupted frames, each during the Fig. 15 LNG case. The image ticks
//! exactly as the host twin does: each result must equal the host
//! campaign's, field for field (the tick replies are bit-identical,
//! `pil::equivalence`), including its pass/fail verdict.

use eha_sim::faults::inject::{Channel, Fault, InputFault};
use eha_sim::faults::{run_on, run_one};
use eha_sim::pil::{firmware_for_tests, require_qemu, Build, QemuOptions, QemuSession};
use eha_sim::scenario::Scenario;

#[test]
fn fault_subset_in_qemu_equals_the_host_campaign() {
    require_qemu();
    let elf = firmware_for_tests(Build::F32);
    let scenario = Scenario::Lng { duration_s: eha_sim::faults::DURATION_S };
    let faults = [
        Fault::Input(Channel::Current, InputFault::GainHalf),
        Fault::Input(Channel::PressureA, InputFault::StuckZero),
        Fault::Input(Channel::Speed, InputFault::NaN),
        Fault::Input(Channel::Speed, InputFault::GainHalf),
        Fault::CorruptedFrames,
    ];
    for f in faults {
        let mut q = QemuOptions::new(Build::F32, &elf);
        q.icount = false;
        let mut session = QemuSession::spawn(&q).unwrap_or_else(|e| panic!("qemu: {e}"));
        let pil = run_on(f, "lng", &scenario, Some(&mut session)).unwrap_or_else(|e| panic!("{e:#}"));
        let _ = session.abort();
        let sil = run_one(f, "lng", &scenario).unwrap_or_else(|e| panic!("{e:#}"));
        println!("{} in QEMU: detected {} after {:?} s, max under {:.3} K, pass {}", pil.fault, pil.detected, pil.detect_s, pil.max_under_k, pil.pass);
        // NaN (the valve never closed after the fault) equals NaN here.
        let same = |a: f64, b: f64| a == b || (a.is_nan() && b.is_nan());
        assert!(
            pil.detected == sil.detected
                && pil.detect_s == sil.detect_s
                && same(pil.max_under_k, sil.max_under_k)
                && same(pil.max_true_drain_closed_c, sil.max_true_drain_closed_c)
                && pil.pass == sil.pass,
            "{}: QEMU {pil:?} and host SIL {sil:?} differ",
            f.name()
        );
    }
}
