//! The campaign's measured design limits: runs that fail the pass rule
//! because of what the design cannot see, each with its reason. A failing
//! run that is not listed here fails `eha-sim faults` (and the tests); the
//! margin by which a listed run fails is in `docs/failure-modes.md`,
//! generated from the run itself.

use super::FaultResult;

/// A design limit: the runs it covers and why.
#[derive(Debug, Clone, Copy)]
pub struct Limit {
    /// The case ([`super::Case::name`]).
    pub fault: &'static str,
    /// The scenario (None: every one).
    pub scenario: Option<&'static str>,
    /// The start (None: every one).
    pub start: Option<&'static str>,
    /// Why the design cannot meet the pass rule.
    pub reason: &'static str,
}

const NO_SECOND_SPEED_SOURCE: &str = "without the drive's electrical frequency nothing independent measures the speed: both sides of the torque cross-check scale with the measured speed, and the stall rule sees only a speed near zero under load, after 2 s; a reading of half or one drifting to zero under load stays plausible (with the electrical frequency every speed fault passes)";

const NO_SUPPLY_PRESSURE: &str = "without the LNG supply pressure nothing shows a tank that is empty before the budget says so: the open valve is credited as cooling (docs/firmware.md, residual risk; with the supply pressure, `+supply`, it passes)";

/// Every listed design limit.
pub const KNOWN_LIMITS: &[Limit] = &[
    Limit { fault: "speed/gain-x0.5+no-elec", scenario: None, start: None, reason: NO_SECOND_SPEED_SOURCE },
    Limit { fault: "speed/drift+no-elec", scenario: None, start: None, reason: NO_SECOND_SPEED_SOURCE },
    Limit {
        fault: "speed/stuck-zero+no-elec",
        scenario: None,
        start: None,
        reason: "without the drive's electrical frequency a speed stuck at zero under load is seen by the stall rule after 2 s (the rule's time, to let a load be held at standstill briefly), not within the 1 s of the pass rule; the estimate runs up to 2.5 K low meanwhile (hot starts too, the oil following its viscosity line), then the speed's worst case takes over",
    },
    Limit { fault: "lng-empty-physical", scenario: None, start: None, reason: NO_SUPPLY_PRESSURE },
    Limit {
        fault: "refill-while-empty",
        scenario: None,
        start: None,
        reason: "a refill confirmed without a new charge (the controller's error; the guard accepts it only with the valve closed and no alarm) restores the budget, and without the LNG supply pressure nothing shows that the tank is empty (with it, `+supply`, it passes)",
    },
    Limit {
        fault: "power-loss-machine-running",
        scenario: None,
        start: None,
        reason: "the guard's MCU unpowered while the pump runs on without LNG: the heat of the off-time is not seen (the power-off cooling assumes the machine stopped with its guard: one supply; docs/firmware.md, residual risk); in cold oil the pump's viscous friction is up to twice its 40 degC value, so an early power loss on the LNG case fails too",
    },
];

/// The limit that covers `r`, if any.
pub fn find(r: &FaultResult) -> Option<&'static Limit> {
    KNOWN_LIMITS
        .iter()
        .find(|l| l.fault == r.fault && l.scenario.is_none_or(|s| s == r.scenario) && l.start.is_none_or(|s| s == r.start))
}
