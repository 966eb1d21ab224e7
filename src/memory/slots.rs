//! Two no-init RAM records (A/B) for warm and watchdog resets.
//!
//! Writes alternate between the slots, each with the next sequence number,
//! so a reset in the middle of a write corrupts at most the slot being
//! written; the other still holds the previous record. At boot the valid
//! record with the newest sequence number wins. The selection logic is plain
//! Rust and host-tested; only the two statics are target-only.

use super::{seq_newer, RecordStatus, Restore, ThermalRecord};

/// The boot rule for two stored records: the newest valid one restores
/// warm; if neither is valid but one carries the magic word (a damaged
/// record: the machine may be hot) the start is conservative; otherwise
/// (power-on RAM) cold.
pub fn restore_from(a: &ThermalRecord, b: &ThermalRecord) -> Restore {
    match (a.classify(), b.classify()) {
        (RecordStatus::Valid, RecordStatus::Valid) => {
            Restore::Warm(if seq_newer(b.seq(), a.seq()) { *b } else { *a })
        }
        (RecordStatus::Valid, _) => Restore::Warm(*a),
        (_, RecordStatus::Valid) => Restore::Warm(*b),
        (RecordStatus::Corrupt, _) | (_, RecordStatus::Corrupt) => Restore::Corrupt,
        (RecordStatus::Absent, RecordStatus::Absent) => Restore::Cold,
    }
}

/// Alternating writer: which slot is next and which sequence number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AbWriter {
    next_slot: usize,
    next_seq: u32,
}

impl AbWriter {
    /// The writer after boot: the next write goes to the slot that does not
    /// hold the newest valid record, with a sequence number after it.
    pub fn after_boot(a: &ThermalRecord, b: &ThermalRecord) -> Self {
        match restore_from(a, b) {
            Restore::Warm(r) => {
                let in_a = a.classify() == RecordStatus::Valid && a.seq() == r.seq() && a.crc == r.crc;
                AbWriter { next_slot: if in_a { 1 } else { 0 }, next_seq: r.seq().wrapping_add(1) }
            }
            _ => AbWriter { next_slot: 0, next_seq: 1 },
        }
    }

    /// Seal `rec` with the next sequence number (keeping its valve state) and
    /// hand it to `store(slot, record)`; then advance to the other slot.
    /// Returns the sealed record.
    pub fn write(&mut self, rec: &ThermalRecord, mut store: impl FnMut(usize, &ThermalRecord)) -> ThermalRecord {
        let sealed = rec.with_seq(self.next_seq, rec.valve_open());
        store(self.next_slot, &sealed);
        self.next_slot ^= 1;
        self.next_seq = self.next_seq.wrapping_add(1) & 0x7FFF_FFFF;
        sealed
    }
}

/// The two no-init RAM records (target only).
#[cfg(target_os = "none")]
pub mod noinit {
    use super::ThermalRecord;
    use core::mem::MaybeUninit;

    #[link_section = ".uninit.thermal_a"]
    static mut RECORD_A: MaybeUninit<ThermalRecord> = MaybeUninit::uninit();
    #[link_section = ".uninit.thermal_b"]
    static mut RECORD_B: MaybeUninit<ThermalRecord> = MaybeUninit::uninit();

    fn slot_ptr(slot: usize) -> *mut ThermalRecord {
        if slot == 0 {
            core::ptr::addr_of_mut!(RECORD_A).cast::<ThermalRecord>()
        } else {
            core::ptr::addr_of_mut!(RECORD_B).cast::<ThermalRecord>()
        }
    }

    /// Reads both records left in no-init RAM (whatever bits are there).
    pub fn load() -> (ThermalRecord, ThermalRecord) {
        // SAFETY: single-threaded access from the main loop; every bit pattern is a
        // valid `ThermalRecord` (integers and floats, no padding); volatile so the
        // compiler makes no assumption about memory it never initialised.
        unsafe { (core::ptr::read_volatile(slot_ptr(0)), core::ptr::read_volatile(slot_ptr(1))) }
    }

    /// Writes slot `slot` (0 = A, anything else = B).
    pub fn store(slot: usize, r: &ThermalRecord) {
        // SAFETY: as in `load`; the statics are only touched from the main loop.
        unsafe { core::ptr::write_volatile(slot_ptr(slot), *r) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(t: f32, seq: u32) -> ThermalRecord {
        ThermalRecord::new([t; crate::params::N_NODES], 20.0, 7, 0, 100).with_seq(seq, t > 40.0)
    }

    #[test]
    fn newest_valid_record_wins_and_a_torn_write_falls_back() {
        let (a, b) = (rec(30.0, 5), rec(31.0, 6));
        assert_eq!(restore_from(&a, &b), Restore::Warm(b));
        assert_eq!(restore_from(&b, &a), Restore::Warm(b));
        // The write of B was torn (one word half written): A restores.
        let mut torn = b;
        torn.temps_c[2] = f32::from_bits(torn.temps_c[2].to_bits() ^ 0x0001_0000);
        assert_eq!(restore_from(&a, &torn), Restore::Warm(a));
        // Both damaged: conservative; neither written: cold.
        let mut torn_a = a;
        torn_a.crc ^= 1;
        assert_eq!(restore_from(&torn_a, &torn), Restore::Corrupt);
        assert_eq!(restore_from(&ThermalRecord::EMPTY, &ThermalRecord::EMPTY), Restore::Cold);
        assert_eq!(restore_from(&ThermalRecord::EMPTY, &a), Restore::Warm(a));
    }

    #[test]
    fn sequence_order_wraps() {
        let (a, b) = (rec(30.0, 0x7FFF_FFFF), rec(31.0, 0));
        assert_eq!(restore_from(&a, &b), Restore::Warm(b), "0 follows 2^31 - 1");
    }

    #[test]
    fn writer_alternates_and_resumes_after_boot() {
        let mut slots = [ThermalRecord::EMPTY; 2];
        let mut w = AbWriter::after_boot(&slots[0], &slots[1]);
        for k in 0..5u32 {
            w.write(&rec(30.0 + k as f32, 0), |s, r| slots[s] = *r);
        }
        // Five writes: A has seq 1, 3, 5; B 2, 4. The newest is A's 5.
        assert_eq!((slots[0].seq(), slots[1].seq()), (5, 4));
        let Restore::Warm(r) = restore_from(&slots[0], &slots[1]) else { panic!("warm") };
        assert_eq!(r.temps_c[0], 34.0);
        // After a reset the next write goes to B (not over the newest) with seq 6.
        let mut w2 = AbWriter::after_boot(&slots[0], &slots[1]);
        w2.write(&rec(50.0, 0), |s, r| slots[s] = *r);
        assert_eq!((slots[1].seq(), slots[1].valve_open()), (6, true));
        assert_eq!(slots[0].seq(), 5, "the newest record before the reset is kept");
    }
}
