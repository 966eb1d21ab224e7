//! Non-volatile thermal record: survives a power loss.
//!
//! The record is one item of a `sequential-storage` map (key
//! [`RECORD_KEY`]) in a dedicated flash range: every write appends, pages are
//! used cyclically (wear levelling), item headers and data are CRC-protected
//! and a write cut by a power loss leaves the previous item readable. The
//! crate is async; flash drivers here are blocking, so [`Blocking`] adapts a
//! blocking `embedded-storage` `NorFlash` and [`block_on`] runs the future
//! to completion (it never waits: every poll makes progress).
//!
//! Write policy ([`NvPolicy`]): a write when a node's estimate has risen by
//! [`NvPolicy::rise_k`] since the last written record (the restore after a
//! power loss adds `rise_k` to every node, so it is never colder than the
//! state at power-off: `super::boot_restore`), when the latched faults
//! change, when the LNG used has grown
//! by [`NvPolicy::lng_rise_cj`] (so the budget never forgets more than that
//! across a power loss), and at the latest every
//! [`NvPolicy::max_interval_ticks`]. Cooling alone needs no write: a restored
//! record that is warmer than the machine is on the safe side. The flash-wear
//! budget for 10 years is worked out in docs/firmware.md from the write rate
//! that `host-tests/tests/firmware/nv_wear.rs` measures on the paper's missions.

use core::future::Future;
use core::ops::Range;
use core::pin::pin;
use core::task::{Context, Poll, Waker};

use embedded_storage::nor_flash as blocking;
use embedded_storage_async::nor_flash as nf;
use sequential_storage::cache::{Cache, Uncached};
use sequential_storage::map::{MapConfig, MapStorage, SerializationError, Value};

use super::{RecordStatus, ThermalRecord};

/// Map key of the thermal record.
pub const RECORD_KEY: u8 = 1;
/// Serialized record size, bytes.
pub use super::RECORD_BYTES;
/// Scratch buffer: key + record, rounded up to the largest flash word (32 B).
const BUF_BYTES: usize = 96;

/// Run a future that never waits (blocking flash underneath) to completion.
pub fn block_on<F: Future>(f: F) -> F::Output {
    let mut f = pin!(f);
    let mut cx = Context::from_waker(Waker::noop());
    loop {
        if let Poll::Ready(v) = f.as_mut().poll(&mut cx) {
            return v;
        }
    }
}

/// A blocking `embedded-storage` NOR flash seen through the async traits
/// `sequential-storage` takes.
#[derive(Debug)]
pub struct Blocking<F>(pub F);

impl<F: blocking::ErrorType> nf::ErrorType for Blocking<F> {
    type Error = F::Error;
}

impl<F: blocking::ReadNorFlash> nf::ReadNorFlash for Blocking<F> {
    const READ_SIZE: usize = F::READ_SIZE;
    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.0.read(offset, bytes)
    }
    fn capacity(&self) -> usize {
        self.0.capacity()
    }
}

impl<F: blocking::NorFlash> nf::NorFlash for Blocking<F> {
    const WRITE_SIZE: usize = F::WRITE_SIZE;
    const ERASE_SIZE: usize = F::ERASE_SIZE;
    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.0.erase(from, to)
    }
    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        self.0.write(offset, bytes)
    }
}

/// The record as a map value: its [`RECORD_BYTES`] bytes
/// ([`ThermalRecord::to_le_bytes`]).
impl<'a> Value<'a> for ThermalRecord {
    fn serialize_into(&self, buffer: &mut [u8]) -> Result<usize, SerializationError> {
        let out = buffer.get_mut(..RECORD_BYTES).ok_or(SerializationError::BufferTooSmall)?;
        out.copy_from_slice(&self.to_le_bytes());
        Ok(RECORD_BYTES)
    }

    fn deserialize_from(buffer: &'a [u8]) -> Result<(Self, usize), SerializationError> {
        let b = buffer.get(..RECORD_BYTES).ok_or(SerializationError::InvalidFormat)?;
        let mut a = [0u8; RECORD_BYTES];
        a.copy_from_slice(b);
        Ok((ThermalRecord::from_le_bytes(&a), RECORD_BYTES))
    }
}

/// What the non-volatile store holds at boot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NvLoad {
    /// No record (erased store, or a board without one): nothing to restore.
    Empty,
    /// The newest record, checked.
    Valid(ThermalRecord),
    /// A record was there but could not be read or failed its check.
    Damaged,
}

impl NvLoad {
    /// The valid record, if any.
    pub fn valid(&self) -> Option<ThermalRecord> {
        match self {
            NvLoad::Valid(r) => Some(*r),
            _ => None,
        }
    }
}

/// Errors of the non-volatile store.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NvError {
    /// The flash range is not a whole number (≥ 2) of erase pages.
    Range,
    /// The flash driver or the storage layer failed.
    Storage,
}

/// The record store in a flash range.
pub struct NvStore<F: nf::NorFlash> {
    map: MapStorage<u8, F, Cache<Uncached, Uncached, Uncached, u8>>,
    buf: [u8; BUF_BYTES],
}

impl<F: nf::NorFlash> NvStore<F> {
    /// A store over `range` of `flash` (byte offsets; whole erase pages, at
    /// least two).
    pub fn new(flash: F, range: Range<u32>) -> Result<Self, NvError> {
        let cfg = MapConfig::try_new(range).map_err(|_| NvError::Range)?;
        Ok(NvStore { map: MapStorage::new(flash, cfg, Cache::new_uncached()), buf: [0; BUF_BYTES] })
    }

    /// The newest stored record: valid (magic, version, CRC, plausible
    /// temperatures), none, or damaged (a read error, or a record that fails
    /// its check: the machine may be hot, so the boot is conservative).
    pub fn load(&mut self) -> NvLoad {
        match block_on(self.map.fetch_item::<ThermalRecord>(&mut self.buf, &RECORD_KEY)) {
            Ok(None) => NvLoad::Empty,
            Ok(Some(r)) if r.classify() == RecordStatus::Valid => NvLoad::Valid(r),
            Ok(Some(_)) | Err(_) => NvLoad::Damaged,
        }
    }

    /// Append `rec` (the newest value of the record).
    pub fn save(&mut self, rec: &ThermalRecord) -> Result<(), NvError> {
        block_on(self.map.store_item(&mut self.buf, &RECORD_KEY, rec)).map_err(|_| NvError::Storage)
    }

    /// The flash driver back (tests, power-loss simulation).
    pub fn into_flash(self) -> F {
        self.map.destroy().0
    }
}

/// When the non-volatile record is rewritten (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NvPolicy {
    /// A node's estimate this much above its last written value forces a write, K.
    pub rise_k: f32,
    /// LNG used this much above the last written value forces a write, cJ.
    pub lng_rise_cj: u32,
    /// A write at least this often, guard ticks (10 ms).
    pub max_interval_ticks: u32,
}

impl NvPolicy {
    /// 2 K, 110 kJ of LNG (5 % of the 5 L charge), 30 minutes. The valve
    /// state rides along in every record but triggers no write: after a
    /// power loss the guard decides it anew from the restored temperatures.
    pub const DEFAULT: NvPolicy = NvPolicy { rise_k: 2.0, lng_rise_cj: 11_000_000, max_interval_ticks: 180_000 };

    /// Whether `now` (the guard's snapshot, valve state in it) must be
    /// written given the `last` record written (None: nothing yet).
    pub fn due(&self, last: Option<&ThermalRecord>, now: &ThermalRecord) -> bool {
        let Some(last) = last else { return true };
        // An unordered (NaN) estimate counts as risen.
        let risen = now.temps_c.iter().zip(last.temps_c.iter()).any(|(n, l)| !n.partial_cmp(&(*l + self.rise_k)).is_some_and(|o| o.is_le()));
        risen
            || now.faults != last.faults
            || now.lng_used_cj.saturating_sub(last.lng_used_cj) >= self.lng_rise_cj
            || now.tick.wrapping_sub(last.tick) >= self.max_interval_ticks
    }
}

/// A RAM-backed NOR flash for host simulation and tests: 4-byte words,
/// 1 KiB erase pages, bits only cleared by writes (like real NOR), with an
/// erase counter per page for wear figures.
#[derive(Clone, Debug)]
pub struct RamFlash<const BYTES: usize> {
    mem: [u8; BYTES],
    erases: [u32; 64],
    /// Every read fails (a dead flash or bus: fault injection).
    pub fail_reads: bool,
    /// Every write and erase fails (a worn or locked flash: fault injection).
    pub fail_writes: bool,
}

/// Erase page of [`RamFlash`], bytes.
pub const RAM_FLASH_PAGE: usize = 1024;

impl<const BYTES: usize> RamFlash<BYTES> {
    /// An erased flash (all ones).
    pub fn new() -> Self {
        RamFlash { mem: [0xFF; BYTES], erases: [0; 64], fail_reads: false, fail_writes: false }
    }

    /// Erase count of each page (the first `BYTES / 1024`).
    pub fn erase_counts(&self) -> &[u32] {
        self.erases.get(..BYTES / RAM_FLASH_PAGE).unwrap_or(&[])
    }
}

impl<const BYTES: usize> Default for RamFlash<BYTES> {
    fn default() -> Self {
        Self::new()
    }
}

/// Out-of-range or misaligned access of [`RamFlash`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RamFlashError;

impl blocking::NorFlashError for RamFlashError {
    fn kind(&self) -> blocking::NorFlashErrorKind {
        blocking::NorFlashErrorKind::OutOfBounds
    }
}

impl<const BYTES: usize> blocking::ErrorType for RamFlash<BYTES> {
    type Error = RamFlashError;
}

impl<const BYTES: usize> blocking::ReadNorFlash for RamFlash<BYTES> {
    const READ_SIZE: usize = 1;
    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), RamFlashError> {
        if self.fail_reads {
            return Err(RamFlashError);
        }
        let o = offset as usize;
        let src = self.mem.get(o..o + bytes.len()).ok_or(RamFlashError)?;
        bytes.copy_from_slice(src);
        Ok(())
    }
    fn capacity(&self) -> usize {
        BYTES
    }
}

impl<const BYTES: usize> blocking::NorFlash for RamFlash<BYTES> {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = RAM_FLASH_PAGE;
    fn erase(&mut self, from: u32, to: u32) -> Result<(), RamFlashError> {
        if self.fail_writes {
            return Err(RamFlashError);
        }
        let (f, t) = (from as usize, to as usize);
        if !f.is_multiple_of(RAM_FLASH_PAGE) || !t.is_multiple_of(RAM_FLASH_PAGE) || t > BYTES || f > t {
            return Err(RamFlashError);
        }
        self.mem.get_mut(f..t).ok_or(RamFlashError)?.fill(0xFF);
        for p in f / RAM_FLASH_PAGE..t / RAM_FLASH_PAGE {
            if let Some(c) = self.erases.get_mut(p) {
                *c += 1;
            }
        }
        Ok(())
    }
    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), RamFlashError> {
        if self.fail_writes {
            return Err(RamFlashError);
        }
        let o = offset as usize;
        if !o.is_multiple_of(4) || !bytes.len().is_multiple_of(4) {
            return Err(RamFlashError);
        }
        let dst = self.mem.get_mut(o..o + bytes.len()).ok_or(RamFlashError)?;
        for (d, s) in dst.iter_mut().zip(bytes) {
            *d &= *s; // NOR: a write only clears bits
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type Flash = Blocking<RamFlash<8192>>;

    fn rec(t: f32, tick: u32) -> ThermalRecord {
        ThermalRecord::new([t; crate::params::N_NODES], 20.0, 1234, 0, tick).with_seq(tick, t > 40.0)
    }

    #[test]
    fn stores_and_restores_the_newest_record_across_pages() {
        let mut nv: NvStore<Flash> = NvStore::new(Blocking(RamFlash::new()), 0..8192).expect("range");
        assert_eq!(nv.load(), NvLoad::Empty, "an erased flash holds no record");
        for k in 0..500u32 {
            nv.save(&rec(20.0 + k as f32 * 0.05, k)).expect("save");
        }
        let r = nv.load().valid().expect("record");
        assert_eq!((r.tick, r.temps_c[0], r.valve_open()), (499, 20.0 + 499.0 * 0.05, true));
        // A power loss: a new store over the same flash reads the same record.
        let flash = nv.into_flash();
        let erases: u32 = flash.0.erase_counts().iter().sum();
        assert!(erases > 0, "500 writes of 64 B must have cycled the 8 pages");
        let mut nv2: NvStore<Flash> = NvStore::new(flash, 0..8192).expect("range");
        assert_eq!(nv2.load(), NvLoad::Valid(r));
    }

    #[test]
    fn rejects_a_range_that_is_not_whole_pages() {
        assert!(NvStore::<Flash>::new(Blocking(RamFlash::new()), 0..1500).is_err());
        assert!(NvStore::<Flash>::new(Blocking(RamFlash::new()), 0..1024).is_err(), "one page is too few");
    }

    #[test]
    fn policy_writes_on_rise_valve_faults_lng_and_interval_only() {
        let p = NvPolicy::DEFAULT;
        let last = rec(30.0, 0);
        assert!(p.due(None, &last));
        assert!(!p.due(Some(&last), &rec(31.9, 100)), "1.9 K rise: no write");
        assert!(p.due(Some(&last), &rec(32.1, 100)), "2.1 K rise: write");
        assert!(!p.due(Some(&last), &rec(10.0, 100)), "cooling alone: no write (restoring warmer is safe)");
        assert!(!p.due(Some(&last), &rec(30.0, 100).with_seq(1, true)), "a valve change alone: no write");
        let mut faulted = rec(30.0, 100);
        faulted.faults = 1;
        assert!(p.due(Some(&last), &faulted), "faults change");
        assert!(p.due(Some(&last), &rec(30.0, 180_000)), "30 minutes");
        let mut more_lng = rec(30.0, 100);
        more_lng.lng_used_cj += p.lng_rise_cj;
        assert!(p.due(Some(&last), &more_lng), "LNG used grew by 20 kJ");
        let mut nan = rec(30.0, 100);
        nan.temps_c[1] = f32::NAN;
        assert!(p.due(Some(&last), &nan), "an unordered estimate forces a write");
    }
}
