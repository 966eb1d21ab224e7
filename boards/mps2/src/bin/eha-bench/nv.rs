//! Non-volatile saves on an in-memory flash, timed and stack-measured.

use crate::clock::{elapsed, now, Stats, WRAPS};
use core::sync::atomic::Ordering;
use eha_guard::Guard;
use semihosting::eprintln;

/// Non-volatile saves on an in-memory flash (its own frame: the 4 KiB
/// flash is built on the stack before it moves to its static).
#[inline(never)]
pub fn nv_saves(guard: &Guard, ovh: u32) {
    // Non-volatile saves on an in-memory flash of 4 pages of 1 KiB:
    // the worst one erases a page and moves the live record, the gap a
    // save opens in the tick loop where the flash does not stall the
    // core (QEMU; the STM32F411 adds the erase itself, docs/firmware.md).
    static mut NV: core::mem::MaybeUninit<eha_guard::memory::nv::NvStore<eha_guard::memory::nv::Blocking<eha_guard::memory::nv::RamFlash<4096>>>> = core::mem::MaybeUninit::uninit();
    // SAFETY: the only reference to NV, taken once.
    let nv = unsafe { &mut *core::ptr::addr_of_mut!(NV) };
    let mut nv_stats = Stats::new();
    // (after the stack figures above: its own high-water mark, from
    // this frame down)
    let depth = eha_cortex_m::stack::depth();
    eha_cortex_m::stack::paint();
    if let Ok(store) = eha_guard::memory::nv::NvStore::new(eha_guard::memory::nv::Blocking(eha_guard::memory::nv::RamFlash::<4096>::new()), 0..4096) {
        let nv = nv.write(store);
        let rec = guard.snapshot();
        for k in 0..600u32 {
            let r = rec.with_seq(k, false);
            let w0 = WRAPS.load(Ordering::Relaxed);
            let t0 = now();
            let ok = nv.save(core::hint::black_box(&r)).is_ok();
            if let Some(t) = elapsed(t0, w0) {
                nv_stats.add(t);
            }
            core::hint::black_box(ok);
        }
    }

    nv_stats.report("non-volatile save on the in-memory flash (max: a page erase and move)", ovh);
    eprintln!("non-volatile save stack: {} bytes below its caller", eha_cortex_m::stack::high_water().saturating_sub(depth));
}
