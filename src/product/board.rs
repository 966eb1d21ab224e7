//! [`Board`]: what the product loop needs from a board (the one trait
//! each board folder implements; the application is shared).

use super::reset::CauseRecord;
use super::wire::Pins;
use super::RX_READ;
use crate::memory::ThermalRecord;
use crate::params_block::BLOCK_LEN;
use crate::protocol::MAX_WIRE;

/// What the product loop needs from a board.
pub trait Board {
    /// Moves bytes received since the last call into `buf`; never blocks.
    /// Returns how many were written.
    fn read_rx(&mut self, buf: &mut [u8]) -> usize;
    /// The bytes received since the last call, taken from the board:
    /// borrowed from the board's own receive buffer where it keeps them in
    /// one piece (the in-memory board: no copy), else read into `scratch`
    /// ([`Board::read_rx`], the default). Empty when nothing is left; the
    /// caller calls again until then.
    #[inline(always)]
    fn rx_bytes<'a>(&'a mut self, scratch: &'a mut [u8; RX_READ]) -> &'a [u8] {
        let n = self.read_rx(scratch);
        scratch.get(..n).unwrap_or(&[])
    }
    /// Received bytes dropped because the receive buffer was full, since boot.
    fn rx_dropped(&self) -> u32;
    /// Sends bytes to the controller (returns when they are queued or sent).
    fn write_tx(&mut self, bytes: &[u8]);
    /// Sends one frame that `fill` writes at the start of a buffer of
    /// [`MAX_WIRE`] bytes (returning its length): straight into the board's
    /// own transmit buffer where it keeps one with room (the in-memory
    /// board: no copy), else into `scratch` and on by [`Board::write_tx`]
    /// (the default).
    #[inline(always)]
    fn write_tx_with(&mut self, scratch: &mut [u8; MAX_WIRE], fill: impl FnOnce(&mut [u8; MAX_WIRE]) -> usize) {
        let n = fill(scratch);
        self.write_tx(scratch.get(..n).unwrap_or(&[]));
    }
    /// Drives the valve and OK pins and returns the levels read back from
    /// the output register.
    fn set_pins(&mut self, pins: Pins) -> Pins;
    /// Restarts the watchdog countdown.
    fn feed_watchdog(&mut self);
    /// Timer periods since boot (incremented by the tick interrupt).
    fn ticks(&self) -> u32;
    /// Sleeps until [`Board::ticks`] differs from `seen` (race-free against
    /// the tick interrupt).
    fn wait_tick(&mut self, seen: u32);
    /// Stores a thermal record in no-init RAM slot `slot` (0 = A, 1 = B).
    fn store_record(&mut self, slot: usize, rec: &ThermalRecord);
    /// Stores the reset-cause record in no-init RAM.
    fn store_cause(&mut self, rec: &CauseRecord);
    /// Saves a record to non-volatile memory: `Some(true)` saved,
    /// `Some(false)` the write failed, `None` the board has none. May stall
    /// (flash erase): the board keeps its watchdog from expiring meanwhile.
    fn nv_save(&mut self, _rec: &ThermalRecord) -> Option<bool> {
        None
    }
    /// Seconds of a battery-backed real-time clock that keeps running while
    /// the board is unpowered (`None`: the board has none, or it lost its
    /// time). Read at boot and at each non-volatile save: the off-time of a
    /// power loss, over which the restored state is cooled
    /// ([`crate::memory::boot_restore`]).
    fn rtc_s(&mut self) -> Option<u32> {
        None
    }
    /// Stores the last-alive word ([`crate::memory::alive_word`]: the
    /// real-time clock's seconds and whether the non-volatile saves are
    /// failing) in a battery-backed register that survives a power loss (on
    /// the STM32F411 an RTC backup register), read back at boot into
    /// [`BootMemory::alive_s`](super::BootMemory::alive_s) and [`BootMemory::nv_failing`](super::BootMemory::nv_failing). The
    /// application stamps it once per [`crate::memory::ALIVE_PERIOD_S`]; it
    /// is the only time base the power-off cooling counts from. No-op on a
    /// board without one.
    fn rtc_alive(&mut self, _word: u32) {}
    /// A free-running core-clock cycle stamp (0 when not available).
    fn cycle_stamp(&self) -> u32 {
        0
    }
    /// Cycles elapsed since `stamp` (0 when not available).
    fn cycles_since(&self, _stamp: u32) -> u32 {
        0
    }
    /// Stack high-water mark of the tick loop, bytes (0 when not measured).
    fn stack_high_water_b(&self) -> u32 {
        0
    }
    /// Stack used by boot (reset to the end of [`AppOf::boot`](super::AppOf::boot)), bytes (0 when
    /// not measured).
    fn boot_stack_b(&self) -> u32 {
        0
    }
    /// The parameter-block region of the flash (`PARAMS` in the board's
    /// `memory.x`), `None` when the board has none ([`crate::params_block`]).
    fn param_block(&self) -> Option<&'static [u8; BLOCK_LEN]> {
        None
    }
}
