//! The `diagnose` subcommand: `eha-sim diagnose <measured.csv> [--rig
//! rig.toml] [--set key=value]... [--out DIR]`. Exit 0 when a diagnosis was
//! made (`none` and `unexplained` included), 2 on bad input (file, rig, or a baseline that
//! cannot run on the inputs).

use super::analysis::{diagnose, DiagnoseOptions};
use super::reference::ReferenceModel;
use super::report::write_outputs;
use super::Simulator;
use crate::measured::MeasuredRun;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `diagnose`.
#[derive(Debug, Clone, clap::Args)]
pub struct DiagnoseArgs {
    /// Measured run in the shared measured-data format.
    pub measured: PathBuf,
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
}

/// The model with a progress bar on the terminal (hidden when stderr is not
/// one): the stage (baseline calibration, then the candidates' fits) and the
/// model runs done of the budget (the baseline fit plus two starts per
/// candidate, each at most `max_sims` runs; fits that converge earlier leave
/// part of the budget unused, so the time left is an upper bound).
struct Progress<'a> {
    inner: &'a dyn Simulator,
    bar: indicatif::ProgressBar,
    candidates: std::sync::atomic::AtomicBool,
}

impl<'a> Progress<'a> {
    fn new(inner: &'a dyn Simulator, max_sims: usize) -> Self {
        let fits = 1 + 2 * super::Candidate::EXTENSIONS.len() as u64;
        let budget = 1 + fits * max_sims as u64;
        let bar = indicatif::ProgressBar::new(budget);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{msg:28} [{bar:30}] {pos}/{len} model runs, {elapsed} elapsed, ≤ {eta} left")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        bar.set_message("calibrating the baseline");
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        Progress { inner, bar, candidates: std::sync::atomic::AtomicBool::new(false) }
    }
}

impl Simulator for Progress<'_> {
    fn nuisance(&self) -> Vec<super::ParamSpec> {
        self.inner.nuisance()
    }
    fn extension_params(&self, c: super::Candidate) -> Vec<super::ParamSpec> {
        self.inner.extension_params(c)
    }
    fn physical_set(&self) -> Option<Box<dyn Simulator + '_>> {
        // The escalated diagnosis runs without the progress bar's counts.
        self.inner.physical_set()
    }

    fn nuisance_set_name(&self) -> &'static str {
        self.inner.nuisance_set_name()
    }

    fn simulate(&self, nuisance: &[f64], c: super::Candidate, ext: &[f64]) -> Result<super::SimSeries, String> {
        if c != super::Candidate::None && !self.candidates.swap(true, std::sync::atomic::Ordering::Relaxed) {
            self.bar.set_message("fitting 7 candidates × 2 starts");
        }
        self.bar.inc(1);
        self.inner.simulate(nuisance, c, ext)
    }
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
    let run = MeasuredRun::read_file(&args.measured)?;
    for n in &run.notes {
        eprintln!("note: {n}");
    }
    let mut rig = match &args.rig {
        Some(p) => crate::rig::Rig::from_toml_file(p)?,
        None => crate::rig::Rig::default(),
    };
    for s in &args.set {
        rig.set_override(s)?;
    }
    let model = ReferenceModel::new(rig, &run)?;
    let mut o = DiagnoseOptions { train_fraction: args.train_fraction.clamp(0.1, 0.7), ..Default::default() };
    o.fit.max_sims = args.max_sims.max(4);
    let t = std::time::Instant::now();
    let progress = Progress::new(&model, o.fit.max_sims);
    let d = diagnose(&run, &progress, &o);
    progress.bar.finish_and_clear();
    let d = d?;
    // The diagnosis's own time (the detectability pass comes after).
    let secs = t.elapsed().as_secs_f64();
    write_outputs(&d, &run, &args.measured.display().to_string(), &args.out)?;
    let mut detect_line = None;
    if args.detectability {
        let fd = detectability_against_floor(&model, &d, &run, &o)?;
        // A section appended to the report just written.
        use std::io::Write as _;
        std::fs::OpenOptions::new().append(true).open(args.out.join("report.md"))?.write_all(fd.markdown().as_bytes())?;
        std::fs::write(args.out.join("detectability.json"), serde_json::to_string_pretty(&fd)? + "\n")?;
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
    let floors: Vec<super::evidence::ChannelFloor> = d
        .posterior
        .channels
        .iter()
        .map(|c| super::evidence::ChannelFloor { channel: c.channel.clone(), noise_k: c.noise_k, rise_k: c.rise_k, misfit_k: c.misfit_k })
        .collect();
    let pts = super::analysis::evidence_points(run, d.split_time_s, o.points_per_channel);
    super::detect::with_answer_tier(model, d, |a| super::projection::floor_detectability(a.sim, run, a.nuisance, pts, a.split, floors))
        .map_err(|e| anyhow::anyhow!("detectability: {e}"))
}
