//! Encoders and decoders of the product frames (layouts in docs/firmware.md,
//! "Product protocol"): little-endian fields through the protocol's reader.

use super::*;

type Buf = Vec<u8, MAX_PAYLOAD>;

fn put(p: &mut Buf, b: &[u8]) {
    // Payloads are fixed-size and below MAX_PAYLOAD; a failure would give a
    // short frame the peer rejects, never a panic.
    let _ = p.extend_from_slice(b);
}

fn out_fields(p: &mut Buf, o: &Output) {
    put(p, &o.drain_c.to_le_bytes());
    put(p, &[crate::protocol::GuardOutput::flags(o)]);
    put(p, &o.faults.bits().to_le_bytes());
    put(p, &o.lng_remaining_kg.to_le_bytes());
    put(p, &o.lng_seconds_left.to_le_bytes());
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
            faults: crate::faults::Faults::from_bits(self.u16()?),
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
        let mut p = Buf::new();
        put(&mut p, &[KIND_COMMAND]);
        put(&mut p, &self.token.to_le_bytes());
        put(&mut p, &[self.cmd.code()]);
        frame(&p, false)
    }

    /// Parses a payload (CRC checked and stripped).
    pub fn from_payload(p: &[u8]) -> Result<Command, DecodeError> {
        let mut r = expect(p, KIND_COMMAND, COMMAND_LEN)?;
        let token = r.u16()?;
        let cmd = Cmd::from_code(r.u8()?).ok_or(DecodeError::Kind)?;
        Ok(Command { token, cmd })
    }
}

impl TickReply {
    /// Wire bytes (leading and trailing delimiter).
    pub fn encode(&self) -> WireFrame {
        let mut p = Buf::new();
        put(&mut p, &[KIND_TICK]);
        put(&mut p, &self.tick.to_le_bytes());
        put(&mut p, &self.sample_seq.to_le_bytes());
        put(&mut p, &[u8::from(self.fresh) | (u8::from(self.not_commissioned) << 1)]);
        out_fields(&mut p, &self.out);
        put(&mut p, &[u8::from(self.pins.valve_pin) | (u8::from(self.pins.ok_pin) << 1)]);
        put(&mut p, &self.overruns.to_le_bytes());
        put(&mut p, &self.rejected.to_le_bytes());
        put(&mut p, &[restore_code(self.restore), self.reset_cause as u8]);
        frame(&p, true)
    }

    /// Parses a payload (host side).
    pub fn from_payload(p: &[u8]) -> Result<TickReply, DecodeError> {
        let mut r = expect(p, KIND_TICK, TICK_LEN)?;
        let tick = r.u32()?;
        let sample_seq = r.u16()?;
        let fresh_byte = r.u8()?;
        let (fresh, not_commissioned) = (fresh_byte & 1 != 0, fresh_byte & 2 != 0);
        let out = r.out()?;
        let pins = r.u8()?;
        let overruns = r.u16()?;
        let rejected = r.u16()?;
        let restore = restore_from_code(r.u8()?).ok_or(DecodeError::Kind)?;
        let reset_cause = ResetCause::from_code(r.u8()?);
        let pins = Pins { valve_pin: pins & 1 != 0, ok_pin: pins & 2 != 0 };
        Ok(TickReply { tick, sample_seq, fresh, not_commissioned, out, pins, overruns, rejected, restore, reset_cause })
    }
}

impl Ack {
    /// Wire bytes.
    pub fn encode(&self) -> WireFrame {
        let mut p = Buf::new();
        put(&mut p, &[KIND_ACK]);
        put(&mut p, &self.token.to_le_bytes());
        put(&mut p, &[self.cmd.code(), self.result as u8]);
        frame(&p, true)
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
        Ok(Ack { token, cmd, result })
    }
}

impl Status {
    /// Wire bytes.
    pub fn encode(&self) -> WireFrame {
        let mut p = Buf::new();
        put(&mut p, &[KIND_STATUS]);
        put(&mut p, &self.token.to_le_bytes());
        put(&mut p, &self.tick.to_le_bytes());
        put(&mut p, &self.overruns.to_le_bytes());
        put(&mut p, &self.worst_tick_cycles.to_le_bytes());
        put(&mut p, &self.stack_high_water_b.to_le_bytes());
        put(&mut p, &self.boot_stack_b.to_le_bytes());
        put(&mut p, &[self.reset_cause, self.restore]);
        for v in [self.boots, self.rejected_crc, self.rejected_framing, self.rejected_sequence, self.superseded] {
            put(&mut p, &v.to_le_bytes());
        }
        put(&mut p, &self.accepted.to_le_bytes());
        put(&mut p, &self.missing.to_le_bytes());
        for v in [self.rx_overflow, self.commands, self.nv_failures, self.faults.bits()] {
            put(&mut p, &v.to_le_bytes());
        }
        frame(&p, true)
    }

    /// Parses a payload (host side).
    pub fn from_payload(p: &[u8]) -> Result<Status, DecodeError> {
        let mut r = expect(p, KIND_STATUS, STATUS_LEN)?;
        Ok(Status {
            token: r.u16()?,
            tick: r.u32()?,
            overruns: r.u32()?,
            worst_tick_cycles: r.u32()?,
            stack_high_water_b: r.u16()?,
            boot_stack_b: r.u16()?,
            reset_cause: r.u8()?,
            restore: r.u8()?,
            boots: r.u16()?,
            rejected_crc: r.u16()?,
            rejected_framing: r.u16()?,
            rejected_sequence: r.u16()?,
            superseded: r.u16()?,
            accepted: r.u32()?,
            missing: r.u32()?,
            rx_overflow: r.u16()?,
            commands: r.u16()?,
            nv_failures: r.u16()?,
            faults: crate::faults::Faults::from_bits(r.u16()?),
        })
    }
}

impl TraceReply {
    /// Wire bytes.
    pub fn encode(&self) -> WireFrame {
        let mut p = Buf::new();
        put(&mut p, &[KIND_TRACE]);
        put(&mut p, &self.token.to_le_bytes());
        put(&mut p, &[self.index, self.count, self.event.tag]);
        put(&mut p, &self.event.tick.to_le_bytes());
        put(&mut p, &self.event.value.to_le_bytes());
        put(&mut p, &self.event.aux.to_le_bytes());
        frame(&p, true)
    }

    /// Parses a payload (host side).
    pub fn from_payload(p: &[u8]) -> Result<TraceReply, DecodeError> {
        let mut r = expect(p, KIND_TRACE, TRACE_LEN)?;
        let token = r.u16()?;
        let index = r.u8()?;
        let count = r.u8()?;
        let tag = r.u8()?;
        let event = TraceWire { tag, tick: r.u32()?, value: r.f32()?, aux: r.u16()? };
        Ok(TraceReply { token, index, count, event })
    }
}
