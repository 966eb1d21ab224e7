//! Thermal memory: the model state survives a warm or watchdog reset in a
//! no-init RAM section, guarded by a magic word and a CRC-32.
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
/// Record layout version. 2: the six temperatures are the reduced model's nodes
/// (pump housing, case oil, loop oil, main block, ball-valve block, actuator); a
/// version-1 record (the former identified network's nodes) is treated as corrupt.
pub const VERSION: u16 = 2;
/// Plausible stored temperature range, degC (anything else is treated as corrupt).
pub const PLAUSIBLE_C: (f32, f32) = (-80.0, 250.0);

/// Persistent thermal record, 52 bytes, no implicit padding.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct ThermalRecord {
    /// LNG heat-sink energy used, cJ (0.01 J).
    pub lng_used_cj: u32,
    /// Guard step counter at save time.
    pub step: u32,
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
    /// Reserved (zero).
    pub reserved: u32,
    /// CRC-32 (IEEE) of all preceding bytes, little endian field order.
    pub crc: u32,
}

/// Nibble table of the reflected CRC-32 (IEEE, polynomial 0xEDB88320).
/// Built at compile time (an out-of-range index would be a compile error).
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
        step: 0,
        reserved: 0,
        crc: 0,
    };

    fn body_crc(&self) -> u32 {
        let mut c = 0xFFFF_FFFF;
        c = crc32_update(c, &self.lng_used_cj.to_le_bytes());
        c = crc32_update(c, &self.step.to_le_bytes());
        c = crc32_update(c, &self.magic.to_le_bytes());
        c = crc32_update(c, &self.version.to_le_bytes());
        c = crc32_update(c, &self.faults.to_le_bytes());
        for t in self.temps_c.iter() {
            c = crc32_update(c, &t.to_bits().to_le_bytes());
        }
        c = crc32_update(c, &self.ambient_c.to_bits().to_le_bytes());
        c = crc32_update(c, &self.reserved.to_le_bytes());
        !c
    }

    /// Builds a sealed record (magic, version, CRC filled in).
    pub fn new(
        temps_c: [f32; N_NODES],
        ambient_c: f32,
        lng_used_cj: u32,
        faults: u16,
        step: u32,
    ) -> Self {
        let mut r = ThermalRecord {
            lng_used_cj,
            magic: MAGIC,
            version: VERSION,
            faults,
            temps_c,
            ambient_c,
            step,
            reserved: 0,
            crc: 0,
        };
        r.crc = r.body_crc();
        r
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
        if self.version == VERSION && self.reserved == 0 && self.crc == self.body_crc() && plausible
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

/// The no-init RAM copy (target only).
#[cfg(target_os = "none")]
pub mod noinit {
    use super::ThermalRecord;
    use core::mem::MaybeUninit;

    #[link_section = ".uninit.thermal"]
    static mut RECORD: MaybeUninit<ThermalRecord> = MaybeUninit::uninit();

    /// Reads the record left in no-init RAM (whatever bits are there).
    pub fn load() -> ThermalRecord {
        // SAFETY: single-threaded access from the main loop; every bit pattern is a
        // valid `ThermalRecord` (integers and floats, no padding); volatile so the
        // compiler makes no assumption about memory it never initialised.
        unsafe { core::ptr::read_volatile(core::ptr::addr_of!(RECORD).cast::<ThermalRecord>()) }
    }

    /// Writes the record to no-init RAM.
    pub fn store(r: &ThermalRecord) {
        // SAFETY: as in `load`; the static is only touched from the main loop.
        unsafe {
            core::ptr::write_volatile(core::ptr::addr_of_mut!(RECORD).cast::<ThermalRecord>(), *r)
        }
    }
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
        // 4 + 4 + 4 + 2 + 2 + 6*4 + 4 + 4 + 4 = 52 bytes of fields.
        assert_eq!(core::mem::size_of::<ThermalRecord>(), 52);
    }
}
