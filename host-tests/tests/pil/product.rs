//! The product image (`eha-mps2`: the flashed application with the QEMU
//! board module) in QEMU, in real time, over its emulated UART: the
//! timer-driven tick, the watchdog, the fault handlers, the pins.
//!
//! These run in real time (10 ms ticks of QEMU's virtual clock = wall
//! time), so they are in the slow tier; they run in parallel with each
//! other (each is a QEMU process that mostly sleeps).

use std::time::Duration;

use eha_guard::product::wire::{Cmd, FromGuard, Pins, ResetCause};
use eha_guard::trace::RestoreKind;
use eha_sim::pil::product::{product_elf, run_closed_loop, ProductSession};
use eha_sim::pil::{firmware_for_tests, require_qemu, run_pil, Build, LoopOptions, QemuOptions};
use eha_sim::plant::Plant;
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;

fn session(extra: &[String]) -> ProductSession {
    require_qemu();
    let elf = product_elf().unwrap_or_else(|e| panic!("building eha-mps2: {e:#}"));
    ProductSession::spawn(&elf, extra).unwrap_or_else(|e| panic!("{e:#}"))
}

fn plant(duration_s: f64) -> Plant {
    Plant::new(&Rig::default(), &Scenario::Lng { duration_s }).unwrap_or_else(|e| panic!("plant: {e}"))
}

/// Valve transitions as (sample index, open).
fn events(v: impl Iterator<Item = bool>) -> Vec<(usize, bool)> {
    let mut last = None;
    let mut out = Vec::new();
    for (k, open) in v.enumerate() {
        if last.is_some_and(|l| l != open) {
            out.push((k, open));
        }
        last = Some(open);
    }
    out
}

/// 120 s of the Fig. 15 LNG case in closed loop over the UART: the same
/// valve events as the semihosting lockstep PIL run of the same plant
/// (within one tick), and the same drain estimate per sample within f32
/// rounding when no tick went without its sample. The pins read back in
/// every tick reply match the outputs.
#[test]
#[ignore = "slow tier: 120 s of real time in QEMU"]
fn fig15_120s_closed_loop_over_the_uart_matches_the_semihosting_pil() {
    let duration_s = 120.0;
    let mut s = session(&[]);
    let run = run_closed_loop(&mut s, &mut plant(duration_s), duration_s, Duration::from_secs(2), &mut |_, _| Ok(true))
        .unwrap_or_else(|e| panic!("{e:#}"));
    let mut ticks = Vec::new();
    let st = s.status(1, &mut ticks).unwrap_or_else(|e| panic!("{e:#}"));
    drop(s);
    assert_eq!(run.steps.len(), 12_000);

    let elf = firmware_for_tests(Build::F32);
    let mut q = QemuOptions::new(Build::F32, &elf);
    q.icount = false;
    let pil = run_pil(&mut plant(duration_s), &q, &LoopOptions { step_s: 0.01, duration_s })
        .unwrap_or_else(|f| panic!("{f}"));

    let prod_ev = events(run.steps.iter().map(|p| p.tick.out.valve_open));
    let pil_ev = events(pil.records.iter().map(|r| r.reply.out.valve_open));
    // Ticks after the first sample that had no sample of their own.
    let first = run.ticks.iter().position(|(_, t)| t.fresh).unwrap_or(0);
    let missed = run.ticks[first..].iter().filter(|(_, t)| !t.fresh).count();
    let max_diff = run
        .steps
        .iter()
        .zip(&pil.records)
        .map(|(p, r)| (p.tick.out.drain_c - r.reply.out.drain_c).abs())
        .fold(0.0f32, f32::max);
    eprintln!(
        "product: {} samples, {} ticks, {missed} missed after the first sample; valve events product {prod_ev:?} pil {pil_ev:?}; \
         max |drain diff| {max_diff:.3e} K; overruns {}; worst tick {} cycles; stack boot {} B tick {} B",
        run.steps.len(),
        run.ticks.len(),
        st.overruns,
        st.worst_tick_cycles,
        st.boot_stack_b,
        st.stack_high_water_b
    );
    assert!(!pil_ev.is_empty(), "the valve opens within 120 s (paper: 110 s)");
    assert_eq!(prod_ev.len(), pil_ev.len(), "valve events: product {prod_ev:?}, PIL {pil_ev:?}");
    for (a, b) in prod_ev.iter().zip(&pil_ev) {
        assert!(a.1 == b.1 && a.0.abs_diff(b.0) <= 1, "valve event product {a:?} vs PIL {b:?}");
    }
    if missed == 0 {
        assert_eq!(max_diff, 0.0, "every sample got its own tick: the estimate must be bit-identical");
    } else {
        // A tick without its sample holds the last inputs 10 ms longer: the
        // difference is the heat of one tick, far below 0.01 K.
        assert!(max_diff <= 0.01, "{missed} ticks missed their sample; max drain difference {max_diff} K");
    }
    assert!(missed * 100 <= run.steps.len(), "more than 1 % of ticks missed their sample: {missed}");
    for p in &run.steps {
        assert_eq!(p.tick.pins, Pins::for_outputs(p.tick.out.valve_open, p.tick.out.alarm), "pins at sample {}", p.request.seq);
    }
    assert_eq!(st.overruns, 0, "no tick overran its 10 ms");
    assert_eq!(st.rejected_crc + st.rejected_framing + st.rejected_sequence, 0);
    assert!(st.boot_stack_b > 0 && st.boot_stack_b <= 4096, "boot stack {} B > 4 KiB", st.boot_stack_b);
    assert!(st.stack_high_water_b > 0 && st.stack_high_water_b <= 2048, "tick stack {} B > 2 KiB", st.stack_high_water_b);
    assert_eq!(run.steps[0].tick.reset_cause, ResetCause::PowerOn);
    assert_eq!(run.steps[0].tick.restore, RestoreKind::Cold);
    let _ = FromGuard::Tick(run.steps[0].tick);
    let _ = Cmd::Status;
}
