//! The `diagnose` subcommand: `eha-sim diagnose <measured.csv>... [--rig
//! rig.toml] [--set key=value]... [--out DIR]`. Several logs are several
//! runs of one machine: one calibration shared by all, one answer
//! ([`super::multi`]). Exit 0 when a diagnosis was made (`none` and
//! `unexplained` included), 2 on bad input (file, rig, or a baseline that
//! cannot run on the inputs).

use super::analysis::{diagnose, DiagnoseOptions};
use super::reference::ReferenceModel;
use super::report::write_outputs;
use super::progress::Progress;
use super::{Candidate, Simulator};
use crate::measured::MeasuredRun;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `diagnose`.
#[derive(Debug, Clone, clap::Args)]
pub struct DiagnoseArgs {
    /// Measured runs in the shared measured-data format. Several files are
    /// logs of one machine: calibrated together (one parameter vector, each
    /// log replayed with its own inputs and circuit) and diagnosed once.
    #[arg(required = true)]
    pub measured: Vec<PathBuf>,
    /// Rig parameter file (TOML); default: the built-in paper rig.
    #[arg(long)]
    pub rig: Option<PathBuf>,
    /// Rig overrides `section.key=value`, applied after `--rig`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Output directory for report.md, diagnosis.json and the PNGs.
    #[arg(long, default_value = "diagnosis-out")]
    pub out: PathBuf,
    /// Fraction of the run used for training (≤ 0.7; the rest is held out).
    #[arg(long, default_value_t = 0.7)]
    pub train_fraction: f64,
    /// Model runs allowed per least-squares fit.
    #[arg(long, default_value_t = 80)]
    pub max_sims: usize,
    /// Also report what this log can show against its structure floor: each
    /// candidate's imprint at 1, 4 and 16 times its typical magnitude
    /// projected off the calibration's sensitivities, the expected imprint
    /// ratio per channel and the angles between candidates (report.md
    /// section, detectability.json; one model run per calibration parameter
    /// and per row).
    #[arg(long)]
    pub detectability: bool,
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
    /// Restart the physical tier's calibrated baseline also from every
    /// candidate's nominal-start fit (a wider search of the same
    /// objective, ~20 % more model runs; docs/diagnosis-limits.md, "The
    /// calibration's basins").
    #[arg(long)]
    pub nominal_restarts: bool,
}

/// Runs `diagnose` and prints a one-line verdict; see the module doc for the
/// exit codes.
pub fn run(args: &DiagnoseArgs) -> ExitCode {
    match run_inner(args) {
        Ok(line) => {
            println!("{line}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn run_inner(args: &DiagnoseArgs) -> anyhow::Result<String> {
    let mut runs = Vec::with_capacity(args.measured.len());
    for f in &args.measured {
        let run = MeasuredRun::read_file(f)?;
        for n in &run.notes {
            eprintln!("note: {}: {n}", f.display());
        }
        runs.push(run);
    }
    let mut rig = match &args.rig {
        Some(p) => crate::rig::Rig::from_toml_file(p)?,
        None => crate::rig::Rig::default(),
    };
    for s in &args.set {
        rig.set_override(s)?;
    }
    let mut o = DiagnoseOptions { train_fraction: args.train_fraction.clamp(0.1, 0.7), ..Default::default() };
    o.fit.max_sims = args.max_sims.max(4);
    o.structure = args.structure.unwrap_or(o.structure);
    o.nominal_restarts = args.nominal_restarts;
    let files: Vec<String> = args.measured.iter().map(|f| f.display().to_string()).collect();
    let t = std::time::Instant::now();
    // One log: its own table and model; several: the logs on one table
    // and one model per log sharing the parameters.
    let refs: Vec<&MeasuredRun> = runs.iter().collect();
    let mut refusal = None;
    let joint = if runs.len() > 1 {
        let (rows, m, why) = super::multi::joint_reference(&rig, &refs, &files, o.train_fraction, o.structure).map_err(|e| anyhow::anyhow!(e))?;
        refusal = why;
        Some((rows, m))
    } else {
        None
    };
    let single;
    let (run, model): (&MeasuredRun, &dyn Simulator) = match &joint {
        Some((rows, m)) => (rows as &MeasuredRun, m as &dyn Simulator),
        None => {
            single = ReferenceModel::new(rig, &runs[0]).map_err(|e| anyhow::anyhow!("{}: {e}", files[0]))?.with_structure(&runs[0], o.structure);
            refusal = single.structure_refusal().map(String::from);
            (&runs[0], &single as &dyn Simulator)
        }
    };
    let structure_note = structure_not_applied(o.structure, refusal.as_deref());
    if let Some(n) = &structure_note {
        eprintln!("note: {}: {n}", files.join(" + "));
    }
    if joint.is_some() {
        o = super::multi::options_for(&o, runs.len());
    }
    let progress = Progress::new(model, o.fit.max_sims, true);
    // The diagnosis, its outputs and the detectability under one bar,
    // cleared once on every path (before the verdict or the error prints).
    let work = || -> anyhow::Result<String> {
        let d = diagnose(run, &progress, &o)?;
        // The diagnosis's own time (the detectability pass comes after).
        let secs = t.elapsed().as_secs_f64();
        match &joint {
            Some((_, m)) => {
                let parts = super::multi::log_parts(&d, &refs, m.layout(), &o);
                super::multi::write_outputs(&d, &parts, &refs, &files, &args.out)?;
            }
            None => write_outputs(&d, run, &files[0], &args.out)?,
        }
        if let Some(n) = &structure_note {
            append_to_report(&args.out, &format!("\n**Note:** {n}\n"))?;
        }
        let mut detect_line = None;
        if args.detectability {
            // One run per calibration parameter and per candidate row, around
            // the answer's tier.
            let p = d.nuisance_before.len();
            progress.extend((1 + p + super::detect::MULTIPLES.len() * Candidate::EXTENSIONS.len()) as u64, "detectability");
            let fd = detectability_against_floor(&progress, &d, run, &o)?;
            append_to_report(&args.out, &fd.markdown())?;
            std::fs::write(args.out.join("detectability.json"), serde_json::to_string_pretty(&fd)? + "\n")?;
            // the posterior restated with the gate's rejection as an observation
            let stated = super::report::ProbabilityJson::of(&d);
            let reach = super::gate_obs::reaches(&fd);
            if let Some(restated) = super::gate_obs::restate_gate_observed(&stated, &|c| super::gate_obs::p_fail_of(&reach, c)) {
                append_to_report(&args.out, &super::gate_obs::markdown(&stated, &restated, &reach))?;
                std::fs::write(args.out.join("gate-observed.json"), serde_json::to_string_pretty(&restated)? + "\n")?;
            }
            detect_line = Some(fd.summary());
        }
        let verdict = format!(
            "cause: {} | held-out RMSE {:.3} -> {:.3} K | training {:.3} -> {:.3} K | {} model runs, {:.1} s | {}",
            d.answer(),
            d.before.heldout_rmse_k,
            d.after.heldout_rmse_k,
            d.before.train_rmse_k,
            d.after.train_rmse_k,
            d.sims,
            secs,
            args.out.join("report.md").display()
        );
        Ok(match detect_line {
            Some(l) => format!("{verdict}\n{l}"),
            None => verdict,
        })
    };
    let outcome = work();
    progress.finish();
    outcome
}

/// Appends `text` to the report just written in `out` (`report.md`).
fn append_to_report(out: &std::path::Path, text: &str) -> std::io::Result<()> {
    use std::io::Write as _;
    std::fs::OpenOptions::new().append(true).open(out.join("report.md"))?.write_all(text.as_bytes())
}

/// The note a single-log diagnosis prints (and appends to report.md) when
/// the structure asked for could not be applied: the pump's `eta_m` did
/// not come from the electrical balance (`refusal`, from
/// [`ReferenceModel::structure_refusal`]: no loaded current, or an
/// implausible value) and the physical tier stays the rig file's, as under
/// `--structure off`. `None` when applied or not asked.
pub fn structure_not_applied(asked: crate::diagnosis::analysis::Structure, refusal: Option<&str>) -> Option<String> {
    use crate::diagnosis::analysis::Structure;
    let why = refusal.filter(|_| asked != Structure::Off)?;
    let name = clap::ValueEnum::to_possible_value(&asked).map_or_else(|| format!("{asked:?}"), |v| v.get_name().to_string());
    Some(format!("structure `{name}` not applied: {why}, so the pump's eta_m does not come from the electrical balance; diagnosed as under `--structure off`"))
}

/// The detectability of `run` against its structure floor around the
/// calibrated point of the tier whose answer stands in `d`: the floors are
/// the diagnosis's own channel numbers, the points the evidence's.
pub fn detectability_against_floor(
    model: &dyn Simulator,
    d: &super::Diagnosis,
    run: &MeasuredRun,
    o: &DiagnoseOptions,
) -> anyhow::Result<super::projection::FloorDetectability> {
    super::projection::against_floor(model, d, run, o)
        .map_err(|e| anyhow::anyhow!("detectability: {e}"))
}

#[cfg(test)]
mod tests {
    use super::structure_not_applied;
    use crate::diagnosis::analysis::Structure;

    /// The note names the structure by its command-line spelling, and only
    /// when a structure was asked for and could not be applied.
    #[test]
    fn structure_note_only_when_asked_and_not_applied() {
        assert_eq!(structure_not_applied(Structure::Off, Some("why")), None);
        assert_eq!(structure_not_applied(Structure::NoCaseHeld, None), None);
        let n = structure_not_applied(Structure::NoCaseHeld, Some("no log has motor current under load")).expect("note");
        assert!(n.contains("`no-case-held` not applied: no log has motor current") && n.contains("--structure off"), "{n}");
    }
}
