//! Controller commands and their acknowledgement: the arm-then-confirm
//! pairs that clear latched faults or refill the LNG account, the key that
//! binds a confirm to its arm and the rig, and the ack's outcome codes
//! (docs/firmware.md, "Commands: arm, then confirm").

/// A controller command.
///
/// Clear and refill cannot undo protection by accident: each is a pair,
/// **arm** then **confirm** within [`ARM_WINDOW_TICKS`] with the key
/// [`command_key`] of the nonce the arm's acknowledgement carries and the
/// parameter block's rig id; a confirmed clear or refill at most once per
/// [`COMMAND_INTERVAL_TICKS`]; every one traced. A refill is refused with the
/// valve open or the guard in alarm; a clear never restores trust in the
/// estimate before it can have recovered (docs/firmware.md, "Commands").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Cmd {
    /// Arm a clear of the latched faults; the ack carries the nonce.
    ClearArm,
    /// Confirm the armed clear (argument: the key). Done under the guard's
    /// clear rule (100 fully valid ticks in a row, no CONFIG).
    ClearConfirm,
    /// Arm a refill of the LNG budget (a new charge installed); the ack
    /// carries the nonce.
    RefillArm,
    /// Confirm the armed refill (argument: the key).
    RefillConfirm,
    /// Send a [`Status`](super::Status) reply.
    Status,
    /// Send the trace ring, oldest event first, as [`TraceReply`](super::TraceReply) frames.
    Trace,
    /// Test builds only (feature `fault-inject`): stop feeding the watchdog.
    InjectHang,
    /// Test builds only (feature `fault-inject`): panic inside the tick.
    InjectPanic,
}

impl Cmd {
    /// Wire code.
    pub fn code(self) -> u8 {
        match self {
            Cmd::ClearArm => 1,
            Cmd::RefillArm => 2,
            Cmd::Status => 3,
            Cmd::Trace => 4,
            Cmd::ClearConfirm => 5,
            Cmd::RefillConfirm => 6,
            Cmd::InjectHang => 0xE0,
            Cmd::InjectPanic => 0xE1,
        }
    }

    /// From a wire code.
    pub fn from_code(c: u8) -> Option<Cmd> {
        Some(match c {
            1 => Cmd::ClearArm,
            2 => Cmd::RefillArm,
            3 => Cmd::Status,
            4 => Cmd::Trace,
            5 => Cmd::ClearConfirm,
            6 => Cmd::RefillConfirm,
            0xE0 => Cmd::InjectHang,
            0xE1 => Cmd::InjectPanic,
            _ => return None,
        })
    }
}

/// Ticks a confirmation may follow its arm (100 = 1 s).
pub const ARM_WINDOW_TICKS: u32 = 100;
/// Least ticks between two confirmed clears, or two confirmed refills
/// (1000 = 10 s): a controller clearing in a loop cannot make a latch
/// self-resetting.
pub const COMMAND_INTERVAL_TICKS: u32 = 1000;

/// The key that confirms an armed command: CRC-32 of the parameter block's
/// rig id (16 bytes, zero-padded; all zero for the compiled-in default), the
/// arm's nonce (little-endian) and the confirming command's code. Line
/// noise, a stray frame or a controller bug does not produce it; a
/// controller that means the command computes it from the ack.
pub fn command_key(rig_id: &[u8; 16], nonce: u32, confirm: Cmd) -> u32 {
    let mut c = crate::memory::crc32_update(0xFFFF_FFFF, rig_id);
    c = crate::memory::crc32_update(c, &nonce.to_le_bytes());
    !crate::memory::crc32_update(c, &[confirm.code()])
}

/// A command frame: the command, a token the reply echoes, and its
/// argument (a confirmation's key; 0 otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Command {
    /// Echoed in the reply so the controller can match it.
    pub token: u16,
    /// What to do.
    pub cmd: Cmd,
    /// The key of a confirmation ([`command_key`]); 0 otherwise.
    pub arg: u32,
}

/// Outcome of a command, in its [`Ack`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AckResult {
    /// Done (an arm: armed, the nonce in [`Ack::value`]).
    Done = 0,
    /// Refused ([`Ack::value`] says why: [`Refusal`]).
    Refused = 1,
}

/// Why a command was refused (the [`Ack::value`] of a refusal).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Refusal {
    /// Not available in this build (fault injection).
    Unavailable = 1,
    /// No matching arm within [`ARM_WINDOW_TICKS`].
    NotArmed = 2,
    /// Wrong key.
    Key = 3,
    /// Within [`COMMAND_INTERVAL_TICKS`] of the last one.
    TooSoon = 4,
    /// The guard's rule: the clear rule not met (faults remain), or a
    /// refill with the valve open or in alarm.
    Rule = 5,
}

/// Acknowledgement of a command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ack {
    /// The command's token.
    pub token: u16,
    /// The command.
    pub cmd: Cmd,
    /// Its outcome.
    pub result: AckResult,
    /// An arm's nonce; a confirmed clear: the seconds UNTRUSTED still holds
    /// (0: trust restored, [`crate::guard::recovery_ticks`]); a refusal: why
    /// ([`Refusal`]); 0 otherwise.
    pub value: u32,
}
