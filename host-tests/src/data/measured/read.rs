//! The strict reader: metadata preamble by line, the table by the `csv`
//! crate, every cell checked against the format's rules.

use super::{Channel, MeasuredError, MeasuredRun, MetaLine};
use std::collections::BTreeMap;

/// Checks one parsed value of channel `ch` at `line`: finite and inside the
/// physical range of [`Channel::range`]. `text` is the cell as written.
pub fn check_value(file: &str, line: u64, ch: Channel, x: f64, text: &str) -> Result<(), MeasuredError> {
    if !x.is_finite() {
        return Err(MeasuredError::NonFinite { file: file.into(), line, column: ch.name().into(), value: text.into() });
    }
    if let Some((lo, hi)) = ch.range() {
        if x < lo || x > hi {
            return Err(MeasuredError::OutOfRange {
                file: file.into(),
                line,
                column: ch.name().into(),
                value: x,
                lo,
                hi,
                unit: ch.unit().into(),
            });
        }
    }
    Ok(())
}

/// Parses one cell: `Ok(None)` for an empty (whitespace-only) cell, the
/// number otherwise; `NaN`/`inf` spellings are non-finite errors.
fn parse_cell(file: &str, line: u64, column: &str, text: &str) -> Result<Option<f64>, MeasuredError> {
    let t = text.trim();
    if t.is_empty() {
        return Ok(None);
    }
    match t.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(Some(x)),
        Ok(_) => Err(MeasuredError::NonFinite { file: file.into(), line, column: column.into(), value: t.into() }),
        Err(_) => Err(MeasuredError::Unparsable { file: file.into(), line, column: column.into(), value: t.into() }),
    }
}

/// Splits one metadata line (`# key: value` or `# free text`).
fn meta_line(line: &str) -> MetaLine {
    let body = line.trim_start_matches('#').trim();
    match body.split_once(':') {
        Some((k, v)) if !k.trim().is_empty() && !k.trim().contains(char::is_whitespace) => {
            MetaLine { key: k.trim().to_string(), value: v.trim().to_string() }
        }
        _ => MetaLine { key: String::new(), value: body.to_string() },
    }
}

/// Parses and validates a whole measured file held in `text`.
pub(super) fn parse_str(file: &str, text: &str) -> Result<MeasuredRun, MeasuredError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Metadata preamble: `#` lines (and blank lines) before the header.
    let mut metadata = Vec::new();
    let mut offset = 0usize;
    let mut preamble_lines = 0u64;
    for l in text.split_inclusive('\n') {
        let tl = l.trim();
        if tl.starts_with('#') {
            metadata.push(meta_line(tl));
        } else if !tl.is_empty() {
            break;
        }
        offset += l.len();
        preamble_lines += 1;
    }
    let table = &text[offset..];
    let header_line = preamble_lines + 1;
    let mut rdr = csv::ReaderBuilder::new().has_headers(false).flexible(false).from_reader(table.as_bytes());
    let mut records = rdr.records();
    let csv_err = |e: csv::Error| {
        let line = e.position().map(|p| p.line() + preamble_lines).unwrap_or(header_line);
        MeasuredError::Csv { file: file.into(), line, message: e.to_string() }
    };
    let header = match records.next() {
        None => return Err(MeasuredError::NoHeader { file: file.into() }),
        Some(r) => r.map_err(csv_err)?,
    };
    let names: Vec<String> = header.iter().map(|h| h.trim().to_string()).collect();
    // Column index of time and of each known channel; unknown ones noted.
    let mut time_col = None;
    let mut cols: Vec<(usize, Channel)> = Vec::new();
    let mut notes = Vec::new();
    for (i, n) in names.iter().enumerate() {
        let dup = |c: &str| MeasuredError::DuplicateColumn { file: file.into(), line: header_line, column: c.into() };
        if n == "time_s" {
            if time_col.is_some() {
                return Err(dup(n));
            }
            time_col = Some(i);
        } else if let Some(ch) = Channel::from_name(n) {
            if cols.iter().any(|(_, c)| *c == ch) {
                return Err(dup(n));
            }
            cols.push((i, ch));
        } else {
            notes.push(format!("{file}:{header_line}: unknown column `{n}` ignored"));
        }
    }
    let missing = |c: &str| MeasuredError::MissingColumn { file: file.into(), line: header_line, column: c.into() };
    let time_col = time_col.ok_or_else(|| missing("time_s"))?;
    for ch in Channel::ALL.into_iter().filter(|c| c.required()) {
        if !cols.iter().any(|(_, c)| *c == ch) {
            return Err(missing(ch.name()));
        }
    }
    let mut time_s: Vec<f64> = Vec::new();
    let mut data: Vec<Vec<Option<f64>>> = vec![Vec::new(); cols.len()];
    for rec in records {
        let rec = rec.map_err(csv_err)?;
        let line = rec.position().map(|p| p.line()).unwrap_or(0) + preamble_lines;
        let t = parse_cell(file, line, "time_s", &rec[time_col])?
            .ok_or(MeasuredError::MissingTime { file: file.into(), line })?;
        if let Some(&prev) = time_s.last() {
            if t <= prev {
                return Err(MeasuredError::TimeNotIncreasing { file: file.into(), line, previous: prev, value: t });
            }
        }
        time_s.push(t);
        for (k, (i, ch)) in cols.iter().enumerate() {
            let cell = &rec[*i];
            let v = parse_cell(file, line, ch.name(), cell)?;
            if let Some(x) = v {
                check_value(file, line, *ch, x, cell.trim())?;
            }
            data[k].push(v);
        }
    }
    let channels: BTreeMap<Channel, Vec<Option<f64>>> = cols.into_iter().map(|(_, c)| c).zip(data).collect();
    Ok(MeasuredRun { metadata, time_s, channels, notes })
}
