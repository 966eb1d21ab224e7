//! Diagnosis on logs of the independent rig emulator ([`crate::emulator`]):
//! generate, diagnose blind with the rig file as baseline, score. Used by
//! the tests (a small subset) and by `eha-sim emulator-sweep`, which writes
//! the whole table (`emulator-sweep.md`, `emulator-sweep.json`).

use super::analysis::{diagnose, DiagnoseOptions, Diagnosis};
use super::evidence::{DecisionRule, StructureTerms};
use super::report::ProbabilityJson;
use super::model::Candidate;
use super::reference::ReferenceModel;
use crate::emulator::missions::EmuScenario;
use crate::emulator::{generate, EmuCase};
use crate::rig::Rig;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

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

/// The posterior of `d` as `diagnosis.json` writes it.
fn probabilities(d: &Diagnosis) -> Vec<ProbabilityJson> {
    d.posterior.causes.iter().map(ProbabilityJson::from).collect()
}

/// [`run_emu_case_twin`]; with `oracle`, also the hidden effect injected
/// into the calibrated reference model ([`EmuResult::hidden_detect`]). The
/// log and its twin are diagnosed in parallel.
pub fn run_emu_case_with(case: EmuCase, o: &DiagnoseOptions, twin: bool, oracle: bool) -> Result<EmuResult, String> {
    let (run, truth) = generate(&case)?;
    let want_twin = twin && truth.affected.is_some();
    let t = std::time::Instant::now();
    let (main, twin_d) = rayon::join(
        || -> Result<(ReferenceModel, Diagnosis), String> {
            let model = ReferenceModel::new(Rig::default(), &run).map_err(|e| e.to_string())?;
            let d = diagnose(&run, &model, o).map_err(|e| e.to_string())?;
            Ok((model, d))
        },
        || -> Result<Option<Diagnosis>, String> {
            if !want_twin {
                return Ok(None);
            }
            let (trun, _) = crate::emulator::generate_twin(&case)?;
            let tmodel = ReferenceModel::new(Rig::default(), &trun).map_err(|e| e.to_string())?;
            diagnose(&trun, &tmodel, o).map(Some).map_err(|e| e.to_string())
        },
    );
    let (model, d) = main?;
    let td = twin_d?;
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
                twin_probabilities: probabilities(&td),
                twin_channels: td.posterior.channels.clone(),
                twin_terms: td.posterior.terms.clone(),
                twin_measured: None,
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
        probabilities: probabilities(&d),
        ranking: d.ranking.iter().map(|r| (r.cause.clone(), r.delta_bic, r.heldout_gain, r.qualifies)).collect(),
        evidence_channels: d.posterior.channels.clone(),
        tier: d.nuisance_set.clone(),
        measured: None,
        evidence_terms: d.posterior.terms.clone(),
        seconds,
    })
}

/// The default case set: two scenarios per candidate (each chosen to excite
/// it) and four without a hidden effect; seeds `base + k`. The two
/// `viscosity-temperature` slots are retired (the viscosity is part of the
/// baseline now) and left out, keeping every other case on its seed.
pub fn default_cases(duration_s: f64, base: u64) -> Vec<EmuCase> {
    use EmuScenario::*;
    let list: [(&str, EmuScenario); 18] = [
        ("winding-resistance-temperature", PressureSpeedSteps),
        ("winding-resistance-temperature", LoadCycles),
        ("viscosity-temperature", LoadCycles),
        ("viscosity-temperature", PressureSpeedSteps),
        ("sensor-lag", ConstantThrottle),
        ("sensor-lag", SpeedSteps),
        ("coulomb-friction", ServoHoldMove),
        ("coulomb-friction", ServoHoldMove),
        ("churning-loss", SpeedSteps),
        ("churning-loss", PressureSpeedSteps),
        ("motor-pump-conduction", ConstantThrottle),
        ("motor-pump-conduction", LoadCycles),
        ("forced-convection", ConstantThrottle),
        ("forced-convection", AirSteps),
        ("none", ConstantThrottle),
        ("none", LoadCycles),
        ("none", SpeedSteps),
        ("none", ServoHoldMove),
    ];
    cases_from(&list, duration_s, base)
}

/// The identification-run case set: every throttle-circuit candidate hidden
/// in two [`EmuScenario::IdentRun`] logs (speed, load and ram air stepped
/// independently), Coulomb friction in two servo logs (only piston motion
/// shows it), and four logs with nothing hidden (three identification
/// runs, one servo run); seeds `base + index` (the retired
/// `viscosity-temperature` slots left out, as in [`default_cases`]).
pub fn ident_cases(duration_s: f64, base: u64) -> Vec<EmuCase> {
    use EmuScenario::*;
    let list: [(&str, EmuScenario); 18] = [
        ("winding-resistance-temperature", IdentRun),
        ("winding-resistance-temperature", IdentRun),
        ("viscosity-temperature", IdentRun),
        ("viscosity-temperature", IdentRun),
        ("sensor-lag", IdentRun),
        ("sensor-lag", IdentRun),
        ("coulomb-friction", ServoHoldMove),
        ("coulomb-friction", ServoHoldMove),
        ("churning-loss", IdentRun),
        ("churning-loss", IdentRun),
        ("motor-pump-conduction", IdentRun),
        ("motor-pump-conduction", IdentRun),
        ("forced-convection", IdentRun),
        ("forced-convection", IdentRun),
        ("none", IdentRun),
        ("none", IdentRun),
        ("none", IdentRun),
        ("none", ServoHoldMove),
    ];
    cases_from(&list, duration_s, base)
}

/// The cases of `list` (hidden candidate name, scenario), seeds `base + index`;
/// a retired candidate's slot ([`RETIRED`]) is skipped with its seed.
fn cases_from(list: &[(&str, EmuScenario)], duration_s: f64, base: u64) -> Vec<EmuCase> {
    list.iter()
        .enumerate()
        .filter(|(_, (h, _))| !RETIRED.contains(h))
        .map(|(k, (h, s))| EmuCase {
            hidden: Candidate::from_name(h).unwrap_or(Candidate::None),
            scenario: *s,
            seed: base + k as u64,
            duration_s,
        })
        .collect()
}

/// Candidates that left the list (their effect is part of the baseline now):
/// their slots in the case sets keep their seeds unused.
pub const RETIRED: [&str; 1] = ["viscosity-temperature"];

/// One Markdown table row of `r`.
pub fn table_row(r: &EmuResult) -> String {
    let ch: Vec<String> = r
        .channels
        .iter()
        .map(|(c, v, q, f, m)| {
            let b = if *m { "**" } else { "" };
            format!("{b}{} {v:.2} ({q:.0}σ, {:.0} %){b}", c.trim_start_matches("t_").trim_end_matches("_c"), 100.0 * f)
        })
        .collect();
    format!(
        "| {:?} ({}) | {} | {} | {} | {} | {} | {:.2} / {:.2} → {:.2} | {} | {} | {:.0} |",
        r.case.scenario,
        r.case.seed,
        r.case.hidden.name(),
        if r.case.hidden == Candidate::None { "–".to_string() } else { format!("{:.3e}", r.magnitude) },
        r.answer,
        r.affected.as_ref().map_or("–".into(), |(c, v)| format!("{c} ({v:.2} K)")),
        r.affected_heldout_k.map_or("–".into(), |(b, a)| format!("{b:.2} → {a:.2} ({:.0} %)", 100.0 * (1.0 - a / b))),
        r.pooled_heldout_k[0],
        r.pooled_heldout_k[1],
        r.pooled_heldout_k[2],
        ch.join(", "),
        if r.at_bounds.is_empty() { "–".into() } else { r.at_bounds.join(", ") },
        r.seconds
    )
}

/// What the hidden effect's own candidate achieved, in three classes:
/// `named`; `oracle < 50 %` (fitted, it does not reach the acceptance's
/// 50 % held-out gain on the affected channel, so no answer could meet it
/// on this log with this model and calibration set); `oracle ≥ 50 %`
/// (it would, and the rules did not name it). `None` for `none` cases.
pub fn miss_class(r: &EmuResult) -> Option<&'static str> {
    let h = r.hidden_fit.as_ref()?;
    Some(if r.hit() {
        "named"
    } else if h.affected_gain().is_some_and(|g| g >= 0.5) {
        "oracle ≥ 50 %"
    } else {
        "oracle < 50 %"
    })
}

/// One row of the oracle table: the hidden candidate as fitted.
pub fn oracle_row(r: &EmuResult) -> Option<String> {
    let h = r.hidden_fit.as_ref()?;
    Some(format!(
        "| {:?} ({}) | {} | {} | {:.1} | {} | {:.2} → {:.2} | {} | {} | {} |",
        r.case.scenario,
        r.case.seed,
        r.case.hidden.name(),
        r.answer,
        h.delta_bic,
        h.affected_heldout_k.zip(h.affected_gain()).map_or("–".into(), |((b, a), g)| format!("{b:.2} → {a:.2} ({:.0} %)", 100.0 * g)),
        h.pooled_heldout_k.0,
        h.pooled_heldout_k.1,
        if h.qualifies { "yes".to_string() } else if h.note.is_empty() { "no".into() } else { format!("no ({})", h.note) },
        r.hidden_detect.as_ref().map_or("–".into(), |x| format!("{:.2} of {:.2} K left ({:.0} %)", x.left_k, x.imprint_k.1, 100.0 * x.best_gain)),
        miss_class(r).unwrap_or("–"),
    ))
}

/// Which emulator case set `emulator-sweep` runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CaseSet {
    /// Each candidate in two of the diagnosis tests' operating families
    /// ([`default_cases`], seeds 1700 + 100·k + index).
    Original,
    /// Identification runs ([`ident_cases`], seeds 2700 + 100·k + index).
    Ident,
}

/// Arguments of `emulator-sweep`.
#[derive(Debug, Clone, clap::Args)]
pub struct EmuSweepArgs {
    /// Log duration, s.
    #[arg(long, default_value_t = 1200.0)]
    pub duration: f64,
    /// Repetitions of each case set (seeds 1700 or 2700 + 100·k + case index).
    #[arg(long, default_value_t = 1)]
    pub seeds: u64,
    /// Case sets (comma-separated), run in this order within each repetition.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [CaseSet::Original])]
    pub cases: Vec<CaseSet>,
    /// Run only the cases with these seeds (comma-separated).
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<u64>,
    /// Leave out the servo cases (slow replays, and with them coulomb-friction).
    #[arg(long)]
    pub no_servo: bool,
    /// Output directory for emulator-sweep.md and emulator-sweep.json (and
    /// emulator-sweep.jsonl, one line per case as it finishes).
    #[arg(long, default_value = "emulator-sweep-out")]
    pub out: PathBuf,
    /// Also write every generated log to OUT/logs/ (measured-data format),
    /// the effect-free twins as `…-twin.csv`.
    #[arg(long)]
    pub logs: bool,
    /// Skip the effect-free twins (no imprint ratios; half the time).
    #[arg(long)]
    pub no_twins: bool,
    /// Skip the oracle (the hidden effect injected into the calibrated
    /// reference model; the "in the model's structure" column).
    #[arg(long)]
    pub no_oracle: bool,
    /// Keep the cases already in OUT/emulator-sweep.jsonl and run the rest.
    #[arg(long)]
    pub resume: bool,
    /// Run nothing: render the cases already in OUT/emulator-sweep.jsonl.
    #[arg(long)]
    pub render_only: bool,
    /// Decide again from the stored evidence terms with this rule
    /// ([`redecide`]) before rendering.
    #[arg(long, value_enum)]
    pub redecide: Option<DecisionRule>,
    /// Also decide with this rule from the stored terms and keep its
    /// posterior beside the sweep's own ([`measure`]): the document adds
    /// its reliability table and counts.
    #[arg(long, value_enum)]
    pub measure: Option<DecisionRule>,
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

/// The sweep's Markdown (`emulator-sweep.md`): the answer table, its
/// summary line, the hidden effects' own fits and their classes. Also what
/// `eha-sim docs` renders into docs/diagnosis.md from the committed JSON.
pub fn document(ok: &[EmuResult]) -> String {
    let mut md = String::from(
        "| scenario (seed) | hidden | magnitude | answer | affected channel (imprint) | its held-out RMSE before → after (K) | pooled held-out RMSE nominal / calibrated → after (K) | calibrated held-out per channel, K (× noise σ, % of rise; **misfit**) | nuisance on a bound | s |\n|---|---|---|---|---|---|---|---|---|---:|\n",
    );
    for r in ok {
        md += &table_row(r);
        md.push('\n');
    }
    let with = ok.iter().filter(|r| r.case.hidden != Candidate::None).count();
    let hits = ok.iter().filter(|r| r.case.hidden != Candidate::None && r.hit()).count();
    let gain = ok.iter().filter(|r| r.case.hidden != Candidate::None && r.hit() && r.affected_gain().is_some_and(|g| g >= 0.5)).count();
    let count = |s: &str| ok.iter().filter(|r| r.answer == s).count();
    let nones: Vec<&EmuResult> = ok.iter().filter(|r| r.case.hidden == Candidate::None).collect();
    let false_disc = nones.iter().filter(|r| r.answer != "none" && r.answer != "unexplained").count();
    let _ = writeln!(
        md,
        "\nHidden effect named in {hits} of {with} (with ≥ 50 % held-out gain on the affected channel: {gain}); \
         `none` cases: {} none, {} unexplained, {false_disc} false discoveries of {}; answers overall: {} unexplained, {} none.",
        nones.iter().filter(|r| r.answer == "none").count(),
        nones.iter().filter(|r| r.answer == "unexplained").count(),
        nones.len(),
        count("unexplained"),
        count("none"),
    );
    md += "\n**The hidden effect's own candidate, as fitted in the diagnosis** (known to the sweep only):\n\n\
           | scenario (seed) | hidden | answer | ΔBIC | affected channel held-out, baseline → with it (gain) | pooled held-out (K) | qualifies | in the model's structure: imprint left after calibration (best gain) | class |\n\
           |---|---|---|---:|---|---|---|---|---|\n";
    for row in ok.iter().filter_map(oracle_row) {
        md += &row;
        md.push('\n');
    }
    let class = |c: &str| ok.iter().filter(|r| miss_class(r) == Some(c)).count();
    let absorbed = ok.iter().filter(|r| !r.hit() && r.hidden_detect.as_ref().is_some_and(|x| x.best_gain < 0.5)).count();
    let _ = writeln!(
        md,
        "\nOf {with} hidden effects: {} named, {} missed with the right candidate reaching ≥ 50 % on the affected channel, \
         {} where the right candidate, fitted, stays under 50 %; of the misses, {absorbed} where even the model's own \
         structure with the effect at its true magnitude leaves less than the 50 % bar after calibration.",
        class("named"),
        class("oracle ≥ 50 %"),
        class("oracle < 50 %"),
    );
    md += &super::emu_tables::ratio_table(ok);
    md += &super::emu_tables::reliability_table(ok);
    md += &super::emu_tables::measured_rule_section(ok);
    md
}

/// Runs the emulator sweep; exit 0 always unless the outputs cannot be
/// written (it is a measurement, not a test). Cases run one after another
/// (each log and its twin in parallel, every diagnosis's fits in parallel),
/// each appended to `emulator-sweep.jsonl` as it finishes.
pub fn run(a: &EmuSweepArgs) -> ExitCode {
    let cases: Vec<EmuCase> = (0..a.seeds)
        .flat_map(|k| {
            a.cases.iter().flat_map(move |set| match set {
                CaseSet::Ident => ident_cases(a.duration, 2700 + 100 * k),
                CaseSet::Original => default_cases(a.duration, 1700 + 100 * k),
            })
        })
        .filter(|c| !(a.no_servo && c.scenario.is_servo()))
        .filter(|c| a.only.is_empty() || a.only.contains(&c.seed))
        .collect();
    if let Err(e) = std::fs::create_dir_all(&a.out) {
        eprintln!("error: {}: {e}", a.out.display());
        return ExitCode::from(2);
    }
    let lines = a.out.join("emulator-sweep.jsonl");
    let mut ok: Vec<EmuResult> = Vec::new();
    if a.resume || a.render_only {
        if let Ok(text) = std::fs::read_to_string(&lines) {
            for (n, l) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
                match serde_json::from_str::<EmuResult>(l) {
                    Ok(r) => ok.push(r),
                    Err(e) => {
                        eprintln!("error: {}:{}: {e}", lines.display(), n + 1);
                        return ExitCode::from(2);
                    }
                }
            }
        }
    } else {
        let _ = std::fs::remove_file(&lines);
    }
    let todo: Vec<EmuCase> =
        if a.render_only { Vec::new() } else { cases.into_iter().filter(|c| !ok.iter().any(|r| r.case.seed == c.seed)).collect() };
    let bar = indicatif::ProgressBar::new(todo.len() as u64);
    let mut errors = Vec::new();
    for c in &todo {
        if a.logs {
            let dir = a.out.join("logs");
            let _ = std::fs::create_dir_all(&dir);
            if let Ok((run, _)) = generate(c) {
                let _ = run.write_file(dir.join(format!("{}-{:?}-{}.csv", c.hidden.name(), c.scenario, c.seed)));
            }
            if let (false, false, Ok((twin, _))) = (a.no_twins, c.hidden == Candidate::None, crate::emulator::generate_twin(c)) {
                let _ = twin.write_file(dir.join(format!("{}-{:?}-{}-twin.csv", c.hidden.name(), c.scenario, c.seed)));
            }
        }
        match run_emu_case_with(*c, &DiagnoseOptions::default(), !a.no_twins, !a.no_oracle) {
            Ok(r) => {
                let line = serde_json::to_string(&r).unwrap_or_default() + "\n";
                let appended = std::fs::OpenOptions::new().create(true).append(true).open(&lines).and_then(|mut f| {
                    use std::io::Write as _;
                    f.write_all(line.as_bytes())
                });
                if let Err(e) = appended {
                    eprintln!("error: {}: {e}", lines.display());
                }
                ok.push(r);
            }
            Err(e) => errors.push(format!("seed {}: {e}", c.seed)),
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    if let Some(rule) = a.redecide {
        ok.iter_mut().for_each(|r| redecide(r, rule));
    }
    if let Some(rule) = a.measure {
        ok.iter_mut().for_each(|r| measure(r, rule));
    }
    ok.sort_by_key(|r| r.case.seed);
    let mut md = document(&ok);
    for e in &errors {
        let _ = writeln!(md, "\nerror: {e}");
    }
    print!("{md}");
    let write = || -> std::io::Result<()> {
        std::fs::write(a.out.join("emulator-sweep.md"), &md)?;
        // The evidence terms stay in the JSONL (they are most of its size).
        let lean: Vec<EmuResult> = ok
            .iter()
            .cloned()
            .map(|mut r| {
                r.evidence_terms.clear();
                if let Some(t) = r.twin.as_mut() {
                    t.twin_terms.clear();
                }
                r
            })
            .collect();
        let j = serde_json::to_string_pretty(&lean).map_err(std::io::Error::other)?;
        std::fs::write(a.out.join("emulator-sweep.json"), j + "\n")
    };
    match write() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
