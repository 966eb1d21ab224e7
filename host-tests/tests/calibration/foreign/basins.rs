//! The local minima of the three-log fit
//! (`commissioning_set_hot`) on big-pump, polished from given multiplier
//! vectors (docs/commissioning-foreign.md, "Reproducibility").

use super::*;
use eha_sim::calibration::commission::with_eta_m_from_current;
use eha_sim::calibration::set::{index, nominal};
use eha_sim::calibration::{calibrate, PARAMS};

/// The two basins of docs/commissioning-foreign.md ("Reproducibility"), their
/// end points' largest moves to two digits: the original run's, then the
/// nudged run's.
const BASINS: &str = "film_ball 3.8, cap_ball_block 2.2, cap_case_oil 1.44, friction_case 0.86, h_out_pump 1.6, film_port 0.71; \
    film_ball 1.4, cap_ball_block 0.87, cap_case_oil 3.0, friction_case 2.1, h_out_pump 2.4, film_port 1.35";

/// Polishes the calibration of big-pump's three-log set (original logs)
/// from each start in `EXP_STARTS` (`;`-separated lists of `name value`
/// pairs, `,`-separated; the rest at the rig file; unset: [`BASINS`], the
/// two basins' end points to two digits, at `EXP_S2` 4.30 unless set) for `EXP_POLISH_ITERS`
/// (default 30) Gauss–Newton iterations without LM before it, and prints
/// where each ends: objective trail, decrements, data χ² (σ 0.2 K), the
/// prior sum and the multipliers. With the default starts it asserts that
/// they end in two basins (below).
#[test]
#[ignore = "slow tier: polishes of the three-log fit from given starts (~75 s)"]
fn slow_three_log_minima() {
    let m = big_pump();
    let s = commissioning_set_hot(&m, 3600).expect("bench");
    let train: Vec<CalLog> = s.train.iter().map(cal).collect();
    let (base, mut o, _) = with_eta_m_from_current(&m.rig_file(), &train, &CalOptions::default());
    o.max_evals = 0;
    o.polish_iters = std::env::var("EXP_POLISH_ITERS").ok().and_then(|v| v.parse().ok()).unwrap_or(30);
    let given = std::env::var("EXP_STARTS").ok();
    let default_s2 = if given.is_none() { Some(4.30) } else { None };
    o.polish_s2 = std::env::var("EXP_S2").ok().and_then(|v| v.parse().ok()).or(default_s2);
    let by_default = given.is_none();
    let starts = given.unwrap_or_else(|| BASINS.to_string());
    let mut chi2 = Vec::new();
    for (i, st) in starts.split(';').enumerate() {
        let mut th = nominal();
        for pair in st.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let (n, v) = pair.split_once(' ').expect("name value");
            th[index(n.trim()).unwrap_or_else(|| panic!("{n}"))] = v.trim().parse().expect("value");
        }
        o.start = Some(th);
        let t0 = std::time::Instant::now();
        let c = calibrate(&base, &train, &o).expect("calibrate");
        let prior: f64 = c.params.iter().zip(PARAMS.iter()).filter(|(p, _)| p.status == eha_sim::calibration::Status::Fitted).map(|(p, d)| (p.value.ln() / (o.prior_scale * d.prior_sigma_ln)).powi(2)).sum();
        eprintln!("START {i}: {:.0} s, {} runs; polish objective {:.3?}", t0.elapsed().as_secs_f64(), c.model_runs, c.polish.objective);
        eprintln!("  decrement {:.3?} converged {} on bound {:?} s2 {:.4}", c.polish.decrement, c.polish.converged, c.polish.on_bound, c.polish.s2);
        eprintln!("  data chi2 {:.2} prior {:.3}", c.chi2_before_after.1, prior);
        chi2.push(c.chi2_before_after.1);
        let v: Vec<String> = c.params.iter().filter(|p| p.status == eha_sim::calibration::Status::Fitted).map(|p| format!("{} {:.4}", p.name, p.value)).collect();
        eprintln!("  END {}", v.join(", "));
    }
    // From [`BASINS`] the two polishes stay apart: measured data χ² 11 105
    // and 20 029 on the fixed reference (b36ffe3; 129 s at load 5–6; before
    // it 10 601 and 19 497, 75 s at load ~2; the second with
    // `cap_case_oil` on its ×3 bound). One minimum would give a ratio near
    // 1; 1.5 asks for two basins with room for the polish's stall.
    if by_default {
        assert!(chi2[1] > 1.5 * chi2[0], "the two basins' data chi2 {:.0} and {:.0}: not two basins apart (measured 11 105 and 20 029)", chi2[0], chi2[1]);
    }
}
