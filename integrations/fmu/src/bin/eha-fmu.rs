//! `cargo fmu [--out DIR]`: packs `EhaPlant.fmu` and `EhaGuard.fmu` (FMI 2.0
//! co-simulation, linux64) from the shared library built beside this binary.

use anyhow::{bail, Context, Result};
use clap::Parser;
use eha_fmu::description::write_fmu;
use eha_fmu::{guard::GuardFmu, plant::PlantFmu};
use std::path::PathBuf;

/// Pack the plant and guard FMUs.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Args {
    /// Output directory.
    #[arg(long, default_value = "out/fmu")]
    out: PathBuf,
}

fn main() -> Result<()> {
    let a = Args::parse();
    let exe = std::env::current_exe().context("locating eha-fmu")?;
    let dir = exe.parent().context("eha-fmu has no parent directory")?;
    let lib = dir.join("libeha_fmu.so");
    if !lib.exists() {
        bail!("{} not found: build the library with the binary (`cargo fmu` does both)", lib.display());
    }
    // Case 1's 600 s in 1 s steps; the guard's Fig. 15 run in 10 ms ticks.
    let p = write_fmu::<PlantFmu>(&a.out, &lib, 600.0, 1.0)?;
    println!("wrote {}", p.display());
    let g = write_fmu::<GuardFmu>(&a.out, &lib, 600.0, 0.01)?;
    println!("wrote {}", g.display());
    Ok(())
}
