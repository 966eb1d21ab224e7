//! Closed-loop PIL scenarios: the firmware in QEMU drives the reference
//! plant's LNG valve in lockstep, at the firmware's own 10 ms step.
//!
//! - Fig. 15 (Case 1 at 60 bar with the LNG exchanger), 600 s: the valve
//!   opens and closes repeatedly inside the run;
//! - Case 2 (26.4 °C, 20 mm 0.2 Hz sine), 600 s.
//!
//! Each checks, with the tolerance and its source:
//! - the run completes: completion marker, every frame accepted, none rejected;
//! - every tick reply of the PIL image equals the host SIL run of the same
//!   application on the same bytes bit for bit (f32 build; see
//!   `equivalence.rs` for why no tolerance is needed);
//! - accuracy against the reference: max |fw − ref drain| ≤ 1.0 K,
//!   under-prediction ≤ 0.5 K; valve switching within 2 s of switching on the
//!   reference's true drain temperature (40 °C threshold) for the first
//!   opening (later events: see `tests/firmware/vs_reference.rs`).

use eha_sim::pil::report::{compare, Summary};
use eha_sim::pil::sil::SilTarget;
use eha_sim::pil::{firmware_for_tests, replay, require_qemu, run_pil, Build, LoopOptions, PilRun, QemuOptions};
use eha_sim::plant::Plant;
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;

const VALVE_OPEN_C: f64 = 40.0;

fn run(scenario: Scenario, duration_s: f64) -> PilRun {
    require_qemu();
    let elf = firmware_for_tests(Build::F32);
    let mut q = QemuOptions::new(Build::F32, &elf);
    q.icount = false;
    let mut plant = Plant::new(&Rig::default(), &scenario).unwrap_or_else(|e| panic!("plant: {e}"));
    let opts = LoopOptions { tick_s: eha_guard::params::S_PER_TICK, duration_s };
    let run = run_pil(&mut plant, &q, &opts).unwrap_or_else(|f| panic!("{f}"));
    assert_eq!(run.records.len() as u64, opts.ticks());
    assert_eq!(run.done.counters.accepted as usize, run.records.len());
    assert_eq!((run.done.counters.rejected_crc, run.done.counters.rejected_framing, run.done.counters.rejected_sequence, run.done.counters.missing), (0, 0, 0, 0));
    run
}

fn check_sil(run: &PilRun) {
    let mut sil = SilTarget::new(run.build);
    let host = replay(&run.records, &mut sil).unwrap();
    let fw: Vec<_> = run.records.iter().map(|r| r.reply).collect();
    let c = compare(&fw, &host);
    assert_eq!(c.identical, c.ticks, "firmware differs from SIL first at step {:?}", c.first_difference);
}

/// First time the reference's true drain temperature reaches `c`.
fn first_crossing(run: &PilRun, c: f64) -> Option<f64> {
    run.records.iter().find(|r| r.sensors.t_drain_c >= c).map(|r| r.t_s)
}

fn report(name: &str, run: &PilRun) -> Summary {
    let s = Summary::of(&run.records, false);
    eprintln!(
        "{name}: {} steps in {:.2} s wall; valve events {:?}; max |fw-ref| {:.3} K; max under {:.3} K; LNG used {:.4} kg; ref crossing 40 C at {:?} s",
        s.ticks,
        run.wall.as_secs_f64(),
        s.valve_events,
        s.max_abs_err_k,
        s.max_under_k,
        s.lng_used_kg,
        first_crossing(run, VALVE_OPEN_C)
    );
    s
}

fn check_accuracy(s: &Summary) {
    assert!(s.max_abs_err_k <= 1.0, "max |fw − ref| = {:.3} K > 1.0 K (specified bound)", s.max_abs_err_k);
    assert!(s.max_under_k <= 0.5, "under-prediction {:.3} K > 0.5 K (specified bound)", s.max_under_k);
}

/// Fig. 15 LNG case, 600 s: SIL equality, the valve's first opening within 2 s of
/// the reference's true drain crossing 40 °C (before it the plant is the same as an
/// uncontrolled one), LNG used iff the valve opened, and the issue-3 accuracy bounds.
#[test]
fn fig15_lng_case_closed_loop() {
    let run = run(Scenario::Lng { duration_s: 600.0 }, 600.0);
    let s = report("Fig. 15 LNG", &run);
    check_sil(&run);
    let truth = first_crossing(&run, VALVE_OPEN_C).expect("reference drain reached 40 °C");
    assert!(truth < 250.0, "the run must contain the valve-opening phase");
    let open = s.valve_events.iter().find(|(_, o)| *o).map(|(t, _)| *t).expect("the firmware opened the LNG valve");
    // Specified: switching within 2 s of switching on the true drain temperature.
    assert!((open - truth).abs() <= 2.0, "valve opened at {open:.2} s, reference crossed 40 °C at {truth:.2} s (bound 2 s)");
    // Whatever the firmware commanded reached the plant: LNG is used iff it opened the valve.
    assert!(s.lng_used_kg > 0.0, "LNG must be used while the valve is open");
    check_accuracy(&s);
}

/// Case 2 (servo, spring load), 600 s: SIL equality and the issue-3 accuracy bounds.
#[test]
fn case2_closed_loop() {
    let run = run(Scenario::Case2 { duration_s: 600.0 }, 600.0);
    let s = report("Case 2", &run);
    check_sil(&run);
    check_accuracy(&s);
}
