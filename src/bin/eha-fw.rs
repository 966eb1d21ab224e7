//! EHA thermal-guard firmware for QEMU processor-in-the-loop runs.
//!
//! One source for both numeric builds:
//! - `cargo fw-build`    : f32, thumbv7em-none-eabihf, QEMU `mps2-an386` (Cortex-M4F)
//! - `cargo fw-build-m3` : fixed point, thumbv7m-none-eabi, QEMU `mps2-an385` (Cortex-M3)
//!
//! Channels (semihosting; see `shared/toolchain-notes.md`):
//! - request frames come in on stdin (`:tt` read);
//! - reply frames go out on `:tt` opened for append (host **stderr**);
//! - the defmt log goes out on stdout (`defmt-semihosting`).
//!
//! The frame handling is [`eha_guard::protocol::Link`], which only sees bytes:
//! a board build hands it the bytes from its UART instead of stdin.
//!
//! At end of input (stdin EOF) the firmware sends the completion marker (a
//! `Done` reply with the final counters), logs a summary and exits 0.
//!
//! Exit codes (`semihosting::process::exit`), decoded by the host harness:
//! | code | meaning |
//! |---|---|
//! | 0 | end of input reached, completion marker sent |
//! | 2 | panic |
//! | 3 | HardFault |
//! | 4 | unexpected exception or interrupt (DefaultHandler) |
//! | 5 | semihosting read (stdin) failed |
//! | 6 | semihosting write (replies) failed |
//! | 7 | semihosting open of stdin/stderr failed |
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(not(target_os = "none"))]
fn main() {}

#[cfg(target_os = "none")]
mod fw {
    use cortex_m::peripheral::{syst::SystClkSource, SYST};
    use cortex_m_rt::{entry, exception, ExceptionFrame};
    use defmt_semihosting as _;
    use eha_guard::memory::slots::{self, noinit, AbWriter};
    use eha_guard::memory::Restore;
    use eha_guard::protocol::{tick_guard, GuardOutput, Link, Reply, ReplyKind, Request};
    use eha_guard::{Guard, GuardConfig};
    use semihosting::io::{Read as _, Write as _};
    use semihosting::process::exit;

    pub const EXIT_PANIC: i32 = 2;
    pub const EXIT_HARDFAULT: i32 = 3;
    pub const EXIT_EXCEPTION: i32 = 4;
    pub const EXIT_READ: i32 = 5;
    pub const EXIT_WRITE: i32 = 6;
    pub const EXIT_OPEN: i32 = 7;

    #[cfg(feature = "fixed-point")]
    const BUILD: &str = "fixed-point";
    #[cfg(not(feature = "fixed-point"))]
    const BUILD: &str = "f32";

    defmt::timestamp!("{=u32}", {
        // Tick counter as the log timestamp: plant time = stamp × 10 ms.
        TICKS.load(core::sync::atomic::Ordering::Relaxed)
    });
    static TICKS: core::sync::atomic::AtomicU32 = core::sync::atomic::AtomicU32::new(0);

    /// SysTick ticks elapsed between two readings of the 24-bit down counter.
    fn ticks_between(start: u32, end: u32) -> u32 {
        start.wrapping_sub(end) & 0x00FF_FFFF
    }

    #[entry]
    fn main() -> ! {
        // Core peripherals are taken once at boot; `take` returns None only
        // on a second call, which cannot happen here.
        let Some(mut cp) = cortex_m::Peripherals::take() else { exit(EXIT_EXCEPTION) };
        cp.SYST.set_clock_source(SystClkSource::Core);
        cp.SYST.set_reload(0x00FF_FFFF);
        cp.SYST.clear_current();
        cp.SYST.enable_counter();

        let (Ok(mut stdin), Ok(mut replies)) = (semihosting::io::stdin(), semihosting::io::stderr()) else {
            exit(EXIT_OPEN)
        };

        // Thermal memory: a warm reset restores the newest valid no-init
        // record (A/B), a cold boot (QEMU starts with zeroed RAM) starts at
        // ambient, damaged records start conservatively (`eha_guard::memory`).
        let (rec_a, rec_b) = noinit::load();
        let restore = slots::restore_from(&rec_a, &rec_b);
        let mut records = AbWriter::after_boot(&rec_a, &rec_b);
        let mut guard = Guard::new(&GuardConfig::DEFAULT, restore);
        defmt::info!("eha-fw up: build {=str}, restore {=str}, faults {=u16:#06x}", BUILD, restore_name(&restore), guard.faults().bits());
        let mut last_trace = guard.trace().recent().copied();

        let mut link = Link::new();
        // The outputs at boot (valve open while waiting for the first frame), so the
        // first frame's changes are logged against them.
        let mut last = guard.output();
        let mut buf = [0u8; 64];
        loop {
            let n = match stdin.read(&mut buf) {
                Ok(n) => n,
                Err(_) => {
                    defmt::error!("stdin read failed");
                    exit(EXIT_READ)
                }
            };
            let Some(chunk) = buf.get(..n) else { exit(EXIT_READ) };
            if chunk.is_empty() {
                // End of input: completion marker, summary, clean exit.
                let done = link.done();
                if replies.write_all(&done.encode()).is_err() {
                    exit(EXIT_WRITE);
                }
                let c = link.counters();
                defmt::info!(
                    "end of input: accepted={=u32} rejected crc={=u16} framing={=u16} sequence={=u16} skipped={=u16} pending_partial={=bool}",
                    c.accepted,
                    c.rejected_crc,
                    c.rejected_framing,
                    c.rejected_sequence,
                    c.skipped,
                    link.pending()
                );
                exit(0)
            }
            let mut write_failed = false;
            link.push_bytes(
                chunk,
                |req: &Request, skipped: u16| {
                    let t0 = SYST::get_current();
                    let out = tick_guard(&mut guard, req, skipped);
                    let t1 = SYST::get_current();
                    records.write(&guard.snapshot(), noinit::store);
                    TICKS.fetch_add(1, core::sync::atomic::Ordering::Relaxed);
                    log_changes(&last, &out);
                    let trace = guard.trace().recent().copied();
                    if trace != last_trace {
                        if let Some(ev) = trace {
                            defmt::info!("trace {}", ev);
                        }
                        last_trace = trace;
                    }
                    last = out;
                    (out, ticks_between(t0, t1))
                },
                |reply: &Reply, wire: &[u8]| {
                    if let ReplyKind::Reject(reason) = reply.kind {
                        defmt::warn!("frame rejected: reason={=u8} seq={=u16} total={=u32}", reason as u8, reply.seq, reply.counters.rejected());
                    }
                    if replies.write_all(wire).is_err() {
                        write_failed = true;
                    }
                },
            );
            if write_failed {
                exit(EXIT_WRITE);
            }
        }
    }

    fn restore_name(r: &Restore) -> &'static str {
        match r {
            Restore::Cold => "cold",
            Restore::Warm(_) => "warm",
            Restore::Corrupt => "corrupt record",
            Restore::PowerLoss(_) => "power loss (non-volatile record)",
        }
    }

    fn log_changes(prev: &GuardOutput, out: &GuardOutput) {
        if prev.valve_open != out.valve_open {
            defmt::info!("LNG valve {=str} at drain {=f32} C", if out.valve_open { "OPEN" } else { "CLOSED" }, out.drain_c);
        }
        if prev.alarm != out.alarm {
            defmt::warn!("over-temperature alarm {=bool} at drain {=f32} C", out.alarm, out.drain_c);
        }
        if prev.faults != out.faults {
            defmt::error!("faults {=u16:#06x} -> {=u16:#06x}", prev.faults.bits(), out.faults.bits());
        }
    }

    #[exception]
    unsafe fn HardFault(_ef: &ExceptionFrame) -> ! {
        // No logging here: the fault may have hit inside the logger.
        exit(EXIT_HARDFAULT)
    }

    #[exception]
    unsafe fn DefaultHandler(_irqn: i16) {
        exit(EXIT_EXCEPTION)
    }

    #[panic_handler]
    fn panic(_info: &core::panic::PanicInfo) -> ! {
        exit(EXIT_PANIC)
    }
}

