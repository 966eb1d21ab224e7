//! The product application: one loop for every board.
//!
//! Each 10 ms tick, one sample flows
//! transport → validate → estimate → protect → outputs:
//! 1. **transport**: the bytes the UART received since the last tick are
//!    deframed; the newest valid sample frame is this tick's sample (none =
//!    a missing sample), command frames are queued;
//! 2. **validate, estimate, protect**: [`crate::GuardOf::tick`] (or
//!    [`crate::GuardOf::tick_missing`]), preceded by a missing tick for every timer
//!    period an overrun swallowed, so the model's clock keeps up with time;
//! 3. **outputs**: valve and OK pins, read back (a mismatch latches ACTUATOR
//!    and opens the valve); the thermal record (A/B no-init RAM, and
//!    non-volatile memory by [`crate::memory::nv::NvPolicy`]); the tick reply; queued commands;
//! 4. the watchdog is fed, only now that the tick has completed.
//!
//! A board ([`Board`]) supplies the UART bytes, pins, timer, watchdog and
//! memories; the QEMU `mps2-an386` board and the STM32F411 board differ only
//! there (`boards/mps2/`, `boards/stm32f411/`).

pub mod clock;
mod board;
mod boot;
mod commands;
pub mod mem_board;
mod records;
pub mod reset;
pub mod wire;

pub use board::Board;
pub use boot::{boot_guard, boot_params, boot_state, catch_up, BootMemory, Booted};
pub use commands::CommandRules;
pub use records::RecordKeeper;
pub use wire::Counters;

use crate::protection::LngConfig;
use crate::num::Num;
use crate::protocol::{Deframer, Request, MAX_WIRE};
use crate::trace::{RestoreKind, Trace};
use crate::params_block::ParamSource;
use crate::{GuardConfig, GuardOf, Output, Real};
use heapless::Deque;
use wire::{Command, Pins, ReplyEncoder, ResetCause, TickReply};

/// Trace events sent per tick while a dump is in progress (a whole ring at
/// once would not fit in one tick at the UART's rate).
pub const TRACE_EVENTS_PER_TICK: usize = 4;
/// Bytes taken from the board's receive buffer per read (a sample frame and
/// a command fit in one).
pub const RX_READ: usize = 64;
/// Commands queued per tick; more are rejected (counted as framing).
pub const COMMAND_QUEUE: usize = 4;
/// Most timer periods one tick catches up as missing ticks (after an
/// overrun). After `stale_ticks` (5) misses STALE has latched and the guard
/// runs on worst-case inputs; a longer gap would only spend time.
pub const MAX_MISSED_TICKS: u32 = 100;
/// Most timer periods one tick accounts as stalled by the board's own
/// non-volatile save (a flash erase stalls the core: up to 4 s on the
/// STM32F411; 5 s, beyond which the watchdog's erase window has reset the
/// MCU): [`crate::GuardOf::tick_blind`], no STALE.
pub const MAX_STALL_TICKS: u32 = 500;
/// Ticks to wait after a failed non-volatile save before the next attempt
/// (60 s): a dead or worn flash must not cost an erase attempt, which can
/// stall the MCU for seconds, on every tick.
pub const NV_RETRY_TICKS: u32 = 6000;

/// The product application of the firmware build's number type.
pub type App = AppOf<Real>;

/// The product application state (one per board, lives for the whole run),
/// generic over the guard's number type (the boards run [`App`]; the host
/// runs the fixed-point build's too, as the twin of the M3 PIL image).
/// `repr(C)`: the fields in their declared order, the guard first (its
/// model's addresses are immediates of the hot code: a reshuffle of the
/// fields around it changed the product image by hundreds of bytes).
#[derive(Clone)]
#[repr(C)]
pub struct AppOf<N: Num> {
    guard: GuardOf<N>,
    /// The tick reply's encoder (re-frames only the per-tick tail while
    /// the outputs, pins and counters hold).
    reply: ReplyEncoder,
    /// The thermal record's write rules (A/B slots, non-volatile policy).
    records: RecordKeeper,
    /// The keyed commands' rules (clear, refill).
    rules: CommandRules,
    sample: Option<Request>,
    last_seq: Option<u16>,
    commands: Deque<Command, COMMAND_QUEUE>,
    rx: Deframer,
    lng: LngConfig,
    /// The bytes of one read from the board's receive buffer.
    rx_buf: [u8; RX_READ],
    counters: Counters,
    /// Tick of the last last-alive stamp ([`Board::rtc_alive`]).
    alive_at: u32,
    /// Timer periods the last non-volatile save stalled the core (the
    /// next tick accounts them as blind, not missing).
    stalled: u32,
    tick: u32,
    worst_tick_cycles: u32,
    /// Trace dump in progress: token, next index, events in the dump.
    dump: Option<(u16, u8, u8)>,
    boots: u16,
    restore: RestoreKind,
    reset_cause: ResetCause,
    /// Where the model constants of this boot come from.
    params: ParamSource,
    /// The tick reply's bytes on a board that takes them by
    /// [`Board::write_tx`].
    tx_buf: [u8; MAX_WIRE],
}

impl<N: Num> AppOf<N> {
    /// Boots: the reset cause, the thermal state (RAM records, else the
    /// non-volatile one, see [`boot_restore`](crate::memory::boot_restore)), the guard, and the safe
    /// outputs of a guard waiting for its first sample (valve open).
    pub fn boot<B: Board>(board: &mut B, cfg: &GuardConfig, mem: &BootMemory) -> Self {
        let mut slot = core::mem::MaybeUninit::uninit();
        Self::boot_into(&mut slot, board, cfg, mem);
        // SAFETY: `boot_into` initialised every field.
        unsafe { slot.assume_init() }
    }

    /// [`App::boot`] into `slot` (a static on the target): each field is
    /// written in place, so the boot stack holds no copy of the whole state.
    #[inline(never)]
    pub fn boot_into<'a, B: Board>(slot: &'a mut core::mem::MaybeUninit<Self>, board: &mut B, cfg: &GuardConfig, mem: &BootMemory) -> &'a mut Self {
        let (reset_cause, boots, running) = reset::at_boot(&mem.cause, mem.hw_hint);
        board.store_cause(&running);
        let (a, b) = &mem.records;
        let p = slot.as_mut_ptr();
        // SAFETY: `p` points to `slot`, valid for writes; every field is written
        // exactly once below before the reference is created.
        let app = unsafe {
            let guard = &mut *core::ptr::addr_of_mut!((*p).guard).cast::<core::mem::MaybeUninit<GuardOf<N>>>();
            let booted = boot_guard(guard, cfg, board.param_block(), (a, b), mem.nv, || board.rtc_s(), mem.alive_s, mem.nv_failing);
            core::ptr::addr_of_mut!((*p).lng).write(cfg.lng);
            core::ptr::addr_of_mut!((*p).rx).write(Deframer::new());
            core::ptr::addr_of_mut!((*p).rx_buf).write([0; RX_READ]);
            core::ptr::addr_of_mut!((*p).reply).write(ReplyEncoder::new());
            core::ptr::addr_of_mut!((*p).tx_buf).write([0; MAX_WIRE]);
            core::ptr::addr_of_mut!((*p).last_seq).write(None);
            core::ptr::addr_of_mut!((*p).sample).write(None);
            core::ptr::addr_of_mut!((*p).commands).write(Deque::new());
            core::ptr::addr_of_mut!((*p).counters).write(Counters::default());
            core::ptr::addr_of_mut!((*p).records).write(RecordKeeper::after_boot(a, b, &mem.nv));
            core::ptr::addr_of_mut!((*p).alive_at).write(0);
            core::ptr::addr_of_mut!((*p).stalled).write(0);
            core::ptr::addr_of_mut!((*p).tick).write(0);
            core::ptr::addr_of_mut!((*p).restore).write(booted.restore);
            core::ptr::addr_of_mut!((*p).reset_cause).write(reset_cause);
            core::ptr::addr_of_mut!((*p).boots).write(boots);
            core::ptr::addr_of_mut!((*p).worst_tick_cycles).write(0);
            core::ptr::addr_of_mut!((*p).dump).write(None);
            core::ptr::addr_of_mut!((*p).params).write(booted.params);
            core::ptr::addr_of_mut!((*p).rules).write(CommandRules::new(booted.rig_id, u32::from(boots)));
            &mut *p
        };
        app.guard.trace_event(Trace::Reset { tick: 0, cause: reset_cause as u8 });
        app.guard.trace_event(Trace::Params { tick: 0, source: app.params.code() });
        let out = app.guard.output();
        let _ = board.set_pins(Pins::for_outputs(out.valve_open, out.alarm || out.derate));
        app
    }

    /// Runs the tick loop forever: wait for the timer, run one tick, count
    /// overruns (a tick still running when the next period began).
    pub fn run<B: Board>(&mut self, board: &mut B) -> ! {
        let mut seen = board.ticks();
        loop {
            self.run_once(board, &mut seen);
        }
    }

    /// One pass of [`AppOf::run`]: waits for the timer period after `seen`,
    /// runs its tick (with the periods that passed without one as `lost`)
    /// and counts an overrun.
    #[inline(always)]
    pub fn run_once<B: Board>(&mut self, board: &mut B, seen: &mut u32) {
        board.wait_tick(*seen);
        let now = board.ticks();
        // Periods that passed with no tick at all (after an overrun).
        let lost = now.wrapping_sub(*seen).saturating_sub(1);
        *seen = now;
        self.tick(board, lost);
        let after = board.ticks();
        if after != now {
            self.overrun(after.wrapping_sub(now));
        }
    }

    /// Records an overrun of `periods` timer periods.
    pub fn overrun(&mut self, periods: u32) {
        self.counters.overruns = self.counters.overruns.saturating_add(periods);
        let lost_ticks = u16::try_from(periods).unwrap_or(u16::MAX);
        self.guard.trace_event(Trace::Overrun { tick: self.guard.ticks(), lost_ticks });
    }

    /// One tick. `lost` = timer periods since the previous tick that had no
    /// tick of their own: those the board's last non-volatile save stalled
    /// are blind ticks ([`crate::GuardOf::tick_blind`], at most
    /// [`MAX_STALL_TICKS`]), the others missing ticks (at most
    /// [`MAX_MISSED_TICKS`]).
    pub fn tick<B: Board>(&mut self, board: &mut B, lost: u32) {
        let stamp = board.cycle_stamp();
        self.tick = self.tick.wrapping_add(1).wrapping_add(lost);

        // 1. transport
        loop {
            let mut rest = board.rx_bytes(&mut self.rx_buf);
            if rest.is_empty() {
                break;
            }
            while !rest.is_empty() {
                let (k, res) = self.rx.feed(rest);
                if let Some(frame) = res.map(commands::Incoming::parse) {
                    commands::accept(&mut self.counters, &mut self.last_seq, &mut self.sample, &mut self.commands, frame);
                }
                rest = rest.get(k..).unwrap_or(&[]);
            }
        }

        // 2. validate, estimate, protect
        if lost > 0 {
            self.catch_up(lost);
        }
        // (the request is used where it is stored: no copy on the stack)
        let fresh = self.sample.is_some();
        let out = match &self.sample {
            Some(req) => self.guard.tick_reported(&req.sample, &req.reports),
            None => {
                self.counters.missing = self.counters.missing.saturating_add(1);
                self.guard.tick_missing()
            }
        };
        self.sample = None;

        // 3. outputs: the thermal record first (a failed save changes the
        // outputs: derate), then the pins and the reply
        let out = if self.records.changed(&self.guard) {
            self.save(board);
            self.guard.output()
        } else {
            out
        };
        let (out, pins) = self.drive(board, out);
        let reply = TickReply {
            tick: self.tick,
            sample_seq: self.last_seq.unwrap_or(0),
            fresh,
            not_commissioned: self.params == ParamSource::Default,
            out,
            pins,
            overruns: u16::try_from(self.counters.overruns).unwrap_or(u16::MAX),
            rejected: self.counters.rejected(),
            restore: self.restore,
            reset_cause: self.reset_cause,
        };
        let (enc, epoch) = (&mut self.reply, self.guard.epoch());
        board.write_tx_with(&mut self.tx_buf, |out| enc.frame_into(&reply, epoch, out));
        while let Some(c) = self.commands.pop_front() {
            self.execute(board, c);
        }
        self.send_trace_chunk(board);

        if self.tick.wrapping_sub(self.alive_at) >= 100 * crate::memory::ALIVE_PERIOD_S {
            self.stamp_alive(board);
        }

        let cycles = board.cycles_since(stamp);
        self.worst_tick_cycles = self.worst_tick_cycles.max(cycles);
        // 4. the tick is complete
        board.feed_watchdog();
    }

    /// The periods a tick came late by: stalled by our own save (blind),
    /// else missing.
    #[cold]
    #[inline(never)]
    fn catch_up(&mut self, lost: u32) {
        catch_up(&mut self.guard, lost, core::mem::replace(&mut self.stalled, 0));
    }

    /// The thermal record, written when the state it holds has changed
    /// (a model step, a fault, the valve, a clear or refill: between those
    /// only its tick count would differ): the next A/B slot, and the
    /// non-volatile store when its policy says so.
    #[inline(never)]
    fn save<B: Board>(&mut self, board: &mut B) {
        let rec = self.records.write_ram(&self.guard, |slot, r| board.store_record(slot, r));
        if self.records.nv_due(self.tick, &rec) {
            let rec = rec.with_rtc(board.rtc_s());
            let t0 = board.ticks();
            let saved = board.nv_save(&rec);
            // A flash erase stalls the core: the periods it took are
            // accounted at the next tick, without STALE.
            self.stalled = board.ticks().wrapping_sub(t0);
            if saved == Some(false) {
                self.counters.nv_failures = self.counters.nv_failures.saturating_add(1);
            }
            self.records.nv_result(self.tick, &rec, saved, &mut self.guard);
        }
    }

    /// The last-alive stamp (when the board has a clock).
    #[inline(never)]
    fn stamp_alive<B: Board>(&mut self, board: &mut B) {
        self.alive_at = self.tick;
        if let Some(s) = board.rtc_s() {
            board.rtc_alive(crate::memory::alive_word(s, self.records.nv_failing()));
        }
    }

    /// Writes the pins for `out`; a read-back that differs latches ACTUATOR,
    /// which opens the valve, and the pins are written again.
    fn drive<B: Board>(&mut self, board: &mut B, out: Output) -> (Output, Pins) {
        let want = Pins::for_outputs(out.valve_open, out.alarm || out.derate);
        let got = board.set_pins(want);
        if got == want {
            return (out, got);
        }
        self.guard.report_actuator_fault();
        let out = self.guard.output();
        let got = board.set_pins(Pins::for_outputs(out.valve_open, out.alarm || out.derate));
        (out, got)
    }

    /// The guard (read only).
    pub fn guard(&self) -> &GuardOf<N> {
        &self.guard
    }

    /// The counters so far.
    pub fn counters(&self) -> Counters {
        self.counters
    }

    /// Where this boot's model constants come from.
    pub fn params(&self) -> ParamSource {
        self.params
    }

    /// Why the MCU last reset.
    pub fn reset_cause(&self) -> ResetCause {
        self.reset_cause
    }
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod safety_tests;
