//! Fault campaign (`eha-sim faults`): every fault of [`inject`] applied to
//! the product application (the f32 [`eha_guard::product::App`] on the
//! shared in-memory board, the host twin of the flashed image; the faults
//! that need no reboot also on the PIL image in QEMU) in closed loop with
//! the reference plant, during the Fig. 15 LNG case and one random mission.
//!
//! Pass rule per fault and scenario: either the guard latches a fault and
//! opens the valve within [`DETECT_S`] of the fault becoming observable, or
//! its drain estimate never under-predicts the true drain by more than
//! [`MAX_UNDER_K`] and the true drain never exceeds [`MAX_CLOSED_C`] while the
//! valve is physically closed (both from the fault's start on).
//!
//! The controller sends one frame per 10 ms tick; the application takes the
//! newest valid sample of the tick, and a tick without one is a missing
//! sample. A reset or a power loss boots the application again on the same
//! board, from what its memories keep (warm: the no-init records; power
//! loss: the non-volatile record; torn write: a damaged record). While the
//! MCU is off the valve is open (normally-open valve, the fail-safe design).

pub mod inject;

use std::path::Path;

use anyhow::{Context, Result};
use eha_guard::memory::ThermalRecord;
use eha_guard::product::mem_board::MemBoard;
use eha_guard::protocol::Request;
use eha_guard::{faults as fbits, GuardConfig, Output, Sample};
use rayon::prelude::*;
use serde::Serialize;

use crate::missions::random_mission;
use crate::pil::sil::AppTarget;
use crate::pil::Target;
use crate::plant::{Control, Plant, Sensors};
use crate::rig::Rig;
use crate::scenario::Scenario;
use inject::{corrupt_sample, Fault, Gauss};

/// Tick of the guard and of the controller's frames, s.
pub const TICK_S: f64 = 0.01;
/// Fault start, s after boot (before the LNG case's first opening at ≈ 78 s).
pub const FAULT_AT_S: f64 = 30.0;
/// Length of every campaign run, s.
pub const DURATION_S: f64 = 600.0;
/// Detection bound of the pass rule, s.
pub const DETECT_S: f64 = 1.0;
/// Under-prediction bound of the pass rule, K.
pub const MAX_UNDER_K: f64 = 1.0;
/// True drain bound while the valve is closed, °C (the 40 °C threshold plus 2 K).
pub const MAX_CLOSED_C: f64 = 42.0;
/// Off-time of the power-loss fault, s.
pub const POWER_OFF_S: f64 = 60.0;
/// Seed of the campaign's random mission (`missions::random_mission`).
pub const MISSION_SEED: u64 = 1;

/// The campaign's scenarios.
pub fn scenarios() -> Vec<(&'static str, Scenario)> {
    vec![
        ("lng", Scenario::Lng { duration_s: DURATION_S }),
        ("random-1", Scenario::Mission(random_mission(MISSION_SEED, DURATION_S))),
    ]
}

/// One row of `faults.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct FaultResult {
    /// Fault name ([`Fault::name`]).
    pub fault: String,
    /// Scenario name.
    pub scenario: String,
    /// A fault bit latched after the fault started.
    pub detected: bool,
    /// Time from the fault becoming observable to the latch, s (None: not detected).
    pub detect_s: Option<f64>,
    /// Largest under-prediction of the true drain from the fault's start on, K.
    pub max_under_k: f64,
    /// Hottest true drain while the valve was physically closed, from the fault's start on, °C.
    pub max_true_drain_closed_c: f64,
    /// The pass rule.
    pub pass: bool,
}

/// The MCU: the application on its board; a reboot boots it again on the
/// same board.
struct Mcu {
    app: AppTarget<f32>,
}

impl Mcu {
    fn boot(board: Box<MemBoard>) -> Self {
        Mcu { app: AppTarget::boot(&GuardConfig::DEFAULT, board) }
    }

    /// A reset: no-init RAM and flash keep their contents.
    fn reset(self, damage_newest_record: bool) -> Self {
        let mut board = self.app.into_board();
        board.warm_reset();
        if damage_newest_record {
            // The reset hit the write of the newest record: one word half written.
            let [a, b] = board.records;
            let newest = usize::from(eha_guard::memory::seq_newer(b.seq(), a.seq()));
            if let Some(r) = board.records.get_mut(newest) {
                r.temps_c[0] = f32::from_bits(r.temps_c[0].to_bits() ^ 0x0040_0000);
            }
        }
        Mcu::boot(board)
    }
}

/// A record whose LNG charge is used up, node temperatures at `ambient_c`.
fn lng_empty_record(cfg: &GuardConfig, ambient_c: f32) -> ThermalRecord {
    let used_cj = (f64::from(cfg.lng.charge_kg()) * f64::from(cfg.lng.j_per_kg()) * 100.0).ceil() as u32;
    ThermalRecord::new([ambient_c; eha_guard::params::N_NODES], ambient_c, used_cj, 0, 0).with_seq(1, false)
}

/// Run one fault in one scenario on the host build of the guard (SIL).
pub fn run_one(fault: Fault, scenario_name: &str, scenario: &Scenario) -> Result<FaultResult> {
    run_on(fault, scenario_name, scenario, None)
}

/// Whether a fault runs on a target given from outside (the PIL image in
/// QEMU): those that need no reboot and no preset memory.
pub fn runs_on_a_target(fault: Fault) -> bool {
    !matches!(fault, Fault::WarmReset | Fault::PowerLoss | Fault::TornRecordWrite | Fault::LngEmpty)
}

/// Run one fault in one scenario; with `target` (the PIL image in QEMU, in
/// lockstep) instead of the host application. It must give the same result
/// as on the host, bit for bit ([`runs_on_a_target`] says which faults can).
pub fn run_on(
    fault: Fault,
    scenario_name: &str,
    scenario: &Scenario,
    mut target: Option<&mut dyn crate::pil::Target>,
) -> Result<FaultResult> {
    if target.is_some() && !runs_on_a_target(fault) {
        anyhow::bail!("{}: reboots and preset memories run on the host application only", fault.name());
    }
    let mut target_error: Option<anyhow::Error> = None;
    let rig = Rig::default();
    let mut plant = Plant::new(&rig, scenario).context("plant")?;
    let cfg = GuardConfig::DEFAULT;
    let first = Sensors::from(&plant.snapshot()).sample();
    let mut board = Box::new(MemBoard::new().with_nv());
    if fault == Fault::LngEmpty {
        board.records[0] = lng_empty_record(&cfg, first.ambient_c);
    }
    let mut mcu = Some(Mcu::boot(board));
    let mut off_board: Option<Box<MemBoard>> = None;
    let mut rng = Gauss::new(0x5EED ^ fault.name().len() as u64);
    let mut seq: u16 = 0;
    let mut out: Option<Output> = None;
    let mut frozen: Option<f32> = None;
    let mut held: Option<Vec<u8>> = None; // out-of-order: a frame held back
    let mut k: u64 = 0;
    let mut latched_before = eha_guard::Faults::NONE;
    let mut observable_at: Option<f64> = None;
    let mut detect: Option<f64> = None;
    let mut max_under = f64::NEG_INFINITY;
    let mut max_closed = f64::NEG_INFINITY;
    let mut powered_off_until: Option<f64> = None;
    let mut stuck_closed = false;
    let mut valve_position = false;
    plant
        .run(TICK_S, DURATION_S, |snap| {
            let s = Sensors::from(snap);
            let t = s.t;
            let active = t >= FAULT_AT_S - 1e-9;
            // Events at the fault's start.
            if active && k == (FAULT_AT_S / TICK_S).round() as u64 {
                latched_before = out.map_or(eha_guard::Faults::NONE, |o| o.faults & fbits::LATCHED);
                match fault {
                    Fault::WarmReset | Fault::TornRecordWrite => {
                        if let Some(m) = mcu.take() {
                            mcu = Some(m.reset(fault == Fault::TornRecordWrite));
                        }
                    }
                    Fault::PowerLoss => {
                        if let Some(m) = mcu.take() {
                            let mut b = m.app.into_board();
                            b.power_loss();
                            off_board = Some(b);
                        }
                        powered_off_until = Some(t + POWER_OFF_S);
                    }
                    Fault::ValveStuckClosed => stuck_closed = true,
                    _ => {}
                }
                if fault != Fault::ValveStuckClosed {
                    observable_at = Some(t);
                }
            }
            if let Some(until) = powered_off_until {
                if t >= until - 1e-9 {
                    // Power back: RAM is lost, the non-volatile record remains.
                    if let Some(b) = off_board.take() {
                        mcu = Some(Mcu::boot(b));
                    }
                    powered_off_until = None;
                    seq = 0;
                }
            }
            // The controller's frame for this tick.
            let mut sample: Sample = s.sample();
            if let (true, Fault::Input(c, f)) = (active, fault) {
                let fz = *frozen.get_or_insert_with(|| c.get(&sample));
                corrupt_sample(&mut sample, c, f, t - FAULT_AT_S, fz, &mut rng);
            }
            let send = match fault {
                Fault::LateStart => t >= 5.0 - 1e-9,
                Fault::DropoutBursts => !(active && ((t - FAULT_AT_S) % 10.0) < 0.5 - 1e-9),
                _ => true,
            };
            let req = Request {
                seq,
                // The valve's position switch: where the valve really is.
                valve_fb: Some(valve_position),
                elec_hz: None,
                lng_supply_bar: None,
                current_a: sample.current_a,
                p_a_bar: sample.p_a_bar,
                p_b_bar: sample.p_b_bar,
                speed_rpm: sample.speed_rpm,
                position_mm: sample.position_mm,
                ambient_c: sample.ambient_c,
            };
            seq = seq.wrapping_add(1);
            if let Some(m) = mcu.as_mut() {
                let mut wire: Vec<u8> = Vec::new();
                if send {
                    let mut frame: Vec<u8> = req.encode().as_slice().to_vec();
                    if active && fault == Fault::CorruptedFrames && k.is_multiple_of(50) && frame.len() > 4 {
                        frame[3] ^= 0x10;
                    }
                    if active && fault == Fault::OutOfOrderFrames && k.is_multiple_of(40) {
                        held = Some(frame);
                    } else {
                        wire.extend_from_slice(&frame);
                        if let Some(h) = held.take() {
                            wire.extend_from_slice(&h);
                        }
                    }
                }
                let res = match target.as_deref_mut() {
                    Some(t) => t.tick(&wire, k),
                    None => m.app.tick(&wire, k),
                };
                match res {
                    Ok(r) => out = Some(r.reply.out),
                    Err(e) => {
                        target_error = Some(e.into());
                        return Ok(Control { lng_valve: None, stop: true });
                    }
                }
            } else {
                out = None;
            }
            // Physical valve: open while the MCU is off (normally-open valve).
            let commanded = match (&mcu, out) {
                (None, _) => true,
                (Some(_), Some(o)) => o.valve_open,
                (Some(_), None) => true,
            };
            // The valve's real position, and whether it cools: an empty tank
            // leaves a working valve with nothing to flow through it.
            let physical = commanded && !stuck_closed;
            valve_position = physical;
            let cooling = physical && fault != Fault::LngEmpty;
            if stuck_closed && commanded && observable_at.is_none() {
                observable_at = Some(t);
            }
            if active {
                if let (Some(_), Some(o)) = (&mcu, out) {
                    let new_latch = o.faults & fbits::LATCHED & !latched_before;
                    if !new_latch.is_empty() && detect.is_none() && o.valve_open {
                        if let Some(t0) = observable_at {
                            detect = Some((t - t0).max(0.0));
                        }
                    }
                    if o.drain_c < 1.0e5 {
                        max_under = max_under.max(s.t_drain_c - f64::from(o.drain_c));
                    }
                }
                if !physical {
                    max_closed = max_closed.max(s.t_drain_c);
                }
            }
            k += 1;
            Ok(Control { lng_valve: Some(cooling), stop: false })
        })
        .context("closed-loop run")?;
    if let Some(e) = target_error {
        return Err(e.context(format!("{} on the target", fault.name())));
    }
    let max_under_k = if max_under.is_finite() { max_under } else { 0.0 };
    let max_true_drain_closed_c = if max_closed.is_finite() { max_closed } else { f64::NAN };
    let detected = detect.is_some();
    let pass = detect.is_some_and(|d| d <= DETECT_S)
        || (max_under_k <= MAX_UNDER_K && (max_true_drain_closed_c.is_nan() || max_true_drain_closed_c <= MAX_CLOSED_C));
    Ok(FaultResult {
        fault: fault.name(),
        scenario: scenario_name.into(),
        detected,
        detect_s: detect,
        max_under_k,
        max_true_drain_closed_c,
        pass,
    })
}

/// The whole campaign (every fault × every scenario, in parallel).
pub fn campaign() -> Result<Vec<FaultResult>> {
    let sc = scenarios();
    let jobs: Vec<(Fault, usize)> = Fault::all().into_iter().flat_map(|f| (0..sc.len()).map(move |i| (f, i))).collect();
    jobs.par_iter().map(|&(f, i)| run_one(f, sc[i].0, &sc[i].1)).collect()
}

/// Markdown table of the results.
pub fn table(rows: &[FaultResult]) -> String {
    let mut s = String::from("| fault | scenario | detected | detect s | max under K | max true drain closed °C | pass |\n|---|---|---|---:|---:|---:|---|\n");
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {:.3} | {} | {} |\n",
            r.fault,
            r.scenario,
            if r.detected { "yes" } else { "no" },
            r.detect_s.map_or("–".into(), |d| format!("{d:.2}")),
            r.max_under_k,
            if r.max_true_drain_closed_c.is_finite() { format!("{:.2}", r.max_true_drain_closed_c) } else { "–".into() },
            if r.pass { "pass" } else { "**FAIL**" }
        ));
    }
    s
}

/// Arguments of `eha-sim faults`.
#[derive(Debug, Clone, clap::Args)]
pub struct FaultsArgs {
    /// Output directory (faults.json, faults.md).
    #[arg(long, default_value = "out/faults")]
    pub out: std::path::PathBuf,
}

/// `eha-sim faults`: run the campaign, write `faults.json` and `faults.md`.
pub fn run(a: &FaultsArgs) -> Result<()> {
    let rows = campaign()?;
    write(&a.out, &rows)?;
    print!("{}", table(&rows));
    let failing = rows.iter().filter(|r| !r.pass).count();
    println!("{} of {} fault runs pass; wrote {}", rows.len() - failing, rows.len(), a.out.join("faults.json").display());
    Ok(())
}

/// Write `faults.json` and `faults.md` to `dir`.
pub fn write(dir: &Path, rows: &[FaultResult]) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    std::fs::write(dir.join("faults.json"), serde_json::to_string_pretty(rows)?).context("writing faults.json")?;
    std::fs::write(dir.join("faults.md"), table(rows)).context("writing faults.md")?;
    Ok(())
}
