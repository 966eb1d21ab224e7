//! Real-board build: STM32F411 (Cortex-M4F, e.g. WeAct "Black Pill" STM32F411CEU6)
//! through `stm32f4xx-hal`, implementing [`eha_guard::board::Board`].
//!
//! Build (CI must keep this compiling):
//! ```text
//! cargo build --release -p eha-guard --bin eha-stm32f4 \
//!     --target thumbv7em-none-eabihf --features board-stm32f4
//! ```
//! (alias `cargo fw-build-stm32f4`; the memory map `boards/stm32f411/memory.x` is
//! selected by `build.rs` when the feature is on).
//!
//! Flash and run with probe-rs (ST-LINK or any CMSIS-DAP probe on SWD):
//! ```text
//! cargo install probe-rs-tools --locked          # once
//! probe-rs run --chip STM32F411CEUx \
//!     target/thumbv7em-none-eabihf/release/eha-stm32f4
//! ```
//! or make it the runner for this build only:
//! `cargo run --release ... --config 'target.thumbv7em-none-eabihf.runner="probe-rs run --chip STM32F411CEUx"'`.
//! defmt output then arrives over RTT when a defmt-rtt logger replaces the
//! semihosting one (semihosting halts a free-running target without a debugger).
//!
//! Pins: valve solenoid driver on PA5 (high = open). Sample transport: the
//! actuator controller's frames (wire protocol `src/protocol.rs`, branch `pil`) are
//! not wired in yet; until then `poll_sample` returns `None`, so the guard declares
//! the input STALE after 50 ms and holds the valve open — the documented fail-safe.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(not(target_os = "none"))]
fn main() {}

#[cfg(target_os = "none")]
mod fw {
    use cortex_m_rt::{entry, exception, ExceptionFrame};
    use defmt_semihosting as _;
    use eha_guard::board::{service, Board};
    use eha_guard::memory::nv::{Blocking, NvPolicy, NvStore};
    use eha_guard::memory::slots::{self, noinit, AbWriter};
    use eha_guard::memory::{boot_restore, ThermalRecord};
    use eha_guard::{Guard, GuardConfig, Sample};
    use embedded_storage::nor_flash::{ErrorType, NorFlash, ReadNorFlash};
    use stm32f4xx_hal::flash::{FlashExt, LockedFlash};
    use stm32f4xx_hal::gpio::{Output, PushPull, PA5};
    use stm32f4xx_hal::timer::SysCounterUs;
    use stm32f4xx_hal::{pac, prelude::*, rcc::Config};

    /// Byte range of the non-volatile thermal record, offsets from the start of
    /// flash: sectors 6-7 (2 x 128 KiB at 0x0804_0000, region `NVREC` of
    /// `boards/stm32f411/memory.x`; wear budget in docs/firmware.md).
    const NV_RANGE: core::ops::Range<u32> = 0x4_0000..0x8_0000;

    /// The internal flash, unlocked only for the duration of an erase or a
    /// write (the HAL's `UnlockedFlash` relocks when dropped).
    struct Flash(LockedFlash);

    impl ErrorType for Flash {
        type Error = stm32f4xx_hal::flash::Error;
    }

    impl ReadNorFlash for Flash {
        const READ_SIZE: usize = 1;
        fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
            ReadNorFlash::read(&mut self.0, offset, bytes)
        }
        fn capacity(&self) -> usize {
            ReadNorFlash::capacity(&self.0)
        }
    }

    impl NorFlash for Flash {
        const WRITE_SIZE: usize = 1;
        const ERASE_SIZE: usize = 128 * 1024;
        fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
            // Stalls the CPU for up to 2 s per 128 KiB sector (single bank):
            // once per ~1 950 record writes.
            NorFlash::erase(&mut self.0.unlocked(), from, to)
        }
        fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
            NorFlash::write(&mut self.0.unlocked(), offset, bytes)
        }
    }

    /// STM32F411 board: PA5 valve output, SysTick 10 ms tick.
    struct F411 {
        valve: PA5<Output<PushPull>>,
        tick: SysCounterUs,
        ms: u32,
    }

    impl Board for F411 {
        type Valve = PA5<Output<PushPull>>;

        fn poll_sample(&mut self) -> Option<Sample> {
            // Transport not wired yet (see module docs): missing → STALE → valve open.
            None
        }

        fn valve(&mut self) -> &mut Self::Valve {
            &mut self.valve
        }

        fn wait_tick(&mut self) {
            while self.tick.wait().is_err() {}
            self.ms = self.ms.wrapping_add(10);
        }

        fn now_ms(&self) -> u32 {
            self.ms
        }
    }

    #[exception]
    unsafe fn HardFault(_ef: &ExceptionFrame) -> ! {
        // Fail-safe: the valve pin keeps its last state; the watchdog (when enabled)
        // resets and the thermal record is restored warm.
        loop {
            cortex_m::asm::bkpt();
        }
    }

    #[panic_handler]
    fn panic(_: &core::panic::PanicInfo) -> ! {
        loop {
            cortex_m::asm::bkpt();
        }
    }

    #[entry]
    fn main() -> ! {
        let (Some(dp), Some(cp)) = (pac::Peripherals::take(), cortex_m::Peripherals::take()) else {
            loop {
                cortex_m::asm::bkpt();
            }
        };
        let mut rcc = dp.RCC.freeze(Config::hsi().sysclk(48.MHz()));
        let gpioa = dp.GPIOA.split(&mut rcc);
        let mut valve = gpioa.pa5.into_push_pull_output();
        valve.set_high(); // open until the guard has decided (fail-safe at boot)
        let mut tick = cp.SYST.counter_us(&rcc.clocks);
        if tick.start(10.millis()).is_err() {
            loop {
                cortex_m::asm::bkpt();
            }
        }
        let mut board = F411 { valve, tick, ms: 0 };

        // Thermal memory: the newest valid RAM record (warm reset), else the
        // flash record (power loss: saved temperatures + 2 K), else cold.
        let mut nv = NvStore::new(Blocking(Flash(LockedFlash::new(dp.FLASH))), NV_RANGE).ok();
        let mut last_nv: Option<ThermalRecord> = nv.as_mut().and_then(|n| n.load());
        let (rec_a, rec_b) = noinit::load();
        let restore = boot_restore(slots::restore_from(&rec_a, &rec_b), last_nv, &NvPolicy::DEFAULT);
        let mut records = AbWriter::after_boot(&rec_a, &rec_b);
        let mut guard = Guard::new(&GuardConfig::DEFAULT, restore);
        loop {
            board.wait_tick();
            let out = service(&mut board, &mut guard);
            if guard.steps().is_multiple_of(100) {
                let rec = guard.snapshot();
                records.write(&rec, noinit::store);
                if NvPolicy::DEFAULT.due(last_nv.as_ref(), &rec) && nv.as_mut().is_some_and(|n| n.save(&rec).is_ok()) {
                    last_nv = Some(rec);
                }
                defmt::info!(
                    "drain {} degC valve {} faults {=u16:#x}",
                    out.drain_c,
                    out.valve_open,
                    out.faults
                );
            }
        }
    }
}
