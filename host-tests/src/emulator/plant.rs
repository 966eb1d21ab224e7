//! The emulated machine: a quasi-static hydraulic operating point (the
//! hydraulics settle in milliseconds, the temperatures in minutes), the
//! losses of eqs. (1)–(11) placed in a 14-node thermal network of its own
//! (a 15th, the inlet port's oil, only with the experiment switch
//! `RefLaw::TwoPorts`),
//! the sensors as first-order states, integrated by Heun's method with a
//! step bounded by the network's fastest time constant.
//!
//! This file holds the machine's types (nodes, state layout, operating
//! point, case budget, [`Plant`]) and its integration ([`Plant::run`]);
//! the behaviour by topic in sibling modules: `op` the operating point,
//! `network` the right-hand side (sources, links, flows, surfaces,
//! sensors), `budget` the case oil's heat balance, `laws` the loss and
//! film laws.

use super::missions::EmuMission;
use super::params::{EmuParams, RefLaw};
use super::props::{oil_cp, oil_rho};
use crate::physics::candidates::Candidate;

/// Thermal nodes of the emulator (the reference model has 12 others).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(usize)]
pub enum N {
    /// Stator: copper and laminations together.
    Stator,
    /// Motor housing (Point 1).
    MotorCase,
    /// Pump barrel housing (most of Point 3).
    Barrel,
    /// Pump port end cap, bolted to the manifold plate.
    EndCap,
    /// Case (drain) oil.
    CaseOil,
    /// Oil in the two port passages.
    PortOil,
    /// Manifold plate: the part of the main block the pump is bolted to.
    Manifold,
    /// Oil circulating in the manifold, block passages and accumulator.
    LoopOil,
    /// Main valve block (Point 4).
    Block,
    /// Ball/needle-valve block (Point 5).
    Ball,
    /// Oil in the ball/needle-valve block.
    BallOil,
    /// Cylinder barrel.
    Cylinder,
    /// Oil in the cylinder chambers.
    CylOil,
    /// Dead-end sensor pocket (only coupled with hidden `sensor-lag`).
    Pocket,
    /// Oil in the inlet port passage: a node of its own only with the
    /// experiment switch `RefLaw::TwoPorts` (then [`N::PortOil`] is the
    /// outlet's); otherwise coupled to nothing and never read.
    InletOil,
}

/// Number of nodes.
pub const NN: usize = 15;
/// State: node temperatures, five sensor states, the drain-port
/// thermocouple ([`DRAIN_SENSOR`]), piston position.
pub const NS: usize = NN + 7;
/// Index of the drain-port thermocouple's state: the case (drain) oil
/// through a first-order lag of `EmuParams::drain_tau_s`.
pub const DRAIN_SENSOR: usize = NN + 5;

/// The hidden effect switched on in the emulated machine, with its
/// magnitude in the unit of the diagnosis candidate's parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hidden {
    /// Which effect (`Candidate::None` for none).
    pub effect: Candidate,
    /// Magnitude (α 1/K, τ s, N, W/(rad/s)^2.5, W/K, m/s).
    pub magnitude: f64,
}

/// Operating point and the heat sources at one instant.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Op {
    /// Shaft speed, rad/s.
    pub omega: f64,
    /// Motor current, A rms.
    pub current_a: f64,
    /// Port pressures, Pa gauge.
    pub p_a: f64,
    /// Port B, Pa gauge.
    pub p_b: f64,
    /// Piston speed, m/s.
    pub v: f64,
    /// Pump leakage flow to the case, m³/s.
    pub q_leak: f64,
    /// Flow through the throttle path, m³/s.
    pub q_path: f64,
    /// Air speed over the housings (logged ram air + hidden draught), m/s.
    pub air: f64,
}

/// The case (drain) oil's heat balance at one instant ([`Plant::case_budget`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CaseBudget {
    /// The case oil's share of the pump's mechanical loss, W.
    pub mech_w: f64,
    /// The whole mechanical loss η_m·D·|Δp|·|ω| (eq. 8), W.
    pub mech_total_w: f64,
    /// Leakage throttled into the case, (1 − αT)·q_leak·Δp, W.
    pub leak_w: f64,
    /// Enthalpy the leakage brings from the port oil above the case oil's, W.
    pub inflow_w: f64,
    /// Case films to the barrel and end cap together, W/K.
    pub film_w_per_k: f64,
    /// Area-weighted wall temperature behind the films, °C.
    pub wall_c: f64,
    /// Case oil, °C.
    pub case_c: f64,
    /// Leakage flow, m³/s.
    pub q_leak: f64,
}

/// Emulated machine running one mission.
pub struct Plant<'a> {
    /// Parameters.
    pub p: &'a EmuParams,
    /// Mission.
    pub m: &'a EmuMission,
    /// Hidden effect.
    pub h: Hidden,
}

impl Plant<'_> {
    /// The hidden effect's magnitude if `c` is the effect switched on.
    pub(super) fn mag(&self, c: Candidate) -> Option<f64> {
        (self.h.effect == c).then_some(self.h.magnitude)
    }

    /// Heat capacities of the nodes at temperatures `y`, J/K.
    pub fn capacities(&self, y: &[f64]) -> [f64; NN] {
        let p = self.p;
        let oil = |v: f64, i: N| v * oil_rho(y[i as usize]) * oil_cp(y[i as usize]);
        let two = p.like_reference.has(RefLaw::TwoPorts);
        [
            p.c_stator,
            p.c_motor_case,
            p.c_pump[0],
            p.c_pump[1],
            oil(p.v_case, N::CaseOil),
            oil(if two { 0.5 * p.v_port } else { p.v_port }, N::PortOil),
            p.c_manifold,
            oil(p.v_loop, N::LoopOil),
            p.c_block,
            p.c_ball,
            oil(p.v_ball, N::BallOil),
            p.cyl[0],
            oil(p.cyl[1], N::CylOil),
            oil(p.pocket[0], N::Pocket),
            oil(0.5 * p.v_port, N::InletOil),
        ]
    }

    /// Initial state: everything at the initial ambient (paper assumption
    /// 1), piston centred.
    pub fn initial(&self) -> Vec<f64> {
        let mut y = vec![self.m.ambient_c(0.0); NS];
        y[NS - 1] = 0.0;
        y
    }

    /// Integrates to the end of the mission and returns the state at every
    /// `dt_out` (t = 0 included), with the operating point there.
    pub fn run(&self, dt_out: f64) -> Vec<(f64, Vec<f64>, Op)> {
        let mut y = self.initial();
        let n_out = (self.m.duration_s / dt_out).round() as usize;
        let dt_ctrl = if self.m.scenario.is_servo() { 0.01 } else { 0.5 };
        let (mut k1, mut k2, mut ys) = (vec![0.0; NS], vec![0.0; NS], vec![0.0; NS]);
        let mut t = 0.0;
        let mut out = Vec::with_capacity(n_out + 1);
        for k in 0..=n_out {
            let t_out = k as f64 * dt_out;
            while t < t_out - 1e-9 {
                let rate = self.rhs(t, &y, &mut k1);
                let dt = (0.8 / rate.max(1e-9)).min(dt_ctrl).min(t_out - t);
                for i in 0..NS {
                    ys[i] = y[i] + dt * k1[i];
                }
                self.rhs(t + dt, &ys, &mut k2);
                for i in 0..NS {
                    y[i] += 0.5 * dt * (k1[i] + k2[i]);
                }
                t += dt;
            }
            out.push((t_out, y.clone(), self.op(t_out, &y, y[NS - 1])));
        }
        out
    }
}
