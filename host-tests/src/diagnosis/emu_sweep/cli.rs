//! `eha-sim emulator-sweep`: which case set, its arguments, and the run
//! over the cases (appended to `emulator-sweep.jsonl` as they finish, the
//! table and JSON written at the end). Separate because it is the command,
//! not the diagnosis of a case.

use super::{default_cases, document, ident_cases, measure, redecide, run_emu_case_reach, EmuResult};
use crate::diagnosis::analysis::DiagnoseOptions;
use crate::diagnosis::evidence::DecisionRule;
use crate::diagnosis::model::Candidate;
use crate::emulator::{generate, EmuCase};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;


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
    /// The physical tier with the commissioning's structure where the log
    /// carries motor current under load (`off`/`full`/`no-case`/`no-case-held`, `false`
    /// and `true` are `off` and `full`; default
    /// `DiagnoseOptions::structure`'s): the pump's `eta_m` from the
    /// current, `pump_friction` held, the friction heat's placement and
    /// speed law and the housing probes' reading towards the air fitted
    /// (`no-case`: without the friction heat's case share and the pump
    /// probe's placement; `no-case-held`: also the loop oil's capacity and
    /// the oil probe held at the rig file;
    /// [`crate::diagnosis::analysis::Structure`]).
    #[arg(long, value_enum, value_name = "VARIANT")]
    pub structure: Option<crate::diagnosis::analysis::Structure>,
    /// Every diagnosis with `DiagnoseOptions::nominal_restarts` (the
    /// physical tier's baseline restarted also from every candidate's
    /// nominal-start fit).
    #[arg(long)]
    pub nominal_restarts: bool,
    /// Also record every candidate's `--detectability` projection on each
    /// log and twin (r̂ at 1, 4, 16 × its typical magnitude;
    /// `EmuResult::reach`, ~1 s a log): what the gate-as-observation
    /// re-statement needs (`diagnosis::gate_obs`).
    #[arg(long)]
    pub detectability: bool,
    /// Model runs allowed per least-squares fit, as `diagnose --max-sims`
    /// (every fit gets at least six Jacobians whatever it says,
    /// `fit::fit_deferred`).
    #[arg(long, default_value_t = crate::diagnosis::fit::FitOptions::default().max_sims)]
    pub max_sims: usize,
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
        let o = DiagnoseOptions {
            structure: a.structure.unwrap_or(DiagnoseOptions::default().structure),
            nominal_restarts: a.nominal_restarts,
            fit: crate::diagnosis::fit::FitOptions { max_sims: a.max_sims, ..Default::default() },
            ..Default::default()
        };
        match run_emu_case_reach(*c, &o, !a.no_twins, !a.no_oracle, a.detectability) {
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
