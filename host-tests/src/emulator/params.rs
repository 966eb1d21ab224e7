//! Parameters of the rig emulator, and where they differ from the rig file
//! (`host-tests/rig/liu2024.toml`, i.e. `eha_sim::rig::Rig::default()`).
//!
//! Table 2/3 quantities of the paper (displacement, R25, masses and areas in
//! total, ram area, spring, load) are the paper's. Everything the paper
//! leaves open was chosen again for the emulator, as a second engineer
//! building the same rig would: see [`EmuParams::deviations`] for the list
//! with the rig file's counterpart and the ratio. On top of these nominal
//! values every generated log draws the [`DRAWN`] parameters log-uniformly
//! within ×/÷ [`DRAW_SPREAD`] (seeded), so no two logs share a machine.

use rand::Rng;

/// Spread of the per-log draw of the [`DRAWN`] parameters (factor).
pub const DRAW_SPREAD: f64 = 1.3;

/// Parameters of the emulated rig (SI units; conductances W/K,
/// capacities J/K, areas m², volumes m³).
#[derive(Debug, Clone, PartialEq)]
pub struct EmuParams {
    /// Winding phase resistance at 25 °C, Ω (Table 2).
    pub r25_ohm: f64,
    /// Motor torque constant, N·m/A rms.
    pub kt_nm_per_a: f64,
    /// Iron-loss coefficients of eq. (2): hysteresis, eddy, excess.
    pub iron_k: [f64; 3],
    /// Peak flux density of eq. (2), T.
    pub b_peak_t: f64,
    /// Pole pairs (electrical frequency f = p·n/60).
    pub pole_pairs: f64,
    /// Stator (copper plus laminations, one node), J/K.
    pub c_stator: f64,
    /// Motor housing, J/K.
    pub c_motor_case: f64,
    /// Stator-to-housing conductance, W/K.
    pub g_stator_case: f64,
    /// Pump displacement, m³/rev (Table 2).
    pub displacement_m3: f64,
    /// Common film thickness of the three leakage gaps of eqs. (5)–(7), m.
    pub gap_m: f64,
    /// Pump mechanical-loss coefficient η_m of eq. (8).
    pub eta_m: f64,
    /// Shares of the eq. (8) loss: delivered oil, case oil, port-plate metal.
    pub mech_split: [f64; 3],
    /// Pump barrel (Point 3 side) and port end cap, J/K.
    pub c_pump: [f64; 2],
    /// Barrel to end-cap conduction, W/K.
    pub g_barrel_end: f64,
    /// Case oil volume, m³.
    pub v_case: f64,
    /// Case-oil wetted areas on barrel and end cap, m².
    pub a_case: [f64; 2],
    /// Rotating-group radius, m.
    pub r_rotor: f64,
    /// Port-passage oil volume (both ports), m³.
    pub v_port: f64,
    /// Port passages: diameter, length, wetted area (both), m, m, m².
    pub port_duct: [f64; 3],
    /// Pump end cap to manifold plate bolted-joint conductance, W/K.
    pub g_end_manifold: f64,
    /// Manifold plate (pump mounting part of the main block), J/K.
    pub c_manifold: f64,
    /// Manifold plate to main block conduction, W/K.
    pub g_manifold_block: f64,
    /// Circulating manifold oil volume, m³.
    pub v_loop: f64,
    /// Manifold passages in the plate: diameter, length, wetted area.
    pub plate_duct: [f64; 3],
    /// Main-block passages and accumulator port: diameter, length, wetted area.
    pub block_duct: [f64; 3],
    /// Main block (Point 4), J/K.
    pub c_block: f64,
    /// Ball/needle-valve block (Point 5), J/K.
    pub c_ball: f64,
    /// Ball block to main block bolted-joint conductance, W/K.
    pub g_ball_block: f64,
    /// Ball-block oil volume, m³.
    pub v_ball: f64,
    /// Ball-block passages: diameter, length, wetted area.
    pub ball_duct: [f64; 3],
    /// Throttle hoses for eq. (10): length, diameter, local loss ξ.
    pub hose: [f64; 3],
    /// Needle discharge coefficient.
    pub needle_cd: f64,
    /// Boost (accumulator) pressure, Pa.
    pub boost_pa: f64,
    /// Cylinder barrel, J/K; chamber oil volume, m³; film area, m².
    pub cyl: [f64; 3],
    /// Viscous seal friction, N·s/m.
    pub seal_viscous: f64,
    /// Cross-piston leakage, m³/(s·Pa) (eq. 11).
    pub act_leak: f64,
    /// Position-loop gain, 1/s.
    pub pos_gain: f64,
    /// Outer surfaces: motor, pump barrel, pump end, manifold, main block,
    /// ball block, cylinder: (area m², height m, diameter m).
    pub surfaces: [[f64; 3]; 7],
    /// Surface emissivity (eq. 19).
    pub emissivity: f64,
    /// Sensor time constants: motor, pump, block, ball block, oil, s.
    pub sensor_tau: [f64; 5],
    /// Drain-port thermocouple (logged as `t_drain_c` when asked): its
    /// response time to the case (drain) oil, s.
    pub drain_tau_s: f64,
    /// Fraction by which a surface probe reads towards ambient (probe
    /// stem and contact resistance).
    pub probe_ambient_frac: f64,
    /// Weight of the barrel in the Point 3 reading (the rest: end cap).
    pub pump_probe_barrel: f64,
    /// Dead-end sensor pocket (hidden `sensor-lag`): oil volume, m³, and its
    /// conductance to the manifold plate, W/K.
    pub pocket: [f64; 2],
    /// Structural experiment switches: the laws of the machine replaced by
    /// the reference model's (none in every machine: the emulator as
    /// built). For the by-hand structural bisection of a commissioning miss
    /// (docs/commissioning-foreign.md), never set in a test's machine.
    pub like_reference: LikeReference,
}

/// A law of the emulator an experiment can replace by the reference
/// model's, one structural difference each (the parameter-level
/// differences are set on the parameters instead, by the experiment,
/// `tests/calibration/mix_audit.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RefLaw {
    /// The case film is the reference's gap law (conduction across a 3 mm
    /// gap, Nu = 2, rising by the Taylor–Couette law above Ta = 1700) on
    /// the machine's own wetted areas, instead of the rotating cylinder.
    CaseGapFilm,
    /// The rotating cylinder's case film as a function of ω/ν alone, as the
    /// reference's churned film is: its Prandtl number at the 40 °C oil's
    /// (Nu = 2 + 0.133·Re^⅔·Pr₄₀^⅓), the Reynolds number and the
    /// conductivity at the oil's temperature.
    CaseFilmOmegaNu,
    /// No iron-loss drag torque in the motor current (the reference's shaft
    /// torque has none: its iron loss heats the housing without a torque).
    NoIronDrag,
    /// The port oil as the reference's two nodes (inlet and outlet passage,
    /// half the volume and half the duct area each; the delivered oil's
    /// heat, the leakage and the throttle path leave from the outlet)
    /// instead of one well-mixed node at the outlet's temperature.
    TwoPorts,
    /// The oil films in the ducts (port, manifold, block, ball-valve,
    /// cylinder) by the reference's Nusselt law (eqs. 13/14:
    /// `heat::nu_tube_with` with `heat::nu_laminar_x`) on the machine's own
    /// areas, instead of Hausen/Gnielinski.
    DuctLaw,
    /// [`RefLaw::DuctLaw`] on the manifold, block and ball-valve films
    /// only (the port and cylinder films keep the machine's law).
    DuctLawBlocks,
    /// The manifold, block and ball-valve films in series with the
    /// reference's block wall (eq. 18: steel 45 W/(m·K), 30 mm, on a face
    /// of side √(A/6) of the block's outer area A), as the reference's
    /// `network::block_path` has them.
    BlockWall,
    /// The outer surfaces by the reference's correlations: free convection
    /// of a horizontal cylinder (eq. 15; motor, pump, cylinder) or a cube
    /// (eq. 16, side √(A/6); the blocks), mixed with the flat plate's forced
    /// convection over the rig file's 0.352 m run, instead of Churchill–Chu
    /// vertical sides, McAdams faces and Churchill–Bernstein.
    OuterLaw,
    /// The main block mounted on the bench through 2 W/K to the air
    /// temperature, as the rig file's `blocks.mount_w_per_k` (the machine
    /// has no mount).
    Mount,
}

/// A set of [`RefLaw`]s ([`EmuParams::like_reference`]); empty by default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LikeReference(u16);

impl LikeReference {
    /// The set with `law` added.
    pub fn with(self, law: RefLaw) -> Self {
        Self(self.0 | 1 << law as u16)
    }
    /// Whether `law` is replaced by the reference's.
    pub fn has(self, law: RefLaw) -> bool {
        self.0 & 1 << law as u16 != 0
    }
}

/// Names of the parameters drawn per log (see [`EmuParams::draw`]).
pub const DRAWN: [&str; 10] = [
    "g_stator_case",
    "eta_m",
    "gap_m (leakage ∝ gap³)",
    "iron_k",
    "a_case",
    "plate_duct/block_duct areas",
    "ball_duct area",
    "g_end_manifold",
    "g_manifold_block",
    "emissivity-free outer h (surface areas)",
];

impl Default for EmuParams {
    fn default() -> Self {
        EmuParams {
            r25_ohm: 0.074,
            kt_nm_per_a: 0.9,
            iron_k: [0.18, 0.0015, 0.006],
            b_peak_t: 1.4,
            pole_pairs: 4.0,
            c_stator: 8.0 * 385.0 + 12.0 * 460.0,
            c_motor_case: 55.0 * 480.0,
            g_stator_case: 24.0,
            displacement_m3: 19e-6,
            gap_m: 13.5e-6,
            eta_m: 0.36,
            mech_split: [0.5, 0.3, 0.2],
            c_pump: [12.0 * 460.0, 8.0 * 460.0],
            g_barrel_end: 9.0,
            v_case: 0.25e-3,
            a_case: [0.018, 0.008],
            r_rotor: 0.03,
            v_port: 0.08e-3,
            port_duct: [0.012, 0.06, 2.0 * std::f64::consts::PI * 0.012 * 0.06],
            g_end_manifold: 10.0,
            c_manifold: 25.0 * 460.0,
            g_manifold_block: 14.0,
            v_loop: 1.2e-3,
            plate_duct: [0.010, 0.5, 0.03],
            block_duct: [0.010, 2.0, 0.09],
            c_block: 125.0 * 460.0,
            c_ball: 40.0 * 460.0,
            g_ball_block: 4.0,
            v_ball: 0.08e-3,
            ball_duct: [0.008, 0.4, 0.015],
            hose: [1.2, 0.010, 4.0],
            needle_cd: 0.65,
            boost_pa: 4e5,
            cyl: [9.0 * 460.0, 0.35e-3, 0.03],
            seal_viscous: 1500.0,
            act_leak: 3e-14,
            pos_gain: 25.0,
            surfaces: [
                [0.5, 0.2, 0.2],
                [0.065, 0.12, 0.12],
                [0.035, 0.12, 0.12],
                [0.06, 0.1, 0.15],
                [0.28, 0.25, 0.25],
                [0.10, 0.15, 0.15],
                [0.14, 0.09, 0.09],
            ],
            emissivity: 0.92,
            sensor_tau: [8.0, 8.0, 10.0, 10.0, 6.0],
            drain_tau_s: 3.0,
            probe_ambient_frac: 0.04,
            pump_probe_barrel: 0.65,
            pocket: [5e-6, 0.03],
            like_reference: LikeReference::default(),
        }
    }
}

/// One row of the deviation table: emulator quantity, its value, the rig
/// file's counterpart, that counterpart's value, note (the ratio is
/// value / counterpart value).
pub type Deviation = (&'static str, f64, &'static str, f64, &'static str);

impl EmuParams {
    /// Draws the [`DRAWN`] parameters log-uniformly within ×/÷
    /// [`DRAW_SPREAD`] of their nominal values.
    pub fn draw(rng: &mut impl Rng) -> Self {
        let mut p = EmuParams::default();
        let s = DRAW_SPREAD.ln();
        let mut f = || rng.random_range(-s..s).exp();
        p.g_stator_case *= f();
        p.eta_m *= f();
        p.gap_m *= f().cbrt();
        let fi = f();
        p.iron_k.iter_mut().for_each(|k| *k *= fi);
        let fc = f();
        p.a_case.iter_mut().for_each(|a| *a *= fc);
        let fd = f();
        p.plate_duct[2] *= fd;
        p.block_duct[2] *= fd;
        p.ball_duct[2] *= f();
        p.g_end_manifold *= f();
        p.g_manifold_block *= f();
        let fs = f();
        p.surfaces.iter_mut().for_each(|s| s[0] *= fs.sqrt());
        p
    }

    /// The nominal emulator values against the rig file, with the ratio.
    /// Counterparts are the rig-file fields (their values as in
    /// `host-tests/rig/liu2024.toml`); structural differences (nodes,
    /// joints, correlations) have no counterpart and are listed in the
    /// module doc of [`crate::emulator`].
    pub fn deviations(&self) -> Vec<Deviation> {
        let leak_ratio = (self.gap_m / 12e-6).powi(3);
        let block_m = (self.c_manifold + self.c_block + self.c_ball) / 460.0;
        vec![
            ("kt_nm_per_a", self.kt_nm_per_a, "motor.torque_constant_nm_per_a", 0.75, "current per torque"),
            ("iron_k[0] (all three ×)", self.iron_k[0], "motor.iron.k_h", 0.3, "iron loss eq. 2"),
            ("c_stator J/K (copper + laminations)", self.c_stator, "winding_mass_kg·winding_cp", 8.0 * 385.0, "laminations lumped with the copper"),
            ("c_motor_case J/K", self.c_motor_case, "(mass−winding)·body_cp", 67.0 * 500.0, ""),
            ("g_stator_case W/K", self.g_stator_case, "motor.winding_to_housing_w_per_k", 15.0, ""),
            ("leakage conductance (gap³)", leak_ratio, "pump.gaps.*_gap_m = 12 µm", 1.0, "gap 13.5 µm"),
            ("eta_m", self.eta_m, "pump.eta_m", 0.277, "eq. 8 (the reference adds T0 and C_v)"),
            ("mech share to delivered oil", self.mech_split[0], "pump.friction_pairs (delivered share)", 0.6, "20 % goes to port-plate metal (no counterpart)"),
            ("v_case m³", self.v_case, "pump.case_oil_m3", 0.15e-3, ""),
            ("case wetted area m²", self.a_case[0] + self.a_case[1], "pump.case_inner_area_m2", 0.02, "other correlation"),
            ("v_port m³", self.v_port, "2·pump.port_oil_m3", 0.10e-3, ""),
            ("v_loop m³", self.v_loop, "blocks.loop_oil_m3", 1.428e-3, ""),
            ("loop film area m²", self.plate_duct[2] + self.block_duct[2], "π·loop_d·loop_len·loop_area_scale", 0.154, "no wall in series"),
            ("valve-block mass kg (3 nodes)", block_m, "main + ball mass", 190.0, "Table 2 total kept"),
            ("main block mass kg", self.c_block / 460.0, "blocks.main_mass_kg", 160.0, "25 kg moved to the manifold plate"),
            ("ball block mass kg", self.c_ball / 460.0, "blocks.ball_mass_kg", 30.0, ""),
            ("main block area m²", self.surfaces[4][0], "blocks.main_area_m2", 0.36, "0.06 m² on the manifold plate"),
            ("ball block area m²", self.surfaces[5][0], "blocks.ball_area_m2", 0.08, ""),
            ("v_ball m³", self.v_ball, "blocks.ball_oil_m3", 0.05e-3, ""),
            ("ball film area m²", self.ball_duct[2], "π·ball_d·ball_len", 0.0075, ""),
            ("hose length m", self.hose[0], "hydraulics.path.length_m", 1.5, ""),
            ("hose diameter m", self.hose[1], "hydraulics.path.diameter_m", 0.008, ""),
            ("boost Pa", self.boost_pa, "hydraulics.accumulator_pa", 5e5, ""),
            ("cylinder barrel J/K", self.cyl[0], "actuator.body_mass_kg·body_cp", 12.0 * 460.0, "chamber oil a separate node"),
            ("seal viscous N·s/m", self.seal_viscous, "actuator.viscous_friction_n_s_per_m", 2000.0, ""),
            ("act_leak m³/(s·Pa)", self.act_leak, "actuator.leak_m3_per_s_pa", 2e-14, ""),
            ("pos_gain 1/s", self.pos_gain, "actuator.position_gain_per_s", 20.0, ""),
            ("cylinder area m²", self.surfaces[6][0], "actuator.area_m2", 0.12, ""),
            ("emissivity", self.emissivity, "outside.emissivity", 0.85, ""),
            ("oil sensor τ s", self.sensor_tau[4], "blocks.sensor_tau_s", 2.0, "surface probes also lag 8–10 s (none in the rig file)"),
        ]
    }
}
