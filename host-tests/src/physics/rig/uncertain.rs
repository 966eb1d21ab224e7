//! What a machine leaves open: surface probes' placement, the calibration's
//! nuisance multipliers, the uncertain parameters and the model extensions.

use super::*;

/// Where each surface thermocouple sits between its metal and the ambient
/// air: the reading is `T_metal − f·(T_metal − T_ambient)` (a probe cemented
/// or clamped on a housing, its leads and the air around it, reads part of
/// the way towards the air). 0: the probe reads its metal (the rig file).
/// A measurement model of the logged surface channels only: the reference's
/// node temperatures and the firmware model do not change. Calibrated by
/// the `probe_surface_*` parameters (`calibration::set`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceProbes {
    /// Motor housing probe (Point 1, `t_motor_c`), fraction towards ambient.
    #[serde(default)]
    pub motor: f64,
    /// Pump housing probe (Point 3, `t_pump_c`), fraction towards ambient.
    #[serde(default)]
    pub pump: f64,
    /// Main valve block probe (Point 4, `t_block_c`), fraction towards ambient.
    #[serde(default)]
    pub main_block: f64,
    /// Ball-valve block probe (Point 5, `t_ballvalve_c`), fraction towards ambient.
    #[serde(default)]
    pub ball_block: f64,
}

impl SurfaceProbes {
    /// Whether every probe reads its metal (nothing to write in a rig file).
    pub fn is_zero(&self) -> bool {
        *self == SurfaceProbes::default()
    }
}

/// Nuisance multipliers: the parameters a thermal engineer does not know on a
/// new rig. All 1 in the paper rig. The diagnosis calibrates them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Nuisance {
    /// Multiplier on every outer (free convection + radiation) conductance.
    pub outer_scale: f64,
    /// Multiplier on every oil-to-metal conductance.
    pub inner_scale: f64,
    /// Multiplier on every metal heat capacity.
    pub metal_capacity_scale: f64,
    /// Multiplier on every oil heat capacity.
    pub oil_capacity_scale: f64,
}

/// One uncertain parameter group of the rig (`[[uncertain]]` in the rig file),
/// sampled by `eha-sim uq` (Latin hypercube, log-uniform): every field of
/// [`Uncertain::keys`] is multiplied by one factor between [`Uncertain::low`]
/// and [`Uncertain::high`] (the nominal, factor 1, inside). The ranges and their
/// sources are docs/calibration.md's "Uncertain parameters".
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Uncertain {
    /// Short name (a column of the sample table).
    pub name: String,
    /// Rig-file keys scaled together, as [`Rig::set_override`] names them.
    pub keys: Vec<String>,
    /// Lowest factor on the nominal (≤ 1).
    pub low: f64,
    /// Highest factor on the nominal (≥ 1).
    pub high: f64,
    /// Where the range comes from.
    pub source: String,
}

impl Uncertain {
    fn new(name: &str, keys: &[&str], low: f64, high: f64, source: &str) -> Self {
        Uncertain { name: name.into(), keys: keys.iter().map(|k| (*k).to_string()).collect(), low, high, source: source.into() }
    }

    /// The documented ranges of the paper rig (committed before any band was
    /// computed; docs/calibration.md). The three stage-1 values and the ram-air
    /// share are fitted, not sampled: each sample would need its own refit.
    pub fn paper_ranges() -> Vec<Uncertain> {
        vec![
            Uncertain::new(
                "leak_gap",
                &["pump.gaps.piston_gap_m", "pump.gaps.slipper_gap_m", "pump.gaps.port_gap_m"],
                0.75,
                1.25,
                "assumed 12 µm films; 9–15 µm is the running-gap range of a small axial-piston unit (Ivantysyn & Ivantysynova, Hydrostatic Pumps and Motors, 2001, ch. 5)",
            ),
            Uncertain::new("no_load_torque", &["pump.no_load_torque_nm"], 0.5, 2.0, "assumed 0.3 N·m: lip seal 0.1–0.3 N·m plus two rolling bearings 0.05–0.3 N·m (SKF bearing friction model)"),
            Uncertain::new(
                "viscous_torque",
                &["pump.viscous_torque_coeff"],
                0.5,
                2.0,
                "assumed C_v = 5e4: the order of Wilson-model coefficients of small axial-piston units (Manring, Hydraulic Control Systems, 2005), a factor 2 either way",
            ),
            Uncertain::new("oil_nu40", &["oil.nu40_cst"], 0.9, 1.1, "ISO 3448: an ISO VG 46 oil has 41.4–50.6 cSt at 40 °C"),
            Uncertain::new("oil_nu100", &["oil.nu100_cst"], 0.93, 1.07, "VG 46 hydraulic oils (HM/HV, VI 95–140): 6.4–7.3 cSt at 100 °C (data sheets)"),
            Uncertain::new("oil_cp", &["oil.cp20_j_per_kg_k"], 0.95, 1.05, "mineral oils 1.79–1.97 kJ/(kg·K) at 20 °C (Cragoe; data sheets)"),
            Uncertain::new("oil_k", &["oil.k0_w_per_m_k"], 0.93, 1.07, "mineral oils 0.125–0.143 W/(m·K) (Cragoe; data sheets)"),
            Uncertain::new("case_area", &["pump.case_inner_area_m2"], 0.7, 1.4, "assumed 0.02 m² of inner case wetted by the case oil (a 19 cm³/rev housing), 0.014–0.028 m²"),
            Uncertain::new("case_gap", &["pump.case_gap_m"], 0.67, 1.33, "assumed 3 mm radial gap barrel–case, 2–4 mm"),
            Uncertain::new("port_area", &["pump.port_area_scale"], 0.7, 1.4, "the port passage as drawn (assumed Ø12 × 50 mm); cross drillings and kidneys add area"),
            Uncertain::new("inner_films", &["nuisance.inner_scale"], 0.85, 1.15, "duct film correlations (Hausen, Gnielinski): ±10–15 % scatter on their data"),
            Uncertain::new("outer_convection", &["nuisance.outer_scale"], 0.8, 1.2, "free convection correlations (Churchill–Chu, McAdams): ±20 % on real housings with fins, flanges and bolts"),
            Uncertain::new("emissivity", &["outside.emissivity"], 0.82, 1.12, "assumed 0.85: painted or oxidised steel and cast iron 0.7–0.95 (Incropera, table A.11)"),
            Uncertain::new("metal_capacity", &["nuisance.metal_capacity_scale"], 0.95, 1.05, "Table 2's masses to a few per cent; steel and cast iron c_p 440–490 J/(kg·K)"),
            Uncertain::new("mount", &["blocks.mount_w_per_k"], 0.5, 2.0, "assumed 2 W/K: a 100 × 100 mm foot, dry painted contact 100–400 W/(m²·K) (Madhusudana, Thermal Contact Conductance, 2014)"),
            Uncertain::new("sensor_tau", &["blocks.sensor_tau_s"], 0.5, 5.0, "assumed 2 s: sheathed probes in thermowells in flowing oil answer in 1–10 s (t63)"),
            Uncertain::new("winding_r", &["motor.r25_ohm"], 0.97, 1.03, "Table 2's 0.074 Ω, read to two digits"),
        ]
    }
}

/// The switchable model extensions; all off (`None`/`false`) in the baseline.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Extensions {
    /// `winding-resistance-temperature`: copper resistance coefficient α, 1/K.
    pub winding_resistance_temperature: Option<f64>,
    /// Removed: the viscosity always follows the oil's Walther line at each
    /// node's temperature. Present only to refuse old rig files clearly.
    #[serde(default, skip_serializing)]
    pub viscosity_temperature: Option<bool>,
    /// `sensor-lag`: time constant of the manifold sensor in its dead-end branch, s.
    pub sensor_lag: Option<f64>,
    /// `coulomb-friction`: Coulomb friction force of the piston seals, N.
    pub coulomb_friction: Option<f64>,
    /// `churning-loss`: churning coefficient, W/(rad/s)^2.5.
    pub churning_loss: Option<f64>,
    /// `motor-pump-conduction`: motor-to-pump-housing conductance through the flange, W/K.
    pub motor_pump_conduction: Option<f64>,
    /// `forced-convection`: unlogged air speed over the housings, m/s.
    pub forced_convection: Option<f64>,
}
