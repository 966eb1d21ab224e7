//! The rig file's reference (`docs/rig-file.md`), rendered from the code:
//! every section and key of `Rig` in the order serde reads them, its
//! default (the calibrated paper rig, `eha-sim rig`) and the field's doc
//! comment (unit, source, paper equation). Optional keys that the default
//! rig leaves out are listed with "absent"; keys kept only to refuse old
//! files (`skip_serializing`) are not listed. Rendering from the sources
//! means the reference cannot drift from what the reader accepts:
//! `eha-sim docs --check` fails when a doc comment or a default changes.

use anyhow::{bail, Context, Result};
use std::collections::BTreeMap;

use crate::rig::Rig;

/// The files that define the rig's structs (rig/mod.rs comes as the
/// section's source text; the others are compiled in).
const OTHER_SOURCES: [&str; 6] = [
    include_str!("../physics/rig/machine.rs"),
    include_str!("../physics/rig/structure.rs"),
    include_str!("../physics/rig/uncertain.rs"),
    include_str!("../physics/fluid.rs"),
    include_str!("../physics/losses.rs"),
    include_str!("../physics/cooling.rs"),
];

/// One struct field as written in the source.
#[derive(Debug, Clone)]
struct Field {
    name: String,
    ty: String,
    doc: String,
    skipped: bool,
}

/// Struct name → its `pub` fields in source order, from Rust source text:
/// a `pub struct X {` line opens, a line `}` closes, `///` lines before a
/// `pub name: Type,` line are its doc, a `skip_serializing)]` attribute
/// marks a field the writer leaves out.
fn parse_structs(sources: &[&str]) -> BTreeMap<String, Vec<Field>> {
    let mut out = BTreeMap::new();
    for src in sources {
        let mut current: Option<(String, Vec<Field>)> = None;
        let mut doc: Vec<String> = Vec::new();
        let mut skipped = false;
        for line in src.lines() {
            let t = line.trim();
            if let Some(rest) = t.strip_prefix("pub struct ") {
                if let Some(name) = rest.strip_suffix(" {") {
                    current = Some((name.to_string(), Vec::new()));
                }
                doc.clear();
                continue;
            }
            let Some((_, fields)) = current.as_mut() else { continue };
            if t == "}" {
                let (name, fields) = current.take().expect("inside a struct");
                out.insert(name, fields);
                doc.clear();
            } else if let Some(d) = t.strip_prefix("///") {
                doc.push(d.trim().to_string());
            } else if t.starts_with("#[") {
                skipped |= t.contains("skip_serializing)]");
            } else if let Some(rest) = t.strip_prefix("pub ") {
                if let Some((name, ty)) = rest.split_once(": ") {
                    fields.push(Field {
                        name: name.to_string(),
                        ty: ty.trim_end_matches(',').to_string(),
                        doc: doc.join(" "),
                        skipped,
                    });
                }
                doc.clear();
                skipped = false;
            }
        }
    }
    out
}

/// The struct a field's type names: `T`, `Option<T>` or `Vec<T>` with `T`
/// a parsed struct; `None` for plain values.
fn struct_of<'a>(ty: &'a str, structs: &BTreeMap<String, Vec<Field>>) -> Option<(&'a str, bool)> {
    let (inner, array) = match ty {
        t if t.starts_with("Option<") => (&t[7..t.len() - 1], false),
        t if t.starts_with("Vec<") => (&t[4..t.len() - 1], true),
        t => (t, false),
    };
    structs.contains_key(inner).then_some((inner, array))
}

/// A TOML value as one table cell.
fn cell(v: Option<&toml::Value>) -> String {
    match v {
        None => "absent".to_string(),
        Some(toml::Value::String(s)) => format!("\"{s}\""),
        Some(toml::Value::Array(a)) if a.len() > 3 => format!("[{} values]", a.len()),
        Some(v) => format!("`{v}`"),
    }
}

/// Markdown-safe doc text: paths in brackets lose their intra-doc link
/// syntax, pipes are escaped.
fn doc_text(d: &str) -> String {
    d.replace("[`", "`").replace("`]", "`").replace('|', "\\|")
}

/// Renders one section and, after it, its sub-sections.
fn section(
    out: &mut String,
    path: &str,
    array: bool,
    ty: &str,
    value: Option<&toml::Value>,
    structs: &BTreeMap<String, Vec<Field>>,
) -> Result<()> {
    let fields = structs.get(ty).with_context(|| format!("no struct {ty} in the rig's sources"))?;
    let table = match value {
        Some(toml::Value::Table(t)) => Some(t),
        Some(toml::Value::Array(a)) => a.first().and_then(|v| v.as_table()),
        _ => None,
    };
    if array {
        let n = value.and_then(|v| v.as_array()).map_or(0, Vec::len);
        out.push_str(&format!("### `[[{path}]]`\n\nRepeated; the default rig has {n}, the first shown.\n\n"));
    } else {
        out.push_str(&format!("### `[{path}]`\n\n"));
    }
    let mut subs = Vec::new();
    let mut rows = String::new();
    for f in fields.iter().filter(|f| !f.skipped) {
        if f.doc.is_empty() {
            bail!("{ty}.{} has no doc comment", f.name);
        }
        let v = table.and_then(|t| t.get(&f.name));
        match struct_of(&f.ty, structs) {
            Some((inner, is_array)) => subs.push((f, inner, is_array, v)),
            None => rows.push_str(&format!("| `{}` | {} | {} |\n", f.name, cell(v), doc_text(&f.doc))),
        }
    }
    if !rows.is_empty() {
        out.push_str("| key | default | meaning |\n|---|---|---|\n");
        out.push_str(&rows);
        out.push('\n');
    }
    for (f, inner, is_array, v) in subs {
        let sub = if path.is_empty() { f.name.clone() } else { format!("{path}.{}", f.name) };
        let absent = if v.is_none() { " Absent from the default rig." } else { "" };
        out.push_str(&format!("`{sub}`: {}{absent}\n\n", doc_text(&f.doc)));
        section(out, &sub, is_array, inner, v, structs)?;
    }
    Ok(())
}

/// `docs/rig-file.md`'s generated part from `rig/mod.rs`'s text (the other
/// struct files compiled in) and `Rig::default()`.
pub fn render(rig_rs: &str) -> Result<String> {
    let mut sources = vec![rig_rs];
    sources.extend(OTHER_SOURCES);
    let structs = parse_structs(&sources);
    let value = toml::Value::try_from(Rig::default()).context("serialising the default rig")?;
    let top = value.as_table().context("the rig is a table")?;
    let rig = structs.get("Rig").context("no struct Rig")?;
    let mut out = String::new();
    for f in rig.iter().filter(|f| !f.skipped) {
        let (inner, array) = struct_of(&f.ty, &structs).with_context(|| format!("Rig.{} is not a section", f.name))?;
        let v = top.get(&f.name);
        let absent = if v.is_none() { " Absent from the default rig." } else { "" };
        out.push_str(&format!("## `{}`: {}{absent}\n\n", f.name, doc_text(&f.doc)));
        section(&mut out, &f.name, array, inner, v, &structs)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every key the default rig writes appears in the reference: walking
    /// the structs covers what serde writes (a key serde writes that the
    /// parser missed would be a struct the parser cannot read).
    #[test]
    fn every_written_key_is_documented() {
        let text = render(include_str!("../physics/rig/mod.rs")).expect("renders");
        fn walk(prefix: &str, v: &toml::Value, keys: &mut Vec<String>) {
            if let Some(t) = v.as_table() {
                for (k, x) in t {
                    walk(&format!("{prefix}.{k}"), x, keys);
                }
            } else if let Some(a) = v.as_array().filter(|a| a.iter().all(|x| x.is_table())) {
                a.iter().for_each(|x| walk(prefix, x, keys));
            } else {
                keys.push(prefix.rsplit('.').next().unwrap_or(prefix).to_string());
            }
        }
        let mut keys = Vec::new();
        walk("", &toml::Value::try_from(Rig::default()).expect("serialises"), &mut keys);
        assert!(keys.len() > 100, "the default rig writes {} keys", keys.len());
        for k in keys {
            assert!(text.contains(&format!("| `{k}` |")), "key {k} missing from the rig-file reference");
        }
    }
}
