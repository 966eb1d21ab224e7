//! What reaches the application between ticks, off the tick's own path:
//! received frames accepted or rejected (sequence rule, counters), commands
//! executed and acknowledged, trace dumps and the status reply.

use super::wire::{self, command_key, Ack, AckResult, Cmd, Command, Refusal, Status, TraceReply, ARM_WINDOW_TICKS, COMMAND_INTERVAL_TICKS, KIND_COMMAND};
use crate::guard::ClearResult;
use super::{AppOf, Board, Counters, COMMAND_QUEUE, TRACE_EVENTS_PER_TICK};
use heapless::Deque;
use crate::num::Num;
use crate::protection::LngConfig;
use crate::GuardOf;
use crate::protocol::{DecodeError, Request};
use crate::trace::Trace;

/// Two byte arrays as one (for the nonce's CRC input).
trait ConcatFixed {
    fn concat_fixed(&self) -> [u8; 8];
}

impl ConcatFixed for [[u8; 4]; 2] {
    fn concat_fixed(&self) -> [u8; 8] {
        let [a, b] = *self;
        [a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]]
    }
}

/// The rules of the keyed commands (clear and refill), apart from the
/// transport that carries them: each is armed, then confirmed within
/// [`ARM_WINDOW_TICKS`] with the [`command_key`] of the arm's nonce and the
/// parameter block's rig id, at most once per [`COMMAND_INTERVAL_TICKS`],
/// then done under the guard's own rule (a clear: [`GuardOf::clear_faults`];
/// a refill: refused with the valve open or in alarm). The product loop
/// ([`AppOf`]) and the C API (`integrations/capi`) both use it.
#[derive(Clone, Copy, Debug)]
pub struct CommandRules {
    /// The parameter block's rig id (all zero for the compiled-in
    /// default): the key of armed commands.
    rig_id: [u8; 16],
    /// The armed clear or refill: (the arm, its nonce, its tick).
    armed: Option<(Cmd, u32, u32)>,
    /// The last nonce handed out.
    nonce: u32,
    /// Tick of the last confirmed clear (0) and refill (1).
    confirmed: [Option<u32>; 2],
}

impl CommandRules {
    /// No command armed; `rig_id` keys the confirmations, `seed` (the boot
    /// count on the boards) starts the nonces.
    pub fn new(rig_id: [u8; 16], seed: u32) -> Self {
        CommandRules { rig_id, armed: None, nonce: seed, confirmed: [None; 2] }
    }

    /// The rig id that keys the confirmations.
    pub fn rig_id(&self) -> &[u8; 16] {
        &self.rig_id
    }

    /// Arms a clear or a refill (`cmd`: [`Cmd::ClearArm`] or
    /// [`Cmd::RefillArm`]) at `tick`: a fresh nonce (from the tick counter and
    /// the last one; not secret: the key guards against accidents, not
    /// attacks), returned.
    pub fn arm(&mut self, cmd: Cmd, tick: u32) -> u32 {
        let nonce = crate::memory::crc32(&[tick.to_le_bytes(), self.nonce.to_le_bytes()].concat_fixed()) | 1;
        self.nonce = nonce;
        self.armed = Some((cmd, nonce, tick));
        nonce
    }

    /// A confirmation ([`Cmd::ClearConfirm`] or [`Cmd::RefillConfirm`] with
    /// its `key`) at `tick`: the matching arm within its window, the key, the
    /// interval since the last one, then the guard's own rule. A confirmed
    /// clear answers the seconds UNTRUSTED still holds (0: trust restored);
    /// a refill restores `lng`'s full budget.
    pub fn confirm<N: Num>(&mut self, cmd: Cmd, key: u32, tick: u32, guard: &mut GuardOf<N>, lng: &LngConfig) -> Result<u32, Refusal> {
        let (want, slot) = match cmd {
            Cmd::ClearConfirm => (Cmd::ClearArm, 0),
            _ => (Cmd::RefillArm, 1),
        };
        let (armed, nonce, at) = self.armed.take().ok_or(Refusal::NotArmed)?;
        if armed != want || tick.wrapping_sub(at) > ARM_WINDOW_TICKS {
            return Err(Refusal::NotArmed);
        }
        if key != command_key(&self.rig_id, nonce, cmd) {
            return Err(Refusal::Key);
        }
        let last = self.confirmed.get(slot).copied().flatten();
        if last.is_some_and(|t| tick.wrapping_sub(t) < COMMAND_INTERVAL_TICKS) {
            return Err(Refusal::TooSoon);
        }
        if let Some(t) = self.confirmed.get_mut(slot) {
            *t = Some(tick);
        }
        match cmd {
            Cmd::ClearConfirm => match guard.clear_faults() {
                ClearResult::Cleared => Ok(0),
                ClearResult::TrustHeld(left) => Ok(left.div_ceil(100).max(1)),
                ClearResult::Refused => Err(Refusal::Rule),
            },
            _ => {
                // A refill with the valve open or in alarm would undo the
                // empty-tank and corrupt-boot rules while they protect.
                let o = guard.output();
                if o.valve_open || o.alarm {
                    return Err(Refusal::Rule);
                }
                guard.refill_lng(lng);
                Ok(0)
            }
        }
    }
}

/// A received frame, parsed: a sample or a command.
pub(super) enum Incoming {
    /// A sample request.
    Sample(Request),
    /// A command.
    Command(Command),
}

impl Incoming {
    /// The frame a CRC-checked payload holds (by its kind byte).
    #[inline(always)]
    pub(super) fn parse(res: Result<&[u8], DecodeError>) -> Result<Incoming, DecodeError> {
        let payload = res?;
        if payload.first() == Some(&KIND_COMMAND) {
            return Command::from_payload(payload).map(Incoming::Command);
        }
        Request::from_payload(payload).map(Incoming::Sample)
    }
}

impl Counters {
    // cold path, kept out of the tick loop's code (flash)
    #[inline(never)]
    pub(super) fn reject(&mut self, e: DecodeError) {
        let slot = match e {
            DecodeError::Crc => &mut self.rejected_crc,
            _ => &mut self.rejected_framing,
        };
        *slot = slot.saturating_add(1);
    }
}

/// One received frame: a sample (sequence rule: newer than the last
/// accepted `last_seq`, within half the u16 range; the tick's `sample`, a
/// newer one supersedes it) or a command (queued). Takes the application's
/// fields apart from the receive buffer the frame is decoded from.
#[inline(always)]
pub(super) fn accept(c: &mut Counters, last_seq: &mut Option<u16>, sample: &mut Option<Request>, commands: &mut Deque<Command, COMMAND_QUEUE>, frame: Result<Incoming, DecodeError>) {
    let req = match frame {
        Ok(Incoming::Sample(r)) => r,
        Ok(Incoming::Command(cmd)) => {
            if commands.push_back(cmd).is_err() {
                c.reject(DecodeError::Overflow);
            }
            return;
        }
        Err(e) => return c.reject(e),
    };
    if let Some(last) = *last_seq {
        let ahead = req.seq.wrapping_sub(last);
        if ahead == 0 || ahead > 0x8000 {
            c.rejected_sequence = c.rejected_sequence.saturating_add(1);
            return;
        }
    }
    *last_seq = Some(req.seq);
    c.accepted = c.accepted.saturating_add(1);
    if sample.replace(req).is_some() {
        c.superseded = c.superseded.saturating_add(1);
    }
}

impl<N: Num> AppOf<N> {
    // cold path, kept out of the tick loop's code (flash)
    #[inline(never)]
    pub(super) fn execute<B: Board>(&mut self, board: &mut B, c: Command) {
        self.counters.commands = self.counters.commands.saturating_add(1);
        let (result, value) = match c.cmd {
            Cmd::ClearArm | Cmd::RefillArm => (AckResult::Done, self.rules.arm(c.cmd, self.tick)),
            Cmd::ClearConfirm | Cmd::RefillConfirm => match self.rules.confirm(c.cmd, c.arg, self.tick, &mut self.guard, &self.lng) {
                Ok(v) => (AckResult::Done, v),
                Err(r) => (AckResult::Refused, r as u32),
            },
            Cmd::Status => {
                board.write_tx(&self.status(board, c.token).encode());
                return;
            }
            Cmd::Trace => {
                let count = u8::try_from(self.guard.trace().len()).unwrap_or(u8::MAX);
                self.dump = Some((c.token, 0, count));
                return;
            }
            Cmd::InjectHang | Cmd::InjectPanic => (AckResult::Refused, self.inject(board, c)),
        };
        let code = if result == AckResult::Done { 0 } else { u8::try_from(value).unwrap_or(u8::MAX) };
        self.guard.trace_event(Trace::Command { tick: self.guard.ticks(), code: c.cmd.code(), result: code });
        board.write_tx(&Ack { token: c.token, cmd: c.cmd, result, value }.encode());
    }

    #[cfg(feature = "fault-inject")]
    fn inject<B: Board>(&mut self, board: &mut B, c: Command) -> u32 {
        board.write_tx(&Ack { token: c.token, cmd: c.cmd, result: AckResult::Done, value: 0 }.encode());
        if c.cmd == Cmd::InjectPanic {
            // Test builds only: exercises the board's panic path.
            #[allow(clippy::panic)]
            {
                panic!("injected by command");
            }
        }
        // Test builds only: the tick never completes, the watchdog is never fed.
        loop {
            core::hint::spin_loop();
        }
    }

    #[cfg(not(feature = "fault-inject"))]
    fn inject<B: Board>(&mut self, _board: &mut B, _c: Command) -> u32 {
        Refusal::Unavailable as u32
    }

    /// Sends the next events of a dump. The dump reads the live ring by
    /// index: the `count` events present when it was asked for, oldest
    /// first. If the ring is full and new events arrive during the dump
    /// (four ticks per four events), the indices shift and the dump ends
    /// with the newest events instead of as many of the oldest.
    // cold path, kept out of the tick loop's code (flash)
    #[inline(never)]
    pub(super) fn send_trace_chunk<B: Board>(&mut self, board: &mut B) {
        let Some((token, next, count)) = self.dump else { return };
        let mut index = next;
        for ev in self.guard.trace().iter().skip(usize::from(next)).take(TRACE_EVENTS_PER_TICK.min(usize::from(count - next.min(count)))) {
            let r = TraceReply { token, index, count, event: wire::encode_trace(ev) };
            board.write_tx(&r.encode());
            index = index.saturating_add(1);
        }
        self.dump = if index >= count { None } else { Some((token, index, count)) };
    }

    /// The status reply for `token`.
    // cold path, kept out of the tick loop's code (flash)
    #[inline(never)]
    pub fn status<B: Board>(&self, board: &B, token: u16) -> Status {
        Status {
            token,
            tick: self.tick,
            counters: self.counters,
            worst_tick_cycles: self.worst_tick_cycles,
            stack_high_water_b: u16::try_from(board.stack_high_water_b()).unwrap_or(u16::MAX),
            boot_stack_b: u16::try_from(board.boot_stack_b()).unwrap_or(u16::MAX),
            reset_cause: self.reset_cause as u8,
            restore: wire::restore_code(self.restore),
            boots: self.boots,
            rx_overflow: u16::try_from(board.rx_dropped()).unwrap_or(u16::MAX),
            faults: self.guard.faults(),
            protocol: crate::protocol::PROTOCOL_VERSION,
        }
    }
}
