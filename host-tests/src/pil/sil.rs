//! Software in the loop: the firmware's frame handling ([`Link`]) and core
//! step run on the host, fed the same bytes as the firmware in QEMU.

use eha_guard::protocol::{GuardOutput, Link, Reply, Request};

use super::{PilError, Target};

/// The host twin of the firmware main loop: same `Link`, same core step.
pub struct SilTarget<F> {
    link: Link,
    core: F,
}

impl<F: FnMut(&Request, u16) -> GuardOutput> SilTarget<F> {
    /// A fresh link around the core step `core`.
    pub fn new(core: F) -> Self {
        Self { link: Link::new(), core }
    }

    /// The frame handler (its counters).
    pub fn link(&self) -> &Link {
        &self.link
    }
}

impl<F: FnMut(&Request, u16) -> GuardOutput> Target for SilTarget<F> {
    fn exchange(&mut self, wire: &[u8], tick: u64) -> Result<Reply, PilError> {
        let Self { link, core } = self;
        let mut got = None;
        link.push_bytes(wire, |r, gap| (core(r, gap), 0), |rep, _| got = Some(*rep));
        got.ok_or_else(|| PilError::Protocol { tick, what: "SIL link produced no reply to a frame".into() })
    }
}

/// One firmware tick on the host: the request and the sequence gap in,
/// the guard's outputs out.
pub type GuardCore = Box<dyn FnMut(&Request, u16) -> GuardOutput>;

/// The firmware's core for `build`, on the host: the same `GuardOf<N>` with
/// the same number type, configuration and boot rule (cold: QEMU starts
/// with zeroed RAM, which reads as an absent thermal record) and the same
/// [`eha_guard::protocol::tick_guard`].
pub fn sil_core(build: super::Build) -> GuardCore {
    use eha_guard::{GuardConfig, GuardOf, Restore};
    match build {
        super::Build::F32 => {
            let mut g = GuardOf::<f32>::new(&GuardConfig::DEFAULT, Restore::Cold);
            Box::new(move |r, gap| eha_guard::protocol::tick_guard(&mut g, r, gap))
        }
        super::Build::Fixed => {
            let mut g = GuardOf::<eha_guard::num::Fx>::new(&GuardConfig::DEFAULT, Restore::Cold);
            Box::new(move |r, gap| eha_guard::protocol::tick_guard(&mut g, r, gap))
        }
    }
}
