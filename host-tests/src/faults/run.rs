//! One run of the campaign: the MCU on its board, the controller's
//! commands, the plant in closed loop, and the pass rule applied.

use anyhow::{bail, Context, Result};
use eha_guard::memory::ThermalRecord;
use eha_guard::product::mem_board::MemBoard;
use eha_guard::product::wire::Cmd;
use eha_guard::protocol::Request;
use eha_guard::{Faults, GuardConfig, Output, Sample};

use super::commander::Commander;
use super::inject::{corrupt_sample, Channel, Fault, Gauss, InputFault};
use super::outcome::{action, bit_names, protected, DETECT_MASK};
use super::{Case, FaultResult, Inputs, ScenarioSpec, Start, DETECT_S, MAX_CLOSED_C, MAX_UNDER_K, POWER_OFF_S, TICK_S, WRITE_FAIL_TO_POWER_LOSS_S};
use crate::pil::sil::AppTarget;
use crate::pil::Target;
use crate::plant::{Control, Plant, Sensors};
use crate::rig::Rig;
use crate::scenario::{PositionRef, Scenario, Schedule};

/// The board clock's reading at boot, s.
const RTC0: u32 = 1_000_000;
/// Motor pole pairs of the paper rig (the parameter word `pole_pairs`).
const POLE_PAIRS: f64 = 4.0;

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
    fn reset(self, damage: Damage) -> Self {
        let mut board = self.app.into_board();
        board.warm_reset();
        let [a, b] = board.records;
        let newest = usize::from(eha_guard::memory::seq_newer(b.seq(), a.seq()));
        for (i, r) in board.records.iter_mut().enumerate() {
            let hit = match damage {
                Damage::None => false,
                Damage::Newest => i == newest,
                Damage::Both => true,
            };
            if hit {
                // One word half written.
                r.temps_c[0] = f32::from_bits(r.temps_c[0].to_bits() ^ 0x0040_0000);
            }
        }
        if damage == Damage::Both {
            board.set_flash_faults(true, false);
        }
        Mcu::boot(board)
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Damage {
    None,
    Newest,
    Both,
}

/// A record whose LNG charge is used up, node temperatures at `ambient_c`.
fn lng_empty_record(cfg: &GuardConfig, ambient_c: f32) -> ThermalRecord {
    let used_cj = (f64::from(cfg.lng.charge_kg()) * f64::from(cfg.lng.j_per_kg()) * 100.0).ceil() as u32;
    ThermalRecord::new([ambient_c; eha_guard::params::N_NODES], ambient_c, used_cj, 0, 0).with_seq(1, false)
}

/// `s` with its value held at `off` (or at its value at `t0`) from `t0` to
/// `t1`, as it was before and after.
fn hold(s: &Schedule, t0: f64, t1: f64, off: Option<f64>) -> Schedule {
    let (v0, v1) = (s.at(t0), s.at(t1));
    let h = off.unwrap_or(v0);
    let mut p: Vec<(f64, f64)> = s.0.iter().copied().filter(|p| p.0 < t0).collect();
    p.extend([(t0, v0), (t0, h), (t1, h), (t1, v1)]);
    p.extend(s.0.iter().copied().filter(|p| p.0 > t1));
    Schedule(p)
}

/// `sc` with the machine stopped from `t0` to `t1` (a power loss of the
/// whole EHA: pump at rest, needle open, the piston held).
fn machine_off(sc: &Scenario, t0: f64, t1: f64) -> Result<Scenario> {
    let mut m = sc.mission().context("a mission")?;
    m.speed_rpm = hold(&m.speed_rpm, t0, t1, Some(0.0));
    m.needle_bar = hold(&m.needle_bar, t0, t1, Some(0.0));
    if let PositionRef::Profile(p) = &m.position {
        m.position = PositionRef::Profile(hold(p, t0, t1, None));
    }
    Ok(Scenario::Mission(m))
}

/// Whether a case runs on a target given from outside (the PIL image in
/// QEMU): those that need no reboot, no preset memory and no flash.
pub fn runs_on_a_target(fault: Fault) -> bool {
    !matches!(
        fault,
        Fault::WarmReset
            | Fault::PowerLoss
            | Fault::PowerLossMachineRunning
            | Fault::TornRecordWrite
            | Fault::LngEmpty
            | Fault::RefillWhileEmpty
            | Fault::FlashWriteFail
            | Fault::FlashReadFail
            | Fault::CorruptStartClear
    )
}

/// Run one case in one scenario from `start` on the host application.
pub fn run_one(case: Case, spec: &ScenarioSpec, start: Start) -> Result<FaultResult> {
    run_case(case, spec, start, None)
}

/// Run one case in one scenario from `start`; with `target` (the PIL image
/// in QEMU, in lockstep) instead of the host application. It must give the
/// same result as on the host, bit for bit ([`runs_on_a_target`] says which
/// faults can).
pub fn run_case(case: Case, spec: &ScenarioSpec, start: Start, mut target: Option<&mut dyn Target>) -> Result<FaultResult> {
    let fault = case.fault;
    if target.is_some() && !runs_on_a_target(fault) {
        bail!("{}: reboots, preset memories and flash faults run on the host application only", fault.name());
    }
    let t_start = start.at_s;
    let k_start = (t_start / TICK_S).round() as u64;
    // Power losses: when, and whether the machine stops meanwhile.
    let power_off: Option<(f64, bool)> = match fault {
        Fault::PowerLoss | Fault::FlashReadFail => Some((t_start, true)),
        Fault::FlashWriteFail => Some((t_start + WRITE_FAIL_TO_POWER_LOSS_S, true)),
        Fault::PowerLossMachineRunning => Some((t_start, false)),
        _ => None,
    };
    let k_off = power_off.map(|(t, _)| (t / TICK_S).round() as u64);
    let scenario = match power_off {
        Some((t, true)) => machine_off(&spec.scenario, t, t + POWER_OFF_S)?,
        _ => spec.scenario.clone(),
    };
    let duration = spec.duration_s();
    let mut target_error: Option<anyhow::Error> = None;
    let rig = Rig::default();
    let mut plant = Plant::new(&rig, &scenario).context("plant")?;
    let cfg = GuardConfig::DEFAULT;
    let first = Sensors::from(&plant.snapshot()).sample();
    let mut board = Box::new(MemBoard::new().with_nv());
    board.rtc = Some(RTC0);
    board.rtc_backup = Some(0);
    let budget_empty = spec.tank_empty || matches!(fault, Fault::LngEmpty | Fault::RefillWhileEmpty);
    if budget_empty {
        board.records[0] = lng_empty_record(&cfg, first.ambient_c);
    }
    let mut mcu = Some(Mcu::boot(board));
    let mut off_board: Option<Box<MemBoard>> = None;
    let mut rng = Gauss::new(0x5EED ^ fault.name().len() as u64);
    let mut cmd = match fault {
        Fault::ClearSpam => Some(Commander::new(Cmd::ClearArm, Cmd::ClearConfirm, k_start, 100)),
        Fault::CorruptStartClear => Some(Commander::new(Cmd::ClearArm, Cmd::ClearConfirm, k_start + 200, 1000)),
        Fault::RefillWhileEmpty => Some(Commander::new(Cmd::RefillArm, Cmd::RefillConfirm, k_start, 1000)),
        _ => None,
    };
    let input = match fault {
        Fault::Input(c, f) => Some((c, f)),
        Fault::ClearSpam => Some((Channel::PressureA, InputFault::StuckZero)),
        _ => None,
    };
    let mut seq: u16 = 0;
    let mut out: Option<Output> = None;
    let mut frozen: Option<f32> = None;
    let mut held: Option<Vec<u8>> = None; // out-of-order: a frame held back
    let mut k: u64 = 0;
    let mut before = Faults::NONE;
    let mut observable_at: Option<f64> = None;
    let mut detect: Option<(f64, Faults, Output)> = None;
    // per tick after the start, while not protected: (t, under K, closed drain °C)
    let mut exposed: Vec<(f64, f64, f64)> = Vec::new();
    let mut powered_off_until: Option<f64> = None;
    let mut stuck_closed = false;
    let mut valve_position = false;
    let mut first_open: Option<f64> = None;
    let mut first_alarm: Option<f64> = None;
    let (mut peak, mut peak_s) = (f64::NEG_INFINITY, 0.0);
    plant
        .run(TICK_S, duration, |snap| {
            let s = Sensors::from(snap);
            let t = s.t;
            let active = k >= k_start;
            if k == k_start {
                before = out.map_or(Faults::NONE, |o| o.faults & DETECT_MASK);
                match fault {
                    Fault::WarmReset | Fault::TornRecordWrite | Fault::CorruptStartClear => {
                        let damage = match fault {
                            Fault::TornRecordWrite => Damage::Newest,
                            Fault::CorruptStartClear => Damage::Both,
                            _ => Damage::None,
                        };
                        if let Some(m) = mcu.take() {
                            mcu = Some(m.reset(damage));
                        }
                    }
                    Fault::ValveStuckClosed => stuck_closed = true,
                    Fault::FlashWriteFail => {
                        if let Some(m) = mcu.as_mut() {
                            m.app.board.set_flash_faults(false, true);
                        }
                    }
                    _ => {}
                }
                if fault != Fault::ValveStuckClosed {
                    observable_at = Some(t);
                }
            }
            if Some(k) == k_off {
                if let Some(m) = mcu.take() {
                    let mut b = m.app.into_board();
                    b.power_loss();
                    off_board = Some(b);
                }
                powered_off_until = Some(t + POWER_OFF_S);
            }
            if let Some(until) = powered_off_until {
                if t >= until - 1e-9 {
                    // Power back: RAM is lost, the flash and the clock remain.
                    if let Some(mut b) = off_board.take() {
                        if fault == Fault::FlashReadFail {
                            b.set_flash_faults(true, false);
                        }
                        mcu = Some(Mcu::boot(b));
                    }
                    powered_off_until = None;
                    seq = 0;
                }
            }
            // The board's clock (runs through a power loss).
            let rtc = Some(RTC0 + t as u32);
            if let Some(m) = mcu.as_mut() {
                m.app.board.rtc = rtc;
            }
            if let Some(b) = off_board.as_mut() {
                b.rtc = rtc;
            }
            // The physical tank: empty from the start, or from the fault on.
            let tank_empty = budget_empty || (active && fault == Fault::LngEmptyPhysical);
            // The controller's frame for this tick.
            let truth: Sample = s.sample();
            let mut sample = truth;
            if let (true, Some((c, f))) = (active, input) {
                let fz = *frozen.get_or_insert_with(|| c.get(&sample));
                corrupt_sample(&mut sample, c, f, t - t_start, fz, &mut rng);
            }
            let send = match fault {
                Fault::LateStart => t >= 5.0 - 1e-9,
                Fault::DropoutBursts => !(active && ((t - t_start) % 10.0) < 0.5 - 1e-9),
                _ => true,
            };
            let fb = !(active && fault == Fault::NoValveFeedback);
            let reports = eha_guard::Reports {
                // The valve's position switch: where the valve really is.
                valve_fb: fb.then_some(valve_position),
                elec_hz: (case.inputs != Inputs::NoElec).then(|| (f64::from(truth.speed_rpm) * POLE_PAIRS / 60.0) as f32),
                lng_supply_bar: (case.inputs == Inputs::Supply).then_some(if tank_empty { 0.0 } else { 5.0 }),
            };
            let req = Request { seq, sample, reports };
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
                if let Some(c) = cmd.as_mut().filter(|_| active) {
                    if let Some(f) = c.frame(k) {
                        wire.extend_from_slice(&f);
                    }
                }
                let res = match target.as_deref_mut() {
                    Some(t) => t.tick(&wire, k),
                    None => m.app.tick(&wire, k),
                };
                match res {
                    Ok(r) => {
                        if let Some(c) = cmd.as_mut() {
                            c.read(&r.others);
                        }
                        out = Some(r.reply.out);
                    }
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
            let physical = commanded && !stuck_closed;
            valve_position = physical;
            let cooling = physical && !tank_empty;
            if stuck_closed && commanded && observable_at.is_none() {
                observable_at = Some(t);
            }
            if let (Some(_), Some(o)) = (&mcu, out) {
                if o.valve_open && first_open.is_none() && t > 1.0 {
                    first_open = Some(t);
                }
                if o.alarm && first_alarm.is_none() && t > 1.0 {
                    first_alarm = Some(t);
                }
            }
            if active {
                if s.t_drain_c > peak {
                    (peak, peak_s) = (s.t_drain_c, t);
                }
                if let (Some(_), Some(o)) = (&mcu, out) {
                    let new = o.faults & DETECT_MASK & !before;
                    if !new.is_empty() && detect.is_none() {
                        if let Some(t0) = observable_at {
                            detect = Some(((t - t0).max(0.0), new, o));
                        }
                    }
                    if !protected(&o) {
                        let under = if o.drain_c < 1.0e5 { s.t_drain_c - f64::from(o.drain_c) } else { f64::NEG_INFINITY };
                        let closed = if physical { f64::NEG_INFINITY } else { s.t_drain_c };
                        exposed.push((t, under, closed));
                    }
                }
            }
            k += 1;
            Ok(Control { lng_valve: Some(cooling), stop: false })
        })
        .context("closed-loop run")?;
    if let Some(e) = target_error {
        return Err(e.context(format!("{} on the target", fault.name())));
    }
    // A protected detection within DETECT_S exempts the time before it.
    let grace = match (observable_at, detect) {
        (Some(t0), Some((d, _, o))) if d <= DETECT_S && protected(&o) => Some((t0, t0 + d)),
        _ => None,
    };
    let counted = exposed.iter().filter(|(t, _, _)| grace.is_none_or(|(a, b)| *t < a - 1e-9 || *t > b + 1e-9));
    let (mut max_under, mut max_closed) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    for (_, u, c) in counted {
        max_under = max_under.max(*u);
        max_closed = max_closed.max(*c);
    }
    let max_under_k = if max_under.is_finite() { max_under } else { 0.0 };
    let max_true_drain_closed_c = max_closed.is_finite().then_some(max_closed);
    let pass = max_under_k <= MAX_UNDER_K && max_true_drain_closed_c.is_none_or(|c| c <= MAX_CLOSED_C);
    Ok(FaultResult {
        fault: case.name(),
        scenario: spec.name.into(),
        start: start.kind.name().into(),
        start_s: t_start,
        detected: detect.is_some(),
        detect_s: detect.map(|d| d.0),
        detect_bits: detect.map(|d| bit_names(d.1)),
        action: detect.map(|d| action(&d.2)),
        max_under_k,
        max_true_drain_closed_c,
        peak_true_drain_c: peak,
        peak_s,
        first_open_s: first_open,
        first_alarm_s: first_alarm,
        commands_done: cmd.map_or(0, |c| c.done),
        pass,
        limit: None,
    })
}
