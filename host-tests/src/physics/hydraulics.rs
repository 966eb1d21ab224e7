//! Hydraulics and mechanics: pump flows, the Case 1 throttle path, the
//! cylinder with its spring–damper load, chamber pressures with bulk
//! modulus, relief and check valves, the position loop of Case 2.

use crate::rig::Rig;
use crate::physics::mission::{Circuit, Mission};
use std::f64::consts::PI;

/// Index of the hydraulic states in the state vector.
pub mod ix {
    /// Port-A line (and chamber A) pressure, Pa gauge.
    pub const PA: usize = 0;
    /// Port-B line (and chamber B) pressure, Pa gauge.
    pub const PB: usize = 1;
    /// Piston position, m.
    pub const X: usize = 2;
    /// Piston velocity, m/s.
    pub const V: usize = 3;
    /// Motor (= pump shaft) speed, rad/s.
    pub const OMEGA: usize = 4;
    /// Number of hydraulic states.
    pub const N: usize = 5;
}

/// Reference flow at which the needle valve is set (500 rpm, paper Case 1), rpm.
pub const NEEDLE_SET_RPM: f64 = 500.0;

/// Smooth positive part ½(x + √(x² + w²)): a valve's opening characteristic
/// with a transition width `w` (keeps the right-hand side differentiable for
/// the stiff solver).
pub fn soft_pos(x: f64, w: f64) -> f64 {
    0.5 * (x + (x * x + w * w).sqrt())
}

/// Valve opening ramp with no leakage tail: 0 below 0, x²/(2w) on [0, w],
/// x − w/2 above (continuously differentiable, so Newton's iteration sees no
/// kink, and exactly closed below the cracking point).
pub fn ramp(x: f64, w: f64) -> f64 {
    if x <= 0.0 {
        0.0
    } else if x < w {
        x * x / (2.0 * w)
    } else {
        x - 0.5 * w
    }
}

/// Smooth absolute value √(x² + w²) − w.
pub fn soft_abs(x: f64, w: f64) -> f64 {
    (x * x + w * w).sqrt() - w
}

/// The hydraulic operating point: everything the losses and the thermal
/// network need from the hydraulic side at one instant.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OpPoint {
    /// Shaft speed, rad/s.
    pub omega: f64,
    /// Port A pressure, Pa gauge.
    pub p_a: f64,
    /// Port B pressure, Pa gauge.
    pub p_b: f64,
    /// Pump case pressure, Pa gauge (the accumulator's).
    pub p_case: f64,
    /// Piston position, m.
    pub x: f64,
    /// Piston velocity, m/s.
    pub v: f64,
    /// Flow through the throttle path A → B, m³/s.
    pub q_path: f64,
    /// Motor current, A rms.
    pub current_a: f64,
    /// Hydraulic circuit.
    pub circuit: Circuit,
    /// Ambient temperature, °C.
    pub ambient_c: f64,
    /// Air speed over the housings, m/s (logged ram air plus unlogged extension air).
    pub air_mps: f64,
}

impl OpPoint {
    /// Circulation flow through the ring of oil nodes, m³/s (signed: positive
    /// A-ward through the pump): the throttle flow in Case 1, the piston's
    /// swept flow in Case 2.
    pub fn circulation(&self, rig: &Rig) -> f64 {
        match self.circuit {
            Circuit::Throttle => self.q_path,
            Circuit::Servo => rig.actuator.ram_area_m2 * self.v,
        }
    }
}

/// Needle-valve orifice coefficient K (m³/s/√Pa) for a setting of `bar` at
/// the 500 rpm reference flow; `None` when fully open (0 bar).
pub fn needle_k(rig: &Rig, bar: f64) -> Option<f64> {
    if bar <= 1e-3 {
        None
    } else {
        let q_ref = rig.displacement_m3_per_rad() * NEEDLE_SET_RPM * 2.0 * PI / 60.0;
        Some(q_ref / (bar * 1e5).sqrt())
    }
}

/// Pressure drop of the throttle path at flow `q` with the oil at `t_oil`
/// (its viscosity and density): line friction and local losses (eq. 10) plus
/// the needle orifice, Pa. Returns (line part, needle part).
pub fn path_dp(rig: &Rig, q: f64, t_oil: f64, needle: Option<f64>) -> (f64, f64) {
    path_dp_props(rig, q, rig.oil.rho(t_oil, 0.0), rig.oil.nu_m2_per_s(t_oil), needle)
}

/// [`path_dp`] with the oil's density `rho` (kg/m³) and kinematic
/// viscosity `nu` (m²/s) given instead of its temperature, Pa.
pub fn path_dp_props(rig: &Rig, q: f64, rho: f64, nu: f64, needle: Option<f64>) -> (f64, f64) {
    let line = rig.hydraulics.path.dp_pa(q, nu, rho);
    let needle_dp = needle.map_or(0.0, |k| q * q.abs() / (k * k));
    (line, needle_dp)
}

/// Flow of the throttle path A → B for a pressure difference `dp` (Pa) with
/// the oil at `t_oil`, m³/s: the inverse of Δp = R₁·q + R₂·q·|q|, with R₁ the laminar
/// (Hagen–Poiseuille, λ = 64/Re) resistance of the path's line and R₂ its
/// local losses Σξ plus the needle orifice. The path runs laminar at the rig's
/// flows (Re ≈ 500 at 9.5 L/min); the line heat itself is evaluated by eq. (10)
/// with the regime-dependent friction factor.
pub fn path_flow(rig: &Rig, dp: f64, t_oil: f64, needle: Option<f64>) -> f64 {
    path_flow_props(rig, dp, rig.oil.rho(t_oil, 0.0), rig.oil.nu_m2_per_s(t_oil), needle)
}

/// [`path_flow`] with the oil's density `rho` (kg/m³) and kinematic
/// viscosity `nu` (m²/s) given instead of its temperature, m³/s.
pub fn path_flow_props(rig: &Rig, dp: f64, rho: f64, nu: f64, needle: Option<f64>) -> f64 {
    path_flow_geom(&PathGeom::new(rig), dp, rho, nu, needle_inv_k2(needle))
}

/// The needle orifice's term 1/k² of the throttle path's quadratic
/// resistance (`needle`: its k from [`needle_k`], None: no orifice, 0),
/// Pa·s²/m⁶.
pub fn needle_inv_k2(needle: Option<f64>) -> f64 {
    needle.map_or(0.0, |k| 1.0 / (k * k))
}

/// The throttle path's rig constants of [`path_flow_props`] (the line's
/// length m, its local loss coefficient Σξ, π·d⁴ m⁴ and 2·a² m⁴), taken
/// once by a model rather than in every hydraulic evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathGeom {
    /// Line length, m.
    pub length_m: f64,
    /// Local loss coefficient Σξ.
    pub loss_coeff: f64,
    /// π·d⁴, m⁴.
    pub pi_d4: f64,
    /// 2·a² (a the line's cross-section), m⁴.
    pub two_a2: f64,
}

impl PathGeom {
    /// The constants of `rig`'s throttle path.
    pub fn new(rig: &Rig) -> Self {
        let line = &rig.hydraulics.path;
        let a = line.area_m2();
        Self { length_m: line.length_m, loss_coeff: line.local_loss_coeff, pi_d4: PI * line.diameter_m.powi(4), two_a2: 2.0 * a * a }
    }
}

/// [`path_flow_props`] with the path's constants `g` and the needle's
/// 1/k² ([`needle_inv_k2`]) given: the same operations, m³/s.
pub fn path_flow_geom(g: &PathGeom, dp: f64, rho: f64, nu: f64, inv_k2: f64) -> f64 {
    let r1 = 128.0 * nu * rho * g.length_m / g.pi_d4;
    let r2 = rho * g.loss_coeff / g.two_a2 + inv_k2;
    let m = dp.abs();
    dp.signum() * 2.0 * m / (r1 + (r1 * r1 + 4.0 * r2 * m).sqrt())
}

/// Flows of the pump and valves at an operating point, m³/s.
#[derive(Debug, Clone, Copy, Default)]
pub struct Flows {
    /// Geometric pump flow D·ω (into A), m³/s.
    pub geometric: f64,
    /// Leakage from port A to the case, m³/s.
    pub leak_a: f64,
    /// Leakage from port B to the case, m³/s.
    pub leak_b: f64,
    /// Check-valve flow from the accumulator into A, B, m³/s.
    pub check_a: f64,
    /// Check-valve flow into B.
    pub check_b: f64,
    /// Relief flow A → B.
    pub relief_ab: f64,
    /// Relief flow B → A.
    pub relief_ba: f64,
    /// Actuator cross-piston leakage A → B (eq. 11), m³/s.
    pub act_leak: f64,
}

/// Pump, valve and actuator flows at `op` with the pump leakage conductance `k_leak`.
pub fn flows(rig: &Rig, op: &OpPoint, k_leak: f64) -> Flows {
    let h = &rig.hydraulics;
    let w = 0.3e5; // valve transition width, Pa
    let dp = op.p_a - op.p_b;
    Flows {
        geometric: rig.displacement_m3_per_rad() * op.omega,
        leak_a: k_leak * (op.p_a - op.p_case),
        leak_b: k_leak * (op.p_b - op.p_case),
        check_a: h.check_gain * ramp(h.accumulator_pa - op.p_a, w),
        check_b: h.check_gain * ramp(h.accumulator_pa - op.p_b, w),
        relief_ab: h.relief_gain * ramp(dp - h.relief_crack_pa, w),
        relief_ba: h.relief_gain * ramp(-dp - h.relief_crack_pa, w),
        act_leak: match op.circuit {
            Circuit::Servo => rig.actuator.leak_m3_per_s_pa * dp,
            Circuit::Throttle => 0.0,
        },
    }
}

/// The check valves' flow limited to the loop's make-up need, for a replay.
///
/// A replay imposes the logged port pressures, so the check valves' orifice
/// law against the rig file's accumulator pressure says nothing about the
/// machine: a charge pressure 1 bar off the rig file's (a bench at 4 bar, the
/// file at 5) would let ~0.1 L/s of make-up oil through that nothing needs
/// and book 5–25 W of valve heat in the loop oil. What the log does fix is
/// the need: the loop loses `leak_a + leak_b` to the case and the check
/// valves can pass no more than that (a soft minimum, width 1e-9 m³/s, so the
/// right-hand side stays smooth in the case oil's temperature). The two
/// valves keep their shares of the orifice law's flow.
pub fn limit_check_to_makeup(f: &mut Flows) {
    let w = 1e-9;
    let total = f.check_a + f.check_b;
    if total <= 0.0 {
        return;
    }
    let need = soft_pos(f.leak_a + f.leak_b, w);
    let q = 0.5 * (total + need - ((total - need) * (total - need) + w * w).sqrt());
    let scale = (q / total).clamp(0.0, 1.0);
    f.check_a *= scale;
    f.check_b *= scale;
}

/// Motor shaft torque: pump load D·Δp plus the friction torques of eq. (8),
/// churning and bearings (opposing the motion), N·m.
pub fn shaft_torque(rig: &Rig, op: &OpPoint, friction_w: f64) -> f64 {
    let d = rig.displacement_m3_per_rad();
    let sign = op.omega / (op.omega * op.omega + 1e-4).sqrt();
    let w = op.omega.abs().max(1.0);
    d * (op.p_a - op.p_b) + sign * friction_w / w
}

/// Speed command of the drive, rad/s: the mission's speed in Case 1; in
/// Case 2 the position loop ω = (A·ẋ_ref + A·K_p·(x_ref − x))/D; both through
/// the smooth [`speed_limit`].
#[inline]
pub fn speed_command(rig: &Rig, m: &Mission, t: f64, x: f64) -> f64 {
    let wmax = rig.motor.max_speed_rpm * 2.0 * PI / 60.0;
    let raw = match m.circuit {
        Circuit::Throttle => m.speed_rpm.at(t) * 2.0 * PI / 60.0,
        Circuit::Servo => {
            let (xr, vr) = m.position.at(t);
            let a = rig.actuator.ram_area_m2;
            (a * vr + a * rig.actuator.position_gain_per_s * (xr - x)) / rig.displacement_m3_per_rad()
        }
    };
    speed_limit(raw, wmax)
}

/// Smooth speed limit: the identity up to 80 % of `wmax` (no nominal
/// operating point is touched), then a tanh knee that tends to `wmax`;
/// continuous with its first derivative, odd in `raw`, rad/s.
#[inline]
pub fn speed_limit(raw: f64, wmax: f64) -> f64 {
    let knee = 0.8 * wmax;
    let a = raw.abs();
    if a <= knee {
        raw
    } else {
        let span = wmax - knee;
        raw.signum() * (knee + span * ((a - knee) / span).tanh())
    }
}

/// Derivatives of the hydraulic states (`dy` = the derivative of the full
/// state), given the operating point `op` and flows `f`.
pub fn derivatives(rig: &Rig, m: &Mission, t: f64, op: &OpPoint, f: &Flows, dy: &mut [f64]) {
    // One length check for the five writes.
    let dy: &mut [f64; ix::N] = (&mut dy[..ix::N]).try_into().expect("the hydraulic derivatives");
    let act = &rig.actuator;
    let beta = rig.hydraulics.bulk_modulus_pa;
    let v_line = rig.hydraulics.line_volume_m3;
    let (q_cyl, v_a, v_b) = match op.circuit {
        Circuit::Servo => {
            let half = 0.5 * act.stroke_m;
            (act.ram_area_m2 * op.v, v_line + act.ram_area_m2 * (half + op.x), v_line + act.ram_area_m2 * (half - op.x))
        }
        Circuit::Throttle => (0.0, v_line, v_line),
    };
    let relief_net = f.relief_ab - f.relief_ba;
    let q_path = op.q_path;
    dy[ix::PA] = beta / v_a * (f.geometric - f.leak_a - q_path - q_cyl - f.act_leak + f.check_a - relief_net);
    dy[ix::PB] = beta / v_b * (-f.geometric - f.leak_b + q_path + q_cyl + f.act_leak + f.check_b + relief_net);
    match op.circuit {
        Circuit::Throttle => {
            dy[ix::X] = 0.0;
            dy[ix::V] = 0.0;
        }
        Circuit::Servo => {
            let coulomb = rig.ext.coulomb_friction.map_or(0.0, |fc| fc * (op.v / 1e-3).tanh());
            let force = act.ram_area_m2 * (op.p_a - op.p_b)
                - act.spring_n_per_m * op.x
                - (act.damping_n_s_per_m + act.viscous_friction_n_s_per_m) * op.v
                - coulomb;
            dy[ix::X] = op.v;
            dy[ix::V] = force / act.load_mass_kg;
        }
    }
    dy[ix::OMEGA] = (speed_command(rig, m, t, op.x) - op.omega) / rig.motor.speed_time_constant_s;
}
