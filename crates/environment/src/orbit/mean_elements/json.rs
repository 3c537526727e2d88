//! OMM as JSON, the form CelesTrak (`gp.php?…&FORMAT=json`) and Space-Track (`class/gp`)
//! serve: one object, or an array of objects, whose keys are the OMM keywords. CelesTrak
//! writes numbers as numbers; Space-Track writes every value as a string; `null` means absent.

use serde_json::Value;

use super::fields::{RawField, RawSet};

/// The element sets of a JSON text.
pub(crate) fn read(text: &str) -> Result<Vec<RawSet>, String> {
    let v: Value = serde_json::from_str(text).map_err(|e| format!("not valid JSON: {e}"))?;
    let objects: Vec<&serde_json::Map<String, Value>> = match &v {
        Value::Object(o) => vec![o],
        Value::Array(a) => a
            .iter()
            .enumerate()
            .map(|(i, x)| {
                x.as_object()
                    .ok_or_else(|| format!("element {i} of the array is not an object"))
            })
            .collect::<Result<_, _>>()?,
        _ => return Err("expected an object or an array of objects".to_string()),
    };
    objects
        .into_iter()
        .enumerate()
        .map(|(i, o)| {
            let mut fields = Vec::new();
            for (k, x) in o {
                let value = match x {
                    Value::Null => continue,
                    Value::String(s) => s.clone(),
                    Value::Number(n) => n.to_string(),
                    Value::Bool(_) | Value::Array(_) | Value::Object(_) => {
                        return Err(format!(
                            "element set {}: {k}: expected a number or a string",
                            i + 1
                        ))
                    }
                };
                fields.push(RawField {
                    key: k.clone(),
                    value,
                    unit: None,
                    line: 0,
                });
            }
            Ok(RawSet { fields })
        })
        .collect()
}
