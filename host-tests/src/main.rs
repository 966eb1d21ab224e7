//! `eha-sim`: command-line front end of the reference simulation and the
//! processor-in-the-loop harness.

use clap::{Parser, Subcommand};

#[derive(Debug, Parser)]
#[command(name = "eha-sim", version, about = "EHA thermal reference simulation and firmware PIL harness")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run the firmware in QEMU in closed loop with the reference plant (PIL).
    Pil(eha_sim::pil::cli::PilArgs),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let res = match &cli.command {
        Command::Pil(a) => eha_sim::pil::cli::run(a),
    };
    match res {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
