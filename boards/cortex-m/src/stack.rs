//! Stack painting: fill the unused stack with a pattern, later find the
//! lowest overwritten word. Used by the product boards (boot and tick-loop
//! high-water marks in the status reply) and the benchmark image.

const PAINT: u32 = 0xDEAD_BEEF;

extern "C" {
    // cortex-m-rt's linker script: lowest and highest address of the stack.
    static _stack_end: u32;
    static _stack_start: u32;
}

/// Fills the unused stack below the live frames (from its lowest address
/// up to 256 bytes below SP) with a pattern.
#[inline(never)]
pub fn paint() {
    let lo = core::ptr::addr_of!(_stack_end) as usize;
    let sp = cortex_m::register::msp::read() as usize;
    let mut p = lo;
    while p + 256 < sp {
        // SAFETY: [lo, sp - 256) is unused stack below the live frames.
        unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
        p += 4;
    }
}

/// Bytes of stack in use at the call (from its top to SP): what a
/// [`high_water`] after a [`paint`] here includes of the caller's frames.
pub fn depth() -> u32 {
    let hi = core::ptr::addr_of!(_stack_start) as usize;
    let sp = cortex_m::register::msp::read() as usize;
    hi.saturating_sub(sp) as u32
}

/// Bytes of stack ever used since the last [`paint`].
pub fn high_water() -> u32 {
    let lo = core::ptr::addr_of!(_stack_end) as usize;
    let hi = core::ptr::addr_of!(_stack_start) as usize;
    let mut p = lo;
    // SAFETY: reading our own stack region word by word.
    while p < hi && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
        p += 4;
    }
    (hi - p) as u32
}

/// At the end of boot: the boot's high-water mark (returned, and logged),
/// then the stack painted again so that later readings are the tick
/// loop's own.
#[inline]
pub fn boot_done() -> u32 {
    let b = high_water();
    paint();
    defmt::info!("boot stack {=u32} B", b);
    b
}
