//! Tables in `docs/` that a command renders from committed JSON, never by
//! hand: `eha-sim docs` re-renders them, `eha-sim docs --check` (in CI)
//! fails when a document differs from its rendering. Each table sits
//! between two marker lines:
//!
//! ```text
//! <!-- begin generated: TAG (from SOURCE by `eha-sim docs`) -->
//! ...
//! <!-- end generated: TAG -->
//! ```

use anyhow::{bail, Context, Result};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::pil::budget::ImageBudget;
use crate::pil::firmware::workspace_root;
use crate::uq::{checks_table, PaperCheck};

/// One generated section: the document, its tag, the JSON it is rendered
/// from (relative to the workspace root) and the renderer.
pub struct Section {
    /// Document, relative to the workspace root.
    pub doc: &'static str,
    /// Marker tag.
    pub tag: &'static str,
    /// The committed JSON it is rendered from (several `, `-separated: the
    /// renderer gets a JSON array of their texts, in this order).
    pub source: &'static str,
    /// JSON text → Markdown.
    pub render: fn(&str) -> Result<String>,
}

/// Every generated section.
pub const SECTIONS: [Section; 9] = [
    Section { doc: "docs/results.md", tag: "uq-paper", source: "docs/data/uq-paper.json", render: render_uq_paper },
    Section { doc: "docs/results.md", tag: "fw-budget", source: ".ci/fw-budget.json", render: render_fw_budget },
    Section { doc: "docs/rig-file.md", tag: "rig-file", source: "host-tests/src/physics/rig/mod.rs", render: crate::tools::rigdoc::render },
    Section { doc: "docs/failure-modes.md", tag: "failure-modes", source: "docs/data/faults.json", render: render_failure_modes },
    Section {
        doc: "docs/diagnosis-off.md",
        tag: "emulator-sweep",
        source: "docs/data/emulator-sweep.json",
        render: render_emulator_sweep,
    },
    Section {
        doc: "docs/diagnosis-numbers.md",
        tag: "emulator-sweep-1800",
        source: "docs/data/emulator-sweep-1800.json",
        render: render_emulator_sweep,
    },
    Section {
        doc: "docs/diagnosis-numbers.md",
        tag: "emulator-sweep-2800",
        source: "docs/data/emulator-sweep-2800.json",
        render: render_emulator_sweep,
    },
    Section {
        doc: "docs/diagnosis-numbers.md",
        tag: "reliability-default",
        source: "docs/data/emulator-sweep-hidden-no-case-held.json, docs/data/emulator-sweep-1800.json, docs/data/emulator-sweep-2800.json, docs/data/imprint-ratios-no-case-held.json",
        render: render_reliability,
    },
    Section {
        doc: "docs/diagnosis-gate.md",
        tag: "reliability-gate",
        source: "docs/data/emulator-sweep-1800.json, docs/data/emulator-sweep-2800.json",
        render: render_gate,
    },
];

/// The gate's rejection as an observation against the product's
/// probabilities ([`crate::diagnosis::emu_calibration::gate_document`]) on
/// the sweep that carries every log's detectability.
/// Its sources' texts as a JSON array (the two seed sets with twins); a
/// third row group pools them.
fn render_gate(json: &str) -> Result<String> {
    let [a, b]: [Vec<crate::diagnosis::emu_sweep::EmuResult>; 2] = serde_json::from_str(json)?;
    let both: Vec<_> = a.iter().chain(&b).cloned().collect();
    Ok(crate::diagnosis::emu_calibration::gate_document(&[("1800–1817 (with twins)", a), ("2800–2817 (with twins)", b), ("both sets", both)]))
}

/// Labels of the sweeps of the `reliability-default` section, in its
/// sources' order.
const RELIABILITY_SETS: [&str; 3] = ["1700s/2700s (17 case logs, no twins)", "1800–1817 (with twins)", "2800–2817 (with twins)"];

/// The reliability of the stated probabilities under the default structure
/// and what an effective sample size does to it
/// ([`crate::diagnosis::emu_calibration`]): its sources' texts as a JSON
/// array, the sweeps' then the imprint ratios (seed → r) of the cases run
/// without twins.
fn render_reliability(json: &str) -> Result<String> {
    let mut parts: Vec<serde_json::Value> = serde_json::from_str(json)?;
    let ratios: BTreeMap<u64, f64> = match parts.pop() {
        Some(v) => serde_json::from_value::<BTreeMap<String, f64>>(v)?.into_iter().filter_map(|(k, r)| Some((k.parse().ok()?, r))).collect(),
        None => BTreeMap::new(),
    };
    let mut sets = Vec::new();
    for (i, v) in parts.into_iter().enumerate() {
        let rows: Vec<crate::diagnosis::emu_sweep::EmuResult> = serde_json::from_value(v)?;
        sets.push((RELIABILITY_SETS.get(i).copied().unwrap_or("more"), rows));
    }
    Ok(crate::diagnosis::emu_calibration::document(&sets, &ratios))
}

/// The emulator sweep's tables (`eha-sim emulator-sweep`, the case sets
/// it ran under `--structure off`, its `emulator-sweep.json`, in
/// docs/diagnosis-off.md; the second seed set's under the default
/// structure, `emulator-sweep-1800.json` and `emulator-sweep-2800.json`,
/// in docs/diagnosis-numbers.md).
fn render_emulator_sweep(json: &str) -> Result<String> {
    let rows: Vec<crate::diagnosis::emu_sweep::EmuResult> = serde_json::from_str(json)?;
    Ok(crate::diagnosis::emu_sweep::document(&rows))
}

/// The fault campaign's table (`eha-sim faults`, the whole campaign).
fn render_failure_modes(json: &str) -> Result<String> {
    let rows: Vec<crate::faults::FaultResult> = serde_json::from_str(json)?;
    Ok(crate::faults::modes::document(&rows))
}

/// The paper numbers against their bands (`eha-sim uq --table5`, 200
/// samples, its `paper.json`).
fn render_uq_paper(json: &str) -> Result<String> {
    let checks: Vec<PaperCheck> = serde_json::from_str(json)?;
    Ok(checks_table(&checks, 200))
}

/// Every image's budget figures (`eha-sim fw-budget`, the committed
/// baseline).
fn render_fw_budget(json: &str) -> Result<String> {
    let b: BTreeMap<String, ImageBudget> = serde_json::from_str(json)?;
    Ok(crate::pil::budget::markdown(&b))
}

/// `text` with the body between `tag`'s markers replaced by `body`; an
/// error names the document and the missing marker.
pub fn splice(text: &str, doc: &str, tag: &str, source: &str, body: &str) -> Result<String> {
    let begin = format!("<!-- begin generated: {tag} ");
    let end = format!("<!-- end generated: {tag} -->");
    let b = text.find(&begin).with_context(|| format!("{doc}: no line starting `{begin}`"))?;
    let b_end = b + text[b..].find('\n').with_context(|| format!("{doc}: the begin marker of {tag} ends the file"))? + 1;
    let e = text[b_end..].find(&end).with_context(|| format!("{doc}: no `{end}` after its begin marker"))? + b_end;
    Ok(format!("{}<!-- begin generated: {tag} (from {source} by `eha-sim docs`) -->\n{body}{}", &text[..b], &text[e..]))
}

/// Re-renders every section; with `check`, writes nothing and fails on the
/// first document that differs. Returns the documents that changed.
pub fn run(root: &Path, check: bool) -> Result<Vec<PathBuf>> {
    let mut docs: BTreeMap<&str, String> = BTreeMap::new();
    for s in &SECTIONS {
        let path = root.join(s.doc);
        let text = match docs.get(s.doc) {
            Some(t) => t.clone(),
            None => std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?,
        };
        // Several sources (", "-separated) reach the renderer as one JSON array of their texts.
        let read = |src: &str| std::fs::read_to_string(root.join(src)).with_context(|| format!("reading {src}"));
        let srcs: Vec<&str> = s.source.split(", ").collect();
        let json = if srcs.len() == 1 { read(s.source)? } else { format!("[{}]", srcs.iter().map(|x| read(x)).collect::<Result<Vec<_>>>()?.join(",")) };
        let body = (s.render)(&json).with_context(|| format!("rendering {} from {}", s.tag, s.source))?;
        docs.insert(s.doc, splice(&text, s.doc, s.tag, s.source, &body)?);
    }
    let mut changed = Vec::new();
    for (doc, text) in docs {
        let path = root.join(doc);
        let old = std::fs::read_to_string(&path)?;
        if old != text {
            if check {
                bail!("{doc} differs from its rendering from the committed JSON: run `eha-sim docs` and commit");
            }
            std::fs::write(&path, &text).with_context(|| format!("writing {}", path.display()))?;
            changed.push(path);
        }
    }
    Ok(changed)
}

/// Arguments of `eha-sim docs`.
#[derive(Debug, Clone, clap::Args)]
pub struct DocsArgs {
    /// Only check: fail when a document differs from its rendering.
    #[arg(long)]
    pub check: bool,
}

/// `eha-sim docs`.
pub fn run_cli(a: &DocsArgs) -> Result<()> {
    let changed = run(&workspace_root(), a.check)?;
    if a.check {
        println!("every generated table matches its JSON");
    } else {
        for p in &changed {
            println!("rewrote {}", p.display());
        }
        if changed.is_empty() {
            println!("nothing to rewrite");
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splice_replaces_only_the_body_and_names_missing_markers() {
        let t = "a\n<!-- begin generated: x (old) -->\nold\n<!-- end generated: x -->\nb\n";
        let s = splice(t, "d.md", "x", "s.json", "new\n").expect("splices");
        assert_eq!(s, "a\n<!-- begin generated: x (from s.json by `eha-sim docs`) -->\nnew\n<!-- end generated: x -->\nb\n");
        let e = splice("a\n", "d.md", "x", "s.json", "").expect_err("no marker");
        assert!(e.to_string().contains("d.md") && e.to_string().contains("begin generated: x"), "{e}");
    }

    /// The committed documents are their renderings (what CI's `eha-sim
    /// docs --check` also checks).
    #[test]
    fn committed_docs_match_their_json() {
        run(&workspace_root(), true).expect("generated tables up to date");
    }
}
