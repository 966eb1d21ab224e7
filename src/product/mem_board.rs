//! A board in memory: the one [`Board`] of the unit tests, the host SIL
//! twin of the PIL image, the fault campaign and the instruction bench.
//!
//! Received bytes are queued by the caller ([`MemBoard::push_rx`]) and
//! drained by the tick; sent bytes collect in a buffer
//! ([`MemBoard::take_tx`]); the pins echo what is written (a valve pin can be
//! made to stick); the two no-init records, the reset-cause record, the
//! non-volatile store (a [`RamFlash`] through the firmware's own
//! [`NvStore`], with read and write failures on request), the real-time
//! clock and the parameter-block region are plain fields, so a test can
//! reset the MCU ([`MemBoard::warm_reset`]) or cut its power
//! ([`MemBoard::power_loss`]) and boot again from what survives.

use super::reset::CauseRecord;
use super::wire::{Pins, ResetCause};
use super::{Board, BootMemory};
use crate::memory::nv::{Blocking, NvStore, RamFlash};
use crate::memory::ThermalRecord;
use crate::params_block::BLOCK_LEN;
use crate::protocol::MAX_WIRE;

/// Receive buffer, bytes (more than a tick's traffic at any baud rate the
/// product uses; the excess is counted as dropped, as a UART ring would).
pub const MEM_RX: usize = 2048;
/// Transmit buffer, bytes (a tick sends at most a reply, four acks, a
/// status and four trace events, under 400 B; a test may let a few hundred
/// ticks' frames collect before it reads them).
pub const MEM_TX: usize = 8192;
/// Non-volatile store, bytes (16 pages of 1 KiB).
pub const NV_BYTES: usize = 16 * 1024;

/// The flash of the in-memory non-volatile store.
pub type MemFlash = Blocking<RamFlash<NV_BYTES>>;

/// A board in memory (see the module docs).
pub struct MemBoard {
    rx: [u8; MEM_RX],
    rx_len: usize,
    rx_at: usize,
    rx_dropped: u32,
    tx: [u8; MEM_TX],
    tx_len: usize,
    /// Bytes that did not fit the transmit buffer.
    pub tx_dropped: u32,
    /// The pin levels as last written (and read back).
    pub pins: Pins,
    /// A valve pin stuck at this level whatever is written.
    pub stuck_valve_pin: Option<bool>,
    /// Watchdog feeds so far.
    pub feeds: u32,
    /// Timer periods since boot.
    pub ticks: u32,
    /// The two no-init RAM records (A, B).
    pub records: [ThermalRecord; 2],
    /// The reset-cause record in no-init RAM.
    pub cause: CauseRecord,
    /// The non-volatile store; `None`: the board has none.
    pub nv: Option<NvStore<MemFlash>>,
    /// Calls of [`Board::nv_save`].
    pub nv_calls: u32,
    /// The last record handed to [`Board::nv_save`].
    pub nv_saved: Option<ThermalRecord>,
    /// The real-time clock's reading, s (`None`: no clock).
    pub rtc: Option<u32>,
    /// The clock's battery-backed backup register holding the last-alive
    /// word (`memory::alive_word`) (kept across a power loss, like the clock; `None`: the board
    /// has none; 0: empty, as after a backup-domain reset).
    pub rtc_backup: Option<u32>,
    /// The flash's parameter-block region (`None`: the board has none).
    pub block: Option<&'static [u8; BLOCK_LEN]>,
    /// The hardware reset flag the board reports at the next boot.
    pub hw_hint: Option<ResetCause>,
    /// Timer periods each flash page erase of the non-volatile store stalls
    /// the core (0: none; the STM32F411's 128 KiB sector: up to 400).
    pub erase_stall_ticks: u32,
}

impl Default for MemBoard {
    fn default() -> Self {
        Self::new()
    }
}

impl MemBoard {
    /// A powered-on board: empty buffers and records, no non-volatile
    /// store, no clock, no parameter block.
    pub const fn new() -> Self {
        MemBoard {
            rx: [0; MEM_RX],
            rx_len: 0,
            rx_at: 0,
            rx_dropped: 0,
            tx: [0; MEM_TX],
            tx_len: 0,
            tx_dropped: 0,
            pins: Pins { valve_pin: false, ok_pin: false },
            stuck_valve_pin: None,
            feeds: 0,
            ticks: 0,
            records: [ThermalRecord::EMPTY; 2],
            cause: CauseRecord::POWER_ON,
            nv: None,
            nv_calls: 0,
            nv_saved: None,
            rtc: None,
            rtc_backup: None,
            block: None,
            hw_hint: None,
            erase_stall_ticks: 0,
        }
    }

    /// Gives the board an erased non-volatile store (the whole flash range).
    pub fn with_nv(mut self) -> Self {
        self.nv = NvStore::new(Blocking(RamFlash::new()), 0..NV_BYTES as u32).ok();
        self
    }

    /// Makes every read (`reads`) and every write or erase (`writes`) of the
    /// non-volatile store fail from now on (a dead or worn flash).
    pub fn set_flash_faults(&mut self, reads: bool, writes: bool) {
        if let Some(store) = self.nv.take() {
            let mut flash = store.into_flash();
            flash.0.fail_reads = reads;
            flash.0.fail_writes = writes;
            self.nv = NvStore::new(flash, 0..NV_BYTES as u32).ok();
        }
    }

    /// Page erases of the non-volatile store so far (0 without one).
    pub fn flash_erases(&mut self) -> u32 {
        let Some(store) = self.nv.take() else { return 0 };
        let flash = store.into_flash();
        let n = flash.0.erase_counts().iter().sum();
        self.nv = NvStore::new(flash, 0..NV_BYTES as u32).ok();
        n
    }

    /// Queues `bytes` as received; returns how many fit (the rest is
    /// counted as dropped).
    pub fn push_rx(&mut self, bytes: &[u8]) -> usize {
        if self.rx_at == self.rx_len {
            self.rx_at = 0;
            self.rx_len = 0;
        }
        let room = MEM_RX - self.rx_len;
        let n = bytes.len().min(room);
        if let (Some(dst), Some(src)) = (self.rx.get_mut(self.rx_len..self.rx_len + n), bytes.get(..n)) {
            dst.copy_from_slice(src);
            self.rx_len += n;
        }
        let lost = u32::try_from(bytes.len() - n).unwrap_or(u32::MAX);
        self.rx_dropped = self.rx_dropped.saturating_add(lost);
        n
    }

    /// The bytes sent since the last [`MemBoard::take_tx`] / [`MemBoard::clear_tx`].
    pub fn tx(&self) -> &[u8] {
        self.tx.get(..self.tx_len).unwrap_or(&[])
    }

    /// Forgets the bytes sent so far.
    pub fn clear_tx(&mut self) {
        self.tx_len = 0;
    }

    /// The bytes sent so far, and forgets them.
    pub fn take_tx(&mut self) -> heapless::Vec<u8, MEM_TX> {
        let v = heapless::Vec::from_slice(self.tx()).unwrap_or_default();
        self.tx_len = 0;
        v
    }

    /// What the board finds in its memories at boot (the non-volatile
    /// store is read as a board's `init` reads it).
    pub fn boot_memory(&mut self) -> BootMemory {
        let nv = self.nv.as_mut().map_or(crate::memory::nv::NvLoad::Empty, |s| s.load());
        let alive = self.rtc_backup.and_then(crate::memory::alive_from_word);
        BootMemory {
            records: (self.records[0], self.records[1]),
            nv,
            alive_s: alive.map(|a| a.0),
            nv_failing: alive.is_some_and(|a| a.1),
            cause: self.cause,
            hw_hint: self.hw_hint,
        }
    }

    /// A reset (watchdog, brown-out, pin): the MCU restarts, no-init RAM and
    /// flash keep their contents, the buffers and the timer start over.
    pub fn warm_reset(&mut self) {
        self.rx_len = 0;
        self.rx_at = 0;
        self.tx_len = 0;
        self.ticks = 0;
        self.pins = Pins::default();
    }

    /// A power loss: RAM (records, reset cause) is gone, the flash and the
    /// battery-backed clock remain.
    pub fn power_loss(&mut self) {
        self.warm_reset();
        self.records = [ThermalRecord::EMPTY; 2];
        self.cause = CauseRecord::POWER_ON;
    }
}

impl Board for MemBoard {
    fn read_rx(&mut self, buf: &mut [u8]) -> usize {
        let n = buf.len().min(self.rx_len - self.rx_at);
        if let (Some(dst), Some(src)) = (buf.get_mut(..n), self.rx.get(self.rx_at..self.rx_at + n)) {
            dst.copy_from_slice(src);
            self.rx_at += n;
            return n;
        }
        0
    }

    /// The received bytes in place, no copy.
    #[inline(always)]
    fn rx_bytes<'a>(&'a mut self, _scratch: &'a mut [u8; super::RX_READ]) -> &'a [u8] {
        let (at, len) = (self.rx_at, self.rx_len);
        self.rx_at = len;
        self.rx.get(at..len).unwrap_or(&[])
    }

    fn rx_dropped(&self) -> u32 {
        self.rx_dropped
    }

    fn write_tx(&mut self, bytes: &[u8]) {
        match self.tx.get_mut(self.tx_len..self.tx_len + bytes.len()) {
            Some(dst) => {
                dst.copy_from_slice(bytes);
                self.tx_len += bytes.len();
            }
            None => self.tx_dropped = self.tx_dropped.saturating_add(u32::try_from(bytes.len()).unwrap_or(u32::MAX)),
        }
    }

    /// Written in place when a whole [`MAX_WIRE`] fits, no copy.
    #[inline(always)]
    fn write_tx_with(&mut self, scratch: &mut [u8; MAX_WIRE], fill: impl FnOnce(&mut [u8; MAX_WIRE]) -> usize) {
        match self.tx.get_mut(self.tx_len..).and_then(|t| t.first_chunk_mut::<MAX_WIRE>()) {
            Some(dst) => self.tx_len += fill(dst).min(MAX_WIRE),
            None => {
                let n = fill(scratch);
                self.write_tx(scratch.get(..n).unwrap_or(&[]));
            }
        }
    }

    fn set_pins(&mut self, pins: Pins) -> Pins {
        self.pins = pins;
        if let Some(v) = self.stuck_valve_pin {
            self.pins.valve_pin = v;
        }
        self.pins
    }

    fn feed_watchdog(&mut self) {
        self.feeds = self.feeds.wrapping_add(1);
    }

    fn ticks(&self) -> u32 {
        self.ticks
    }

    fn wait_tick(&mut self, _seen: u32) {
        self.ticks = self.ticks.wrapping_add(1);
    }

    fn store_record(&mut self, slot: usize, rec: &ThermalRecord) {
        if let Some(r) = self.records.get_mut(slot & 1) {
            *r = *rec;
        }
    }

    fn store_cause(&mut self, rec: &CauseRecord) {
        self.cause = *rec;
    }

    fn nv_save(&mut self, rec: &ThermalRecord) -> Option<bool> {
        let stall = self.erase_stall_ticks;
        let before = if stall > 0 { self.flash_erases() } else { 0 };
        let store = self.nv.as_mut()?;
        self.nv_calls = self.nv_calls.wrapping_add(1);
        self.nv_saved = Some(*rec);
        let ok = store.save(rec).is_ok();
        if stall > 0 {
            // the core stalled through the erases: the timer ran on
            let erased = self.flash_erases().wrapping_sub(before);
            self.ticks = self.ticks.wrapping_add(erased.wrapping_mul(stall));
        }
        Some(ok)
    }

    fn rtc_s(&mut self) -> Option<u32> {
        self.rtc
    }

    fn rtc_alive(&mut self, word: u32) {
        if let Some(r) = self.rtc_backup.as_mut() {
            *r = word;
        }
    }

    fn param_block(&self) -> Option<&'static [u8; BLOCK_LEN]> {
        self.block
    }
}
