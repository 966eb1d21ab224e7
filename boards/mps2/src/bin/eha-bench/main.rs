//! Benchmark firmware: instructions per `Guard::tick` (per 10 ms tick, split into
//! ticks with and without the 100 ms model step), `Model::tick_n` and
//! `Model::update` in QEMU, stack high-water mark, init cost. Run with `cargo fw-bench` (M4F, f32) or
//! `cargo fw-bench-m3` (M3, fixed point); see `docs/firmware-numbers.md`.
//!
//! Method (docs/toolchain.md): QEMU `-icount shift=10,align=off,sleep=off`
//! makes every instruction 1.024 us of virtual time; SysTick runs on the 25 MHz core
//! clock, so instructions = SysTick ticks / 25.6. The timing overhead (two SysTick
//! reads) is measured on an empty region and subtracted. Report on semihosting
//! stderr; completion marker `EHA-BENCH-DONE`; exit codes: 0 ok, 101 panic,
//! 102 HardFault, 103 other exception, 104 no peripherals.
#![no_std]
#![no_main]

// The mps2 vector table (shared with the product image).
#[path = "../../vectors.rs"]
mod vectors;

mod clock;
mod input;
mod nv;
mod parts;

use core::sync::atomic::Ordering;
use clock::{elapsed, now, Stats, WRAPS};
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{entry, exception, ExceptionFrame};
use defmt_semihosting as _;
use eha_guard::model::{InputScales, Model, ModelInputN};
use eha_guard::num::Num;
use eha_guard::product::mem_board::MemBoard;
use eha_guard::validate::{self, Channels, LimitsN};
use eha_guard::{Guard, GuardConfig, Real, Restore};
use input::{sample, TICKS};
use nv::nv_saves;
use parts::*;
use semihosting::eprintln;

#[exception]
fn SysTick() {
    WRAPS.fetch_add(1, Ordering::Relaxed);
}

#[exception]
unsafe fn HardFault(_ef: &ExceptionFrame) -> ! {
    semihosting::process::exit(102)
}

#[exception]
unsafe fn DefaultHandler(_irqn: i16) {
    semihosting::process::exit(103)
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    semihosting::process::exit(101)
}

#[entry]
fn main() -> ! {
    eha_cortex_m::stack::paint();
    let Some(mut p) = cortex_m::Peripherals::take() else {
        semihosting::process::exit(104)
    };
    p.SYST.set_clock_source(SystClkSource::Core);
    p.SYST.set_reload(0x00FF_FFFF);
    p.SYST.clear_current();
    p.SYST.enable_interrupt();
    p.SYST.enable_counter();

    // Timing overhead of an empty region.
    let mut empty = Stats::new();
    for _ in 0..100 {
        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        if let Some(t) = elapsed(t0, w0) {
            empty.add(t);
        }
    }
    let ovh = empty.min;

    // Init cost: ZOH matrices via the f64 matrix exponential (wrap-counted).
    let w0 = WRAPS.load(Ordering::Relaxed);
    let t0 = now();
    let mut guard = Guard::new(&GuardConfig::DEFAULT, Restore::Cold);
    let t1 = now();
    let wraps = WRAPS.load(Ordering::Relaxed) - w0;
    let init_ticks = wraps as u64 * 0x0100_0000 + (t0.wrapping_sub(t1) & 0x00FF_FFFF) as u64;

    let Ok(mut model) = Model::<Real>::from_consts(&eha_guard::model::DEFAULT_CONSTS) else {
        semihosting::process::exit(105)
    };
    let Some(scales) = InputScales::<Real>::new() else {
        semihosting::process::exit(106)
    };
    model.set_temperatures(&[16.0; eha_guard::params::N_NODES], 16.0);

    // Stack used by boot + init (f64 matrix exponential), then repaint to measure
    // the tick loop alone (its figure includes main's own frame).
    let init_stack = eha_cortex_m::stack::high_water();
    eha_cortex_m::stack::paint();
    let Some(limits) = LimitsN::<Real>::new(&GuardConfig::DEFAULT.limits, &scales) else {
        semihosting::process::exit(107)
    };
    let mut prev_ch: Channels<Real> = validate::convert(&sample(0, &mut 1), &scales).0;
    // Guard::tick over all ticks, over the ticks without a model step, and over
    // the ticks that end a model step (every TICKS_PER_STEP-th).
    let mut g_stats = Stats::new();
    let mut gt_stats = Stats::new();
    let mut gm_stats = Stats::new();
    let mut mt_stats = Stats::new();
    let mut mu_stats = Stats::new();
    let mut v_stats = Stats::new();
    let mut vc_stats = Stats::new();
    let mut noise = 1u32;
    let mut prev_pos = 0.0f32;
    let mut last = eha_guard::Output::default();
    let mut opened_at = None;
    let mut lng_ticks = 0u32;
    for k in 0..TICKS {
        let s = sample(k, &mut noise);
        let dpos_mm = s.position_mm - prev_pos;
        let lng_open = last.valve_open;
        prev_pos = s.position_mm;

        // Both addresses are formed before the timed window (the guard's
        // stack offset would otherwise count as Guard::tick's cost).
        let (g, sr) = (core::hint::black_box(&mut guard), core::hint::black_box(&s));
        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        let out = guard_tick(g, sr);
        if let Some(t) = elapsed(t0, w0) {
            g_stats.add(t);
            if guard.model().map_or(0, |m| m.pending_ticks()) == 0 {
                gm_stats.add(t);
            } else {
                gt_stats.add(t);
            }
        }
        last = core::hint::black_box(out);
        if last.valve_open && opened_at.is_none() {
            opened_at = Some(k);
        }

        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        let vu = validate_tick(core::hint::black_box(&s), &prev_ch, &scales, &limits);
        if let Some(t) = elapsed(t0, w0) {
            v_stats.add(t);
        }
        core::hint::black_box(vu);
        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        let vc = validate_classify(core::hint::black_box(&s), &prev_ch, &scales, &limits);
        if let Some(t) = elapsed(t0, w0) {
            vc_stats.add(t);
        }
        core::hint::black_box(vc);
        prev_ch = validate::convert(&s, &scales).0;

        // The model alone, in wire units converted as the guard converts them.
        let un = ModelInputN {
            current_ha: Real::from_f32_scaled(s.current_a, scales.ha_per_a),
            p_a_hbar: Real::from_f32_scaled(s.p_a_bar, scales.hbar_per_bar),
            p_b_hbar: Real::from_f32_scaled(s.p_b_bar, scales.hbar_per_bar),
            speed_hrads: Real::from_f32_scaled(s.speed_rpm, scales.hrads_per_rpm),
            dpos_mm: Real::from_f32_scaled(dpos_mm, scales.one),
            ambient_c: Real::from_f32_scaled(s.ambient_c, scales.one),
        };
        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        let full = model_tick(&mut model, core::hint::black_box(&un));
        if let Some(t) = elapsed(t0, w0) {
            mt_stats.add(t);
        }
        lng_ticks += lng_open as u32;
        if full {
            let w0 = WRAPS.load(Ordering::Relaxed);
            let t0 = now();
            model_update(&mut model, core::hint::black_box(lng_ticks));
            lng_ticks = 0;
            if let Some(t) = elapsed(t0, w0) {
                mu_stats.add(t);
            }
        }
    }

    // Fault path: one NaN current sample, then 200 valid samples with the fault
    // latched (worst-case current substituted, valve forced open, trace written).
    let mut f_stats = Stats::new();
    let mut ft_stats = Stats::new();
    let mut fm_stats = Stats::new();
    for k in 0..201u32 {
        let mut s = sample(TICKS / 2 - 1, &mut noise);
        if k == 0 {
            s.current_a = f32::NAN;
        }
        // Both addresses are formed before the timed window (the guard's
        // stack offset would otherwise count as Guard::tick's cost).
        let (g, sr) = (core::hint::black_box(&mut guard), core::hint::black_box(&s));
        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        let out = guard_tick(g, sr);
        if let Some(t) = elapsed(t0, w0) {
            f_stats.add(t);
            if guard.model().map_or(0, |m| m.pending_ticks()) == 0 {
                fm_stats.add(t);
            } else {
                ft_stats.add(t);
            }
        }
        last = core::hint::black_box(out);
    }

    // The product loop per tick (src/product): deframe the 32-byte sample
    // frame, Guard::tick, pins, A/B record, NV policy check, tick reply
    // (COBS + CRC), watchdog; the same samples as above, from a cold boot.
    // The shared in-memory board (the product's boards differ only in
    // their I/O): the frame is queued before the tick, so the UART
    // interrupt's per-byte work is not counted; the replies are dropped
    // after each tick.
    static mut APP: core::mem::MaybeUninit<eha_guard::product::App> = core::mem::MaybeUninit::uninit();
    // (in .bss, written at run time: as an initialised static it would
    // put its 27 KB in .data, i.e. in flash)
    static mut BOARD: core::mem::MaybeUninit<MemBoard> = core::mem::MaybeUninit::uninit();
    // SAFETY: the only references to APP and BOARD, taken once.
    let board = unsafe { &mut *core::ptr::addr_of_mut!(BOARD) }.write(MemBoard::new());
    let mem = board.boot_memory();
    // SAFETY: as above.
    let app = eha_guard::product::App::boot_into(unsafe { &mut *core::ptr::addr_of_mut!(APP) }, board, &GuardConfig::DEFAULT, &mem);
    let mut tx_bytes = 0u32;
    let mut a_stats = Stats::new();
    let mut noise_a = 1u32;
    for k in 0..TICKS {
        let s = sample(k, &mut noise_a);
        let req = eha_guard::protocol::Request { seq: (k & 0xFFFF) as u16, sample: s, reports: eha_guard::Reports::default() };
        board.push_rx(&req.encode());
        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        app_tick(app, board);
        if let Some(t) = elapsed(t0, w0) {
            a_stats.add(t);
        }
        tx_bytes = tx_bytes.wrapping_add(board.tx().len() as u32);
        board.clear_tx();
    }
    core::hint::black_box(tx_bytes);
    let ao = app.guard().output();
    eprintln!("App run end: faults {:#06x}, valve {}, epoch {}", ao.faults.bits(), ao.valve_open, app.guard().epoch());

    // Where the loop's instructions go: its parts alone, same frames.
    let mut pd_stats = Stats::new();
    let mut pe_stats = Stats::new();
    let mut pr_stats = Stats::new();
    let mut pn_stats = Stats::new();
    let mut deframer = eha_guard::protocol::Deframer::new();
    let mut noise_p = 1u32;
    let mut nv_last = None;
    let mut writer = eha_guard::memory::slots::AbWriter::after_boot(&eha_guard::ThermalRecord::EMPTY, &eha_guard::ThermalRecord::EMPTY);
    for k in 0..600u32 {
        let s = sample(k, &mut noise_p);
        let req = eha_guard::protocol::Request { seq: (k & 0xFFFF) as u16, sample: s, reports: eha_guard::Reports::default() };
        let wire = req.encode();
        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        let got = part_deframe(&mut deframer, core::hint::black_box(&wire));
        if let Some(t) = elapsed(t0, w0) { pd_stats.add(t); }
        core::hint::black_box(got);
        let reply = eha_guard::product::wire::TickReply {
            tick: k, sample_seq: k as u16, fresh: true, not_commissioned: true, out: last,
            pins: eha_guard::product::wire::Pins::default(), overruns: 0, rejected: 0,
            restore: eha_guard::trace::RestoreKind::Cold, reset_cause: eha_guard::product::wire::ResetCause::PowerOn,
        };
        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        let enc = part_encode(core::hint::black_box(&reply));
        if let Some(t) = elapsed(t0, w0) { pe_stats.add(t); }
        core::hint::black_box(enc);
        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        let rec = part_record(core::hint::black_box(&guard), &mut writer);
        if let Some(t) = elapsed(t0, w0) { pr_stats.add(t); }
        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        let due = part_nv_due(core::hint::black_box(nv_last.as_ref()), &rec);
        if let Some(t) = elapsed(t0, w0) { pn_stats.add(t); }
        if due { nv_last = Some(rec); }
    }

    // A flash-erase stall's catch-up: 400 blind ticks (4 s, the
    // STM32F411's worst 128 KiB sector erase) in one call.
    let mut blind = None;
    for _ in 0..4 {
        let w0 = WRAPS.load(Ordering::Relaxed);
        let t0 = now();
        core::hint::black_box(guard.tick_blind(400));
        blind = elapsed(t0, w0);
        if blind.is_some() {
            break;
        }
    }

    // Thermal-memory save (snapshot + CRC + no-init write).
    let w0 = WRAPS.load(Ordering::Relaxed);
    let t0 = now();
    let rec = guard.snapshot();
    eha_guard::memory::slots::noinit::store(0, &rec);
    let save = elapsed(t0, w0).unwrap_or(0);

    let build = if cfg!(feature = "fixed-point") {
        "fixed-point Q9.23/Q2.30/Q9.55"
    } else {
        "f32"
    };
    eprintln!("EHA-BENCH build: {}", build);
    eprintln!("timing overhead: {} ticks (subtracted)", ovh);
    eprintln!(
        "size_of Guard {} B, Model {} B, ThermalRecord {} B",
        core::mem::size_of::<Guard>(),
        core::mem::size_of::<Model<Real>>(),
        core::mem::size_of::<eha_guard::ThermalRecord>()
    );
    eprintln!(
        "model step: every {} ticks of 10 ms",
        eha_guard::params::TICKS_PER_STEP
    );
    g_stats.report("Guard::tick, every tick", ovh);
    gt_stats.report("Guard::tick, ticks without a model step", ovh);
    gm_stats.report("Guard::tick, ticks with the model step", ovh);
    f_stats.report(
        "Guard::tick, fault latched (NaN current then worst case), every tick",
        ovh,
    );
    ft_stats.report("  fault latched, ticks without a model step", ovh);
    fm_stats.report("  fault latched, ticks with the model step", ovh);
    a_stats.report(
        "App::tick (product loop: 32-byte frame in, Guard::tick, pins, A/B record, tick reply; UART interrupt not counted), every tick",
        ovh,
    );
    pd_stats.report("  App part: deframe + decode the 32-byte sample frame", ovh);
    pe_stats.report("  App part: encode the tick reply (CRC-16 + COBS)", ovh);
    pr_stats.report("  App part: snapshot + A/B record (CRC-32; written at model steps and changes only)", ovh);
    pn_stats.report("  App part: non-volatile policy check", ovh);
    mt_stats.report("Model::tick_n (tick accumulation)", ovh);
    mu_stats.report("Model::update (model step)", ovh);
    v_stats.report(
        "validation, fast path (convert+combined check+inputs; standalone call)",
        ovh,
    );
    vc_stats.report(
        "validation, classifying path (convert+check+substitute; standalone call)",
        ovh,
    );
    eprintln!(
        "Guard::new (constants, checks, stability): {} instructions",
        init_ticks * 10 / 256
    );
    match blind {
        Some(t) => eprintln!("erase-stall catch-up, Guard::tick_blind(400): {} instructions", (t.saturating_sub(ovh) as u64 * 10) / 256),
        None => eprintln!("erase-stall catch-up, Guard::tick_blind(400): timer wrapped"),
    }
    eprintln!(
        "snapshot+store record: {} instructions",
        (save.saturating_sub(ovh) as u64 * 10) / 256
    );
    eprintln!(
        "stack high-water mark: boot+init {} bytes, tick loop {} bytes",
        init_stack,
        eha_cortex_m::stack::high_water()
    );
    nv_saves(&guard, ovh);
    let dc = (last.drain_c * 1000.0) as i32;
    eprintln!(
        "final drain {}.{:03} degC, valve {}, faults {:#06x}, model drain {} mK, first open tick {:?}",
        dc / 1000, (dc % 1000).abs(), last.valve_open, last.faults,
        (model.drain_c().to_f32() * 1000.0) as i32, opened_at
    );
    defmt::info!("EHA-BENCH-DONE");
    eprintln!("EHA-BENCH-DONE");
    semihosting::process::exit(0)
}
