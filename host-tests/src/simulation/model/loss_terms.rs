//! The model's losses at one instant (eqs. 1–11) and where the pump's
//! friction heat goes (extended eq. 8): the heat sources of the node
//! balances, apart from the balances themselves (`thermal.rs`).

use super::{Drive, Model};
use crate::hydraulics::{self, OpPoint};
use crate::losses;
use crate::network::Node;
use crate::scenario::Circuit;

/// Every loss of the model at one instant, W.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Losses {
    /// Copper loss, eq. (1).
    pub copper: f64,
    /// Iron loss, eq. (2).
    pub iron: f64,
    /// Bearing friction, eq. (3) (optional).
    pub bearing: f64,
    /// Pump leakage, eqs. (5)–(7).
    pub leakage: f64,
    /// Pump mechanical loss, eq. (8).
    pub mechanical: f64,
    /// Churning loss (extension).
    pub churning: f64,
    /// Line friction and local losses, eq. (10).
    pub line: f64,
    /// Needle-valve throttling.
    pub needle: f64,
    /// Relief and check valves.
    pub valves: f64,
    /// Actuator leakage, eq. (11).
    pub act_leak: f64,
    /// Piston seal friction (viscous + Coulomb).
    pub act_friction: f64,
    /// The part of [`Losses::mechanical`] that heats metal (the pump's
    /// housing and rotating group) rather than oil, W: where the
    /// sliding-pair rule puts it ([`Model::friction_heat`]). Not a loss of
    /// its own: [`Losses::total`] counts it once, inside `mechanical`.
    pub mech_metal: f64,
}

impl Losses {
    /// Sum of all losses, W.
    pub fn total(&self) -> f64 {
        self.copper + self.iron + self.bearing + self.leakage + self.mechanical + self.churning + self.line + self.needle
            + self.valves + self.act_leak + self.act_friction
    }

    /// Named values for outputs.
    pub fn channels(&self) -> [(&'static str, f64); 11] {
        [
            ("p_cu_w", self.copper),
            ("p_fe_w", self.iron),
            ("p_bearing_w", self.bearing),
            ("p_leak_w", self.leakage),
            ("p_mech_w", self.mechanical),
            ("p_churn_w", self.churning),
            ("p_line_w", self.line),
            ("p_throttle_w", self.needle),
            ("p_valves_w", self.valves),
            ("p_act_leak_w", self.act_leak),
            ("p_act_friction_w", self.act_friction),
        ]
    }

    /// The pump friction of eq. (8) split by what it heats: (oil, metal), W.
    /// Output channels `p_mech_oil_w`, `p_mech_metal_w` (they add up to `p_mech_w`).
    pub fn friction_split_channels(&self) -> [(&'static str, f64); 2] {
        [("p_mech_oil_w", self.mechanical - self.mech_metal), ("p_mech_metal_w", self.mech_metal)]
    }
}

/// Where the pump's friction heat (extended eq. 8) goes at one instant, W
/// ([`Model::friction_heat`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FrictionHeat {
    /// Into the delivered (high-pressure port) oil.
    pub delivered: f64,
    /// Into the case oil.
    pub case: f64,
    /// Into the pump housing.
    pub housing: f64,
    /// Into the pump's internals (only with [`crate::rig::Pump::split`]).
    pub internals: f64,
}

impl FrictionHeat {
    /// The part that heats metal (housing and internals), W.
    pub fn metal(&self) -> f64 {
        self.internals + self.housing
    }
}

impl Model {
    /// The pump's friction heat by term (extended eq. 8), with the film
    /// viscosity at the case-oil temperature `t_case`, W.
    pub fn pump_friction(&self, op: &OpPoint, t_case: f64) -> losses::PumpFriction {
        let p = &self.rig.pump;
        let mu = self.mu(t_case);
        losses::PumpFriction::new(p.no_load_torque_nm, p.viscous_torque_coeff, p.eta_m, self.rig.displacement_m3_per_rad(), mu, op.p_a - op.p_b, op.omega)
    }

    /// The pump's friction heat placed by the sliding pairs, W.
    ///
    /// One pump node (the baseline): the no-load term (bearings, shaft seal)
    /// heats the housing, the viscous and pressure terms divide by
    /// [`crate::rig::FrictionPairs::shares`].
    ///
    /// The pump as it is built ([`crate::rig::Pump::split`]): the viscous and
    /// pressure terms arise in the three lubricating films (piston/bore,
    /// slipper/swash plate, barrel/valve plate); a film of a few µm conducts
    /// its heat into its two faces (δ/k ≈ 1e-4 m²·K/W, a hundredth of the
    /// faces' films to the oil; its own leakage convects a few per cent), and
    /// every one of those faces belongs to the internals. The no-load term
    /// divides by [`crate::rig::PumpSplit::no_load_to_housing`].
    pub fn friction_heat(&self, op: &OpPoint, t_case: f64) -> FrictionHeat {
        self.friction_heat_of(&self.pump_friction(op, t_case))
    }

    /// [`Model::friction_heat`] of the pump friction `fr` already taken.
    fn friction_heat_of(&self, fr: &losses::PumpFriction) -> FrictionHeat {
        let films = fr.viscous_w + fr.pressure_w;
        match &self.rig.pump.split {
            Some(s) => {
                let to_housing = s.no_load_to_housing * fr.no_load_w;
                FrictionHeat { internals: films + fr.no_load_w - to_housing, housing: to_housing, ..FrictionHeat::default() }
            }
            None => {
                let (f_del, f_case, f_metal) = self.rig.pump.friction_pairs.shares();
                FrictionHeat { delivered: f_del * films, case: f_case * films, housing: fr.no_load_w + f_metal * films, internals: 0.0 }
            }
        }
    }

    /// All losses at an operating point and temperatures, W.
    pub fn losses(&self, t: f64, op: &OpPoint, temps: &[f64]) -> Losses {
        self.loss_parts(t, op, temps, None).0
    }

    /// [`Model::losses`] with the two of its parts the heat balances use
    /// again ([`Model::thermal_with`]): where the pump's friction heat goes
    /// and the pump and valve flows (each taken once, not once for the
    /// losses and once for the balances: the same calls on the same
    /// arguments, so the same values to the last bit). `friction`: the
    /// pump friction at `op` and the case oil of `temps` if already taken
    /// ([`Model::op_point_parts`]). The fourth part: the throttle path's
    /// line pressure drop at |q_path| (Pa) when it was taken here (the
    /// flow's sign bit clear, so the same call as the balances' on the same
    /// argument bits), for [`Model::thermal_with`].
    pub(super) fn loss_parts(&self, t: f64, op: &OpPoint, temps: &[f64], friction: Option<losses::PumpFriction>) -> (Losses, FrictionHeat, hydraulics::Flows, Option<f64>) {
        let rig = &self.rig;
        let tc = |n: Node| temps[n as usize];
        let mut f = hydraulics::flows(rig, op, self.k_leak(tc(Node::Case)));
        if let Drive::Replay(_) = self.drive {
            hydraulics::limit_check_to_makeup(&mut f);
        }
        let fr = friction.unwrap_or_else(|| self.pump_friction(op, tc(Node::Case)));
        let fh = self.friction_heat_of(&fr);
        let dp = op.p_a - op.p_b;
        let mut line_dp = None;
        let (line, needle) = match (&self.drive, op.circuit) {
            (Drive::Mission(m), Circuit::Throttle) => {
                let nk = self.needle(m.needle_bar.at(t)).0;
                let (l, n) = self.path_dp(op.q_path, tc(Node::BallOil), nk);
                line_dp = op.q_path.is_sign_positive().then_some(l);
                (l * op.q_path, n * op.q_path)
            }
            (Drive::Replay(_), Circuit::Throttle) => {
                let (l, _) = self.path_dp(op.q_path, tc(Node::BallOil), None);
                line_dp = op.q_path.is_sign_positive().then_some(l);
                let line = l * op.q_path;
                (line, losses::throttle_w(dp, op.q_path) - line)
            }
            (_, Circuit::Servo) => (0.0, 0.0),
        };
        let h = &rig.hydraulics;
        let valves = (f.relief_ab + f.relief_ba) * dp.abs()
            + f.check_a * (h.accumulator_pa - op.p_a)
            + f.check_b * (h.accumulator_pa - op.p_b);
        let coulomb = rig.ext.coulomb_friction.map_or(0.0, |fc| fc * (op.v / 1e-3).tanh() * op.v);
        let l = Losses {
            copper: losses::copper_w(
                rig.motor.phases,
                op.current_a,
                rig.motor.r25_ohm,
                rig.ext.winding_resistance_temperature,
                tc(Node::Winding),
            ),
            iron: self.iron_w(op.omega),
            bearing: rig.motor.bearing_friction_nm.map_or(0.0, |m| losses::bearing_w(m, op.omega)),
            leakage: f.leak_a * (op.p_a - op.p_case) + f.leak_b * (op.p_b - op.p_case),
            mechanical: fr.total_w(),
            mech_metal: fh.metal(),
            churning: rig.ext.churning_loss.map_or(0.0, |k| losses::churning_w(k, op.omega)),
            line,
            needle,
            valves,
            act_leak: f.act_leak * dp,
            act_friction: match op.circuit {
                Circuit::Servo => rig.actuator.viscous_friction_n_s_per_m * op.v * op.v + coulomb,
                Circuit::Throttle => 0.0,
            },
        };
        (l, fh, f, line_dp)
    }
}
