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
    pub fn to_payload(&self) -> Vec<u8, REQUEST_MAX_LEN> {
        let mut p = Vec::new();
        let _ = p.push(KIND_SAMPLE);
        let _ = p.extend_from_slice(&self.seq.to_le_bytes());
        let (s, r) = (&self.sample, &self.reports);
        for v in [s.current_a, s.p_a_bar, s.p_b_bar, s.speed_rpm, s.position_mm, s.ambient_c] {
            let _ = p.extend_from_slice(&v.to_le_bytes());
        }
        let mut flags = match r.valve_fb {
            None => 0,
            Some(false) => FLAG_VALVE_FB,
            Some(true) => FLAG_VALVE_FB | FLAG_VALVE_FB_OPEN,
        };
        if r.elec_hz.is_some() {
            flags |= FLAG_ELEC_HZ;
        }
        if r.lng_supply_bar.is_some() {
            flags |= FLAG_LNG_SUPPLY;
        }
        let _ = p.push(flags);
        for v in [r.elec_hz, r.lng_supply_bar].into_iter().flatten() {
            let _ = p.extend_from_slice(&v.to_le_bytes());
        }
        p
    }

    /// Parse a payload (CRC already checked and stripped).
    pub fn from_payload(p: &[u8]) -> Result<Self, DecodeError> {
        let mut r = Rd(p);
        if r.u8()? != KIND_SAMPLE {
            return Err(DecodeError::Kind);
        }
        let flags = p.get(REQUEST_LEN - 1).copied().ok_or(DecodeError::Length)?;
        if flags & !(FLAG_VALVE_FB | FLAG_VALVE_FB_OPEN | FLAG_ELEC_HZ | FLAG_LNG_SUPPLY) != 0 || flags & (FLAG_VALVE_FB | FLAG_VALVE_FB_OPEN) == FLAG_VALVE_FB_OPEN {
            return Err(DecodeError::Kind);
        }
        let want = REQUEST_LEN + 4 * usize::from(flags & FLAG_ELEC_HZ != 0) + 4 * usize::from(flags & FLAG_LNG_SUPPLY != 0);
        if p.len() != want {
            return Err(DecodeError::Length);
        }
        let seq = r.u16()?;
        let sample = Sample {
            current_a: r.f32()?,
            p_a_bar: r.f32()?,
            p_b_bar: r.f32()?,
            speed_rpm: r.f32()?,
            position_mm: r.f32()?,
            ambient_c: r.f32()?,
        };
        let _ = r.u8()?;
        let mut reports = Reports { valve_fb: (flags & FLAG_VALVE_FB != 0).then_some(flags & FLAG_VALVE_FB_OPEN != 0), ..Reports::default() };
        if flags & FLAG_ELEC_HZ != 0 {
            reports.elec_hz = Some(r.f32()?);
        }
        if flags & FLAG_LNG_SUPPLY != 0 {
            reports.lng_supply_bar = Some(r.f32()?);
        }
        Ok(Request { seq, sample, reports })
    }

    /// Wire bytes: COBS frame terminated by `0x00` (no leading delimiter).
    pub fn encode(&self) -> WireFrame {
        frame(&self.to_payload(), false)
    }
}
