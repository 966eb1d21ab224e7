//! The fast plant's step-size control: the thermal step levels (powers of
//! two of the callback interval), when a step grows, when the thermal
//! Jacobian or its drifting columns are taken anew, the per-level
//! φ-function cache, the work pending before a step, and the hydraulic
//! solver's errors as the plant's. The numbers' measurements are in
//! `docs/reference-speed.md`.

use crate::fast::phi::Phi;
use crate::fast::rosenbrock::RosError;
use crate::fast::thermal::NT;
use crate::plant::SimError;

/// Finest step level: the callback interval / 2^24.
pub(super) const LEVEL_MIN: i32 = -24;
/// Coarsest level: the callback interval · 2^8.
pub(super) const LEVEL_MAX: i32 = 8;
/// Number of levels.
pub(super) const LEVELS: usize = (LEVEL_MAX - LEVEL_MIN + 1) as usize;
/// Growth of the thermal step (levels: factors of two) after which the
/// thermal Jacobian is taken anew.
pub(super) const REFRESH_LEVELS: i32 = 6;
/// Accepted steps without growth after which that Jacobian is taken anyway.
pub(super) const STALL_STEPS: u32 = 16;
/// Error (in tolerances) below which a thermal step doubles: (0.9/2)³,
/// the doubled step's error at 0.9 of the bound were it ∝ h³. A doubling
/// that is then rejected halves this bound for the run (down to
/// `GROW_ERR_MIN`), a doubling accepted raises it by 10 % (up to
/// `GROW_ERR`): on Case 2 the step is a servo cycle's, too long at some
/// phases of it, and the doubling failed there every cycle (1 536 rejected
/// steps of 8 681, each also re-integrating its hydraulics; with this and
/// `SWITCH_DROP`, 513 of 7 765, 332 → 265 M instructions, 6.75e-3 → 6.41e-3 K).
pub(super) const GROW_ERR: f64 = 0.091125;
/// Lowest doubling bound, in tolerances.
pub(super) const GROW_ERR_MIN: f64 = 0.01;
/// Levels the step drops on the far side of a branch switch of the heat
/// balances: the first step there at the former level failed nine times in
/// ten on Case 2 (errors of 3–18 tolerances: the forcing's slope changes
/// there). Two levels cost accuracy (Case 2's winding 6.4e-3 → 9.8e-3 K).
pub(super) const SWITCH_DROP: i32 = 1;
/// Largest move of a node temperature, K, since the last thermal Jacobian
/// or drift refresh after which the Jacobian's drifting columns are taken
/// anew (`Thermal::drift`: the columns of the nodes that held the step,
/// one model evaluation each and one at z; the φ-functions stay A's). The
/// case oil's diagonal grows 4.3× from the start's A to 600 s on Case 1
/// (viscosity: its gap film and the leakage), treated explicitly that held
/// the steps by an error growing from step to step. Measured on Case 1
/// (`docs/reference-speed.md` section 8): 119 → 105 thermal steps, 2.62 →
/// 2.51 M instructions at 20 K; 30 K the same, a fixed 100 s or 250 s
/// interval 2.52 / 2.47 M (two refreshes, at 65 s and 250 s, here).
pub(super) const DRIFT_MOVE_K: f64 = 20.0;

/// The step levels' φ-functions, by level (boxed: a level is 5.4 kB and a
/// run uses a dozen of the 33).
pub(super) type Ladder = Vec<Option<Box<Phi<NT>>>>;

/// Work pending before the next thermal step.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Todo {
    /// Take the thermal Jacobian anew.
    pub(super) jacobian: bool,
    /// Take f anew and forget the step history (the forcing stepped).
    pub(super) fresh: bool,
    /// Restart the hydraulic integration (a schedule breakpoint).
    pub(super) hydraulics: bool,
    /// Take f anew on the far side of a branch switch at this time.
    pub(super) switch: Option<f64>,
    /// Take the drifting columns of the Jacobian anew (`Thermal::drift`).
    pub(super) drift: bool,
}

/// The hydraulic track's solver error as the plant's [`SimError::Solver`].
pub(super) fn hyd_error(e: RosError) -> SimError {
    let (t, what) = match e {
        RosError::StepUnderflow(t) => (t, "hydraulic step underflow"),
        RosError::Singular(t) => (t, "singular hydraulic iteration matrix"),
    };
    SimError::Solver { t, message: what.into() }
}
