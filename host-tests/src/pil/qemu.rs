//! Running the PIL image in `qemu-system-arm` and talking to it in lockstep.
//!
//! Channels (see `boards/mps2/src/bin/eha-fw.rs`, `eha_guard::protocol::lockstep`):
//! per-tick chunks of received bytes → QEMU stdin; the tick's frames and its
//! end-of-tick frame ← QEMU stderr (semihosting `:tt` append); defmt log ←
//! QEMU stdout. Both output pipes are drained by threads so the emulator
//! never blocks on a full pipe; frames reach the lockstep loop over a
//! channel, which is what gives the timeout.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, ExitStatus, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use eha_guard::product::wire::{FromGuard, Status};
use eha_guard::protocol::lockstep::{parse_tick_end, DONE_TOKEN};
use eha_guard::protocol::Deframer;

use super::error::{exit_meaning, PilError};
use super::firmware::Build;

/// Options of one QEMU session.
#[derive(Clone, Debug)]
pub struct QemuOptions {
    /// Firmware build (selects machine and CPU by default).
    pub build: Build,
    /// The firmware ELF to run.
    pub elf: PathBuf,
    /// QEMU machine and CPU (default: the build's; the tests override them
    /// to run M4F code on a Cortex-M3 and provoke a HardFault).
    pub machine: String,
    /// QEMU CPU (see `machine`).
    pub cpu: String,
    /// How long to wait for one tick's frames before declaring the firmware dead.
    pub reply_timeout: Duration,
    /// Deterministic instruction counting (`-icount shift=10`): the SysTick
    /// cycles of each tick then count instructions × 25.6.
    pub icount: bool,
    /// Extra arguments (e.g. `-S` to start with the CPU stopped, which is how
    /// the tests simulate a firmware that never answers).
    pub extra_args: Vec<String>,
}

impl QemuOptions {
    /// The build's machine and CPU, a 5 s reply timeout, `-icount` on.
    pub fn new(build: Build, elf: &Path) -> Self {
        Self {
            build,
            elf: elf.to_path_buf(),
            machine: build.machine().into(),
            cpu: build.cpu().into(),
            reply_timeout: Duration::from_secs(5), icount: true, extra_args: Vec::new() }
    }
}

/// SysTick ticks per instruction under `-icount shift=10` (25 MHz SysTick,
/// 1.024 µs of virtual time per instruction).
pub const TICKS_PER_INSTRUCTION: f64 = 25.6;

/// Check that `qemu-system-arm` can be run.
pub fn qemu_available() -> Result<String, PilError> {
    match Command::new("qemu-system-arm").arg("--version").stdin(Stdio::null()).output() {
        Ok(o) => Ok(String::from_utf8_lossy(&o.stdout).lines().next().unwrap_or("").to_string()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(PilError::QemuMissing),
        Err(e) => Err(PilError::Spawn(e)),
    }
}

/// For the interactive command: install QEMU with apt-get when it is missing
/// and we can (root, Debian-like system); otherwise say exactly what to do.
pub fn ensure_qemu() -> Result<String, PilError> {
    match qemu_available() {
        Err(PilError::QemuMissing) => {}
        other => return other,
    }
    let is_root = Command::new("id").arg("-u").output().is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    let has_apt = Command::new("apt-get").arg("--version").stdout(Stdio::null()).status().is_ok_and(|s| s.success());
    if !(is_root && has_apt) {
        return Err(PilError::QemuMissing);
    }
    eprintln!("qemu-system-arm not found: installing it (apt-get install -y qemu-system-arm) ...");
    let ok = |args: &[&str]| {
        Command::new("apt-get").args(args).env("DEBIAN_FRONTEND", "noninteractive").stdin(Stdio::null()).status().is_ok_and(|s| s.success())
    };
    // Install; if that fails, refresh the package lists and install again.
    let installed = ok(&["install", "-y", "qemu-system-arm"]) || (ok(&["update"]) && ok(&["install", "-y", "qemu-system-arm"]));
    if !installed {
        return Err(PilError::QemuMissing);
    }
    qemu_available()
}

/// One item read from the firmware's frame stream.
#[derive(Debug)]
enum Item {
    /// A product frame.
    Frame(FromGuard),
    /// The end of a tick, with its cost in cycles.
    TickEnd(u32),
}

/// What a finished session leaves behind.
#[derive(Debug)]
pub struct SessionEnd {
    /// The completion marker (a status reply with the final counters).
    pub done: Status,
    /// QEMU's exit status.
    pub status: ExitStatus,
    /// Raw defmt bytes from stdout.
    pub defmt: Vec<u8>,
    /// Text on stderr that was not a reply frame (QEMU warnings).
    pub text: String,
}

/// A running QEMU with the firmware.
pub struct QemuSession {
    child: Child,
    stdin: Option<ChildStdin>,
    replies: Receiver<Vec<u8>>,
    stdout_thread: Option<JoinHandle<Vec<u8>>>,
    deframer: Deframer,
    pending: std::collections::VecDeque<Item>,
    /// Non-frame bytes seen on stderr (kept for error messages).
    junk: Vec<u8>,
    reply_timeout: Duration,
    eof: bool,
}

impl QemuSession {
    /// The `qemu-system-arm` command line for `opts` (stdio not yet set).
    pub fn command(opts: &QemuOptions) -> Command {
        let mut cmd = Command::new("qemu-system-arm");
        cmd.args(["-machine", &opts.machine, "-cpu", &opts.cpu])
            .args(["-nographic", "-monitor", "none", "-serial", "none"])
            .args(["-semihosting-config", "enable=on,target=native"]);
        if opts.icount {
            cmd.args(["-icount", "shift=10,align=off,sleep=off"]);
        }
        cmd.args(&opts.extra_args).arg("-kernel").arg(&opts.elf);
        cmd
    }

    /// Starts QEMU with the firmware, replies read on a background thread.
    pub fn spawn(opts: &QemuOptions) -> Result<Self, PilError> {
        qemu_available()?;
        let mut child = Self::command(opts)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(PilError::Spawn)?;
        let stdin = child.stdin.take();
        let mut stdout = child.stdout.take().ok_or_else(|| PilError::Spawn(std::io::Error::other("no stdout pipe")))?;
        let mut stderr = child.stderr.take().ok_or_else(|| PilError::Spawn(std::io::Error::other("no stderr pipe")))?;
        let stdout_thread = std::thread::spawn(move || {
            let mut all = Vec::new();
            // Keeps whatever arrived even if the read fails midway.
            let _ = stdout.read_to_end(&mut all);
            all
        });
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            loop {
                match stderr.read(&mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(n) => {
                        if tx.send(buf[..n].to_vec()).is_err() {
                            break;
                        }
                    }
                }
            }
        });
        Ok(Self {
            child,
            stdin,
            replies: rx,
            stdout_thread: Some(stdout_thread),
            deframer: Deframer::new(),
            pending: Default::default(),
            junk: Vec::new(),
            reply_timeout: opts.reply_timeout,
            eof: false,
        })
    }

    /// Send raw bytes to the firmware's stdin (tests of a broken harness).
    pub fn send_raw(&mut self, bytes: &[u8]) -> Result<(), PilError> {
        let stdin = self.stdin.as_mut().ok_or_else(|| PilError::Io(std::io::Error::other("stdin already closed")))?;
        stdin.write_all(bytes)?;
        stdin.flush()?;
        Ok(())
    }

    /// Send one tick's received bytes (a length-prefixed chunk).
    pub fn send_chunk(&mut self, bytes: &[u8]) -> Result<(), PilError> {
        let n = u16::try_from(bytes.len()).map_err(|_| PilError::Io(std::io::Error::other("a tick's chunk is longer than 65535 bytes")))?;
        let stdin = self.stdin.as_mut().ok_or_else(|| PilError::Io(std::io::Error::other("stdin already closed")))?;
        stdin.write_all(&n.to_le_bytes())?;
        stdin.write_all(bytes)?;
        stdin.flush()?;
        Ok(())
    }

    fn text(&self) -> String {
        String::from_utf8_lossy(&self.junk).trim().to_string()
    }

    /// The frames of the next tick, up to its end-of-tick frame, waiting at
    /// most the reply timeout for each.
    pub fn recv_tick(&mut self, tick: u64) -> Result<super::TickOut, PilError> {
        let mut frames = Vec::new();
        loop {
            match self.recv(tick)? {
                Item::Frame(f) => frames.push(f),
                Item::TickEnd(cycles) => {
                    return super::tick_out(frames, cycles)
                        .ok_or_else(|| PilError::Protocol { tick, what: "a tick without a tick reply".into() });
                }
            }
        }
    }

    /// Receive the next item, waiting at most the reply timeout.
    fn recv(&mut self, tick: u64) -> Result<Item, PilError> {
        let deadline = Instant::now() + self.reply_timeout;
        loop {
            if let Some(r) = self.pending.pop_front() {
                return Ok(r);
            }
            if self.eof {
                return Err(self.exited(tick));
            }
            let now = Instant::now();
            let wait = deadline.saturating_duration_since(now);
            match self.replies.recv_timeout(wait) {
                Ok(chunk) => self.absorb(&chunk),
                Err(RecvTimeoutError::Timeout) => {
                    let _ = self.child.kill();
                    let _ = self.child.wait();
                    return Err(PilError::Timeout { tick, waited: self.reply_timeout, text: self.text() });
                }
                Err(RecvTimeoutError::Disconnected) => self.eof = true,
            }
        }
    }

    fn absorb(&mut self, chunk: &[u8]) {
        for &b in chunk {
            if b != 0 {
                // Keep a copy of the raw bytes of the current frame in case it
                // turns out to be text rather than a reply.
                self.junk.push(b);
            }
            match self.deframer.push(b) {
                None => {}
                Some(Ok(p)) => {
                    // A payload that is not a frame of ours stays as text.
                    let item = match parse_tick_end(p) {
                        Some(c) => Some(Item::TickEnd(c)),
                        None => FromGuard::from_payload(p).ok().map(Item::Frame),
                    };
                    if let Some(item) = item {
                        self.pending.push_back(item);
                        self.junk_drop_frame();
                    }
                }
                Some(Err(_)) => {} // not a frame: keep as text
            }
            if b == 0 {
                self.junk.push(b'\n');
            }
        }
        // Bound the kept text.
        if self.junk.len() > 8192 {
            let cut = self.junk.len() - 8192;
            self.junk.drain(..cut);
        }
    }

    fn junk_drop_frame(&mut self) {
        // A decoded reply's COBS bytes are the last bytes in `junk` up to the
        // previous '\n' marker: remove them so only genuine text remains.
        let start = self.junk.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        self.junk.truncate(start);
    }

    /// The process ended (replies channel closed): say how.
    fn exited(&mut self, tick: u64) -> PilError {
        let status = wait_timeout(&mut self.child, Duration::from_secs(5));
        let code = status.and_then(|s| s.code());
        PilError::Exited { tick, code, meaning: code.map_or("killed by a signal or did not exit", exit_meaning), text: self.text() }
    }

    /// Close stdin (end of input), collect the completion marker and wait
    /// for a clean exit. Any other ending is an error.
    pub fn finish(mut self, tick: u64) -> Result<SessionEnd, PilError> {
        drop(self.stdin.take());
        let done = loop {
            match self.recv(tick) {
                Ok(Item::Frame(FromGuard::Status(s))) if s.token == DONE_TOKEN => break Some(s),
                Ok(_) => continue,
                Err(PilError::Exited { code: Some(0), .. }) => break None,
                Err(e) => return Err(e),
            }
        };
        let status = match wait_timeout(&mut self.child, self.reply_timeout) {
            Some(s) => s,
            None => {
                let _ = self.child.kill();
                let _ = self.child.wait();
                return Err(PilError::Timeout { tick, waited: self.reply_timeout, text: self.text() });
            }
        };
        let defmt = self.stdout_thread.take().and_then(|h| h.join().ok()).unwrap_or_default();
        let text = self.text();
        match (done, status.code()) {
            (Some(done), Some(0)) => Ok(SessionEnd { done, status, defmt, text }),
            (None, _) => Err(PilError::NoCompletionMarker { status: status.to_string(), text }),
            (Some(_), code) => Err(PilError::Exited {
                tick,
                code,
                meaning: code.map_or("killed by a signal", exit_meaning),
                text,
            }),
        }
    }

    /// Raw defmt bytes received so far are only available after `finish`;
    /// on an error path call this to salvage them.
    pub fn abort(mut self) -> Vec<u8> {
        let _ = self.child.kill();
        let _ = self.child.wait();
        drop(self.stdin.take());
        self.stdout_thread.take().and_then(|h| h.join().ok()).unwrap_or_default()
    }
}

impl Drop for QemuSession {
    fn drop(&mut self) {
        // Never leave an emulator behind.
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

fn wait_timeout(child: &mut Child, timeout: Duration) -> Option<ExitStatus> {
    let deadline = Instant::now() + timeout;
    loop {
        match child.try_wait() {
            Ok(Some(s)) => return Some(s),
            Ok(None) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(2)),
            _ => return None,
        }
    }
}
