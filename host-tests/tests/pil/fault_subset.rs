//! A representative subset of the fault campaign (`eha_sim::faults`) with the
//! PIL image in QEMU (f32, the product application in lockstep over
//! semihosting) instead of the host application: input faults on the three
//! channels that carry the pump's heat (current reading low, a port
//! pressure stuck at zero, a non-finite speed), a speed sensor reading half,
//! corrupted frames and a controller clearing every second (armed and keyed
//! commands over the wire), during the Fig. 15 LNG case, the early start.
//! The image ticks exactly as the host twin does: each result must equal
//! the host campaign's, field for field (the tick replies are
//! bit-identical, `pil::equivalence`), including its pass/fail verdict.

use eha_sim::faults::inject::{Channel, Fault, InputFault};
use eha_sim::faults::{run_case, run_one, scenario, Case, Start, StartKind, FAULT_AT_S};
use eha_sim::pil::{firmware_for_tests, require_qemu, Build, QemuOptions, QemuSession};

#[test]
fn fault_subset_in_qemu_equals_the_host_campaign() {
    require_qemu();
    let elf = firmware_for_tests(Build::F32);
    let spec = scenario("lng").expect("the LNG case");
    let start = Start { kind: StartKind::Early, at_s: FAULT_AT_S };
    let faults = [
        Fault::Input(Channel::Current, InputFault::GainHalf),
        Fault::Input(Channel::PressureA, InputFault::StuckZero),
        Fault::Input(Channel::Speed, InputFault::NaN),
        Fault::Input(Channel::Speed, InputFault::GainHalf),
        Fault::CorruptedFrames,
        Fault::ClearSpam,
    ];
    for f in faults {
        let mut q = QemuOptions::new(Build::F32, &elf);
        q.icount = false;
        let mut session = QemuSession::spawn(&q).unwrap_or_else(|e| panic!("qemu: {e}"));
        let pil = run_case(Case::new(f), &spec, start, Some(&mut session)).unwrap_or_else(|e| panic!("{e:#}"));
        let _ = session.abort();
        let sil = run_one(Case::new(f), &spec, start).unwrap_or_else(|e| panic!("{e:#}"));
        println!("{} in QEMU: detected {:?} after {:?} s, max under {:.3} K, pass {}", pil.fault, pil.detect_bits, pil.detect_s, pil.max_under_k, pil.pass);
        assert_eq!(pil, sil, "{}: QEMU and host SIL differ", f.name());
    }
}
