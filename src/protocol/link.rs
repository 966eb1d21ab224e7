//! The guard's end of the link: sequence rule, counters, one reply per frame.

use super::*;

// ------------------------------------------------------------------ link

/// The guard's end of the link: deframes requests, enforces the sequence
/// rule, counts rejections, ticks the guard on accepted frames and produces
/// exactly one reply per non-empty frame. Transport independent.
#[derive(Debug, Default)]
pub struct Link {
    rx: Deframer,
    last_seq: Option<u16>,
    counters: Counters,
    last_out: GuardOutput,
}

fn sat_inc(c: &mut u16) {
    *c = c.saturating_add(1);
}

impl Link {
    /// A fresh link: no sequence yet, counters zero.
    pub const fn new() -> Self {
        Self {
            rx: Deframer::new(),
            last_seq: None,
            counters: Counters {
                rejected_crc: 0,
                rejected_framing: 0,
                rejected_sequence: 0,
                skipped: 0,
                accepted: 0,
            },
            last_out: GuardOutput {
                drain_c: 0.0,
                valve_open: false,
                alarm: false,
                derate: false,
                faults: crate::faults::Faults::NONE,
                lng_remaining_kg: 0.0,
                lng_seconds_left: 0.0,
            },
        }
    }

    /// Counters so far.
    pub fn counters(&self) -> Counters {
        self.counters
    }

    /// Last accepted sequence number.
    pub fn last_seq(&self) -> Option<u16> {
        self.last_seq
    }

    /// True while a partial frame is buffered.
    pub fn pending(&self) -> bool {
        self.rx.pending()
    }

    /// Feed received bytes. For each complete frame, `tick` is called when it
    /// is accepted (it returns the guard output and the tick's cost in core-clock cycles)
    /// and `send` gets the encoded reply. Never panics, never blocks.
    pub fn push_bytes<S, W>(&mut self, bytes: &[u8], mut tick: S, mut send: W)
    where
        S: FnMut(&Request, u16) -> (GuardOutput, u32),
        W: FnMut(&Reply, &[u8]),
    {
        for &b in bytes {
            let Some(res) = self.rx.push(b) else { continue };
            let reply = self.handle(res, &mut tick);
            send(&reply, &reply.encode());
        }
    }

    fn handle<S>(&mut self, res: Result<Payload, DecodeError>, tick: &mut S) -> Reply
    where
        S: FnMut(&Request, u16) -> (GuardOutput, u32),
    {
        let reject_seq = self.last_seq.unwrap_or(0);
        let req = match res.and_then(|p| Request::from_payload(&p)) {
            Ok(r) => r,
            Err(e) => {
                match e {
                    DecodeError::Crc => sat_inc(&mut self.counters.rejected_crc),
                    _ => sat_inc(&mut self.counters.rejected_framing),
                }
                return self.reply(ReplyKind::Reject(e.reason()), reject_seq, 0);
            }
        };
        let mut gap = 0;
        if let Some(last) = self.last_seq {
            let ahead = req.seq.wrapping_sub(last);
            if ahead == 0 || ahead > 0x8000 {
                sat_inc(&mut self.counters.rejected_sequence);
                return self.reply(ReplyKind::Reject(RejectReason::Sequence), req.seq, 0);
            }
            gap = ahead - 1;
            self.counters.skipped = self.counters.skipped.saturating_add(gap);
        }
        self.last_seq = Some(req.seq);
        self.counters.accepted = self.counters.accepted.saturating_add(1);
        let (out, cycles) = tick(&req, gap);
        self.last_out = out;
        self.reply(ReplyKind::Tick, req.seq, cycles)
    }

    fn reply(&self, kind: ReplyKind, seq: u16, tick_cycles: u32) -> Reply {
        Reply { kind, seq, out: self.last_out, counters: self.counters, tick_cycles }
    }

    /// The completion marker: sent once at end of input.
    pub fn done(&self) -> Reply {
        self.reply(ReplyKind::Done, self.last_seq.unwrap_or(0), 0)
    }
}
