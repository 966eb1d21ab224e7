//! Cooling over a measured off-time: after a power loss on a
//! board with a battery-backed real-time clock, the saved temperatures are
//! cooled by an upper bound of the model's own cooling at rest, so the
//! restore stays on the hot side while a machine that was off for hours does
//! not start with its old, hot estimate.
//!
//! The bound (derivation in `eha_sim::reduce::rest_cooling`): with the pump
//! stopped and no power, the model's excess over the air `y = T - T_air`
//! stays below `c v_i e^(-r_i t)` node by node when it starts below `c v`,
//! with `v` the positive mode shape and `r_i` the slowest decay rate of the
//! group of nodes `i` is coupled to at rest (both from the parameter block;
//! at rest the pump, the main block, the ball-valve block and the actuator
//! exchange no heat with each other in the paper rig's model). So
//! `c = max_i y_i / v_i` and `T_i(t) <= T_air + c v_i e^(-r_i t)`, never
//! above the hottest saved node (a passive network: maximum principle).
//!
//! Assumptions, documented as the residual risk: the air during the off-time
//! was never warmer than the larger of the saved and the first measured
//! ambient (the guard raises every node by the difference when the first
//! sample's ambient is the warmer, [`crate::guard::Guard`]); the machine did
//! not run during the off-time; the clock did not jump forward. A clock that
//! reads earlier than the record (reset, battery change) gives no cooling.

use crate::model::ModelConsts;
use crate::params::N_NODES;

/// The model's cooling bound at rest, from the model constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestCooling {
    /// Decay rate `r_i` of each node's bound, 1/s (> 0).
    pub rate_per_s: [f32; N_NODES],
    /// Mode shape `v`, node order, each in (0, 1].
    pub mode: [f32; N_NODES],
}

impl RestCooling {
    /// The bound of `c` (rest rate and mode words); `None` when the constants
    /// carry none (rate 0 or a mode entry not in (0, 1]): no cooling.
    pub fn from_consts(c: &ModelConsts<f32>) -> Option<Self> {
        let ok = c.rest_rate.iter().all(|r| *r > 0.0 && r.is_finite()) && c.rest_mode.iter().all(|v| *v > 0.0 && *v <= 1.0);
        ok.then_some(RestCooling { rate_per_s: c.rest_rate, mode: c.rest_mode })
    }

    /// Upper bound of the node temperatures (degC) `off_s` seconds after the
    /// state `temps_c` at air `ambient_c`, at rest.
    pub fn cool(&self, temps_c: &[f32; N_NODES], ambient_c: f32, off_s: u32) -> [f32; N_NODES] {
        let mut c = 0.0f32;
        let mut top = ambient_c;
        for (t, v) in temps_c.iter().zip(self.mode.iter()) {
            c = c.max((t - ambient_c) / v);
            top = top.max(*t);
        }
        let mut out = *temps_c;
        for ((o, v), r) in out.iter_mut().zip(self.mode.iter()).zip(self.rate_per_s.iter()) {
            *o = (ambient_c + c * v * libm::expf(-r * off_s as f32)).min(top);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::DEFAULT_CONSTS;

    fn bound() -> RestCooling {
        RestCooling::from_consts(&DEFAULT_CONSTS).expect("the default constants carry a bound")
    }

    /// No time off: every node at least its saved temperature, none above the hottest.
    #[test]
    fn zero_off_time_keeps_the_state_or_raises_it() {
        let t = [45.0, 52.0, 48.0, 41.0, 39.0, 30.0];
        let out = bound().cool(&t, 20.0, 0);
        for (o, s) in out.iter().zip(t.iter()) {
            assert!(*o >= *s - 1e-4 && *o <= 52.0 + 1e-4, "{out:?}");
        }
    }

    /// Cooling is monotone in the off-time and tends to the air.
    #[test]
    fn longer_off_is_cooler_and_ends_at_the_air() {
        let t = [60.0; N_NODES];
        let b = bound();
        let (a, h, d) = (b.cool(&t, 20.0, 600), b.cool(&t, 20.0, 3600), b.cool(&t, 20.0, 3_000_000));
        for i in 0..N_NODES {
            assert!(h[i] <= a[i] && a[i] <= 60.0, "{a:?} {h:?}");
            assert!((d[i] - 20.0).abs() < 0.01, "{d:?}");
        }
    }

    /// A state colder than the air stays at most the air (never cooled below it).
    #[test]
    fn below_the_air_bound_is_the_air() {
        let out = bound().cool(&[10.0; N_NODES], 20.0, 3600);
        assert!(out.iter().all(|t| *t <= 20.0 && *t >= 10.0), "{out:?}");
    }

    /// Constants without a bound give none.
    #[test]
    fn no_bound_without_words() {
        let mut c = DEFAULT_CONSTS;
        c.rest_rate[2] = 0.0;
        assert_eq!(RestCooling::from_consts(&c), None);
    }
}
