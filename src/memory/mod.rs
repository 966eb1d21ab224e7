//! Thermal memory: the model state survives a warm or watchdog reset in two
//! no-init RAM records (A/B, [`slots`]: a reset during a write leaves the
//! other one), and a power loss in non-volatile flash ([`nv`], through
//! `sequential-storage`), each record guarded by a magic word, a sequence
//! number and a CRC-32. The record carries the node temperatures, the LNG
//! energy used (never reset except by the refill command), the latched
//! faults and the valve state.
//!
//! Boot order: the newest valid RAM record (warm reset), else the newest
//! valid flash record (power loss: the saved temperatures, cooled over the
//! off-time only where a real-time clock measured it, [`boot_restore`]),
//! else a cold start.
//!
//! Boot rules (documented behaviour):
//! * **Cold boot** (power-on: the magic word is absent, i.e. more than 4 bits from it): every node starts at the
//!   first ambient sample — the machine has been off long enough to be at ambient.
//!   (A warm-looking garbage pattern matching the 32-bit magic has probability 2^-32.)
//! * **Warm / watchdog reset** (magic present, CRC and plausibility good): the node
//!   temperatures, the LNG energy used and the latched faults are restored.
//! * **Corrupt record** (magic present, CRC or plausibility bad): the state is
//!   unknown but the machine may be hot, so every node starts at the over-temperature
//!   alarm temperature (60 degC, the paper's permissible drain temperature), the
//!   valve is forced open by the latched `MEMORY_CORRUPT` fault, and the LNG budget
//!   is taken as empty (unknown use: report the worst case). The estimate is not
//!   trusted: alarm and derate are raised at once (the start temperature alone would
//!   not raise them: the alarm fires above it) and held until the clear rule
//!   (`faults::UNTRUSTED`); the estimate relaxes with the model dynamics.
//!
//! The record type and CRC are plain Rust and host-tested; only the static in the
//! `.uninit.thermal` section (cortex-m-rt's NOLOAD `.uninit`) is target-only.

use crate::params::N_NODES;

/// Record magic: "EHAT".
pub const MAGIC: u32 = 0x4548_4154;
/// Record layout version. 4: the RTC time of the write ([`ThermalRecord::rtc_s`]).
/// 3: the former reserved word holds the sequence
/// number and the valve state ([`ThermalRecord::seq`], [`ThermalRecord::valve_open`]).
/// 2: the six temperatures are the reduced model's nodes (pump housing, case
/// oil, loop oil, main block, ball-valve block, actuator). An older record is
/// treated as corrupt (conservative).
pub const VERSION: u16 = 4;
/// [`ThermalRecord::rtc_s`] of a board without a real-time clock.
pub const RTC_NONE: u32 = u32::MAX;
/// Bit of [`ThermalRecord::seq_flags`] that holds the valve state (1 = open).
pub const FLAG_VALVE_OPEN: u32 = 1 << 31;
/// Plausible stored temperature range, degC (anything else is treated as corrupt).
pub const PLAUSIBLE_C: (f32, f32) = (-80.0, 250.0);

/// Size of a [`ThermalRecord`] and of its byte form, bytes.
pub const RECORD_BYTES: usize = 56;

/// Persistent thermal record, 56 bytes, no implicit padding.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct ThermalRecord {
    /// LNG heat-sink energy used, cJ (0.01 J).
    pub lng_used_cj: u32,
    /// Guard tick counter (10 ms) at save time.
    pub tick: u32,
    /// [`MAGIC`] when written by this firmware.
    pub magic: u32,
    /// [`VERSION`].
    pub version: u16,
    /// Latched fault bits at save time.
    pub faults: u16,
    /// Node temperatures, degC, contract order.
    pub temps_c: [f32; N_NODES],
    /// Ambient the temperatures were referred to, degC.
    pub ambient_c: f32,
    /// Sequence number of the write (bits 0–30, wrapping) and the valve
    /// state ([`FLAG_VALVE_OPEN`]).
    pub seq_flags: u32,
    /// Seconds of the board's battery-backed real-time clock at the write
    /// ([`RTC_NONE`]: no clock), for the cooling over the off-time.
    pub rtc_s: u32,
    /// CRC-32 (IEEE) of all preceding bytes, little endian field order.
    pub crc: u32,
}

/// Nibble table of the reflected CRC-32 (IEEE, polynomial 0xEDB88320).
/// Built at compile time (an out-of-range index would be a compile error).
/// Not the `crc` crate: it offers a bitwise CRC-32 (the A/B record's CRC in
/// every product tick then took the loop from ~5 000 to ~10 600
/// instructions per tick, measured) or a 1 KiB table (960 B more, past the
/// product image's 32 KiB flash); this 64-byte table does two lookups per byte.
#[allow(clippy::indexing_slicing)]
const CRC_NIBBLE: [u32; 16] = {
    let mut t = [0u32; 16];
    let mut i = 0;
    while i < 16 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 4 {
            c = if c & 1 != 0 {
                (c >> 1) ^ 0xEDB8_8320
            } else {
                c >> 1
            };
            k += 1;
        }
        t[i] = c;
        i += 1;
    }
    t
};

/// CRC-32 (IEEE 802.3, as zlib's `crc32`) update over `data`.
#[inline(never)]
pub fn crc32_update(mut crc: u32, data: &[u8]) -> u32 {
    for b in data {
        crc ^= *b as u32;
        for _ in 0..2 {
            let idx = (crc & 0xf) as usize;
            crc = (crc >> 4) ^ CRC_NIBBLE.get(idx).copied().unwrap_or(0);
        }
    }
    crc
}

/// CRC-32 of `data` (init and final xor 0xFFFFFFFF).
pub fn crc32(data: &[u8]) -> u32 {
    !crc32_update(0xFFFF_FFFF, data)
}

impl ThermalRecord {
    /// An all-zero record (not valid: no magic).
    pub const EMPTY: ThermalRecord = ThermalRecord {
        lng_used_cj: 0,
        magic: 0,
        version: 0,
        faults: 0,
        temps_c: [0.0; N_NODES],
        ambient_c: 0.0,
        tick: 0,
        seq_flags: 0,
        rtc_s: RTC_NONE,
        crc: 0,
    };

    fn body_crc(&self) -> u32 {
        let mut c = 0xFFFF_FFFF;
        c = crc32_update(c, &self.lng_used_cj.to_le_bytes());
        c = crc32_update(c, &self.tick.to_le_bytes());
        c = crc32_update(c, &self.magic.to_le_bytes());
        c = crc32_update(c, &self.version.to_le_bytes());
        c = crc32_update(c, &self.faults.to_le_bytes());
        for t in self.temps_c.iter() {
            c = crc32_update(c, &t.to_bits().to_le_bytes());
        }
        c = crc32_update(c, &self.ambient_c.to_bits().to_le_bytes());
        c = crc32_update(c, &self.seq_flags.to_le_bytes());
        c = crc32_update(c, &self.rtc_s.to_le_bytes());
        !c
    }

    /// Builds a sealed record (magic, version, CRC filled in).
    pub fn new(
        temps_c: [f32; N_NODES],
        ambient_c: f32,
        lng_used_cj: u32,
        faults: u16,
        tick: u32,
    ) -> Self {
        let mut r = ThermalRecord {
            lng_used_cj,
            magic: MAGIC,
            version: VERSION,
            faults,
            temps_c,
            ambient_c,
            tick,
            seq_flags: 0,
            rtc_s: RTC_NONE,
            crc: 0,
        };
        r.crc = r.body_crc();
        r
    }

    /// The same record stamped with the real-time clock `rtc_s` (seconds;
    /// `None`: no clock), resealed.
    pub fn with_rtc(mut self, rtc_s: Option<u32>) -> Self {
        self.rtc_s = rtc_s.unwrap_or(RTC_NONE);
        self.crc = self.body_crc();
        self
    }

    /// The same record with sequence number `seq` (31 bits) and the valve
    /// state, resealed.
    pub fn with_seq(mut self, seq: u32, valve_open: bool) -> Self {
        self.seq_flags = (seq & !FLAG_VALVE_OPEN) | if valve_open { FLAG_VALVE_OPEN } else { 0 };
        self.crc = self.body_crc();
        self
    }

    /// The record's bytes: every field little-endian in field order (the
    /// form stored in flash and in no-init RAM on a little-endian target).
    pub fn to_le_bytes(&self) -> [u8; RECORD_BYTES] {
        let mut words = [0u32; RECORD_BYTES / 4];
        words[0] = self.lng_used_cj;
        words[1] = self.tick;
        words[2] = self.magic;
        words[3] = u32::from(self.version) | (u32::from(self.faults) << 16);
        for (w, t) in words[4..4 + N_NODES].iter_mut().zip(self.temps_c.iter()) {
            *w = t.to_bits();
        }
        words[10] = self.ambient_c.to_bits();
        words[11] = self.seq_flags;
        words[12] = self.rtc_s;
        words[13] = self.crc;
        let mut out = [0u8; RECORD_BYTES];
        for (chunk, w) in out.chunks_exact_mut(4).zip(words.iter()) {
            chunk.copy_from_slice(&w.to_le_bytes());
        }
        out
    }

    /// The record of [`Self::to_le_bytes`] bytes (not checked: see [`Self::classify`]).
    pub fn from_le_bytes(b: &[u8; RECORD_BYTES]) -> Self {
        let mut w = [0u32; RECORD_BYTES / 4];
        for (x, chunk) in w.iter_mut().zip(b.chunks_exact(4)) {
            let mut a = [0u8; 4];
            a.copy_from_slice(chunk);
            *x = u32::from_le_bytes(a);
        }
        let mut temps_c = [0.0f32; N_NODES];
        for (t, x) in temps_c.iter_mut().zip(w[4..4 + N_NODES].iter()) {
            *t = f32::from_bits(*x);
        }
        ThermalRecord {
            lng_used_cj: w[0],
            tick: w[1],
            magic: w[2],
            version: (w[3] & 0xFFFF) as u16,
            faults: (w[3] >> 16) as u16,
            temps_c,
            ambient_c: f32::from_bits(w[10]),
            seq_flags: w[11],
            rtc_s: w[12],
            crc: w[13],
        }
    }

    /// Sequence number of the write (31 bits, wrapping).
    pub fn seq(&self) -> u32 {
        self.seq_flags & !FLAG_VALVE_OPEN
    }

    /// The valve was open when the record was written.
    pub fn valve_open(&self) -> bool {
        self.seq_flags & FLAG_VALVE_OPEN != 0
    }

    /// Classifies the record per the module's boot rules.
    pub fn classify(&self) -> RecordStatus {
        // A magic within 4 bit flips of MAGIC is a damaged record, not a cold boot
        // (random power-on RAM lands there with probability ~1e-5: then conservative).
        if (self.magic ^ MAGIC).count_ones() > 4 {
            return RecordStatus::Absent;
        }
        let (lo, hi) = PLAUSIBLE_C;
        let plausible = self
            .temps_c
            .iter()
            .chain(core::iter::once(&self.ambient_c))
            .all(|t| t.is_finite() && *t >= lo && *t <= hi);
        if self.version == VERSION && self.crc == self.body_crc() && plausible
        {
            RecordStatus::Valid
        } else {
            RecordStatus::Corrupt
        }
    }
}

/// Outcome of checking a stored record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordStatus {
    /// No magic: cold boot.
    Absent,
    /// Magic, version, CRC and ranges good: warm restore.
    Valid,
    /// Magic present but the rest is bad: conservative start.
    Corrupt,
}

/// How [`crate::guard::Guard::new`] initialises the thermal state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Restore {
    /// Cold boot: all nodes at the first ambient sample.
    Cold,
    /// Warm reset with a valid record.
    Warm(ThermalRecord),
    /// Power loss: the non-volatile record, raised by the write policy's
    /// `rise_k` and cooled over the off-time where a clock measured it
    /// ([`boot_restore`]). The guard raises every node by the ambient's rise
    /// at its first sample.
    PowerLoss(ThermalRecord),
    /// A corrupt record was found: conservative start (see module docs).
    Corrupt,
}

impl Restore {
    /// Maps a stored record to the boot rule.
    pub fn from_record(r: &ThermalRecord) -> Restore {
        match r.classify() {
            RecordStatus::Absent => Restore::Cold,
            RecordStatus::Valid => Restore::Warm(*r),
            RecordStatus::Corrupt => Restore::Corrupt,
        }
    }
}

pub mod cooling;
pub mod nv;
pub mod slots;

/// The boot rule over both memories: the RAM records' rule
/// ([`slots::restore_from`]) unless RAM holds nothing (power-on), then the
/// non-volatile record (a power loss), else a cold start. A damaged RAM
/// record stays a conservative start even when flash holds an older valid one.
///
/// After a power loss every node is first raised by the write policy's
/// `rise_k` (the most the estimate can have risen since that record was
/// written, so the state is never colder than at power-off). Then, when the
/// record and the board both have a clock reading (`now_rtc_s`) and the clock
/// has not gone back, the state is cooled by the model's bound at rest
/// ([`cooling::RestCooling`]) over the off-time minus the policy's longest
/// write interval (the machine may have run that long after the write);
/// without a clock or a bound, the saved temperatures stand (power loss of
/// unknown length: conservative).
pub fn boot_restore(ram: Restore, nv: Option<ThermalRecord>, policy: &nv::NvPolicy, cool: Option<&cooling::RestCooling>, now_rtc_s: Option<u32>) -> Restore {
    match (ram, nv) {
        (Restore::Cold, Some(r)) => {
            let mut hot = r.temps_c;
            for t in hot.iter_mut() {
                *t += policy.rise_k;
            }
            let run_s = policy.max_interval_ticks / 100;
            let off_s = match (now_rtc_s, r.rtc_s) {
                (Some(now), saved) if saved != RTC_NONE && now >= saved => Some((now - saved).saturating_sub(run_s)).filter(|s| *s > 0),
                _ => None,
            };
            if let (Some(b), Some(off)) = (cool, off_s) {
                hot = b.cool(&hot, r.ambient_c, off);
            }
            Restore::PowerLoss(ThermalRecord::new(hot, r.ambient_c, r.lng_used_cj, r.faults, r.tick).with_seq(r.seq(), r.valve_open()).with_rtc(Some(r.rtc_s)))
        }
        (ram, _) => ram,
    }
}

/// Whether sequence number `a` is newer than `b` (31-bit wrapping order).
pub fn seq_newer(a: u32, b: u32) -> bool {
    let d = a.wrapping_sub(b) & !FLAG_VALVE_OPEN;
    d != 0 && d < (1 << 30)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_check_value() {
        // The standard CRC-32 check value of "123456789" is 0xCBF43926.
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn record_has_no_padding() {
        // 4 + 4 + 4 + 2 + 2 + 6*4 + 4 + 4 + 4 + 4 = 56 bytes of fields.
        assert_eq!(core::mem::size_of::<ThermalRecord>(), RECORD_BYTES);
    }
}
