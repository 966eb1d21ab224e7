//! The direct parameters: which fields of the reduced block each multiplier
//! scales, their priors and ranges, and the block a multiplier vector
//! gives. Separate because it is the parameter space, not the fit.

use eha_guard::model::{Model, ReducedParams};

/// Which fields of [`ReducedParams`] a direct parameter multiplies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// `eta_m` (eq. 8, pressure term).
    LossPressure,
    /// `no_load_torque_nm` and `viscous_w_s2_per_rad2` together (extended
    /// eq. 8, the speed terms).
    LossSpeed,
    /// `k_leak_m3_per_s_pa` (eqs. 5-7).
    Leak,
    /// `mech_to_case`, taken from (or given to) the housing's share.
    SplitCase,
    /// `g_case_w_per_k` (case oil <-> housing film).
    FilmCase,
    /// The case film's speed law: the table tilted by `(w / W_REF)^ln θ`
    /// (w held at `W_FLOOR` below it), so that ln θ is the exponent added
    /// to the rig file's law.
    FilmCaseSpeed,
    /// The port passage films: `g_port_w_per_k` and the four `g_port_re*` tables.
    FilmPort,
    /// Loop oil <-> main block: `g_loop_block_w_per_k`, the `g_loop_re*`
    /// films and the wall `duct_wall_w_per_k[0]` (the series path scales as one).
    FilmLoop,
    /// Ball-valve oil <-> its block, as [`Target::FilmLoop`] (`duct_wall_w_per_k[1]`).
    FilmBall,
    /// Outer surface `i` of `OUTER_NODES`: its constant, `|dT|^(1/4)` and
    /// radiation conductances together.
    Outer(usize),
    /// `pump_j_per_k`.
    CapPump,
    /// `main_block_j_per_k`.
    CapMain,
    /// `ball_block_j_per_k`.
    CapBall,
    /// `case_oil_m3` (the drain node's oil volume).
    CapCaseOil,
    /// `loop_oil_m3`.
    CapLoopOil,
}

/// One parameter of the direct set: a multiplier θ on reduced-model fields.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectParam {
    /// Name in reports.
    pub name: &'static str,
    /// The fields it multiplies.
    pub target: Target,
    /// Lower bound of θ.
    pub lo: f64,
    /// Upper bound of θ (for [`Target::SplitCase`] also capped so that the
    /// shares sum to at most 1).
    pub hi: f64,
    /// Prior standard deviation of ln θ (centre θ = 1, the reduction).
    pub prior_sigma_ln: f64,
    /// Why this range and prior.
    pub why: &'static str,
}

/// The direct set. Ranges: a machine built otherwise than its rig file
/// (films and outer transfer by correlations good to a factor 2-3, loss
/// coefficients to ±50 %, masses to ±30 %, the case oil volume to a factor
/// 2); priors half the log-range or less, so that the set stays
/// well-conditioned where a log says little.
pub const DIRECT_PARAMS: [DirectParam; 17] = [
    DirectParam { name: "loss_pressure", target: Target::LossPressure, lo: 0.33, hi: 3.0, prior_sigma_ln: 0.4, why: "eta_m of another pump: 0.15-1.3 about the rig's 0.44" },
    DirectParam { name: "loss_speed", target: Target::LossSpeed, lo: 0.1, hi: 4.0, prior_sigma_ln: 0.5, why: "bearing/seal drag and viscous friction: not in the paper (a pump built to it has next to none: the rig emulator's fit went to a 0.25 bound), a factor 2 either way" },
    DirectParam { name: "leak", target: Target::Leak, lo: 0.33, hi: 3.0, prior_sigma_ln: 0.4, why: "gap conductance ∝ gap^3: ±40 % in the gaps" },
    DirectParam { name: "split_case", target: Target::SplitCase, lo: 0.33, hi: 3.0, prior_sigma_ln: 0.4, why: "share of the sliding pairs' friction heating the case oil (the rest of the non-delivered share heats the housing)" },
    DirectParam { name: "film_case", target: Target::FilmCase, lo: 0.2, hi: 20.0, prior_sigma_ln: 0.5, why: "Taylor-Couette film of a case gap whose geometry the rig file guesses (the rig emulator's case film is another correlation on 5.3 times the wetted area: its fit went to a 5 and then a 10 bound)" },
    DirectParam { name: "film_case_speed", target: Target::FilmCaseSpeed, lo: 0.5, hi: 2.7, prior_sigma_ln: 0.5, why: "exponent added to the case film's speed law (ln θ, -0.7..+1): the rig file's Taylor-Couette film is flat below ~600 rpm (laminar gap), where a rotating-cylinder film (Nu ∝ Re^2/3, the rig emulator's) still falls with speed; measured on the emulator's big-pump, the idle after a soak was under-predicted by 1.9-2.8 K" },
    DirectParam { name: "film_port", target: Target::FilmPort, lo: 0.25, hi: 4.0, prior_sigma_ln: 0.5, why: "duct film correlations ±30 %, passage areas unknown" },
    DirectParam { name: "film_loop", target: Target::FilmLoop, lo: 0.25, hi: 4.0, prior_sigma_ln: 0.5, why: "block passages' film and wall" },
    DirectParam { name: "film_ball", target: Target::FilmBall, lo: 0.25, hi: 4.0, prior_sigma_ln: 0.5, why: "ball-valve passage film and wall" },
    DirectParam { name: "outer_pump", target: Target::Outer(0), lo: 0.25, hi: 4.0, prior_sigma_ln: 0.5, why: "still-air h 3-15 W/(m² K), exposed area and mounting" },
    DirectParam { name: "outer_main", target: Target::Outer(1), lo: 0.25, hi: 4.0, prior_sigma_ln: 0.5, why: "main block surface and its bench mounting" },
    DirectParam { name: "outer_ball", target: Target::Outer(2), lo: 0.25, hi: 4.0, prior_sigma_ln: 0.5, why: "ball-valve block surface" },
    DirectParam { name: "cap_pump", target: Target::CapPump, lo: 0.5, hi: 2.0, prior_sigma_ln: 0.3, why: "housing mass and the metal the node lumps" },
    DirectParam { name: "cap_main", target: Target::CapMain, lo: 0.5, hi: 2.0, prior_sigma_ln: 0.3, why: "main block mass" },
    DirectParam { name: "cap_ball", target: Target::CapBall, lo: 0.5, hi: 2.0, prior_sigma_ln: 0.3, why: "ball-valve block mass" },
    DirectParam { name: "cap_case_oil", target: Target::CapCaseOil, lo: 0.4, hi: 2.5, prior_sigma_ln: 0.4, why: "case oil volume: rarely on a drawing" },
    DirectParam { name: "cap_loop_oil", target: Target::CapLoopOil, lo: 0.5, hi: 2.0, prior_sigma_ln: 0.3, why: "loop oil volume (hoses, accumulator side)" },
];

/// Reference speed of `film_case_speed`'s tilt (the film there is left as
/// it is), rad/s: 100 rad/s ≈ 955 rpm, inside the 300–1500 rpm benches.
pub const W_REF_RAD_S: f64 = 100.0;

/// Speed below which `film_case_speed`'s tilt is held, rad/s (≈ 95 rpm).
pub const W_FLOOR_RAD_S: f64 = 10.0;

/// Index of a direct parameter by name.
pub fn index(name: &str) -> Option<usize> {
    DIRECT_PARAMS.iter().position(|d| d.name == name)
}

/// Range of parameter `k` ([`DIRECT_PARAMS`] index) at `p0`: its
/// `lo..hi`, narrowed so that every model word it scales stays inside the
/// firmware's bounds table (`eha_guard::model::bounds`; e.g. a duct film
/// table of 34 kW/K at -20 degC may grow ×2.9 before the table's 100 kW/K)
/// and, for the split, so that `mech_to_outlet + mech_to_case < 1`. The
/// scaled words are found by deriving the words at θ = 2: each moves as
/// θ or 1/θ.
pub fn range(k: usize, p0: &ReducedParams) -> (f64, f64) {
    let d = &DIRECT_PARAMS[k];
    let (mut lo, mut hi) = (d.lo, d.hi);
    if d.target == Target::SplitCase && p0.mech_to_case > 0.0 {
        hi = hi.min(0.999 * (1.0 - p0.mech_to_outlet) / p0.mech_to_case);
    }
    let mut th = vec![1.0; DIRECT_PARAMS.len()];
    th[k] = 2.0;
    let derive = eha_guard::model::consts::derive;
    let (Ok(c0), Ok(c2)) = (derive(p0), derive(&scaled(p0, &th))) else { return (lo, hi) };
    for (i, (w0, w2)) in c0.as_words().iter().zip(c2.as_words()).enumerate() {
        let Some((_, _, b, _)) = eha_guard::model::bounds::word_bound(i) else { continue };
        if *w0 == 0.0 || w0 == w2 {
            continue;
        }
        let e = (w2 / w0).ln() / 2f64.ln();
        let (blo, bhi) = (f64::from(b.lo), f64::from(b.hi));
        // the range of θ that keeps w0 θ^e in [blo, bhi], 1 % inside
        let (a, z) = if (e - 1.0).abs() < 1e-6 {
            (blo / w0, bhi / w0)
        } else if (e + 1.0).abs() < 1e-6 {
            (w0 / bhi, if blo > 0.0 { w0 / blo } else { f64::INFINITY })
        } else {
            continue;
        };
        lo = lo.max(1.01 * a);
        hi = hi.min(0.99 * z);
    }
    (lo, hi.max(lo))
}

fn scale(t: &mut [f64], s: f64) {
    t.iter_mut().for_each(|x| *x *= s);
}

/// `p0` with the multipliers `theta` ([`DIRECT_PARAMS`] order) on their
/// fields, nothing recomputed.
fn scaled(p0: &ReducedParams, theta: &[f64]) -> ReducedParams {
    let mut p = *p0;
    for (d, &s) in DIRECT_PARAMS.iter().zip(theta) {
        match d.target {
            Target::LossPressure => p.eta_m *= s,
            Target::LossSpeed => {
                p.no_load_torque_nm *= s;
                p.viscous_w_s2_per_rad2 *= s;
            }
            Target::Leak => p.k_leak_m3_per_s_pa *= s,
            Target::SplitCase => p.mech_to_case *= s,
            Target::FilmCase => scale(&mut p.g_case_w_per_k, s),
            Target::FilmCaseSpeed => {
                let n = (p.g_case_w_per_k.len() - 1) as f64;
                for (i, g) in p.g_case_w_per_k.iter_mut().enumerate() {
                    // the table's speed points: w_max (i / (N - 1))^2
                    let w = (p.speed_table_max_rad_s * (i as f64 / n).powi(2)).max(W_FLOOR_RAD_S);
                    *g *= (w / W_REF_RAD_S).powf(s.ln());
                }
            }
            Target::FilmPort => {
                scale(&mut p.g_port_w_per_k, s);
                for t in [&mut p.g_port_re2300_w_per_k, &mut p.g_port_re1e4_w_per_k, &mut p.g_port_re3e4_w_per_k, &mut p.g_port_re1e5_w_per_k] {
                    scale(t, s);
                }
            }
            Target::FilmLoop => {
                scale(&mut p.g_loop_block_w_per_k, s);
                for t in [&mut p.g_loop_re2300_w_per_k, &mut p.g_loop_re1e4_w_per_k, &mut p.g_loop_re3e4_w_per_k, &mut p.g_loop_re1e5_w_per_k] {
                    scale(t, s);
                }
                p.duct_wall_w_per_k[0] *= s;
            }
            Target::FilmBall => {
                scale(&mut p.g_ball_block_w_per_k, s);
                for t in [&mut p.g_ball_re2300_w_per_k, &mut p.g_ball_re1e4_w_per_k, &mut p.g_ball_re3e4_w_per_k, &mut p.g_ball_re1e5_w_per_k] {
                    scale(t, s);
                }
                p.duct_wall_w_per_k[1] *= s;
            }
            Target::Outer(i) => {
                p.outer_w_per_k[i] *= s;
                p.outer_quarter_w_per_k125[i] *= s;
                p.outer_rad_w_per_k4[i] *= s;
            }
            Target::CapPump => p.pump_j_per_k *= s,
            Target::CapMain => p.main_block_j_per_k *= s,
            Target::CapBall => p.ball_block_j_per_k *= s,
            Target::CapCaseOil => p.case_oil_m3 *= s,
            Target::CapLoopOil => p.loop_oil_m3 *= s,
        }
    }
    p
}

/// `p0` with the multipliers `theta` ([`DIRECT_PARAMS`] order) applied,
/// rediscretised (nominal Jacobian, `Phi`, rest-cooling bound recomputed
/// for the new values); `None` if the firmware model rejects the result
/// (`Model::new` in `f64` and, for the flashed block, in `f32`).
pub fn apply(p0: &ReducedParams, theta: &[f64]) -> Option<ReducedParams> {
    let p = scaled(p0, theta);
    if p.mech_to_outlet + p.mech_to_case > 1.0 {
        return None;
    }
    let p = crate::reduce::rediscretise(&p)?;
    Model::<f64>::new(&p).ok()?;
    let c = eha_guard::model::consts::derive(&p).ok()?.to_f32();
    Model::<f32>::from_consts(&c).ok()?;
    Some(p)
}
