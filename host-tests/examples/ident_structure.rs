//! Where the identification-run calibration misses the rig emulator
//! (docs/calibration.md, "Rig-level structure in the commissioning and
//! diagnosis calibration set"): the nominal emulator's logs of the slow test
//! `slow_identification_runs_commission_across_regimes` (training:
//! identification runs 44 and 45; held out: pressure-speed steps 43 and
//! identification run 46), calibrated on the training pair, every channel's
//! error on each log; the oil channel's residual binned by shaft speed,
//! needle drop and ram air, and regressed on them. Then the same with one
//! emulator path switched off at a time (a variant changes the emulator's
//! parameters only; the reference and its set are the same).
//!
//! `cargo run --profile fast -p eha-sim --example ident_structure -- [VARIANT...]`
//! (default `nominal`; `all` for every variant; ~20 s per variant on two
//! cores). Variants: see [`VARIANTS`].

use eha_sim::calibration::{calibrate, channel_errors, CalLog, CalOptions, Calibration};
use eha_sim::diagnosis::Candidate;
use eha_sim::emulator::missions::{draw, EmuScenario};
use eha_sim::emulator::params::EmuParams;
use eha_sim::emulator::plant::{Hidden, Plant, N};
use eha_sim::measured::Channel;
use eha_sim::rig::Rig;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

/// A variant: name, what it changes, the change.
type Variant<T> = (&'static str, &'static str, fn(&mut T));

/// Emulator variants: name, what is switched off, the change.
const VARIANTS: [Variant<EmuParams>; 8] = [
    ("nominal", "nothing", |_| {}),
    ("no-pump-manifold", "pump end cap → manifold plate joint (g_end_manifold 10 → 0 W/K)", |p| p.g_end_manifold = 0.0),
    ("no-plate-film", "loop oil ↔ manifold plate film (plate wetted area → 0, block film area +0.03 m²)", |p| {
        p.block_duct[2] += p.plate_duct[2];
        p.plate_duct[2] = 1e-9;
    }),
    ("plate-in-block", "manifold plate as a node of its own (g_manifold_block 14 → 1e4 W/K)", |p| p.g_manifold_block = 1e4),
    ("no-mech-metal", "20 % of the eq. (8) loss into the port-plate metal (→ delivered oil)", |p| p.mech_split = [0.7, 0.3, 0.0]),
    ("no-ball-joint", "ball block → main block joint (g_ball_block 4 → 0 W/K)", |p| p.g_ball_block = 0.0),
    ("fast-probes", "sensor lags and the surface probes' 4 % towards ambient", |p| {
        p.sensor_tau = [1.0, 1.0, 1.0, 1.0, 2.0];
        p.probe_ambient_frac = 0.0;
    }),
    ("no-hose", "throttle hoses' eq. (10) loss in the loop oil (hose 1.2 m → 0.05 m, ξ 4 → 0)", |p| p.hose = [0.05, p.hose[1], 0.0]),
];

/// Reference-side variants (the base rig before the calibration): name,
/// what changes, the change.
const REF_VARIANTS: [Variant<Rig>; 9] = [
    ("rig", "the rig file", |_| {}),
    ("no-speed-friction", "pump no-load and viscous friction (T0, C_v) off: η_m·D·Δp only, as the emulator", |r| {
        r.pump.no_load_torque_nm = 0.0;
        r.pump.viscous_torque_coeff = 0.0;
    }),
    ("no-viscous-friction", "pump viscous friction C_v off", |r| r.pump.viscous_torque_coeff = 0.0),
    ("thin-wall", "block wall in series with the loop and ball films ×10 (wall_m 0.03 → 0.003 m)", |r| r.blocks.wall_m *= 0.1),
    ("thin-wall-x3", "block wall in series with the films ×3 (wall_m 0.03 → 0.01 m)", |r| r.blocks.wall_m /= 3.0),
    ("no-wall", "block wall in series with the films ×100 (wall_m 0.03 → 0.0003 m)", |r| r.blocks.wall_m *= 0.01),
    ("thin-wall+manifold-joint", "thin-wall and the a-priori pump → manifold joint (2.0 W/K)", |r| {
        r.blocks.wall_m *= 0.1;
        let mut j = eha_sim::rig::Joints::a_priori();
        j.pump_motor.contact_w_per_m2_k = 0.0;
        r.joints = Some(j);
    }),
    ("thin-wall+manifold-joint-x5", "thin-wall and a pump → manifold joint of 10 W/K (the emulator's)", |r| {
        r.blocks.wall_m *= 0.1;
        let mut j = eha_sim::rig::Joints::a_priori();
        j.pump_motor.contact_w_per_m2_k = 0.0;
        j.pump_manifold = eha_sim::rig::WallPath { k_w_per_m_k: 48.0, area_m2: 2.8e-3, length_m: 0.05, contact_area_m2: 4.0e-3, contact_w_per_m2_k: 20_000.0 };
        j.pump_manifold.length_m = 0.011_76; // 10.0 W/K
        r.joints = Some(j);
    }),
    ("joints", "the a-priori pump → motor and pump → manifold joints", |r| r.joints = Some(eha_sim::rig::Joints::a_priori())),
];

/// The log of `s` flown by the emulator with parameters `p` (the slow
/// test's seeds and draw), with the noise-free loop oil and manifold plate
/// of the trace at the log's rows.
fn emu_log(p: &EmuParams, s: EmuScenario, seed: u64) -> (CalLog, Vec<[f64; 3]>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let m = draw(s, 1200.0, &mut rng);
    let trace = Plant { p, m: &m, h: Hidden { effect: Candidate::None, magnitude: 0.0 } }.run(s.log_interval_s());
    let run = eha_sim::emulator::log_mission(&trace, &m, &mut rng);
    let truth = run
        .time_s
        .iter()
        .map(|&t| {
            let r = &trace[(t / s.log_interval_s()).round() as usize].1;
            [r[N::LoopOil as usize], r[N::Manifold as usize], r[N::Block as usize]]
        })
        .collect();
    (CalLog::new(&format!("{s:?}-{seed}"), run, 120).expect("cal log"), truth)
}

fn pooled(e: &[eha_sim::calibration::ChannelError]) -> f64 {
    (e.iter().map(|c| c.rmse_k * c.rmse_k).sum::<f64>() / e.len() as f64).sqrt()
}

/// One log row seen by the oil anatomy.
struct Row {
    t: f64,
    /// Oil residual sim − meas, K.
    r: f64,
    rpm: f64,
    dp: f64,
    air: f64,
    /// Measured oil above ambient, K.
    rise: f64,
    /// Emulator loop oil, manifold plate, block (noise-free), °C.
    truth: [f64; 3],
}

/// The oil residual (sim − meas) of `log` under `c`, binned and regressed.
fn oil_anatomy(log: &CalLog, truth: &[[f64; 3]], c: &Calibration) {
    let s = log.simulate(&c.rig).expect("sim");
    let run = &log.run;
    let col = |ch: Channel| run.get(ch).expect("column");
    let (meas, sim) = (col(Channel::TOilC), &s[&Channel::TOilC]);
    let (speed, pa, pb, amb) = (col(Channel::SpeedRpm), col(Channel::PABar), col(Channel::PBBar), col(Channel::AmbientC));
    let air = run.get(Channel::AirSpeedMps);
    let blk = col(Channel::TBlockC);
    let mut rows = Vec::new();
    for i in 0..run.len() {
        let (Some(m), Some(n), Some(a), Some(b), Some(t_a)) = (meas[i], speed[i], pa[i], pb[i], amb[i]) else { continue };
        let v = air.and_then(|c| c[i]).unwrap_or(0.0);
        rows.push(Row { t: run.time_s[i], r: sim[i] - m, rpm: n, dp: a - b, air: v, rise: m - t_a, truth: truth[i] });
    }
    // Last two thirds only (after the first warm-up): the regime-dependent part.
    let late: Vec<&Row> = rows.iter().filter(|x| x.t >= 400.0).collect();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let bin = |name: &str, key: fn(&Row) -> f64, edges: &[f64]| {
        let mut line = format!("    by {name}:");
        for w in edges.windows(2) {
            let r: Vec<f64> = late.iter().filter(|x| (w[0]..w[1]).contains(&key(x))).map(|x| x.r).collect();
            if !r.is_empty() {
                line += &format!(" [{:.0},{:.0}) {:+.2} K (n {})", w[0], w[1], mean(&r), r.len());
            }
        }
        println!("{line}");
    };
    bin("speed rpm", |x| x.rpm, &[400.0, 800.0, 1100.0, 1400.0, 1700.0, 2100.0]);
    bin("drop bar", |x| x.dp, &[0.0, 30.0, 55.0, 80.0, 110.0]);
    bin("air m/s", |x| x.air, &[-0.1, 0.5, 12.0, 30.0]);
    bin("oil-amb K", |x| x.rise, &[0.0, 10.0, 20.0, 30.0, 45.0, 80.0]);
    // Least squares r = a + b·n/1000 + c·Δp/100 + d·air/10 + e·(oil−amb)/10.
    let x: Vec<[f64; 5]> = late.iter().map(|r| [1.0, r.rpm / 1000.0, r.dp / 100.0, r.air / 10.0, r.rise / 10.0]).collect();
    let y: Vec<f64> = late.iter().map(|r| r.r).collect();
    let xm = nalgebra::DMatrix::from_fn(x.len(), 5, |i, j| x[i][j]);
    let ym = nalgebra::DVector::from_vec(y.clone());
    let svd = xm.clone().svd(true, true);
    let beta = svd.solve(&ym, 1e-12).expect("lsq");
    let res = &ym - &xm * &beta;
    let r2 = 1.0 - res.norm_squared() / ym.iter().map(|v| (v - mean(&y)).powi(2)).sum::<f64>();
    println!(
        "    regression (t ≥ 400 s): {:+.2} K {:+.2} K/1000 rpm {:+.2} K/100 bar {:+.2} K/(10 m/s) {:+.2} K/(10 K oil rise), R² {:.2}",
        beta[0], beta[1], beta[2], beta[3], beta[4], r2
    );
    // The emulator's own nodes: how far the loop oil sits above the manifold
    // plate and the block (its films), against what the reference puts
    // between its loop oil and main block.
    let t = |i: usize| late.iter().map(|r| r.truth[i]).collect::<Vec<f64>>();
    let (lo, mf, bk) = (t(0), t(1), t(2));
    println!(
        "    emulator truth (t ≥ 400 s): loop oil − manifold plate {:.2} K, loop oil − block {:.2} K, manifold − block {:.2} K",
        mean(&lo.iter().zip(&mf).map(|(a, b)| a - b).collect::<Vec<_>>()),
        mean(&lo.iter().zip(&bk).map(|(a, b)| a - b).collect::<Vec<_>>()),
        mean(&mf.iter().zip(&bk).map(|(a, b)| a - b).collect::<Vec<_>>())
    );
    let so = &s[&Channel::TOilC];
    let sb = &s[&Channel::TBlockC];
    let idx: Vec<usize> = (0..run.len()).filter(|&i| run.time_s[i] >= 400.0).collect();
    println!(
        "    reference (t ≥ 400 s): oil − block {:.2} K (measured oil − block probe {:.2} K)",
        mean(&idx.iter().map(|&i| so[i] - sb[i]).collect::<Vec<_>>()),
        mean(&idx.iter().filter_map(|&i| Some(meas[i]? - blk[i]?)).collect::<Vec<_>>())
    );
}

fn variant(name: &str, what: &str, change: fn(&mut EmuParams), base: &Rig, anatomy: bool) {
    let mut p = EmuParams::default();
    change(&mut p);
    let t0 = Instant::now();
    let train = [emu_log(&p, EmuScenario::IdentRun, 44), emu_log(&p, EmuScenario::IdentRun, 45)];
    let holds = [emu_log(&p, EmuScenario::PressureSpeedSteps, 43), emu_log(&p, EmuScenario::IdentRun, 46)];
    let o = CalOptions { hold: Vec::new(), ..CalOptions::default() };
    let logs: Vec<CalLog> = train.iter().map(|l| l.0.clone()).collect();
    let c = calibrate(base, &logs, &o).expect("calibration");
    println!("## {name}: {what}");
    let bound: Vec<&str> = c.params.iter().filter(|q| q.at_bound).map(|q| q.name.as_str()).collect();
    println!("  {} model runs, {:.1} s; on bounds: {bound:?}", c.model_runs, t0.elapsed().as_secs_f64());
    let mut line = String::from("  values:");
    for q in &c.params {
        line += &format!(" {} {:.3}", q.name, q.value);
    }
    println!("{line}");
    for (kind, (l, truth)) in [("train", &train[0]), ("train", &train[1]), ("held out", &holds[0]), ("held out", &holds[1])] {
        let e = channel_errors(l, &l.simulate(&c.rig).expect("sim"));
        let per: Vec<String> = e.iter().map(|c| format!("{} {:.2}", c.channel, c.rmse_k)).collect();
        println!("  {kind:8} {:22} pooled {:.3} K | {}", l.name, pooled(&e), per.join(", "));
        if anatomy {
            oil_anatomy(l, truth, &c);
        }
    }
}

/// The loop oil's conductance to the valve-block metal, reference (duct
/// film in series with the block wall, the rig file) against the emulator
/// (plate and block duct films, no wall), over speed and oil temperature.
fn conductances() {
    use eha_sim::network::{block_path, duct_conductance};
    let rig = Rig::default();
    let p = EmuParams::default();
    let b = &rig.blocks;
    println!("loop oil → block metal, W/K: reference film | with wall ; emulator plate + block films");
    for t in [30.0, 50.0, 70.0] {
        let mut line = format!("  {t:.0} °C:");
        for rpm in [500.0, 1000.0, 1500.0, 2000.0] {
            let q = rig.displacement_m3_per_rad() * rpm * std::f64::consts::PI / 30.0;
            let nu = rig.oil.nu_m2_per_s(t);
            let film = duct_conductance(&rig, q, b.loop_d_m, b.loop_len_m, b.loop_area_scale, t, nu);
            let g_ref = block_path(&rig, film, b.main_area_m2);
            let qe = p.displacement_m3 * rpm / 60.0;
            let nue = eha_sim::emulator::props::oil_nu(t);
            let ge: f64 = [p.plate_duct, p.block_duct].iter().map(|d| eha_sim::emulator::props::duct_film(qe, d[0], d[1], d[2], nue, t)).sum();
            line += &format!(" {rpm:.0} rpm {film:.1} | {g_ref:.1} ; {ge:.1}");
        }
        println!("{line}");
    }
}

/// `commission` on the identification runs (its own options: probe held,
/// η_m from the current; `--hold-wall` holds `block_wall` too): the fitted
/// wall, and the firmware's six-state reduction against the commissioned
/// reference on every log.
fn commission_ident(hold_wall: bool) {
    use eha_sim::calibration::commission::commission;
    let p = EmuParams::default();
    let t0 = Instant::now();
    let train = [emu_log(&p, EmuScenario::IdentRun, 44).0, emu_log(&p, EmuScenario::IdentRun, 45).0];
    let holds = [emu_log(&p, EmuScenario::PressureSpeedSteps, 43).0, emu_log(&p, EmuScenario::IdentRun, 46).0];
    let mut o = CalOptions::default();
    if hold_wall {
        o.hold.push(("block_wall", "held for the comparison".into()));
    }
    let c = commission(&Rig::default(), &train, &holds, &o).expect("commission");
    println!("commission: {} model runs, {:.1} s; flashable {}", c.cal.model_runs, t0.elapsed().as_secs_f64(), c.flashable());
    for q in c.cal.params.iter().filter(|q| ["block_wall", "pump_friction", "probe_oil"].contains(&q.name.as_str())) {
        println!("  {} {:.3} {:?}", q.name, q.value, q.status);
    }
    for h in &c.holdout {
        println!("  held out {}: pooled {:.3} K", h.log, pooled(&h.commissioned));
    }
    for r in &c.reduced {
        println!("  reduced vs reference drain, {}: max {:.3} K, under {:.3} K", r.log, r.vs_reference_max_k, r.vs_reference_under_k);
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--conductances") {
        conductances();
        return;
    }
    if args.iter().any(|a| a == "--commission") {
        commission_ident(args.iter().any(|a| a == "--hold-wall"));
        return;
    }
    let anatomy = args.iter().any(|a| a == "--anatomy");
    let names: Vec<&str> = args.iter().filter(|a| !a.starts_with("--")).map(String::as_str).collect();
    let names = if names.is_empty() { vec!["nominal"] } else { names };
    let refs: Vec<&str> = args.iter().filter_map(|a| a.strip_prefix("--ref=")).collect();
    let refs = if refs.is_empty() { vec!["rig"] } else { refs };
    for (rname, rwhat, rchange) in REF_VARIANTS {
        if !refs.contains(&rname) {
            continue;
        }
        let mut base = Rig::default();
        rchange(&mut base);
        println!("# reference: {rname} ({rwhat})");
        for (name, what, change) in VARIANTS {
            if names.contains(&"all") || names.contains(&name) {
                variant(name, what, change, &base, anatomy);
            }
        }
    }
}
