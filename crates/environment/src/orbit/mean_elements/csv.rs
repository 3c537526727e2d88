//! OMM as CSV, the form CelesTrak (`gp.php?…&FORMAT=csv`) and Space-Track serve: a header row
//! of OMM keywords, then one row per element set. Fields may be quoted (RFC 4180: `"…"`, with
//! `""` for a quote inside).

use super::fields::{RawField, RawSet};

/// Splits one CSV record.
fn split(line: &str, n: usize) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut chars = line.chars().peekable();
    let mut quoted = false;
    let mut was_quoted = false;
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                cur.push('"');
            }
            (true, '"') => quoted = false,
            (true, c) => cur.push(c),
            (false, '"') if cur.is_empty() && !was_quoted => {
                quoted = true;
                was_quoted = true;
            }
            (false, ',') => {
                out.push(std::mem::take(&mut cur));
                was_quoted = false;
            }
            (false, c) => cur.push(c),
        }
    }
    if quoted {
        return Err(format!("line {n}: unterminated quoted field"));
    }
    out.push(cur);
    Ok(out)
}

/// The element sets of a CSV text.
pub(crate) fn read(text: &str) -> Result<Vec<RawSet>, String> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((hn, header)) = lines.next() else {
        return Err("empty CSV".to_string());
    };
    let keys: Vec<String> = split(header, hn)?
        .into_iter()
        .map(|k| k.trim().to_string())
        .collect();
    lines
        .map(|(n, l)| {
            let values = split(l, n)?;
            if values.len() != keys.len() {
                return Err(format!(
                    "line {n}: {} fields where the header (line {hn}) has {}",
                    values.len(),
                    keys.len()
                ));
            }
            Ok(RawSet {
                fields: keys
                    .iter()
                    .zip(values)
                    .map(|(k, v)| RawField {
                        key: k.clone(),
                        value: v.trim().to_string(),
                        unit: None,
                        line: n,
                    })
                    .collect(),
            })
        })
        .collect()
}
