//! What reaches the application between ticks, off the tick's own path:
//! received frames accepted or rejected (sequence rule, counters), commands
//! executed and acknowledged, trace dumps and the status reply.

use super::wire::{self, Ack, AckResult, Cmd, Command, Status, TraceReply, KIND_COMMAND};
use super::{AppOf, Board, TRACE_EVENTS_PER_TICK};
use crate::num::Num;
use crate::protocol::{DecodeError, Request};
use crate::trace::Trace;

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

impl<N: Num> AppOf<N> {
    // cold path, kept out of the tick loop's code (flash)
    #[inline(never)]
    pub(super) fn reject(&mut self, e: DecodeError) {
        let c = &mut self.counters;
        let slot = match e {
            DecodeError::Crc => &mut c.rejected_crc,
            _ => &mut c.rejected_framing,
        };
        *slot = slot.saturating_add(1);
    }

    /// One received frame: a sample (sequence rule: newer than the last
    /// accepted, within half the u16 range) or a command.
    pub(super) fn accept(&mut self, frame: Result<Incoming, DecodeError>) {
        let req = match frame {
            Ok(Incoming::Sample(r)) => r,
            Ok(Incoming::Command(c)) => {
                if self.commands.push_back(c).is_err() {
                    self.reject(DecodeError::Overflow);
                }
                return;
            }
            Err(e) => return self.reject(e),
        };
        if let Some(last) = self.last_seq {
            let ahead = req.seq.wrapping_sub(last);
            if ahead == 0 || ahead > 0x8000 {
                self.counters.rejected_sequence = self.counters.rejected_sequence.saturating_add(1);
                return;
            }
        }
        self.last_seq = Some(req.seq);
        self.counters.accepted = self.counters.accepted.saturating_add(1);
        if self.sample.replace(req).is_some() {
            self.counters.superseded = self.counters.superseded.saturating_add(1);
        }
    }

    // cold path, kept out of the tick loop's code (flash)
    #[inline(never)]
    pub(super) fn execute<B: Board>(&mut self, board: &mut B, c: Command) {
        self.counters.commands = self.counters.commands.saturating_add(1);
        self.guard.trace_event(Trace::Command { tick: self.guard.ticks(), code: c.cmd.code() });
        let ack = |result| Ack { token: c.token, cmd: c.cmd, result };
        match c.cmd {
            Cmd::ClearFaults => {
                let ok = self.guard.clear_faults();
                board.write_tx(&ack(if ok { AckResult::Done } else { AckResult::Refused }).encode());
            }
            Cmd::RefillLng => {
                let lng = self.lng;
                self.guard.refill_lng(&lng);
                board.write_tx(&ack(AckResult::Done).encode());
            }
            Cmd::Status => board.write_tx(&self.status(board, c.token).encode()),
            Cmd::Trace => {
                let count = u8::try_from(self.guard.trace().len()).unwrap_or(u8::MAX);
                self.dump = Some((c.token, 0, count));
            }
            Cmd::InjectHang | Cmd::InjectPanic => self.inject(board, c, ack),
        }
    }

    #[cfg(feature = "fault-inject")]
    fn inject<B: Board>(&mut self, board: &mut B, c: Command, ack: impl Fn(AckResult) -> Ack) {
        board.write_tx(&ack(AckResult::Done).encode());
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
    fn inject<B: Board>(&mut self, board: &mut B, _c: Command, ack: impl Fn(AckResult) -> Ack) {
        board.write_tx(&ack(AckResult::Refused).encode());
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
        let c = &self.counters;
        Status {
            token,
            tick: self.tick,
            overruns: c.overruns,
            worst_tick_cycles: self.worst_tick_cycles,
            stack_high_water_b: u16::try_from(board.stack_high_water_b()).unwrap_or(u16::MAX),
            boot_stack_b: u16::try_from(board.boot_stack_b()).unwrap_or(u16::MAX),
            reset_cause: self.reset_cause as u8,
            restore: wire::restore_code(self.restore),
            boots: self.boots,
            rejected_crc: c.rejected_crc,
            rejected_framing: c.rejected_framing,
            rejected_sequence: c.rejected_sequence,
            superseded: c.superseded,
            accepted: c.accepted,
            missing: c.missing,
            rx_overflow: u16::try_from(board.rx_dropped()).unwrap_or(u16::MAX),
            commands: c.commands,
            nv_failures: c.nv_failures,
            faults: self.guard.faults(),
            protocol: crate::protocol::PROTOCOL_VERSION,
        }
    }
}
