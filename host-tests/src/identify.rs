//! Identification of the firmware's reduced-order thermal model
//! ([`eha_guard::params::ReducedParams`]) from the reference simulation.
//!
//! Procedure (docs/identification.md):
//!
//! 1. **Loss coefficients by reduction.** Where the reduced model uses the same
//!    physics as the reference, its coefficients are taken from `Rig` directly:
//!    phases and R (constant, `alpha = 0` as in the baseline), the iron-loss
//!    terms of eq. (2) with `f = p·ω/2π`, the gap conductance at 40 °C
//!    (`K_leak`, viscosity held: `k_mu = 0`), `η_m`, the displacement `D` and
//!    the ram area `A`. See [`reduce_losses`].
//! 2. **Training set.** Named reference runs ([`training_set`]): Case 1 at 10,
//!    30 and 50 bar and Case 2 (600 s each), plus the seeded random missions of
//!    [`TRAIN_SEEDS`] (none at present: adding idle missions degraded the paper
//!    cases, see docs/identification.md), each recorded at the firmware's 10 ms
//!    tick ([`record`]). The acceptance suite's random missions use the disjoint
//!    seeds [`TEST_SEEDS`].
//! 3. **Model.** The reduced model is [`eha_guard::model::Model<f64>`] itself,
//!    driven by the reference's sensor signals (current, port pressures, speed,
//!    position, ambient) exactly as the guard feeds it ([`simulate_reduced`]).
//! 4. **Fit.** Levenberg–Marquardt (crate `levenberg-marquardt`) on the
//!    log-parameters of the thermal network (6 capacities, 6 node-to-node
//!    conductances, 3 ambient conductances, `g_od1`) and the logits of two
//!    loss splits (mechanical: loop oil vs drain; throttling: loop oil vs valve
//!    block), each kept in a smooth box around [`initial_guess`] ([`bounded`]).
//!    Residual: drain-temperature error every 1 s (weight 1) plus the other
//!    mapped node temperatures (weight [`W_OTHER`]) for identifiability.
//!    Forward-difference Jacobian, columns in parallel (rayon). The result
//!    must also build as the f32 and fixed-point models.
//! 5. **Conservative bias.** If the fitted model under-predicts the drain on
//!    the training set by more than [`UNDER_BUDGET_K`], the ambient
//!    conductances are scaled down by bisection, applied only if that meets the
//!    budget ([`Identified::ambient_scale`]).
//!
//! [`render_params_rs`] prints the result as the `DEFAULT` constant of
//! `src/params.rs`; `examples/identify.rs` regenerates the file.

use crate::network::Node;
use crate::plant::{Control, Plant, Sensors, SimError};
use crate::rig::Rig;
use crate::scenario::{Circuit, Mission, PositionRef, Scenario, Schedule, ValveRule};
use eha_guard::model::{Model, ModelInputN, HA_PER_A, HBAR_PER_BAR, HRADS_PER_RPM};
use eha_guard::params::{ReducedParams, N_LOSSES, N_NODES, S_PER_TICK, TICKS_PER_STEP};
use crate::lsq::FdProblem;
use levenberg_marquardt::LevenbergMarquardt;
use nalgebra::DVector;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Starting network of the fit: the hand-reasoned pre-identification parameters
/// (paper Tables 2, 3, 6; formerly `eha_guard::params::DEFAULT`), kept here so that
/// the identification does not depend on its own previous output.
pub const HAND_START: ReducedParams = ReducedParams {
    capacity_j_per_k: [4000.0, 32500.0, 9200.0, 4960.0, 87400.0, 500.0],
    conductance_w_per_k: [
        [0.0, 15.0, 0.0, 0.0, 0.0, 0.0],
        [15.0, 0.0, 2.0, 0.0, 0.0, 0.0],
        [0.0, 2.0, 0.0, 10.0, 0.0, 30.0],
        [0.0, 0.0, 10.0, 0.0, 40.0, 5.0],
        [0.0, 0.0, 0.0, 40.0, 0.0, 0.0],
        [0.0, 0.0, 30.0, 5.0, 0.0, 0.0],
    ],
    ambient_w_per_k: [0.0, 5.0, 1.0, 1.0, 4.4, 0.0],
    loss_split: [
        [1.0, 0.3, 0.0, 0.0, 0.0],
        [0.0, 0.7, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 0.5, 0.0],
        [0.0, 0.0, 0.0, 0.0, 0.8],
        [0.0, 0.0, 0.0, 0.0, 0.2],
        [0.0, 0.0, 1.0, 0.5, 0.0],
    ],
    phases: 3.0,
    r0_ohm: 0.074,
    alpha_r_per_k: 0.00393,
    k_fe1_w_s_per_rad: 0.05,
    k_fe2_w_s2_per_rad2: 0.0002,
    k_fe15_w_per_rad15: 0.005,
    k_leak_w_per_pa2: 1.39e-12,
    k_mu_per_k: 0.0,
    t_mu_ref_c: 40.0,
    eta_m: 0.05,
    displacement_m3_per_rad: 3.0239439187142e-6,
    ram_area_m2: 1.52681e-3,
    g_od0_w_per_k: 5.0,
    g_od1_w_per_k_pa: 2.3e-6,
    g_pd1_w_per_k_sqrt_rad_s: 0.3,
    g_lb1_w_per_k_sqrt_rad_s: 1.0,
    lng_max_w_per_k: 0.0,
    lng_slope_w_s_per_k_rad: 0.0,
    lng_inlet_c: -162.0,
    feed_rise_k_per_pa: 1.5e-7,
};

/// Shaft speed at which the LNG exchanger's effectiveness is reduced to a constant,
/// rpm (the slowest loaded speed of the random missions; see [`reduce_losses`]).
pub const LNG_REDUCTION_RPM: f64 = 300.0;

/// Seeds of the random missions used for training.
pub const TRAIN_SEEDS: [u64; 6] = [6, 9, 19, 22, 24, 29];
/// Seeds of the random missions of the acceptance suite (never used for training).
pub const TEST_SEEDS: [u64; 5] = [1, 2, 3, 4, 5];
/// Residual weight of the non-drain node temperatures (drain weight is 1).
pub const W_OTHER: f64 = 0.1;
/// Under-prediction budget on the training set before a bias is applied, K.
pub const UNDER_BUDGET_K: f64 = 0.3;
/// Residual of every sample for a parameter set the firmware model rejects, K.
pub const INFEASIBLE_K: f64 = 1e3;
/// Residual sampling interval, firmware ticks (1 s; a whole number of model steps,
/// so the residuals compare states right after a model step).
pub const RESIDUAL_EVERY: usize = 100;
const _: () = assert!(RESIDUAL_EVERY.is_multiple_of(TICKS_PER_STEP as usize));

/// Reference nodes compared with the reduced nodes (contract order
/// winding, motor, pump, loop oil, valve block, drain).
pub const NODE_MAP: [Node; N_NODES] = [Node::Winding, Node::Motor, Node::Pump, Node::Loop, Node::MainBlock, Node::Case];

/// One reference run recorded at the firmware's 10 ms tick.
#[derive(Debug, Clone)]
pub struct Recording {
    /// Run name.
    pub name: String,
    /// Sensor snapshots at `t = k·10 ms`, `k = 0..=n`.
    pub sensors: Vec<Sensors>,
    /// Reference temperatures of the [`NODE_MAP`] nodes at the same instants, °C.
    pub temps: Vec<[f64; N_NODES]>,
}

/// Small deterministic generator (SplitMix64), so missions are reproducible by seed.
#[derive(Debug, Clone)]
pub struct SplitMix(u64);

impl SplitMix {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        SplitMix(seed ^ 0x5DEE_CE66_D1CE_4E5B)
    }
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// A random mission of `duration_s` from `seed`, inside the rig's envelope of the
/// paper's cases: a throttle mission (segments of 60–200 s at 300–700 rpm with a
/// needle setting that gives 0–60 bar at that speed, 20 % idle segments at 0 rpm)
/// or a servo mission (triangle position waves of 5–25 mm at 0.05–0.3 Hz per
/// segment, 20 % rest), ambient 10–30 °C, still air, no LNG.
pub fn random_mission(seed: u64, duration_s: f64) -> Mission {
    let mut r = SplitMix::new(seed);
    let ambient = r.uniform(10.0, 30.0);
    let servo = r.uniform(0.0, 1.0) < 0.3;
    let mut speed: Vec<(f64, f64)> = vec![];
    let mut needle: Vec<(f64, f64)> = vec![];
    let mut pos = vec![];
    let mut t = 0.0;
    let mut first = true;
    while t < duration_s {
        let seg = r.uniform(60.0, 200.0);
        let idle = r.uniform(0.0, 1.0) < 0.2 && !first;
        if servo {
            let amp = r.uniform(0.005, 0.025);
            let f = r.uniform(0.05, 0.3);
            let quarter = 0.25 / f;
            let end = (t + seg).min(duration_s);
            let mut tt = t;
            let mut k = 0usize;
            while tt < end {
                let x = if idle { 0.0 } else { [0.0, amp, 0.0, -amp][k % 4] };
                pos.push((tt, x));
                tt += quarter;
                k += 1;
            }
        } else {
            let rpm = if idle { 0.0 } else { r.uniform(300.0, 700.0) };
            // The setting is the drop at 500 rpm; the drop scales with flow squared.
            let dp_bar = r.uniform(0.0, 60.0);
            let setting = if rpm > 0.0 { dp_bar * (500.0 / rpm).powi(2) } else { 0.0 };
            if let (Some(&(_, ls)), Some(&(_, ln))) = (speed.last(), needle.last()) {
                speed.push((t, ls));
                needle.push((t, ln));
            }
            speed.push((t, rpm));
            needle.push((t, setting));
        }
        first = false;
        t += seg;
    }
    if servo {
        pos.push((duration_s, 0.0));
    }
    Mission {
        name: format!("random-{seed}"),
        circuit: if servo { Circuit::Servo } else { Circuit::Throttle },
        duration_s,
        ambient_c: Schedule::constant(ambient),
        speed_rpm: if servo { Schedule::constant(0.0) } else { Schedule(speed) },
        needle_bar: if servo { Schedule::constant(0.0) } else { Schedule(needle) },
        position: if servo { PositionRef::Profile(Schedule(pos)) } else { PositionRef::Profile(Schedule::constant(0.0)) },
        air_speed_mps: Schedule::constant(0.0),
        valve: ValveRule::None,
    }
}

/// One training run: name, scenario, and for runs with the LNG exchanger the
/// drain-thermostat band `(open above, close below)` in °C that switches it.
pub type TrainingRun = (String, Scenario, Option<(f64, f64)>);

/// LNG training runs: (needle bar or random seed, open above °C, close below °C).
/// Their thermostat bands (on the true drain) differ from the guard's 40/38 °C and
/// from the Fig. 15 loop-oil thermostat of the acceptance suite, so the exchanger
/// switches at other temperatures and load levels than in the tests.
pub const LNG_TRAINING: [(&str, f64, f64, f64); 3] =
    [("case1-50bar", 50.0, 35.0, 32.0), ("case1-30bar", 30.0, 31.0, 29.0), ("random-22", 22.0, 34.0, 31.0)];

/// The named training runs.
pub fn training_set() -> Vec<TrainingRun> {
    let mut v: Vec<TrainingRun> = [10.0, 30.0, 50.0]
        .iter()
        .map(|&b| (format!("case1-{b}bar"), Scenario::Case1 { needle_bar: b, duration_s: 600.0 }, None))
        .collect();
    v.push(("case2".into(), Scenario::Case2 { duration_s: 600.0 }, None));
    for s in TRAIN_SEEDS {
        v.push((format!("random-{s}"), Scenario::Mission(random_mission(s, 600.0)), None));
    }
    for (name, x, open, close) in LNG_TRAINING {
        let mut m = if name.starts_with("random") {
            random_mission(x as u64, 600.0)
        } else {
            Scenario::Case1 { needle_bar: x, duration_s: 600.0 }.mission().unwrap_or_else(|| random_mission(0, 600.0))
        };
        m.valve = ValveRule::Drain;
        v.push((format!("{name}-lng{open}/{close}"), Scenario::Mission(m), Some((open, close))));
    }
    v
}

/// Run the reference at the firmware's 10 ms tick with the scenario's own valve rule and
/// record the sensor signals and the mapped node temperatures.
pub fn record(rig: &Rig, name: &str, scenario: &Scenario) -> Result<Recording, SimError> {
    let mut plant = Plant::new(rig, scenario)?;
    let rule = plant.valve_rule();
    let mut sensors = vec![];
    let mut temps = vec![];
    plant.run(S_PER_TICK, scenario.duration_s(), |snap| {
        sensors.push(Sensors::from(snap));
        let mut t = [0.0; N_NODES];
        for (o, n) in t.iter_mut().zip(NODE_MAP) {
            *o = snap.temp(n);
        }
        temps.push(t);
        Ok(Control { lng_valve: rule.command(snap), stop: false })
    })?;
    Ok(Recording { name: name.into(), sensors, temps })
}

/// The reduced model's inputs (model units) for firmware tick `k` of a recording:
/// the sample at `t_k`, position change since `t_{k-1}` (as the guard computes it).
pub fn model_input(rec: &Recording, k: usize) -> ModelInputN<f64> {
    let s = &rec.sensors[k];
    let dpos = if k == 0 { 0.0 } else { s.position_mm - rec.sensors[k - 1].position_mm };
    ModelInputN {
        current_ha: s.current_a * HA_PER_A,
        dp_hbar: (s.p_a_bar - s.p_b_bar) * HBAR_PER_BAR,
        speed_hrads: s.speed_rpm * HRADS_PER_RPM,
        dpos_mm: dpos,
        ambient_c: s.ambient_c,
    }
}

/// LNG valve state of the reference over firmware tick `k` (from `t_k` to
/// `t_{k+1}`): the state the snapshot at `t_{k+1}` reports.
pub fn lng_during(rec: &Recording, k: usize) -> bool {
    rec.sensors.get(k + 1).is_some_and(|s| s.lng_open)
}

/// Simulate the reduced model (f64) on a recording exactly as the guard drives it:
/// cold start at the first ambient, every 10 ms tick accumulated
/// ([`Model::tick_n`]), and every [`TICKS_PER_STEP`] ticks the model step
/// ([`Model::update`]) with the count of that step's ticks during which the LNG
/// exchanger ran ([`lng_during`]). Element `k` is the state after tick `k` (the last
/// model step's, held between model steps as the guard's output holds it),
/// compared with the reference at `t_{k+1}`.
pub fn simulate_reduced(p: &ReducedParams, rec: &Recording) -> Option<Vec<[f64; N_NODES]>> {
    let mut m = Model::<f64>::new(p).ok()?;
    m.set_uniform(rec.sensors.first()?.ambient_c);
    let n = rec.sensors.len().saturating_sub(1);
    let mut out = Vec::with_capacity(n);
    let mut lng_ticks = 0u32;
    for k in 0..n {
        lng_ticks += u32::from(lng_during(rec, k));
        if m.tick_n(&model_input(rec, k)) {
            m.update(lng_ticks);
            lng_ticks = 0;
        }
        out.push(m.temperatures_c());
    }
    Some(out)
}

/// Drain error statistics of one run (prediction − reference), K.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorStats {
    /// max |error|.
    pub max_abs: f64,
    /// RMS error.
    pub rms: f64,
    /// Largest under-prediction (reference − prediction, ≥ 0).
    pub max_under: f64,
    /// Largest over-prediction (≥ 0).
    pub max_over: f64,
}

/// Drain error statistics of a parameter set on a recording.
pub fn drain_errors(p: &ReducedParams, rec: &Recording) -> Option<ErrorStats> {
    let pred = simulate_reduced(p, rec)?;
    Some(stats(pred.iter().zip(rec.temps.iter().skip(1)).map(|(a, b)| a[5] - b[5])))
}

/// Statistics of an error sequence.
pub fn stats(errs: impl Iterator<Item = f64>) -> ErrorStats {
    let (mut n, mut ss, mut max_abs, mut under, mut over) = (0usize, 0.0, 0.0f64, 0.0f64, 0.0f64);
    for e in errs {
        n += 1;
        ss += e * e;
        max_abs = max_abs.max(e.abs());
        under = under.max(-e);
        over = over.max(e);
    }
    ErrorStats { max_abs, rms: (ss / n.max(1) as f64).sqrt(), max_under: under, max_over: over }
}

/// `ReducedParams` with the loss coefficients reduced from the rig (step 1) and
/// the thermal network of `start` (capacities, conductances, splits).
pub fn reduce_losses(rig: &Rig, start: &ReducedParams) -> ReducedParams {
    let mut p = *start;
    let m = &rig.motor;
    p.phases = m.phases;
    p.r0_ohm = m.r25_ohm;
    p.alpha_r_per_k = rig.ext.winding_resistance_temperature.unwrap_or(0.0);
    let fe = &m.iron;
    let c = fe.pole_pairs / (2.0 * PI); // f = c·ω
    p.k_fe1_w_s_per_rad = fe.k_h * fe.b_peak_t * fe.b_peak_t * c;
    p.k_fe2_w_s2_per_rad2 = fe.k_c * fe.b_peak_t * fe.b_peak_t * c * c;
    p.k_fe15_w_per_rad15 = fe.k_e * (fe.b_peak_t * c).powf(1.5);
    p.k_leak_w_per_pa2 = rig.pump.gaps.conductance(rig.oil.mu_pa_s(40.0));
    p.k_mu_per_k = 0.0;
    p.t_mu_ref_c = 40.0;
    p.eta_m = rig.pump.eta_m;
    p.displacement_m3_per_rad = rig.displacement_m3_per_rad();
    p.ram_area_m2 = rig.actuator.ram_area_m2;
    // LNG exchanger, eqs. (20)-(22): above ~30 rpm the LNG stream is the smaller
    // capacity rate, g = eps(NTU, C*) C_LNG, with C* = C_LNG / (rho c_p D |w|); eps
    // is held at its value at LNG_REDUCTION_RPM, the slowest loaded speed of the
    // missions, where it is smallest: faster, the model under-credits the exchanger
    // (conservative, < 2.5 % up to 1000 rpm). At very low speed the oil stream is the
    // smaller, and g -> rho c_p D |w| (eps -> 1 as NTU grows; the same constant is the
    // oil stream's capacity rate in the model's cooled-feed term, so it stays the
    // physical rho c_p D; below ~200 rpm this over-credits the exchanger).
    let rho_cp_d = rig.oil.rho(40.0, 0.0) * rig.oil.cp(40.0) * p.displacement_m3_per_rad;
    let c_lng = rig.lng.capacity_rate_w_per_k();
    let c_oil = rho_cp_d * LNG_REDUCTION_RPM * 2.0 * PI / 60.0;
    let (c_min, c_max) = if c_lng < c_oil { (c_lng, c_oil) } else { (c_oil, c_lng) };
    p.lng_max_w_per_k = crate::cooling::effectiveness(rig.lng.ua_w_per_k / c_min, c_min / c_max) * c_min;
    p.lng_slope_w_s_per_k_rad = rho_cp_d;
    p.lng_inlet_c = rig.lng.inlet_c;
    p
}

/// Node-to-node links that are fitted: (i, j).
pub const LINKS: [(usize, usize); 6] = [(0, 1), (1, 2), (2, 5), (2, 3), (3, 4), (3, 5)];
/// Nodes with a fitted ambient conductance (the metal nodes that see the air).
pub const AMBIENT_NODES: [usize; 3] = [1, 2, 4];
/// Number of fitted parameters.
pub const N_PHI: usize = N_NODES + LINKS.len() + AMBIENT_NODES.len() + 6;

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

fn logit(p: f64) -> f64 {
    let p = p.clamp(1e-6, 1.0 - 1e-6);
    (p / (1.0 - p)).ln()
}

/// Parameter vector → `ReducedParams` (loss coefficients from `base`).
/// Layout: ln C[6], ln g[LINKS], ln g_amb[AMBIENT_NODES], logit(mech → loop oil),
/// logit(throttling → loop oil), ln g_od1, ln g_pd1, ln g_lb1, ln feed rise.
pub fn decode(base: &ReducedParams, phi: &[f64]) -> ReducedParams {
    let mut p = *base;
    let mut it = phi.iter().copied();
    let mut next = || it.next().unwrap_or(0.0);
    for c in p.capacity_j_per_k.iter_mut() {
        *c = next().exp();
    }
    p.conductance_w_per_k = [[0.0; N_NODES]; N_NODES];
    for (i, j) in LINKS {
        let g = next().exp();
        p.conductance_w_per_k[i][j] = g;
        p.conductance_w_per_k[j][i] = g;
    }
    p.g_od0_w_per_k = p.conductance_w_per_k[3][5];
    p.ambient_w_per_k = [0.0; N_NODES];
    for n in AMBIENT_NODES {
        p.ambient_w_per_k[n] = next().exp();
    }
    let mech_loop = sigmoid(next());
    let thr_loop = sigmoid(next());
    p.g_od1_w_per_k_pa = next().exp();
    p.g_pd1_w_per_k_sqrt_rad_s = next().exp();
    p.g_lb1_w_per_k_sqrt_rad_s = next().exp();
    p.feed_rise_k_per_pa = next().exp();
    let mut s = [[0.0; N_LOSSES]; N_NODES];
    s[0][0] = 1.0; // copper → winding
    s[1][1] = 1.0; // iron → motor (the reference puts the stator loss in the housing node)
    s[5][2] = 1.0; // leakage → drain oil
    s[3][3] = mech_loop;
    s[5][3] = 1.0 - mech_loop;
    s[3][4] = thr_loop;
    s[4][4] = 1.0 - thr_loop;
    p.loss_split = s;
    p
}

/// `ReducedParams` → parameter vector (inverse of [`decode`] on its image).
pub fn encode(p: &ReducedParams) -> Vec<f64> {
    let mut v: Vec<f64> = p.capacity_j_per_k.iter().map(|c| c.ln()).collect();
    for (i, j) in LINKS {
        v.push(p.conductance_w_per_k[i][j].max(1e-3).ln());
    }
    for n in AMBIENT_NODES {
        v.push(p.ambient_w_per_k[n].max(1e-3).ln());
    }
    v.push(logit(p.loss_split[3][3]));
    v.push(logit(p.loss_split[3][4]));
    v.push(p.g_od1_w_per_k_pa.max(1e-12).ln());
    v.push(p.g_pd1_w_per_k_sqrt_rad_s.max(1e-9).ln());
    v.push(p.g_lb1_w_per_k_sqrt_rad_s.max(1e-9).ln());
    v.push(p.feed_rise_k_per_pa.max(1e-12).ln());
    v
}

/// Starting point: capacities from the rig's masses, the network of
/// [`HAND_START`], the mechanical split of the rig.
pub fn initial_guess(rig: &Rig) -> ReducedParams {
    let base = reduce_losses(rig, &HAND_START);
    let rho = rig.oil.rho(40.0, 0.0);
    let cp = rig.oil.cp(40.0);
    let m = &rig.motor;
    let b = &rig.blocks;
    let mut p = base;
    p.capacity_j_per_k = [
        m.winding_mass_kg * m.winding_cp,
        (m.mass_kg - m.winding_mass_kg) * m.body_cp,
        rig.pump.mass_kg * rig.pump.cp,
        rho * cp * (b.loop_oil_m3 + 2.0 * rig.pump.port_oil_m3 + b.ball_oil_m3 + b.sensor_oil_m3),
        (b.main_mass_kg + b.ball_mass_kg) * b.cp,
        rho * cp * rig.pump.case_oil_m3,
    ];
    let mut phi = encode(&p);
    // Mechanical split of the rig; throttling mostly into the oil.
    phi[N_NODES + LINKS.len() + AMBIENT_NODES.len()] = logit(rig.pump.mech_to_outlet);
    phi[N_NODES + LINKS.len() + AMBIENT_NODES.len() + 1] = logit(0.9);
    p.g_od1_w_per_k_pa = rho * cp * p.k_leak_w_per_pa2; // advection of the leakage flow K·|Δp|
    let n = phi.len();
    phi[n - 4] = p.g_od1_w_per_k_pa.ln();
    // Outlet-port rise of the leakage feed: the outlet's share of eq. (8) over the
    // circulating flow, f eta_m |dp| / (rho c_p).
    phi[n - 1] = (rig.pump.mech_to_outlet * rig.pump.eta_m / (rho * cp)).max(1e-12).ln();
    decode(&base, &phi)
}

/// Half-width of the box around the initial guess in log space: every fitted
/// quantity stays within a factor e^BOX_LN (≈ 400) of its starting value (logits
/// within ±6 of theirs), by the smooth map `phi0 + B tanh((z - phi0)/B)`.
pub const BOX_LN: f64 = 6.0;

/// Half-width of the box of the capacities (they follow from the rig's masses, so
/// kept as a separate knob; the same factor e^6 as the rest).
pub const BOX_LN_CAPACITY: f64 = 6.0;

/// LM variable `z` → bounded parameter vector.
pub fn bounded(phi0: &[f64], z: &[f64]) -> Vec<f64> {
    phi0.iter()
        .zip(z)
        .enumerate()
        .map(|(i, (c, x))| {
            let b = if i < N_NODES { BOX_LN_CAPACITY } else { BOX_LN };
            c + b * ((x - c) / b).tanh()
        })
        .collect()
}

/// Residuals of a parameter vector on the training recordings.
fn residuals(base: &ReducedParams, phi0: &[f64], z: &[f64], recs: &[Recording]) -> Option<DVector<f64>> {
    let p = decode(base, &bounded(phi0, z));
    let mut r = vec![];
    for rec in recs {
        let Some(pred) = simulate_reduced(&p, rec) else {
            // Parameters the firmware model rejects (e.g. an explicit exchange rate
            // above `MAX_EXPLICIT_RATE`): a large constant residual of the right
            // length, so that LM rejects the step instead of stopping.
            let n: usize = recs.iter().map(|r| (r.sensors.len().saturating_sub(1)) / RESIDUAL_EVERY * N_NODES).sum();
            return Some(DVector::from_element(n, INFEASIBLE_K));
        };
        for (k, (a, b)) in pred.iter().zip(rec.temps.iter().skip(1)).enumerate() {
            if (k + 1) % RESIDUAL_EVERY != 0 {
                continue;
            }
            r.push(a[5] - b[5]);
            for i in 0..5 {
                r.push(W_OTHER * (a[i] - b[i]));
            }
        }
    }
    let v = DVector::from_vec(r);
    v.iter().all(|x| x.is_finite()).then_some(v)
}

/// Result of [`identify`].
#[derive(Debug, Clone)]
pub struct Identified {
    /// The identified parameters (with the conservative bias, if any, applied).
    pub params: ReducedParams,
    /// The unbiased least-squares fit.
    pub fitted: ReducedParams,
    /// Conservative bias: factor applied to the fitted ambient conductances (1 = none).
    pub ambient_scale: f64,
    /// Drain error statistics per training run (of `params`).
    pub training: Vec<(String, ErrorStats)>,
    /// LM iterations (objective evaluations).
    pub evaluations: usize,
    /// LM termination, as text.
    pub termination: String,
    /// Sum of squared residuals before and after the fit.
    pub cost: (f64, f64),
}

/// Record the training set on `rig` (in parallel).
pub fn record_training(rig: &Rig) -> Result<Vec<Recording>, SimError> {
    training_set()
        .par_iter()
        .map(|(n, s, band)| {
            let mut r = rig.clone();
            if let Some((open, close)) = band {
                r.lng.open_above_c = *open;
                r.lng.close_below_c = *close;
            }
            record(&r, n, s)
        })
        .collect()
}

/// The whole procedure: reduce the losses, record the training set, fit by LM,
/// apply the conservative bias if needed. `max_evals` bounds the LM work
/// (0 = the crate's default patience).
pub fn identify(rig: &Rig, max_evals: usize) -> Result<Identified, SimError> {
    let recs = record_training(rig)?;
    identify_on(rig, &recs, max_evals)
}

/// [`identify`] on already recorded training runs, starting from [`initial_guess`].
pub fn identify_on(rig: &Rig, recs: &[Recording], max_evals: usize) -> Result<Identified, SimError> {
    identify_from(recs, &initial_guess(rig), max_evals)
}

/// One LM fit on `recs` starting from `start` (its loss coefficients are kept).
pub fn identify_from(recs: &[Recording], start: &ReducedParams, max_evals: usize) -> Result<Identified, SimError> {
    let start = *start;
    let base = start;
    let phi0 = DVector::from_vec(encode(&start));
    let c = phi0.as_slice().to_vec();
    let cost0 = residuals(&base, &c, &c, recs).map_or(f64::NAN, |r| r.norm_squared());
    let problem = FdProblem::new(|z: &[f64]| residuals(&base, &c, z, recs), phi0, 1e-5);
    let lm = LevenbergMarquardt::new()
        .with_stepbound(0.5)
        .with_patience(if max_evals == 0 { 100 } else { max_evals.div_ceil(N_PHI + 1).max(1) });
    let (problem, report) = lm.minimize(problem);
    let phi = bounded(&c, problem.x().as_slice());
    let fitted = decode(&base, &phi);
    let cost1 = residuals(&base, &c, problem.x().as_slice(), recs).map_or(f64::NAN, |r| r.norm_squared());
    // The firmware's f32 and fixed-point builds must accept the result too.
    let builds = Model::<f32>::new(&fitted).is_ok() && Model::<eha_guard::num::Fx>::new(&fitted).is_ok();
    if !builds || !fitted.is_plausible() || !cost1.is_finite() || cost1 > cost0 {
        return Err(SimError::Scenario(format!(
            "identification failed (f32/fixed builds {builds}): {:?}, cost {cost0} -> {cost1}: {fitted:?}",
            report.termination
        )));
    }
    // Conservative bias: scale the ambient conductances down until the training
    // under-prediction is within the budget (bisection on the scale).
    let under = |p: &ReducedParams| {
        recs.par_iter().map(|r| drain_errors(p, r).map_or(f64::INFINITY, |e| e.max_under)).reduce(|| 0.0, f64::max)
    };
    let scaled = |s: f64| {
        let mut p = fitted;
        for g in p.ambient_w_per_k.iter_mut() {
            *g *= s;
        }
        p
    };
    let mut scale = 1.0;
    if under(&fitted) > UNDER_BUDGET_K {
        let (mut lo, mut hi) = (0.5, 1.0);
        for _ in 0..20 {
            let mid = 0.5 * (lo + hi);
            if under(&scaled(mid)) > UNDER_BUDGET_K {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        // Only a bias that meets the budget is applied; otherwise none (reported).
        scale = if under(&scaled(lo)) <= UNDER_BUDGET_K { lo } else { 1.0 };
    }
    let params = scaled(scale);
    let training = recs.iter().map(|r| (r.name.clone(), drain_errors(&params, r).unwrap_or(stats(std::iter::empty())))).collect();
    Ok(Identified {
        params,
        fitted,
        ambient_scale: scale,
        training,
        evaluations: report.number_of_evaluations,
        termination: format!("{:?}", report.termination),
        cost: (cost0, cost1),
    })
}

fn lit(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

fn row<const N: usize>(r: &[f64; N]) -> String {
    format!("[{}]", r.iter().map(|x| lit(*x)).collect::<Vec<_>>().join(", "))
}

/// The `DEFAULT` constant of `src/params.rs` (doc comment and item) for `id`.
pub fn render_params_rs(id: &Identified) -> String {
    let p = &id.params;
    let mut s = String::new();
    s.push_str("/// Default parameters, identified from the reference simulation (`eha_sim::identify`,\n");
    s.push_str("/// docs/identification.md): loss coefficients reduced from `Rig::default()`\n");
    s.push_str("/// (R constant, iron eq. 2 with f = p w / 2 pi, K_leak = gap conductance at 40 degC,\n");
    s.push_str("/// eta_m, D, A; LNG exchanger eqs. 20-22 at 300 rpm); capacities, conductances, ambient\n");
    s.push_str("/// conductances, the mechanical and throttling splits, g_od1, g_pd1, g_lb1 and the feed\n");
    s.push_str("/// rise fitted by Levenberg-Marquardt on log-parameters to the drain temperature of the\n");
    s.push_str(&format!("/// training runs (Case 1 at 10/30/50 bar, Case 2, random missions {:?}, and the\n", TRAIN_SEEDS));
    s.push_str("/// drain-thermostat LNG runs of `LNG_TRAINING`).\n");
    if id.ambient_scale < 1.0 {
        s.push_str(&format!(
            "/// Conservative bias: ambient conductances scaled by {:.4} (fit x {:.4}) so that the\n/// training under-prediction stays within {UNDER_BUDGET_K} K.\n",
            id.ambient_scale, id.ambient_scale
        ));
    } else {
        s.push_str("/// No conservative bias applied (training under-prediction within budget).\n");
    }
    s.push_str("/// THIS CONSTANT IS REGENERATED BY THE IDENTIFICATION TOOL: keep plain literals.\n");
    s.push_str("pub const DEFAULT: ReducedParams = ReducedParams {\n");
    s.push_str(&format!("    capacity_j_per_k: {},\n", row(&p.capacity_j_per_k)));
    s.push_str("    conductance_w_per_k: [\n");
    for r in &p.conductance_w_per_k {
        s.push_str(&format!("        {},\n", row(r)));
    }
    s.push_str("    ],\n");
    s.push_str(&format!("    ambient_w_per_k: {},\n", row(&p.ambient_w_per_k)));
    s.push_str("    loss_split: [\n");
    for r in &p.loss_split {
        s.push_str(&format!("        {},\n", row(r)));
    }
    s.push_str("    ],\n");
    for (name, v) in [
        ("phases", p.phases),
        ("r0_ohm", p.r0_ohm),
        ("alpha_r_per_k", p.alpha_r_per_k),
        ("k_fe1_w_s_per_rad", p.k_fe1_w_s_per_rad),
        ("k_fe2_w_s2_per_rad2", p.k_fe2_w_s2_per_rad2),
        ("k_fe15_w_per_rad15", p.k_fe15_w_per_rad15),
        ("k_leak_w_per_pa2", p.k_leak_w_per_pa2),
        ("k_mu_per_k", p.k_mu_per_k),
        ("t_mu_ref_c", p.t_mu_ref_c),
        ("eta_m", p.eta_m),
        ("displacement_m3_per_rad", p.displacement_m3_per_rad),
        ("ram_area_m2", p.ram_area_m2),
        ("g_od0_w_per_k", p.g_od0_w_per_k),
        ("g_od1_w_per_k_pa", p.g_od1_w_per_k_pa),
        ("g_pd1_w_per_k_sqrt_rad_s", p.g_pd1_w_per_k_sqrt_rad_s),
        ("g_lb1_w_per_k_sqrt_rad_s", p.g_lb1_w_per_k_sqrt_rad_s),
        ("lng_max_w_per_k", p.lng_max_w_per_k),
        ("lng_slope_w_s_per_k_rad", p.lng_slope_w_s_per_k_rad),
        ("lng_inlet_c", p.lng_inlet_c),
        ("feed_rise_k_per_pa", p.feed_rise_k_per_pa),
    ] {
        s.push_str(&format!("    {name}: {},\n", lit(v)));
    }
    s.push_str("};\n");
    s
}

/// Replace the `DEFAULT` item (from its doc comment to the closing `};`) in the
/// text of `src/params.rs` with `rendered`. `None` if the item is not found.
pub fn splice_params_rs(file: &str, rendered: &str) -> Option<String> {
    let item = file.find("pub const DEFAULT: ReducedParams")?;
    // Start of the doc-comment block directly above the item.
    let mut start = item;
    let before = &file[..item];
    let mut lines: Vec<&str> = before.split_inclusive('\n').collect();
    while let Some(l) = lines.last() {
        if l.trim_start().starts_with("///") {
            start -= l.len();
            lines.pop();
        } else {
            break;
        }
    }
    let end = item + file[item..].find("\n};\n")? + 4;
    Some(format!("{}{}{}", &file[..start], rendered, &file[end..]))
}
