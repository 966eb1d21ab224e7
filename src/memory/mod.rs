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

mod crc;

use crate::params::N_NODES;
pub use crc::{crc32, crc32_update};
use crc::crc32_words;

/// Record magic: "EHAT".
pub const MAGIC: u32 = 0x4548_4154;
/// Record layout version. 5: the fault word is 32 bits (60 bytes).
/// 4: the RTC time of the write ([`ThermalRecord::rtc_s`]).
/// 3: the former reserved word holds the sequence
/// number and the valve state ([`ThermalRecord::seq`], [`ThermalRecord::valve_open`]).
/// 2: the six temperatures are the reduced model's nodes (pump housing, case
/// oil, loop oil, main block, ball-valve block, actuator). An older record is
/// treated as corrupt (conservative).
pub const VERSION: u16 = 5;
/// [`ThermalRecord::rtc_s`] of a board without a real-time clock.
pub const RTC_NONE: u32 = u32::MAX;
/// Bit of [`ThermalRecord::seq_flags`] that holds the valve state (1 = open).
pub const FLAG_VALVE_OPEN: u32 = 1 << 31;
/// Plausible stored temperature range, degC (anything else is treated as corrupt).
pub const PLAUSIBLE_C: (f32, f32) = (-80.0, 250.0);

/// Size of a [`ThermalRecord`] and of its byte form, bytes.
pub const RECORD_BYTES: usize = 60;

/// Persistent thermal record, 60 bytes, no implicit padding.
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
    /// Reserved, 0.
    pub reserved: u16,
    /// Latched fault bits at save time (the 32-bit fault word).
    pub faults: u32,
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


impl ThermalRecord {
    /// An all-zero record (not valid: no magic).
    pub const EMPTY: ThermalRecord = ThermalRecord {
        lng_used_cj: 0,
        magic: 0,
        version: 0,
        reserved: 0,
        faults: 0,
        temps_c: [0.0; N_NODES],
        ambient_c: 0.0,
        tick: 0,
        seq_flags: 0,
        rtc_s: RTC_NONE,
        crc: 0,
    };

    /// CRC-32 of the record's bytes before `crc` (its fields in order,
    /// little-endian), a word at a time: one call, no per-field calls (the
    /// product loop seals a record at every model step).
    #[inline(never)]
    fn body_crc(&self) -> u32 {
        let [t0, t1, t2, t3, t4, t5] = self.temps_c.map(f32::to_bits);
        let words = [
            self.lng_used_cj,
            self.tick,
            self.magic,
            u32::from(self.version) | (u32::from(self.reserved) << 16),
            self.faults,
            t0,
            t1,
            t2,
            t3,
            t4,
            t5,
            self.ambient_c.to_bits(),
            self.seq_flags,
            self.rtc_s,
        ];
        !crc32_words(0xFFFF_FFFF, &words)
    }

    /// Builds a sealed record (magic, version, CRC filled in).
    pub fn new(
        temps_c: [f32; N_NODES],
        ambient_c: f32,
        lng_used_cj: u32,
        faults: u32,
        tick: u32,
    ) -> Self {
        let mut r = Self::unsealed(temps_c, ambient_c, lng_used_cj, faults, tick);
        r.crc = r.body_crc();
        r
    }

    /// [`ThermalRecord::new`] without its CRC (0): for a writer that seals it
    /// itself ([`ThermalRecord::with_seq`]), so the CRC is taken once.
    pub fn unsealed(
        temps_c: [f32; N_NODES],
        ambient_c: f32,
        lng_used_cj: u32,
        faults: u32,
        tick: u32,
    ) -> Self {
        ThermalRecord {
            lng_used_cj,
            magic: MAGIC,
            version: VERSION,
            reserved: 0,
            faults,
            temps_c,
            ambient_c,
            tick,
            seq_flags: 0,
            rtc_s: RTC_NONE,
            crc: 0,
        }
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
        words[3] = u32::from(self.version) | (u32::from(self.reserved) << 16);
        words[4] = self.faults;
        for (w, t) in words[5..5 + N_NODES].iter_mut().zip(self.temps_c.iter()) {
            *w = t.to_bits();
        }
        words[11] = self.ambient_c.to_bits();
        words[12] = self.seq_flags;
        words[13] = self.rtc_s;
        words[14] = self.crc;
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
        for (t, x) in temps_c.iter_mut().zip(w[5..5 + N_NODES].iter()) {
            *t = f32::from_bits(*x);
        }
        ThermalRecord {
            lng_used_cj: w[0],
            tick: w[1],
            magic: w[2],
            version: (w[3] & 0xFFFF) as u16,
            reserved: (w[3] >> 16) as u16,
            faults: w[4],
            temps_c,
            ambient_c: f32::from_bits(w[11]),
            seq_flags: w[12],
            rtc_s: w[13],
            crc: w[14],
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

/// Period of the last-alive stamp in the clock's backup register, s
/// ([`crate::product::Board::rtc_alive`]): the machine stopped at most this
/// long after the stamp.
pub const ALIVE_PERIOD_S: u32 = 1;

/// The last-alive word in the clock's backup register: the seconds `s`
/// shifted left by one, bit 0 set while the non-volatile saves are failing
/// (since the last good save: the record misses the machine's state since).
/// 31 bits of seconds: 68 years of the clock.
pub fn alive_word(s: u32, nv_failing: bool) -> u32 {
    (s << 1) | u32::from(nv_failing)
}

/// The seconds and the failing flag of a last-alive word (0: none stored).
pub fn alive_from_word(w: u32) -> Option<(u32, bool)> {
    (w != 0).then_some((w >> 1, w & 1 != 0))
}

/// The boot rule over both memories: the RAM records' rule
/// ([`slots::restore_from`]) unless RAM holds nothing (power-on), then the
/// non-volatile record (a power loss), else a cold start. A damaged RAM
/// record stays a conservative start even when flash holds an older valid
/// one, and so does a damaged or unreadable flash record
/// ([`nv::NvLoad::Damaged`]): the machine may be hot.
///
/// After a power loss every node is raised by the write policy's `rise_k`
/// (the most the estimate can have risen since that record was written, so
/// the state is never colder than at power-off) and the LNG used by its
/// `lng_rise_cj` (the most that can be unwritten: never under-counted).
/// The off-time is known only from the clock's last-alive stamp
/// (`alive_s`, battery-backed, [`ALIVE_PERIOD_S`]): then a record older
/// than the stamp by more than the policy's longest write interval is
/// stale (its saves failed while the machine ran on: its state is unknown)
/// and the start is conservative; otherwise the state is cooled by the
/// model's bound at rest ([`cooling::RestCooling`]) over `now - alive`.
/// So is a record the stamp says the saves were failing after
/// (`nv_failing`): the machine ran on unrecorded. Without the stamp, a clock
/// or a bound, the saved temperatures stand (power loss of unknown length:
/// conservative).
pub fn boot_restore(
    ram: Restore,
    nv: nv::NvLoad,
    policy: &nv::NvPolicy,
    cool: Option<&cooling::RestCooling>,
    now_rtc_s: Option<u32>,
    alive_s: Option<u32>,
    nv_failing: bool,
) -> Restore {
    let r = match (ram, nv) {
        (Restore::Cold, nv::NvLoad::Damaged) => return Restore::Corrupt,
        (Restore::Cold, nv::NvLoad::Valid(_)) if nv_failing => return Restore::Corrupt,
        (Restore::Cold, nv::NvLoad::Valid(r)) => r,
        (ram, _) => return ram,
    };
    let mut hot = r.temps_c;
    for t in hot.iter_mut() {
        *t += policy.rise_k;
    }
    let saved = (r.rtc_s != RTC_NONE).then_some(r.rtc_s);
    if let (Some(saved), Some(alive)) = (saved, alive_s) {
        let longest_s = policy.max_interval_ticks / 100 + ALIVE_PERIOD_S;
        if alive >= saved && alive - saved > longest_s {
            return Restore::Corrupt;
        }
    }
    let off_s = match (now_rtc_s, alive_s, saved) {
        (Some(now), Some(alive), Some(saved)) if alive >= saved && now >= alive => Some(now - alive).filter(|s| *s > ALIVE_PERIOD_S).map(|s| s - ALIVE_PERIOD_S),
        _ => None,
    };
    if let (Some(b), Some(off)) = (cool, off_s) {
        hot = b.cool(&hot, r.ambient_c, off);
    }
    let used = r.lng_used_cj.saturating_add(policy.lng_rise_cj);
    Restore::PowerLoss(ThermalRecord::new(hot, r.ambient_c, used, r.faults, r.tick).with_seq(r.seq(), r.valve_open()).with_rtc(saved))
}

/// Whether sequence number `a` is newer than `b` (31-bit wrapping order).
pub fn seq_newer(a: u32, b: u32) -> bool {
    let d = a.wrapping_sub(b) & !FLAG_VALVE_OPEN;
    d != 0 && d < (1 << 30)
}

#[cfg(test)]
mod tests;
