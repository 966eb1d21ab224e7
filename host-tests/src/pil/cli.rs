//! `eha-sim pil`: the PIL demo (README's main job).

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Context, Result};

use crate::plant::Plant;
use crate::rig::Rig;
use crate::scenario::Scenario;

use super::report::{self, Summary};
use super::sil::SilTarget;
use super::{build_firmware, replay, run_pil, Build, LoopOptions, QemuOptions};

/// Arguments of the `pil` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct PilArgs {
    /// Scenario: `lng` (Fig. 15, Case 1 at 60 bar with the LNG exchanger),
    /// `case2` (26.4 °C, 20 mm 0.2 Hz sine) or `case1` (with --needle-bar).
    #[arg(long, default_value = "lng")]
    pub scenario: String,
    /// Needle-valve pressure for `case1`, bar.
    #[arg(long, default_value_t = 60.0)]
    pub needle_bar: f64,
    /// Plant time to run, s.
    #[arg(long, default_value_t = 600.0)]
    pub duration: f64,
    /// Firmware build: `f32` (Cortex-M4F, mps2-an386) or `fixed` (Cortex-M3, mps2-an385).
    #[arg(long, default_value = "f32")]
    pub build: String,
    /// Use this ELF instead of building the firmware.
    #[arg(long)]
    pub elf: Option<PathBuf>,
    /// Output directory for CSV, defmt log and transcript.
    #[arg(long, default_value = "out/pil")]
    pub out: PathBuf,
    /// Seconds to wait for one firmware reply before calling it dead.
    #[arg(long, default_value_t = 5.0)]
    pub timeout: f64,
    /// Run QEMU without `-icount` (faster, but no instruction counts).
    #[arg(long)]
    pub no_icount: bool,
    /// Print a table row every this many seconds of plant time.
    #[arg(long, default_value_t = 30.0)]
    pub table_every: f64,
    /// Skip the SIL replay comparison.
    #[arg(long)]
    pub no_sil: bool,
    /// Software in the loop only: the firmware's own code on the host (the
    /// same core and frames as in QEMU) in closed loop with the plant; no
    /// emulator. Writes `sil_<scenario>_<build>.csv`.
    #[arg(long, conflicts_with_all = ["elf", "no_icount", "no_sil"])]
    pub sil: bool,
}

/// Parse the scenario name.
pub fn scenario(name: &str, duration_s: f64, needle_bar: f64) -> Result<Scenario> {
    Ok(match name {
        "lng" | "fig15" => Scenario::Lng { duration_s },
        "case2" => Scenario::Case2 { duration_s },
        "case1" => Scenario::Case1 { needle_bar, duration_s },
        other => bail!("unknown PIL scenario {other:?} (expected lng, case2 or case1)"),
    })
}

/// Run the PIL demo and print its summary.
pub fn run(args: &PilArgs) -> Result<()> {
    let build: Build = args.build.parse()?;
    if args.sil {
        return run_sil(args, build);
    }
    let qemu_version = super::qemu::ensure_qemu()?;
    let scen = scenario(&args.scenario, args.duration, args.needle_bar)?;
    let elf = match &args.elf {
        Some(p) => p.clone(),
        None => {
            eprintln!("building the {} firmware ({}) ...", build.name(), build.target());
            build_firmware(build)?
        }
    };
    let rig = Rig::default();
    let mut plant = Plant::new(&rig, &scen).map_err(|e| anyhow::anyhow!("reference plant: {e}"))?;
    let mut q = QemuOptions::new(build, &elf);
    q.icount = !args.no_icount;
    q.reply_timeout = Duration::from_secs_f64(args.timeout);
    let opts = LoopOptions { tick_s: eha_guard::params::S_PER_TICK, duration_s: args.duration };
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let stem = format!("pil_{}_{}", args.scenario, build.name());
    let csv = args.out.join(format!("{stem}.csv"));
    let log_path = args.out.join(format!("{stem}.defmt.log"));
    let meta = |note: String| {
        vec![
            ("rig", "reference plant eha_sim (Rig::default)".to_string()),
            ("case", args.scenario.clone()),
            ("note", note),
        ]
    };
    eprintln!(
        "running {} s of the {} scenario in lockstep with the firmware in {qemu_version} {} ({} ticks of {} s) ...",
        args.duration,
        args.scenario,
        build.machine(),
        opts.ticks(),
        opts.tick_s
    );
    let run = match run_pil(&mut plant, &q, &opts) {
        Ok(r) => r,
        Err(fail) => {
            // Never lose data: write what was recorded, then report.
            let note = format!("FAILED PIL run ({build:?}): {:#}", fail.error);
            let _ = report::write_csv(&csv, &fail.records, &meta(note));
            let _ = report::write_log(&log_path, &fail.log);
            bail!("{fail}\n(partial results: {} and {})", csv.display(), log_path.display());
        }
    };
    let s = Summary::of(&run.records, run.icount);
    report::write_csv(&csv, &run.records, &meta(format!("PIL {} firmware in QEMU {}, tick {} s", build.name(), build.machine(), opts.tick_s)))?;
    report::write_log(&log_path, &run.log)?;
    let transcript = args.out.join(format!("{stem}.run"));
    std::fs::write(&transcript, report::transcript(&run, args.table_every)).with_context(|| format!("writing {}", transcript.display()))?;

    println!("{}", report::table(&run.records, args.table_every));
    print!("{}", report::summary_text(&run, &s));
    if !args.no_sil {
        let mut sil = SilTarget::new(build);
        let sil_replies = replay(&run.records, &mut sil)?;
        let fw: Vec<_> = run.records.iter().map(|r| r.reply).collect();
        let c = report::compare(&fw, &sil_replies);
        println!(
            "firmware vs host SIL : {}/{} replies bit-identical, max drain diff {:.2e} K, flag mismatches {}",
            c.identical, c.ticks, c.max_drain_diff_k, c.flag_mismatches
        );
    }
    println!("results             : {}, {}, {}", csv.display(), log_path.display(), transcript.display());
    if let Some(png) = super::plot::plot_if_available(&run.records, &args.out.join(format!("{stem}.png")))? {
        println!("plot                : {}", png.display());
    }
    Ok(())
}

/// `pil --sil`: the closed loop with the host SIL core.
fn run_sil(args: &PilArgs, build: Build) -> Result<()> {
    let scen = scenario(&args.scenario, args.duration, args.needle_bar)?;
    let mut plant = Plant::new(&Rig::default(), &scen).map_err(|e| anyhow::anyhow!("reference plant: {e}"))?;
    let opts = LoopOptions { tick_s: eha_guard::params::S_PER_TICK, duration_s: args.duration };
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let csv = args.out.join(format!("sil_{}_{}.csv", args.scenario, build.name()));
    let mut target = SilTarget::new(build);
    let meta = |note: String| vec![("rig", "reference plant eha_sim (Rig::default)".to_string()), ("case", args.scenario.clone()), ("note", note)];
    let records = match super::run_closed_loop(&mut plant, &mut target, &opts) {
        Ok(r) => r,
        Err(fail) => {
            let _ = report::write_csv(&csv, &fail.records, &meta(format!("FAILED SIL run ({build:?}): {:#}", fail.error)));
            bail!("{:#}\n(partial results: {})", fail.error, csv.display());
        }
    };
    report::write_csv(&csv, &records, &meta(format!("SIL {} firmware core on the host, tick {} s", build.name(), opts.tick_s)))?;
    println!("{}", report::table(&records, args.table_every));
    println!("results             : {}", csv.display());
    Ok(())
}
