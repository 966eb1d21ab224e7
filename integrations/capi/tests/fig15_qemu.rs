//! The C example (`examples/fig15`: a C main loop compiled with
//! arm-none-eabi-gcc against the Cortex-M4F static library) in QEMU
//! mps2-an386, in closed loop with the reference plant on the Fig. 15 case
//! (Case 1 at 60 bar with the LNG exchanger, 600 s, 60 000 ticks), and every
//! tick reply compared bit for bit with the Rust application's on the same
//! frames: the product image `eha-fw` in QEMU and its host twin (SIL).
//!
//! Tolerance: none. The C loop calls the same Rust code through the C API
//! (same compiler, same f32 operations, no fused multiply-add); a
//! difference would be a shim that does something the product loop does
//! not (a missed report, a record hook out of order), which is what this
//! guards. The replies carry the C loop's own transport fields too (tick,
//! sequence, pins read back, rejected frames), so those are compared as well.

mod common;

use std::process::Command;

use eha_guard::product::wire::TickReply;
use eha_sim::pil::report::{compare, Summary};
use eha_sim::pil::sil::SilTarget;
use eha_sim::pil::qemu::SessionEnd;
use eha_sim::pil::{firmware_for_tests, replay, require_qemu, run_closed_loop, Build, LoopOptions, QemuOptions, QemuSession, TickRecord};
use eha_sim::plant::Plant;
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;

const DURATION_S: f64 = 600.0;

/// Instructions per tick, mean and max, from SysTick cycles under -icount.
fn instructions(cycles: &[u32]) -> (f64, f64) {
    let v: Vec<f64> = cycles.iter().map(|c| f64::from(*c) / eha_sim::pil::qemu::TICKS_PER_INSTRUCTION).collect();
    (v.iter().sum::<f64>() / v.len().max(1) as f64, v.iter().cloned().fold(0.0, f64::max))
}

/// A C image (`q`, with -icount) in closed loop with the reference plant on
/// Fig. 15 for `DURATION_S`: its tick records, its end-of-run report and the
/// wall time, s. Every tick ran and every sample frame was accepted.
fn c_image_on_fig15(mut q: QemuOptions) -> (Vec<TickRecord>, SessionEnd, f64) {
    let opts = LoopOptions { tick_s: eha_guard::params::S_PER_TICK, duration_s: DURATION_S };
    let n = opts.ticks();
    q.icount = true;
    let t0 = std::time::Instant::now();
    let mut c = QemuSession::spawn(&q).unwrap_or_else(|e| panic!("{e}"));
    let mut plant = Plant::new(&Rig::default(), &Scenario::Lng { duration_s: DURATION_S }).unwrap_or_else(|e| panic!("plant: {e}"));
    let records = match run_closed_loop(&mut plant, &mut c, &opts) {
        Ok(r) => r,
        Err(f) => panic!("C image ({}) closed loop failed after {} ticks: {:#}", q.machine, f.records.len(), f.error),
    };
    let end = c.finish(n).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(records.len() as u64, n);
    assert_eq!(end.done.counters.accepted as u64, n, "the C loop accepted every sample frame");
    (records, end, t0.elapsed().as_secs_f64())
}

#[test]
fn c_example_in_qemu_equals_the_rust_application_bit_for_bit_on_fig15() {
    require_qemu();
    let lib = common::staticlib(Some("thumbv7em-none-eabihf"));
    let elf = common::scratch("fig15").join("fig15.elf");
    common::run(Command::new(common::crate_dir().join("examples/fig15/build.sh")).arg(&elf).arg(&lib), "building the C example");
    let size = common::run(Command::new("arm-none-eabi-size").arg(&elf), "arm-none-eabi-size");
    let lib_bytes = std::fs::metadata(&lib).map(|m| m.len()).unwrap_or(0);
    eprintln!("C example (arm-none-eabi-gcc, libeha_guard_capi.a {lib_bytes} B with debug info):\n{size}");
    // No panicking path of the Rust core is linked into the C image (the
    // core's denied lints leave none; the panic handler would fault).
    let syms = common::run(Command::new("arm-none-eabi-nm").arg("-C").arg(&elf), "arm-none-eabi-nm");
    let panics: Vec<&str> = syms.lines().filter(|l| l.contains("panic")).collect();
    assert!(panics.is_empty(), "the C image links panicking code: {panics:?}");

    // The C image in closed loop with the plant (-icount: instruction counts).
    let (records, end, wall_c) = c_image_on_fig15(QemuOptions::new(Build::F32, &elf));
    let n = records.len() as u64;
    // The C image's stack high-water mark (painted at reset), on its stdout.
    let stdout = String::from_utf8_lossy(&end.defmt);
    let stack_b: u32 = stdout.lines().find_map(|l| l.strip_prefix("stack_high_water_b=")).and_then(|v| v.trim().parse().ok()).unwrap_or_else(|| panic!("no stack report on the C image's stdout: {stdout:?}"));
    assert!(stack_b > 0 && stack_b < 16 * 1024, "stack high-water {stack_b} B");
    assert_eq!((end.done.counters.missing, end.done.counters.rejected_crc, end.done.counters.rejected_framing, end.done.counters.rejected_sequence), (0, 0, 0, 0));
    let c_replies: Vec<TickReply> = records.iter().map(|r| r.reply).collect();

    // The run is the Fig. 15 case: the valve opened on temperature and closed.
    let s = Summary::of(&records, true);
    let opened = s.valve_events.iter().filter(|(_, o)| *o).count();
    let closed = s.valve_events.iter().filter(|(_, o)| !*o).count();
    assert!(opened >= 1 && closed >= 1, "the Fig. 15 run must open and close the LNG valve: {:?}", s.valve_events);
    assert!(s.lng_used_kg > 0.0, "LNG must be used while the valve is open");

    // The Rust application on the host (SIL) on the same frames.
    let mut sil = SilTarget::new(Build::F32);
    let host = replay(&records, &mut sil).unwrap_or_else(|e| panic!("{e}"));
    let vs_sil = compare(&c_replies, &host);

    // The Rust product image (eha-fw) in QEMU on the same frames.
    let fw = firmware_for_tests(Build::F32);
    let mut rq = QemuOptions::new(Build::F32, &fw);
    rq.icount = true;
    let t1 = std::time::Instant::now();
    let mut rs = QemuSession::spawn(&rq).unwrap_or_else(|e| panic!("{e}"));
    let mut rust_cycles = Vec::with_capacity(records.len());
    let mut rust = Vec::with_capacity(records.len());
    for (k, r) in records.iter().enumerate() {
        let o = eha_sim::pil::Target::tick(&mut rs, &r.request.encode(), k as u64).unwrap_or_else(|e| panic!("{e}"));
        rust.push(o.reply);
        rust_cycles.push(o.cycles);
    }
    rs.finish(n).unwrap_or_else(|e| panic!("{e}"));
    let wall_rust = t1.elapsed().as_secs_f64();
    let vs_image = compare(&c_replies, &rust);

    let (c_mean, c_max) = instructions(&records.iter().map(|r| r.cycles).collect::<Vec<_>>());
    let (r_mean, r_max) = instructions(&rust_cycles);
    eprintln!(
        "Fig. 15, {n} ticks: C image vs Rust image {}/{} bit-identical, vs host SIL {}/{}; valve events {:?}; LNG used {:.4} kg; \
         instructions per tick (whole loop, -icount): C {c_mean:.0} mean {c_max:.0} max, Rust eha-fw {r_mean:.0} mean {r_max:.0} max; \
         C stack high-water {stack_b} B; wall: C closed loop {wall_c:.1} s, Rust replay {wall_rust:.1} s",
        vs_image.identical, vs_image.ticks, vs_sil.identical, vs_sil.ticks, s.valve_events, s.lng_used_kg
    );
    assert_eq!(vs_image.ticks as u64, n);
    assert_eq!(vs_image.identical, vs_image.ticks, "C image differs from the Rust image first at tick {:?}: C {:?} vs Rust {:?}",
        vs_image.first_difference, vs_image.first_difference.map(|k| c_replies[k]), vs_image.first_difference.map(|k| rust[k]));
    assert_eq!(vs_sil.identical, vs_sil.ticks, "C image differs from the host SIL first at tick {:?}", vs_sil.first_difference);
}

/// The same C example built for the Cortex-M3 (`EHA_CPU=cortex-m3`: no FPU,
/// the library's f32 in soft-float, `thumbv7m-none-eabi`) in QEMU
/// mps2-an385, in closed loop on Fig. 15: every tick reply bit-identical to
/// the Rust application on the host (SIL) on the same frames, which the test
/// above shows equal to the Cortex-M4F image. Tolerance: none — IEEE single
/// precision is the same arithmetic with or without the FPU (correctly
/// rounded operations, no fused multiply-add, the same libm code).
#[test]
fn c_example_for_the_cortex_m3_equals_the_rust_application_bit_for_bit_on_fig15() {
    require_qemu();
    let lib = common::staticlib(Some("thumbv7m-none-eabi"));
    let elf = common::scratch("fig15-m3").join("fig15.elf");
    common::run(
        Command::new(common::crate_dir().join("examples/fig15/build.sh")).arg(&elf).arg(&lib).env("EHA_CPU", "cortex-m3"),
        "building the C example for the Cortex-M3",
    );
    let size = common::run(Command::new("arm-none-eabi-size").arg(&elf), "arm-none-eabi-size");
    eprintln!("C example for the Cortex-M3:\n{size}");
    let mut q = QemuOptions::new(Build::F32, &elf);
    q.machine = "mps2-an385".into();
    q.cpu = "cortex-m3".into();
    let (records, _, wall) = c_image_on_fig15(q);
    let n = records.len() as u64;
    let c_replies: Vec<TickReply> = records.iter().map(|r| r.reply).collect();
    let s = Summary::of(&records, true);
    assert!(s.valve_events.iter().any(|(_, o)| *o), "the Fig. 15 run must open the LNG valve: {:?}", s.valve_events);
    let mut sil = SilTarget::new(Build::F32);
    let host = replay(&records, &mut sil).unwrap_or_else(|e| panic!("{e}"));
    let vs_sil = compare(&c_replies, &host);
    let (mean_instr, _) = instructions(&records.iter().map(|r| r.cycles).collect::<Vec<_>>());
    eprintln!(
        "Fig. 15 on the Cortex-M3, {n} ticks: C image vs host SIL {}/{} bit-identical; valve events {:?}; {mean_instr:.0} instructions per tick (soft-float); wall {:.1} s",
        vs_sil.identical,
        vs_sil.ticks,
        s.valve_events,
        wall
    );
    assert_eq!(vs_sil.identical, vs_sil.ticks, "Cortex-M3 C image differs from the host SIL first at tick {:?}", vs_sil.first_difference);
}
