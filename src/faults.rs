//! The fault word as a typed set ([`Faults`]) and its named members
//! (`faults::RANGE`, …), and the set of input channels ([`ChannelSet`]).
//! Bits 0-6 and 14 latch until the clear rule
//! ([`crate::GuardOf::clear_faults`]); bits 7 and 15 are live status; bits
//! 8-13 name the latched bad input channels (a [`ChannelSet`] shifted by
//! [`CH_SHIFT`]); bits 16.. are the status bits added with the safety case
//! (non-volatile save failed, cooling not confirmed). The same 32 bits go
//! on the wire ([`Faults::bits`], `crate::product::wire`) and into the
//! thermal record.

use core::ops::{BitAnd, BitAndAssign, BitOr, BitOrAssign, Not};

/// A set of the six input channels of a [`crate::Sample`], bit `i` for
/// channel `i` in the sample's order (current, port A, port B, speed,
/// position, ambient): the channels a check found bad, the channels whose
/// previous value is valid, the latched bad channels.
#[derive(Clone, Copy, Default, PartialEq, Eq)]
#[repr(transparent)]
pub struct ChannelSet(u8);

impl ChannelSet {
    /// No channel.
    pub const NONE: ChannelSet = ChannelSet(0);
    /// Motor current.
    pub const CURRENT: ChannelSet = ChannelSet(1 << 0);
    /// Port A pressure.
    pub const P_A: ChannelSet = ChannelSet(1 << 1);
    /// Port B pressure.
    pub const P_B: ChannelSet = ChannelSet(1 << 2);
    /// Motor speed.
    pub const SPEED: ChannelSet = ChannelSet(1 << 3);
    /// Piston position.
    pub const POSITION: ChannelSet = ChannelSet(1 << 4);
    /// Ambient temperature.
    pub const AMBIENT: ChannelSet = ChannelSet(1 << 5);
    /// All six channels.
    pub const ALL: ChannelSet = ChannelSet(0x3F);

    /// The set of a channel mask (bits above the six channels dropped).
    #[inline(always)]
    pub const fn from_bits(bits: u8) -> ChannelSet {
        ChannelSet(bits & 0x3F)
    }

    /// The mask (bit `i` = channel `i`).
    #[inline(always)]
    pub const fn bits(self) -> u8 {
        self.0
    }

    /// Channel `i` alone (0 current .. 5 ambient; none for `i` ≥ 6).
    #[inline(always)]
    pub const fn channel(i: usize) -> ChannelSet {
        if i < 6 {
            ChannelSet(1 << i)
        } else {
            ChannelSet::NONE
        }
    }

    /// The channels of both sets (`|` in a `const`).
    #[inline(always)]
    pub const fn union(self, other: ChannelSet) -> ChannelSet {
        ChannelSet(self.0 | other.0)
    }

    /// No channel in the set.
    #[inline(always)]
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Every channel of `other` is in the set.
    #[inline(always)]
    pub const fn contains(self, other: ChannelSet) -> bool {
        self.0 & other.0 == other.0
    }

    /// Some channel of `other` is in the set.
    #[inline(always)]
    pub const fn intersects(self, other: ChannelSet) -> bool {
        self.0 & other.0 != 0
    }
}

impl BitOr for ChannelSet {
    type Output = ChannelSet;
    #[inline(always)]
    fn bitor(self, o: ChannelSet) -> ChannelSet {
        ChannelSet(self.0 | o.0)
    }
}

impl BitOrAssign for ChannelSet {
    #[inline(always)]
    fn bitor_assign(&mut self, o: ChannelSet) {
        self.0 |= o.0;
    }
}

impl BitAnd for ChannelSet {
    type Output = ChannelSet;
    #[inline(always)]
    fn bitand(self, o: ChannelSet) -> ChannelSet {
        ChannelSet(self.0 & o.0)
    }
}

/// The other channels (the complement within the six).
impl Not for ChannelSet {
    type Output = ChannelSet;
    #[inline(always)]
    fn not(self) -> ChannelSet {
        ChannelSet(!self.0 & 0x3F)
    }
}

impl core::fmt::Debug for ChannelSet {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "ChannelSet({:#08b})", self.0)
    }
}

/// In the defmt log: the mask in binary.
#[cfg(feature = "defmt")]
impl defmt::Format for ChannelSet {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "{=u8:#08b}", self.0)
    }
}

/// A set of guard faults (the fault word: 32 bits on the wire and in the
/// thermal record).
#[derive(Clone, Copy, Default, PartialEq, Eq)]
pub struct Faults(u32);

/// In the defmt log: the word in hex, as on the wire.
#[cfg(feature = "defmt")]
impl defmt::Format for Faults {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "{=u32:#010x}", self.0)
    }
}

impl Faults {
    /// No fault.
    pub const NONE: Faults = Faults(0);

    /// The word's bits (wire and record form).
    pub const fn bits(self) -> u32 {
        self.0
    }

    /// The set of a fault word (every bit has a meaning; none is dropped).
    pub const fn from_bits(bits: u32) -> Faults {
        Faults(bits)
    }

    /// The latched bad channels `ch` as fault bits.
    #[inline(always)]
    pub const fn channels(ch: ChannelSet) -> Faults {
        Faults((ch.0 as u32) << CH_SHIFT)
    }

    /// The bad channels in this set.
    #[inline(always)]
    pub const fn channel_set(self) -> ChannelSet {
        ChannelSet(((self.0 >> CH_SHIFT) & 0x3F) as u8)
    }

    /// No fault in the set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Every member of `other` is in the set.
    pub const fn contains(self, other: Faults) -> bool {
        self.0 & other.0 == other.0
    }

    /// Some member of `other` is in the set.
    pub const fn intersects(self, other: Faults) -> bool {
        self.0 & other.0 != 0
    }

    /// `other` if `on`, else no fault.
    pub const fn when(on: bool, other: Faults) -> Faults {
        if on {
            other
        } else {
            Faults::NONE
        }
    }
}

impl BitOr for Faults {
    type Output = Faults;
    fn bitor(self, o: Faults) -> Faults {
        Faults(self.0 | o.0)
    }
}

impl BitOrAssign for Faults {
    fn bitor_assign(&mut self, o: Faults) {
        self.0 |= o.0;
    }
}

impl BitAnd for Faults {
    type Output = Faults;
    fn bitand(self, o: Faults) -> Faults {
        Faults(self.0 & o.0)
    }
}

impl BitAndAssign for Faults {
    fn bitand_assign(&mut self, o: Faults) {
        self.0 &= o.0;
    }
}

impl Not for Faults {
    type Output = Faults;
    fn not(self) -> Faults {
        Faults(!self.0)
    }
}

impl core::fmt::LowerHex for Faults {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        core::fmt::LowerHex::fmt(&self.0, f)
    }
}

/// Names of the single-bit members, for `Debug`.
const NAMES: [(Faults, &str); 14] = [
    (RANGE, "RANGE"),
    (RATE, "RATE"),
    (NON_FINITE, "NON_FINITE"),
    (STALE, "STALE"),
    (MEMORY_CORRUPT, "MEMORY_CORRUPT"),
    (CONFIG, "CONFIG"),
    (ACTUATOR, "ACTUATOR"),
    (LNG_LOW, "LNG_LOW"),
    (SENSOR_DISAGREE, "SENSOR_DISAGREE"),
    (UNTRUSTED, "UNTRUSTED"),
    (NV_FAILED, "NV_FAILED"),
    (LNG_UNCONFIRMED, "LNG_UNCONFIRMED"),
    (NO_VALVE_FEEDBACK, "NO_VALVE_FEEDBACK"),
    (RECOVERING, "RECOVERING"),
];

impl core::fmt::Debug for Faults {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "Faults(")?;
        let mut first = true;
        for (bit, name) in NAMES.iter() {
            if self.contains(*bit) {
                write!(f, "{}{name}", if first { "" } else { " | " })?;
                first = false;
            }
        }
        if !self.channel_set().is_empty() {
            write!(f, "{}channels {:#08b}", if first { "" } else { " | " }, self.channel_set().bits())?;
            first = false;
        }
        if first {
            write!(f, "none")?;
        }
        write!(f, ")")
    }
}

/// An input was outside its plausible range.
pub const RANGE: Faults = Faults(1 << 0);
/// An input changed faster than its rate limit.
pub const RATE: Faults = Faults(1 << 1);
/// An input was NaN or infinite.
pub const NON_FINITE: Faults = Faults(1 << 2);
/// No new sample for `stale_ticks` consecutive ticks.
pub const STALE: Faults = Faults(1 << 3);
/// The thermal-memory record was corrupt at boot.
pub const MEMORY_CORRUPT: Faults = Faults(1 << 4);
/// The parameters could not be built into a model (model disabled, fail-safe).
/// Not clearable at run time: needs valid parameters and a restart.
pub const CONFIG: Faults = Faults(1 << 5);
/// The valve output pin reported an error, or its position feedback
/// disagreed with the command (set by the board layer / the guard).
pub const ACTUATOR: Faults = Faults(1 << 6);
/// LNG remaining below the low threshold (live status, not latched).
pub const LNG_LOW: Faults = Faults(1 << 7);
/// The motor current and the port pressures / speed have disagreed about the
/// shaft's loss for `crosscheck.persist_windows` windows in a row (analytic
/// redundancy, [`crate::crosscheck`]). Latched: valve open, alarm and derate
/// (UNTRUSTED), the model heats with the larger of the two losses.
pub const SENSOR_DISAGREE: Faults = Faults(1 << 14);
/// Shift of the latched bad-channel mask inside the fault word.
pub const CH_SHIFT: u32 = 8;
/// The estimate is not trusted (corrupt thermal record at boot, or no sample by
/// the start-up timeout): alarm and derate are held until a successful
/// [`super::GuardOf::clear_faults`]. Status, not a latched fault; kept in the
/// thermal record so a warm reset does not drop it.
pub const UNTRUSTED: Faults = Faults(1 << 15);
/// A non-volatile save of the thermal record failed: after a power loss the
/// guard could restore a state older than its write policy promises. Status
/// with derate (the controller is told; the valve is not forced: the
/// estimate itself is still good), held until a clear after a good save.
pub const NV_FAILED: Faults = Faults(1 << 16);
/// Status: the cooling is credited on the LNG budget alone, no supply
/// pressure confirms the tank has LNG (a tank emptier than the budget says
/// would be credited: docs/firmware.md, residual risk).
pub const LNG_UNCONFIRMED: Faults = Faults(1 << 17);
/// Status: no valve position is reported, so no cooling is credited (the
/// estimate runs hot while the valve is open: the safe side).
pub const NO_VALVE_FEEDBACK: Faults = Faults(1 << 18);
/// Status: the estimate started from an unknown thermal state (a corrupt or
/// damaged record, no sample by the start-up timeout) and has not yet run
/// long enough to forget it; UNTRUSTED cannot be cleared before this bit
/// goes (docs/firmware.md, "Commands"). Kept in the thermal record: a reset
/// restarts the hold.
pub const RECOVERING: Faults = Faults(1 << 19);
/// Bits that latch.
pub const LATCHED: Faults = Faults(0x7f | (1 << 14));
/// Bits the thermal record keeps: the latched faults, the bad channels and
/// UNTRUSTED and RECOVERING (live status bits are not saved: they would make
/// the non-volatile write policy write at every valve change).
pub const RECORDED: Faults = Faults(LATCHED.0 | (0x3F << CH_SHIFT) | UNTRUSTED.0 | RECOVERING.0);
/// Bits that latch or are status, besides the channels: every named member.
pub const ALL_NAMED: Faults = Faults(0x7f | (1 << 7) | (1 << 14) | (1 << 15) | (15 << 16));

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;

    #[test]
    fn set_operations_and_names() {
        let f = STALE | Faults::channels(ChannelSet::CURRENT | ChannelSet::P_B) | UNTRUSTED;
        assert!(f.contains(STALE) && f.intersects(UNTRUSTED | RANGE) && !f.contains(STALE | RANGE));
        assert_eq!(f.channel_set().bits(), 0b101);
        assert_eq!(Faults::from_bits(f.bits()), f);
        assert_eq!((f & !UNTRUSTED) & UNTRUSTED, Faults::NONE);
        assert_eq!(std::format!("{:?}", f), "Faults(STALE | UNTRUSTED | channels 0b000101)");
        assert_eq!(std::format!("{:?}", Faults::NONE), "Faults(none)");
        assert_eq!(ALL_NAMED.bits() & Faults::channels(ChannelSet::ALL).bits(), 0);
        assert_eq!(!ChannelSet::SPEED, ChannelSet::from_bits(0b110111));
        assert_eq!(ChannelSet::channel(5), ChannelSet::AMBIENT);
        assert_eq!(ChannelSet::channel(6), ChannelSet::NONE);
    }
}
