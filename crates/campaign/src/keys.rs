//! TOML paths into a configuration document: `hub.inertia_bc_b_kg_m2[0][0]`,
//! `panel_pairs[*].panel1.k_nm_rad`, `initial.omega_bn_b_rad_s`. A segment is a table key
//! followed by any number of `[i]` (an array index) or `[*]` (every element). A path that ends
//! on an array of numbers names each of its numbers.

use toml::{Table, Value};

/// One step of a path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Step {
    /// A table key.
    Key(String),
    /// An array index.
    Index(usize),
    /// Every element of an array.
    All,
}

/// Parses `path`; the error says what is wrong at which character.
pub fn parse(path: &str) -> Result<Vec<Step>, String> {
    let mut steps = Vec::new();
    if path.is_empty() {
        return Err("empty key".into());
    }
    for (n, segment) in path.split('.').enumerate() {
        let (name, mut rest) = match segment.find('[') {
            Some(i) => (&segment[..i], &segment[i..]),
            None => (segment, ""),
        };
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        {
            return Err(format!(
                "segment {} ({segment:?}) is not a table key",
                n + 1
            ));
        }
        steps.push(Step::Key(name.to_owned()));
        while !rest.is_empty() {
            let close = rest
                .find(']')
                .filter(|_| rest.starts_with('['))
                .ok_or_else(|| format!("segment {segment:?}: expected [index] or [*]"))?;
            let inner = &rest[1..close];
            steps.push(if inner == "*" {
                Step::All
            } else {
                Step::Index(
                    inner.parse().map_err(|_| {
                        format!("segment {segment:?}: {inner:?} is not an index or *")
                    })?,
                )
            });
            rest = &rest[close + 1..];
        }
    }
    Ok(steps)
}

/// Every concrete numeric leaf `path` names in `doc`, as canonical paths with indices
/// (`panel_pairs[1].panel1.k_nm_rad`, `initial.omega_bn_b_rad_s[2]`), in document order. An
/// error names the first step that does not exist or does not hold numbers.
pub fn expand(doc: &Table, path: &str) -> Result<Vec<String>, String> {
    let steps = parse(path)?;
    // `parse` always starts with a table key.
    let (Some(Step::Key(first)), rest) = (steps.first(), &steps[1..]) else {
        return Err("a key must start with a table key".into());
    };
    let child = doc
        .get(first)
        .ok_or_else(|| format!("{first} does not exist in the base configuration"))?;
    let mut out = Vec::new();
    walk(child, rest, first.clone(), &mut out)?;
    if out.is_empty() {
        return Err("names no number (an empty array?)".into());
    }
    Ok(out)
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_owned()
    } else {
        format!("{prefix}.{key}")
    }
}

fn walk(v: &Value, steps: &[Step], at: String, out: &mut Vec<String>) -> Result<(), String> {
    let Some((step, rest)) = steps.split_first() else {
        return match v {
            Value::Integer(_) | Value::Float(_) => {
                out.push(at);
                Ok(())
            }
            // A path ending on an array of numbers names each number.
            Value::Array(items) => {
                for (i, item) in items.iter().enumerate() {
                    walk(item, &[], format!("{at}[{i}]"), out)?;
                }
                Ok(())
            }
            other => Err(format!("{at} is a {}, not a number", other.type_str())),
        };
    };
    match (step, v) {
        (Step::Key(k), Value::Table(t)) => match t.get(k) {
            Some(child) => walk(child, rest, join(&at, k), out),
            None => Err(format!(
                "{} does not exist in the base configuration",
                join(&at, k)
            )),
        },
        (Step::Index(i), Value::Array(items)) => match items.get(*i) {
            Some(child) => walk(child, rest, format!("{at}[{i}]"), out),
            None => Err(format!(
                "{at}[{i}] does not exist ({at} has {} elements)",
                items.len()
            )),
        },
        (Step::All, Value::Array(items)) => {
            for (i, child) in items.iter().enumerate() {
                walk(child, rest, format!("{at}[{i}]"), out)?;
            }
            Ok(())
        }
        (Step::Key(k), other) => Err(format!(
            "{at} is a {}, so it has no key {k:?}",
            other.type_str()
        )),
        (_, other) => Err(format!("{at} is a {}, not an array", other.type_str())),
    }
}

fn leaf_mut<'a>(doc: &'a mut Table, path: &str) -> Option<&'a mut Value> {
    let steps = parse(path).ok()?;
    let (first, rest) = steps.split_first()?;
    let Step::Key(k) = first else { return None };
    let mut v = doc.get_mut(k)?;
    for s in rest {
        v = match (s, v) {
            (Step::Key(k), Value::Table(t)) => t.get_mut(k)?,
            (Step::Index(i), Value::Array(a)) => a.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(v)
}

/// The number at a canonical path (from [`expand`]).
pub fn get(doc: &Table, path: &str) -> Option<f64> {
    let steps = parse(path).ok()?;
    let (first, rest) = steps.split_first()?;
    let Step::Key(k) = first else { return None };
    let mut v = doc.get(k)?;
    for s in rest {
        v = match (s, v) {
            (Step::Key(k), Value::Table(t)) => t.get(k)?,
            (Step::Index(i), Value::Array(a)) => a.get(*i)?,
            _ => return None,
        };
    }
    match v {
        Value::Integer(i) => Some(*i as f64),
        Value::Float(x) => Some(*x),
        _ => None,
    }
}

/// Writes `x` at a canonical path (from [`expand`]); `false` if the path does not hold a number.
pub fn set(doc: &mut Table, path: &str, x: f64) -> bool {
    match leaf_mut(doc, path) {
        Some(v @ (Value::Integer(_) | Value::Float(_))) => {
            *v = Value::Float(x);
            true
        }
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc() -> Table {
        toml::from_str(
            r#"
            [hub]
            inertia = [[1.0, 0.0], [0.0, 2]]
            [[pairs]]
            p1 = { k = 100.0 }
            [[pairs]]
            p1 = { k = 90 }
            [initial]
            w = [0.1, 0.2, 0.3]
            name = "x"
            "#,
        )
        .unwrap()
    }

    #[test]
    fn paths_expand_to_every_number_they_name() {
        let d = doc();
        assert_eq!(
            expand(&d, "hub.inertia[1][1]").unwrap(),
            ["hub.inertia[1][1]"]
        );
        assert_eq!(
            expand(&d, "pairs[*].p1.k").unwrap(),
            ["pairs[0].p1.k", "pairs[1].p1.k"]
        );
        assert_eq!(
            expand(&d, "initial.w").unwrap(),
            ["initial.w[0]", "initial.w[1]", "initial.w[2]"]
        );
        assert_eq!(get(&d, "pairs[1].p1.k"), Some(90.0));
        let mut d2 = d.clone();
        assert!(set(&mut d2, "hub.inertia[1][1]", 2.5));
        assert_eq!(get(&d2, "hub.inertia[1][1]"), Some(2.5));
    }

    #[test]
    fn a_wrong_path_says_where_it_stops() {
        let d = doc();
        for (path, want) in [
            ("hub.inertai[0][0]", "hub.inertai does not exist"),
            (
                "pairs[2].p1.k",
                "pairs[2] does not exist (pairs has 2 elements)",
            ),
            ("initial.name", "initial.name is a string, not a number"),
            ("hub[0]", "hub is a table, not an array"),
            ("hub.inertia[x]", "is not an index"),
            ("", "empty key"),
        ] {
            let e = expand(&d, path).unwrap_err();
            assert!(e.contains(want), "{path}: {e}");
        }
    }
}
