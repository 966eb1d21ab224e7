//! The controller's side of a command (a clear or a refill) in the fault
//! campaign: arm, read the nonce from the ack, confirm with the key.

use eha_guard::product::wire::{command_key, AckResult, Cmd, Command, FromGuard};

/// A controller that arms and confirms a command (a clear or a refill)
/// every `period` ticks from tick `from`, with the key of the default rig id.
pub(super) struct Commander {
    arm: Cmd,
    confirm: Cmd,
    next: u64,
    period: u64,
    nonce: Option<u32>,
    token: u16,
    /// Confirmations acknowledged as done.
    pub(super) done: u32,
}

impl Commander {
    /// Arms `arm` from tick `from`, again every `period` ticks.
    pub(super) fn new(arm: Cmd, confirm: Cmd, from: u64, period: u64) -> Self {
        Commander { arm, confirm, next: from, period, nonce: None, token: 0x4000, done: 0 }
    }

    /// This tick's command frame, if any.
    pub(super) fn frame(&mut self, k: u64) -> Option<Vec<u8>> {
        self.token = self.token.wrapping_add(1);
        if let Some(n) = self.nonce.take() {
            let arg = command_key(&[0; 16], n, self.confirm);
            return Some(Command { token: self.token, cmd: self.confirm, arg }.encode().as_slice().to_vec());
        }
        if k >= self.next {
            self.next = k + self.period;
            return Some(Command { token: self.token, cmd: self.arm, arg: 0 }.encode().as_slice().to_vec());
        }
        None
    }

    /// The acknowledgements of the tick.
    pub(super) fn read(&mut self, others: &[FromGuard]) {
        for f in others {
            if let FromGuard::Ack(a) = f {
                if a.cmd == self.arm && a.result == AckResult::Done {
                    self.nonce = Some(a.value);
                } else if a.cmd == self.confirm && a.result == AckResult::Done {
                    self.done += 1;
                }
            }
        }
    }
}
