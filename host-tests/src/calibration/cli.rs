//! `eha-sim commission`: from a team's rig logs to firmware parameters for
//! their EHA. Writes `rig.toml`, `params.rs`, `firmware-params.bin`
//! (only when the reduced model holds), `report.md` and `holdout-*.png` into
//! `--out`; `--check firmware-params.bin` runs the firmware's boot checks; exit 0 when the reduced model meets the
//! 0.2 K bound on every log, 1 when it does not (the report says why), 2 on
//! bad input (file:line:column from the measured-data reader).

use super::commission::{commission, Commissioning, TrainingSpread, REDUCED_BOUND_K};
use super::fit::{CalOptions, Status};
use super::log::CalLog;
use crate::measured::{Channel, MeasuredRun};
use crate::plot::{lines, Panel};
use crate::rig::Rig;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `commission`.
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "Bench procedure, how to read the report and the parameter set: docs/commissioning.md")]
pub struct CommissionArgs {
    /// Run the firmware's boot checks on a parameter block (magic, version,
    /// CRC, value ranges, stability of the discretisation) and exit: 0 if the
    /// firmware accepts it, 1 with the reason if it would latch CONFIG.
    #[arg(long, value_name = "FIRMWARE_PARAMS_BIN", conflicts_with_all = ["rig", "train", "holdout"])]
    pub check: Option<PathBuf>,
    /// Your rig's parameter file (TOML, `eha-sim rig` writes the paper rig's
    /// as a template): geometry, masses and areas as built. The calibration
    /// starts from it and is regularised towards it.
    #[arg(long, required_unless_present = "check")]
    pub rig: Option<PathBuf>,
    /// Training logs (shared measured-data format; a `t_drain_c` column, if
    /// logged, is fitted too). Use several missions of different kinds.
    #[arg(long, num_args = 1.., required_unless_present = "check")]
    pub train: Vec<PathBuf>,
    /// Held-out logs: scored, never fitted (a different kind of mission).
    #[arg(long, num_args = 1.., required_unless_present = "check")]
    pub holdout: Vec<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "commission-out")]
    pub out: PathBuf,
    /// A model extension named by `diagnose`, switched on at the value it
    /// fitted, as `rig-extension-field=value` (e.g. `sensor_lag=120`,
    /// `motor_pump_conduction=4`; the fields of `[ext]` in the rig file).
    /// Held fixed during the calibration (not fitted jointly yet).
    #[arg(long = "with", value_name = "EXT=VALUE")]
    pub with: Vec<String>,
    /// Data σ in K: residuals are weighed against the prior with it.
    #[arg(long, default_value_t = 0.2)]
    pub sigma_data_k: f64,
    /// Fit points per channel and log.
    #[arg(long, default_value_t = 120)]
    pub points_per_channel: usize,
    /// Budget of residual evaluations of the fit.
    #[arg(long, default_value_t = 600)]
    pub max_evals: usize,
    /// Also fit the oil probe's response time (`probe_oil`, 0.5–10 s),
    /// held at the rig file otherwise: use it when the oil channel visibly
    /// lags a step that the other channels follow (docs/commissioning.md).
    #[arg(long)]
    pub fit_oil_probe: bool,
    /// Write `firmware-params.bin` even when commissioning refuses it, with
    /// the drain margin from the validation on a split of the training
    /// missions (needs `t_drain_c` in every training log); the report states
    /// the margin and its cost.
    #[arg(long)]
    pub accept_with_margin: bool,
}

impl CommissionArgs {
    /// The rig file (clap requires it unless `--check` is given).
    fn rig_path(&self) -> &Path {
        self.rig.as_deref().unwrap_or(Path::new(""))
    }
}

/// Runs `commission`; see the module doc for the exit codes.
pub fn run(args: &CommissionArgs) -> ExitCode {
    if let Some(file) = &args.check {
        let res = crate::params_block::read_block(file).and_then(|b| crate::params_block::check_bytes(&b));
        return match res {
            Ok(r) => {
                println!("{}: {r}", file.display());
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {}: the firmware would refuse this block (CONFIG fault): {e:#}", file.display());
                ExitCode::FAILURE
            }
        };
    }
    let inputs = match load(args) {
        Ok(x) => x,
        Err(e) => {
            eprintln!("error: {e:#}");
            return ExitCode::from(2);
        }
    };
    let t = std::time::Instant::now();
    let mut o = CalOptions { sigma_data_k: args.sigma_data_k, points_per_channel: args.points_per_channel, max_evals: args.max_evals, ..Default::default() };
    if args.fit_oil_probe {
        o.hold.retain(|(name, _)| *name != super::set::PROBE_OIL);
    }
    let res = commission(&inputs.0, &inputs.1, &inputs.2, &o).map_err(anyhow::Error::from).and_then(|c| {
        write_outputs(args, &inputs.0, &inputs.2, &c)?;
        Ok(c)
    });
    match res {
        Ok(c) => {
            for w in &c.cal.warnings {
                eprintln!("{w}");
            }
            for l in super::envelope_report::not_validated_lines(&c) {
                eprintln!("note: {l}");
            }
            println!("{} | {:.1} s | {}", headline(&c), t.elapsed().as_secs_f64(), args.out.join("report.md").display());
            if c.flashable() {
                ExitCode::SUCCESS
            } else if accepted(args, &c) {
                eprintln!("warning: refused ({}); firmware-params.bin written as asked (--accept-with-margin); the block carries the drain margin {:.2} K", reduced_failure(&c), c.params.drain_margin_k);
                ExitCode::SUCCESS
            } else {
                eprintln!("error: {}", reduced_failure(&c));
                ExitCode::FAILURE
            }
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

type Inputs = (Rig, Vec<CalLog>, Vec<CalLog>);

fn load(args: &CommissionArgs) -> anyhow::Result<Inputs> {
    let mut rig = Rig::from_toml_file(args.rig_path())?;
    for w in &args.with {
        rig.set_override(&format!("ext.{w}"))?;
    }
    let read = |p: &PathBuf| -> anyhow::Result<CalLog> {
        let run = MeasuredRun::read_file(p)?;
        for n in &run.notes {
            eprintln!("note: {n}");
        }
        let name = p.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| p.display().to_string());
        CalLog::new(&name, run, args.points_per_channel).map_err(anyhow::Error::msg)
    };
    let train = args.train.iter().map(read).collect::<anyhow::Result<_>>()?;
    let hold = args.holdout.iter().map(read).collect::<anyhow::Result<_>>()?;
    Ok((rig, train, hold))
}

fn headline(c: &Commissioning) -> String {
    let h: Vec<String> = c
        .holdout_with_margin
        .iter()
        .filter_map(|r| Some(format!("{}: firmware drain max |e| {:.2} K, under {:.2} K vs measured", r.log, r.vs_measured_max_k?, r.vs_measured_under_k?)))
        .collect();
    let mut m = c.margin.as_ref().map_or("no margin (needs t_drain_c in every training log)".to_string(), |m| format!("margin {:.2} K", m.margin_k));
    if let Some(t) = TrainingSpread::of(&c.train_chosen) {
        m += &format!(" (no margin brings max |e| below {:.2} K even on the training logs)", t.floor_k());
    }
    if h.is_empty() { "held-out logs carry no t_drain_c: no firmware drain accuracy".into() } else { format!("{m}; {}", h.join("; ")) }
}

/// Whether a refused block is written anyway: asked for, with a validated margin.
fn accepted(args: &CommissionArgs, c: &Commissioning) -> bool {
    args.accept_with_margin && c.margin.is_some()
}

fn reduced_failure(c: &Commissioning) -> String {
    match c.refusal() {
        Some(r) => format!("{r}; params.rs is written but must not be flashed unless accepted with the margin (--accept-with-margin)"),
        None => "flashable".into(),
    }
}

/// Writes rig.toml, params.rs, report.md and the held-out PNGs.
fn write_outputs(args: &CommissionArgs, base: &Rig, hold: &[CalLog], c: &Commissioning) -> anyhow::Result<()> {
    std::fs::create_dir_all(&args.out)?;
    std::fs::write(args.out.join("rig.toml"), c.cal.rig.to_toml())?;
    std::fs::write(args.out.join("params.rs"), crate::reduce::render_params_rs(&c.params))?;
    // The flash parameter block, only when the reduced model holds the
    // commissioned machine (else the report says why and nothing flashable is
    // written).
    let bin = args.out.join("firmware-params.bin");
    if c.flashable() || accepted(args, c) {
        let id = args.rig_path().file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        std::fs::write(&bin, crate::params_block::block_for(&c.params, &id)?)?;
    } else if bin.exists() {
        std::fs::remove_file(&bin)?;
    }
    std::fs::write(args.out.join("report.md"), report(args, c))?;
    for l in hold {
        plot_log(&args.out, base, c, l)?;
    }
    Ok(())
}

fn plot_log(dir: &Path, base: &Rig, c: &Commissioning, l: &CalLog) -> anyhow::Result<()> {
    let a = l.simulate(base).map_err(anyhow::Error::msg)?;
    let b = l.simulate(&c.cal.rig).map_err(anyhow::Error::msg)?;
    let t = &l.run.time_s;
    let panels: Vec<Panel> = l
        .channels
        .iter()
        .map(|&ch| {
            let m: Vec<(f64, f64)> = l.run.get(ch).unwrap_or(&[]).iter().zip(t).filter_map(|(v, &t)| Some((t, (*v)?))).collect();
            let s = |v: &Vec<f64>| t.iter().copied().zip(v.iter().copied()).collect::<Vec<_>>();
            Panel {
                y_label: format!("{}, °C", ch.name()),
                series: vec![("measured".into(), m), ("rig as given".into(), s(&a[&ch])), ("commissioned".into(), s(&b[&ch]))],
            }
        })
        .collect();
    let stem = l.name.trim_end_matches(".csv");
    lines(&dir.join(format!("holdout-{stem}.png")), &format!("held out: {}", l.name), &panels)
}

/// The two paths (reduction, direct identification): which was flashed
/// and why, and both paths' numbers after the split and on the held-out logs.
fn paths_section(s: &mut String, c: &Commissioning) {
    let _ = writeln!(s, "## Path: {}\n\nChosen because {}. (The held-out logs decide between two blocks, each fitted without them.)\n", c.choice.chosen.name(), c.choice.why);
    let f = |x: Option<f64>| x.map_or("–".into(), |v| format!("{v:.3}"));
    let _ = writeln!(s, "| path | margin K | on the folds' scored parts, margin counted: max \\|e\\| K | held out, margin counted: worst max \\|e\\| K | worst under K |\n|---|---:|---:|---:|---:|");
    for p in std::iter::once(&c.reduction_path).chain(c.direct_path.as_ref().ok()) {
        let w = p.holdout_worst();
        let _ = writeln!(s, "| {} | {} | {} | {} | {} |", p.kind.name(), f(p.margin_k()), f(p.validation_max_k()), f(w.map(|w| w.0)), f(w.map(|w| w.1)));
    }
    if let Err(e) = &c.direct_path {
        let _ = writeln!(s, "\nThe direct path did not run: {e}.");
    }
    if let Some(d) = &c.direct_fit {
        let _ = writeln!(s, "\nDirect identification (fitted, not a validation): χ² {:.0} → {:.0} over {} points, {} model runs; multipliers on the reduction: {}.", d.chi2_before_after.0, d.chi2_before_after.1, d.n_points, d.model_runs,
            d.results.iter().filter(|r| r.held.is_none()).map(|r| format!("`{}` {:.3}{}", r.name, r.value, if r.at_bound { " (on a bound)" } else { "" })).collect::<Vec<_>>().join(", "));
    }
    let _ = writeln!(s);
}

/// The drain margin: how it was validated, what it costs on the held-out
/// logs, and which bench run would shrink it.
fn margin_section(s: &mut String, c: &Commissioning) {
    let _ = writeln!(s, "## Drain margin (validation on a split of the training missions)\n");
    let Some(m) = &c.margin else {
        let _ = writeln!(s, "Not computed: it needs `t_drain_c` in every training log and a validation fit the firmware model accepts.\n");
        return;
    };
    let pct = 100.0 * super::commission::SPLIT_FRACTION;
    let _ = writeln!(s, "Fitted on the first {pct:.0} % of every training log (the chosen path) and scored on the rest; and (rows marked {}) fitted on the last {pct:.0} % and scored on the log's start (its cold start):\n\n| training log | firmware on the scored part: max \\|e\\| K | under K | where the under-prediction is largest |\n|---|---:|---:|---|", super::commission::HEAD_FOLD_TAG);
    let f = |x: Option<f64>| x.map_or("–".into(), |v| format!("{v:.3}"));
    for r in &m.folds {
        let _ = writeln!(s, "| {} | {} | {} | {} |", r.log, f(r.vs_measured_max_k), f(r.vs_measured_under_k), r.vs_measured_region.as_ref().map_or("–".into(), |g| g.to_string()));
    }
    let _ = writeln!(s, "\nMargin **{:.2} K** = largest under-prediction {:.2} K + allowance {:.2} K (twice the thermocouple noise σ).\n", m.margin_k, m.margin_k - m.allowance_k, m.allowance_k);
    let held = c.holdout_without_margin();
    let _ = writeln!(s, "Cost on the held-out logs (the guard's valve on the estimate, open loop):\n\n| log | valve open s, no margin | with margin | LNG kg, no margin | with margin |\n|---|---:|---:|---:|---:|");
    for (a, b) in held.iter().zip(&c.holdout_with_margin) {
        let _ = writeln!(s, "| {} | {:.0} | {:.0} | {:.3} | {:.3} |", a.log, a.valve_open_s, b.valve_open_s, a.lng_kg, b.lng_kg);
    }
    if let Some(g) = m.worst().and_then(|w| w.vs_measured_region.as_ref()) {
        let _ = writeln!(s, "\nTo shrink it: {}.\n", g.bench_run());
    }
}

/// The flashed block on the logs it was commissioned on, and the floor
/// that spread puts under any constant margin ([`TrainingSpread`]).
fn training_section(s: &mut String, c: &Commissioning) {
    let _ = writeln!(s, "## The firmware on its own training logs (in-sample, no margin)\n\n| training log | under K | over K | RMSE K |\n|---|---:|---:|---:|");
    let f = |x: Option<f64>| x.map_or("–".into(), |v| format!("{v:.3}"));
    for r in &c.train_chosen {
        let _ = writeln!(s, "| {} | {} | {} | {} |", r.log, f(r.vs_measured_under_k), f(r.vs_measured_over_k), f(r.vs_measured_rmse_k));
    }
    match TrainingSpread::of(&c.train_chosen) {
        Some(t) => {
            let _ = writeln!(s, "\nNo constant margin brings the firmware's max |e| on these logs below **{:.2} K** (half of the {:.2} K between its largest under- and over-prediction; a margin of {:+.2} K would reach it), and none does better on logs the model has not seen: below that the model itself has to follow the drain more closely (a structure, not a margin; docs/commissioning-foreign.md).\n", t.floor_k(), t.under_k + t.over_k, t.centring_margin_k());
        }
        None => {
            let _ = writeln!(s, "\nNo floor follows: the error does not take both signs on the training logs (or they carry no `t_drain_c`).\n");
        }
    }
}

fn report(args: &CommissionArgs, c: &Commissioning) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Commissioning report\n\nRig file: `{}`; training: {}; held out: {}.\n", args.rig_path().display(),
        args.train.iter().map(|p| format!("`{}`", p.display())).collect::<Vec<_>>().join(", "),
        args.holdout.iter().map(|p| format!("`{}`", p.display())).collect::<Vec<_>>().join(", "));
    match c.eta_m_from_current {
        Some((eta, n)) => {
            let _ = writeln!(s, "Pump friction `eta_m` (eq. 8) = {eta:.4} from the electrical balance of {n} loaded samples (shaft power from the current minus the hydraulic power), held in the thermal fit: the firmware's sensor cross-check then agrees with this machine.\n");
        }
        None => {
            let why = c.eta_m_balance.refusal().unwrap_or_else(|| "not taken from the current".into());
            let _ = writeln!(s, "**Pump friction `eta_m` from the temperatures only** ({why}): the firmware's sensor cross-check may disagree with this machine and latch SENSOR_DISAGREE (fail-safe). Log `current_a` under a load that varies (e.g. the needle steps at speed).\n");
        }
    }
    let _ = writeln!(s, "## Headline: firmware drain accuracy on the held-out logs\n");
    let _ = writeln!(s, "| log | commissioned firmware: max \\|e\\| K | under K | RMSE K | paper-default firmware: max \\|e\\| K | under K |\n|---|---:|---:|---:|---:|---:|");
    let held = &c.holdout_with_margin;
    for (r, d) in held.iter().zip(&c.default_on_holdout) {
        let f = |x: Option<f64>| x.map_or("–".into(), |v| format!("{v:.3}"));
        let _ = writeln!(s, "| {} | {} | {} | {} | {} | {} |", r.log, f(r.vs_measured_max_k), f(r.vs_measured_under_k), f(r.vs_measured_rmse_k), f(d.vs_measured_max_k), f(d.vs_measured_under_k));
    }
    let _ = writeln!(s, "\n(Against the measured `t_drain_c`, which carries the thermocouple's noise; open loop: the logged LNG valve, if any, drives the exchanger; the commissioned firmware with the drain margin below added. Held-out logs without `t_drain_c` show –.)\n");
    paths_section(&mut s, c);
    margin_section(&mut s, c);
    training_section(&mut s, c);
    super::envelope_report::envelope_section(&mut s, c);
    if !c.cal.warnings.is_empty() {
        let _ = writeln!(s, "## Warnings\n");
        for w in &c.cal.warnings {
            let _ = writeln!(s, "- {w}");
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(s, "## Reduced firmware model vs commissioned reference (every log's inputs, bound {REDUCED_BOUND_K} K)\n\n| log | drain max \\|e\\| K | verdict |\n|---|---:|---|");
    for r in &c.reduced {
        let _ = writeln!(s, "| {} | {:.3} | {} |", r.log, r.vs_reference_max_k, if r.vs_reference_max_k <= REDUCED_BOUND_K { "ok" } else { "**exceeds**" });
    }
    if !c.flashable() {
        let _ = writeln!(s, "\n**REFUSED:** {}\n", reduced_failure(c));
        if accepted(args, c) {
            let _ = writeln!(s, "`firmware-params.bin` written as asked (`--accept-with-margin`); the block carries the drain margin {:.2} K (`drain_margin_k`), which the guard adds to its drain estimate.\n", c.params.drain_margin_k);
        }
    }
    let _ = writeln!(s, "\n## Held-out validation of the reference model\n\n| log | channel | RMSE as given K | RMSE commissioned K | max as given K | max commissioned K |\n|---|---|---:|---:|---:|---:|");
    for h in &c.holdout {
        for (a, b) in h.as_given.iter().zip(&h.commissioned) {
            let _ = writeln!(s, "| {} | {} | {:.3} | {:.3} | {:.3} | {:.3} |", h.log, a.channel, a.rmse_k, b.rmse_k, a.max_abs_k, b.max_abs_k);
        }
    }
    let (c0, c1) = c.cal.chi2_before_after;
    let _ = writeln!(s, "\n## Calibration (fitted on the training logs — not a validation)\n\nχ² (residuals / σ_d) {c0:.0} → {c1:.0} over {} points, {} model runs.\n", c.cal.n_points, c.cal.model_runs);
    let _ = writeln!(s, "| parameter | multiplier | ≈95 % interval | status |\n|---|---:|---|---|");
    for p in &c.cal.params {
        let st = match &p.status {
            Status::Fitted if p.at_bound => "fitted, **on a bound**".to_string(),
            Status::Fitted => "fitted".to_string(),
            Status::Held(why) => format!("held: {why}"),
        };
        let _ = writeln!(s, "| `{}` | {:.3} | {:.3}–{:.3} | {} |", p.name, p.value, p.interval95.0, p.interval95.1, st);
    }
    let id = &c.cal.ident;
    let _ = writeln!(s, "\nSingular values of the scaled Jacobian: {}.\n", id.singular_values.iter().map(|v| format!("{v:.3e}")).collect::<Vec<_>>().join(", "));
    if !id.correlated.is_empty() {
        let _ = writeln!(s, "Strongly correlated pairs (|ρ| ≥ 0.9; only their combination is determined):\n");
        for (a, b, r) in &id.correlated {
            let _ = writeln!(s, "- `{a}` – `{b}`: ρ = {r:+.3}");
        }
    }
    let _ = writeln!(s, "\nParameter → rig fields: `eha_sim::calibration::set::PARAMS`. Plots: `holdout-*.png`. Channels: {}.", Channel::TEMPERATURES.iter().map(|c| c.name()).collect::<Vec<_>>().join(", ") + ", t_drain_c when logged");
    s
}
