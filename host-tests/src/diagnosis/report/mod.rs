//! Writing a diagnosis: `diagnosis.json` (the machine-readable verdict with
//! its documented keys) and `report.md` (the evidence, with PNGs).
//!
//! By topic: `json` the verdict's types and their construction from a
//! [`Diagnosis`], `markdown` the report's sections; this file writes
//! both ([`write_outputs`]).

mod json;
mod markdown;

pub use json::{DiagnosisJson, LogChannelJson, LogJson, MisfitJson, ProbabilityJson, RankingJson, UnexplainedJson};
pub use markdown::{report_markdown, report_markdown_logs};

use super::analysis::Diagnosis;
use std::path::Path;

/// Writes `report.md`, `diagnosis.json` and the PNGs of `d` into `out`.
pub fn write_outputs(d: &Diagnosis, run: &crate::measured::MeasuredRun, source: &str, out: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(out)?;
    let pngs = super::plot::write_plots(d, run, out).map_err(|e| std::io::Error::other(e.to_string()))?;
    std::fs::write(out.join("report.md"), report_markdown(d, source, &pngs))?;
    let j = serde_json::to_string_pretty(&DiagnosisJson::from_diagnosis(d)).map_err(std::io::Error::other)?;
    std::fs::write(out.join("diagnosis.json"), j + "\n")
}
