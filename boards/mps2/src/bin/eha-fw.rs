//! The product application in QEMU for processor-in-the-loop runs: the same
//! [`eha_guard::product::App`] as the flashed image, on a semihosting board
//! that ticks once per chunk of bytes the host sends (lockstep: a run is
//! deterministic and as fast as the emulator). What is tested is what ships;
//! only the board differs.
//!
//! One source for both numeric builds:
//! - `cargo fw-build`    : f32, thumbv7em-none-eabihf, QEMU `mps2-an386` (Cortex-M4F)
//! - `cargo fw-build-m3` : fixed point, thumbv7m-none-eabi, QEMU `mps2-an385` (Cortex-M3)
//!
//! Channels (semihosting; transport in [`eha_guard::protocol::lockstep`]):
//! - per tick, a length-prefixed chunk of received bytes on stdin (`:tt` read);
//! - the tick's frames and an end-of-tick frame (its cost in SysTick cycles)
//!   on `:tt` opened for append (host **stderr**);
//! - the defmt log on stdout (`defmt-semihosting`).
//!
//! The thermal records live in no-init RAM as on the boards (QEMU starts with
//! zeroed RAM: a cold start). At end of input the firmware sends the
//! completion marker (a status reply with token
//! [`eha_guard::protocol::lockstep::DONE_TOKEN`]), logs a summary and exits 0.
//!
//! Exit codes (`semihosting::process::exit`), decoded by the host harness:
//! | code | meaning |
//! |---|---|
//! | 0 | end of input reached, completion marker sent |
//! | 2 | panic |
//! | 3 | HardFault |
//! | 4 | unexpected exception or interrupt (DefaultHandler) |
//! | 5 | semihosting read (stdin) failed, or a chunk was cut short |
//! | 6 | semihosting write (replies) failed |
//! | 7 | semihosting open of stdin/stderr failed |
#![no_std]
#![no_main]

// The mps2 vector table (shared with the product image).
#[path = "../vectors.rs"]
mod vectors;

mod fw {
    use core::mem::MaybeUninit;
    use cortex_m::peripheral::{syst::SystClkSource, SYST};
    use cortex_m_rt::{entry, exception, ExceptionFrame};
    use defmt_semihosting as _;
    use eha_cortex_m::noinit;
    use eha_guard::memory::nv::NvLoad;
    use eha_guard::memory::ThermalRecord;
    use eha_guard::product::reset::CauseRecord;
    use eha_guard::product::wire::Pins;
    use eha_guard::product::{App, Board};
    use eha_guard::protocol::lockstep::{tick_end, DONE_TOKEN};
    use eha_guard::{GuardConfig, Output};
    use semihosting::io::{Stderr, Stdin};
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

    /// Largest chunk of received bytes per tick (the host's chunks are one
    /// sample frame and a few commands; more is a harness error).
    const RX_CHUNK: usize = 1024;
    /// Bytes a tick may send (reply, acks, status, trace: under 400).
    const TX_CHUNK: usize = 1024;

    /// The lockstep board: the tick's received bytes come from the host's
    /// chunk, sent bytes collect until the end of the tick, pins echo,
    /// records in no-init RAM as on the product boards.
    struct Lockstep {
        stdin: Stdin,
        out: Stderr,
        rx: [u8; RX_CHUNK],
        rx_len: usize,
        rx_at: usize,
        tx: heapless::Vec<u8, TX_CHUNK>,
        tx_lost: u32,
        ticks: u32,
    }

    impl Lockstep {
        /// Reads the next tick's chunk; `false` at end of input.
        fn next_chunk(&mut self) -> bool {
            let mut hdr = [0u8; 2];
            match read_exact(&mut self.stdin, &mut hdr) {
                Ok(true) => {}
                Ok(false) => return false,
                Err(()) => exit(EXIT_READ),
            }
            let n = usize::from(u16::from_le_bytes(hdr));
            let Some(dst) = self.rx.get_mut(..n) else { exit(EXIT_READ) };
            if read_exact(&mut self.stdin, dst) != Ok(true) && n > 0 {
                exit(EXIT_READ)
            }
            self.rx_len = n;
            self.rx_at = 0;
            true
        }

        /// Sends the tick's frames and its end-of-tick frame.
        fn end_tick(&mut self, cycles: u32) {
            let end = tick_end(cycles);
            if self.tx.extend_from_slice(&end).is_err() {
                self.tx_lost = self.tx_lost.saturating_add(1);
            }
            if self.out.write_all(&self.tx).is_err() {
                exit(EXIT_WRITE)
            }
            self.tx.clear();
        }
    }

    /// Fills `buf`; `Ok(false)` at end of input before the first byte.
    fn read_exact(fd: &mut Stdin, buf: &mut [u8]) -> Result<bool, ()> {
        let mut at = 0;
        while at < buf.len() {
            let Some(rest) = buf.get_mut(at..) else { return Err(()) };
            match fd.read(rest) {
                Ok(0) if at == 0 => return Ok(false),
                Ok(0) => return Err(()),
                Ok(n) => at += n,
                Err(_) => return Err(()),
            }
        }
        Ok(true)
    }

    impl Board for Lockstep {
        fn read_rx(&mut self, buf: &mut [u8]) -> usize {
            let n = buf.len().min(self.rx_len - self.rx_at);
            if let (Some(d), Some(s)) = (buf.get_mut(..n), self.rx.get(self.rx_at..self.rx_at + n)) {
                d.copy_from_slice(s);
                self.rx_at += n;
                return n;
            }
            0
        }
        fn rx_dropped(&self) -> u32 {
            0
        }
        fn write_tx(&mut self, bytes: &[u8]) {
            if self.tx.extend_from_slice(bytes).is_err() {
                self.tx_lost = self.tx_lost.saturating_add(1);
            }
        }
        fn set_pins(&mut self, pins: Pins) -> Pins {
            pins
        }
        fn feed_watchdog(&mut self) {}
        fn ticks(&self) -> u32 {
            self.ticks
        }
        fn wait_tick(&mut self, _seen: u32) {
            self.ticks = self.ticks.wrapping_add(1);
        }
        fn store_record(&mut self, slot: usize, rec: &ThermalRecord) {
            noinit::store_record(slot, rec);
        }
        fn store_cause(&mut self, rec: &CauseRecord) {
            noinit::store_cause(rec);
        }
    }

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

        let (Ok(stdin), Ok(out)) = (semihosting::io::stdin(), semihosting::io::stderr()) else { exit(EXIT_OPEN) };
        static mut BOARD: MaybeUninit<Lockstep> = MaybeUninit::uninit();
        // SAFETY: `main` runs once; this is the only reference to BOARD.
        let board = unsafe { &mut *core::ptr::addr_of_mut!(BOARD) }.write(Lockstep {
            stdin,
            out,
            rx: [0; RX_CHUNK],
            rx_len: 0,
            rx_at: 0,
            tx: heapless::Vec::new(),
            tx_lost: 0,
            ticks: 0,
        });
        let mem = noinit::boot_memory(NvLoad::Empty, None, false, None);
        // The application state lives in .bss, not on the stack.
        static mut APP: MaybeUninit<App> = MaybeUninit::uninit();
        // SAFETY: `main` runs once; this is the only reference to APP.
        let app = App::boot_into(unsafe { &mut *core::ptr::addr_of_mut!(APP) }, board, &GuardConfig::DEFAULT, &mem);
        defmt::info!("eha-fw up: build {=str}, faults {=u32:#010x}", BUILD, app.guard().faults().bits());
        let mut last = app.guard().output();
        let mut last_trace = app.guard().trace().recent().copied();
        while board.next_chunk() {
            board.wait_tick(0);
            let t0 = SYST::get_current();
            app.tick(board, 0);
            let t1 = SYST::get_current();
            board.end_tick(ticks_between(t0, t1));
            TICKS.fetch_add(1, core::sync::atomic::Ordering::Relaxed);
            let out = app.guard().output();
            log_changes(&last, &out);
            last = out;
            let trace = app.guard().trace().recent().copied();
            if trace != last_trace {
                if let Some(ev) = trace {
                    defmt::info!("trace {}", ev);
                }
                last_trace = trace;
            }
        }
        // End of input: completion marker, summary, clean exit.
        let st = app.status(board, DONE_TOKEN);
        board.write_tx(&st.encode());
        board.end_tick(0);
        let c = app.counters();
        defmt::info!(
            "end of input: accepted={=u32} missing={=u32} rejected crc={=u16} framing={=u16} sequence={=u16} tx lost={=u32}",
            c.accepted,
            c.missing,
            c.rejected_crc,
            c.rejected_framing,
            c.rejected_sequence,
            board.tx_lost
        );
        exit(0)
    }

    fn log_changes(prev: &Output, out: &Output) {
        if prev.valve_open != out.valve_open {
            defmt::info!("LNG valve {=str} at drain {=f32} C", if out.valve_open { "OPEN" } else { "CLOSED" }, out.drain_c);
        }
        if prev.alarm != out.alarm {
            defmt::warn!("over-temperature alarm {=bool} at drain {=f32} C", out.alarm, out.drain_c);
        }
        if prev.faults != out.faults {
            defmt::error!("faults {=u32:#010x} -> {=u32:#010x}", prev.faults.bits(), out.faults.bits());
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
