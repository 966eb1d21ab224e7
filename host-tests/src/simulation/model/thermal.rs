//! The thermal right-hand side: the node heat balances (network eqs.
//! 12–19, the advection ring, the LNG exchanger eqs. 20–22) and the energy
//! integrals. Separate because it is the longest single part of the model.

use super::{FrictionHeat, Losses, Model};
use crate::hydraulics::{self, OpPoint};
use crate::network::{self, Node, N_NODES, NODES};
use crate::scenario::Circuit;

impl Model {
    /// Thermal right-hand side: node heat balances and energy integrals.
    /// Returns (energy input W, heat to ambient W, heat to LNG W) and fills
    /// `dt` (K/s per node). The energy input is every loss that enters a node
    /// as heat plus the pump's work on the oil, minus the actuator's: the
    /// pump leakage, line and needle losses are not sources here, they follow
    /// from the oil's enthalpy h(T, p) at each node's pressure.
    pub fn thermal(&self, op: &OpPoint, l: &Losses, temps: &[f64], dt: &mut [f64]) -> (f64, f64, f64) {
        let t_case = temps[Node::Case as usize];
        let fh = self.friction_heat(op, t_case);
        let f = hydraulics::flows(&self.rig, op, self.k_leak(t_case));
        self.thermal_with(op, l, &fh, &f, None, temps, dt)
    }

    /// [`Model::thermal`] given the pump's friction heat `fh` and the flows
    /// `f` at `op` and these temperatures (from [`Model::loss_parts`]), and
    /// the throttle path's line pressure drop at |q_path| if it was taken
    /// there (`line_dp`, Pa; None: taken here).
    #[allow(clippy::too_many_arguments)] // the parts the losses took, each reused
    pub(super) fn thermal_with(&self, op: &OpPoint, l: &Losses, fh: &FrictionHeat, f: &hydraulics::Flows, line_dp: Option<f64>, temps: &[f64], dt: &mut [f64]) -> (f64, f64, f64) {
        let rig = &self.rig;
        let oil = &rig.oil;
        // As arrays: one length check here instead of one at every read
        // (~50 a balance; the same values).
        let temps: &[f64; N_NODES] = temps[..N_NODES].try_into().expect("a temperature per node");
        let dt: &mut [f64; N_NODES] = (&mut dt[..N_NODES]).try_into().expect("a derivative per node");
        let tc = |n: Node| temps[n as usize];
        let mut q = [0.0f64; N_NODES];
        let mut q_in = 0.0;
        // Heat sources (losses that are not a pressure drop of the ring) into their nodes.
        let hp = if op.p_a >= op.p_b { Node::Outlet } else { Node::Inlet };
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
        let g_ball = self.duct_conductance(qc, b.ball_d_m, b.ball_len_m, 1.0, tc(Node::BallOil), self.ball_oil(tc(Node::BallOil)).1);
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
        let q_leak = hydraulics::soft_pos(f.leak_a, 1e-9) + hydraulics::soft_pos(f.leak_b, 1e-9);
        let m_l = self.ring_mass_flow(q_leak, tc(Node::Loop));
        // The ring's direction: the throttle path's flow; in the servo circuit
        // the piston's flow while it exceeds the leakage, and below that (a
        // hold: the piston still, the pump turning slowly to make up the
        // loaded port's leakage) the pump's delivery (the sign of ω; at a
        // standstill towards the high port): the leakage passes the pump in
        // its delivery direction (taken from the piston alone, a reverse hold
        // lost the pump's work on it). The switch at |A·ẋ| = the leakage flow
        // keeps the jump in the ring's flows at the leakage's size.
        let forward = match op.circuit {
            Circuit::Throttle => qc >= 0.0,
            Circuit::Servo if qc.abs() > q_leak => qc > 0.0,
            Circuit::Servo if op.omega != 0.0 => op.omega > 0.0,
            Circuit::Servo => op.p_a >= op.p_b,
        };
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
            Circuit::Throttle => line_dp.unwrap_or_else(|| self.path_dp(op.q_path.abs(), tc(Node::BallOil), None).0).max(0.0),
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
        // h(T, p) of the ring's nodes and the case oil, each taken once.
        let mut h_node = [0.0f64; N_NODES];
        for &n in ring.iter().chain(&[Node::Case]) {
            h_node[n as usize] = oil.enthalpy_tp(tc(n), pres(n));
        }
        let h = |n: Node| h_node[n as usize];
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
}
