//! The emulated machine: a quasi-static hydraulic operating point (the
//! hydraulics settle in milliseconds, the temperatures in minutes), the
//! losses of eqs. (1)–(11) placed in a 14-node thermal network of its own
//! (a 15th, the inlet port's oil, only with the experiment switch
//! `RefLaw::TwoPorts`),
//! the sensors as first-order states, integrated by Heun's method with a
//! step bounded by the network's fastest time constant.

use super::missions::{linear_at, step_at, EmuMission};
use super::params::{EmuParams, RefLaw};
use super::props::{self, oil_cp, oil_rho};
use crate::physics::candidates::Candidate;
use std::f64::consts::PI;

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
    fn mag(&self, c: Candidate) -> Option<f64> {
        (self.h.effect == c).then_some(self.h.magnitude)
    }

    /// Operating point at `t` with temperatures `y` and piston position `x`.
    pub fn op(&self, t: f64, y: &[f64], x: f64) -> Op {
        let p = self.p;
        let mu_case = self.nu(y[N::CaseOil as usize]) * oil_rho(y[N::CaseOil as usize]);
        let kl = self.k_leak(mu_case);
        let air = step_at(&self.m.air, t) + self.mag(Candidate::ForcedConvection).unwrap_or(0.0);
        let d_rad = p.displacement_m3 / (2.0 * PI);
        let churn = |w: f64| self.mag(Candidate::ChurningLoss).map_or(0.0, |k| k * w.abs().powf(1.5) * w.signum());
        if self.m.scenario.is_servo() {
            let v = p.pos_gain * (linear_at(&self.m.x_ref, t) - x);
            let fc = self.mag(Candidate::CoulombFriction).map_or(0.0, |f| f * (v / 1e-3).tanh());
            // Spring, spring damping, seal friction; the 13.5 kg load's
            // inertia (< 30 N here) is left out.
            let force = 245e3 * x + 15e3 * v + p.seal_viscous * v + fc;
            let dp = force / 1526.81e-6;
            let q_leak = kl * dp.abs();
            let q = 1526.81e-6 * v + p.act_leak * dp + q_leak * dp.signum();
            let omega = q / d_rad;
            let torque = d_rad * dp + p.eta_m * d_rad * dp.abs() * omega.signum() + churn(omega);
            let drag = self.iron_drag_nm(omega);
            let (pa, pb) = (p.boost_pa + dp.max(0.0), p.boost_pa + (-dp).max(0.0));
            Op { omega, current_a: (torque.abs() + drag) / p.kt_nm_per_a, p_a: pa, p_b: pb, v, q_leak, q_path: 0.0, air }
        } else {
            let omega = step_at(&self.m.speed, t) * PI / 30.0;
            // Needle opening set for the target drop at the nominal flow
            // (first guess without leakage), then the actual drop.
            let q_nom = d_rad * omega;
            let target = step_at(&self.m.dp_bar, t).max(0.5) * 1e5;
            let rho = oil_rho(y[N::BallOil as usize]);
            let area = q_nom / (p.needle_cd * (2.0 * target / rho).sqrt());
            let mut q_path = q_nom;
            let mut dp = target;
            for _ in 0..3 {
                q_path = (q_nom - kl * dp).max(0.0);
                dp = 0.5 * rho * (q_path / (p.needle_cd * area)).powi(2) + self.hose_dp(q_path, y[N::LoopOil as usize]);
            }
            let torque = d_rad * dp * (1.0 + p.eta_m) + churn(omega);
            let drag = self.iron_drag_nm(omega);
            Op {
                omega,
                current_a: (torque + drag) / p.kt_nm_per_a,
                p_a: p.boost_pa + dp,
                p_b: p.boost_pa,
                v: 0.0,
                q_leak: kl * dp,
                q_path,
                air,
            }
        }
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

    /// The case (drain) oil's heat balance at `t` with state `y`, read-only
    /// (the same laws as [`Plant::rhs`], for heat-source audits against the
    /// reference): what enters the case oil by source and what its films
    /// take to the housing.
    pub fn case_budget(&self, t: f64, y: &[f64]) -> CaseBudget {
        let p = self.p;
        let o = self.op(t, y, y[NS - 1]);
        let tn = |n: N| y[n as usize];
        let dp = o.p_a - o.p_b;
        let d_rad = p.displacement_m3 / (2.0 * PI);
        let mech = p.eta_m * d_rad * dp.abs() * o.omega.abs();
        let at = if self.m.scenario.is_servo() { 0.0 } else { props::oil_alpha(tn(N::PortOil)) * (tn(N::PortOil) + 273.15) };
        let nu_case = self.nu(tn(N::CaseOil));
        let film: f64 = p.a_case.iter().map(|&a| self.case_film(o.omega, a, nu_case, tn(N::CaseOil))).sum();
        let wall = p.a_case[0] * tn(N::Barrel) + p.a_case[1] * tn(N::EndCap);
        let wall = wall / (p.a_case[0] + p.a_case[1]);
        let rho_cp = oil_rho(tn(N::PortOil)) * oil_cp(tn(N::PortOil));
        CaseBudget {
            mech_w: p.mech_split[1] * mech,
            mech_total_w: mech,
            leak_w: (1.0 - at) * o.q_leak * (o.p_a.max(o.p_b) - p.boost_pa),
            inflow_w: o.q_leak * rho_cp * (tn(N::PortOil) - tn(N::CaseOil)),
            film_w_per_k: film,
            wall_c: wall,
            case_c: tn(N::CaseOil),
            q_leak: o.q_leak,
        }
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

#[cfg(test)]
mod tests {
    use super::super::missions::{draw, EmuScenario};
    use super::*;
    use rand::SeedableRng;

    /// The case budget is the case-oil node's own balance: capacity × dT/dt
    /// of [`Plant::rhs`] equals what enters (mechanical share, leakage
    /// throttled, the leakage's enthalpy from the port oil) minus the films
    /// to the wall, at a hot state 600 s into a throttle mix (to 1e-9
    /// relative: the same laws, summed in another order).
    #[test]
    fn case_budget_is_the_case_oil_balance() {
        let p = EmuParams::default();
        let m = draw(EmuScenario::ThrottleMix, 900.0, &mut rand_chacha::ChaCha8Rng::seed_from_u64(7));
        let plant = Plant { p: &p, m: &m, h: Hidden { effect: Candidate::None, magnitude: 0.0 } };
        let trace = plant.run(300.0);
        let (t, y, _) = &trace[2];
        let mut dy = vec![0.0; NS];
        plant.rhs(*t, y, &mut dy);
        let c = plant.capacities(y)[N::CaseOil as usize];
        let b = plant.case_budget(*t, y);
        let net = b.mech_w + b.leak_w + b.inflow_w - b.film_w_per_k * (b.case_c - b.wall_c);
        let lhs = c * dy[N::CaseOil as usize];
        assert!(b.mech_w > 0.0 && b.leak_w > 0.0 && b.case_c > b.wall_c, "{b:?}");
        assert!((lhs - net).abs() <= 1e-9 * (b.mech_w + b.leak_w + b.inflow_w.abs()), "C dT/dt {lhs} W, budget {net} W ({b:?})");
    }
}
