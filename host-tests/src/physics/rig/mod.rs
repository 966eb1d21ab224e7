//! Rig parameters: the test rig of the paper (Tables 2, 3 and 6) plus every
//! parameter the paper does not give, each marked with its source:
//! "Table N" (the paper), "assumed" (engineering value for this class of
//! machine, stated once here) or "calibrated" (fitted, see
//! `docs/calibration.md` and the `calibrate` command).
//!
//! The TOML file `host-tests/rig/liu2024.toml` is `Rig::default()` written
//! out; `--set section.key=value` overrides any field.

use crate::cooling::Lng;
use crate::fluid::Oil;
use crate::losses::{IronLoss, Line, PumpGaps};

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::path::Path;

mod machine;
mod structure;
#[cfg(test)]
mod tests;
mod uncertain;

pub use machine::*;
pub use structure::*;
pub use uncertain::*;

/// Errors of rig loading and overriding.
#[derive(Debug, thiserror::Error)]
pub enum RigError {
    /// The TOML file could not be read.
    #[error("cannot read rig file {path}: {source}")]
    Io {
        /// File path.
        path: String,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The TOML text is not a valid rig (message names line and column).
    #[error("invalid rig file {path}: {message}")]
    Parse {
        /// File path (or `<override>`).
        path: String,
        /// toml's message, with line and column.
        message: String,
    },
    /// An override was not of the form `section.key=value` or named no field.
    #[error("bad override `{0}`: {1}")]
    Override(String, String),
    /// A parameter is outside its physical range.
    #[error("invalid parameter {0}: {1}")]
    Invalid(&'static str, String),
}

/// The whole rig.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rig {
    /// Hydraulic oil (Table 2: ISO VG 46).
    pub oil: Oil,
    /// Motor.
    pub motor: Motor,
    /// Pump.
    pub pump: Pump,
    /// Valve blocks.
    pub blocks: Blocks,
    /// Hydraulic circuit.
    pub hydraulics: Hydraulics,
    /// Cylinder and load.
    pub actuator: Actuator,
    /// Outer heat transfer.
    pub outside: Outside,
    /// Metal paths from the pump housing to the motor and the manifold
    /// (optional, **off by default**, with [`Pump::split`] the pump as it is
    /// built: [`Joints::a_priori`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joints: Option<Joints>,
    /// LNG cooling (Table 6).
    pub lng: Lng,
    /// Nuisance multipliers.
    pub nuisance: Nuisance,
    /// Surface probes' reading towards ambient (a measurement model; zero:
    /// on their metal).
    #[serde(default, skip_serializing_if = "SurfaceProbes::is_zero")]
    pub probes: SurfaceProbes,
    /// Model extensions.
    #[serde(default)]
    pub ext: Extensions,
    /// The uncertain parameters and their ranges (`eha-sim uq`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub uncertain: Vec<Uncertain>,
}

impl Default for Rig {
    fn default() -> Self {
        Self {
            oil: Oil::default(),
            motor: Motor {
                phases: 3.0,
                r25_ohm: 0.074,
                inductance_h: 1.433e-3,
                max_current_a: 340.5,
                torque_constant_nm_per_a: 0.75,
                iron: IronLoss { k_h: 0.3, k_c: 0.002, k_e: 0.01, b_peak_t: 1.4, pole_pairs: 4.0 },
                bearing_friction_nm: None,
                mass_kg: 75.0,
                winding_mass_kg: 8.0,
                winding_cp: 385.0,
                body_cp: 500.0,
                area_m2: 0.5,
                diameter_m: 0.2,
                winding_to_housing_w_per_k: 15.0,
                speed_time_constant_s: 0.02,
                max_speed_rpm: 3000.0,
            },
            pump: Pump {
                displacement_cm3: 19.0,
                gaps: PumpGaps {
                    pistons: 9.0,
                    piston_d_m: 0.010,
                    piston_seal_m: 0.020,
                    piston_gap_m: 12e-6,
                    eccentricity: 0.5,
                    slipper_gap_m: 12e-6,
                    slipper_r2_over_r1: 1.5,
                    port_angle_rad: PI,
                    port_radius_m: 0.02,
                    port_gap_m: 12e-6,
                    port_seal_m: 0.005,
                },
                eta_m: 0.443_590,
                no_load_torque_nm: 0.3,
                viscous_torque_coeff: 5.0e4,
                friction_pairs: FrictionPairs { piston_bore: 0.5, slipper_swash: 0.3, valve_plate: 0.2, case_share_scale: 1.0 },
                split: None,
                mass_kg: 20.0,
                cp: 460.0,
                area_m2: 0.1,
                diameter_m: 0.12,
                case_oil_m3: 0.15e-3,
                port_oil_m3: 0.05e-3,
                case_inner_area_m2: 0.02,
                case_gap_m: 0.003,
                case_churn: 1.0,
                case_churn_speed_exp: 0.0,
                rotor_radius_m: 0.03,
                port_d_m: 0.012,
                port_len_m: 0.05,
                port_area_scale: 1.0,
            },
            blocks: Blocks {
                main_mass_kg: 160.0,
                main_area_m2: 0.36,
                ball_mass_kg: 30.0,
                ball_area_m2: 0.08,
                cp: 460.0,
                loop_oil_m3: 1.669_741e-3,
                loop_d_m: 0.010,
                loop_len_m: 1.0,
                loop_area_scale: 5.599_682,
                ball_oil_m3: 0.05e-3,
                ball_d_m: 0.008,
                ball_len_m: 0.3,
                sensor_oil_m3: 5e-6,
                sensor_tau_s: 2.0,
                sensor_to_block_w_per_k: 0.05,
                mount_w_per_k: 2.0,
                wall_m: 0.03,
                steel_k: 45.0,
                duct_turbulent_scale: 1.0,
            },
            hydraulics: Hydraulics {
                bulk_modulus_pa: 7.0e8,
                line_volume_m3: 0.15e-3,
                accumulator_pa: 5e5,
                check_gain: 1e-9,
                relief_crack_pa: 210e5,
                relief_gain: 1e-10,
                path: Line { length_m: 1.5, diameter_m: 0.008, local_loss_coeff: 6.0 },
            },
            actuator: Actuator {
                ram_area_m2: 1526.81e-6,
                stroke_m: 0.1,
                load_mass_kg: 13.5,
                spring_n_per_m: 245e3,
                damping_n_s_per_m: 15e3,
                viscous_friction_n_s_per_m: 2e3,
                leak_m3_per_s_pa: 2e-14,
                body_mass_kg: 12.0,
                body_cp: 460.0,
                area_m2: 0.12,
                diameter_m: 0.09,
                position_gain_per_s: 20.0,
            },
            outside: Outside { emissivity: 0.85, ram_run_length_m: 0.352_009, pump_ram_exposure: 1.0, altitude_m: 0.0, ram_property_c: None },
            joints: None,
            lng: Lng::default(),
            nuisance: Nuisance { outer_scale: 1.0, inner_scale: 1.0, metal_capacity_scale: 1.0, oil_capacity_scale: 1.0 },
            probes: SurfaceProbes::default(),
            ext: Extensions::default(),
            uncertain: Uncertain::paper_ranges(),
        }
    }
}

impl Rig {
    /// Parse a rig from TOML text (`name` is used in error messages).
    pub fn from_toml_str(text: &str, name: &str) -> Result<Self, RigError> {
        let rig: Rig = toml::from_str(text).map_err(|e| RigError::Parse { path: name.into(), message: e.to_string() })?;
        rig.validate()?;
        Ok(rig)
    }

    /// Read a rig TOML file.
    pub fn from_toml_file(path: &Path) -> Result<Self, RigError> {
        let text = std::fs::read_to_string(path).map_err(|source| RigError::Io { path: path.display().to_string(), source })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// A copy of the rig's physics without its list of uncertain parameters
    /// ([`Rig::uncertain`]: the ranges `eha-sim uq` samples, read by no
    /// model equation), what a simulation's model keeps. The list's names,
    /// keys and sources are most of a clone's allocations: a plant built by
    /// a full clone spent ~30 k instructions on it and its release (1.4 %
    /// of a fast Case 1 run, `docs/reference-speed.md` section 3).
    pub fn physics_clone(&self) -> Self {
        let Rig { oil, motor, pump, blocks, hydraulics, actuator, outside, joints, lng, nuisance, probes, ext, uncertain: _ } = self;
        Rig {
            oil: *oil,
            motor: motor.clone(),
            pump: pump.clone(),
            blocks: blocks.clone(),
            hydraulics: hydraulics.clone(),
            actuator: actuator.clone(),
            outside: outside.clone(),
            joints: *joints,
            lng: *lng,
            nuisance: nuisance.clone(),
            probes: *probes,
            ext: ext.clone(),
            uncertain: Vec::new(),
        }
    }

    /// The rig as TOML text.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_default()
    }

    /// Apply an override `section.key=value` (any depth, e.g.
    /// `pump.gaps.piston_gap_m=10e-6`, `ext.sensor_lag=60`); `none` clears an
    /// optional field.
    pub fn set_override(&mut self, spec: &str) -> Result<(), RigError> {
        let (path, value) = spec.split_once('=').ok_or_else(|| RigError::Override(spec.into(), "expected key=value".into()))?;
        let mut doc: toml::Value =
            toml::Value::try_from(&*self).map_err(|e| RigError::Override(spec.into(), e.to_string()))?;
        let keys: Vec<&str> = path.trim().split('.').collect();
        let (last, parents) = keys.split_last().ok_or_else(|| RigError::Override(spec.into(), "empty key".into()))?;
        let mut cur = &mut doc;
        for k in parents {
            cur = cur
                .get_mut(*k)
                .ok_or_else(|| RigError::Override(spec.into(), format!("no section `{k}`")))?;
        }
        let table = cur.as_table_mut().ok_or_else(|| RigError::Override(spec.into(), "not a section".into()))?;
        let v = value.trim();
        if v.eq_ignore_ascii_case("none") {
            table.remove(*last);
        } else {
            let parsed = if let Ok(b) = v.parse::<bool>() {
                toml::Value::Boolean(b)
            } else if let Ok(x) = v.parse::<f64>() {
                toml::Value::Float(x)
            } else {
                return Err(RigError::Override(spec.into(), format!("`{v}` is not a number, bool or none")));
            };
            table.insert((*last).to_string(), parsed);
        }
        let text = toml::to_string(&doc).map_err(|e| RigError::Override(spec.into(), e.to_string()))?;
        *self = Self::from_toml_str(&text, "<override>").map_err(|e| RigError::Override(spec.into(), e.to_string()))?;
        Ok(())
    }

    /// Check the ranges that would make the model meaningless.
    pub fn validate(&self) -> Result<(), RigError> {
        let positive: [(&'static str, f64); 10] = [
            ("pump.displacement_cm3", self.pump.displacement_cm3),
            ("motor.r25_ohm", self.motor.r25_ohm),
            ("motor.torque_constant_nm_per_a", self.motor.torque_constant_nm_per_a),
            ("blocks.loop_oil_m3", self.blocks.loop_oil_m3),
            ("pump.case_oil_m3", self.pump.case_oil_m3),
            ("hydraulics.bulk_modulus_pa", self.hydraulics.bulk_modulus_pa),
            ("actuator.ram_area_m2", self.actuator.ram_area_m2),
            ("nuisance.metal_capacity_scale", self.nuisance.metal_capacity_scale),
            ("nuisance.oil_capacity_scale", self.nuisance.oil_capacity_scale),
            ("blocks.sensor_tau_s", self.blocks.sensor_tau_s),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(RigError::Invalid(name, format!("must be > 0, got {v}")));
            }
        }
        let cs = self.pump.friction_pairs.case_share_scale;
        if !(cs.is_finite() && cs > 0.0) {
            return Err(RigError::Invalid("pump.friction_pairs.case_share_scale", format!("must be > 0 (1: the sliding-pair rule alone), got {cs}")));
        }
        let pr = self.probes;
        for (name, f) in [("probes.motor", pr.motor), ("probes.pump", pr.pump), ("probes.main_block", pr.main_block), ("probes.ball_block", pr.ball_block)] {
            if !(f.is_finite() && (-0.5..0.5).contains(&f)) {
                return Err(RigError::Invalid(name, format!("must be within -0.5..0.5 (the fraction of metal − ambient the probe reads towards ambient; 0: on the metal), got {f}")));
            }
        }
        let dts = self.blocks.duct_turbulent_scale;
        if !(dts.is_finite() && dts > 0.0) {
            return Err(RigError::Invalid("blocks.duct_turbulent_scale", format!("must be > 0 (1: eq. 14 as printed), got {dts}")));
        }
        if !(self.pump.case_churn.is_finite() && self.pump.case_churn > 0.0) {
            return Err(RigError::Invalid("pump.case_churn", format!("must be > 0 (1: the gap law alone), got {}", self.pump.case_churn)));
        }
        if !(self.pump.case_churn_speed_exp.is_finite() && self.pump.case_churn_speed_exp.abs() <= 2.0) {
            return Err(RigError::Invalid("pump.case_churn_speed_exp", format!("must be within -2..2 (0: the gap law's own), got {}", self.pump.case_churn_speed_exp)));
        }
        if self.ext.viscosity_temperature.is_some() {
            return Err(RigError::Invalid(
                "ext.viscosity_temperature",
                "no longer exists: the oil's viscosity always follows its Walther line (oil.nu40_cst, oil.nu100_cst); remove the line".into(),
            ));
        }
        if self.outside.ram_property_c.is_some() {
            return Err(RigError::Invalid(
                "outside.ram_property_c",
                "no longer exists: ram-air properties are taken at the air temperature and the pressure of outside.altitude_m; remove the line".into(),
            ));
        }
        if !(self.outside.altitude_m.is_finite() && (-500.0..=11_000.0).contains(&self.outside.altitude_m)) {
            return Err(RigError::Invalid("outside.altitude_m", format!("must be within -500..11000 m (troposphere), got {}", self.outside.altitude_m)));
        }
        for u in &self.uncertain {
            if u.name.is_empty() || u.keys.is_empty() || u.source.trim().is_empty() {
                return Err(RigError::Invalid("uncertain", format!("`{}`: needs a name, keys and a source", u.name)));
            }
            if !(u.low.is_finite() && u.high.is_finite() && 0.0 < u.low && u.low <= 1.0 && u.high >= 1.0) {
                return Err(RigError::Invalid("uncertain", format!("`{}`: the range {}..{} must hold the nominal (0 < low <= 1 <= high)", u.name, u.low, u.high)));
            }
        }
        if let Some(tau) = self.ext.sensor_lag {
            if !(tau.is_finite() && tau > 0.0) {
                return Err(RigError::Invalid("ext.sensor_lag", format!("must be > 0 s, got {tau}")));
            }
        }
        Ok(())
    }

    /// This rig with the pump as it is built ([`PumpSplit::a_priori`],
    /// [`Joints::a_priori`]) and the three calibrated values refitted to
    /// Table 4 with it (`eha-sim calibrate`, 1fb1418: loop_area_scale 3.932,
    /// loop oil 1.145 L, η_m 0.476; the ram-air share stays at its bound 1).
    /// The optional structure whose measured misses `pump_energy.rs` asserts.
    pub fn with_pump_as_built(mut self) -> Self {
        self.pump.split = Some(PumpSplit::a_priori());
        self.joints = Some(Joints::a_priori());
        self.pump.eta_m = 0.475_534;
        self.blocks.loop_oil_m3 = 1.145_368e-3;
        self.blocks.loop_area_scale = 3.931_983;
        self
    }

    /// Pump displacement, m³/rad.
    pub fn displacement_m3_per_rad(&self) -> f64 {
        self.pump.displacement_cm3 * 1e-6 / (2.0 * PI)
    }
}
