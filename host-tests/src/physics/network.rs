//! Thermal network: the nodes of the lumped model, their heat capacities
//! (Table 2 masses) and the conductances between them (eqs. 12–19),
//! evaluated at the current temperatures and flows.

use crate::heat::{self, h_forced_plate, h_free_cube, h_free_cylinder, h_mixed, radiation_w, series};
use crate::rig::{PumpSplit, Rig};

/// Thermal nodes. Index into the temperature part of the state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(usize)]
pub enum Node {
    /// Motor winding (copper).
    Winding = 0,
    /// Motor housing: Point 1 of the rig.
    Motor,
    /// Pump housing (with its end cap): Point 3.
    Pump,
    /// Oil in the pump case, which leaves through the drain port.
    Case,
    /// Oil in the pump inlet port passage (port B in forward flow).
    Inlet,
    /// Oil in the pump outlet port passage (port A in forward flow).
    Outlet,
    /// Circulating oil in the main-block passages, hoses and accumulator side.
    Loop,
    /// Main valve block: Point 4.
    MainBlock,
    /// Ball/needle-valve block: Point 5.
    BallBlock,
    /// Oil in the ball/needle-valve block, where the throttling heat appears.
    BallOil,
    /// Oil at the manifold temperature sensor.
    Sensor,
    /// Actuator (cylinder body with its oil).
    Actuator,
    /// The pump's internals: cylinder barrel, pistons and slippers, swash and
    /// valve plates, shaft; every sliding pair's faces. A node of its own only
    /// with [`crate::rig::Pump::split`]; otherwise it holds nothing and
    /// follows the pump housing.
    PumpInternals,
}

/// Number of thermal nodes.
pub const N_NODES: usize = 13;

/// All nodes in index order.
pub const NODES: [Node; N_NODES] = [
    Node::Winding,
    Node::Motor,
    Node::Pump,
    Node::Case,
    Node::Inlet,
    Node::Outlet,
    Node::Loop,
    Node::MainBlock,
    Node::BallBlock,
    Node::BallOil,
    Node::Sensor,
    Node::Actuator,
    Node::PumpInternals,
];

impl Node {
    /// Channel name of the node temperature in outputs (°C).
    pub fn channel(self) -> &'static str {
        match self {
            Node::Winding => "t_winding_c",
            Node::Motor => "t_motor_c",
            Node::Pump => "t_pump_c",
            Node::Case => "t_drain_c",
            Node::Inlet => "t_inlet_c",
            Node::Outlet => "t_outlet_c",
            Node::Loop => "t_loop_oil_c",
            Node::MainBlock => "t_block_c",
            Node::BallBlock => "t_ballvalve_c",
            Node::BallOil => "t_ball_oil_c",
            Node::Sensor => "t_oil_c",
            Node::Actuator => "t_actuator_c",
            Node::PumpInternals => "t_pump_internals_c",
        }
    }

    /// Whether the node is oil (capacity from the oil's cp(T)) or metal.
    pub fn is_oil(self) -> bool {
        matches!(self, Node::Case | Node::Inlet | Node::Outlet | Node::Loop | Node::BallOil | Node::Sensor)
    }
}

/// What each node holds: metal nodes (mass kg, specific heat J/(kg·K)), oil
/// nodes (volume m³, 0): an oil node's capacity is its volume times
/// ρ(T)·c_p(T) at its own temperature ([`capacity_j_per_k`]). The nuisance
/// capacity scales are applied here.
pub fn contents(rig: &Rig) -> [(f64, f64); N_NODES] {
    // the internals hold no heat of their own unless the pump is split
    let internals_kg = rig.pump.split.map_or(0.0, |s| s.internals_mass_kg);
    let v = rig.nuisance.oil_capacity_scale;
    let ms = rig.nuisance.metal_capacity_scale;
    let m = &rig.motor;
    [
        (m.winding_mass_kg * ms, m.winding_cp),
        ((m.mass_kg - m.winding_mass_kg) * ms, m.body_cp),
        ((rig.pump.mass_kg - internals_kg) * ms, rig.pump.cp),
        (v * rig.pump.case_oil_m3, 0.0),
        (v * rig.pump.port_oil_m3, 0.0),
        (v * rig.pump.port_oil_m3, 0.0),
        (v * rig.blocks.loop_oil_m3, 0.0),
        (rig.blocks.main_mass_kg * ms, rig.blocks.cp),
        (rig.blocks.ball_mass_kg * ms, rig.blocks.cp),
        (v * rig.blocks.ball_oil_m3, 0.0),
        (v * rig.blocks.sensor_oil_m3, 0.0),
        (rig.actuator.body_mass_kg * ms, rig.actuator.body_cp),
        (internals_kg * ms, rig.pump.cp),
    ]
}

/// Heat capacity of node `n` holding `content` (an entry of [`contents`]) at
/// `t_c`, J/K: m·c for metal, V·ρ(T)·c_p(T) for oil.
pub fn capacity_j_per_k(rig: &Rig, n: Node, content: (f64, f64), t_c: f64) -> f64 {
    if n.is_oil() {
        content.0 * rig.oil.rho_cp(t_c)
    } else {
        content.0 * content.1
    }
}

/// Heat stored in node `n` at `t_c` relative to 20 °C, J (consistent with
/// [`capacity_j_per_k`]: its derivative in `t_c`).
pub fn stored_j(rig: &Rig, n: Node, content: (f64, f64), t_c: f64) -> f64 {
    stored_j_with(&rig.oil.enthalpy_cubic(), n, content, t_c)
}

/// [`stored_j`] with the oil's enthalpy cubic `oil` taken once
/// ([`crate::fluid::Oil::enthalpy_cubic`]), J.
#[inline]
pub fn stored_j_with(oil: &crate::fluid::EnthalpyCubic, n: Node, content: (f64, f64), t_c: f64) -> f64 {
    if n.is_oil() {
        content.0 * oil.at(t_c)
    } else {
        content.0 * content.1 * (t_c - 20.0)
    }
}

/// Oil-to-metal conductance of a duct: forced convection by eqs. (13)/(14)
/// (h = Nu·k/d, eq. 12; eq. 14 times the rig's
/// `blocks.duct_turbulent_scale`) on the wetted area π·d·L·scale, W/K.
pub fn duct_conductance(rig: &Rig, q_m3_per_s: f64, d: f64, len: f64, area_scale: f64, t_oil: f64, nu: f64) -> f64 {
    duct_conductance_with(rig, q_m3_per_s, d, len, area_scale, t_oil, nu, heat::nu_laminar_x)
}

/// [`duct_conductance`] with the laminar Nusselt number of X = Re·Pr·d/L
/// given ([`heat::nu_tube_with`]).
#[allow(clippy::too_many_arguments)] // duct_conductance's arguments and the laminar law
#[inline]
pub fn duct_conductance_with(rig: &Rig, q_m3_per_s: f64, d: f64, len: f64, area_scale: f64, t_oil: f64, nu: f64, laminar: impl Fn(f64) -> f64) -> f64 {
    let re = heat::reynolds(q_m3_per_s, d, nu);
    let pr = rig.oil.prandtl(t_oil, nu);
    let h = heat::nu_tube_turb(re, pr, d / len, laminar, rig.blocks.duct_turbulent_scale) * rig.oil.k(t_oil) / d;
    h * std::f64::consts::PI * d * len * area_scale * rig.nuisance.inner_scale
}

/// Film coefficient of the oil between the pump case and the rotating
/// cylinder barrel (Taylor–Couette flow in the radial gap), W/(m²·K):
/// h = Nu·k/(2e) with Nu from [`heat::nu_taylor_couette`] at the barrel's
/// speed `omega` (rad/s, either sign), times the churned case's
/// [`case_churn_factor`]; it holds on both walls of the gap. `t_oil` °C and
/// `nu` m²/s are the case oil's.
pub fn case_gap_h(rig: &Rig, omega: f64, t_oil: f64, nu: f64) -> f64 {
    let p = &rig.pump;
    let e = p.case_gap_m;
    let r_mean = p.rotor_radius_m + 0.5 * e;
    let ta = omega * omega * r_mean * e.powi(3) / (nu * nu);
    heat::nu_taylor_couette(ta) * rig.oil.k(t_oil) / (2.0 * e) * case_churn_factor(rig, omega, nu)
}

/// Reference speed of the churned case film ([`crate::rig::Pump::case_churn`]
/// is its factor there), rad/s (≈ 955 rpm, inside a 300–1500 rpm bench),
/// with the oil at [`CASE_CHURN_REF_C`].
pub const CASE_CHURN_REF_RAD_S: f64 = 100.0;

/// Speed at which the churned film is half blended in, rad/s (≈ 95 rpm,
/// oil at [`CASE_CHURN_REF_C`]): below it the rim of a 30 mm barrel moves
/// < 0.3 m/s and the stirring Reynolds numbers (~100 on a 15 mm slipper)
/// are far from churned flow; conduction across the gap takes over.
pub const CASE_CHURN_ONSET_RAD_S: f64 = 10.0;

/// Oil temperature of the churned film's reference speeds, °C.
pub const CASE_CHURN_REF_C: f64 = 40.0;

/// Factor of the churned case on the gap's film: 1 + s·(θ·rⁿ − 1), with
/// θ = [`crate::rig::Pump::case_churn`], n =
/// [`crate::rig::Pump::case_churn_speed_exp`], r the gap's Reynolds number
/// ω·r·e/ν over its value at [`CASE_CHURN_REF_RAD_S`] with the oil at
/// [`CASE_CHURN_REF_C`], and the blend s = r²/(r² + r₀²), r₀ the same ratio
/// at [`CASE_CHURN_ONSET_RAD_S`]: the churned law θ·rⁿ on the gap law at
/// speed, the gap law (Nu = 2 across the gap, conduction: a lower bound) at
/// rest. Exactly 1 for the rig file's θ = 1, n = 0. A function of ω/ν alone,
/// as the gap law is (the reduction tabulates it over speed at 40 °C).
pub fn case_churn_factor(rig: &Rig, omega: f64, nu: f64) -> f64 {
    let p = &rig.pump;
    if p.case_churn == 1.0 && p.case_churn_speed_exp == 0.0 {
        return 1.0;
    }
    let r = omega.abs() * rig.oil.nu_m2_per_s(CASE_CHURN_REF_C) / (CASE_CHURN_REF_RAD_S * nu);
    if r == 0.0 {
        return 1.0;
    }
    let r0 = CASE_CHURN_ONSET_RAD_S / CASE_CHURN_REF_RAD_S;
    let s = r * r / (r * r + r0 * r0);
    1.0 + s * (p.case_churn * r.powf(p.case_churn_speed_exp) - 1.0)
}

/// Case-oil film to the pump housing: [`case_gap_h`] on the case's inner
/// area, W/K.
pub fn case_film_w_per_k(rig: &Rig, omega: f64, t_oil: f64, nu: f64) -> f64 {
    case_gap_h(rig, omega, t_oil, nu) * rig.pump.case_inner_area_m2 * rig.nuisance.inner_scale
}

/// Case-oil film to the pump's internals, W/K: the barrel's periphery
/// through the case gap ([`case_gap_h`] on 2π·r·L) plus the slippers and
/// piston shanks swept through the case oil at the barrel's rim speed, a
/// laminar flat plate of the slipper's length ([`heat::nu_flat_plate_laminar`]).
pub fn internals_case_film_w_per_k(rig: &Rig, split: &PumpSplit, omega: f64, t_oil: f64, nu: f64) -> f64 {
    let p = &rig.pump;
    let s = split;
    let barrel = case_gap_h(rig, omega, t_oil, nu) * 2.0 * std::f64::consts::PI * p.rotor_radius_m * s.barrel_length_m;
    let u = omega.abs() * p.rotor_radius_m;
    let re = u * s.swept_length_m / nu;
    let h_swept = heat::nu_flat_plate_laminar(re, rig.oil.prandtl(t_oil, nu)) * rig.oil.k(t_oil) / s.swept_length_m;
    (barrel + h_swept * s.case_swept_area_m2) * rig.nuisance.inner_scale
}

/// Film between the pump's internals and one port's oil through the
/// displacement chambers, W/K: half the pistons' bores face each kidney, each
/// passing its share of the displaced flow `q_displaced` (m³/s, either sign)
/// as a laminar developing duct flow (eq. 13) over the chamber length that
/// makes their wall area half of [`PumpSplit::bore_area_m2`].
pub fn bore_film_w_per_k(rig: &Rig, split: &PumpSplit, q_displaced: f64, t_oil: f64, nu: f64) -> f64 {
    let p = &rig.pump;
    let n = 0.5 * p.gaps.pistons;
    let d = p.gaps.piston_d_m;
    let len = 0.5 * split.bore_area_m2 / (n * std::f64::consts::PI * d);
    if len <= 0.0 {
        return 0.0;
    }
    n * duct_conductance(rig, q_displaced.abs() / n, d, len, 1.0, t_oil, nu)
}

/// Outer surfaces exchanging heat with ambient.
#[derive(Debug, Clone, Copy)]
pub enum Shape {
    /// Horizontal cylinder of the given outer diameter, eq. (15).
    Cylinder(f64),
    /// Cube-like block of the given side, eq. (16).
    Cube(f64),
}

/// The metal nodes that see the air: node, area m², shape, and the share of
/// the area the ram air reaches (1 but for the pump housing, see
/// [`crate::rig::Outside::pump_ram_exposure`]).
pub fn surfaces(rig: &Rig) -> [(Node, f64, Shape, f64); 5] {
    let side = |a: f64| (a / 6.0).sqrt();
    [
        (Node::Motor, rig.motor.area_m2, Shape::Cylinder(rig.motor.diameter_m), 1.0),
        (Node::Pump, rig.pump.area_m2, Shape::Cylinder(rig.pump.diameter_m), rig.outside.pump_ram_exposure),
        (Node::MainBlock, rig.blocks.main_area_m2, Shape::Cube(side(rig.blocks.main_area_m2)), 1.0),
        (Node::BallBlock, rig.blocks.ball_area_m2, Shape::Cube(side(rig.blocks.ball_area_m2)), 1.0),
        (Node::Actuator, rig.actuator.area_m2, Shape::Cylinder(rig.actuator.diameter_m), 1.0),
    ]
}

/// Heat flow from a surface of which the share `ram_share` of `area` sees
/// the ram air at `air_mps` and the rest only free convection, plus
/// radiation from all of it, W.
pub fn q_outer_exposed(rig: &Rig, area: f64, shape: Shape, t_wall: f64, t_air: f64, air_mps: f64, ram_share: f64) -> f64 {
    if air_mps > 0.0 && ram_share < 1.0 {
        ram_share * q_outer(rig, area, shape, t_wall, t_air, air_mps) + (1.0 - ram_share) * q_outer(rig, area, shape, t_wall, t_air, 0.0)
    } else {
        q_outer(rig, area, shape, t_wall, t_air, air_mps)
    }
}

/// Convective coefficient of an outer surface: free convection (eq. 15 or
/// 16) combined with forced convection at `air_mps` (ram air), W/(m²·K); the
/// air at `t_air` and the pressure of the rig's altitude.
pub fn h_outer(rig: &Rig, shape: Shape, t_wall: f64, t_air: f64, air_mps: f64) -> f64 {
    let p_air = rig.outside.air_pressure_pa();
    let free = match shape {
        Shape::Cylinder(d) => h_free_cylinder(t_wall, t_air, p_air, d),
        Shape::Cube(a) => h_free_cube(t_wall, t_air, p_air, a),
    };
    if air_mps > 0.0 {
        // forced convection with the stream's properties: its static
        // temperature (the ambient) and the altitude's pressure
        h_mixed(free, h_forced_plate(air_mps, rig.outside.ram_run_length_m, t_air, p_air))
    } else {
        free
    }
}

/// Heat flow from a surface to ambient: convection (eq. 12) + radiation
/// (eq. 19), times the nuisance outer scale, W.
pub fn q_outer(rig: &Rig, area: f64, shape: Shape, t_wall: f64, t_air: f64, air_mps: f64) -> f64 {
    let conv = h_outer(rig, shape, t_wall, t_air, air_mps) * area * (t_wall - t_air);
    (conv + radiation_w(rig.outside.emissivity, area, t_wall, t_air)) * rig.nuisance.outer_scale
}

/// Conductance through a block wall in series with the oil film, eq. (18)
/// in series with eq. (12), W/K.
pub fn block_path(rig: &Rig, film_w_per_k: f64, block_area_m2: f64) -> f64 {
    let a = (block_area_m2 / 6.0).sqrt();
    series(film_w_per_k, heat::g_plane_wall(rig.blocks.steel_k, a, rig.blocks.wall_m))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The churned case film: exactly the gap law for the rig file and at
    /// rest; θ at the reference speed with the oil at 40 °C (to the blend,
    /// 1 %); a function of ω/ν alone.
    #[test]
    fn case_churn_is_the_gap_law_at_the_centre_and_at_rest() {
        let mut rig = Rig::default();
        let nu40 = rig.oil.nu_m2_per_s(CASE_CHURN_REF_C);
        assert_eq!(case_churn_factor(&rig, CASE_CHURN_REF_RAD_S, nu40), 1.0);
        rig.pump.case_churn = 30.0;
        rig.pump.case_churn_speed_exp = 0.6;
        assert_eq!(case_churn_factor(&rig, 0.0, nu40), 1.0);
        let at_ref = case_churn_factor(&rig, CASE_CHURN_REF_RAD_S, nu40);
        assert!((at_ref / 30.0 - 1.0).abs() < 0.011, "{at_ref}");
        let (a, b) = (case_churn_factor(&rig, 50.0, nu40), case_churn_factor(&rig, 25.0, nu40 / 2.0));
        assert!((a - b).abs() < 1e-12 * a);
        assert!(case_churn_factor(&rig, 1.0, nu40) < 1.1);
    }
}
