//! The `diagnose` subcommand: `eha-sim diagnose <measured.csv> [--rig
//! rig.toml] [--set key=value]... [--out DIR]`. Exit 0 when a diagnosis was
//! made (`none` included), 2 on bad input (file, rig, or a baseline that
//! cannot run on the inputs).

use super::analysis::{diagnose, DiagnoseOptions};
use super::reference::ReferenceModel;
use super::report::write_outputs;
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
    let d = diagnose(&run, &model, &o)?;
    write_outputs(&d, &run, &args.measured.display().to_string(), &args.out)?;
    Ok(format!(
        "cause: {} | held-out RMSE {:.3} -> {:.3} K | training {:.3} -> {:.3} K | {} model runs, {:.1} s | {}",
        d.cause.name(),
        d.before.heldout_rmse_k,
        d.after.heldout_rmse_k,
        d.before.train_rmse_k,
        d.after.train_rmse_k,
        d.sims,
        t.elapsed().as_secs_f64(),
        args.out.join("report.md").display()
    ))
}
