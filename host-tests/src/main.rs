//! `eha-sim`: command line of the reference simulation and its tools.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "eha-sim", version, about = "EHA thermal reference simulation and tools")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Diagnose a measured run: what the model gets wrong, the cause, the gain.
    Diagnose(eha_sim::diagnosis::cli::DiagnoseArgs),
    /// Hidden-effect sweep: synthetic runs with one effect each, diagnosed blind.
    DiagnoseSweep(eha_sim::diagnosis::sweep::SweepArgs),
}

fn main() -> ExitCode {
    match Cli::parse().cmd {
        Cmd::Diagnose(a) => eha_sim::diagnosis::cli::run(&a),
        Cmd::DiagnoseSweep(a) => eha_sim::diagnosis::sweep::run(&a),
    }
}
