//! The emulated machine's right-hand side: the heat sources of eqs.
//! (1)–(11) placed in its own nodes, the conduction and film links, the
//! advection rings and tidal mixing, the outer surfaces, then the
//! sensors' first-order lags and the piston position.

use super::params::RefLaw;
use super::plant::{Plant, DRAIN_SENSOR, N, NN, NS};
use super::props::{self, oil_cp, oil_rho};
use crate::physics::candidates::Candidate;
use std::f64::consts::PI;

/// Heat flows and conductance sums being assembled, per node.
struct Acc {
    q: [f64; NN],
    g: [f64; NN],
}

impl Acc {
    /// Symmetric exchange `g` (W/K) between `a` and `b`.
    fn link(&mut self, y: &[f64], a: N, b: N, g: f64) {
        let w = g * (y[a as usize] - y[b as usize]);
        self.q[a as usize] -= w;
        self.q[b as usize] += w;
        self.g[a as usize] += g;
        self.g[b as usize] += g;
    }

    /// Stream of capacity rate `g` (ṁ·c, W/K) from `from` into the
    /// well-mixed node `to`, which sends the same flow on (upwind).
    fn flow(&mut self, y: &[f64], from: N, to: N, g: f64) {
        self.q[to as usize] += g * (y[from as usize] - y[to as usize]);
        self.g[to as usize] += g;
    }
}

impl Plant<'_> {
    /// Right-hand side: fills `dy` and returns the largest ΣG/C (1/s) of
    /// the thermal nodes, which bounds the explicit step.
    pub fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> f64 {
        let p = self.p;
        let x = y[NS - 1];
        let o = self.op(t, y, x);
        let amb = self.m.ambient_c(t);
        let tn = |n: N| y[n as usize];
        let mut acc = Acc { q: [0.0; NN], g: [0.0; NN] };
        // Sources, eqs. (1)–(11).
        let alpha = self.mag(Candidate::WindingResistanceTemperature).unwrap_or(0.0);
        let r = p.r25_ohm * (1.0 + alpha * (tn(N::Stator) - 25.0));
        acc.q[N::Stator as usize] += 3.0 * o.current_a * o.current_a * r + self.iron_w(o.omega);
        let dp = o.p_a - o.p_b;
        let d_rad = p.displacement_m3 / (2.0 * PI);
        let mech = p.eta_m * d_rad * dp.abs() * o.omega.abs();
        let [ms_oil, ms_case, ms_metal] = p.mech_split;
        acc.q[N::PortOil as usize] += ms_oil * mech;
        acc.q[N::EndCap as usize] += ms_metal * mech;
        let churn = self.mag(Candidate::ChurningLoss).map_or(0.0, |k| k * o.omega.abs().powf(2.5));
        // First law for the oil in the throttle runs: the pump's pressure
        // work on the delivered flow heats it by α·T per unit of work
        // (compression); the leakage, the needle and the hoses return the
        // rest, (1 − α·T), on expansion. One α·T (at the port oil) for all
        // four keeps the total at Δp·Q. Servo runs: all on expansion.
        let at = if self.m.scenario.is_servo() { 0.0 } else { props::oil_alpha(tn(N::PortOil)) * (tn(N::PortOil) + 273.15) };
        acc.q[N::CaseOil as usize] += ms_case * mech + (1.0 - at) * o.q_leak * (o.p_a.max(o.p_b) - p.boost_pa) + churn;
        if self.m.scenario.is_servo() {
            let coul = self.mag(Candidate::CoulombFriction).map_or(0.0, |f| f * (o.v / 1e-3).tanh() * o.v);
            acc.q[N::Cylinder as usize] += p.seal_viscous * o.v * o.v + coul;
            acc.q[N::CylOil as usize] += p.act_leak * dp * dp;
        } else {
            let hose = self.hose_dp(o.q_path, tn(N::LoopOil)) * o.q_path;
            acc.q[N::PortOil as usize] += at * dp * (o.q_path + o.q_leak);
            acc.q[N::LoopOil as usize] += (1.0 - at) * hose;
            acc.q[N::BallOil as usize] += (1.0 - at) * (dp * o.q_path - hose).max(0.0);
        }
        // Conduction and films.
        acc.link(y, N::Stator, N::MotorCase, p.g_stator_case);
        if let Some(g) = self.mag(Candidate::MotorPumpConduction) {
            acc.link(y, N::MotorCase, N::Barrel, g);
        }
        acc.link(y, N::Barrel, N::EndCap, p.g_barrel_end);
        acc.link(y, N::EndCap, N::Manifold, p.g_end_manifold);
        acc.link(y, N::Manifold, N::Block, p.g_manifold_block);
        acc.link(y, N::Ball, N::Block, p.g_ball_block);
        let nu_case = self.nu(tn(N::CaseOil));
        for (wall, a) in [(N::Barrel, p.a_case[0]), (N::EndCap, p.a_case[1])] {
            acc.link(y, N::CaseOil, wall, self.case_film(o.omega, a, nu_case, tn(N::CaseOil)));
        }
        let q_geo = d_rad * o.omega.abs();
        let duct = |dct: [f64; 3], flow: f64, n: N| self.duct(dct, flow.max(1e-7), tn(n), matches!(n, N::LoopOil | N::BallOil));
        let two = p.like_reference.has(RefLaw::TwoPorts);
        if two {
            // the reference's two port nodes, each on half the passages
            let half = [p.port_duct[0], p.port_duct[1], 0.5 * p.port_duct[2]];
            acc.link(y, N::PortOil, N::EndCap, duct(half, q_geo, N::PortOil));
            acc.link(y, N::InletOil, N::EndCap, duct(half, q_geo, N::InletOil));
        } else {
            acc.link(y, N::PortOil, N::EndCap, duct(p.port_duct, q_geo, N::PortOil));
        }
        let [s_manifold, s_block, s_ball] = [p.surfaces[3][0], p.surfaces[4][0], p.surfaces[5][0]];
        acc.link(y, N::LoopOil, N::Manifold, self.block_film(duct(p.plate_duct, q_geo, N::LoopOil), s_manifold));
        acc.link(y, N::LoopOil, N::Block, self.block_film(duct(p.block_duct, q_geo, N::LoopOil), s_block));
        let q_ball = if self.m.scenario.is_servo() { 0.0 } else { o.q_path };
        acc.link(y, N::BallOil, N::Ball, self.block_film(duct(p.ball_duct, q_ball, N::BallOil), s_ball));
        let q_cyl = 1526.81e-6 * o.v.abs();
        acc.link(y, N::CylOil, N::Cylinder, duct([0.063, 0.1, p.cyl[2]], q_cyl, N::CylOil));
        // Sensor pocket: dead end with `sensor-lag`, otherwise a small
        // well-stirred volume following the loop (never read then).
        let c_pocket = p.pocket[0] * oil_rho(tn(N::Pocket)) * oil_cp(tn(N::Pocket));
        match self.mag(Candidate::SensorLag) {
            Some(tau) => {
                acc.link(y, N::LoopOil, N::Pocket, c_pocket / tau);
                acc.link(y, N::Manifold, N::Pocket, p.pocket[1]);
            }
            None => acc.link(y, N::LoopOil, N::Pocket, c_pocket / 5.0),
        }
        // Advection (upwind, mass-balanced rings) and tidal mixing.
        let rho_cp = |n: N| oil_rho(tn(n)) * oil_cp(tn(n));
        acc.flow(y, N::PortOil, N::CaseOil, o.q_leak * rho_cp(N::PortOil));
        acc.flow(y, N::CaseOil, N::LoopOil, o.q_leak * rho_cp(N::CaseOil));
        // The pump's suction: the loop oil straight into the (outlet) port
        // node, or through the inlet port's node (`RefLaw::TwoPorts`).
        let suction = |acc: &mut Acc, q: f64| {
            if two {
                acc.flow(y, N::LoopOil, N::InletOil, q * rho_cp(N::LoopOil));
                acc.flow(y, N::InletOil, N::PortOil, q * rho_cp(N::InletOil));
            } else {
                acc.flow(y, N::LoopOil, N::PortOil, q * rho_cp(N::LoopOil));
            }
        };
        if self.m.scenario.is_servo() {
            suction(&mut acc, o.q_leak);
            // Oil swinging between pump, manifold and chambers.
            let g_pump = q_geo * rho_cp(N::PortOil);
            acc.link(y, N::PortOil, N::LoopOil, g_pump);
            if two {
                acc.link(y, N::InletOil, N::LoopOil, q_geo * rho_cp(N::InletOil));
            }
            acc.link(y, N::LoopOil, N::CylOil, 0.5 * q_cyl * rho_cp(N::LoopOil));
        } else {
            suction(&mut acc, o.q_path + o.q_leak);
            acc.flow(y, N::PortOil, N::BallOil, o.q_path * rho_cp(N::PortOil));
            acc.flow(y, N::BallOil, N::LoopOil, o.q_path * rho_cp(N::BallOil));
        }
        // Outer surfaces.
        let outer = [N::MotorCase, N::Barrel, N::EndCap, N::Manifold, N::Block, N::Ball, N::Cylinder];
        for (k, n) in outer.iter().enumerate() {
            let w = self.outer_w(p.surfaces[k], (3..6).contains(&k), tn(*n), amb, o.air);
            acc.q[*n as usize] -= w;
            acc.g[*n as usize] += (w / (tn(*n) - amb)).abs().min(50.0);
        }
        if p.like_reference.has(RefLaw::Mount) {
            // the rig file's bench mount of the main block, 2 W/K
            acc.q[N::Block as usize] -= 2.0 * (tn(N::Block) - amb);
            acc.g[N::Block as usize] += 2.0;
        }
        let c = self.capacities(y);
        let mut rate: f64 = 0.0;
        for i in 0..NN {
            dy[i] = acc.q[i] / c[i];
            rate = rate.max(acc.g[i] / c[i]);
        }
        // Sensors: Point 1, Point 3 (barrel/end-cap mix), Point 4,
        // Point 5 (surface probes read a little towards ambient) and the
        // manifold oil (thermowell in the flow, or the dead-end pocket).
        let surf = |t: f64| t - p.probe_ambient_frac * (t - amb);
        let w = p.pump_probe_barrel;
        let oil_target = if self.h.effect == Candidate::SensorLag { tn(N::Pocket) } else { tn(N::LoopOil) };
        let targets = [
            surf(tn(N::MotorCase)),
            surf(w * tn(N::Barrel) + (1.0 - w) * tn(N::EndCap)),
            surf(tn(N::Block)),
            surf(tn(N::Ball)),
            oil_target,
        ];
        for k in 0..5 {
            dy[NN + k] = (targets[k] - y[NN + k]) / p.sensor_tau[k];
        }
        // Drain-port thermocouple in the case-drain flow.
        dy[DRAIN_SENSOR] = (tn(N::CaseOil) - y[DRAIN_SENSOR]) / p.drain_tau_s;
        dy[NS - 1] = o.v;
        rate
    }
}
