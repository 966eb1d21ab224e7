//! Software in the loop: the firmware's frame handling ([`Link`]) and core
//! step run on the host, fed the same bytes as the firmware in QEMU.

use eha_guard::protocol::{GuardOutput, Link, Reply, Request};

use super::{PilError, Target};

/// The host twin of the firmware main loop: same `Link`, same core step.
pub struct SilTarget<F> {
    link: Link,
    core: F,
}

impl<F: FnMut(&Request) -> GuardOutput> SilTarget<F> {
    pub fn new(core: F) -> Self {
        Self { link: Link::new(), core }
    }

    pub fn link(&self) -> &Link {
        &self.link
    }
}

impl<F: FnMut(&Request) -> GuardOutput> Target for SilTarget<F> {
    fn exchange(&mut self, wire: &[u8], step: u64) -> Result<Reply, PilError> {
        let Self { link, core } = self;
        let mut got = None;
        link.push_bytes(wire, |r| (core(r), 0), |rep, _| got = Some(*rep));
        got.ok_or_else(|| PilError::Protocol { step, what: "SIL link produced no reply to a frame".into() })
    }
}
