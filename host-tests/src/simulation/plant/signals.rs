//! What a run shows and takes at each segment end: the model's
//! [`Snapshot`], the controller's [`Sensors`], the callback's [`Control`],
//! the solver's [`Stats`] and the scenario's valve rule ([`RuleEval`]).

use super::*;

/// What the model shows at one instant: the operating point, every node
/// temperature, every loss and the energy integrals.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Time, s.
    pub t: f64,
    /// Hydraulic operating point.
    pub op: OpPoint,
    /// Node temperatures, °C, in [`crate::network::NODES`] order.
    pub temps: [f64; N_NODES],
    /// Losses, W.
    pub losses: Losses,
    /// LNG valve open.
    pub lng_open: bool,
    /// Integrated losses, J.
    pub e_loss_j: f64,
    /// Integrated heat to ambient, J.
    pub e_amb_j: f64,
    /// Integrated heat to the LNG, J.
    pub e_lng_j: f64,
    /// Energy stored in the nodes since the start, J.
    pub stored_j: f64,
    /// LNG used since the start, kg (eq. 24).
    pub lng_used_kg: f64,
}

impl Snapshot {
    /// Temperature of a node, °C.
    pub fn temp(&self, n: Node) -> f64 {
        self.temps[n as usize]
    }
}

/// The signals the actuator controller has (the firmware's inputs), plus the
/// true drain temperature it tries to estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensors {
    /// Time, s.
    pub t: f64,
    /// Motor current, A rms.
    pub current_a: f64,
    /// Port A pressure, bar gauge.
    pub p_a_bar: f64,
    /// Port B pressure, bar gauge.
    pub p_b_bar: f64,
    /// Motor speed, rpm.
    pub speed_rpm: f64,
    /// Piston position, mm.
    pub position_mm: f64,
    /// Ambient, °C.
    pub ambient_c: f64,
    /// True drain-port (pump case) oil temperature, °C.
    pub t_drain_c: f64,
    /// True circulating-oil temperature, °C.
    pub t_loop_oil_c: f64,
    /// LNG valve open.
    pub lng_open: bool,
}

impl Sensors {
    /// The firmware's wire sample of these signals (f32, the units of
    /// `eha_guard::Sample`), as a controller would send them every step.
    pub fn sample(&self) -> eha_guard::Sample {
        eha_guard::Sample {
            current_a: self.current_a as f32,
            p_a_bar: self.p_a_bar as f32,
            p_b_bar: self.p_b_bar as f32,
            speed_rpm: self.speed_rpm as f32,
            position_mm: self.position_mm as f32,
            ambient_c: self.ambient_c as f32,
        }
    }
}

impl From<&Snapshot> for Sensors {
    fn from(s: &Snapshot) -> Self {
        Sensors {
            t: s.t,
            current_a: s.op.current_a,
            p_a_bar: s.op.p_a * 1e-5,
            p_b_bar: s.op.p_b * 1e-5,
            speed_rpm: s.op.omega * 60.0 / (2.0 * std::f64::consts::PI),
            position_mm: s.op.x * 1e3,
            ambient_c: s.op.ambient_c,
            t_drain_c: s.temp(Node::Case),
            t_loop_oil_c: s.temp(Node::Loop),
            lng_open: s.lng_open,
        }
    }
}

/// What a step callback returns.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Control {
    /// New LNG valve command (None: unchanged).
    pub lng_valve: Option<bool>,
    /// Stop the run after this step.
    pub stop: bool,
}

/// Solver statistics of a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Right-hand-side evaluations (including those of Jacobian products).
    pub rhs_evals: u64,
    /// Accepted solver steps.
    pub steps: u64,
    /// Of `rhs_evals`, those spent on Jacobian columns.
    pub jacobian_evals: u64,
    /// Newton iterations (BDF only).
    pub newton_iterations: u64,
    /// Jacobian factorisations (BDF: diffsol's linear-solver setups; fast
    /// path: thermal Jacobians).
    pub factorizations: u64,
}

/// A scenario's valve rule, evaluated on snapshots.
#[derive(Debug, Clone)]
pub struct RuleEval {
    rule: ValveRule,
    lng: crate::cooling::Lng,
    replay: Option<crate::model::ReplayDrive>,
}

impl RuleEval {
    /// The valve rule of `model`'s drive.
    pub(crate) fn for_model(model: &Model) -> Self {
        RuleEval {
            rule: model.valve_rule(),
            lng: model.rig().lng,
            replay: match &model.drive {
                Drive::Replay(r) => Some(r.clone()),
                Drive::Mission(_) => None,
            },
        }
    }

    /// The valve command at a snapshot (None: leave it to the caller).
    pub fn command(&self, snap: &Snapshot) -> Option<bool> {
        let next = |t: f64| crate::cooling::valve_next(snap.lng_open, t, &self.lng);
        match self.rule {
            ValveRule::None => Some(false),
            ValveRule::LoopOil => Some(next(snap.temp(Node::Loop))),
            ValveRule::Drain => Some(next(snap.temp(Node::Case))),
            ValveRule::External => self.replay.as_ref().map(|r| r.lng_open(snap.t)),
        }
    }
}

/// Snapshot of state `y` at `t` (with `y0` the initial state for the stored energy).
pub fn snapshot(model: &Model, t: f64, y: &[f64], y0: &[f64]) -> Snapshot {
    snapshot_stored(model, t, y, model.stored_energy(y0, y))
}

/// [`snapshot`] with the stored energy given, J (a plant that keeps its
/// initial node energies: [`Model::stored_energy_from`]).
pub fn snapshot_stored(model: &Model, t: f64, y: &[f64], stored_j: f64) -> Snapshot {
    let (op, losses) = model.op_point_losses(t, y);
    let mut temps = [0.0; N_NODES];
    temps.copy_from_slice(&y[T0..T0 + N_NODES]);
    Snapshot {
        t,
        op,
        temps,
        losses,
        lng_open: model.lng_open.get(),
        e_loss_j: y[E_LOSS],
        e_amb_j: y[E_AMB],
        e_lng_j: y[E_LNG],
        stored_j,
        lng_used_kg: y[E_LNG] / model.rig().lng.heat_per_kg(),
    }
}
