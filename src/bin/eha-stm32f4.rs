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
    use eha_guard::memory::slots::{self, noinit, AbWriter};
    use eha_guard::{Guard, GuardConfig, Sample};
    use stm32f4xx_hal::gpio::{Output, PushPull, PA5};
    use stm32f4xx_hal::timer::SysCounterUs;
    use stm32f4xx_hal::{pac, prelude::*, rcc::Config};

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

        let (rec_a, rec_b) = noinit::load();
        let restore = slots::restore_from(&rec_a, &rec_b);
        let mut records = AbWriter::after_boot(&rec_a, &rec_b);
        let mut guard = Guard::new(&GuardConfig::DEFAULT, restore);
        loop {
            board.wait_tick();
            let out = service(&mut board, &mut guard);
            if guard.steps().is_multiple_of(100) {
                records.write(&guard.snapshot(), noinit::store);
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
