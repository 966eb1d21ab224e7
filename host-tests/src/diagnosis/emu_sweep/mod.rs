//! Diagnosis on logs of the independent rig emulator ([`crate::emulator`]):
//! generate, diagnose blind with the rig file as baseline, score. Used by
//! the tests (a small subset) and by `eha-sim emulator-sweep`, which writes
//! the whole table (`emulator-sweep.md`, `emulator-sweep.json`).
//!
//! This file runs one case and redecides a stored result under another
//! rule; by topic beside it: `cases.rs` (the case sets and their seeds),
//! `markdown.rs` (the sweep's table rows and document) and `cli.rs`
//! (`eha-sim emulator-sweep`: its arguments and the run over the cases).

mod cases;
mod cli;
mod markdown;

pub use cases::{case_of_seed, default_cases, effect_free_log, ident_cases, RETIRED};
pub use cli::{run, CaseSet, EmuSweepArgs};
pub use markdown::{document, miss_class, oracle_row, table_row};

use super::analysis::{diagnose, DiagnoseOptions, Diagnosis};
use super::evidence::{DecisionRule, StructureTerms};
use super::report::ProbabilityJson;
use super::model::Candidate;
use super::reference::ReferenceModel;
use crate::emulator::{generate, EmuCase};
use crate::rig::Rig;

pub use super::emu_result::{EmuResult, HiddenFit, MeasuredRule, TwinCheck};

/// Generates and diagnoses `case` with the rig file as baseline.
pub fn run_emu_case(case: EmuCase, o: &DiagnoseOptions) -> Result<EmuResult, String> {
    run_emu_case_twin(case, o, false)
}

/// [`run_emu_case`], and with `twin` (for a hidden effect) its effect-free
/// twin diagnosed too, for the imprint ratio ([`TwinCheck`]).
pub fn run_emu_case_twin(case: EmuCase, o: &DiagnoseOptions, twin: bool) -> Result<EmuResult, String> {
    run_emu_case_with(case, o, twin, true)
}

/// [`run_emu_case_twin`]; with `oracle`, also the hidden effect injected
/// into the calibrated reference model ([`EmuResult::hidden_detect`]). The
/// log and its twin are diagnosed in parallel.
pub fn run_emu_case_with(case: EmuCase, o: &DiagnoseOptions, twin: bool, oracle: bool) -> Result<EmuResult, String> {
    run_emu_case_reach(case, o, twin, oracle, false)
}

/// Every candidate's reach on the diagnosed log `run` ([`EmuResult::reach`];
/// empty when the projection fails, with a message on stderr).
fn reach_of(model: &ReferenceModel, d: &Diagnosis, run: &crate::measured::MeasuredRun, o: &DiagnoseOptions) -> Vec<super::gate_obs::Reach> {
    match super::projection::against_floor(model, d, run, o) {
        Ok(fd) => super::gate_obs::reaches(&fd),
        Err(e) => {
            eprintln!("reach: {e}");
            Vec::new()
        }
    }
}

/// [`run_emu_case_with`]; with `reach`, also every candidate's
/// detectability projection on the log and its twin ([`EmuResult::reach`],
/// ~1 s a log after the calibration).
pub fn run_emu_case_reach(case: EmuCase, o: &DiagnoseOptions, twin: bool, oracle: bool, reach: bool) -> Result<EmuResult, String> {
    let (run, truth) = generate(&case)?;
    let want_twin = twin && truth.affected.is_some();
    let t = std::time::Instant::now();
    let (main, twin_d) = rayon::join(
        || -> Result<(ReferenceModel, Diagnosis, Vec<super::gate_obs::Reach>), String> {
            let model = ReferenceModel::new(Rig::default(), &run).map_err(|e| e.to_string())?.with_structure(&run, o.structure);
            let d = diagnose(&run, &model, o).map_err(|e| e.to_string())?;
            let r = if reach { reach_of(&model, &d, &run, o) } else { Vec::new() };
            Ok((model, d, r))
        },
        || -> Result<Option<(Diagnosis, Vec<super::gate_obs::Reach>)>, String> {
            if !want_twin {
                return Ok(None);
            }
            let (trun, _) = crate::emulator::generate_twin(&case)?;
            let tmodel = ReferenceModel::new(Rig::default(), &trun).map_err(|e| e.to_string())?.with_structure(&trun, o.structure);
            let td = diagnose(&trun, &tmodel, o).map_err(|e| e.to_string())?;
            let r = if reach { reach_of(&tmodel, &td, &trun, o) } else { Vec::new() };
            Ok(Some((td, r)))
        },
    );
    let (model, d, reach) = main?;
    let (td, twin_reach) = match twin_d? {
        Some((td, r)) => (Some(td), r),
        None => (None, Vec::new()),
    };
    let affected = truth.affected.map(|(c, v)| (c.name().to_string(), v));
    let affected_heldout_k =
        affected.as_ref().and_then(|(c, _)| Some((d.before.channel(c)?.heldout_rmse_k, d.after.channel(c)?.heldout_rmse_k)));
    let best = d.ranking.iter().find(|r| r.cause != "none").map(|r| (r.cause.clone(), r.delta_bic, r.heldout_gain, r.qualifies));
    let held = |e: &super::analysis::RankEntry, c: &str| e.channel_heldout_k.iter().find(|(n, _)| n == c).map(|(_, v)| *v);
    let none_entry = d.ranking.iter().find(|r| r.cause == "none");
    let hidden_fit = d.ranking.iter().find(|r| r.cause == case.hidden.name() && case.hidden != Candidate::None).zip(none_entry).map(|(e, n)| {
        HiddenFit {
            delta_bic: e.delta_bic,
            affected_heldout_k: affected.as_ref().and_then(|(c, _)| Some((held(n, c)?, held(e, c)?))),
            pooled_heldout_k: (n.heldout_rmse_k, e.heldout_rmse_k),
            qualifies: e.qualifies,
            note: e.note.clone(),
        }
    });
    let hidden_detect = (oracle && case.hidden != Candidate::None)
        .then(|| {
            super::detect::with_answer_tier(&model, &d, |a| {
                let ext: Vec<f64> = a.sim.extension_params(case.hidden).iter().map(|_| truth.magnitude).collect();
                super::detect::detect_one(&run, a, o, case.hidden, &ext)
            })
        })
        .flatten();
    let seconds = t.elapsed().as_secs_f64();
    let twin = match (&affected, td) {
        (Some((c, _)), Some(td)) => {
            let misfit = |m: &super::stats::Metrics| m.channel(c).map(|x| x.heldout_rmse_k);
            misfit(&d.before).zip(misfit(&td.before)).map(|(a, b)| TwinCheck {
                misfit_k: a,
                twin_misfit_k: b,
                twin_answer: td.answer().into(),
                twin_probabilities: ProbabilityJson::of(&td),
                twin_channels: td.posterior.channels.clone(),
                twin_terms: td.posterior.terms.clone(),
                twin_measured: None,
                twin_heldout_k: std::iter::once(("pooled".to_string(), td.before.heldout_rmse_k))
                    .chain(td.before.channels.iter().map(|c| (c.channel.clone(), c.heldout_rmse_k)))
                    .collect(),
                twin_reach: twin_reach.clone(),
            })
        }
        _ => None,
    };
    Ok(EmuResult {
        case,
        magnitude: truth.magnitude,
        twin,
        answer: d.answer().into(),
        affected,
        affected_heldout_k,
        pooled_heldout_k: [d.nominal.heldout_rmse_k, d.before.heldout_rmse_k, d.after.heldout_rmse_k],
        channels: d
            .adequacy
            .channels
            .iter()
            .map(|c| (c.channel.clone(), c.heldout_rmse_k, c.heldout_rmse_k / c.noise_k, c.heldout_rmse_k / c.rise_k.max(1e-9), c.misfit))
            .collect(),
        at_bounds: d.adequacy.at_bounds.iter().map(|b| format!("{} {}", b.name, b.bound)).collect(),
        best_candidate: best,
        hidden_fit,
        hidden_detect,
        probabilities: ProbabilityJson::of(&d),
        ranking: d.ranking.iter().map(|r| (r.cause.clone(), r.delta_bic, r.heldout_gain, r.qualifies)).collect(),
        evidence_channels: d.posterior.channels.clone(),
        tier: d.nuisance_set.clone(),
        measured: None,
        evidence_terms: d.posterior.terms.clone(),
        reach,
        seconds,
    })
}


/// `r` (and its twin) with the posterior and answer under `rule` stored
/// beside its own ([`EmuResult::measured`]), as [`redecide`] would make
/// them. Results without terms are left as they are.
pub fn measure(r: &mut EmuResult, rule: DecisionRule) {
    let name = clap::ValueEnum::to_possible_value(&rule).map_or_else(|| format!("{rule:?}"), |v| v.get_name().to_string());
    let mut again = r.clone();
    redecide(&mut again, rule);
    if !r.evidence_terms.is_empty() {
        r.measured = Some(MeasuredRule { rule: name.clone(), answer: again.answer.clone(), probabilities: again.probabilities.clone() });
    }
    if let (Some(t), Some(a)) = (r.twin.as_mut(), again.twin.as_ref()) {
        if !t.twin_terms.is_empty() {
            t.twin_measured = Some(MeasuredRule { rule: name, answer: a.twin_answer.clone(), probabilities: a.twin_probabilities.clone() });
        }
    }
}

/// `r` decided again from its stored evidence terms with `rule`
/// ([`super::evidence::posterior_from_terms`]): new
/// probabilities; the answer is the cause named at P ≥ 0.9, else the old
/// answer when it named nothing, else `unexplained` when a channel misfits
/// (for a twin, whose adequacy flags are not stored: a channel at imprint
/// ratio ≥ 2 against its floor) and `none` otherwise. Exact for the tier the sweep's answer came from;
/// an answer that would have changed the escalation path is not replayed.
/// Results without terms are left as they are.
pub fn redecide(r: &mut EmuResult, rule: DecisionRule) {
    let again = |terms: &[StructureTerms], answer: &mut String, probs: &mut Vec<ProbabilityJson>, misfits: bool| {
        if terms.is_empty() {
            return;
        }
        let p = super::evidence::posterior_from_terms(terms, rule);
        *probs = p.iter().map(ProbabilityJson::from).collect();
        *answer = match super::evidence::named_cause(&p) {
            Some(c) => c.cause.clone(),
            None if super::evidence::names_a_cause(answer) => (if misfits { "unexplained" } else { "none" }).into(),
            None => answer.clone(),
        };
    };
    let misfits = r.channels.iter().any(|c| c.4);
    again(&r.evidence_terms, &mut r.answer, &mut r.probabilities, misfits);
    if let Some(t) = r.twin.as_mut() {
        let twin_misfits = t.twin_channels.iter().any(|c| c.imprint_ratio >= 2.0);
        again(&t.twin_terms, &mut t.twin_answer, &mut t.twin_probabilities, twin_misfits);
    }
}
