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

/// The probe offsets need the drain thermocouple (`Needs::Sensor(t_drain_c)`;
/// their own surface sensor too, without which the screening holds them:
/// the offset then acts on nothing). Without the case oil's temperature the
/// pump probe's offset trades with the pump's heat paths (measured on the rig
/// emulator's nominal machine, no drain: pump probe 10.7 %, block 18.3 %,
/// held-out pooled RMSE 0.84 -> 0.95 K); so the diagnosis, whose channels
/// have no drain, does not fit them.
///
/// The probe offsets' θ: the fraction towards ambient is ln θ (θ = 1 on
/// the metal), as [`CASE_CHURN_SPEED`]'s exponent is.
const PROBE_WHY: &str = "a thermocouple cemented or clamped on a painted housing reads between its metal and the air: its junction's contact conductance against the leads' and the boundary layer's (a few W/(m·K) of lead in still air) puts it 1–10 % of metal − ambient towards the air, more on a shielded or lagged mount; slightly negative would be a probe pressed into a hotter spot than the lumped metal. Fraction ln θ within −0.05…+0.18, σ 0.05 on it (a well-mounted probe reads within 5 %)";

/// The calibration set, in fit order.
pub const PARAMS: [ParamDef; 31] = [
    ParamDef {
        name: "h_out_motor",
        what: "outer heat transfer of the motor housing (free convection + radiation)",
        fields: "motor.area_m2",
        lo: 0.25, hi: 4.0, prior_sigma_ln: 0.5,
        centre: RIG_FILE,
        why: "still-air h of painted housings is 3–15 W/(m²·K) against the correlation's 6–9; exposed area 50–100 % of Table 2's",
        needs: Needs::Sensor(Channel::TMotorC),
        excitation: "a long soak (> 20 min) with the motor loaded, then a cool-down with the shaft stopped",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "h_out_pump",
        what: "outer heat transfer of the pump housing",
        fields: "pump.area_m2",
        lo: 0.25, hi: 4.0, prior_sigma_ln: 0.5,
        centre: RIG_FILE,
        why: "as h_out_motor; the pump's mounting can shield or add area",
        needs: Needs::Sensor(Channel::TPumpC),
        excitation: "a soak to near steady state and a cool-down at 0 rpm",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "h_out_main_block",
        what: "outer heat transfer of the main valve block (also scales its wall conduction area)",
        fields: "blocks.main_area_m2",
        lo: 0.25, hi: 4.0, prior_sigma_ln: 0.5,
        centre: RIG_FILE,
        why: "Table 2 gives 0.44 m² for both blocks; the split and the exposed fraction are assumed",
        needs: Needs::Sensor(Channel::TBlockC),
        excitation: "a long soak (the main block's time constant is hours) and a cool-down",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "h_out_ball_block",
        what: "outer heat transfer of the ball/needle-valve block (also scales its wall conduction area)",
        fields: "blocks.ball_area_m2",
        lo: 0.25, hi: 4.0, prior_sigma_ln: 0.5,
        centre: RIG_FILE,
        why: "split of Table 2's block area assumed",
        needs: Needs::Sensor(Channel::TBallvalveC),
        excitation: "throttling through the needle for > 20 min, then a cool-down",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: H_FORCED,
        what: "forced-convection (ram-air) coefficient of every housing, as a factor on the rig's flat-plate law",
        fields: "outside.ram_run_length_m (×θ^-5: the turbulent flat-plate h ∝ L^-0.2, so h_forced ×θ exactly)",
        lo: 0.25, hi: 4.0, prior_sigma_ln: 0.4,
        centre: "the rig file's law: turbulent flat plate with the run length that gives Table 5's 66.1 W/(m²·K) at 15 m/s",
        why: "the paper's coefficient is one flat-plate law for every housing; cross-flow correlations for cylinders and blocks of these sizes (Churchill–Bernstein, Hilpert) give 0.6–0.8 of it, and ducting, blockage and shielding on a real bench move it by ±30 %: σ 0.4 in ln covers ×0.45…×2.2 at 2σ",
        needs: Needs::Input(Channel::AirSpeedMps),
        excitation: "ram-air steps (0 and 5–25 m/s) with the housings well above the air",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "film_loop",
        what: "oil-to-metal film, loop oil ↔ main block (eqs. 12–14)",
        fields: "blocks.loop_area_scale",
        lo: 0.2, hi: 5.0, prior_sigma_ln: 0.7,
        centre: RIG_FILE,
        why: "duct correlations scatter ±30 %; the wetted area of drilled passages is unknown within a factor 3",
        needs: Needs::Sensor(Channel::TBlockC),
        excitation: "flow steps (shaft speed) while the oil is tens of kelvin above the block",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "film_port",
        what: "oil-to-metal film, pump port passages ↔ pump housing",
        fields: "pump.port_area_scale",
        lo: 0.2, hi: 5.0, prior_sigma_ln: 0.7,
        centre: RIG_FILE,
        why: "port geometry assumed",
        needs: Needs::Sensor(Channel::TPumpC),
        excitation: "speed steps at a constant pressure drop",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "film_ball",
        what: "oil-to-metal film, ball-valve oil ↔ ball block",
        fields: "nuisance.inner_scale (×θ) with blocks.loop_area_scale, pump.port_area_scale, pump.case_inner_area_m2 (÷θ, so only the ball film changes)",
        lo: 0.2, hi: 5.0, prior_sigma_ln: 0.7,
        centre: RIG_FILE,
        why: "ball-block passage geometry assumed",
        needs: Needs::Sensor(Channel::TBallvalveC),
        excitation: "needle throttling at several flows",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "film_case",
        what: "case-oil film on the pump housing (rotating group)",
        fields: "pump.case_inner_area_m2",
        lo: 0.1, hi: 10.0, prior_sigma_ln: 1.0,
        centre: RIG_FILE,
        why: "the reference takes the case flow as laminar Taylor–Couette flow (Nu = 2 below the instability, a lower bound: slippers, pistons and the leakage jets churn a real case) on an assumed inner area",
        needs: Needs::Sensor(Channel::TPumpC),
        excitation: "speed steps with a drain thermocouple (t_drain_c) or a pump-surface sensor",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: CASE_CHURN,
        what: "the case film churned by the rotating group: factor on the case gap's laminar film at 955 rpm (oil at 40 °C), blended in above ~100 rpm; the gap film stays the floor at rest (network::case_churn_factor)",
        fields: "pump.case_churn",
        lo: 0.5, hi: 100.0, prior_sigma_ln: 2.0,
        centre: "the rig file's law: laminar Taylor–Couette flow across the 3 mm case gap (Nu = 2 below the instability), nothing churned",
        why: "Nu = 2 across the gap is conduction, a lower bound: the slippers, pistons and leakage jets of a rotating group churn its case. A rotating cylinder of this size in oil (Becker's Nu = 0.133·Re^⅔·Pr^⅓ on the 60 mm barrel at 955 rpm, 40 °C: h ≈ 600 W/(m²·K)) gives 10 times the gap law there (58 W/(m²·K)), the slippers and jets a few times more; ×100 (h ≈ 6 kW/(m²·K), oil jets impinging) is the upper end. Below 1: a case not full of oil (drained, aerated at speed). σ 2 in ln: the rig file's law is a floor, not an estimate; the logs decide",
        needs: Needs::Sensor(Channel::TDrainC),
        excitation: "speed steps (300–1500 rpm) and holds at a low speed (servo holds, the shaft stopped) with a drain thermocouple (t_drain_c)",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: CASE_CHURN_SPEED,
        what: "speed exponent added to the churned case film (pump.case_churn_speed_exp = ln θ)",
        fields: "pump.case_churn_speed_exp (+ ln θ)",
        lo: 0.5, hi: 2.7, prior_sigma_ln: 0.5,
        centre: "the gap law's own speed dependence (exponent added 0)",
        why: "churned films go as Re^0.5 (laminar boundary layers on slippers) to Re^0.8 (turbulent), a rotating cylinder as Re^⅔; the gap law over 300–1500 rpm goes as Re^0 below the Taylor instability to Re^0.7 above it: an added exponent −0.7…+1 (θ 0.5–2.7) covers the difference, σ 0.5 its likely half",
        needs: Needs::Sensor(Channel::TDrainC),
        excitation: "speed steps (300–1500 rpm) with a drain thermocouple (t_drain_c)",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: BLOCK_WALL,
        what: "conduction from the oil passages' wall into the valve blocks' lumped metal, in series with the loop and ball-valve films",
        fields: "blocks.wall_m (÷θ: the wall conductance k·a²/wall_m ×θ)",
        lo: 0.25, hi: 100.0, prior_sigma_ln: 1.5,
        centre: "the rig file's plane wall: one sixth of the block's outer area, 30 mm of steel (90 W/K for the main block)",
        why: "how a lumped block's temperature connects to its passages is a modelling choice, not a measured value: a plane wall of a sixth of the block's face gives 90 W/K; the conduction shape factor of drilled passages (2πkL/ln(r_o/r_i), 1–2 m of Ø10 mm bores with r_o/r_i 3–10) 120–500 W/K; a block lumped with its passage walls none (θ → ∞). In series with a film that grows with flow and falls with viscosity, the wall caps the oil's coupling to the block at high flow and hot oil (measured on the rig emulator: 68 W/K at 2000 rpm and 70 °C against its 216 W/K of films). σ 1.5 in ln covers ×0.05…×20 at 2σ; the bound ×100 is the no-wall limit",
        needs: Needs::SensorWithJointExcitation(Channel::TBlockC),
        excitation: "an identification run: speed (flow) and needle drop (heat input) stepped independently, the oil tens of kelvin above the block, hot and cold (the film changes with flow and viscosity, the wall does not)",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: DUCT_TURBULENT,
        what: "turbulent level of the oil ducts' films: factor on eq. (14)'s Nusselt number, above Re 10⁴ and at the turbulent end of the 2300–10⁴ blend (so on the film's rise through the transition)",
        fields: "blocks.duct_turbulent_scale",
        lo: 0.5, hi: 4.0, prior_sigma_ln: 0.5,
        centre: "the rig file's law: eqs. (13)/(14) blended linearly in Re between 2300 and 10⁴ (Gnielinski 1995), eq. 14 as printed",
        why: "where a duct flow turns turbulent depends on its inlet: drilled passages with bends, cross-drillings and valve seats trip it at Re 2300–4000, a smooth long tube near 10⁴; at Re 4000–5300 (oil Pr ~260) a flow turbulent from 4000 has 1.2–1.4 times the film of the 10⁴ blend (×1.4 at 4000). Eq. (14) itself scatters ±10–20 %. σ 0.5 in ln covers ×0.37…×2.7 at 2σ; bounds ×0.5…×4",
        needs: Needs::Sensor(Channel::TBlockC),
        excitation: "speed steps at 850–1200 rpm with the needle set for 40–60 bar after a warm-up, the oil hot (the main-block passage's flow at Re above 3000 for ≥ 5 min), the block and oil sensors logged",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "cap_motor",
        what: "heat capacity of the motor housing (mass without the winding)",
        fields: "motor.mass_kg (the part above motor.winding_mass_kg)",
        lo: 0.4, hi: 2.5, prior_sigma_ln: 0.3,
        centre: RIG_FILE,
        why: "Table 2 gives the total mass; the part that follows the surface sensor within minutes is 50–100 %",
        needs: Needs::Sensor(Channel::TMotorC),
        excitation: "load steps: the motor's heating rate right after a current step",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "cap_pump",
        what: "heat capacity of the pump housing",
        fields: "pump.mass_kg",
        lo: 0.4, hi: 2.5, prior_sigma_ln: 0.3,
        centre: RIG_FILE,
        why: "Table 2 mass; participating fraction and cp (steel/aluminium) uncertain",
        needs: Needs::Sensor(Channel::TPumpC),
        excitation: "pressure or speed steps: the pump's heating rate after a step",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "cap_main_block",
        what: "heat capacity of the main valve block",
        fields: "blocks.main_mass_kg",
        lo: 0.4, hi: 2.5, prior_sigma_ln: 0.4,
        centre: RIG_FILE,
        why: "split of Table 2's 190 kg assumed",
        needs: Needs::Sensor(Channel::TBlockC),
        excitation: "a load step held for > 20 min",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "cap_ball_block",
        what: "heat capacity of the ball/needle-valve block",
        fields: "blocks.ball_mass_kg",
        lo: 0.4, hi: 2.5, prior_sigma_ln: 0.4,
        centre: RIG_FILE,
        why: "split of Table 2's 190 kg assumed",
        needs: Needs::Sensor(Channel::TBallvalveC),
        excitation: "needle pressure steps",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "cap_loop_oil",
        what: "circulating-oil volume (main-block passages, hoses, accumulator side)",
        fields: "blocks.loop_oil_m3",
        lo: 0.3, hi: 3.0, prior_sigma_ln: 0.5,
        centre: RIG_FILE,
        why: "hose lengths and accumulator volume differ between rigs",
        needs: Needs::Sensor(Channel::TOilC),
        excitation: "load steps: the oil sensor's rate right after a step",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "cap_case_oil",
        what: "oil volume of the pump case",
        fields: "pump.case_oil_m3",
        lo: 0.3, hi: 3.0, prior_sigma_ln: 0.5,
        centre: RIG_FILE,
        why: "pump design; not in the paper",
        needs: Needs::Sensor(Channel::TDrainC),
        excitation: "a drain thermocouple (t_drain_c) and pressure steps",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: PROBE_OIL,
        what: "response time of the manifold oil probe in the flowing oil (thermowell, sheath)",
        fields: "blocks.sensor_tau_s",
        lo: 0.25, hi: 5.0, prior_sigma_ln: 1.0,
        centre: RIG_FILE,
        why: "sheathed probes in thermowells in flowing oil answer in 1–20 s (t63); the rig file's 2 s is assumed. Longer lags belong to a dead-end pocket (candidate sensor-lag)",
        needs: Needs::Sensor(Channel::TOilC),
        excitation: "load or speed steps: the oil channel's delay right after a step",
        stage: Stage::SensorResponse,
    },
    ParamDef {
        name: "pump_friction",
        what: "pump friction torque of the extended eq. (8), T0 + C_v·μ·D·ω + η_m·D·Δp, as a whole",
        fields: "pump.no_load_torque_nm, pump.viscous_torque_coeff, pump.eta_m",
        lo: 0.1, hi: 2.0, prior_sigma_ln: 0.5,
        centre: RIG_FILE,
        why: "hydro-mechanical efficiency 70–95 % (the rig file's η_m 0.28 is calibrated on one rig)",
        needs: Needs::Nothing,
        excitation: "pressure steps at constant speed and speed steps at constant pressure (separates it from leakage)",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: FRICTION_CASE,
        what: "share of the pump's viscous and pressure friction heat that enters the case oil, as a factor on the sliding-pair rule's 0.15 (the delivered oil's and the housing's shares scaled down together)",
        fields: "pump.friction_pairs.case_share_scale",
        lo: 0.3, hi: 4.0, prior_sigma_ln: 0.7,
        centre: "the rig file's sliding-pair rule: half the slipper film's heat to the case oil, none of the piston/bore or valve-plate films' (0.15 of the friction heat)",
        why: "the leakage through the piston/bore and slipper gaps carries their films' heat into the case, and the rotating group's churning heats the case oil itself; the rule counts neither. 0.05–0.6 of the friction heat (×0.3–4): the upper end a pump whose pistons' film heat leaves with their leakage, the lower a case flushed from outside. Fitted only with friction_speed (where the heat goes and how it scales with speed and load trade on the drain)",
        needs: Needs::Sensor(Channel::TDrainC),
        excitation: "pressure steps at two or more speeds with a drain thermocouple (t_drain_c): the drain's rise against the pump housing's per watt of friction",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: FRICTION_SPEED,
        what: "the speed law of the pump's friction: factor on the no-load and viscous torques T₀ + C_v·μ·D·ω of the extended eq. (8), the pressure term η_m·D·Δp kept",
        fields: "pump.no_load_torque_nm, pump.viscous_torque_coeff",
        lo: 0.05, hi: 3.0, prior_sigma_ln: 1.0,
        centre: "the rig file's law: T₀ = 0.3 N·m (shaft seal and bearings) and Wilson's C_v = 5·10⁴, both assumed (docs/calibration.md)",
        why: "no-load torques of 15–30 cm³/rev axial-piston pumps are 0.1–1 N·m and Wilson's viscous coefficient scatters by ×3 between designs; a pump whose loss is nearly all pressure-proportional (well-lubricated slippers, low-drag seal) has ×0.05. σ 1 in ln: the rig file's split between the speed and pressure terms is a guess. When η_m comes from the current it is taken with the rig file's T₀ and C_v (the current then carries this factor's difference as iron or bearing drag outside the pump's heat)",
        needs: Needs::Sensor(Channel::TDrainC),
        excitation: "speed steps at a low pressure drop and needle steps at one speed with a drain thermocouple (t_drain_c): the speed terms' heat follows ω and μ, the pressure term Δp",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "leak_gap",
        what: "pump leakage gap height (pistons, slippers, valve plate; leakage ∝ gap³)",
        fields: "pump.gaps.piston_gap_m, pump.gaps.slipper_gap_m, pump.gaps.port_gap_m",
        lo: 0.33, hi: 2.5, prior_sigma_ln: 0.3,
        centre: RIG_FILE,
        why: "gaps of 4–30 µm for the rig file's 12 µm",
        needs: Needs::Nothing,
        excitation: "pressure steps at a low speed (leakage heat ∝ Δp² does not scale with ω)",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "winding_r",
        what: "winding resistance at 25 °C (eq. 1)",
        fields: "motor.r25_ohm",
        lo: 0.5, hi: 2.0, prior_sigma_ln: 0.15,
        centre: RIG_FILE,
        why: "Table 2 gives 0.074 Ω; cables, connectors and the measurement temperature move it by tens of %",
        needs: Needs::Nothing,
        excitation: "current steps (pressure steps) with the motor sensor logged; or measure R with a 4-wire meter",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "iron_loss",
        what: "stator iron-loss coefficients k_h, k_c, k_e of eq. (2)",
        fields: "motor.iron.k_h, motor.iron.k_c, motor.iron.k_e",
        lo: 0.2, hi: 5.0, prior_sigma_ln: 0.7,
        centre: RIG_FILE,
        why: "Bertotti coefficients of electrical steels span an order of magnitude; not in the paper",
        needs: Needs::Nothing,
        excitation: "speed steps at a low pressure drop (iron loss follows ω, copper loss the current)",
        stage: Stage::Thermal,
    },
    ParamDef {
        name: "needle_split",
        what: "share of the throttling heat released in the line/hoses (loop oil) rather than at the needle (ball-valve oil)",
        fields: "hydraulics.path.length_m, hydraulics.path.local_loss_coeff",
        lo: 0.1, hi: 5.0, prior_sigma_ln: 0.7,
        centre: RIG_FILE,
        why: "hose lengths and fittings of the throttle path are assumed",
        needs: Needs::Sensor(Channel::TBallvalveC),
        excitation: "needle throttling at several flows (line loss ∝ q², needle heat = the rest)",
        stage: Stage::Thermal,
    },
    surface_probe(PROBE_SURFACE[0], "where the motor housing probe (Point 1, t_motor_c) sits between its metal and the ambient air: it reads the fraction ln θ of metal − ambient towards the air", "probes.motor (= ln θ)"),
    surface_probe(PROBE_SURFACE[1], "where the pump housing probe (Point 3, t_pump_c) sits between its metal and the ambient air: it reads the fraction ln θ of metal − ambient towards the air", "probes.pump (= ln θ)"),
    surface_probe(PROBE_SURFACE[2], "where the main valve block probe (Point 4, t_block_c) sits between its metal and the ambient air: it reads the fraction ln θ of metal − ambient towards the air", "probes.main_block (= ln θ)"),
    surface_probe(PROBE_SURFACE[3], "where the ball-valve block probe (Point 5, t_ballvalve_c) sits between its metal and the ambient air: it reads the fraction ln θ of metal − ambient towards the air", "probes.ball_block (= ln θ)"),
];

/// The calibration parameter of a surface probe's reading offset: `name`,
/// `what` it is and the rig field it sets; bounds, prior, needs and
/// excitation are the same for every housing probe ([`PROBE_WHY`]).
const fn surface_probe(name: &'static str, what: &'static str, fields: &'static str) -> ParamDef {
    ParamDef {
        name,
        what,
        fields,
        lo: 0.95, hi: 1.2, prior_sigma_ln: 0.05,
        centre: "on its metal (fraction 0): the rig file has no probe model",
        why: PROBE_WHY,
        needs: Needs::Sensor(Channel::TDrainC),
        excitation: "the housing tens of kelvin above the air and the air moving (a soak, a cool-down), its own surface sensor logged beside a drain thermocouple (t_drain_c): the offset scales with metal − ambient, a film or capacity does not",
        stage: Stage::Thermal,
    }
}

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
