//! Field encoder and decoder of the sample request payload (layout in
//! the [module docs](super)).

use super::*;

/// Little-endian field reader that never panics (also used by
/// [`crate::product::wire`]).
pub(crate) struct Rd<'a>(pub(crate) &'a [u8]);
impl Rd<'_> {
    fn arr<const K: usize>(&mut self) -> Result<[u8; K], DecodeError> {
        let (head, tail) = self.0.split_at_checked(K).ok_or(DecodeError::Length)?;
        self.0 = tail;
        head.try_into().map_err(|_| DecodeError::Length)
    }
    pub(crate) fn u8(&mut self) -> Result<u8, DecodeError> {
        Ok(u8::from_le_bytes(self.arr()?))
    }
    pub(crate) fn u16(&mut self) -> Result<u16, DecodeError> {
        Ok(u16::from_le_bytes(self.arr()?))
    }
    pub(crate) fn u32(&mut self) -> Result<u32, DecodeError> {
        Ok(u32::from_le_bytes(self.arr()?))
    }
    pub(crate) fn f32(&mut self) -> Result<f32, DecodeError> {
        Ok(f32::from_le_bytes(self.arr()?))
    }
}

impl Request {
    /// Payload bytes (without CRC).
    pub fn to_payload(&self) -> Vec<u8, REQUEST_LEN> {
        let mut p = Vec::new();
        let _ = p.push(KIND_SAMPLE);
        let _ = p.extend_from_slice(&self.seq.to_le_bytes());
        for v in [self.current_a, self.p_a_bar, self.p_b_bar, self.speed_rpm, self.position_mm, self.ambient_c] {
            let _ = p.extend_from_slice(&v.to_le_bytes());
        }
        let flags = match self.valve_fb {
            None => 0,
            Some(false) => FLAG_VALVE_FB,
            Some(true) => FLAG_VALVE_FB | FLAG_VALVE_FB_OPEN,
        };
        let _ = p.push(flags);
        p
    }

    /// Parse a payload (CRC already checked and stripped).
    pub fn from_payload(p: &[u8]) -> Result<Self, DecodeError> {
        let mut r = Rd(p);
        if r.u8()? != KIND_SAMPLE {
            return Err(DecodeError::Kind);
        }
        if p.len() != REQUEST_LEN {
            return Err(DecodeError::Length);
        }
        let mut q = Request {
            seq: r.u16()?,
            current_a: r.f32()?,
            p_a_bar: r.f32()?,
            p_b_bar: r.f32()?,
            speed_rpm: r.f32()?,
            position_mm: r.f32()?,
            ambient_c: r.f32()?,
            valve_fb: None,
        };
        q.valve_fb = match r.u8()? {
            0 => None,
            FLAG_VALVE_FB => Some(false),
            f if f == FLAG_VALVE_FB | FLAG_VALVE_FB_OPEN => Some(true),
            _ => return Err(DecodeError::Kind),
        };
        Ok(q)
    }

    /// Wire bytes: COBS frame terminated by `0x00` (no leading delimiter).
    pub fn encode(&self) -> WireFrame {
        frame(&self.to_payload(), false)
    }
}
