//! What the reduced model reports between steps: its temperatures, the last
//! step's losses, heats and the exchanger's duty (read by the guard, the
//! telemetry and the host's comparisons).

use super::{Model, N_LOSSES};
use crate::num::Num;
use crate::params::{NODE_DRAIN, N_NODES};

impl<N: Num> Model<N> {
    /// Predicted drain (case) oil temperature, degC.
    #[inline(always)]
    pub fn drain_c(&self) -> N {
        self.temp.get(NODE_DRAIN).map_or(N::ZERO, |s| N::value(*s))
    }

    /// All node temperatures, degC, in node order.
    pub fn temperatures_c(&self) -> [N; N_NODES] {
        let mut t = [N::ZERO; N_NODES];
        for (o, th) in t.iter_mut().zip(self.temp.iter()) {
            *o = N::value(*th);
        }
        t
    }

    /// Quasi-steady ring links of the last step: inlet port, outlet port, ball-valve oil, degC.
    pub fn links_c(&self) -> [N; 3] {
        self.links
    }

    /// Ambient of the last step, degC.
    pub fn ambient_c(&self) -> N {
        self.ambient_c
    }

    /// Ticks accumulated towards the next model step.
    pub fn pending_ticks(&self) -> u32 {
        self.sums.ticks
    }

    /// Sum of the last step's losses (eqs. 1-11), kW: the dissipation `P_sum` of eq. (23).
    pub fn last_total_kw(&self) -> N {
        self.last_total_kw
    }

    /// Heat of the last step's pump-side losses (eqs. 5-11: leakage, mechanical, line,
    /// throttling, actuator), kW: what heats the six nodes.
    pub fn last_heat_kw(&self) -> N {
        self.last_heat_kw
    }

    /// The shaft's (mechanical) loss of the last step from two independent sets of
    /// sensors, kW: `(eq. 8 from the port pressures and the speed, the shaft power
    /// Kt |I| |w| minus the hydraulic power D dp w from the current)`, with the sign of
    /// the hydraulic power (`sign(dp w)`) applied to the shaft power (the current is
    /// an rms magnitude). On consistent sensors both are eq. 8.
    pub fn last_mech_pair_kw(&self) -> (N, N) {
        self.last_mech_pair_kw
    }

    /// While set, every model step heats with the larger of the two mechanical-loss
    /// estimates of [`Model::last_mech_pair_kw`] (the guard sets it while the sensors
    /// disagree).
    pub fn set_loss_max(&mut self, on: bool) {
        self.loss_max = on;
    }

    /// Mean losses of the last step, kW: `[copper (eq. 1), iron (eq. 2), leakage
    /// (eqs. 5-7), mechanical (eq. 8), throttling = line + needle (eqs. 10-11),
    /// actuator leakage + seal friction]`.
    pub fn last_losses_kw(&self) -> [N; N_LOSSES] {
        self.last_losses_kw
    }

    /// Heat the outer surfaces gave to the air over the last step (eqs. 15, 16, 19), kW.
    pub fn last_outer_kw(&self) -> N {
        self.last_outer_kw
    }

    /// Heat the LNG exchanger removed from the oil over the last step, kW (0 when closed).
    pub fn last_lng_kw(&self) -> N {
        self.last_lng_kw
    }
}
