//! How a run's guard output is read: protecting or not, the detection
//! bits, and the names of faults and actions in the campaign's tables.

use eha_guard::{faults as fbits, Faults, Output};

use super::inject::Channel;

/// The guard is protecting: a latched fault with the valve commanded open,
/// or the estimate untrusted (alarm and derate held).
pub(super) fn protected(o: &Output) -> bool {
    (o.faults.intersects(fbits::LATCHED) && o.valve_open) || o.faults.contains(fbits::UNTRUSTED)
}

/// The bits whose appearance counts as a detection.
pub(super) const DETECT_MASK: Faults = Faults::from_bits(
    fbits::LATCHED.bits() | fbits::UNTRUSTED.bits() | fbits::NV_FAILED.bits() | fbits::NO_VALVE_FEEDBACK.bits() | fbits::LNG_LOW.bits(),
);

/// The named members of a fault set, `+`-separated (channels as
/// `ch:<name>`).
pub fn bit_names(f: Faults) -> String {
    let dbg = format!("{f:?}");
    let inner = dbg.trim_start_matches("Faults(").trim_end_matches(')');
    let mut out: Vec<String> = inner.split(" | ").filter(|p| !p.starts_with("channels")).map(str::to_string).collect();
    for c in Channel::ALL {
        let ch = eha_guard::ChannelSet::channel(Channel::ALL.iter().position(|x| *x == c).unwrap_or(0));
        if f.channel_set().contains(ch) {
            out.push(format!("ch:{}", c.name()));
        }
    }
    out.join(" + ")
}

/// The actions an output takes, comma-separated (`none` without any).
pub(super) fn action(o: &Output) -> String {
    let mut a = Vec::new();
    if o.valve_open {
        a.push("valve open");
    }
    if o.alarm {
        a.push("alarm");
    }
    if o.derate {
        a.push("derate");
    }
    if a.is_empty() {
        "none".into()
    } else {
        a.join(", ")
    }
}
