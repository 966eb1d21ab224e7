//! The commissioning experiment run by hand: one commissioning per
//! machine with the knobs (`EXP_*`) that the measurements in
//! docs/commissioning-foreign.md name. Prints; asserts nothing.

use super::{cal, headline, report};
use eha_sim::calibration::commission::commission_with;
use eha_sim::calibration::{CalLog, CalOptions};
use eha_sim::emulator::bench::{bench_set, commissioning_set, commissioning_set_hot, machines, EmuMachine};
use eha_sim::measured::Channel;

/// Measurement by hand (prints, asserts nothing): one commissioning
/// without the margin per machine, on `EXP_TRAIN` = `bench` (the two
/// throttle logs of `bench_set`), `hot` (`commissioning_set_hot`) or
/// `procedure` (`commissioning_set`, default), with the parameters named in
/// `EXP_HOLD` (comma-separated) held and those in `EXP_FREE` taken out of
/// the default holds (e.g. `duct_turbulent`); `EXP_MACHINE` = `big-pump` or `leaky-heavy` for one machine;
/// `EXP_MARGIN=1` with the margin and both paths; `EXP_RIG_CASE_SHARE=k`
/// scales the rig file's case share of the friction heat (the fit's start
/// and prior centre for `friction_case`), `EXP_RIG_CASE_OIL=k` and
/// `EXP_RIG_CASE_AREA=k` the case oil's volume and the case film's area
/// (start, prior centre and bounds of `cap_case_oil`, `film_case`);
/// `EXP_THINNING` the training logs' fit points ([`exp_thinning`]);
/// `EXP_DRAIN_WEIGHT=w` the drain residuals' weight (`CalOptions::drain_weight`);
/// `EXP_RIG_JOINT_MANIFOLD=k` a pump housing → main block metal path of k ×
/// the a-priori one (`Joints::a_priori`, 2.0 W/K; k = 0 the path open,
/// the same numbers as without it), held: the firmware cannot carry it, so
/// the reference's calibration and every log's channel errors only;
/// `EXP_DIRECT_SIGMA_OTHER=k` the direct path's data σ of the channels
/// other than the drain (K; 0.5 by default) and `EXP_DIRECT_FREE` its
/// default holds taken out (with `EXP_MARGIN=1`, which runs the direct
/// path; its block's in-sample floor under any margin is printed).
#[test]
#[ignore = "measurement by hand: one commissioning per machine"]
fn slow_structure_experiment() {
    let hold: Vec<&'static str> = env_list("EXP_HOLD")
        .iter()
        .map(|s| eha_sim::calibration::set::PARAMS.iter().find(|p| p.name == s).unwrap_or_else(|| panic!("no parameter {s}")).name)
        .collect();
    let train_kind = std::env::var("EXP_TRAIN").unwrap_or_default();
    let procedure = train_kind != "bench";
    let margin = std::env::var("EXP_MARGIN").is_ok_and(|v| v == "1");
    let only = std::env::var("EXP_MACHINE").ok();
    for m in machines().into_iter().filter(|m| only.as_deref().is_none_or(|o| o == m.name)) {
        let s = match train_kind.as_str() {
            "bench" => bench_set(&m, 3600),
            "hot" => commissioning_set_hot(&m, 3600),
            _ => commissioning_set(&m, 3600),
        }
        .expect("bench");
        let train: Vec<CalLog> = s.train.iter().map(cal).collect();
        let hold_logs: Vec<CalLog> = s.holdout.iter().map(cal).collect();
        let mut o = CalOptions::default();
        let free = env_list("EXP_FREE");
        o.hold.retain(|h| !free.iter().any(|f| f == h.0));
        for h in &hold {
            o.hold.push((h, "EXP_HOLD".into()));
        }
        o.prior_sigma.extend(exp_priors());
        if let Some(w) = env_f64("EXP_DRAIN_WEIGHT") {
            o.drain_weight = w;
        }
        o.margin_head_fold = exp_head_fold();
        if let Some(d) = o.direct.as_mut() {
            // the direct path's data weights and holds (EXP_DIRECT_SIGMA_OTHER, EXP_DIRECT_FREE)
            if let Some(s) = env_f64("EXP_DIRECT_SIGMA_OTHER") {
                d.sigma_other_k = s;
            }
            let free = env_list("EXP_DIRECT_FREE");
            d.hold.retain(|h| !free.iter().any(|f| f == h));
        }
        o.commission_thinning = exp_thinning();
        print_starts_points(&m, &train, &o);
        let t0 = std::time::Instant::now();
        let cpu0 = eha_sim::tools::cpu::process_cpu_s();
        let mut base = m.rig_file();
        if let Some(k) = env_f64("EXP_RIG_CASE_SHARE") {
            // the user's rig file with the sliding-pair rule's case share scaled (prior centre and start)
            base.pump.friction_pairs.case_share_scale *= k;
        }
        // the user's rig file with the case oil's volume and the case film's area scaled
        // (the fit's start, prior centre and bounds for `cap_case_oil`, `film_case`)
        if let Some(k) = env_f64("EXP_RIG_CASE_OIL") {
            base.pump.case_oil_m3 *= k;
        }
        if let Some(k) = env_f64("EXP_RIG_CASE_AREA") {
            base.pump.case_inner_area_m2 *= k;
        }
        if let Some(k) = env_f64("EXP_RIG_JOINT_MANIFOLD") {
            // a pump housing -> main block metal path of k times the a-priori 2.0 W/K (held)
            let mut j = eha_sim::rig::Joints::a_priori();
            j.pump_motor.contact_w_per_m2_k = 0.0;
            j.pump_manifold.k_w_per_m_k *= k;
            j.pump_manifold.contact_w_per_m2_k *= k;
            base.joints = Some(j);
            // the firmware cannot carry a joint: the reference's calibration and its held-out drain only
            let tr = eha_sim::calibration::log::rethinned(&train, o.commission_thinning, o.points_per_channel);
            let (b, o2, _) = eha_sim::calibration::commission::with_eta_m_from_current(&base, &tr, &o);
            let cal = eha_sim::calibration::calibrate(&b, &tr, &o2).expect("calibration");
            let fitted: Vec<String> = eha_sim::calibration::set::PARAMS.iter().zip(&cal.theta).map(|(p, t)| format!("{} {t:.3}", p.name)).collect();
            eprintln!("EXP {} joint ×{k}: objective {:.3}; {}", m.name, cal.chi2_before_after.1, fitted.join(", "));
            for l in tr.iter().chain(&hold_logs) {
                let s = l.simulate(&cal.rig).expect("replay");
                for e in eha_sim::calibration::log::channel_errors(l, &s) {
                    eprintln!("EXP {} joint {}: {} rmse {:.3} max {:.3} under {:.3}", m.name, l.name, e.channel, e.rmse_k, e.max_abs_k, e.max_under_k);
                }
            }
            continue;
        }
        let c = commission_with(&base, &train, &hold_logs, &o, margin).expect("commissioning");
        report(&m, &c, t0.elapsed().as_secs_f64());
        eprintln!("EXP {}: commissioning CPU {:.1} s (user + system, all threads)", m.name, eha_sim::tools::cpu::process_cpu_s() - cpu0);
        if let Ok(d) = &c.direct_path {
            // the direct block on the training logs (in-sample) and its floor under any margin
            // (the flashed block's are in the commissioning when it is the direct one)
            let checks: Vec<_> = if c.choice.chosen == eha_sim::calibration::paths::PathKind::Direct {
                c.train_chosen.clone()
            } else {
                train.iter().map(|l| eha_sim::calibration::commission::check_reduced(&c.cal.rig, &d.params, l).expect("check")).collect()
            };
            let t = eha_sim::calibration::commission::TrainingSpread::of(&checks);
            let held: Vec<String> = d.holdout.iter().map(|r| format!("{} {:.3}/{:.3}", r.log, r.vs_measured_max_k.unwrap_or(f64::NAN), r.vs_measured_under_k.unwrap_or(f64::NAN))).collect();
            eprintln!("EXP {} direct: in-sample floor {:?} K; held out without margin {}", m.name, t.map(|t| t.floor_k()), held.join(", "));
        }
        let h = headline(&m, &c, &s.holdout);
        let w: Vec<String> = c.holdout_without_margin().iter().map(|r| format!("{} {:.3}/{:.3}", r.log, r.vs_measured_max_k.unwrap_or(f64::NAN), r.vs_measured_under_k.unwrap_or(f64::NAN))).collect();
        eprintln!("EXP {} train={} hold={:?} margin={}: without margin {}; with margin {:.3} K: {:.3?}", m.name, if procedure { train_kind.as_str() } else { "bench" }, hold, margin, w.join(", "), h.margin_k, h.measured);
    }
}

/// `EXP_THINNING`: an experiment knob, the commissioning's thinning of
/// the training logs' fit points (`uniform`, `motion`; default the
/// calibration's).
fn exp_thinning() -> eha_sim::calibration::thinning::Thinning {
    use eha_sim::calibration::thinning::Thinning;
    match std::env::var("EXP_THINNING").as_deref() {
        Ok("uniform") => Thinning::Uniform,
        Ok("motion") => Thinning::Motion,
        _ => CalOptions::default().commission_thinning,
    }
}

/// Prints how many `t_drain_c` fit points each training log has in its
/// first 60, 120 and 300 s under the commissioning's thinning.
fn print_starts_points(m: &EmuMachine, train: &[CalLog], o: &CalOptions) {
    for l in eha_sim::calibration::log::rethinned(train, o.commission_thinning, o.points_per_channel) {
        let t0 = l.run.time_s[0];
        let n = |dt: f64| l.points.iter().filter(|&&(ch, i)| ch == Channel::TDrainC && l.run.time_s[i] - t0 < dt).count();
        let all = l.points.iter().filter(|p| p.0 == Channel::TDrainC).count();
        eprintln!("EXP {} {} thinning {:?}: drain points {all}, in the first 60/120/300 s {}/{}/{}", m.name, l.name, o.commission_thinning, n(60.0), n(120.0), n(300.0));
    }
}

/// `EXP_HEAD_FOLD`: an experiment knob, how the margin scores the
/// training logs' starts (`off`, `tails`, `loo`; default the calibration's).
pub(super) fn exp_head_fold() -> eha_sim::calibration::margin::HeadFold {
    use eha_sim::calibration::margin::{HeadFold, HEAD_FOLD_DEFAULT};
    match std::env::var("EXP_HEAD_FOLD").as_deref() {
        Ok("off") => HeadFold::Off,
        Ok("tails") => HeadFold::Tails,
        Ok("loo") => HeadFold::LeaveOneOut,
        _ => HEAD_FOLD_DEFAULT,
    }
}

/// `EXP_PRIOR`: an experiment knob, prior widths (σ in ln θ) that replace
/// the set's, as `name=σ,name=σ`.
pub(super) fn exp_priors() -> Vec<(&'static str, f64)> {
    std::env::var("EXP_PRIOR")
        .unwrap_or_default()
        .split(',')
        .filter(|s| !s.is_empty())
        .map(|s| {
            let (n, v) = s.split_once('=').unwrap_or_else(|| panic!("EXP_PRIOR entry {s}: name=sigma"));
            let p = eha_sim::calibration::set::PARAMS.iter().find(|p| p.name == n).unwrap_or_else(|| panic!("no parameter {n}"));
            (p.name, v.parse().unwrap_or_else(|_| panic!("EXP_PRIOR {s}")))
        })
        .collect()
}

/// Measurement by hand (prints, asserts nothing): which logged channels
/// contradict the case's joint move. Big-pump commissioned as the
/// procedure prescribes (no margin); then the commissioned rig with the
/// case's friction share, oil volume and film area scaled by
/// `EXP_JOINT=share,volume,area` (default 3.5,2.0,2.4: the soak start's
/// heat audit, docs/commissioning-foreign.md) and nothing refitted; each
/// training and held-out log's channel RMSE / max under, K, both rigs.
#[test]
#[ignore = "measurement by hand: one commissioning"]
fn slow_joint_move_channels() {
    use eha_sim::calibration::log::channel_errors;
    let m = machines().into_iter().find(|m| m.name == "big-pump").expect("big-pump");
    let s = commissioning_set(&m, 3600).expect("bench");
    let train: Vec<CalLog> = s.train.iter().map(cal).collect();
    let hold: Vec<CalLog> = s.holdout.iter().map(cal).collect();
    let c = commission_with(&m.rig_file(), &train, &hold, &CalOptions::default(), false).expect("commissioning");
    let k: Vec<f64> = std::env::var("EXP_JOINT").unwrap_or_else(|_| "3.5,2.0,2.4".into()).split(',').map(|x| x.parse().expect("EXP_JOINT: share,volume,area")).collect();
    let mut joint = c.cal.rig.clone();
    joint.pump.friction_pairs.case_share_scale *= k[0];
    joint.pump.case_oil_m3 *= k[1];
    joint.pump.case_inner_area_m2 *= k[2];
    for l in train.iter().chain(&hold) {
        let (a, b) = (l.simulate(&c.cal.rig).expect("as built"), l.simulate(&joint).expect("joint"));
        for (x, y) in channel_errors(l, &a).iter().zip(channel_errors(l, &b)) {
            eprintln!("EXP joint {k:?} {:40} {:10} rmse {:.3} -> {:.3}, under {:.3} -> {:.3}", l.name, x.channel, x.rmse_k, y.rmse_k, x.max_under_k, y.max_under_k);
        }
    }
}

/// The comma-separated names in the environment variable `name` (empty
/// when unset).
fn env_list(name: &str) -> Vec<String> {
    std::env::var(name).unwrap_or_default().split(',').filter(|s| !s.is_empty()).map(String::from).collect()
}

/// An experiment knob's number: the environment variable `name` parsed as
/// f64, `None` when unset or not a number.
fn env_f64(name: &str) -> Option<f64> {
    std::env::var(name).ok().and_then(|v| v.parse::<f64>().ok())
}
