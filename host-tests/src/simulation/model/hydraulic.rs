//! The hydraulic side of the model: the operating point at (t, y) (a
//! mission's hydraulic states or a replay's logged inputs), the motor
//! current and the hydraulic derivatives, with the oil properties through
//! which the temperatures enter them ([`HydraulicOil`]).

use super::{t_ix, Drive, Model, T0};
use crate::hydraulics::{self, ix, OpPoint};
use crate::losses;
use crate::network::{Node, N_NODES};
use crate::scenario::Circuit;

/// The oil properties through which the node temperatures enter the
/// hydraulic derivatives of a mission ([`Model::hydraulic_oil`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct HydraulicOil {
    /// Pump leakage conductance at the case-oil temperature, m³/(s·Pa).
    pub k_leak: f64,
    /// Density of the ball-valve oil (the throttle path's), kg/m³.
    pub rho_ball: f64,
    /// Kinematic viscosity of the ball-valve oil, m²/s.
    pub nu_ball: f64,
}

impl HydraulicOil {
    /// `other` − `self`, property by property.
    pub fn delta_to(&self, other: &Self) -> Self {
        Self { k_leak: other.k_leak - self.k_leak, rho_ball: other.rho_ball - self.rho_ball, nu_ball: other.nu_ball - self.nu_ball }
    }

    /// `self` + `w`·`d` property by property: with `d` = [`Self::delta_to`]
    /// of `other`, the linear interpolation towards it at weight `w`
    /// (`self` at 0).
    pub fn along(&self, d: &Self, w: f64) -> Self {
        Self { k_leak: self.k_leak + w * d.k_leak, rho_ball: self.rho_ball + w * d.rho_ball, nu_ball: self.nu_ball + w * d.nu_ball }
    }
}

impl Model {
    /// Hydraulic operating point at (t, y).
    pub fn op_point(&self, t: f64, y: &[f64]) -> OpPoint {
        self.op_point_parts(t, y).0
    }

    /// [`Model::op_point`] with the pump friction a mission's motor current
    /// was taken with (None in a replay, whose current is logged): the
    /// losses take it again ([`Model::loss_parts`]); it does not depend on
    /// the current.
    pub(super) fn op_point_parts(&self, t: f64, y: &[f64]) -> (OpPoint, Option<losses::PumpFriction>) {
        let mut op = self.op_hydraulic(t, y);
        let mut friction = None;
        if let Drive::Mission(_) = &self.drive {
            let fr = self.pump_friction(&op, y[t_ix(Node::Case)]);
            op.current_a = self.motor_current(&op, &fr);
            friction = Some(fr);
        }
        (op, friction)
    }

    /// [`Model::op_point`] without the motor current of a mission (zero
    /// there): what the hydraulic derivatives need.
    pub fn op_hydraulic(&self, t: f64, y: &[f64]) -> OpPoint {
        let ball = || {
            self.ball_oil(y[t_ix(Node::BallOil)])
        };
        self.op_hydraulic_with(t, y, true, ball)
    }

    /// [`Model::op_hydraulic`] with the ball-valve oil's (density kg/m³,
    /// kinematic viscosity m²/s) from `ball` (asked for in a throttle
    /// mission only) instead of from its temperature in `y`; without
    /// `surroundings`, a mission's ambient temperature and air speed are
    /// left at 0 (the hydraulic derivatives do not read them).
    fn op_hydraulic_with(&self, t: f64, y: &[f64], surroundings: bool, ball: impl FnOnce() -> (f64, f64)) -> OpPoint {
        match &self.drive {
            Drive::Replay(r) => {
                let mut op = r.op(&self.rig, t);
                if op.circuit == Circuit::Throttle {
                    // The throttle path takes what the pump delivers minus
                    // its leakage at the case-oil viscosity, as in a mission.
                    let k = self.k_leak(y[t_ix(Node::Case)]);
                    op.q_path = self.rig.displacement_m3_per_rad() * op.omega - k * (op.p_a - op.p_case);
                }
                op
            }
            Drive::Mission(m) => {
                // One length check for the five reads.
                let y: &[f64; ix::N] = y[..ix::N].try_into().expect("the hydraulic states");
                let mut op = OpPoint {
                    omega: y[ix::OMEGA],
                    p_a: y[ix::PA],
                    p_b: y[ix::PB],
                    p_case: self.rig.hydraulics.accumulator_pa,
                    x: y[ix::X],
                    v: y[ix::V],
                    q_path: 0.0,
                    current_a: 0.0,
                    circuit: m.circuit,
                    ambient_c: 0.0,
                    air_mps: 0.0,
                };
                if surroundings {
                    op.ambient_c = m.ambient_c.at(t);
                    op.air_mps = m.air_speed_mps.at(t) + self.rig.ext.forced_convection.unwrap_or(0.0);
                }
                if m.circuit == Circuit::Throttle {
                    let (_, inv_k2) = self.needle(m.needle_bar.at(t));
                    let (rho, nu) = ball();
                    op.q_path = hydraulics::path_flow_geom(&self.path_geom, op.p_a - op.p_b, rho, nu, inv_k2);
                }
                op
            }
        }
    }

    /// Motor current of a mission's operating point, A rms: the shaft
    /// torque (pump load plus friction, `pump` the pump's at the case-oil
    /// temperature) over the torque constant.
    fn motor_current(&self, op: &OpPoint, pump: &losses::PumpFriction) -> f64 {
        let fr = pump.total_w()
            + self.rig.ext.churning_loss.map_or(0.0, |k| losses::churning_w(k, op.omega))
            + self.rig.motor.bearing_friction_nm.map_or(0.0, |m| losses::bearing_w(m, op.omega));
        hydraulics::soft_abs(hydraulics::shaft_torque(&self.rig, op, fr), 1e-3) / self.rig.motor.torque_constant_nm_per_a
    }

    /// The hydraulic part of [`Model::rhs`]: fills `dy[..ix::N]` (zero in a
    /// replay, whose operating point is imposed) and returns the operating
    /// point at (t, y) without a mission's motor current
    /// ([`Model::op_hydraulic`]). The temperatures in `y` enter through the leakage
    /// conductance and the oil viscosity.
    pub fn hydraulic_rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> OpPoint {
        let op = self.op_hydraulic(t, y);
        self.hydraulic_rhs_at(t, y, &op, dy);
        op
    }

    /// The oil properties through which the node temperatures `temps`
    /// enter the hydraulic derivatives ([`Model::hydraulic_rhs_oil`]).
    pub fn hydraulic_oil(&self, temps: &[f64]) -> HydraulicOil {
        let (rho_ball, nu_ball) = self.ball_oil(temps[Node::BallOil as usize]);
        HydraulicOil { k_leak: self.k_leak(temps[Node::Case as usize]), rho_ball, nu_ball }
    }

    /// The hydraulic operating point of a mission at the hydraulic states
    /// `yh` with the oil properties `oil` ([`Model::hydraulic_rhs_oil`]);
    /// its ambient temperature and air speed are left at 0. Not for a
    /// replay (whose operating point is the log's: [`Model::op_hydraulic`]).
    pub fn op_hydraulic_oil(&self, t: f64, yh: &[f64], oil: &HydraulicOil) -> OpPoint {
        self.op_hydraulic_with(t, yh, false, || (oil.rho_ball, oil.nu_ball))
    }

    /// The hydraulic derivatives of a mission (`dy[..ix::N]`, zero in a
    /// replay) at the hydraulic states `yh` with the oil properties `oil`
    /// given instead of the temperatures: with `oil` from
    /// [`Model::hydraulic_oil`] the same as [`Model::hydraulic_rhs`], to
    /// the last bit. (The multirate fast path interpolates `oil` between
    /// the ends of a thermal step: each property costs a `log10` and two
    /// `pow`, several times a hydraulic evaluation's own arithmetic.)
    pub fn hydraulic_rhs_oil(&self, t: f64, yh: &[f64], oil: &HydraulicOil, dy: &mut [f64]) {
        match &self.drive {
            Drive::Mission(m) => {
                let op = self.op_hydraulic_with(t, yh, false, || (oil.rho_ball, oil.nu_ball));
                let f = hydraulics::flows(&self.rig, &op, oil.k_leak);
                hydraulics::derivatives(&self.rig, m, t, &op, &f, dy);
            }
            Drive::Replay(_) => dy[..ix::N].iter_mut().for_each(|d| *d = 0.0),
        }
    }

    pub(super) fn hydraulic_rhs_at(&self, t: f64, y: &[f64], op: &OpPoint, dy: &mut [f64]) {
        let temps = &y[T0..T0 + N_NODES];
        match &self.drive {
            Drive::Mission(m) => {
                let f = hydraulics::flows(&self.rig, op, self.k_leak(temps[Node::Case as usize]));
                hydraulics::derivatives(&self.rig, m, t, op, &f, dy);
            }
            Drive::Replay(_) => dy[..ix::N].iter_mut().for_each(|d| *d = 0.0),
        }
    }
}
