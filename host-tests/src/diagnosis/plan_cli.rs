//! The `plan` subcommand: `eha-sim plan --log LOG [--rig R] [--candidates
//! name[=magnitude],…] [--diagnosis diagnosis.json] --out DIR` writes
//! mission.csv, plan.md and plan.json ([`super::plan`]).

use super::model::{Candidate, Simulator};
use super::plan::{leading, plan, Decision, Limits, DEFAULT_AIR_MPS, DEFAULT_MAX_TEMP_C};
use super::reference::ReferenceModel;
use crate::measured::MeasuredRun;
use crate::rig::Rig;

/// (cause, probability, ln Bayes factor) of every structure in a
/// `diagnosis.json` file.
pub fn read_probabilities(path: &std::path::Path) -> anyhow::Result<Vec<(String, f64, f64)>> {
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path)?).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let list = v.get("probabilities").and_then(|p| p.as_array()).ok_or_else(|| anyhow::anyhow!("{}: no `probabilities` array", path.display()))?;
    list.iter()
        .map(|e| {
            let cause = e.get("cause").and_then(|c| c.as_str()).ok_or_else(|| anyhow::anyhow!("{}: a probability without `cause`", path.display()))?;
            let num = |k: &str| e.get(k).and_then(|x| x.as_f64()).unwrap_or(f64::NEG_INFINITY);
            Ok((cause.to_string(), num("probability"), num("log_bayes_factor")))
        })
        .collect()
}

/// Arguments of `plan`.
#[derive(Debug, Clone, clap::Args)]
pub struct PlanArgs {
    /// Rig parameter file (TOML); default: the built-in paper rig.
    #[arg(long)]
    pub rig: Option<std::path::PathBuf>,
    /// The user's measured log (shared measured-data format).
    #[arg(long)]
    pub log: std::path::PathBuf,
    /// Leading candidates, `name` or `name=magnitude` (the parameter's unit),
    /// comma-separated; default: the two leading ones of `--diagnosis` (all
    /// when it admitted none, `plan::leading`), else every candidate a
    /// throttle run can excite; without `=magnitude`, at the model's fit
    /// start of each (30 s lag, 1 W/K flange path, 3 m/s draught, …: at or
    /// below the low end of the physical range the diagnosis calls typical;
    /// docs/test-plans.md says what planning for the middle did).
    #[arg(long, value_delimiter = ',')]
    pub candidates: Vec<String>,
    /// `diagnosis.json` of the log (`eha-sim diagnose`): its two leading
    /// candidates are planned for when `--candidates` is not given.
    #[arg(long)]
    pub diagnosis: Option<std::path::PathBuf>,
    /// Output directory for mission.csv, plan.md and plan.json.
    #[arg(long, default_value = "plan-out")]
    pub out: std::path::PathBuf,
    /// Duration of the planned run, s (default: the log's, at least 1200 s).
    #[arg(long)]
    pub duration_s: Option<f64>,
    /// Shaft speed range, rpm (`lo,hi`; default 500 to 2000 within the rig's limit).
    #[arg(long, value_delimiter = ',')]
    pub speed_rpm: Option<Vec<f64>>,
    /// Needle drop range at the running speed, bar (`lo,hi`; default 10 to
    /// 100 within half the relief pressure).
    #[arg(long, value_delimiter = ',')]
    pub drop_bar: Option<Vec<f64>>,
    /// Largest ram air, m/s (used only when the log logs ram air).
    #[arg(long, default_value_t = DEFAULT_AIR_MPS)]
    pub max_air_mps: f64,
    /// Largest temperature a logged channel may reach in the prediction, °C.
    #[arg(long, default_value_t = DEFAULT_MAX_TEMP_C)]
    pub max_temp_c: f64,
    /// Plan for the joint decision: the planned run to be diagnosed
    /// together with `--log` (`eha-sim diagnose LOG planned.csv`), one
    /// calibration for both; default: the planned run diagnosed alone.
    #[arg(long)]
    pub joint: bool,
}

/// Parses `name` or `name=magnitude` (the fit start of `rig`'s model's
/// parameter for it when absent).
fn parse_candidate(s: &str, model: &ReferenceModel) -> Result<(Candidate, f64), String> {
    let (name, value) = match s.split_once('=') {
        Some((n, v)) => (n.trim(), Some(v.trim().parse::<f64>().map_err(|e| format!("candidate `{s}`: magnitude: {e}"))?)),
        None => (s.trim(), None),
    };
    let c = Candidate::from_name(name).filter(|c| *c != Candidate::None).ok_or_else(|| {
        let names: Vec<&str> = Candidate::EXTENSIONS.iter().map(|c| c.name()).collect();
        format!("unknown candidate `{name}` (expected one of {})", names.join(", "))
    })?;
    let spec = model.extension_params(c).into_iter().next().ok_or_else(|| format!("`{name}` has no parameter"))?;
    let v = value.unwrap_or(spec.start);
    if !(v.is_finite() && v >= spec.lo && v <= spec.hi) {
        return Err(format!("candidate `{name}`: magnitude {v} outside [{}, {}] {}", spec.lo, spec.hi, spec.unit));
    }
    Ok((c, v))
}

/// Runs `plan`: writes mission.csv, plan.md, plan.json to `--out` and
/// prints the chosen mission and the expected ratios.
pub fn run(a: &PlanArgs) -> anyhow::Result<()> {
    let log = MeasuredRun::read_file(&a.log)?;
    let rig = match &a.rig {
        Some(p) => Rig::from_toml_file(p)?,
        None => Rig::default(),
    };
    let model = ReferenceModel::new(rig.clone(), &log)?;
    let cands: Vec<(Candidate, f64)> = if let (true, Some(p)) = (a.candidates.is_empty(), &a.diagnosis) {
        leading(&read_probabilities(p)?, 2).iter().map(|c| parse_candidate(c.name(), &model)).collect::<Result<_, _>>()
    } else if a.candidates.is_empty() {
        Candidate::EXTENSIONS.iter().filter(|c| **c != Candidate::CoulombFriction).map(|c| parse_candidate(c.name(), &model)).collect::<Result<_, _>>()
    } else {
        a.candidates.iter().map(|s| parse_candidate(s, &model)).collect::<Result<_, _>>()
    }
    .map_err(|e| anyhow::anyhow!(e))?;
    let mut limits = Limits::for_rig(&rig, &log);
    let pair = |v: &[f64], what: &str| -> anyhow::Result<(f64, f64)> {
        match v {
            [a, b] => Ok((*a, *b)),
            _ => anyhow::bail!("--{what}: expected two values `lo,hi`, got {}", v.len()),
        }
    };
    if let Some(v) = &a.speed_rpm {
        let (lo, hi) = pair(v, "speed-rpm")?;
        limits.speed_rpm = (lo, hi.min(rig.motor.max_speed_rpm));
    }
    if let Some(v) = &a.drop_bar {
        let (lo, hi) = pair(v, "drop-bar")?;
        limits.drop_bar = (lo, hi.min(rig.hydraulics.relief_crack_pa / 1e5));
    }
    limits.air_mps = limits.air_mps.map(|_| a.max_air_mps);
    limits.max_temp_c = a.max_temp_c;
    if !(limits.speed_rpm.0 > 0.0 && limits.speed_rpm.0 <= limits.speed_rpm.1 && limits.drop_bar.0 > 0.0 && limits.drop_bar.0 <= limits.drop_bar.1) {
        anyhow::bail!("empty envelope: speed {:?} rpm, drop {:?} bar", limits.speed_rpm, limits.drop_bar);
    }
    let span = log.time_s[log.len() - 1] - log.time_s[0];
    let duration = a.duration_s.unwrap_or(span.max(1200.0));
    let decision = if a.joint { Decision::Joint } else { Decision::Alone };
    let p = plan(&rig, &log, &cands, limits, duration, decision).map_err(|e| anyhow::anyhow!(e))?;
    std::fs::create_dir_all(&a.out)?;
    std::fs::write(a.out.join("mission.csv"), p.design.csv())?;
    std::fs::write(a.out.join("plan.md"), p.markdown())?;
    std::fs::write(a.out.join("plan.json"), serde_json::to_string_pretty(&p)? + "\n")?;
    println!("mission: {} (D_s {:.3}) -> {}", p.design.name, p.d_s, a.out.join("mission.csv").display());
    // Each candidate with the magnitude planned for: r̂ follows it
    // (docs/test-plans.md, "What stands between lifted and named").
    for e in &p.expected {
        let mag: Vec<String> = e.planned.magnitude.iter().map(|(n, v, u)| format!("{n} {v:.3e} {u}")).collect();
        println!(
            "  {} at {}: expected r {:.2} on {} (separated {:.2}; on the log {}){}",
            e.planned.candidate,
            mag.join(", "),
            e.planned.best.1,
            e.planned.best.0,
            e.planned_separated,
            e.on_log.as_ref().map_or("–".into(), |r| format!("{:.2}", r.best.1)),
            e.refused.as_ref().map_or(String::new(), |w| format!("; not nameable on it: {w}"))
        );
    }
    if let Some(w) = p.warning() {
        println!("  note: {w}");
    }
    Ok(())
}
