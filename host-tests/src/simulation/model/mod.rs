//! The full lumped thermal-hydraulic model: state vector, operating point,
//! losses (eqs. 1–11) assigned to the thermal nodes, the network (eqs.
//! 12–19), the LNG exchanger (eqs. 20–22) and the energy bookkeeping.
//!
//! This file holds the state layout, the [`Model`] and its drive, the oil
//! properties on the grids and the full right-hand side; the parts of the
//! right-hand side live by topic in `loss_terms.rs` (the losses and where the
//! pump's friction heat goes), `thermal.rs` (the node heat balances),
//! `hydraulic.rs` (the operating point and the hydraulic derivatives) and
//! `replay_drive.rs` (interpolation in measured inputs).

mod hydraulic;
#[cfg(test)]
mod hold_tests;
mod loss_terms;
mod replay_drive;
mod thermal;

pub use hydraulic::HydraulicOil;
pub use loss_terms::{FrictionHeat, Losses};
pub use replay_drive::ReplayDrive;

use crate::hydraulics::{self, ix};
use crate::network::{self, Node, N_NODES, NODES};
use crate::simulation::grids::{LaminarGrid, NuGrid, OuterGrid, NU_GRID_FACTOR};
use crate::rig::Rig;
use crate::scenario::{Mission, ValveRule};
use std::cell::Cell;

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
    /// Rig parameters ([`Model::rig`]). Private: the node contents, the
    /// throttle path's constants, the enthalpy cubic and the memos (iron
    /// loss, needle, μ, ball-valve oil) are taken from it in
    /// [`Model::new`], so a changed rig would leave them stale; build a new
    /// model for another rig.
    rig: Rig,
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
    /// The motor's iron loss (eq. 2, a `powf`) at the last shaft speed it
    /// was taken for: (ω's bits, W) ([`Model::iron_w`]).
    iron_memo: BitsMemo<f64>,
    /// The throttle path's constants (π·d⁴, 2·a²), taken once.
    path_geom: hydraulics::PathGeom,
    /// The oil's stored heat per volume as a cubic, taken once (the
    /// snapshots' stored energy: [`Model::stored_energy_from`]).
    enthalpy: crate::fluid::EnthalpyCubic,
    /// The needle valve at the last setting it was taken for: (the
    /// setting's bits in bar, k, 1/k²) ([`Model::needle`]).
    needle_memo: BitsMemo<(Option<f64>, f64)>,
    /// The dynamic viscosity at the last temperature it was taken for:
    /// (the temperature's bits, Pa·s) ([`Model::mu`]; NaN's bits: none).
    mu_memo: BitsMemo<f64>,
    /// The ball-valve oil's (density kg/m³, kinematic viscosity m²/s) at
    /// the last temperature they were taken for ([`Model::ball_oil`]).
    ball_memo: BitsMemo<(f64, f64)>,
}

/// A one-entry memo keyed on an `f64` argument's bits: the value computed
/// for the same bits again (so the same to the last bit), computed anew for
/// any other argument. The model's iron loss, needle, μ and ball-valve oil
/// memos.
#[derive(Debug)]
struct BitsMemo<T: Copy>(Cell<(u64, T)>);

impl<T: Copy> BitsMemo<T> {
    /// Holding `value`, the value at argument `x`.
    fn new(x: f64, value: T) -> Self {
        Self(Cell::new((x.to_bits(), value)))
    }

    /// The value at `x`: the kept one when `x`'s bits are the key,
    /// otherwise `f()`, kept.
    #[inline]
    fn get_or(&self, x: f64, f: impl FnOnce() -> T) -> T {
        let (bits, v) = self.0.get();
        if bits == x.to_bits() {
            return v;
        }
        let v = f();
        self.0.set((x.to_bits(), v));
        v
    }
}

/// A memo's value that stands for "nothing kept": NaN in every field (what
/// a computation at the NaN key gives too).
trait Unset: Copy {
    /// The all-NaN value.
    const NAN: Self;
}

impl Unset for f64 {
    const NAN: Self = f64::NAN;
}

impl Unset for (f64, f64) {
    const NAN: Self = (f64::NAN, f64::NAN);
}

impl<T: Unset> BitsMemo<T> {
    /// Holding nothing: [`Unset::NAN`] at NaN's bits.
    fn empty() -> Self {
        Self::new(f64::NAN, T::NAN)
    }
}

impl Model {
    /// Build a model.
    pub fn new(rig: Rig, drive: Drive) -> Self {
        let contents = network::contents(&rig);
        let iron_memo = BitsMemo::new(0.0, rig.motor.iron.power_w(0.0));
        let path_geom = hydraulics::PathGeom::new(&rig);
        let enthalpy = rig.oil.enthalpy_cubic();
        let k0 = hydraulics::needle_k(&rig, 0.0);
        let needle_memo = BitsMemo::new(0.0, (k0, hydraulics::needle_inv_k2(k0)));
        Self { rig, drive, lng_open: Cell::new(false), contents, outer_grid: None, nu_grid: None, lam_grid: None, leak_geom: None, iron_memo, path_geom, enthalpy, needle_memo, mu_memo: BitsMemo::empty(), ball_memo: BitsMemo::empty() }
    }

    /// The rig the model was built for (read-only: see [`Model::new`]).
    #[inline]
    pub fn rig(&self) -> &Rig {
        &self.rig
    }

    /// The needle valve at setting `bar` ([`hydraulics::needle_k`]: its k,
    /// and 1/k² of [`hydraulics::needle_inv_k2`]), the values computed for
    /// the same bits of the setting when they repeat (a square root and
    /// three divisions in every hydraulic evaluation otherwise).
    #[inline]
    fn needle(&self, bar: f64) -> (Option<f64>, f64) {
        self.needle_memo.get_or(bar, || {
            let k = hydraulics::needle_k(&self.rig, bar);
            (k, hydraulics::needle_inv_k2(k))
        })
    }

    /// The motor's iron loss at shaft speed `omega` (eq. 2,
    /// [`crate::losses::IronLoss::power_w`]), W: the value computed for the
    /// same bits of ω when they repeat (a machine at a steady speed), so the
    /// same to the last bit. (A `powf` in every heat balance and snapshot:
    /// ~20 k instructions of a fast Case 1 run.)
    pub fn iron_w(&self, omega: f64) -> f64 {
        self.iron_memo.get_or(omega, || self.rig.motor.iron.power_w(omega))
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
        // ν moves from the exact line to the grid (or back): μ and the
        // ball-valve oil anew.
        self.mu_memo = BitsMemo::empty();
        self.ball_memo = BitsMemo::empty();
        self.lam_grid = step.map(|_| LaminarGrid::new());
        self.leak_geom = step.map(|_| self.rig.pump.gaps.conductance(1.0));
    }

    /// Exact evaluations behind the grids so far: (outer surfaces, viscosities).
    /// The outer surfaces' count is of the grid's points, some of them read
    /// from the per-thread table of earlier runs; the viscosities' counts
    /// only the points this grid computed (a grid built after another on
    /// the same thread starts with that one's points).
    pub fn grid_evals(&self) -> (u64, u64) {
        (self.outer_grid.as_ref().map_or(0, |g| g.evals.get()), self.nu_grid.as_ref().map_or(0, |g| g.evals.get()))
    }

    /// Oil-to-metal conductance of a duct ([`network::duct_conductance`]),
    /// W/K, the laminar Nusselt number on its grid when the grids are set.
    #[inline]
    fn duct_conductance(&self, q_m3_per_s: f64, d: f64, len: f64, area_scale: f64, t_oil: f64, nu: f64) -> f64 {
        match &self.lam_grid {
            Some(g) => network::duct_conductance_with(&self.rig, q_m3_per_s, d, len, area_scale, t_oil, nu, |x| g.nu(x)),
            None => network::duct_conductance(&self.rig, q_m3_per_s, d, len, area_scale, t_oil, nu),
        }
    }

    /// Pressure drops of the throttle path ([`hydraulics::path_dp`]) with
    /// the ball-valve oil at `t_oil`: its properties from
    /// [`Model::ball_oil`], Pa.
    fn path_dp(&self, q: f64, t_oil: f64, needle: Option<f64>) -> (f64, f64) {
        let (rho, nu) = self.ball_oil(t_oil);
        hydraulics::path_dp_props(&self.rig, q, rho, nu, needle)
    }

    /// The ball-valve oil's density at 0 bar (kg/m³) and kinematic
    /// viscosity ([`Model::nu`], m²/s) at `t_oil`: kept for the last
    /// temperature's bits (a heat balance asks for them at the same
    /// temperature up to five times: the operating point, the losses, the
    /// ball duct's film, the throttle path's drop), so the same values to
    /// the last bit.
    #[inline]
    pub(crate) fn ball_oil(&self, t_oil: f64) -> (f64, f64) {
        self.ball_memo.get_or(t_oil, || (self.rig.oil.rho(t_oil, 0.0), self.nu(t_oil)))
    }

    /// Kinematic viscosity of the oil at `t_oil` (its Walther line), m²/s.
    /// (Inlined: ~1 700 calls a fast Case 1 run, each a kept cell of the
    /// grid of ~20 instructions, which the call itself doubled.)
    #[inline]
    pub fn nu(&self, t_oil: f64) -> f64 {
        match &self.nu_grid {
            Some(g) => g.nu(&self.rig.oil, t_oil),
            None => self.rig.oil.nu_m2_per_s(t_oil),
        }
    }

    /// Dynamic viscosity of the oil at `t_oil` and 0 bar, Pa·s (ν·ρ, as
    /// [`crate::fluid::Oil::mu_pa_s`]).
    ///
    /// The value computed for the same bits of `t_oil` when they repeat (a
    /// heat balance asks for the case oil's twice: the pump friction and
    /// the leakage conductance), so the same to the last bit.
    pub fn mu(&self, t_oil: f64) -> f64 {
        self.mu_memo.get_or(t_oil, || self.nu(t_oil) * self.rig.oil.rho(t_oil, 0.0))
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

    /// The operating point at (t, y) ([`Model::op_point`]) and the losses
    /// there at the node temperatures of `y` ([`Model::losses`]), W, with
    /// the pump friction taken once (the losses took it again: the same
    /// call on the same arguments, so the same values to the last bit).
    pub fn op_point_losses(&self, t: f64, y: &[f64]) -> (hydraulics::OpPoint, Losses) {
        let (op, friction) = self.op_point_parts(t, y);
        let l = self.loss_parts(t, &op, &y[T0..T0 + N_NODES], friction).0;
        (op, l)
    }

    /// Full right-hand side dy/dt = f(t, y).
    pub fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        let (op, friction) = self.op_point_parts(t, y);
        let temps = &y[T0..T0 + N_NODES];
        let (l, fh, f, line_dp) = self.loss_parts(t, &op, temps, friction);
        self.hydraulic_rhs_at(t, y, &op, dy);
        let (q_in, q_amb, q_lng) = self.thermal_with(&op, &l, &fh, &f, line_dp, temps, &mut dy[T0..T0 + N_NODES]);
        dy[E_LOSS] = q_in;
        dy[E_AMB] = q_amb;
        dy[E_LNG] = q_lng;
    }

    /// [`Model::rhs`] without the hydraulic derivatives (`dy[..ix::N]` is
    /// left as it is): the node temperatures' derivatives and the energy
    /// rates, the same to the last bit.
    pub fn thermal_rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        let (op, friction) = self.op_point_parts(t, y);
        let temps = &y[T0..T0 + N_NODES];
        let (l, fh, f, line_dp) = self.loss_parts(t, &op, temps, friction);
        let (q_in, q_amb, q_lng) = self.thermal_with(&op, &l, &fh, &f, line_dp, temps, &mut dy[T0..T0 + N_NODES]);
        dy[E_LOSS] = q_in;
        dy[E_AMB] = q_amb;
        dy[E_LNG] = q_lng;
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
        self.stored_energy_from(&self.node_energies(y0), y)
    }

    /// Each node's stored energy at the state `y`, J (relative to the
    /// network's 20 °C reference, `network::stored_j`).
    pub fn node_energies(&self, y: &[f64]) -> [f64; N_NODES] {
        std::array::from_fn(|i| network::stored_j_with(&self.enthalpy, NODES[i], self.contents[i], y[T0 + i]))
    }

    /// [`Model::stored_energy`] relative to the node energies `e0` of the
    /// initial state ([`Model::node_energies`], taken once a run): the
    /// same differences summed in the same order.
    pub fn stored_energy_from(&self, e0: &[f64; N_NODES], y: &[f64]) -> f64 {
        // One bounds check for the thirteen reads.
        let z = &y[T0..T0 + N_NODES];
        NODES
            .iter()
            .zip(&self.contents)
            .zip(z)
            .zip(e0)
            .map(|(((n, c), t), e)| network::stored_j_with(&self.enthalpy, *n, *c, *t) - e)
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
