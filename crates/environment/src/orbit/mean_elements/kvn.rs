//! CCSDS OMM in keyword = value notation (KVN, CCSDS 502.0-B-3 §4.2 and §7):
//! `KEYWORD = value [unit]` lines, `COMMENT` lines, blank lines. A file may hold several
//! messages one after the other; each starts with `CCSDS_OMM_VERS`. Bare `…_START` / `…_STOP`
//! block markers are skipped.

use super::fields::{RawField, RawSet};

/// The element sets of a KVN text, or a message naming the line.
pub(crate) fn read(text: &str) -> Result<Vec<RawSet>, String> {
    let mut sets: Vec<RawSet> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let l = raw.trim();
        if l.is_empty() || l.starts_with("COMMENT") {
            continue;
        }
        if !l.contains('=') && (l.ends_with("_START") || l.ends_with("_STOP")) {
            continue;
        }
        let Some((k, v)) = l.split_once('=') else {
            return Err(format!(
                "line {line}: expected `KEYWORD = value`, got {l:?}"
            ));
        };
        let key = k.trim().to_string();
        if key.is_empty()
            || !key
                .bytes()
                .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == b'_')
        {
            return Err(format!(
                "line {line}: {key:?} is not a KVN keyword (upper-case letters, digits and `_`)"
            ));
        }
        let v = v.trim();
        // An optional trailing `[unit]`.
        let (value, unit) = match v.strip_suffix(']').and_then(|s| s.rsplit_once('[')) {
            Some((val, unit)) => (val.trim().to_string(), Some(unit.trim().to_string())),
            None => (v.to_string(), None),
        };
        if key == "CCSDS_OMM_VERS" || sets.is_empty() {
            sets.push(RawSet::default());
        }
        if let Some(set) = sets.last_mut() {
            set.fields.push(RawField {
                key,
                value,
                unit,
                line,
            });
        }
    }
    if sets.is_empty() {
        return Err("no `KEYWORD = value` line found".to_string());
    }
    Ok(sets)
}
