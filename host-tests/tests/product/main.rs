//! The product image (`eha-mps2`: the flashed application with the QEMU
//! board module) in QEMU, in real time, over its emulated UART: the
//! timer-driven tick, the watchdog, the fault handlers, the pins.
//!
//! These run in real time (10 ms ticks of QEMU's virtual clock = wall
//! time), so they are in the slow tier, as one test that runs the five
//! short scenarios at once, each in its own thread with its own QEMU (they
//! mostly sleep), then the 120 s closed loop alone: ~165 s. They are a
//! test binary of their own so that no other test competes with them for
//! the CPU (a host that answers late costs samples in real time). One
//! scenario alone: `EHA_PRODUCT=hang cargo test --profile fast -p eha-sim
//! --test product -- --ignored` (names: fig15, hang, panic, garbage, alarm,
//! params; a comma-separated list selects several).
//!
//! The scenarios by topic: `fig15` (the closed loop against the PIL),
//! `fault_resets` (hang, panic), `uart` (garbage), `pins_and_params` (the
//! alarm pin, a parameter block in flash); here the runner and what they
//! share.

use std::time::{Duration, Instant};

use eha_guard::product::wire::{Cmd, FromGuard, Pins, ResetCause};
use eha_guard::trace::RestoreKind;
use eha_sim::pil::product::{product_elf, run_closed_loop, ProductSample, ProductSession};
use eha_sim::pil::{firmware_for_tests, require_qemu, run_pil, Build, LoopOptions, QemuOptions};
use eha_sim::plant::Plant;
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;

mod fault_resets;
mod fig15;
mod pins_and_params;
mod uart;

use fault_resets::*;
use fig15::*;
use pins_and_params::*;
use uart::*;

/// The scenarios, by name.
const SCENARIOS: [(&str, fn()); 6] = [
    ("fig15", fig15_120s_closed_loop_over_the_uart_matches_the_semihosting_pil),
    ("hang", hang_is_reset_by_the_watchdog_with_safe_outputs_and_warm_restore),
    ("panic", panic_gives_safe_outputs_a_reset_and_warm_restore),
    ("garbage", garbage_and_bursts_on_the_uart_are_rejected_without_a_hang),
    ("alarm", alarm_pin_follows_the_60c_alarm),
    ("params", parameter_block_in_flash_runs_its_rig_and_an_invalid_one_is_refused),
];

/// Every product scenario in QEMU; fails with the names and messages of the
/// scenarios that failed. The short scenarios run concurrently, then the
/// 120 s closed loop alone: beside the other five (a 40 KiB UART burst,
/// reboots) its samples come late more often.
#[test]
#[ignore = "slow tier: ~165 s of real time in QEMU"]
fn product_image_in_qemu_over_the_uart() {
    require_qemu();
    product_elf().unwrap_or_else(|e| panic!("building eha-mps2: {e:#}"));
    let only = std::env::var("EHA_PRODUCT").ok();
    let selected = |name: &str| only.as_deref().is_none_or(|o| o.split(',').any(|o| o.trim() == name));
    let mut failed = run_concurrently(SCENARIOS.iter().filter(|(n, _)| *n != "fig15" && selected(n)));
    failed.extend(run_concurrently(SCENARIOS.iter().filter(|(n, _)| *n == "fig15" && selected(n))));
    assert!(failed.is_empty(), "product scenarios failed:\n{}", failed.join("\n"));
}

/// Runs `scenarios`, each in its own thread, and returns "name: message"
/// of each that panicked.
fn run_concurrently<'a>(scenarios: impl Iterator<Item = &'a (&'a str, fn())>) -> Vec<String> {
    std::thread::scope(|sc| {
        let handles: Vec<_> = scenarios.map(|(name, f)| (*name, sc.spawn(*f))).collect();
        handles
            .into_iter()
            .filter_map(|(name, h)| {
                h.join().err().map(|e| {
                    let msg = e.downcast_ref::<String>().cloned().or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()));
                    format!("{name}: {}", msg.unwrap_or_default())
                })
            })
            .collect()
    })
}

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

/// Runs a real-time scenario that returns `Err(description)` when a host
/// stall made the guard latch STALE (its correct controller-silent
/// response, checked by the scenario) where the case under test needs live
/// samples; repeats it once, and fails when the host stalls both runs.
fn retry_on_host_stall(f: impl Fn() -> Result<(), String>) {
    let mut stalls = Vec::new();
    for _ in 0..2 {
        match f() {
            Ok(()) => return,
            Err(stall) => {
                eprintln!("{stall}; scenario repeated");
                stalls.push(stall);
            }
        }
    }
    panic!("the host stalled the scenario in both runs: {stalls:?}");
}

/// The first tick whose output carries STALE (the guard saw `stale_ticks`
/// ticks in a row without a sample), with its fail-safe checked: valve
/// open from there on.
fn stale_tick(run: &eha_sim::pil::product::ProductRun) -> Option<u32> {
    let stale = eha_guard::faults::STALE;
    let k = run.ticks.iter().position(|(_, t)| t.out.faults.contains(stale))?;
    assert!(run.ticks[k..].iter().all(|(_, t)| t.out.valve_open), "STALE without the valve open after tick {}", run.ticks[k].1.tick);
    Some(run.ticks[k].1.tick)
}
