//! Command-line subcommands of the reference simulation: `simulate`,
//! `size-lng`, `sweep`, `calibrate` and `rig`.

use crate::calibrate::{calibrate, PAPER, PARAMS};
use crate::cooling::size;
use crate::rig::Rig;
use crate::scenario::{read_mission_csv, Scenario, ValveRule};
use crate::sim::{simulate, simulate_with, SimOptions, SimOutput, Solver};
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Rig selection shared by the subcommands.
#[derive(Debug, Args, Clone)]
pub struct RigArgs {
    /// Rig parameter file (TOML); default: the calibrated paper rig.
    #[arg(long)]
    pub rig: Option<PathBuf>,
    /// Override a parameter, e.g. `--set pump.eta_m=0.3` or `--set ext.sensor_lag=60`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

impl RigArgs {
    /// Load the rig and apply the overrides.
    pub fn load(&self) -> Result<Rig> {
        let mut rig = match &self.rig {
            Some(p) => Rig::from_toml_file(p)?,
            None => Rig::default(),
        };
        for s in &self.set {
            rig.set_override(s)?;
        }
        Ok(rig)
    }
}

/// Paper scenarios.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Case {
    /// Case 1: 500 rpm through the needle valve, 16 °C.
    Case1,
    /// Case 2: closed-loop 20 mm / 0.2 Hz sine against the spring, 26.4 °C.
    Case2,
    /// Fig. 15: Case 1 at 60 bar with the LNG exchanger.
    Lng,
}

/// A paper case with its needle pressure and duration (shared by `simulate` and `sweep`).
#[derive(Debug, Args)]
pub struct CaseArgs {
    /// Paper scenario (`simulate`: ignored with --mission or --replay).
    #[arg(long, value_enum, default_value = "case1")]
    pub scenario: Case,
    /// Needle-valve pressure for Case 1, bar.
    #[arg(long, default_value_t = 60.0)]
    pub needle_bar: f64,
    /// Duration, s.
    #[arg(long, default_value_t = 600.0)]
    pub duration_s: f64,
}

impl Case {
    /// The scenario of this paper case.
    pub fn scenario(self, needle_bar: f64, duration_s: f64) -> Scenario {
        match self {
            Case::Case1 => Scenario::Case1 { needle_bar, duration_s },
            Case::Case2 => Scenario::Case2 { duration_s },
            Case::Lng => Scenario::Lng { duration_s },
        }
    }
}

/// `simulate`: run a scenario, write CSV (+ PNG).
#[derive(Debug, Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    /// Paper case.
    pub case: CaseArgs,
    /// Mission CSV of inputs (`time_s,speed_rpm,needle_bar,position_mm,ambient_c,air_speed_mps`).
    #[arg(long)]
    pub mission: Option<PathBuf>,
    /// Replay the input columns (speed, pressures, current, ambient, position)
    /// of a measured-data file (shared format).
    #[arg(long, conflicts_with = "mission")]
    pub replay: Option<PathBuf>,
    /// Output sample interval, s.
    #[arg(long, default_value_t = 1.0)]
    pub output_interval_s: f64,
    /// Relative tolerance of the solver's error control.
    #[arg(long, default_value_t = crate::plant::RTOL)]
    pub rtol: f64,
    /// Integrator: the BDF reference or the multirate fast path (within
    /// 0.01 K of it on missions; docs/reference-speed.md).
    #[arg(long, value_enum, default_value_t = Solver::Bdf)]
    pub solver: Solver,
    /// Output directory.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    #[command(flatten)]
    /// Rig.
    pub rig: RigArgs,
}

/// The scenario a `simulate` invocation asks for.
pub fn scenario_of(a: &SimulateArgs) -> Result<Scenario> {
    if let Some(m) = &a.mission {
        return Ok(Scenario::Mission(read_mission_csv(m, ValveRule::None)?));
    }
    if let Some(p) = &a.replay {
        let run = crate::measured::MeasuredRun::read_file(p)?;
        let name = p.file_stem().map_or("replay".into(), |s| format!("replay-{}", s.to_string_lossy()));
        return Ok(Scenario::Replay(crate::simulation::replay::replay_inputs(&run, &name)?));
    }
    Ok(a.case.scenario.scenario(a.case.needle_bar, a.case.duration_s))
}

/// Write a run's CSV beside a summary, returning the CSV path.
pub fn write_run(out: &SimOutput, rig: &Rig, dir: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let csv = dir.join(format!("{}.csv", out.name));
    out.write_csv(
        &csv,
        &[
            ("rig", "liu2024 EHA rig (reference simulation)".into()),
            ("case", out.name.clone()),
            ("ambient_c", format!("{:.2}", out.get("ambient_c").and_then(|a| a.first().copied()).unwrap_or(f64::NAN))),
            ("note", format!("eha-sim {} reference model; extensions {:?}", env!("CARGO_PKG_VERSION"), rig.ext)),
        ],
    )
    .with_context(|| format!("writing {}", csv.display()))?;
    Ok(csv)
}

/// Run `simulate`.
pub fn run_simulate(a: &SimulateArgs) -> Result<()> {
    let rig = a.rig.load()?;
    let sc = scenario_of(a)?;
    let t = std::time::Instant::now();
    if !(a.rtol > 0.0 && a.rtol < 1.0) {
        anyhow::bail!("--rtol {} must lie in (0, 1)", a.rtol);
    }
    let opt = SimOptions { output_interval_s: a.output_interval_s, control_interval_s: 0.1 };
    let out = match a.solver {
        Solver::Bdf => crate::sim::simulate_rtol(&rig, &sc, &opt, a.rtol)?,
        Solver::Fast if a.rtol != crate::plant::RTOL => anyhow::bail!("--rtol sets the BDF's tolerance; the fast path has its own (docs/reference-speed.md): use --solver bdf"),
        Solver::Fast => simulate_with(&rig, &sc, &opt, a.solver)?,
    };
    let wall = t.elapsed();
    let csv = write_run(&out, &rig, &a.out)?;
    println!("{}: {:.0} s simulated in {:.1} ms ({} rhs evaluations, {} solver steps)", out.name, sc.duration_s(), wall.as_secs_f64() * 1e3, out.stats.rhs_evals, out.stats.steps);
    for ch in ["t_inlet_c", "t_outlet_c", "t_drain_c", "t_pump_c", "t_motor_c", "t_block_c", "t_ballvalve_c", "t_oil_c"] {
        println!("  {ch:<14} final {:7.2} °C   max {:7.2} °C", out.last(ch).unwrap_or(f64::NAN), out.max(ch).unwrap_or(f64::NAN));
    }
    println!("  total loss at end {:.0} W; LNG used {:.3} kg", out.last("p_total_w").unwrap_or(0.0), out.last("lng_used_kg").unwrap_or(0.0));
    if !out.valve_open_times_s.is_empty() {
        println!("  LNG valve opens at {:?} s, closes at {:?} s", out.valve_open_times_s, out.valve_close_times_s);
    }
    println!("  wrote {}", csv.display());
    let png = csv.with_extension("png");
    plot_run(&out, &png)?;
    println!("  wrote {}", png.display());
    Ok(())
}

/// PNG of a run: the pump ports and drain, the surface points, the losses.
pub fn plot_run(out: &SimOutput, png: &Path) -> Result<()> {
    let series = |names: &[&str]| -> Vec<(String, Vec<(f64, f64)>)> {
        names
            .iter()
            .filter_map(|n| out.get(n).map(|v| (n.to_string(), out.time_s.iter().copied().zip(v.iter().copied()).collect())))
            .collect()
    };
    let panels = [
        crate::plot::Panel { y_label: "oil, °C".into(), series: series(&["t_inlet_c", "t_outlet_c", "t_drain_c", "t_oil_c", "t_loop_oil_c"]) },
        crate::plot::Panel {
            y_label: "surface, °C".into(),
            series: series(&["t_motor_c", "t_pump_c", "t_block_c", "t_ballvalve_c", "t_winding_c", "t_actuator_c"]),
        },
        crate::plot::Panel { y_label: "loss, W".into(), series: series(&["p_cu_w", "p_fe_w", "p_leak_w", "p_mech_w", "p_throttle_w", "p_line_w", "p_total_w"]) },
    ];
    crate::plot::lines(png, &format!("EHA reference simulation: {}", out.name), &panels)
}

/// `size-lng`: LNG charge by eqs. (23)–(25).
#[derive(Debug, Args)]
pub struct SizeLngArgs {
    /// Heat power to absorb, W (paper: 1500). Omit with --from-model.
    #[arg(long)]
    pub power_w: Option<f64>,
    /// Take the power from the model's total loss at the end of Case 1 at this needle pressure, bar.
    #[arg(long)]
    pub from_model_bar: Option<f64>,
    /// Mission time, s (680 s reproduces the paper's 2.3 L at 1.5 kW).
    #[arg(long, default_value_t = 680.0)]
    pub mission_s: f64,
    /// Redundancy factor (paper: 2).
    #[arg(long, default_value_t = 2.0)]
    pub redundancy: f64,
    #[command(flatten)]
    /// Rig.
    pub rig: RigArgs,
}

/// Run `size-lng`.
pub fn run_size_lng(a: &SizeLngArgs) -> Result<()> {
    let rig = a.rig.load()?;
    let p = match (a.power_w, a.from_model_bar) {
        (Some(p), None) => p,
        (None, Some(bar)) => {
            let out = simulate(&rig, &Scenario::Case1 { needle_bar: bar, duration_s: 600.0 }, &SimOptions::default())?;
            out.last("p_total_w").unwrap_or(f64::NAN)
        }
        (None, None) => 1500.0,
        (Some(_), Some(_)) => bail!("give either --power-w or --from-model-bar"),
    };
    if !(p > 0.0 && a.mission_s > 0.0 && a.redundancy >= 1.0) {
        bail!("power ({p} W) and mission time ({} s) must be > 0, redundancy ≥ 1", a.mission_s);
    }
    let s = size(&rig.lng, p, a.mission_s, a.redundancy);
    println!("heat power P_sum        {:10.1} W", p);
    println!("mission time t_m        {:10.1} s", a.mission_s);
    println!("heat sink Q_LNG (23)    {:10.1} kJ", s.heat_j / 1e3);
    println!("LNG per kg (24)         {:10.1} kJ/kg", rig.lng.heat_per_kg() / 1e3);
    println!("LNG mass M_LNG (24)     {:10.3} kg", s.mass_kg);
    println!("LNG volume V_LNG (25)   {:10.3} L", s.volume_m3 * 1e3);
    println!("with redundancy x{:<4}   {:10.3} L = {:.3} kg", a.redundancy, s.volume_with_redundancy_m3 * 1e3, s.mass_with_redundancy_kg);
    println!("configured charge       {:10.3} L = {:.3} kg, lasts {:.0} s at this power", rig.lng.charge_m3 * 1e3, rig.lng.charge_kg(), rig.lng.mission_time_s(p, rig.lng.charge_m3));
    Ok(())
}

/// `sweep`: one parameter over a range, Case 1 (or Case 2) runs in parallel.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// Parameter key, e.g. `pump.eta_m`, or `needle_bar` for the needle pressure.
    #[arg(long)]
    pub param: String,
    /// Values, comma separated (e.g. `0,20,40,60`).
    #[arg(long, value_delimiter = ',', required = true)]
    pub values: Vec<f64>,
    #[command(flatten)]
    /// Paper case.
    pub case: CaseArgs,
    /// Output CSV.
    #[arg(long, default_value = "out/sweep.csv")]
    pub out: PathBuf,
    /// Integrator (default: the multirate fast path, within 0.01 K of the
    /// BDF reference on the paper's cases; `bdf` for the reference itself).
    #[arg(long, value_enum, default_value_t = Solver::Fast)]
    pub solver: Solver,
    #[command(flatten)]
    /// Rig.
    pub rig: RigArgs,
}

/// Run `sweep`.
pub fn run_sweep(a: &SweepArgs) -> Result<()> {
    let base = a.rig.load()?;
    let bar = ProgressBar::new(a.values.len() as u64);
    bar.set_style(ProgressStyle::with_template("{bar:40} {pos}/{len} runs {elapsed}").unwrap_or_else(|_| ProgressStyle::default_bar()));
    let channels = ["t_inlet_c", "t_outlet_c", "t_drain_c", "t_pump_c", "t_motor_c", "t_block_c", "t_ballvalve_c", "t_oil_c", "p_total_w"];
    let rows: Vec<Result<Vec<f64>>> = a
        .values
        .par_iter()
        .map(|&v| {
            let mut rig = base.clone();
            let mut needle = a.case.needle_bar;
            if a.param == "needle_bar" {
                needle = v;
            } else {
                rig.set_override(&format!("{}={v}", a.param))?;
            }
            let sc = a.case.scenario.scenario(needle, a.case.duration_s);
            let out = simulate_with(&rig, &sc, &SimOptions { output_interval_s: 10.0, control_interval_s: 0.1 }, a.solver)?;
            bar.inc(1);
            Ok(std::iter::once(v).chain(channels.iter().map(|c| out.last(c).unwrap_or(f64::NAN))).collect())
        })
        .collect();
    bar.finish_and_clear();
    if let Some(dir) = a.out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut w = csv::Writer::from_path(&a.out).with_context(|| format!("writing {}", a.out.display()))?;
    let mut header = vec![a.param.clone()];
    header.extend(channels.iter().map(|c| c.to_string()));
    w.write_record(&header)?;
    println!("{}", header.join("  "));
    for r in rows {
        let r = r?;
        w.write_record(r.iter().map(|x| format!("{x:.4}")))?;
        println!("{}", r.iter().map(|x| format!("{x:8.2}")).collect::<Vec<_>>().join("  "));
    }
    w.flush()?;
    println!("wrote {}", a.out.display());
    Ok(())
}

/// `calibrate`: refit the calibrated parameters to the paper's numbers.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    #[command(flatten)]
    /// Starting rig.
    pub rig: RigArgs,
}

/// Run `calibrate`.
pub fn run_calibrate(a: &CalibrateArgs) -> Result<()> {
    let rig = a.rig.load()?;
    let c = calibrate(&rig, &PAPER)?;
    println!("target  {:?}", PAPER);
    println!("before  {:?}", c.before);
    println!("after   {:?}", c.after);
    println!("stage 1 (Table 4 and the 110 s opening, residuals / sigma {:?}):", crate::calibrate::SIGMA);
    for ((n, v), (lo, hi)) in c.values.iter().zip(&c.ident.intervals) {
        println!("  {n} = {v:.6e}   (95 % approx. {lo:.4e} .. {hi:.4e})");
    }
    println!("  singular values of the scaled Jacobian: {:?}", c.ident.singular_values);
    for (n, row) in PARAMS.iter().zip(&c.ident.correlation) {
        println!("  correlation {n}: {:?}", row.iter().map(|x| (x * 1000.0).round() / 1000.0).collect::<Vec<_>>());
    }
    println!("stage 2 (Table 5 shell at {} m/s): outside.pump_ram_exposure = {:.6}", crate::calibrate::RAM_FIT_MPS, c.pump_ram_exposure);
    Ok(())
}

/// Print the default rig as TOML (a starting point for a rig file).
pub fn run_rig() -> Result<()> {
    print!("{}", Rig::default().to_toml());
    Ok(())
}
