//! The campaign: jobs over cases × scenarios × starts, run in parallel,
//! the fast tier's subset, the table, `eha-sim faults` and its files.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use rayon::prelude::*;

use super::inject::{Channel, Fault, InputFault};
use super::{baseline, cases, limits, run_one, scenarios, starts, Baseline, Case, FaultResult, Inputs, ScenarioSpec, Start, StartKind};

/// A run of the campaign: a case, a scenario, a start.
#[derive(Debug, Clone)]
pub struct Job {
    /// The case.
    pub case: Case,
    /// The scenario (index into [`scenarios`]).
    pub scenario: usize,
    /// The start.
    pub start: Start,
}

/// Every run of the campaign: each case in each scenario at each of the
/// scenario's start times (a fault that acts from boot at the early one
/// only). The baselines run first (in parallel).
pub fn jobs(cases: &[Case]) -> Result<(Vec<ScenarioSpec>, Vec<Job>)> {
    let sc = scenarios();
    let base = baselines(&sc)?;
    let mut v = Vec::new();
    for c in cases {
        for (i, (spec, b)) in sc.iter().zip(&base).enumerate() {
            for st in starts(spec, b) {
                if c.fault.from_boot() && st.kind != StartKind::Early {
                    continue;
                }
                v.push(Job { case: *c, scenario: i, start: st });
            }
        }
    }
    Ok((sc, v))
}

/// The fault-free runs of `sc` (in parallel).
pub fn baselines(sc: &[ScenarioSpec]) -> Result<Vec<Baseline>> {
    sc.par_iter().map(baseline).collect()
}

/// Runs `jobs` (in parallel) and marks each failing run's listed limit.
pub fn run_jobs(sc: &[ScenarioSpec], jobs: &[Job]) -> Result<Vec<FaultResult>> {
    let mut rows: Vec<FaultResult> = jobs.par_iter().map(|j| run_one(j.case, &sc[j.scenario], j.start)).collect::<Result<_>>()?;
    for r in rows.iter_mut().filter(|r| !r.pass) {
        r.limit = limits::find(r).map(|l| l.reason.to_string());
    }
    Ok(rows)
}

/// The whole campaign.
pub fn campaign() -> Result<Vec<FaultResult>> {
    let (sc, jobs) = jobs(&cases())?;
    run_jobs(&sc, &jobs)
}

/// The fast tier's subset: one run per kind of fault and per scenario,
/// the hot starts and the new faults first (about 25 runs).
pub fn fast_subset() -> Vec<(Case, &'static str, StartKind)> {
    use StartKind::{Early, Hot, Open};
    let input = |c, f| Case::new(Fault::Input(c, f));
    vec![
        (Case::new(Fault::None), "lng", Early),
        (Case::new(Fault::None), "random-1", Early),
        (Case::new(Fault::None), "hot-60", Early),
        (input(Channel::Current, InputFault::GainHalf), "lng", Open),
        (input(Channel::PressureA, InputFault::StuckZero), "hot-60", Hot),
        (input(Channel::Speed, InputFault::GainHalf), "lng", Open),
        (Case { fault: Fault::Input(Channel::Speed, InputFault::StuckZero), inputs: Inputs::NoElec }, "hot-60", Open),
        (input(Channel::Ambient, InputFault::Drift), "random-1", Early),
        (Case::new(Fault::DropoutBursts), "hot-60", Hot),
        (Case::new(Fault::WarmReset), "hot-60", Hot),
        (Case::new(Fault::TornRecordWrite), "lng", Open),
        (Case::new(Fault::PowerLoss), "hot-60", Hot),
        (Case::new(Fault::ValveStuckClosed), "lng", Early),
        (Case::new(Fault::NoValveFeedback), "lng", Open),
        (Case::new(Fault::FlashReadFail), "lng", Open),
        (Case::new(Fault::FlashWriteFail), "random-1", Early),
        (Case::new(Fault::ClearSpam), "hot-60", Hot),
        (Case::new(Fault::CorruptStartClear), "lng", Open),
        (Case::new(Fault::RefillWhileEmpty), "lng", Early),
        (Case { fault: Fault::LngEmptyPhysical, inputs: Inputs::Supply }, "lng", Open),
    ]
}

/// Runs the [`fast_subset`] (the start times from the baselines).
pub fn fast_campaign() -> Result<Vec<FaultResult>> {
    let sc = scenarios();
    let base = baselines(&sc)?;
    let mut v = Vec::new();
    for (c, name, kind) in fast_subset() {
        let i = sc.iter().position(|s| s.name == name).context("scenario")?;
        let st = starts(&sc[i], &base[i]).into_iter().find(|s| s.kind == kind).with_context(|| format!("{name} has no {} start", kind.name()))?;
        v.push(Job { case: c, scenario: i, start: st });
    }
    run_jobs(&sc, &v)
}

/// Markdown table of the results.
pub fn table(rows: &[FaultResult]) -> String {
    let mut s = String::from(
        "| fault | scenario | start | detected after | bits | max under K | max true drain closed °C | pass |\n|---|---|---|---:|---|---:|---:|---|\n",
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} ({:.0} s) | {} | {} | {:.3} | {} | {} |\n",
            r.fault,
            r.scenario,
            r.start,
            r.start_s,
            r.detect_s.map_or("–".into(), |d| format!("{d:.2} s")),
            r.detect_bits.clone().unwrap_or_else(|| "–".into()),
            r.max_under_k,
            r.max_true_drain_closed_c.map_or("–".into(), |c| format!("{c:.2}")),
            match (r.pass, &r.limit) {
                (true, _) => "pass",
                (false, Some(_)) => "limit",
                (false, None) => "**FAIL**",
            }
        ));
    }
    s
}

/// What is wrong with a campaign's rows: failing runs that are not a
/// listed limit.
pub fn unlisted_failures(rows: &[FaultResult]) -> Vec<String> {
    rows.iter()
        .filter(|r| !r.pass && r.limit.is_none())
        .map(|r| {
            format!(
                "{} / {} / {} ({:.0} s) fails: detected {:?} after {:?} s, max under {:.3} K, max true drain with the valve closed {:?} °C",
                r.fault, r.scenario, r.start, r.start_s, r.detect_bits, r.detect_s, r.max_under_k, r.max_true_drain_closed_c
            )
        })
        .collect()
}

/// Arguments of `eha-sim faults`.
#[derive(Debug, Clone, clap::Args)]
pub struct FaultsArgs {
    /// Output directory (faults.json, faults.md).
    #[arg(long, default_value = "out/faults")]
    pub out: PathBuf,
    /// Run the fast tier's subset only.
    #[arg(long)]
    pub fast: bool,
    /// Do not run: write the failure-mode table from this `faults.json`.
    #[arg(long)]
    pub from: Option<PathBuf>,
    /// Where the whole campaign's results are committed (after a run of
    /// the whole campaign, or with `--from`), relative to the workspace
    /// root; `docs/failure-modes.md` is then re-rendered from it.
    #[arg(long, default_value = "docs/data/faults.json")]
    pub data: PathBuf,
}

/// `eha-sim faults`: run the campaign, write `faults.json` and `faults.md`
/// (and, for the whole campaign, the failure-mode table); an error when a
/// run fails that is not a listed design limit.
pub fn run(a: &FaultsArgs) -> Result<()> {
    if let Some(json) = &a.from {
        let text = std::fs::read_to_string(json).with_context(|| format!("reading {}", json.display()))?;
        let rows: Vec<FaultResult> = serde_json::from_str(&text).context("parsing faults.json")?;
        return commit_data(a, &rows);
    }
    let t0 = std::time::Instant::now();
    let rows = if a.fast { fast_campaign()? } else { campaign()? };
    write(&a.out, &rows)?;
    print!("{}", table(&rows));
    if !a.fast {
        commit_data(a, &rows)?;
    }
    let passing = rows.iter().filter(|r| r.pass).count();
    let limited = rows.iter().filter(|r| !r.pass && r.limit.is_some()).count();
    println!(
        "{passing} of {} runs pass, {limited} are listed design limits ({:.0} s); wrote {}",
        rows.len(),
        t0.elapsed().as_secs_f64(),
        a.out.join("faults.json").display()
    );
    let bad = unlisted_failures(&rows);
    if !bad.is_empty() {
        bail!("{} runs fail that are not listed design limits:\n{}", bad.len(), bad.join("\n"));
    }
    Ok(())
}

/// The whole campaign's rows to `docs/data/faults.json` (or `a.data`);
/// the command line then re-renders the documents from it (`eha-sim docs`).
fn commit_data(a: &FaultsArgs, rows: &[FaultResult]) -> Result<()> {
    let path = crate::pil::firmware::workspace_root().join(&a.data);
    std::fs::write(&path, data_json(rows)?).with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {} ({} runs)", path.display(), rows.len());
    Ok(())
}

/// `rows` as committed in `docs/data/faults.json`: one run per line, every
/// non-integer number rounded to 1e-4 (the table prints two decimals), so
/// a re-run that changes nothing the table shows changes little in git.
pub fn data_json(rows: &[FaultResult]) -> Result<String> {
    fn round(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Number(n) => {
                if let Some(x) = n.as_f64().filter(|x| x.fract() != 0.0) {
                    if let Some(r) = serde_json::Number::from_f64((x * 1e4).round() / 1e4) {
                        *n = r;
                    }
                }
            }
            serde_json::Value::Object(m) => m.values_mut().for_each(round),
            serde_json::Value::Array(a) => a.iter_mut().for_each(round),
            _ => {}
        }
    }
    let mut lines = Vec::with_capacity(rows.len());
    for r in rows {
        let mut v = serde_json::to_value(r)?;
        round(&mut v);
        lines.push(serde_json::to_string(&v)?);
    }
    Ok(format!("[\n{}\n]\n", lines.join(",\n")))
}

/// Write `faults.json` and `faults.md` to `dir`.
pub fn write(dir: &Path, rows: &[FaultResult]) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    std::fs::write(dir.join("faults.json"), serde_json::to_string_pretty(rows)?).context("writing faults.json")?;
    std::fs::write(dir.join("faults.md"), table(rows)).context("writing faults.md")?;
    Ok(())
}
