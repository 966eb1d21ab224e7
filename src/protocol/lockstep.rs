//! The lockstep transport of the QEMU PIL image (`boards/mps2/src/bin/eha-fw.rs`): the
//! product application ([`crate::product::App`]) ticks once per chunk of
//! received bytes the host sends, so a run is deterministic and as fast as
//! the emulator.
//!
//! * host → firmware (semihosting stdin): per tick, a little-endian `u16`
//!   length and that many bytes, what the controller's UART delivered during
//!   the tick (a sample frame, commands, garbage; none: a missing sample).
//!   End of input ends the run.
//! * firmware → host (semihosting `:tt`, host stderr): the tick's frames as
//!   a board sends them (tick reply, acknowledgements, status, trace), then
//!   one end-of-tick frame ([`KIND_TICK_END`], the tick's cost in core-clock
//!   cycles). The frames keep their COBS delimiters, so text an emulator
//!   mixes into the stream is skipped as a refused frame.
//! * at end of input the firmware sends a status reply with token
//!   [`DONE_TOKEN`] (the completion marker, with the final counters), an
//!   end-of-tick frame, and exits 0.

use super::{frame, WireFrame};

/// Kind byte of the end-of-tick frame (PIL image only).
pub const KIND_TICK_END: u8 = 0x9F;
/// Payload length of the end-of-tick frame: kind, cycles (u32).
pub const TICK_END_LEN: usize = 5;
/// Token of the status reply that marks the end of a PIL run.
pub const DONE_TOKEN: u16 = 0xD0E5;

/// The end-of-tick frame: the tick cost `cycles` core-clock cycles (SysTick
/// ticks; under QEMU `-icount shift=10`, 25.6 per instruction).
pub fn tick_end(cycles: u32) -> WireFrame {
    let c = cycles.to_le_bytes();
    frame(&[KIND_TICK_END, c[0], c[1], c[2], c[3]], true)
}

/// The cycles of an end-of-tick payload, `None` for any other payload.
pub fn parse_tick_end(p: &[u8]) -> Option<u32> {
    match p {
        [KIND_TICK_END, a, b, c, d] => Some(u32::from_le_bytes([*a, *b, *c, *d])),
        _ => None,
    }
}
