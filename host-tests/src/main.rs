//! `eha-sim`: command line of the reference simulation and its tools.

use clap::{Parser, Subcommand};
use eha_sim::cli;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "eha-sim", version, about = "EHA thermal reference simulation (Liu et al.) and tools")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Simulate a paper case or a mission; write CSV (shared format + internal channels).
    Simulate(cli::SimulateArgs),
    /// Size the LNG charge by eqs. (23)-(25).
    SizeLng(cli::SizeLngArgs),
    /// Sweep one parameter over values, runs in parallel.
    Sweep(cli::SweepArgs),
    /// Refit the calibrated parameters to Table 4, Table 5 and Fig. 15.
    Calibrate(cli::CalibrateArgs),
    /// Print the default (calibrated paper) rig as TOML.
    Rig,
    /// Run the firmware in QEMU in closed loop with the reference plant (processor in the loop).
    Pil(eha_sim::pil::cli::PilArgs),
    /// Diagnose a measured run: what the model gets wrong, the cause, the gain.
    Diagnose(eha_sim::diagnosis::cli::DiagnoseArgs),
    /// Hidden-effect sweep: synthetic runs with one effect each, diagnosed blind.
    DiagnoseSweep(eha_sim::diagnosis::sweep::SweepArgs),
    /// Emulator sweep: logs of the independent rig emulator with one hidden
    /// effect each (or none), diagnosed blind; writes a Markdown/JSON table.
    EmulatorSweep(eha_sim::diagnosis::emu_sweep::EmuSweepArgs),
    /// Firmware budgets: instructions per tick, stack, flash, RAM of every
    /// image (QEMU -icount), written to out/fw-budget.json and checked
    /// against .ci/fw-budget.json (fails on > 10 % over a budget).
    FwBudget(eha_sim::pil::budget::BudgetArgs),
    /// Fault campaign: every sensor, transport, memory and actuator fault in
    /// closed loop with the reference plant; writes out/faults/faults.json.
    Faults(eha_sim::faults::FaultsArgs),
    /// Firmware parameter blocks (firmware-params.bin): write one from a rig
    /// file, or run the firmware's boot checks on one.
    ParamsBlock(eha_sim::params_block::ParamsBlockArgs),
    /// Uncertainty bands: Case 1 over Latin-hypercube samples of the rig's
    /// [[uncertain]] parameters (in parallel); 5/50/95 % bands of every channel
    /// (CSV, PNG) and the paper's numbers against their 90 % bands.
    Uq(eha_sim::uq::UqArgs),
    /// Commissioning: calibrate the reference model to your rig's logs,
    /// validate on held-out logs, reduce to firmware parameters and check
    /// them (rig.toml, params.rs, firmware-params.bin, report.md, PNGs);
    /// `--check firmware-params.bin` runs the firmware's boot checks.
    Commission(eha_sim::calibration::cli::CommissionArgs),
    /// Test plan: a bench mission (mission.csv) that makes the leading
    /// candidates of a log showable against its structure floor, with the
    /// expected imprint ratio per candidate.
    Plan(eha_sim::diagnosis::plan_cli::PlanArgs),
    /// Re-render the generated tables in docs/ from their committed JSON
    /// (`--check`: fail on a difference instead; CI runs it).
    Docs(eha_sim::gendoc::DocsArgs),
}

fn main() -> ExitCode {
    let res = match Cli::parse().cmd {
        Cmd::Simulate(a) => cli::run_simulate(&a),
        Cmd::SizeLng(a) => cli::run_size_lng(&a),
        Cmd::Sweep(a) => cli::run_sweep(&a),
        Cmd::Calibrate(a) => cli::run_calibrate(&a),
        Cmd::Rig => cli::run_rig(),
        Cmd::Pil(a) => eha_sim::pil::cli::run(&a),
        Cmd::FwBudget(a) => eha_sim::pil::budget::run(&a),
        Cmd::Faults(a) => {
            let res = eha_sim::faults::run(&a);
            // the whole campaign (or --from) committed its data: the docs follow it
            let docs = if a.fast { Ok(()) } else { eha_sim::gendoc::run_cli(&eha_sim::gendoc::DocsArgs { check: false }) };
            res.and(docs)
        }
        Cmd::ParamsBlock(a) => eha_sim::params_block::run(&a),
        Cmd::Uq(a) => eha_sim::uq::run_cli(&a),
        Cmd::Docs(a) => eha_sim::gendoc::run_cli(&a),
        Cmd::Plan(a) => eha_sim::diagnosis::plan_cli::run(&a),
        // Own exit codes: 0 diagnosis made (none included), 2 bad input.
        Cmd::Diagnose(a) => return eha_sim::diagnosis::cli::run(&a),
        Cmd::DiagnoseSweep(a) => return eha_sim::diagnosis::sweep::run(&a),
        Cmd::EmulatorSweep(a) => return eha_sim::diagnosis::emu_sweep::run(&a),
        // Own exit codes: 0 commissioned, 1 reduced-model check failed, 2 bad input.
        Cmd::Commission(a) => return eha_sim::calibration::cli::run(&a),
    };
    match res {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
