//! Write rate of the non-volatile thermal record and the flash-wear budget
//! for 10 years (issue "No silent protection failure", item 5).
//!
//! The guard (f32, as flashed) runs in closed loop with the reference plant
//! for one hour from cold on the Fig. 15 LNG case and on the random missions
//! of the acceptance suite (each hour includes a full warm-up); after every
//! tick its snapshot goes through the firmware's write policy
//! (`NvPolicy::DEFAULT`). Measured: writes per operating hour, and the flash
//! consumed per write by the firmware's `NvStore` (page erases over 2000
//! writes into a small RAM-backed flash). Budget: the STM32F411 keeps the
//! record in its last two 128 KiB sectors (region `NVREC` of
//! `boards/stm32f411/memory.x`; 10 000 erase cycles each, datasheet
//! endurance); running 24 hours a day for 10 years, every hour as the worst
//! measured hour (a warm-up from cold every hour), must stay under that
//! endurance. (Two 16 KiB sectors were measured too small: 15 400 cycles.)

use eha_guard::memory::nv::{Blocking, NvPolicy, NvStore, RamFlash, RAM_FLASH_PAGE};
use eha_guard::memory::ThermalRecord;
use eha_guard::{GuardConfig, GuardOf, Restore};
use eha_sim::missions::{random_mission, TEST_SEEDS};
use eha_sim::plant::{Control, Plant, Sensors};
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;
use rayon::prelude::*;

/// A small store (4 pages) so that every run cycles it and the erases
/// measure the flash consumed per write.
const FLASH: usize = 4 * 1024;
/// Sector size and count reserved for the record on the STM32F411, bytes.
const SECTOR_B: f64 = 128.0 * 1024.0;
const SECTORS: f64 = 2.0;
/// Datasheet erase endurance of the STM32F411's flash, cycles.
const ENDURANCE: f64 = 10_000.0;

/// (writes, duration s) of one closed-loop run.
fn run(scenario: &Scenario) -> (u64, f64) {
    let rig = Rig::default();
    let mut plant = Plant::new(&rig, scenario).expect("plant");
    let cfg = GuardConfig::DEFAULT;
    let mut guard = GuardOf::<f32>::new(&cfg, Restore::Cold);
    let mut last: Option<ThermalRecord> = None;
    let mut writes = 0u64;
    plant
        .run(0.01, scenario.duration_s(), |snap| {
            guard.valve_feedback(snap.lng_open);
            let o = guard.tick(&Sensors::from(snap).sample());
            let rec = guard.snapshot();
            if NvPolicy::DEFAULT.due(last.as_ref(), &rec) {
                last = Some(rec);
                writes += 1;
            }
            Ok(Control { lng_valve: Some(o.valve_open), stop: false })
        })
        .expect("run");
    (writes, scenario.duration_s())
}

/// Flash bytes the store consumes per record write, in steady state.
fn bytes_per_write() -> f64 {
    let mut nv = NvStore::new(Blocking(RamFlash::<FLASH>::new()), 0..FLASH as u32).expect("store");
    let n = 2000u32;
    for k in 0..n {
        let rec = ThermalRecord::new([20.0 + (k % 50) as f32; 6], 20.0, k, 0, k).with_seq(k, k % 2 == 0);
        nv.save(&rec).expect("save");
    }
    let erases: u64 = nv.into_flash().0.erase_counts().iter().map(|&e| u64::from(e)).sum();
    erases as f64 * RAM_FLASH_PAGE as f64 / f64::from(n)
}

#[test]
fn nv_write_rate_keeps_the_flash_within_its_endurance_for_10_years() {
    let mut scenarios = vec![("lng".to_string(), Scenario::Lng { duration_s: 3600.0 })];
    scenarios.extend(TEST_SEEDS.iter().map(|&s| (format!("random-{s}"), Scenario::Mission(random_mission(s, 3600.0)))));
    let rows: Vec<(String, (u64, f64))> = scenarios.par_iter().map(|(n, s)| (n.clone(), run(s))).collect();
    let mut worst_rate = 0.0f64;
    for (n, (w, d)) in &rows {
        let rate = *w as f64 / d * 3600.0;
        println!("{n}: {w} writes in {d} s ({rate:.0} per hour)");
        worst_rate = worst_rate.max(rate);
    }
    let bpw = bytes_per_write();
    let writes_10y = worst_rate * 24.0 * 365.25 * 10.0;
    let erases_per_sector = writes_10y * bpw / (SECTORS * SECTOR_B);
    println!(
        "worst {worst_rate:.0} writes/h, {bpw:.1} B of flash per write: {writes_10y:.3e} writes in 10 years at 24 h/day, {erases_per_sector:.0} erases per 128 KiB sector (endurance {ENDURANCE})"
    );
    // The record is 56 B + key + item header, rounded to words: 56 to 128 B.
    assert!((56.0..=128.0).contains(&bpw), "{bpw} B per write");
    // Budget: 10 years of continuous operation within the endurance.
    assert!(erases_per_sector <= ENDURANCE, "{erases_per_sector:.0} erases per sector in 10 years > {ENDURANCE}");
}
