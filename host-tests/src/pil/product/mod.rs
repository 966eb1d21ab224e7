//! The product image (`eha-mps2`) in QEMU, driven over its emulated UART.
//!
//! QEMU runs in real time (no `-icount`): the firmware's 10 ms tick comes
//! from the emulated CMSDK timer, the watchdog is the emulated CMSDK APB
//! watchdog. UART0 is a unix socket; the QEMU monitor is a second socket,
//! used to read the output pins (the FPGAIO LED register) while the
//! firmware cannot report them (hang, reset). The defmt log (semihosting)
//! is kept.

use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use eha_guard::product::wire::{Ack, Cmd, Command as GuardCommand, FromGuard, Pins, Status, TickReply, TraceReply};
use eha_guard::protocol::{Deframer, Request};

use super::{build_bin, Build, PlantModel, PlantSensors, StepControl};

/// Address of the FPGAIO LED register (the two output pins) on mps2-an386.
pub const PINS_ADDR: u32 = 0x4002_8000;

/// Builds the QEMU product image (with the test-only fault injection) once
/// per process and returns the ELF.
pub fn product_elf() -> Result<PathBuf> {
    use std::sync::{Mutex, OnceLock};
    static ELF: OnceLock<Mutex<Option<PathBuf>>> = OnceLock::new();
    let m = ELF.get_or_init(|| Mutex::new(None));
    let mut g = m.lock().unwrap_or_else(|p| p.into_inner());
    if let Some(p) = g.as_ref() {
        return Ok(p.clone());
    }
    let p = build_bin(Build::F32, super::firmware::MPS2, "eha-mps2", &["fault-inject"])?;
    *g = Some(p.clone());
    Ok(p)
}

mod session;
pub use session::*;

/// One plant sample and the tick that used it.
#[derive(Clone, Copy, Debug)]
pub struct ProductSample {
    /// Plant time of the sample, s.
    pub t_s: f64,
    /// The sensors (true drain included).
    pub sensors: PlantSensors,
    /// The request sent.
    pub request: Request,
    /// The tick reply of the tick that consumed it.
    pub tick: TickReply,
}

/// A closed-loop run over the UART.
#[derive(Debug, Default)]
pub struct ProductRun {
    /// One entry per plant sample.
    pub samples: Vec<ProductSample>,
    /// Every tick reply, in order, with its arrival time (s).
    pub ticks: Vec<(f64, TickReply)>,
    /// Other frames received.
    pub others: Vec<Received>,
}

/// Hook called after each plant sample's tick: may send commands; returns
/// `false` to stop the run.
pub type Hook<'a> = dyn FnMut(&mut ProductSession, &ProductSample) -> Result<bool> + 'a;

/// Runs `plant` in closed loop with the product image: each plant sample is
/// sent, the tick that consumed it gives the valve command for the plant's
/// next 10 ms. Waits up to `tick_timeout` for a tick (longer across a reset).
pub fn run_closed_loop(
    s: &mut ProductSession,
    plant: &mut dyn PlantModel,
    duration_s: f64,
    tick_timeout: Duration,
    hook: &mut Hook<'_>,
) -> Result<ProductRun> {
    let mut run = ProductRun::default();
    let mut failure: Option<anyhow::Error> = None;
    let n = (duration_s / 0.01).round() as usize;
    let debug = std::env::var_os("EHA_DEBUG").is_some();
    let mut on_step = |t_s: f64, sensors: &PlantSensors| -> StepControl {
        let k = run.samples.len();
        if k >= n {
            return StepControl::Stop;
        }
        let request = sensors.request((k & 0xFFFF) as u16);
        if let Err(e) = s.send_sample(&request) {
            failure = Some(e);
            return StepControl::Stop;
        }
        let mut waited = 0u32;
        loop {
            match s.next_tick(tick_timeout, &mut run.others) {
                Ok(Some((at, t))) => {
                    if debug && (run.ticks.len() % 500 == 0 || t.tick <= 2) {
                        eprintln!("tick {t:?}");
                    }
                    run.ticks.push((at, t));
                    if t.fresh && t.sample_seq == request.seq {
                        let sample = ProductSample { t_s, sensors: *sensors, request, tick: t };
                        run.samples.push(sample);
                        match hook(s, &sample) {
                            Ok(true) => return StepControl::Valve(t.out.valve_open),
                            Ok(false) => return StepControl::Stop,
                            Err(e) => {
                                failure = Some(e);
                                return StepControl::Stop;
                            }
                        }
                    }
                    // A tick without this sample: it was lost (garbage
                    // on the line, a reboot emptied the receive buffer):
                    // after a few such ticks, or right after a reboot, send
                    // it again (the same sequence number).
                    if !t.fresh {
                        waited += 1;
                        if t.tick <= 2 || waited.is_multiple_of(5) {
                            let _ = s.send_sample(&request);
                        }
                    }
                }
                Ok(None) => {
                    failure = Some(anyhow!("no tick reply within {tick_timeout:?} at plant t = {t_s:.2} s"));
                    return StepControl::Stop;
                }
                Err(e) => {
                    failure = Some(e);
                    return StepControl::Stop;
                }
            }
        }
    };
    let res = plant.run(0.01, duration_s + 0.01, &mut on_step);
    if let Some(e) = failure {
        return Err(e);
    }
    res?;
    Ok(run)
}

/// The host build of the product application (SIL) fed exactly what the
/// firmware's tick replies say it saw: per tick, the sample it used (by
/// sequence number) or none, and the periods an overrun swallowed (gaps in
/// the tick counter). Returns the host's tick replies, one per firmware tick
/// of the first boot (a reset ends the replay).
pub fn sil_replay(run: &ProductRun) -> Vec<TickReply> {
    sil_replay_with_block(run, None)
}

/// [`sil_replay`] on a board whose flash holds the parameter block `block`
/// (as the firmware's PARAMS region). The block is leaked: it stands for
/// flash, which lives as long as the program.
pub fn sil_replay_with_block(run: &ProductRun, block: Option<&[u8; eha_guard::params_block::BLOCK_LEN]>) -> Vec<TickReply> {
    use eha_guard::product::mem_board::MemBoard;
    use eha_guard::product::App;
    #[repr(C, align(4))]
    struct Aligned([u8; eha_guard::params_block::BLOCK_LEN]);
    let block = block.map(|b| &Box::leak(Box::new(Aligned(*b))).0);
    let by_seq: std::collections::HashMap<u16, Request> = run.samples.iter().map(|p| (p.request.seq, p.request)).collect();
    let mut b = Box::new(MemBoard::new());
    b.block = block;
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &eha_guard::GuardConfig::DEFAULT, &mem);
    let mut out = Vec::new();
    let mut last_tick = 0u32;
    for (_, t) in &run.ticks {
        if t.tick <= last_tick {
            break; // the firmware rebooted
        }
        let lost = t.tick - last_tick - 1;
        last_tick = t.tick;
        if t.fresh {
            if let Some(r) = by_seq.get(&t.sample_seq) {
                b.push_rx(&r.encode());
            }
        }
        b.clear_tx();
        app.tick(&mut *b, lost);
        for f in super::sil::frames(b.tx()) {
            if let FromGuard::Tick(r) = f {
                out.push(r);
            }
        }
    }
    out
}

/// The address of a static in `elf` whose symbol name contains every one of
/// `parts` (e.g. the no-init thermal record `["noinit", "RECORD_A"]`).
pub fn symbol_addr(elf: &Path, parts: &[&str]) -> Result<u32> {
    use object::{Object, ObjectSymbol};
    let data = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let file = object::File::parse(&*data).with_context(|| format!("parsing {}", elf.display()))?;
    for sym in file.symbols() {
        if let Ok(name) = sym.name() {
            if parts.iter().all(|p| name.contains(p)) {
                return u32::try_from(sym.address()).context("symbol address above 4 GiB");
            }
        }
    }
    bail!("no symbol containing {parts:?} in {}", elf.display())
}

/// The bytes of a thermal record as the firmware stores it (`#[repr(C)]`,
/// little endian), for `-device loader` into no-init RAM.
pub fn record_bytes(r: &eha_guard::ThermalRecord) -> Vec<u8> {
    r.to_le_bytes().to_vec()
}
