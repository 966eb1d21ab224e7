//! The housings' structure: conduction paths and joints, the metal blocks,
//! the hydraulic lines, the actuator and the outside air (eqs. 12–19).

use super::*;

/// A conduction path through a wall and a bolted or seated joint:
/// G = 1 / (L/(k·A) + 1/(h_c·A_c)) (eq. 18's k·A/L in series with a contact
/// conductance), W/K. The body on the far side is lumped at its mean
/// temperature, its own spreading resistance is left out (it would lower G).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallPath {
    /// Thermal conductivity of the wall's material, W/(m·K).
    pub k_w_per_m_k: f64,
    /// Cross-section of the wall the heat flows through, m².
    pub area_m2: f64,
    /// Length of the conduction path through the wall, m.
    pub length_m: f64,
    /// Area of the joint, m².
    pub contact_area_m2: f64,
    /// Contact conductance of the joint, W/(m²·K).
    pub contact_w_per_m2_k: f64,
}

impl WallPath {
    /// Conductance of the path, W/K (0 when any part is 0).
    pub fn conductance_w_per_k(&self) -> f64 {
        let wall = self.k_w_per_m_k * self.area_m2 / self.length_m;
        let joint = self.contact_w_per_m2_k * self.contact_area_m2;
        crate::heat::series(wall, joint)
    }
}

/// Metal paths from the pump housing to its neighbours (a priori, no fitted
/// value; docs/calibration.md, "The pump as it is built").
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Joints {
    /// Pump housing → motor flange: the housing's cylindrical wall from its
    /// mid-length to the mounting flange, then the bolted flange face.
    pub pump_motor: WallPath,
    /// Pump housing → manifold (the main block): the end cap's wall to the
    /// port face, then the bolted port face.
    pub pump_manifold: WallPath,
}

impl Joints {
    /// The a-priori values (committed in 8971154 before any run with them):
    /// grey cast iron housing (EN-GJL-250, 48 W/(m·K); an aluminium housing
    /// would be ≈ 150), the wall Ø112 mm mean × 8 mm; dry bolted faces
    /// 2000 W/(m²·K) (500–5000).
    pub fn a_priori() -> Self {
        Joints {
            pump_motor: WallPath { k_w_per_m_k: 48.0, area_m2: 2.8e-3, length_m: 0.06, contact_area_m2: 7.5e-3, contact_w_per_m2_k: 2000.0 },
            pump_manifold: WallPath { k_w_per_m_k: 48.0, area_m2: 2.8e-3, length_m: 0.05, contact_area_m2: 4.0e-3, contact_w_per_m2_k: 2000.0 },
        }
    }
}

/// The two valve blocks and the oil in them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Blocks {
    /// Mass of the main valve block, kg (Table 2 gives 190 kg for the valve
    /// blocks; the split between the two blocks is assumed).
    pub main_mass_kg: f64,
    /// Outer area of the main block, m² (Table 2 gives 0.44 m² in all; split assumed).
    pub main_area_m2: f64,
    /// Mass of the ball/needle-valve block, kg (assumed split of Table 2).
    pub ball_mass_kg: f64,
    /// Outer area of the ball/needle-valve block, m² (assumed split of Table 2).
    pub ball_area_m2: f64,
    /// Block specific heat, J/(kg·K) (steel, 460).
    pub cp: f64,
    /// Circulating-oil volume (main-block passages, hoses, accumulator side), m³ (calibrated).
    pub loop_oil_m3: f64,
    /// Main-block passage diameter, m (assumed).
    pub loop_d_m: f64,
    /// Main-block passage length, m (assumed).
    pub loop_len_m: f64,
    /// Main-block wetted-area multiplier (calibrated).
    pub loop_area_scale: f64,
    /// Oil volume in the ball/needle-valve block, m³ (assumed).
    pub ball_oil_m3: f64,
    /// Ball/needle-valve block passage diameter, m (assumed).
    pub ball_d_m: f64,
    /// Ball/needle-valve block passage length, m (assumed).
    pub ball_len_m: f64,
    /// Oil volume of the manifold temperature-sensor pocket, m³ (assumed).
    pub sensor_oil_m3: f64,
    /// Time constant of the sensor pocket in the baseline (sensor in the
    /// flowing manifold), s (assumed).
    pub sensor_tau_s: f64,
    /// Conductance of the sensor pocket to the block metal in the
    /// dead-end geometry of Figs. 9–10 (extension `sensor-lag`), W/K (assumed).
    pub sensor_to_block_w_per_k: f64,
    /// Conductance from the main block to the test bench it is bolted to
    /// (the bench held at the air temperature), W/K (assumed 2 W/K: a
    /// 100 × 100 mm foot, dry painted contact of about 200 W/(m²·K)).
    pub mount_w_per_k: f64,
    /// Block wall thickness between passages and surface for eq. (18), m (assumed).
    pub wall_m: f64,
    /// Steel conductivity, W/(m·K).
    pub steel_k: f64,
    /// Factor on the turbulent Nusselt number of every oil duct's film
    /// (eq. 14, Gnielinski), and so on its share of the transition blend
    /// between Re 2300 and 10⁴ (`crate::heat::nu_tube_turb`): 1, the
    /// paper's law (the rig file; calibrated by `duct_turbulent` when the
    /// logs run the passages' flow through the transition hot).
    #[serde(default = "super::machine::one")]
    pub duct_turbulent_scale: f64,
}

/// Hydraulic circuit: lines, pressures, valves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hydraulics {
    /// Effective bulk modulus of oil plus hoses, Pa (assumed 7e8: pure oil
    /// is 1.6e9; hose compliance and entrained air halve it and more).
    pub bulk_modulus_pa: f64,
    /// Oil volume of each pump-port line up to the valves, m³ (assumed).
    pub line_volume_m3: f64,
    /// Accumulator (boost) pressure, Pa gauge (assumed).
    pub accumulator_pa: f64,
    /// Check-valve flow gain, m³/(s·Pa) (assumed).
    pub check_gain: f64,
    /// Relief-valve cracking pressure, Pa (assumed).
    pub relief_crack_pa: f64,
    /// Relief-valve flow gain above cracking, m³/(s·Pa) (assumed).
    pub relief_gain: f64,
    /// Case 1 flow path (ball valve, needle valve, hoses) for eq. (10) (assumed).
    pub path: Line,
}

/// Cylinder, load and position loop (Table 3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Actuator {
    /// Effective ram area, m² (Table 3: 1526.81 mm²).
    pub ram_area_m2: f64,
    /// Stroke, m (Table 3: 100 mm, i.e. ±50 mm).
    pub stroke_m: f64,
    /// Load mass, kg (Table 3: 13.5 kg).
    pub load_mass_kg: f64,
    /// Spring stiffness, N/m (Table 3: 245 N/mm).
    pub spring_n_per_m: f64,
    /// Spring damping, N·s/m (Table 3: 15 N/(mm/s)).
    pub damping_n_s_per_m: f64,
    /// Viscous seal friction of the piston, N·s/m (assumed; the paper's model has only viscous friction).
    pub viscous_friction_n_s_per_m: f64,
    /// Cross-piston leakage coefficient of eq. (11), m³/(s·Pa) (assumed).
    pub leak_m3_per_s_pa: f64,
    /// Cylinder body mass (with its oil), kg (assumed).
    pub body_mass_kg: f64,
    /// Body specific heat, J/(kg·K) (steel).
    pub body_cp: f64,
    /// Outer area, m² (assumed).
    pub area_m2: f64,
    /// Outer diameter, m (assumed).
    pub diameter_m: f64,
    /// Position-loop gain, 1/s (assumed; Case 2 controller).
    pub position_gain_per_s: f64,
}

/// Outer heat transfer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Outside {
    /// Surface emissivity of the painted housings, eq. (19) (assumed 0.85).
    pub emissivity: f64,
    /// Flat-plate run length of the ram-air correlation, m (set so that the
    /// 15 m/s coefficient is Table 5's 66.13 W/(m²·K)).
    pub ram_run_length_m: f64,
    /// Share of the pump housing's outer area that the ram air reaches (the
    /// rest stays in free convection: flange, shadowed faces), fitted to
    /// Table 5's pump shell at 30 m/s.
    pub pump_ram_exposure: f64,
    /// Altitude of the air around the rig, m: its static pressure (ICAO
    /// standard atmosphere) sets the air density of free and forced
    /// convection (0: sea level, the paper's laboratory).
    #[serde(default)]
    pub altitude_m: f64,
    /// Removed: ram-air properties are now taken at the air temperature and
    /// the altitude's pressure. Present only to refuse old rig files clearly.
    #[serde(default, skip_serializing)]
    pub ram_property_c: Option<f64>,
}

impl Outside {
    /// Static pressure of the air, Pa (ISA at [`Outside::altitude_m`]).
    pub fn air_pressure_pa(&self) -> f64 {
        crate::air::isa_pressure_pa(self.altitude_m)
    }
}
