//! Encoders and decoders of the product frames (layouts in docs/firmware.md,
//! "Product protocol"): little-endian fields through the protocol's reader.

use super::*;

/// A frame built in place: `fill` writes the payload, then it is sealed
/// (CRC, COBS, delimiters; `lead`: with the leading delimiter).
#[inline(always)]
fn framed(lead: bool, fill: impl FnOnce(&mut PutAt<'_>)) -> WireFrame {
    let mut w = WireFrame::zeroed();
    let mut p = w.payload();
    fill(&mut p);
    let n = p.len();
    w.seal(n, lead);
    w
}

impl Rd<'_> {
    /// The output fields of a reply (drain, flags, faults, LNG kg and s).
    fn out(&mut self) -> Result<Output, DecodeError> {
        let drain_c = self.f32()?;
        let flags = self.u8()?;
        Ok(Output {
            drain_c,
            valve_open: flags & 1 != 0,
            alarm: flags & 2 != 0,
            derate: flags & 4 != 0,
            faults: crate::faults::Faults::from_bits(self.u32()?),
            lng_remaining_kg: self.f32()?,
            lng_seconds_left: self.f32()?,
        })
    }
}

fn expect(p: &[u8], kind: u8, len: usize) -> Result<Rd<'_>, DecodeError> {
    match p.first() {
        Some(&k) if k == kind => {}
        _ => return Err(DecodeError::Kind),
    }
    if p.len() != len {
        return Err(DecodeError::Length);
    }
    Ok(Rd(p.get(1..).unwrap_or(&[])))
}

impl Command {
    /// Wire bytes (controller side).
    pub fn encode(&self) -> WireFrame {
        framed(false, |p| {
            p.u8(KIND_COMMAND);
            p.u16(self.token);
            p.u8(self.cmd.code());
            p.u32(self.arg);
        })
    }

    /// Parses a payload (CRC checked and stripped).
    pub fn from_payload(p: &[u8]) -> Result<Command, DecodeError> {
        let mut r = expect(p, KIND_COMMAND, COMMAND_LEN)?;
        let token = r.u16()?;
        let cmd = Cmd::from_code(r.u8()?).ok_or(DecodeError::Kind)?;
        Ok(Command { token, cmd, arg: r.u32()? })
    }
}

impl TickReply {
    /// The fields that change only with the outputs, the pins or the
    /// counters (layout: docs/firmware.md): written first, so that the
    /// product loop re-frames only the per-tick tail ([`super::ReplyEncoder`]).
    #[inline(always)]
    pub(super) fn head(&self, p: &mut PutAt<'_>) {
        p.u8(KIND_TICK);
        p.u8(u8::from(self.not_commissioned) << 1);
        p.f32(self.out.drain_c);
        p.u8(crate::protocol::GuardOutput::flags(&self.out));
        p.u32(self.out.faults.bits());
        p.f32(self.out.lng_remaining_kg);
        p.f32(self.out.lng_seconds_left);
        p.u8(u8::from(self.pins.valve_pin) | (u8::from(self.pins.ok_pin) << 1));
        p.u16(self.overruns);
        p.u16(self.rejected);
        p.u8(restore_code(self.restore));
        p.u8(self.reset_cause as u8);
    }

    /// The per-tick tail: tick counter, the sample's sequence number, fresh.
    #[inline(always)]
    pub(super) fn tail(&self) -> [u8; TICK_TAIL_LEN] {
        let t = self.tick.to_le_bytes();
        let s = self.sample_seq.to_le_bytes();
        [t[0], t[1], t[2], t[3], s[0], s[1], u8::from(self.fresh)]
    }

    /// Wire bytes (leading and trailing delimiter).
    pub fn encode(&self) -> WireFrame {
        framed(true, |p| {
            self.head(p);
            p.bytes(&self.tail());
        })
    }

    /// Parses a payload (host side).
    pub fn from_payload(p: &[u8]) -> Result<TickReply, DecodeError> {
        let mut r = expect(p, KIND_TICK, TICK_LEN)?;
        let not_commissioned = r.u8()? & 2 != 0;
        let out = r.out()?;
        let pins = r.u8()?;
        let overruns = r.u16()?;
        let rejected = r.u16()?;
        let restore = restore_from_code(r.u8()?).ok_or(DecodeError::Kind)?;
        let reset_cause = ResetCause::from_code(r.u8()?);
        let tick = r.u32()?;
        let sample_seq = r.u16()?;
        let fresh = r.u8()? & 1 != 0;
        let pins = Pins { valve_pin: pins & 1 != 0, ok_pin: pins & 2 != 0 };
        Ok(TickReply { tick, sample_seq, fresh, not_commissioned, out, pins, overruns, rejected, restore, reset_cause })
    }
}

impl Ack {
    /// Wire bytes.
    pub fn encode(&self) -> WireFrame {
        framed(true, |p| {
            p.u8(KIND_ACK);
            p.u16(self.token);
            p.u8(self.cmd.code());
            p.u8(self.result as u8);
            p.u32(self.value);
        })
    }

    /// Parses a payload (host side).
    pub fn from_payload(p: &[u8]) -> Result<Ack, DecodeError> {
        let mut r = expect(p, KIND_ACK, ACK_LEN)?;
        let token = r.u16()?;
        let cmd = Cmd::from_code(r.u8()?).ok_or(DecodeError::Kind)?;
        let result = match r.u8()? {
            0 => AckResult::Done,
            1 => AckResult::Refused,
            _ => return Err(DecodeError::Kind),
        };
        Ok(Ack { token, cmd, result, value: r.u32()? })
    }
}

impl Status {
    /// Wire bytes.
    pub fn encode(&self) -> WireFrame {
        framed(true, |p| {
            p.u8(KIND_STATUS);
            p.u16(self.token);
            let c = &self.counters;
            p.u32(self.tick);
            p.u32(c.overruns);
            p.u32(self.worst_tick_cycles);
            p.u16(self.stack_high_water_b);
            p.u16(self.boot_stack_b);
            p.u8(self.reset_cause);
            p.u8(self.restore);
            for v in [self.boots, c.rejected_crc, c.rejected_framing, c.rejected_sequence, c.superseded] {
                p.u16(v);
            }
            p.u32(c.accepted);
            p.u32(c.missing);
            for v in [self.rx_overflow, c.commands, c.nv_failures] {
                p.u16(v);
            }
            p.u32(self.faults.bits());
            p.u8(self.protocol);
        })
    }

    /// Parses a payload (host side).
    pub fn from_payload(p: &[u8]) -> Result<Status, DecodeError> {
        let mut r = expect(p, KIND_STATUS, STATUS_LEN)?;
        // In wire order: the counters interleave with the other fields.
        let token = r.u16()?;
        let tick = r.u32()?;
        let overruns = r.u32()?;
        let worst_tick_cycles = r.u32()?;
        let stack_high_water_b = r.u16()?;
        let boot_stack_b = r.u16()?;
        let reset_cause = r.u8()?;
        let restore = r.u8()?;
        let boots = r.u16()?;
        let rejected_crc = r.u16()?;
        let rejected_framing = r.u16()?;
        let rejected_sequence = r.u16()?;
        let superseded = r.u16()?;
        let accepted = r.u32()?;
        let missing = r.u32()?;
        let rx_overflow = r.u16()?;
        let commands = r.u16()?;
        let nv_failures = r.u16()?;
        let counters = Counters { rejected_crc, rejected_framing, rejected_sequence, superseded, accepted, missing, overruns, commands, nv_failures };
        Ok(Status {
            token,
            tick,
            counters,
            worst_tick_cycles,
            stack_high_water_b,
            boot_stack_b,
            reset_cause,
            restore,
            boots,
            rx_overflow,
            faults: crate::faults::Faults::from_bits(r.u32()?),
            protocol: r.u8()?,
        })
    }
}

impl TraceReply {
    /// Wire bytes.
    pub fn encode(&self) -> WireFrame {
        framed(true, |p| {
            p.u8(KIND_TRACE);
            p.u16(self.token);
            p.u8(self.index);
            p.u8(self.count);
            p.u8(self.event.tag);
            p.u32(self.event.tick);
            p.f32(self.event.value);
            p.u32(self.event.aux);
        })
    }

    /// Parses a payload (host side).
    pub fn from_payload(p: &[u8]) -> Result<TraceReply, DecodeError> {
        let mut r = expect(p, KIND_TRACE, TRACE_LEN)?;
        let token = r.u16()?;
        let index = r.u8()?;
        let count = r.u8()?;
        let tag = r.u8()?;
        let event = TraceWire { tag, tick: r.u32()?, value: r.f32()?, aux: r.u32()? };
        Ok(TraceReply { token, index, count, event })
    }
}
