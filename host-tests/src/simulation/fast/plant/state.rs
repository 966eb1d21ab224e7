//! What one [`FastPlant::run`](super::FastPlant::run) carries from one
//! thermal step to the next ([`RunState`]: the step level, the pending
//! work, the growth and refresh bookkeeping, the callback clock), and the
//! step-size decisions that read and write only it.

use super::steps::{Ladder, Todo, DRIFT_MOVE_K, GROW_ERR, LEVEL_MAX, LEVEL_MIN, REFRESH_LEVELS, STALL_STEPS};
use crate::fast::hydraulic::NH;
use crate::fast::options::FastOptions;
use crate::fast::thermal::{Thermal, NT};
use crate::plant::Control;
use std::iter::Peekable;
use std::vec::IntoIter;

/// The mutable locals of one `FastPlant::run`, in one place so that the
/// loop's phases can be methods (the plant's own fields stay the plant's).
#[derive(Debug)]
pub(super) struct RunState {
    /// Callback interval, s.
    pub(super) dt_s: f64,
    /// Time the run started at, s (the callback clock's origin).
    pub(super) t_start: f64,
    /// Time the run ends at, s.
    pub(super) t_end: f64,
    /// The schedule breakpoints ahead, then `t_end`.
    pub(super) stops: Peekable<IntoIter<f64>>,
    /// The last callback's answer.
    pub(super) ctl: Control,
    /// A replay of logged inputs: no hydraulic track (the log gives them).
    pub(super) replay: bool,
    /// `FAST_DEBUG` set: a line per step on stderr.
    pub(super) debug: bool,
    /// The thermal scheme and its step levels' φ-functions, taken from the
    /// plant for the run and given back at its end.
    pub(super) kept: Box<(Thermal, Ladder)>,
    /// Hydraulic states at the current time.
    pub(super) yh: [f64; NH],
    /// Current step level (the step is `dt_s · 2^level`).
    pub(super) level: i32,
    /// Pending work before the next step.
    pub(super) todo: Todo,
    /// The level of the last Jacobian.
    pub(super) jac_level: i32,
    /// Whether the step's growth since the last Jacobian still calls for
    /// one (once after each start or breakpoint).
    pub(super) refresh_armed: bool,
    /// Accepted steps since the level last grew.
    pub(super) stalled: u32,
    /// The error below which the step doubles (see `GROW_ERR`).
    pub(super) grow_err: f64,
    /// Whether the last accepted step was a doubling.
    pub(super) just_grew: bool,
    /// The finest level's step, s.
    pub(super) h_fine: f64,
    /// The level grid's origin, s: step ends are origin + ticks·h_fine,
    /// free of accumulated round-off.
    pub(super) origin: f64,
    /// Position since `origin` in units of `h_fine`.
    pub(super) ticks: u64,
    /// Where the next search for a branch switch starts, s.
    pub(super) scan_from: f64,
    /// Number of the next callback (the run's first is number 0).
    pub(super) k: u64,
    /// Time of the next callback, s.
    pub(super) t_cb: f64,
    /// The plant's thermal step count at the run's start (the step budget's base).
    pub(super) steps_at_start: u64,
    /// The end of the start's looser tolerance (`FastOptions::start_tol_factor`).
    pub(super) loose_until: f64,
    /// The hydraulics' relative tolerance to return to.
    pub(super) rtol0: f64,
    /// The hydraulics' absolute tolerances to return to.
    pub(super) atol0: [f64; NH],
    /// The end of the hydraulics' looser start (`FastOptions::start_hyd_factor`).
    pub(super) hyd_loose_until: f64,
    /// Whether the hydraulics still run on the start's looser tolerances.
    pub(super) hyd_loose: bool,
    /// The drifting columns (see `DRIFT_MOVE_K`): the nodes that held the
    /// step when a drift refresh was due.
    pub(super) drift_cols: Vec<usize>,
    /// The node that held the last accepted step.
    pub(super) last_worst: usize,
    /// Temperatures at the last Jacobian or drift refresh.
    pub(super) drift_z: [f64; NT],
}

impl RunState {
    /// The level whose step is the largest power-of-two multiple of the
    /// callback interval not above `h`, within the levels.
    pub(super) fn start_level(&self, h: f64) -> i32 {
        ((h / self.dt_s).log2().floor() as i32).clamp(LEVEL_MIN, LEVEL_MAX)
    }

    /// Drops the stops at or behind `t` and returns the end of the current
    /// segment (the next breakpoint, or the run's end).
    pub(super) fn segment_end(&mut self, t: f64) -> f64 {
        while self.stops.peek().is_some_and(|&s| s <= t + 1e-9) {
            self.stops.next();
        }
        self.stops.peek().copied().unwrap_or(self.t_end)
    }

    /// Lowers the level until the position is a multiple of its step (a
    /// level is usable only there) and returns where that step ends, s.
    pub(super) fn level_end(&mut self) -> f64 {
        while self.level > LEVEL_MIN && !self.ticks.is_multiple_of(1u64 << (self.level - LEVEL_MIN)) {
            self.level -= 1;
        }
        self.origin + (self.ticks + (1u64 << (self.level - LEVEL_MIN))) as f64 * self.h_fine
    }

    /// After an accepted ladder step of `h` s with error `err` (in
    /// tolerances; `hyd_h` the hydraulic step): the position moves on, the
    /// level grows when the error and the limits allow, and the Jacobian or
    /// its drifting columns fall due.
    pub(super) fn after_ladder_step(&mut self, opts: &FastOptions, err: f64, h: f64, hyd_h: f64) {
        self.ticks += 1u64 << (self.level - LEVEL_MIN);
        let next = self.level + 1;
        if self.just_grew {
            self.grow_err = (self.grow_err * 1.1).min(GROW_ERR);
        }
        self.just_grew = false;
        let grow = err <= self.grow_err;
        let room = next <= LEVEL_MAX && 2.0 * h <= opts.h_max_s && 2.0 * h <= opts.alias_ratio * hyd_h;
        if grow && room && self.ticks.is_multiple_of(1u64 << (next - LEVEL_MIN)) {
            self.level = next;
            self.stalled = 0;
            self.just_grew = true;
        } else {
            self.stalled += 1;
        }
        // After a start or a breakpoint, one Jacobian once the step
        // has grown 64-fold (the transient is over) or stopped
        // growing (the explicit start's stability limit, or the
        // transient's own time scale, holds it).
        if self.refresh_armed && (self.level >= self.jac_level + REFRESH_LEVELS || self.stalled >= STALL_STEPS) {
            self.todo.jacobian = true;
            self.refresh_armed = false;
        }
        // A node that has moved `DRIFT_MOVE_K` since the last Jacobian
        // or drift refresh: the drifting columns anew.
        let th = &self.kept.0;
        if !self.refresh_armed && !th.is_zero() {
            let moved = th.z.iter().zip(&self.drift_z).fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
            if moved >= DRIFT_MOVE_K {
                self.todo.drift = true;
            }
        }
    }
}
