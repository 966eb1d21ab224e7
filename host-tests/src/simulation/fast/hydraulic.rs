//! The hydraulic states' own integration: Rosenbrock steps at the hydraulics'
//! pace, independent of the thermal steps, kept as a short track of
//! (t, y, f) points that the thermal scheme reads by cubic Hermite
//! interpolation. A thermal step that is rejected and retried shorter reads
//! the same track: the hydraulics are never integrated twice.

use super::rosenbrock::{RosError, Rosenbrock};
use crate::hydraulics::ix;
use crate::model::{HydraulicOil, Model, N_STATE, T0};
use crate::network::N_NODES;

/// Hydraulic states.
pub const NH: usize = ix::N;

/// One (t, y, f(t, y)) point of the hydraulic integration.
pub type HydPoint = (f64, [f64; NH], [f64; NH]);

/// The integration's recent points and its integrator.
#[derive(Debug, Clone)]
pub struct HydTrack {
    /// The integrator (its step size carries over between calls).
    pub ros: Rosenbrock<NH>,
    pts: Vec<HydPoint>,
    /// The branch values of the last scan's end, (t, values).
    last_branch: Option<(f64, [f64; 3])>,
    /// The node temperatures the hydraulics see: linear in time through
    /// (t₀, z₀) and (t₁, z₁), the thermal step's start and predicted end.
    path: TempPath,
    /// Whether the hydraulic derivatives depend on the temperatures at all
    /// (leakage and throttle viscosity with `viscosity-temperature`): then
    /// the hydraulic steps end with the thermal step and go on from there
    /// with the new temperatures. (Measured on Case 1: a 3 s hydraulic step
    /// under 20 ms thermal steps saw temperatures seconds old, 0.5 K on the
    /// ball-valve oil; cut inside a hydraulic step instead, the
    /// interpolant's error kicked the stiff pressures at every thermal
    /// step; reaching one thermal step ahead on extrapolated temperatures,
    /// 1e-2 K and 4 k steps.)
    coupled: bool,
    /// The time argument of the last point's f when the coupled step that
    /// made it left f untaken (see [`Rosenbrock::step`]'s `lazy_end`): the
    /// thermal step's end takes f there anew with the new temperatures
    /// (`advance`), so it is taken here only where it is read
    /// (`fill`), with the path it was integrated on.
    pending: Option<f64>,
}

/// Node temperatures linear in time through two points, and the oil
/// properties the hydraulics see through them, linear in time between
/// their values at the two points. (Interpolating the properties rather
/// than evaluating them at the interpolated temperatures: the difference
/// is their curvature over a thermal step's few millikelvin, ~1e-9
/// relative; evaluated, they were half of a hydraulic evaluation's cost,
/// a `log10` and two `pow` each.)
#[derive(Debug, Clone, Copy)]
pub struct TempPath {
    t0: f64,
    z0: [f64; N_NODES],
    t1: f64,
    z1: [f64; N_NODES],
    oil0: HydraulicOil,
    oil1: HydraulicOil,
    /// t₁ − t₀ and oil1 − oil0, taken once a path (the same bits as in
    /// every `weight` and `oil_at`, which took them at each evaluation).
    dt: f64,
    doil: HydraulicOil,
}

impl TempPath {
    /// Constant temperatures `z`, with the oil's properties there
    /// (`Model::hydraulic_oil(z)`).
    pub fn constant(z: [f64; N_NODES], oil: HydraulicOil) -> Self {
        Self::line(0.0, z, 1.0, z, oil, oil)
    }

    /// The line through (t0, z0) and (t1, z1), with the oil's properties
    /// `oil0`, `oil1` at its two points.
    pub fn line(t0: f64, z0: [f64; N_NODES], t1: f64, z1: [f64; N_NODES], oil0: HydraulicOil, oil1: HydraulicOil) -> Self {
        Self { t0, z0, t1, z1, oil0, oil1, dt: t1 - t0, doil: oil0.delta_to(&oil1) }
    }

    /// Weight of the second point at `t` (held beyond the points: a
    /// hydraulic step past the thermal step must not extrapolate a transient).
    fn weight(&self, t: f64) -> f64 {
        if self.t1 > self.t0 {
            ((t - self.t0) / self.dt).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// Temperatures at `t`.
    pub fn at(&self, t: f64) -> [f64; N_NODES] {
        let w = self.weight(t);
        std::array::from_fn(|i| self.z0[i] + w * (self.z1[i] - self.z0[i]))
    }

    /// The hydraulics' oil properties at `t`.
    pub fn oil_at(&self, t: f64) -> HydraulicOil {
        self.oil0.along(&self.doil, self.weight(t))
    }
}

impl HydTrack {
    /// A track with `ros` as integrator, starting at (t, y).
    pub fn new(ros: Rosenbrock<NH>, t: f64, y: [f64; NH]) -> Self {
        let path = TempPath::constant([0.0; N_NODES], HydraulicOil::default());
        Self { ros, pts: vec![(t, y, [0.0; NH])], last_branch: None, path, coupled: false, pending: None }
    }

    /// The last point's f, when a step left it untaken (`pending`): with
    /// the path the point was integrated on (every change of the path
    /// fills it first), the same bits as the step's own evaluation.
    fn fill(&mut self, model: &Model) {
        if let Some(te) = self.pending.take() {
            // (A pending point is the last: `cover` pushed it.)
            if let Some(p) = self.pts.last_mut() {
                model.hydraulic_rhs_oil(te, &p.1, &self.path.oil_at(p.0), &mut p.2);
                self.ros.stats.evals += 1;
            }
        }
    }

    /// [`Self::fill`] when reading the track at `t` needs the last point's
    /// f ([`Self::at`] reads it past the point before the last, at any
    /// time but the last point's own).
    fn fill_for(&mut self, model: &Model, t: f64) {
        if self.pending.is_some() {
            let n = self.pts.len();
            if n >= 2 && t > self.pts[n - 2].0 && t != self.pts[n - 1].0 {
                self.fill(model);
            }
        }
    }

    /// Restart at (t, y) with step `h0`: the first point's f is computed
    /// anew (the forcing may step here).
    pub fn restart(&mut self, model: &Model, z: &[f64; N_NODES], t: f64, y: [f64; NH], h0: f64) {
        let mut f = [0.0; NH];
        rhs(model, z, t, &y, &mut f);
        self.ros.stats.evals += 1;
        self.check_coupling(model, z, t, &y, &f);
        self.path = TempPath::constant(*z, model.hydraulic_oil(z));
        self.pts.clear();
        self.pts.push((t, y, f));
        self.pending = None;
        self.last_branch = None;
        self.ros.h = h0;
        self.ros.forget_jacobian();
    }

    /// Time of the last integrated point, s.
    pub fn head(&self) -> f64 {
        self.pts.last().map_or(f64::NEG_INFINITY, |p| p.0)
    }

    /// Whether the hydraulic derivatives at (t, y) change with the
    /// temperatures (+1 K on every node); once seen, for good. (At rest
    /// they need not: no leakage or throttle flow to depend on them.)
    fn check_coupling(&mut self, model: &Model, z: &[f64; N_NODES], t: f64, y: &[f64; NH], f: &[f64; NH]) {
        if !self.coupled {
            let mut fw = [0.0; NH];
            rhs(model, &z.map(|x| x + 1.0), t, y, &mut fw);
            self.ros.stats.evals += 1;
            self.coupled = *f != fw;
        }
    }

    /// The temperatures the hydraulics see from now on: the line through
    /// (t0, z0) and (t1, z1) (the properties at z0 kept from the last path
    /// when it ended there).
    pub fn set_line(&mut self, model: &Model, t0: f64, z0: [f64; N_NODES], t1: f64, z1: [f64; N_NODES]) {
        self.fill(model);
        let oil0 = if self.path.z1 == z0 { self.path.oil1 } else { model.hydraulic_oil(&z0) };
        self.path = TempPath::line(t0, z0, t1, z1, oil0, model.hydraulic_oil(&z1));
    }

    /// Integrates until the track covers `t` (at most up to `t_max`, a
    /// schedule breakpoint), with the temperatures of the path. The
    /// schedules are read as left limits at `t_max` (a step there belongs
    /// to the next segment).
    pub fn cover(&mut self, model: &Model, t: f64, t_max: f64) -> Result<(), RosError> {
        self.fill(model);
        let Some(&(mut tt, mut y, mut f)) = self.pts.last() else { return Ok(()) };
        let t_left = left_of(t_max);
        let t_stop = if self.coupled { t.min(t_max) } else { t_max };
        // (Borrowed: a copy of the path was a `memcpy` in every call.)
        let path = &self.path;
        let mut fun = |t: f64, y: &[f64; NH], d: &mut [f64; NH]| model.hydraulic_rhs_oil(t.min(t_left), y, &path.oil_at(t), d);
        while tt < t - 1e-12 * t.abs().max(1.0) && tt < t_stop {
            // Coupled, a step to the thermal step's end leaves f there
            // untaken (`pending`).
            tt = self.ros.step(&mut fun, tt, &mut y, &mut f, t_stop, self.coupled)?;
            self.pts.push((tt, y, f));
            if self.coupled && tt == t_stop {
                self.pending = Some(tt.min(t_left));
            }
        }
        Ok(())
    }

    /// A rejected thermal step: when the hydraulics see the temperatures,
    /// their integration past `t` (the step's start) goes.
    pub fn reject(&mut self, t: f64) {
        if self.coupled {
            let (n, i) = (self.pts.len(), self.pts.partition_point(|p| p.0 <= t));
            self.pts.truncate(i.max(1));
            if self.pts.len() < n {
                self.pending = None;
            }
            self.last_branch = None;
        }
    }

    /// The hydraulic states at `t` (inside the track), cubic Hermite.
    pub fn at(&mut self, model: &Model, t: f64) -> [f64; NH] {
        self.fill_for(model, t);
        self.at_filled(t)
    }

    /// [`Self::at`] where the f it reads are all taken.
    fn at_filled(&self, t: f64) -> [f64; NH] {
        let n = self.pts.len();
        if n < 2 {
            return self.pts.first().map_or([0.0; NH], |p| p.1);
        }
        let i = self.pts.partition_point(|p| p.0 <= t).clamp(1, n - 1);
        let (a, b) = (&self.pts[i - 1], &self.pts[i]);
        // At a point of the track its state (what the interpolant gives
        // there to the bit: the basis is (1, 0, 0, 0) or (0, 0, 1, 0)); the
        // thermal steps read the track at their ends, which are its points.
        if t == a.0 {
            return a.1;
        }
        if t == b.0 {
            return b.1;
        }
        let h = b.0 - a.0;
        let (a0, b0, a1, b1) = hermite(((t - a.0) / h).clamp(0.0, 1.0));
        std::array::from_fn(|k| a0 * a.1[k] + b0 * h * a.2[k] + a1 * b.1[k] + b1 * h * b.2[k])
    }

    /// After a thermal step to `t`: forgets the points before the one at or
    /// before `t` and, when the hydraulics see the temperatures, the
    /// points after `t` too (integrated with the step's predicted
    /// temperatures): the track goes on from its interpolant at `t`, with
    /// f taken anew at the temperatures `z` of the step's end.
    pub fn advance(&mut self, model: &Model, t: f64, z: &[f64; N_NODES], t_max: f64) {
        // A point left without f stays pending only at t, where it is
        // replaced below.
        self.fill_for(model, t);
        // The oil properties at z once, for f and for the path (the same
        // bits as `rhs`, which computes them from z).
        let oil = model.hydraulic_oil(z);
        let t_f = t.min(left_of(t_max));
        // f at the track's point at t with the step's end temperatures:
        // for the coupling check and, once coupled, the track's new end
        // (taken once when the check sees the coupling at this step).
        let mut at_t: Option<([f64; NH], [f64; NH])> = None;
        if !self.coupled {
            // Whether the temperatures matter now, at every thermal step:
            // while they do not, the track runs ahead of the thermal steps
            // with the last path's oil in its f, and once they do, the next
            // path's first step would start from an f that is not its own
            // (a Jacobian and ∂f/∂t of differences against it: with the
            // check every 16th step, Case 1's pump start took 52 rejected
            // hydraulic steps, some blowing up to 1e12 Pa, before it).
            let (y, mut f) = (self.at_filled(t), [0.0; NH]);
            model.hydraulic_rhs_oil(t_f, &y, &oil, &mut f);
            self.ros.stats.evals += 1;
            self.check_coupling(model, z, t_f, &y, &f);
            at_t = Some((y, f));
        }
        if self.coupled {
            // The track ends at t (or past it before a callback's rewind):
            // f there anew with the step's end temperatures.
            let (y, f) = at_t.unwrap_or_else(|| {
                let (y, mut f) = (self.at_filled(t), [0.0; NH]);
                model.hydraulic_rhs_oil(t_f, &y, &oil, &mut f);
                self.ros.stats.evals += 1;
                (y, f)
            });
            let i = self.pts.partition_point(|p| p.0 < t);
            self.pts.truncate(i);
            self.pts.push((t, y, f));
            self.pending = None;
            // The branch values the last scan ended with at t stay (the
            // same state; the oil of the step's end temperatures instead
            // of the predicted ones moves them by a few millionths, and
            // only their signs are read): the next scan starts from them.
        }
        self.path = TempPath::constant(*z, oil);
        let i = self.pts.partition_point(|p| p.0 <= t);
        if i > 1 {
            self.pts.drain(..i - 1);
        }
    }
}

/// Sign changes at which the model's heat balances switch branch: the
/// pressure difference across the pump (which port's oil leaks to the
/// case, where the ring's leakage flow ends), the circulation through the
/// ring (the upwind direction) and the shaft speed (the friction torque's
/// sign in the motor current). Values below the thresholds (1 Pa,
/// 1e-10 m³/s, 1e-4 rad/s) are a machine at rest, not a reversal.
fn branch_values(model: &Model, oil: &HydraulicOil, t: f64, yh: &[f64; NH]) -> [f64; 3] {
    let op = model.op_hydraulic_oil(t, yh, oil);
    [op.p_a - op.p_b, op.circulation(model.rig()), op.omega]
}

const BRANCH_THRESHOLDS: [f64; 3] = [1.0, 1e-10, 1e-4];

fn crossed(a: &[f64; 3], b: &[f64; 3]) -> bool {
    a.iter().zip(b).zip(BRANCH_THRESHOLDS).any(|((x, y), thr)| x.abs() > thr && y.abs() > thr && (*x > 0.0) != (*y > 0.0))
}

impl HydTrack {
    /// The first branch switch (see `branch_values`) in (`t0`, `t1`] of
    /// the covered track, as a bracket (t_lo, t_hi) narrower than 1e-7 s
    /// (relative to t), or None.
    pub fn first_switch(&mut self, model: &Model, t0: f64, t1: f64) -> Option<(f64, f64)> {
        let mut ta = t0;
        let mut va = match self.last_branch {
            Some((t, v)) if t == t0 => v,
            _ => self.branch_at(model, t0),
        };
        // The track's points inside (t0, t1) (in order), then t1.
        let mut k = self.pts.partition_point(|p| p.0 <= t0);
        loop {
            let tb = match self.pts.get(k) {
                Some(p) if p.0 < t1 => p.0,
                _ => t1,
            };
            k += 1;
            let vb = self.branch_at(model, tb);
            if crossed(&va, &vb) {
                let (mut lo, mut hi) = (ta, tb);
                let width = 1e-7 * t1.abs().max(1.0);
                while hi - lo > width {
                    let mid = 0.5 * (lo + hi);
                    if crossed(&va, &self.branch_at(model, mid)) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                self.last_branch = None;
                return Some((lo, hi));
            }
            if tb == t1 {
                self.last_branch = Some((t1, vb));
                return None;
            }
            (ta, va) = (tb, vb);
        }
    }

    /// The branch values on the track at `t`.
    fn branch_at(&mut self, model: &Model, t: f64) -> [f64; 3] {
        let yh = self.at(model, t);
        branch_values(model, &self.path.oil_at(t), t, &yh)
    }
}

/// A time just before `t` (1e-9 relative, at least 1 ns): where a segment's
/// schedules are read at its end, so that a step at the breakpoint is not
/// seen inside the segment.
pub fn left_of(t: f64) -> f64 {
    t - 1e-9 * t.abs().max(1.0)
}

/// The hydraulic derivatives at (t, y) with the node temperatures `z`.
fn rhs(model: &Model, z: &[f64; N_NODES], t: f64, yh: &[f64; NH], d: &mut [f64; NH]) {
    let mut y = [0.0; N_STATE];
    y[..NH].copy_from_slice(yh);
    y[T0..T0 + N_NODES].copy_from_slice(z);
    let mut dy = [0.0; N_STATE];
    model.hydraulic_rhs(t, &y, &mut dy);
    d.copy_from_slice(&dy[..NH]);
}

/// Cubic Hermite basis at θ ∈ [0, 1]: (value 0, slope 0, value 1, slope 1).
pub fn hermite(th: f64) -> (f64, f64, f64, f64) {
    let (t2, t3) = (th * th, th * th * th);
    (2.0 * t3 - 3.0 * t2 + 1.0, t3 - 2.0 * t2 + th, -2.0 * t3 + 3.0 * t2, t3 - t2)
}
