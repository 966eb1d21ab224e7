//! A session with the product image in QEMU: its UART and monitor
//! sockets, the gdb stub, and the frames received.

use super::*;

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
        crate::pil::qemu::qemu_available()?;
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
