//! A memo of the calibration's model runs: a log's residuals at a rig
//! already replayed are taken from it instead of replaying the log again.
//! Every multiplier vector is rounded to the θ lattice before the model
//! runs ([`super::residuals::THETA_LATTICE_LN`]) and the replay is
//! deterministic, so a repeated (rig, log) pair gives the bit-identical
//! residuals: the memo changes no number, only the time. Repeats are
//! frequent: the polish evaluates its start twice, every Gauss–Newton
//! Jacobian's base point is the accepted point of the step before, and the
//! final identifiability Jacobian repeats the polish's last one when its
//! last step did not move (docs/commissioning-foreign.md, "Time").

use super::log::CalLog;
use crate::rig::Rig;
use std::collections::HashMap;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Entries kept at most; the memo is emptied when it is full (a log's
/// residuals are a few kB: ≤ ~25 MB). Repeats come within a fit.
const CAPACITY: usize = 4096;

/// (rig, log) key: two independent 64-bit hashes of their whole content.
type Key = (u64, u64);

static MEMO: Mutex<Option<HashMap<Key, Vec<f64>>>> = Mutex::new(None);
static HITS: AtomicUsize = AtomicUsize::new(0);

/// Model runs answered from the memo in this process so far (a
/// measurement counter; the calibrations' `model_runs` count every
/// evaluation, answered or run, as before the memo).
pub fn hits() -> usize {
    HITS.load(Ordering::Relaxed)
}

/// Writes `f64`s to a hasher by their bits.
fn bits(h: &mut impl Hasher, v: &[f64]) {
    v.len().hash(h);
    for x in v {
        x.to_bits().hash(h);
    }
}

/// Streams `Debug` text into a hasher (the rig: every field, floats in
/// their shortest round-trip form, so two rigs hash alike only when equal).
struct HashWrite<'a, H: Hasher>(&'a mut H);

impl<H: Hasher> std::fmt::Write for HashWrite<'_, H> {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.write(s.as_bytes());
        Ok(())
    }
}

fn hash_into(h: &mut impl Hasher, rig: &Rig, log: &CalLog) {
    use std::fmt::Write;
    let _ = write!(HashWrite(h), "{rig:?}");
    log.hash_content(h);
}

/// The key of `log` replayed on `rig`.
fn key(rig: &Rig, log: &CalLog) -> Key {
    let mut a = DefaultHasher::new();
    hash_into(&mut a, rig, log);
    let mut b = DefaultHasher::new();
    0x5eed_u64.hash(&mut b);
    hash_into(&mut b, rig, log);
    (a.finish(), b.finish())
}

/// `log`'s residuals on `rig` (simulated − measured at its fit points, K,
/// [`CalLog::residuals`]), from the memo or from `run`.
pub(crate) fn residuals(rig: &Rig, log: &CalLog, run: impl FnOnce() -> Option<Vec<f64>>) -> Option<Vec<f64>> {
    let k = key(rig, log);
    if let Some(r) = MEMO.lock().ok().and_then(|m| m.as_ref().and_then(|m| m.get(&k).cloned())) {
        HITS.fetch_add(1, Ordering::Relaxed);
        return Some(r);
    }
    let r = run()?;
    if let Ok(mut m) = MEMO.lock() {
        let m = m.get_or_insert_with(HashMap::new);
        if m.len() >= CAPACITY {
            m.clear();
        }
        m.insert(k, r.clone());
    }
    Some(r)
}

impl CalLog {
    /// Feeds everything the log's replay and residuals depend on to `h`:
    /// name, measured rows, channels, fit points, replay inputs, output
    /// options, tolerance.
    pub(crate) fn hash_content(&self, h: &mut impl Hasher) {
        self.name.hash(h);
        bits(h, &self.run.time_s);
        for (ch, v) in &self.run.channels {
            ch.hash(h);
            v.len().hash(h);
            for x in v {
                x.map(f64::to_bits).hash(h);
            }
        }
        self.channels.hash(h);
        self.points.hash(h);
        self.hash_replay(h);
        self.rtol.to_bits().hash(h);
        self.fit_from_s.to_bits().hash(h);
    }
}
