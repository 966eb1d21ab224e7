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

/// Sends one gdb remote-protocol packet and, if `reply`, waits for `OK`.
fn gdb_packet(s: &mut UnixStream, body: &str, reply: bool) -> Result<()> {
    let sum = body.bytes().fold(0u8, u8::wrapping_add);
    s.write_all(format!("${body}#{sum:02x}").as_bytes())?;
    if !reply {
        return Ok(());
    }
    s.set_read_timeout(Some(Duration::from_secs(5)))?;
    let mut got = Vec::new();
    let mut buf = [0u8; 256];
    while !got.windows(2).any(|w| w == b"OK") {
        let n = s.read(&mut buf).context("reading the gdb stub")?;
        if n == 0 {
            bail!("gdb stub closed");
        }
        got.extend_from_slice(&buf[..n]);
        if got.starts_with(b"+$E") || got.windows(2).any(|w| w == b"$E") {
            bail!("gdb stub refused `{}`: {}", &body[..body.len().min(20)], String::from_utf8_lossy(&got));
        }
    }
    s.write_all(b"+")?;
    Ok(())
}

/// A frame from the guard with its arrival time.
#[derive(Clone, Copy, Debug)]
pub struct Received {
    /// Wall time since the session started, s.
    pub at_s: f64,
    /// The frame.
    pub frame: FromGuard,
}

/// A running product image.
pub struct ProductSession {
    child: Child,
    uart: UnixStream,
    monitor: Option<BufReader<UnixStream>>,
    rx: Receiver<Received>,
    stdout: Option<JoinHandle<Vec<u8>>>,
    start: Instant,
    dir: PathBuf,
    /// Frames received but not yet consumed, in order.
    pub backlog: std::collections::VecDeque<Received>,
}

fn connect(path: &Path, child: &mut Child) -> Result<UnixStream> {
    let t0 = Instant::now();
    loop {
        match UnixStream::connect(path) {
            Ok(s) => return Ok(s),
            Err(e) => {
                if let Ok(Some(st)) = child.try_wait() {
                    bail!("QEMU exited ({st}) before opening {}", path.display());
                }
                if t0.elapsed() > Duration::from_secs(20) {
                    return Err(e).with_context(|| format!("connecting to {}", path.display()));
                }
                std::thread::sleep(Duration::from_millis(20));
            }
        }
    }
}

impl ProductSession {
    /// Starts QEMU with `elf`; `extra` are more QEMU arguments.
    pub fn spawn(elf: &Path, extra: &[String]) -> Result<Self> {
        Self::spawn_with_ram(elf, extra, &[])
    }

    /// Starts QEMU with `elf` and the bytes `ram` written at their addresses
    /// before the CPU runs (e.g. a thermal record in no-init RAM, as a warm
    /// reset leaves it). The writes go through QEMU's gdb stub: the CPU starts
    /// stopped (`-S`), the memory is written, then the stub detaches. (A
    /// `-device loader` blob there overlaps the ELF's RAM segment, which QEMU
    /// refuses.)
    pub fn spawn_with_ram(elf: &Path, extra: &[String], ram: &[(u32, Vec<u8>)]) -> Result<Self> {
        super::qemu::qemu_available()?;
        let dir = std::env::temp_dir().join(format!("eha-product-{}-{:?}", std::process::id(), std::thread::current().id()))
            .with_extension(format!("{}", Instant::now().elapsed().as_nanos()));
        let dir = PathBuf::from(dir.to_string_lossy().replace(['(', ')', ' '], ""));
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        let uart = dir.join("uart.sock");
        let mon = dir.join("mon.sock");
        let gdb = dir.join("gdb.sock");
        let mut gdb_args: Vec<String> = Vec::new();
        if !ram.is_empty() {
            gdb_args = vec!["-S".into(), "-gdb".into(), format!("unix:{},server=on,wait=off", gdb.display())];
        }
        let mut child = Command::new("qemu-system-arm")
            .args(&gdb_args)
            .args(["-machine", "mps2-an386", "-cpu", "cortex-m4", "-nographic"])
            .args(["-semihosting-config", "enable=on,target=native"])
            .arg("-chardev")
            .arg(format!("socket,id=ctl,path={},server=on,wait=on", uart.display()))
            .args(["-serial", "chardev:ctl"])
            .arg("-monitor")
            .arg(format!("unix:{},server=on,wait=off", mon.display()))
            .args(extra)
            .arg("-kernel")
            .arg(elf)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .context("starting qemu-system-arm")?;
        let mut out = child.stdout.take().ok_or_else(|| anyhow!("no stdout pipe"))?;
        let stdout = std::thread::spawn(move || {
            let mut all = Vec::new();
            let _ = out.read_to_end(&mut all);
            all
        });
        let uart = connect(&uart, &mut child)?;
        let monitor = connect(&mon, &mut child).ok().map(BufReader::new);
        if !ram.is_empty() {
            let mut g = connect(&gdb, &mut child)?;
            for (addr, bytes) in ram {
                let hex: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
                gdb_packet(&mut g, &format!("M{addr:x},{:x}:{hex}", bytes.len()), true)?;
            }
            // Detach: the CPU runs, and the stub is out of the way (a stub
            // that stays attached stops the machine at a later reset).
            gdb_packet(&mut g, "D", true)?;
        }
        let start = Instant::now();
        let (tx, rx) = mpsc::channel();
        let mut reader = uart.try_clone().context("cloning the UART socket")?;
        std::thread::spawn(move || {
            let mut d = Deframer::new();
            let mut buf = [0u8; 1024];
            loop {
                let n = match reader.read(&mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(n) => n,
                };
                for &b in &buf[..n] {
                    if let Some(Ok(p)) = d.push(b) {
                        if let Ok(frame) = FromGuard::from_payload(p) {
                            let r = Received { at_s: start.elapsed().as_secs_f64(), frame };
                            if tx.send(r).is_err() {
                                return;
                            }
                        }
                    }
                }
            }
        });
        let mut s = ProductSession { child, uart, monitor, rx, stdout: Some(stdout), start, dir, backlog: Default::default() };
        if let Some(m) = s.monitor.as_mut() {
            // Swallow the monitor's banner.
            let mut line = String::new();
            let _ = m.get_mut().set_read_timeout(Some(Duration::from_millis(500)));
            let _ = m.read_line(&mut line);
        }
        Ok(s)
    }

    /// Wall seconds since the session started.
    pub fn elapsed_s(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    /// Sends raw bytes on the UART.
    pub fn send(&mut self, bytes: &[u8]) -> Result<()> {
        self.uart.write_all(bytes).context("writing to the emulated UART")
    }

    /// Sends a sample.
    pub fn send_sample(&mut self, r: &Request) -> Result<()> {
        self.send(&r.encode())
    }

    /// Sends a command.
    pub fn command(&mut self, token: u16, cmd: Cmd) -> Result<()> {
        self.send(&GuardCommand { token, cmd, arg: 0 }.encode())
    }

    /// The next frame, waiting at most `timeout`.
    pub fn next(&mut self, timeout: Duration) -> Result<Option<Received>> {
        if let Some(r) = self.backlog.pop_front() {
            return Ok(Some(r));
        }
        match self.rx.recv_timeout(timeout) {
            Ok(r) => Ok(Some(r)),
            Err(RecvTimeoutError::Timeout) => Ok(None),
            Err(RecvTimeoutError::Disconnected) => bail!("the UART closed (QEMU exited?)"),
        }
    }

    /// The next tick reply; other frames go to `others`.
    pub fn next_tick(&mut self, timeout: Duration, others: &mut Vec<Received>) -> Result<Option<(f64, TickReply)>> {
        let t0 = Instant::now();
        loop {
            let left = timeout.saturating_sub(t0.elapsed());
            match self.next(left)? {
                None => return Ok(None),
                Some(Received { at_s, frame: FromGuard::Tick(t) }) => return Ok(Some((at_s, t))),
                Some(r) => others.push(r),
            }
        }
    }

    /// Sends a command and waits for its reply frames: the ack (or status),
    /// and for a trace dump every event. Tick replies in between go to `ticks`.
    pub fn request(&mut self, token: u16, cmd: Cmd, ticks: &mut Vec<(f64, TickReply)>) -> Result<Vec<FromGuard>> {
        self.command(token, cmd)?;
        let t0 = Instant::now();
        let mut got = Vec::new();
        while t0.elapsed() < Duration::from_secs(5) {
            let Some(r) = self.next(Duration::from_millis(200))? else { continue };
            match r.frame {
                FromGuard::Tick(t) => ticks.push((r.at_s, t)),
                FromGuard::Ack(Ack { token: k, .. }) if k == token => {
                    got.push(r.frame);
                    return Ok(got);
                }
                FromGuard::Status(Status { token: k, .. }) if k == token => {
                    got.push(r.frame);
                    return Ok(got);
                }
                FromGuard::Trace(TraceReply { token: k, index, count, .. }) if k == token => {
                    got.push(r.frame);
                    if index + 1 >= count {
                        return Ok(got);
                    }
                }
                _ => {}
            }
        }
        bail!("no reply to command {cmd:?} (token {token}) within 5 s")
    }

    /// The status reply.
    pub fn status(&mut self, token: u16, ticks: &mut Vec<(f64, TickReply)>) -> Result<Status> {
        match self.request(token, Cmd::Status, ticks)?.pop() {
            Some(FromGuard::Status(s)) => Ok(s),
            other => bail!("expected a status reply, got {other:?}"),
        }
    }

    /// The output pins read through the QEMU monitor (works while the
    /// firmware is hung or resetting).
    pub fn pins(&mut self) -> Result<Pins> {
        let m = self.monitor.as_mut().ok_or_else(|| anyhow!("no QEMU monitor"))?;
        m.get_mut().write_all(format!("xp /1wx {PINS_ADDR:#x}\n").as_bytes())?;
        let mut line = String::new();
        let t0 = Instant::now();
        while t0.elapsed() < Duration::from_secs(2) {
            line.clear();
            if m.read_line(&mut line).is_err() {
                continue;
            }
            if let Some(v) = line.trim().strip_prefix(&format!("{PINS_ADDR:016x}:")) {
                let v = u32::from_str_radix(v.trim().trim_start_matches("0x"), 16)?;
                return Ok(Pins { valve_pin: v & 1 != 0, ok_pin: v & 2 != 0 });
            }
        }
        bail!("the QEMU monitor did not answer `xp`")
    }

    /// Stops QEMU and returns the raw defmt bytes it wrote.
    pub fn stop(mut self) -> Vec<u8> {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let out = self.stdout.take().and_then(|h| h.join().ok()).unwrap_or_default();
        let _ = std::fs::remove_dir_all(&self.dir);
        out
    }
}

impl Drop for ProductSession {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

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
