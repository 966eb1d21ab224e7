//! The EHA guard inside an RTIC v2 application on an STM32F411: what "the
//! model runs on the actuator controller MCU" looks like in a firmware that
//! already owns its ADC, encoder and valve driver.
//!
//! - ADC1 scans five channels (motor current, port A and B pressures,
//!   ambient, piston position) into a buffer by DMA2 stream 0; the 10 ms task
//!   starts each scan, the DMA interrupt hands the finished buffer over.
//! - TIM4 counts the motor encoder (quadrature, PB6/PB7): speed is the count
//!   difference over one tick.
//! - TIM2 interrupts every 10 ms: the task converts the last scan to a
//!   [`Sample`], reports the valve's position switch, calls
//!   [`Guard::tick`], drives the valve and OK pins and feeds the watchdog. A
//!   tick without a new scan is a missing sample ([`Guard::tick_missing`]).
//! - Pins are *high = healthy*, as on the product board: PB12 high energises
//!   (closes) the normally-open LNG valve, PB14 high = no alarm, no derate; a
//!   stopped, reset or panicking MCU leaves both low (valve open, alarm on).
//!
//! Sensor transfer functions ([`SCALES`]) are this example's assumptions:
//! replace them with your board's. Build: `cargo rtic-example`.
#![no_std]
#![no_main]

use defmt_rtt as _;
use eha_guard::{Guard, Sample};

/// Linear transfer function of one ADC channel: value = offset + gain · volts.
#[derive(Clone, Copy)]
pub struct Scale {
    /// Value at 0 V, in the channel's unit.
    pub offset: f32,
    /// Unit per volt.
    pub gain: f32,
}

/// ADC reference, V, and full scale of the 12-bit converter.
const VREF_V: f32 = 3.3;
const FULL_SCALE: f32 = 4095.0;

/// The five scanned channels, in scan order: current (hall sensor, 0 A at
/// 0.33 V, 80 A/V), pressures A and B (0.5-4.5 V transducers for 0-250 bar
/// behind a 2:3 divider: 0 bar at 0.333 V, 93.75 bar/V), ambient (RTD
/// amplifier, -50 °C at 0 V, 50 °C/V), piston position (LVDT conditioner,
/// -50 mm at 0 V, 30.3 mm/V).
pub const SCALES: [Scale; 5] = [
    Scale { offset: -26.4, gain: 80.0 },
    Scale { offset: -31.25, gain: 93.75 },
    Scale { offset: -31.25, gain: 93.75 },
    Scale { offset: -50.0, gain: 50.0 },
    Scale { offset: -50.0, gain: 30.3 },
];

/// Encoder counts per revolution (1024 lines, quadrature ×4).
pub const COUNTS_PER_REV: f32 = 4096.0;
/// Guard tick, s.
pub const TICK_S: f32 = 0.01;

/// The guard's sample from one ADC scan and the encoder's count difference
/// over the tick.
pub fn sample(raw: &[u16; 5], counts: i16) -> Sample {
    let v = |i: usize| {
        let s = SCALES[i];
        s.offset + s.gain * f32::from(raw[i]) * (VREF_V / FULL_SCALE)
    };
    Sample {
        current_a: v(0),
        p_a_bar: v(1),
        p_b_bar: v(2),
        ambient_c: v(3),
        position_mm: v(4),
        speed_rpm: f32::from(counts) / COUNTS_PER_REV / TICK_S * 60.0,
    }
}

/// GPIOB BSRR value that drives PB12 (valve) and PB14 (OK) low.
const SAFE_BSRR: u32 = (1 << (16 + 12)) | (1 << (16 + 14));

/// Valve open and alarm on with one register write, from any state.
fn safe_outputs() {
    // SAFETY: BSRR is write-only; this write resets PB12 and PB14 and
    // touches no other pin.
    unsafe { (*stm32f4xx_hal::pac::GPIOB::ptr()).bsrr().write(|w| w.bits(SAFE_BSRR)) };
}

/// A panic (none is reachable: the guard never panics, `.ci/clippy`) leaves
/// the outputs safe and waits for the watchdog.
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    safe_outputs();
    loop {
        cortex_m::asm::nop();
    }
}

#[rtic::app(device = stm32f4xx_hal::pac, peripherals = true)]
mod app {
    use super::{sample, Guard};
    use core::mem::MaybeUninit;
    use eha_guard::{params_block, GuardConfig, Restore};
    use stm32f4xx_hal::adc::config::{AdcConfig, Dma, SampleTime, Scan, Sequence};
    use stm32f4xx_hal::adc::Adc;
    use stm32f4xx_hal::dma::config::DmaConfig;
    use stm32f4xx_hal::dma::{DMAError, PeripheralToMemory, Stream0, StreamsTuple, Transfer};
    use stm32f4xx_hal::gpio::{Input, Output, PB12, PB13, PB14};
    use stm32f4xx_hal::pac::{ADC1, DMA2, TIM2, TIM4};
    use stm32f4xx_hal::prelude::*;
    use stm32f4xx_hal::qei::Qei;
    use stm32f4xx_hal::rcc::Config;
    use stm32f4xx_hal::timer::{CounterHz, Event};
    use stm32f4xx_hal::watchdog::IndependentWatchdog;

    type Scan5 = Transfer<Stream0<DMA2>, 0, Adc<ADC1>, PeripheralToMemory, &'static mut [u16; 5]>;

    #[shared]
    struct Shared {
        /// The ADC scan in flight.
        transfer: Scan5,
        /// The last finished scan, taken by the tick.
        latest: Option<[u16; 5]>,
    }

    #[local]
    struct Local {
        guard: &'static mut Guard,
        timer: CounterHz<TIM2>,
        encoder: Qei<TIM4>,
        last_count: u16,
        valve: PB12<Output>,
        valve_switch: PB13<Input>,
        ok: PB14<Output>,
        wdt: IndependentWatchdog,
        spare: Option<&'static mut [u16; 5]>,
    }

    #[init(local = [
        slot: MaybeUninit<Guard> = MaybeUninit::uninit(),
        buf_a: [u16; 5] = [0; 5],
        buf_b: [u16; 5] = [0; 5],
    ])]
    fn init(cx: init::Context) -> (Shared, Local) {
        let dp = cx.device;
        let mut rcc = dp.RCC.freeze(Config::hse(25.MHz()).sysclk(100.MHz()));
        let gpioa = dp.GPIOA.split(&mut rcc);
        let gpiob = dp.GPIOB.split(&mut rcc);

        // Outputs low (valve open, alarm) until the guard says otherwise.
        let valve = gpiob.pb12.into_push_pull_output();
        let ok = gpiob.pb14.into_push_pull_output();
        let valve_switch = gpiob.pb13.into_pull_up_input();

        // The guard: the commissioned parameter block if flashed, else the
        // paper rig's constants; a block that fails its checks is refused
        // (CONFIG fault: valve open, alarm).
        let region = params_block::flash_region();
        let (model, refused) = match params_block::view(region) {
            Ok(Some(c)) => (c, false),
            Ok(None) => (&eha_guard::model::DEFAULT_CONSTS, false),
            Err(_) => (&eha_guard::model::DEFAULT_CONSTS, true),
        };
        let config = GuardConfig { model, ..GuardConfig::DEFAULT };
        // A cold start; the product image (boards/stm32f411) adds the
        // thermal record in no-init RAM and flash (Restore::Warm/PowerLoss).
        let guard = Guard::new_in(cx.local.slot, &config, Restore::Cold);
        if refused {
            guard.refuse_config();
        }

        // ADC1: five channels, one scan per tick, into memory by DMA.
        let adc_config = AdcConfig::default().dma(Dma::Single).scan(Scan::Enabled);
        let mut adc = Adc::new(dp.ADC1, true, adc_config, &mut rcc);
        adc.configure_channel(&gpioa.pa0.into_analog(), Sequence::One, SampleTime::Cycles_112);
        adc.configure_channel(&gpioa.pa1.into_analog(), Sequence::Two, SampleTime::Cycles_112);
        adc.configure_channel(&gpioa.pa4.into_analog(), Sequence::Three, SampleTime::Cycles_112);
        adc.configure_channel(&gpiob.pb0.into_analog(), Sequence::Four, SampleTime::Cycles_112);
        adc.configure_channel(&gpiob.pb1.into_analog(), Sequence::Five, SampleTime::Cycles_112);
        let dma = StreamsTuple::new(dp.DMA2, &mut rcc);
        let dma_config = DmaConfig::default().transfer_complete_interrupt(true).memory_increment(true).double_buffer(false);
        let transfer = Transfer::init_peripheral_to_memory(dma.0, adc, cx.local.buf_a, None, dma_config);

        // Motor encoder on TIM4 (PB6/PB7).
        let encoder = Qei::new(dp.TIM4, (gpiob.pb6, gpiob.pb7), &mut rcc);
        let last_count = encoder.count();

        // The independent watchdog: a hung task stops feeding it.
        let mut wdt = IndependentWatchdog::new(dp.IWDG);
        wdt.start(250u32.millis());

        // The 10 ms tick.
        let mut timer = dp.TIM2.counter_hz(&mut rcc);
        let _ = timer.start(100.Hz());
        timer.listen(Event::Update);

        (
            Shared { transfer, latest: None },
            Local { guard, timer, encoder, last_count, valve, valve_switch, ok, wdt, spare: Some(cx.local.buf_b) },
        )
    }

    /// The 10 ms task: transport → validate, estimate, protect (the guard) → pins.
    #[task(binds = TIM2, priority = 2, shared = [transfer, latest],
           local = [guard, timer, encoder, last_count, valve, valve_switch, ok, wdt])]
    fn tick(mut cx: tick::Context) {
        let l = cx.local;
        l.timer.clear_all_flags();
        let count = l.encoder.count();
        let counts = count.wrapping_sub(*l.last_count) as i16;
        *l.last_count = count;
        let raw = cx.shared.latest.lock(|x| x.take());
        // The switch reads low when the valve is shut (energised).
        l.guard.valve_feedback(l.valve_switch.is_high());
        let out = match raw {
            Some(raw) => l.guard.tick(&sample(&raw, counts)),
            None => l.guard.tick_missing(),
        };
        l.valve.set_state((!out.valve_open).into());
        l.ok.set_state((!out.alarm && !out.derate).into());
        // The next scan, read by the next tick.
        cx.shared.transfer.lock(|t| t.start(|adc| adc.start_conversion()));
        l.wdt.feed();
    }

    /// A scan finished: keep it for the next tick, give the DMA the spare buffer.
    #[task(binds = DMA2_STREAM0, priority = 3, shared = [transfer, latest], local = [spare])]
    fn scan_done(mut cx: scan_done::Context) {
        let Some(spare) = cx.local.spare.take() else { return };
        let done = cx.shared.transfer.lock(|t| t.next_transfer(spare));
        match done {
            Ok((buf, _)) => {
                let scan = *buf;
                *cx.local.spare = Some(buf);
                cx.shared.latest.lock(|x| *x = Some(scan));
            }
            // The DMA refused the swap: keep the spare, no scan this tick (the
            // guard counts a missing sample).
            Err(DMAError::NotReady(b) | DMAError::SmallBuffer(b) | DMAError::Overrun(b)) => *cx.local.spare = Some(b),
        }
    }
}
