//! The full lumped thermal-hydraulic model: state vector, operating point,
//! losses (eqs. 1–11) assigned to the thermal nodes, the network (eqs.
//! 12–19), the LNG exchanger (eqs. 20–22) and the energy bookkeeping.

use crate::hydraulics::{self, ix, OpPoint};
use crate::losses;
use crate::network::{self, Node, N_NODES, NODES};
use crate::simulation::grids::{LaminarGrid, NuGrid, OuterGrid, NU_GRID_FACTOR};
use crate::rig::Rig;
use crate::scenario::{Circuit, Mission, ReplayInputs, ValveRule};
use std::cell::Cell;
use std::f64::consts::PI;

/// Offset of the temperatures in the state vector.
pub const T0: usize = ix::N;
/// Index of the integrated energy input into the nodes, J: every loss that
/// is a heat source plus the pump's work on the oil minus the actuator's
/// (see [`Model::thermal`]); in a throttle run it equals the integrated
/// losses but for the reversible compression terms.
pub const E_LOSS: usize = T0 + N_NODES;
/// Index of the integrated heat to ambient, J.
pub const E_AMB: usize = E_LOSS + 1;
/// Index of the integrated heat to the LNG, J.
pub const E_LNG: usize = E_LOSS + 2;
/// State dimension.
pub const N_STATE: usize = E_LOSS + 3;

/// Index of a node's temperature in the state vector.
pub const fn t_ix(n: Node) -> usize {
    T0 + n as usize
}

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
    /// Linear interpolation towards `other` at weight `w` ∈ [0, 1]
    /// (`self` at 0).
    pub fn lerp(&self, other: &Self, w: f64) -> Self {
        let l = |a: f64, b: f64| a + w * (b - a);
        Self { k_leak: l(self.k_leak, other.k_leak), rho_ball: l(self.rho_ball, other.rho_ball), nu_ball: l(self.nu_ball, other.nu_ball) }
    }
}

/// Linear interpolation in measured inputs.
#[derive(Debug, Clone)]
pub struct ReplayDrive {
    inputs: ReplayInputs,
    /// Segment of the last [`ReplayDrive::locate`]: the solver asks for
    /// times close to each other, so the next is usually this one or the
    /// one after (checked, else a binary search).
    hint: Cell<usize>,
}

impl ReplayDrive {
    /// Wrap replay inputs.
    pub fn new(inputs: ReplayInputs) -> Self {
        Self { inputs, hint: Cell::new(0) }
    }

    /// The inputs.
    pub fn inputs(&self) -> &ReplayInputs {
        &self.inputs
    }

    /// Segment index and fraction at time `t`.
    fn locate(&self, t: f64) -> (usize, f64) {
        let ts = &self.inputs.time_s;
        let n = ts.len();
        if n < 2 {
            return (0, 0.0);
        }
        // Segment i holds t when ts[i] <= t < ts[i+1]; the first also takes
        // earlier times and the last later ones (the binary search's clamp).
        let holds = |i: usize| i + 1 < n && (i == 0 || ts[i] <= t) && (i + 2 == n || t < ts[i + 1]);
        let h = self.hint.get();
        let i = if holds(h) {
            h
        } else if holds(h + 1) {
            h + 1
        } else {
            ts.partition_point(|&x| x <= t).clamp(1, n - 1) - 1
        };
        self.hint.set(i);
        let (a, b) = (ts[i], ts[i + 1]);
        (i, ((t - a) / (b - a)).clamp(0.0, 1.0))
    }

    fn lerp(v: &[f64], i: usize, f: f64) -> f64 {
        match (v.get(i), v.get(i + 1)) {
            (Some(a), Some(b)) => a + (b - a) * f,
            (Some(a), None) => *a,
            _ => 0.0,
        }
    }

    /// Piston speed at logged sample `i`, mm/s: the mean of the difference
    /// quotients of the segments on either side (one side at the ends).
    fn node_speed(&self, i: usize) -> f64 {
        let r = &self.inputs;
        let Some(p) = &r.position_mm else { return 0.0 };
        let ts = &r.time_s;
        let q = |j: usize| -> Option<f64> {
            let (a, b) = (ts.get(j)?, ts.get(j + 1)?);
            Some((p.get(j + 1)? - p.get(j)?) / (b - a))
        };
        match (i.checked_sub(1).and_then(q), q(i)) {
            (Some(a), Some(b)) => 0.5 * (a + b),
            (Some(a), None) => a,
            (None, Some(b)) => b,
            (None, None) => 0.0,
        }
    }

    /// Operating point at `t` from the measured inputs.
    pub fn op(&self, rig: &Rig, t: f64) -> OpPoint {
        let (i, f) = self.locate(t);
        let r = &self.inputs;
        let circuit = r.circuit;
        // The piston moves only in the servo circuit (in the throttle circuit
        // the cylinder is isolated; a logged position is its rest position).
        let (x, v) = match (&r.position_mm, circuit) {
            (Some(p), Circuit::Servo) => {
                let x = Self::lerp(p, i, f) * 1e-3;
                // Piston speed: the logged samples' difference quotients
                // averaged onto the samples and interpolated linearly, so
                // that the speed is continuous (a piecewise-constant speed
                // would make the friction and flow heat jump at every logged
                // sample and force the solver to stop there).
                let v = (1.0 - f) * self.node_speed(i) + f * self.node_speed(i + 1);
                (x, v * 1e-3)
            }
            _ => (0.0, 0.0),
        };
        let omega = Self::lerp(&r.speed_rpm, i, f) * 2.0 * PI / 60.0;
        let p_a = Self::lerp(&r.p_a_bar, i, f) * 1e5;
        let p_b = Self::lerp(&r.p_b_bar, i, f) * 1e5;
        let logged_air = r.air_speed_mps.as_ref().map_or(0.0, |a| Self::lerp(a, i, f));
        let mut op = OpPoint {
            omega,
            p_a,
            p_b,
            p_case: rig.hydraulics.accumulator_pa,
            x,
            v,
            q_path: 0.0,
            current_a: Self::lerp(&r.current_a, i, f),
            circuit,
            ambient_c: Self::lerp(&r.ambient_c, i, f),
            air_mps: logged_air + rig.ext.forced_convection.unwrap_or(0.0),
        };
        if circuit == Circuit::Throttle {
            // The pump's delivered flow goes through the throttle path (the
            // leakage here at 40 °C; `Model::op_point` takes it at the case oil).
            let k = rig.pump.gaps.conductance(rig.oil.mu_pa_s(40.0));
            op.q_path = rig.displacement_m3_per_rad() * omega - k * (p_a - op.p_case);
        }
        op
    }

    /// Logged LNG valve command at `t`.
    pub fn lng_open(&self, t: f64) -> bool {
        let (i, _) = self.locate(t);
        self.inputs.lng_valve.as_ref().and_then(|v| v.get(i)).is_some_and(|&x| x > 0.5)
    }
}

/// What drives the model.
#[derive(Debug, Clone)]
pub enum Drive {
    /// A mission: the hydraulic states are integrated.
    Mission(Mission),
    /// Measured inputs: the hydraulic operating point is imposed.
    Replay(ReplayDrive),
}

/// The model: rig, drive and the LNG valve state.
#[derive(Debug)]
pub struct Model {
    /// Rig parameters.
    pub rig: Rig,
    /// Drive.
    pub drive: Drive,
    /// LNG valve open (set between solver segments).
    pub lng_open: Cell<bool>,
    contents: [(f64, f64); N_NODES],
    /// The outer surfaces' heat flows and the oil's viscosity on a
    /// temperature grid (the fast plant's; None: the exact correlations).
    outer_grid: Option<OuterGrid>,
    nu_grid: Option<NuGrid>,
    lam_grid: Option<LaminarGrid>,
    /// The pump gaps' conductance times viscosity (eqs. 5–7 are ∝ 1/μ),
    /// m³·Pa⁻¹·s⁻¹·Pa·s, taken once with the grids (the fast plant's).
    leak_geom: Option<f64>,
}

impl Model {
    /// Build a model.
    pub fn new(rig: Rig, drive: Drive) -> Self {
        let contents = network::contents(&rig);
        Self { rig, drive, lng_open: Cell::new(false), contents, outer_grid: None, nu_grid: None, lam_grid: None, leak_geom: None }
    }

    /// Interpolate the outer surfaces' heat flows on a grid of `step_k`
    /// kelvin (a cubic on a coarser one away from the air), the oil's
    /// viscosity on one `NU_GRID_FACTOR` times coarser and the ducts'
    /// laminar Nusselt number on a grid of its argument from now on
    /// ([`crate::simulation::grids`]), or (None) evaluate them exactly.
    pub fn set_grids(&mut self, step_k: Option<f64>) {
        let step = step_k.filter(|&s| s > 0.0 && s.is_finite());
        self.outer_grid = step.map(OuterGrid::new);
        self.nu_grid = step.map(|s| NuGrid::new(s * NU_GRID_FACTOR));
        self.lam_grid = step.map(|_| LaminarGrid::new());
        self.leak_geom = step.map(|_| self.rig.pump.gaps.conductance(1.0));
    }

    /// Exact evaluations behind the grids so far: (outer surfaces, viscosities).
    pub fn grid_evals(&self) -> (u64, u64) {
        (self.outer_grid.as_ref().map_or(0, |g| g.evals.get()), self.nu_grid.as_ref().map_or(0, |g| g.evals.get()))
    }

    /// Oil-to-metal conductance of a duct ([`network::duct_conductance`]),
    /// W/K, the laminar Nusselt number on its grid when the grids are set.
    fn duct_conductance(&self, q_m3_per_s: f64, d: f64, len: f64, area_scale: f64, t_oil: f64, nu: f64) -> f64 {
        match &self.lam_grid {
            Some(g) => network::duct_conductance_with(&self.rig, q_m3_per_s, d, len, area_scale, t_oil, nu, |x| g.nu(x)),
            None => network::duct_conductance(&self.rig, q_m3_per_s, d, len, area_scale, t_oil, nu),
        }
    }

    /// Pressure drops of the throttle path ([`hydraulics::path_dp`]) with
    /// the oil at `t_oil`: its viscosity from [`Model::nu`] (on the grid
    /// when the grids are set), Pa.
    fn path_dp(&self, q: f64, t_oil: f64, needle: Option<f64>) -> (f64, f64) {
        hydraulics::path_dp_props(&self.rig, q, self.rig.oil.rho(t_oil, 0.0), self.nu(t_oil), needle)
    }

    /// Kinematic viscosity of the oil at `t_oil` (its Walther line), m²/s.
    pub fn nu(&self, t_oil: f64) -> f64 {
        match &self.nu_grid {
            Some(g) => g.nu(&self.rig.oil, t_oil),
            None => self.rig.oil.nu_m2_per_s(t_oil),
        }
    }

    /// Dynamic viscosity of the oil at `t_oil` and 0 bar, Pa·s (ν·ρ, as
    /// [`crate::fluid::Oil::mu_pa_s`]).
    pub fn mu(&self, t_oil: f64) -> f64 {
        self.nu(t_oil) * self.rig.oil.rho(t_oil, 0.0)
    }

    /// Pump leakage conductance of eqs. (5)–(7) at the case-oil temperature
    /// (the films' viscosity), m³/(s·Pa).
    pub fn k_leak(&self, t_case: f64) -> f64 {
        match self.leak_geom {
            // The fast plant: the geometric factor over μ (a division, not
            // three and a logarithm).
            Some(g) => g / self.mu(t_case),
            None => self.rig.pump.gaps.conductance(self.mu(t_case)),
        }
    }

    /// Heat capacity of node `n` at `t_c`, J/K (oil: V·ρ(T)·c_p(T)).
    pub fn capacity(&self, n: Node, t_c: f64) -> f64 {
        network::capacity_j_per_k(&self.rig, n, self.contents[n as usize], t_c)
    }

    /// Mass flow of a volumetric flow `q` (m³/s) around the oil ring, kg/s:
    /// at the density of the loop oil (the pump's suction side), one value
    /// for every link of the ring so that the ring conserves mass.
    fn ring_mass_flow(&self, q: f64, t_loop: f64) -> f64 {
        self.rig.oil.rho(t_loop, 0.0) * q
    }

    /// Initial state: hydraulics at rest (lines at the accumulator pressure),
    /// every node at the initial ambient (paper assumption 1).
    pub fn initial_state(&self) -> Vec<f64> {
        let mut y = vec![0.0; N_STATE];
        let amb = self.ambient(0.0);
        y[ix::PA] = self.rig.hydraulics.accumulator_pa;
        y[ix::PB] = self.rig.hydraulics.accumulator_pa;
        for n in NODES {
            y[t_ix(n)] = amb;
        }
        y
    }

    /// Ambient temperature at `t`, °C.
    pub fn ambient(&self, t: f64) -> f64 {
        match &self.drive {
            Drive::Mission(m) => m.ambient_c.at(t),
            Drive::Replay(r) => r.op(&self.rig, t).ambient_c,
        }
    }

    /// Hydraulic operating point at (t, y).
    pub fn op_point(&self, t: f64, y: &[f64]) -> OpPoint {
        let mut op = self.op_hydraulic(t, y);
        if let Drive::Mission(_) = &self.drive {
            op.current_a = self.motor_current(&op, y[t_ix(Node::Case)]);
        }
        op
    }

    /// [`Model::op_point`] without the motor current of a mission (zero
    /// there): what the hydraulic derivatives need.
    pub fn op_hydraulic(&self, t: f64, y: &[f64]) -> OpPoint {
        let ball = || {
            let t_ball = y[t_ix(Node::BallOil)];
            (self.rig.oil.rho(t_ball, 0.0), self.nu(t_ball))
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
                    let needle = hydraulics::needle_k(&self.rig, m.needle_bar.at(t));
                    let (rho, nu) = ball();
                    op.q_path = hydraulics::path_flow_props(&self.rig, op.p_a - op.p_b, rho, nu, needle);
                }
                op
            }
        }
    }

    /// Motor current of a mission's operating point, A rms: the shaft
    /// torque (pump load plus friction at the case-oil temperature
    /// `t_case`) over the torque constant.
    fn motor_current(&self, op: &OpPoint, t_case: f64) -> f64 {
        let fr = self.pump_friction(op, t_case).total_w()
            + self.rig.ext.churning_loss.map_or(0.0, |k| losses::churning_w(k, op.omega))
            + self.rig.motor.bearing_friction_nm.map_or(0.0, |m| losses::bearing_w(m, op.omega));
        hydraulics::soft_abs(hydraulics::shaft_torque(&self.rig, op, fr), 1e-3) / self.rig.motor.torque_constant_nm_per_a
    }

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
        let fr = self.pump_friction(op, t_case);
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
        let rig = &self.rig;
        let tc = |n: Node| temps[n as usize];
        let f = hydraulics::flows(rig, op, self.k_leak(tc(Node::Case)));
        let dp = op.p_a - op.p_b;
        let (line, needle) = match (&self.drive, op.circuit) {
            (Drive::Mission(m), Circuit::Throttle) => {
                let nk = hydraulics::needle_k(rig, m.needle_bar.at(t));
                let (l, n) = self.path_dp(op.q_path, tc(Node::BallOil), nk);
                (l * op.q_path, n * op.q_path)
            }
            (Drive::Replay(_), Circuit::Throttle) => {
                let (l, _) = self.path_dp(op.q_path, tc(Node::BallOil), None);
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
        Losses {
            copper: losses::copper_w(
                rig.motor.phases,
                op.current_a,
                rig.motor.r25_ohm,
                rig.ext.winding_resistance_temperature,
                tc(Node::Winding),
            ),
            iron: rig.motor.iron.power_w(op.omega),
            bearing: rig.motor.bearing_friction_nm.map_or(0.0, |m| losses::bearing_w(m, op.omega)),
            leakage: f.leak_a * (op.p_a - op.p_case) + f.leak_b * (op.p_b - op.p_case),
            mechanical: self.pump_friction(op, tc(Node::Case)).total_w(),
            mech_metal: self.friction_heat(op, tc(Node::Case)).metal(),
            churning: rig.ext.churning_loss.map_or(0.0, |k| losses::churning_w(k, op.omega)),
            line,
            needle,
            valves,
            act_leak: f.act_leak * dp,
            act_friction: match op.circuit {
                Circuit::Servo => rig.actuator.viscous_friction_n_s_per_m * op.v * op.v + coulomb,
                Circuit::Throttle => 0.0,
            },
        }
    }

    /// Thermal right-hand side: node heat balances and energy integrals.
    /// Returns (energy input W, heat to ambient W, heat to LNG W) and fills
    /// `dt` (K/s per node). The energy input is every loss that enters a node
    /// as heat plus the pump's work on the oil, minus the actuator's: the
    /// pump leakage, line and needle losses are not sources here, they follow
    /// from the oil's enthalpy h(T, p) at each node's pressure.
    pub fn thermal(&self, op: &OpPoint, l: &Losses, temps: &[f64], dt: &mut [f64]) -> (f64, f64, f64) {
        let rig = &self.rig;
        let oil = &rig.oil;
        let tc = |n: Node| temps[n as usize];
        let mut q = [0.0f64; N_NODES];
        let mut q_in = 0.0;
        // Heat sources (losses that are not a pressure drop of the ring) into their nodes.
        let hp = if op.p_a >= op.p_b { Node::Outlet } else { Node::Inlet };
        let fh = self.friction_heat(op, tc(Node::Case));
        for (n, w) in [
            (Node::Winding, l.copper),
            (Node::Motor, l.iron + l.bearing),
            (Node::Pump, fh.housing),
            (Node::PumpInternals, fh.internals),
            (Node::Case, fh.case + l.churning),
            (hp, fh.delivered),
            (Node::Loop, l.valves),
            (Node::Actuator, l.act_leak + l.act_friction),
        ] {
            q[n as usize] += w;
            q_in += w;
        }
        // Conductances (symmetric exchanges).
        let link = |q: &mut [f64; N_NODES], a: Node, b: Node, g: f64| {
            let w = g * (tc(a) - tc(b));
            q[a as usize] -= w;
            q[b as usize] += w;
        };
        let qc = op.circulation(rig);
        let p = &rig.pump;
        let b = &rig.blocks;
        link(&mut q, Node::Winding, Node::Motor, rig.motor.winding_to_housing_w_per_k);
        if let Some(g) = rig.ext.motor_pump_conduction {
            link(&mut q, Node::Motor, Node::Pump, g);
        }
        let nu_case = self.nu(tc(Node::Case));
        link(&mut q, Node::Case, Node::Pump, network::case_film_w_per_k(rig, op.omega, tc(Node::Case), nu_case));
        for port in [Node::Inlet, Node::Outlet] {
            let g = self.duct_conductance(qc, p.port_d_m, p.port_len_m, p.port_area_scale, tc(port), self.nu(tc(port)));
            link(&mut q, port, Node::Pump, g);
        }
        if let Some(s) = &p.split {
            // the internals: films to the case oil and, through the bores, to
            // the port oil; their seats in the housing
            link(&mut q, Node::Case, Node::PumpInternals, network::internals_case_film_w_per_k(rig, s, op.omega, tc(Node::Case), nu_case));
            let q_displaced = rig.displacement_m3_per_rad() * op.omega;
            for port in [Node::Inlet, Node::Outlet] {
                link(&mut q, port, Node::PumpInternals, network::bore_film_w_per_k(rig, s, q_displaced, tc(port), self.nu(tc(port))));
            }
            link(&mut q, Node::PumpInternals, Node::Pump, s.seats.conductance_w_per_k());
        }
        if let Some(j) = &rig.joints {
            // metal paths: the housing's flange on the motor and its port face
            // on the manifold (main block)
            link(&mut q, Node::Pump, Node::Motor, j.pump_motor.conductance_w_per_k());
            link(&mut q, Node::Pump, Node::MainBlock, j.pump_manifold.conductance_w_per_k());
        }
        let g_loop = self.duct_conductance(qc, b.loop_d_m, b.loop_len_m, b.loop_area_scale, tc(Node::Loop), self.nu(tc(Node::Loop)));
        link(&mut q, Node::Loop, Node::MainBlock, network::block_path(rig, g_loop, b.main_area_m2));
        let g_ball = self.duct_conductance(qc, b.ball_d_m, b.ball_len_m, 1.0, tc(Node::BallOil), self.nu(tc(Node::BallOil)));
        link(&mut q, Node::BallOil, Node::BallBlock, network::block_path(rig, g_ball, b.ball_area_m2));
        // Manifold sensor pocket: in the flowing manifold in the baseline; in
        // a dead-end branch (Figs. 9–10) with `sensor-lag`.
        let c_sensor = self.capacity(Node::Sensor, tc(Node::Sensor));
        match rig.ext.sensor_lag {
            None => link(&mut q, Node::Loop, Node::Sensor, c_sensor / b.sensor_tau_s),
            Some(tau) => {
                link(&mut q, Node::Loop, Node::Sensor, c_sensor / tau);
                link(&mut q, Node::MainBlock, Node::Sensor, b.sensor_to_block_w_per_k);
            }
        }
        // Advection of h(T, p) around the ring of oil nodes, upwind,
        // mass-consistent. Each node emits its oil at its own pressure: the
        // ports at p_a (outlet) and p_b (inlet), the loop at the pump's
        // suction pressure, the ball-valve oil behind the needle (the line
        // drop still ahead of it). A pressure drop between two nodes is then
        // an isenthalpic throttling that warms the oil by (1 − αT)Δp/(ρc_p);
        // the pump's work m·Δp/ρ enters the delivered port (net warming by
        // compression αTΔp/(ρc_p)); in the servo circuit the actuator takes
        // m·Δp/ρ out of the oil it passes to the loop.
        let m_c = self.ring_mass_flow(qc.abs(), tc(Node::Loop));
        let f = hydraulics::flows(rig, op, self.k_leak(tc(Node::Case)));
        let m_l = self.ring_mass_flow(hydraulics::soft_pos(f.leak_a, 1e-9) + hydraulics::soft_pos(f.leak_b, 1e-9), tc(Node::Loop));
        let forward = qc >= 0.0;
        let ring: &[Node] = match (op.circuit, forward) {
            (Circuit::Throttle, true) => &[Node::Loop, Node::Inlet, Node::Outlet, Node::BallOil],
            (Circuit::Throttle, false) => &[Node::Loop, Node::BallOil, Node::Outlet, Node::Inlet],
            (Circuit::Servo, true) => &[Node::Loop, Node::Inlet, Node::Outlet],
            (Circuit::Servo, false) => &[Node::Loop, Node::Outlet, Node::Inlet],
        };
        // Node pressures. Throttle circuit, forward: outlet (p_a) → ball-valve oil
        // (needle drop) → loop (line drop) → inlet (p_b); reverse: inlet (p_b) →
        // loop (line drop) → ball-valve oil (needle drop) → outlet (p_a). Servo: the
        // loop at the pump's suction pressure (the actuator does the work between).
        let p_suction = if forward { op.p_b } else { op.p_a };
        let line_dp = match op.circuit {
            Circuit::Throttle => self.path_dp(op.q_path.abs(), tc(Node::BallOil), None).0.max(0.0),
            Circuit::Servo => 0.0,
        };
        let (p_loop, p_ball) = match (op.circuit, forward) {
            (Circuit::Throttle, true) => (op.p_b, op.p_b + line_dp),
            (Circuit::Throttle, false) => (op.p_b - line_dp, op.p_a),
            (Circuit::Servo, _) => (p_suction, p_suction),
        };
        let pres = |n: Node| match n {
            Node::Inlet => op.p_b,
            Node::Outlet => op.p_a,
            Node::BallOil => p_ball,
            Node::Case => op.p_case,
            _ => p_loop,
        };
        let h = |n: Node| oil.enthalpy_tp(tc(n), pres(n));
        let hp_pos = ring.iter().position(|&n| n == hp).unwrap_or(0);
        let mut q_lng = 0.0;
        for k in 0..ring.len() {
            let (from, to) = (ring[k], ring[(k + 1) % ring.len()]);
            let m = if k < hp_pos { m_c + m_l } else { m_c };
            let mut w = m * (h(from) - h(to));
            if k == 0 && self.lng_open.get() {
                // LNG exchanger in the return line, eqs. (20)–(22).
                q_lng = rig.lng.exchanger_w(m * oil.cp(tc(from)), tc(from));
                w -= q_lng;
            }
            let pump = matches!((from, to), (Node::Inlet, Node::Outlet) | (Node::Outlet, Node::Inlet));
            let actuator = op.circuit == Circuit::Servo && to == Node::Loop;
            if pump || actuator {
                // volume flow × Δp, the volume at the density the mass flow was taken at
                let work = m / oil.rho(tc(Node::Loop), 0.0) * (pres(to) - pres(from));
                w += work;
                q_in += work;
            }
            q[to as usize] += w;
        }
        q[Node::Case as usize] += m_l * (h(hp) - h(Node::Case));
        q[Node::Loop as usize] += m_l * (h(Node::Case) - h(Node::Loop));
        if op.circuit == Circuit::Servo {
            // Tidal exchange with the cylinder chambers.
            link(&mut q, Node::Loop, Node::Actuator, m_c * oil.cp(tc(Node::Loop)));
        }
        // Outer surfaces: convection (eqs. 15/16, ram air) + radiation (eq. 19),
        // and the main block's mounting to the bench (held at the air temperature).
        let mut q_amb = 0.0;
        for (i, (n, area, shape, ram_share)) in network::surfaces(rig).into_iter().enumerate() {
            let w = match &self.outer_grid {
                Some(g) => g.q(i, rig, area, shape, tc(n), op.ambient_c, op.air_mps, ram_share),
                None => network::q_outer_exposed(rig, area, shape, tc(n), op.ambient_c, op.air_mps, ram_share),
            };
            q[n as usize] -= w;
            q_amb += w;
        }
        let w_mount = b.mount_w_per_k * (tc(Node::MainBlock) - op.ambient_c);
        q[Node::MainBlock as usize] -= w_mount;
        q_amb += w_mount;
        for (i, n) in NODES.iter().enumerate() {
            dt[i] = match (n, &p.split) {
                // one pump node: the internals are the housing (no heat, no
                // capacity of their own) and follow it; started elsewhere
                // (a state set by hand) they relax onto it at 1/s, which also
                // fixes them in an equilibrium solve
                (Node::PumpInternals, None) => dt[Node::Pump as usize] + (tc(Node::Pump) - tc(Node::PumpInternals)),
                _ => q[i] / self.capacity(*n, temps[i]),
            };
        }
        (q_in, q_amb, q_lng)
    }

    /// Full right-hand side dy/dt = f(t, y).
    pub fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        let op = self.op_point(t, y);
        let temps = &y[T0..T0 + N_NODES];
        let l = self.losses(t, &op, temps);
        self.hydraulic_rhs_at(t, y, &op, dy);
        let (q_in, q_amb, q_lng) = self.thermal(&op, &l, temps, &mut dy[T0..T0 + N_NODES]);
        dy[E_LOSS] = q_in;
        dy[E_AMB] = q_amb;
        dy[E_LNG] = q_lng;
    }

    /// [`Model::rhs`] without the hydraulic derivatives (`dy[..ix::N]` is
    /// left as it is): the node temperatures' derivatives and the energy
    /// rates, the same to the last bit.
    pub fn thermal_rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        let op = self.op_point(t, y);
        let temps = &y[T0..T0 + N_NODES];
        let l = self.losses(t, &op, temps);
        let (q_in, q_amb, q_lng) = self.thermal(&op, &l, temps, &mut dy[T0..T0 + N_NODES]);
        dy[E_LOSS] = q_in;
        dy[E_AMB] = q_amb;
        dy[E_LNG] = q_lng;
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
        let t_ball = temps[Node::BallOil as usize];
        HydraulicOil { k_leak: self.k_leak(temps[Node::Case as usize]), rho_ball: self.rig.oil.rho(t_ball, 0.0), nu_ball: self.nu(t_ball) }
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

    fn hydraulic_rhs_at(&self, t: f64, y: &[f64], op: &OpPoint, dy: &mut [f64]) {
        let temps = &y[T0..T0 + N_NODES];
        match &self.drive {
            Drive::Mission(m) => {
                let f = hydraulics::flows(&self.rig, op, self.k_leak(temps[Node::Case as usize]));
                hydraulics::derivatives(&self.rig, m, t, op, &f, dy);
            }
            Drive::Replay(_) => dy[..ix::N].iter_mut().for_each(|d| *d = 0.0),
        }
    }

    /// The states no derivative of [`Model::rhs`] depends on: the energy
    /// integrals always, and in a replay the hydraulic states too (the
    /// operating point is imposed from the log). Their Jacobian columns are
    /// zero.
    pub fn inert_states(&self) -> [bool; N_STATE] {
        let mut inert = [false; N_STATE];
        for e in [E_LOSS, E_AMB, E_LNG] {
            inert[e] = true;
        }
        if matches!(self.drive, Drive::Replay(_)) {
            inert[..ix::N].iter_mut().for_each(|i| *i = true);
        }
        inert
    }

    /// Energy stored in the nodes relative to the state `y0`, J.
    pub fn stored_energy(&self, y0: &[f64], y: &[f64]) -> f64 {
        NODES
            .iter()
            .enumerate()
            .map(|(i, n)| {
                let c = self.contents[i];
                network::stored_j(&self.rig, *n, c, y[T0 + i]) - network::stored_j(&self.rig, *n, c, y0[T0 + i])
            })
            .sum()
    }

    /// The LNG valve rule of the drive.
    pub fn valve_rule(&self) -> ValveRule {
        match &self.drive {
            Drive::Mission(m) => m.valve,
            Drive::Replay(_) => ValveRule::External,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The segment hint of `locate` changes only the search, not the
    /// answer: for times ascending, descending, jumping and outside the log,
    /// the same (segment, fraction) as a fresh binary search.
    #[test]
    fn locate_with_a_hint_equals_the_binary_search() {
        let time_s = vec![0.0, 0.1, 0.2, 0.5, 0.6, 2.0];
        let n = time_s.len();
        let z = vec![0.0; n];
        let inputs = ReplayInputs {
            name: "t".into(),
            circuit: Circuit::Throttle,
            time_s: time_s.clone(),
            speed_rpm: z.clone(),
            current_a: z.clone(),
            p_a_bar: z.clone(),
            p_b_bar: z.clone(),
            ambient_c: z,
            position_mm: None,
            air_speed_mps: None,
            lng_valve: None,
        };
        let d = ReplayDrive::new(inputs);
        let fresh = |t: f64| {
            let i = time_s.partition_point(|&x| x <= t).clamp(1, n - 1) - 1;
            (i, ((t - time_s[i]) / (time_s[i + 1] - time_s[i])).clamp(0.0, 1.0))
        };
        let ts = [-1.0, 0.0, 0.05, 0.1, 0.1, 0.15, 0.2, 0.55, 0.6, 1.9, 2.0, 3.0, 0.3, 0.0, 0.19, 2.5, 0.6, 0.59];
        for t in ts {
            assert_eq!(d.locate(t), fresh(t), "t = {t}");
        }
    }
}
