//! The motor and the pump: nameplate, losses and where the pump's heat
//! goes (Tables 2–3, eqs. 1–11).

use super::*;

/// Motor (servo PMSM of the Moog EPU) parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Motor {
    /// Number of phases m, eq. (1) (three-phase PMSM).
    pub phases: f64,
    /// Phase resistance at 25 °C, Ω (Table 2: 0.074 Ω).
    pub r25_ohm: f64,
    /// Winding inductance, H (Table 2: 1.433 mH; not needed thermally).
    pub inductance_h: f64,
    /// Maximum current, A rms (Table 2: 340.5 A).
    pub max_current_a: f64,
    /// Torque constant, N·m/A rms (assumed: not in the paper).
    pub torque_constant_nm_per_a: f64,
    /// Stator iron-loss coefficients, eq. (2) (assumed).
    pub iron: IronLoss,
    /// Bearing friction torque k_m·M_m of eq. (3), N·m; `None` = off (the
    /// paper neglects it, eq. 4).
    pub bearing_friction_nm: Option<f64>,
    /// Total motor mass, kg (Table 2: 75 kg).
    pub mass_kg: f64,
    /// Winding (copper) mass, kg (assumed).
    pub winding_mass_kg: f64,
    /// Copper specific heat, J/(kg·K) (385).
    pub winding_cp: f64,
    /// Specific heat of the rest of the motor, J/(kg·K) (steel/aluminium mix, assumed 500).
    pub body_cp: f64,
    /// Outer area, m² (Table 2: 0.5 m²).
    pub area_m2: f64,
    /// Outer diameter for eq. (15), m (assumed).
    pub diameter_m: f64,
    /// Winding-to-housing conductance, W/K (assumed).
    pub winding_to_housing_w_per_k: f64,
    /// Speed-loop time constant of the drive, s (assumed).
    pub speed_time_constant_s: f64,
    /// Speed limit, rpm (assumed).
    pub max_speed_rpm: f64,
}

/// Serde default of a factor that is 1 unless the rig file says otherwise.
pub(super) fn one() -> f64 {
    1.0
}

/// Piston pump and its housing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pump {
    /// Displacement, cm³/rev (Table 2: 19).
    pub displacement_cm3: f64,
    /// Leakage gaps of eqs. (5)–(7) (assumed: 12 µm films of a 19 cm³/rev
    /// nine-piston pump; none of them is fitted).
    pub gaps: PumpGaps,
    /// Pressure-proportional friction coefficient of eq. (8), C_p = η_m: the
    /// friction torque's load term is η_m·D·|Δp| (calibrated).
    pub eta_m: f64,
    /// No-load friction torque T₀ of the extended eq. (8), N·m: shaft seal and
    /// bearings, independent of pressure and speed (assumed, see
    /// `docs/calibration.md`).
    pub no_load_torque_nm: f64,
    /// Viscous friction coefficient C_v of the extended eq. (8) (Wilson's
    /// model: T_v = C_v·μ·D·|ω|), dimensionless (assumed).
    pub viscous_torque_coeff: f64,
    /// How the viscous and pressure friction heat divides between the sliding
    /// pairs, and so between the delivered oil, the case oil and the housing
    /// (assumed; not used when [`Pump::split`] is set).
    pub friction_pairs: FrictionPairs,
    /// The pump as it is built: its internals a node of their own, every
    /// sliding pair's faces on them (optional, **off by default**; a priori
    /// values in [`PumpSplit::a_priori`], docs/calibration.md "The pump as it
    /// is built": measured, they miss the issue's targets by far, so the
    /// baseline keeps one pump node). Without it the internals node follows
    /// the housing and holds no heat.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub split: Option<PumpSplit>,
    /// Pump mass, kg (Table 2: 20 kg).
    pub mass_kg: f64,
    /// Housing specific heat, J/(kg·K) (steel, 460).
    pub cp: f64,
    /// Outer area, m² (Table 2: 0.1 m²).
    pub area_m2: f64,
    /// Outer diameter for eq. (15), m (assumed).
    pub diameter_m: f64,
    /// Oil volume of the pump case (drain side), m³ (assumed).
    pub case_oil_m3: f64,
    /// Oil volume of each port passage, m³ (assumed).
    pub port_oil_m3: f64,
    /// Inner case area wetted by the case oil around the rotating group
    /// (cylinder wall and end faces), m² (assumed from a 19 cm³/rev housing).
    pub case_inner_area_m2: f64,
    /// Radial gap between the rotating cylinder barrel and the case, m (assumed).
    pub case_gap_m: f64,
    /// The case film churned by the rotating group: factor on the gap's
    /// laminar Taylor–Couette film at [`crate::network::CASE_CHURN_REF_RAD_S`]
    /// (oil at 40 °C), blended in above
    /// [`crate::network::CASE_CHURN_ONSET_RAD_S`]; the gap law stays the
    /// floor at rest (`crate::network::case_churn_factor`). 1: the gap law
    /// alone (the rig file; calibrated by `case_churn` from a drain
    /// thermocouple).
    #[serde(default = "one")]
    pub case_churn: f64,
    /// Speed exponent added to the churned case film's law (in the gap's
    /// Reynolds number ω·r·e/ν): 0, the gap law's own (the rig file;
    /// calibrated by `case_churn_speed`).
    #[serde(default)]
    pub case_churn_speed_exp: f64,
    /// Outer radius of the rotating cylinder barrel, m (assumed).
    pub rotor_radius_m: f64,
    /// Port passage diameter, m (assumed).
    pub port_d_m: f64,
    /// Port passage length, m (assumed).
    pub port_len_m: f64,
    /// Port-passage wetted area multiplier (assumed 1: the passage as drawn).
    pub port_area_scale: f64,
}

/// Shares of the pump's viscous and pressure friction (the C_v and C_p terms
/// of the extended eq. 8) by sliding pair. The rule that places each pair's
/// heat (docs/calibration.md): the piston/bore film is swept by the displaced
/// oil every stroke (all to the delivered oil); the slipper/swash-plate film
/// lies between the case oil and the swash plate, which sits in the housing
/// (half to the case oil, half to the housing metal); the valve-plate film
/// lies between the kidney ports' oil and the port plate bolted to the
/// housing (half to the delivered oil, half to the housing metal). The
/// no-load torque (bearings, shaft seal, both seated in the housing) heats
/// the housing metal.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionPairs {
    /// Piston/bore share (assumed 0.5).
    pub piston_bore: f64,
    /// Slipper/swash-plate share (assumed 0.3).
    pub slipper_swash: f64,
    /// Valve-plate share (assumed 0.2).
    pub valve_plate: f64,
    /// Factor on the case oil's share of the rule above (the delivered oil's
    /// and the housing's scaled down together so that the shares still add
    /// up to 1): the leakage through the piston and slipper gaps carries
    /// their films' heat into the case, which the rule does not count.
    /// 1: the rule alone (the rig file; calibrated by `friction_case` from a
    /// drain thermocouple).
    #[serde(default = "one")]
    pub case_share_scale: f64,
}

impl FrictionPairs {
    /// Shares of the C_v and C_p friction heat that enter (delivered oil,
    /// case oil, housing metal); they add up to 1. The case oil's share of
    /// the pairs' rule times [`FrictionPairs::case_share_scale`] (at most
    /// 0.95).
    pub fn shares(&self) -> (f64, f64, f64) {
        let sum = self.piston_bore + self.slipper_swash + self.valve_plate;
        let (p, s, v) = (self.piston_bore / sum, self.slipper_swash / sum, self.valve_plate / sum);
        let (del, case, metal) = (p + 0.5 * v, 0.5 * s, 0.5 * s + 0.5 * v);
        if self.case_share_scale == 1.0 {
            return (del, case, metal);
        }
        let case_k = (case * self.case_share_scale).min(0.95);
        let rest = (1.0 - case_k) / (1.0 - case);
        (del * rest, case_k, metal * rest)
    }
}

/// The pump split into its internals and its housing (optional structure,
/// [`Pump::split`]; every value a priori, none fitted: docs/calibration.md,
/// "The pump as it is built"). The viscous and pressure friction of the
/// extended eq. (8) arises in the three lubricating films, whose faces all
/// belong to the internals; the no-load term divides by
/// [`PumpSplit::no_load_to_housing`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PumpSplit {
    /// Share of the no-load friction T₀·|ω| (bearings, shaft seal) that heats
    /// the housing, the rest the internals (a priori 0.5: each rolling
    /// bearing's heat leaves through both races, the inner on the shaft, the
    /// outer in the housing; the lip seal sits in the housing's front cover;
    /// range 0.3–0.7).
    pub no_load_to_housing: f64,
    /// Mass of the pump's internals: cylinder barrel, pistons and slippers,
    /// swash and valve plates, shaft, kg (a priori 3.5 kg, range 2.5–5.0:
    /// steel parts sized from this rig file's barrel radius 30 mm, nine
    /// 10 mm pistons and the 26.9 mm stroke of 19 cm³/rev — barrel ≈ 1.0,
    /// pistons and slippers ≈ 0.35, swash plate ≈ 1.0, valve plate ≈ 0.25,
    /// shaft ≈ 0.4, bearings and retainer ≈ 0.5 kg). The housing is the rest
    /// of Table 2's 20 kg.
    pub internals_mass_kg: f64,
    /// Area of the displacement chambers (bores and piston faces) wetted by
    /// the port oil, both kidneys together, m² (a priori 5.9e-3, range
    /// 4e-3–8e-3: nine 10 mm bores over the mean chamber length of 18.4 mm,
    /// a 5 mm dead length plus half the stroke, and the piston faces). Half
    /// of it exchanges with each port's oil through a laminar developing duct
    /// film (eq. 13) of the bores' share of the flow.
    pub bore_area_m2: f64,
    /// Area of the internals swept through the case oil (slippers, piston
    /// shanks outside the bores, retainer plate), m² (a priori 7e-3, range
    /// 5e-3–1e-2: nine slippers of about 3e-4 m² and nine shanks of 10 mm
    /// over a mean exposed 15 mm). Laminar flat-plate film (Pohlhausen,
    /// Nu = 0.664·Re^½·Pr^⅓) over the slipper length at the barrel's rim
    /// speed; the barrel's own periphery exchanges through the Taylor–Couette
    /// film of the case gap ([`Pump::case_gap_m`]).
    pub case_swept_area_m2: f64,
    /// Characteristic length of the swept surfaces, m (a priori 0.015: a
    /// slipper's length; range 0.01–0.025).
    pub swept_length_m: f64,
    /// Length of the barrel (its periphery faces the case gap), m (a priori
    /// 0.06, range 0.05–0.07: about twice the 26.9 mm stroke).
    pub barrel_length_m: f64,
    /// Conduction internals → housing through the swash plate's cradle and
    /// the valve plate's seat on the end cap.
    pub seats: WallPath,
}

impl PumpSplit {
    /// The a-priori values (committed in 8971154 before any run with them).
    pub fn a_priori() -> Self {
        Self {
            no_load_to_housing: 0.5,
            internals_mass_kg: 3.5,
            bore_area_m2: 5.9e-3,
            case_swept_area_m2: 7.0e-3,
            swept_length_m: 0.015,
            barrel_length_m: 0.06,
            // swash plate (20 mm) and valve plate (8 mm), steel (45 W/(m·K)),
            // 6.1e-3 m² of seat in all, oil-filled machined joints under the
            // hydraulic load: 5000 W/(m²·K) (2000–20000)
            seats: WallPath { k_w_per_m_k: 45.0, area_m2: 6.1e-3, length_m: 0.014, contact_area_m2: 6.1e-3, contact_w_per_m2_k: 5000.0 },
        }
    }
}
