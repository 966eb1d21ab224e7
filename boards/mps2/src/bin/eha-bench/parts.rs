//! The timed regions' call boundaries: each an `#[inline(never)]` function so
//! that the inlined work stays inside the timed window.

use eha_guard::model::{InputScales, Model, ModelInputN};
use eha_guard::validate::{self, Channels, LimitsN};
use eha_guard::product::mem_board::MemBoard;
use eha_guard::{Guard, Real, Sample};

/// Opaque call boundaries: keep the inlined model work inside the timed window
/// (volatile SysTick reads do not order ordinary computation).
#[inline(never)]
pub fn model_tick(m: &mut Model<Real>, u: &ModelInputN<Real>) -> bool {
    m.tick_n(u)
}

#[inline(never)]
pub fn model_update(m: &mut Model<Real>, lng_ticks: u32) {
    m.update(lng_ticks);
}

/// Validation alone, fast path: convert + combined range/rate check + inputs.
#[inline(never)]
pub fn validate_tick(
    s: &Sample,
    prev: &Channels<Real>,
    sc: &InputScales<Real>,
    lim: &LimitsN<Real>,
) -> (ModelInputN<Real>, bool) {
    let (v, ok) = validate::convert_check(s, prev, sc, lim);
    (validate::direct(&v, prev), ok)
}

/// Validation, classifying path (a failed sample): convert + per-channel
/// range/rate/non-finite classification + worst-case substitution.
#[inline(never)]
pub fn validate_classify(
    s: &Sample,
    prev: &Channels<Real>,
    sc: &InputScales<Real>,
    lim: &LimitsN<Real>,
) -> ModelInputN<Real> {
    let (v, nf) = validate::convert(s, sc);
    let c = validate::check(&v, nf, prev, eha_guard::ChannelSet::ALL, lim);
    validate::substitute(&v, c.bad, Some(v[4]), lim)
}

#[inline(never)]
pub fn guard_tick(g: &mut Guard, s: &Sample) -> eha_guard::Output {
    g.tick(s)
}

#[inline(never)]
pub fn app_tick(app: &mut eha_guard::product::App, b: &mut MemBoard) {
    app.tick(b, 0);
}

#[inline(never)]
pub fn part_deframe(d: &mut eha_guard::protocol::Deframer, wire: &[u8]) -> Option<eha_guard::protocol::Request> {
    let mut got = None;
    let mut rest = wire;
    while !rest.is_empty() {
        let (n, res) = d.feed(rest);
        if let Some(Ok(p)) = res {
            got = eha_guard::protocol::Request::from_payload(p).ok();
        }
        rest = rest.get(n..).unwrap_or(&[]);
    }
    got
}

#[inline(never)]
pub fn part_encode(r: &eha_guard::product::wire::TickReply) -> usize {
    core::hint::black_box(r.encode()).len()
}

#[inline(never)]
pub fn part_record(g: &Guard, w: &mut eha_guard::memory::slots::AbWriter) -> eha_guard::ThermalRecord {
    w.write(&g.snapshot_unsealed(), eha_guard::memory::slots::noinit::store)
}

#[inline(never)]
pub fn part_nv_due(last: Option<&eha_guard::ThermalRecord>, rec: &eha_guard::ThermalRecord) -> bool {
    eha_guard::memory::nv::NvPolicy::DEFAULT.due(last, rec)
}
