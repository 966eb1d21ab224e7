//! The declared physical calibration set: every parameter, its physical
//! bounds, its prior towards the rig file, the rig field(s) it changes and
//! the excitation that identifies it.
//!
//! Every parameter is a multiplier θ on rig-file values (θ = 1 is the rig
//! as given), fitted in ln θ; the case film's speed exponent and the
//! surface probes' reading towards ambient are ln θ itself, added to a rig
//! field that is 0 in the rig file. **The mapping "parameter → rig fields" lives
//! only in [`apply`]** (and is listed in [`PARAMS`]' `fields` text), so
//! that a change of the reference physics remaps one table. `pump_friction`
//! scales the whole loss torque of the extended eq. (8), T₀ + C_v·μ·D·ω +
//! η_m·D·Δp (its shape from the rig file).

use crate::measured::Channel;
use crate::rig::Rig;

/// What a log set must carry for a parameter to be calibrated at all.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Needs {
    /// Nothing beyond the required columns.
    Nothing,
    /// A logged temperature channel on that node.
    Sensor(Channel),
    /// A logged input column that is above zero somewhere (the ram air:
    /// without a logged stream its coefficient acts on nothing).
    Input(Channel),
    /// A logged temperature channel in a log that moves shaft speed and
    /// pressure drop independently
    /// ([`super::ident::independent_speed_and_load`]): a parameter that the
    /// data separate from its neighbours only through how flow and heat
    /// input combine.
    SensorWithJointExcitation(Channel),
}

/// One parameter of the calibration set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamDef {
    /// Name used in reports and in `--with`-style lists.
    pub name: &'static str,
    /// What it is, physically.
    pub what: &'static str,
    /// The rig field(s) it multiplies (documentation of [`apply`]).
    pub fields: &'static str,
    /// Lower bound of the multiplier (physical range, see `why_bounds`).
    pub lo: f64,
    /// Upper bound of the multiplier.
    pub hi: f64,
    /// Standard deviation of the prior on ln θ; the prior's centre is θ = 1,
    /// which is [`ParamDef::centre`].
    pub prior_sigma_ln: f64,
    /// What θ = 1 (the prior's centre) is, with its source.
    pub centre: &'static str,
    /// Why these bounds and this prior width.
    pub why: &'static str,
    /// Sensor the logs must carry for this parameter to be fitted.
    pub needs: Needs,
    /// The excitation that identifies it (shown when it is held).
    pub excitation: &'static str,
    /// Fit stage ([`Stage`]).
    pub stage: Stage,
}

/// When a parameter joins the fit: the thermal network first, the sensor
/// responses on top of it (`calibration::calibrate`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Heat paths, capacities and losses.
    Thermal,
    /// A sensor's own response time.
    SensorResponse,
}

/// Name of the oil probe's response-time parameter (held by default in
/// `commission`, freed by `--fit-oil-probe`).
pub const PROBE_OIL: &str = "probe_oil";

/// The prior centre of a multiplier on a rig-file value: the rig file.
pub const RIG_FILE: &str = "the rig file's value";

/// Name of the valve blocks' wall-conduction parameter.
pub const BLOCK_WALL: &str = "block_wall";

/// Name of the duct films' turbulent level
/// ([`crate::rig::Blocks::duct_turbulent_scale`]).
pub const DUCT_TURBULENT: &str = "duct_turbulent";

/// Name of the forced-convection (ram-air) coefficient's parameter.
pub const H_FORCED: &str = "h_forced";

/// Name of the churned case film's level ([`crate::rig::Pump::case_churn`]).
pub const CASE_CHURN: &str = "case_churn";

/// Name of the churned case film's speed exponent
/// ([`crate::rig::Pump::case_churn_speed_exp`]).
pub const CASE_CHURN_SPEED: &str = "case_churn_speed";

/// Name of the case oil's share of the pump friction heat
/// ([`crate::rig::FrictionPairs::case_share_scale`]).
pub const FRICTION_CASE: &str = "friction_case";

/// Name of the factor on the pump's speed-law friction (the no-load and
/// viscous terms of the extended eq. 8).
pub const FRICTION_SPEED: &str = "friction_speed";

/// Names of the surface probes' reading-towards-ambient parameters
/// ([`crate::rig::SurfaceProbes`]): motor, pump, main block, ball block.
pub const PROBE_SURFACE: [&str; 4] = ["probe_surface_motor", "probe_surface_pump", "probe_surface_block", "probe_surface_ball"];

/// The rig-level structural freedoms the held-out drain misses' bisection
/// named (docs/commissioning-foreign.md): the pump friction heat's placement and
/// speed law, the surface probes' reading towards ambient. Fitted by
/// `commission` (the pump's loss level from the current); a caller that
/// wants the set as it was before them holds these.
pub const STRUCTURAL: [&str; 6] = [FRICTION_CASE, FRICTION_SPEED, PROBE_SURFACE[0], PROBE_SURFACE[1], PROBE_SURFACE[2], PROBE_SURFACE[3]];

mod table;

pub use table::PARAMS;

/// Index of parameter `name` in [`PARAMS`].
pub fn index(name: &str) -> Option<usize> {
    PARAMS.iter().position(|p| p.name == name)
}

/// The rig with multipliers `theta` (one per [`PARAMS`] entry, in order)
/// applied to `base`. **The one place** where calibration parameters touch
/// rig fields.
pub fn apply(base: &Rig, theta: &[f64]) -> Rig {
    assert_eq!(theta.len(), PARAMS.len(), "one multiplier per calibration parameter");
    let mut r = base.clone();
    for (def, &t) in PARAMS.iter().zip(theta) {
        match def.name {
            "h_out_motor" => r.motor.area_m2 *= t,
            "h_out_pump" => r.pump.area_m2 *= t,
            "h_out_main_block" => r.blocks.main_area_m2 *= t,
            "h_out_ball_block" => r.blocks.ball_area_m2 *= t,
            H_FORCED => r.outside.ram_run_length_m *= t.powi(-5),
            "film_loop" => r.blocks.loop_area_scale *= t,
            "film_port" => r.pump.port_area_scale *= t,
            "film_ball" => {
                r.nuisance.inner_scale *= t;
                r.blocks.loop_area_scale /= t;
                r.pump.port_area_scale /= t;
                r.pump.case_inner_area_m2 /= t;
            }
            "film_case" => r.pump.case_inner_area_m2 *= t,
            CASE_CHURN => r.pump.case_churn *= t,
            CASE_CHURN_SPEED => r.pump.case_churn_speed_exp += t.ln(),
            BLOCK_WALL => r.blocks.wall_m /= t,
            DUCT_TURBULENT => r.blocks.duct_turbulent_scale *= t,
            "cap_motor" => {
                let w = r.motor.winding_mass_kg;
                r.motor.mass_kg = w + t * (r.motor.mass_kg - w);
            }
            "cap_pump" => r.pump.mass_kg *= t,
            "cap_main_block" => r.blocks.main_mass_kg *= t,
            "cap_ball_block" => r.blocks.ball_mass_kg *= t,
            "cap_loop_oil" => r.blocks.loop_oil_m3 *= t,
            "cap_case_oil" => r.pump.case_oil_m3 *= t,
            PROBE_OIL => r.blocks.sensor_tau_s *= t,
            // Every term of the pump loss torque T0 + C_v·μ·ω + C_p·Δp
            // (extended eq. 8) scales together.
            "pump_friction" => {
                r.pump.eta_m *= t;
                r.pump.no_load_torque_nm *= t;
                r.pump.viscous_torque_coeff *= t;
            }
            "leak_gap" => {
                r.pump.gaps.piston_gap_m *= t;
                r.pump.gaps.slipper_gap_m *= t;
                r.pump.gaps.port_gap_m *= t;
            }
            "winding_r" => r.motor.r25_ohm *= t,
            "iron_loss" => {
                r.motor.iron.k_h *= t;
                r.motor.iron.k_c *= t;
                r.motor.iron.k_e *= t;
            }
            FRICTION_CASE => r.pump.friction_pairs.case_share_scale *= t,
            FRICTION_SPEED => {
                r.pump.no_load_torque_nm *= t;
                r.pump.viscous_torque_coeff *= t;
            }
            n if n == PROBE_SURFACE[0] => r.probes.motor += t.ln(),
            n if n == PROBE_SURFACE[1] => r.probes.pump += t.ln(),
            n if n == PROBE_SURFACE[2] => r.probes.main_block += t.ln(),
            n if n == PROBE_SURFACE[3] => r.probes.ball_block += t.ln(),
            "needle_split" => {
                r.hydraulics.path.length_m *= t;
                r.hydraulics.path.local_loss_coeff *= t;
            }
            other => unreachable!("calibration parameter {other} has no rig mapping"),
        }
    }
    r
}

/// The all-ones multiplier vector (the rig as given).
pub fn nominal() -> Vec<f64> {
    vec![1.0; PARAMS.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every parameter maps to at least one rig field and θ = 1 is the
    /// identity; `film_ball` changes the ball film only (the other films'
    /// products stay as in the rig file, to 1e-12 relative).
    #[test]
    fn mapping_is_identity_at_one_and_film_ball_is_isolated() {
        let rig = Rig::default();
        assert_eq!(apply(&rig, &nominal()), rig);
        for k in 0..PARAMS.len() {
            let mut th = nominal();
            th[k] = 1.5;
            assert_ne!(apply(&rig, &th), rig, "{} changes nothing", PARAMS[k].name);
            assert!(PARAMS[k].lo < 1.0 && PARAMS[k].hi > 1.0, "{}: the rig file inside the bounds", PARAMS[k].name);
        }
        let mut th = nominal();
        th[index("film_ball").unwrap()] = 2.0;
        let r = apply(&rig, &th);
        let rel = |a: f64, b: f64| ((a - b) / b).abs();
        assert!(rel(r.nuisance.inner_scale * r.blocks.loop_area_scale, rig.blocks.loop_area_scale) < 1e-12);
        assert!(rel(r.nuisance.inner_scale * r.pump.case_inner_area_m2, rig.pump.case_inner_area_m2) < 1e-12);
        assert!(rel(r.nuisance.inner_scale * r.pump.port_area_scale, rig.pump.port_area_scale) < 1e-12);
    }
}
