//! The typed TOML reader every configuration schema uses, and its error type.
//!
//! A leaf module (it imports nothing else of this crate but [`crate::numfmt`] and
//! [`crate::validate`]), so a model's schema can live beside the model
//! (`crates/dynamics/src/effectors/<kind>/schema.rs`, `crates/sensors/src/<kind>/schema.rs`) and report a
//! located [`config_error::ConfigError`] without an import cycle through `flexdyn_vehicle::config`,
//! which assembles the schemas and validates the whole document. The [`source_map`] locates a
//! TOML path in the text, and [`checks`] holds the checks every schema shares.

use std::fmt;

pub mod checks;
pub mod config_error;
pub mod kind_list;
pub mod plausible;
pub mod reader;
pub mod source_map;

pub use reader::TableReader;

/// The keys `a` then `b` as one array, at compile time: a table whose keys are read by two
/// modules lists each key once, in the module that reads it. `N` must be `A + B` (checked when
/// the constant is evaluated).
pub const fn concat_keys<const A: usize, const B: usize, const N: usize>(
    a: [&'static str; A],
    b: [&'static str; B],
) -> [&'static str; N] {
    assert!(A + B == N, "concat_keys: N must be A + B");
    let mut out = [""; N];
    let mut i = 0;
    while i < A {
        out[i] = a[i];
        i += 1;
    }
    let mut j = 0;
    while j < B {
        out[A + j] = b[j];
        j += 1;
    }
    out
}

/// A 3×3 matrix from the rows the reader returns (`TableReader::mat3`).
pub fn mat3(rows: &[[f64; 3]; 3]) -> nalgebra::Matrix3<f64> {
    nalgebra::Matrix3::from_fn(|i, j| rows[i][j])
}

/// A 3-vector from the array the reader returns (`TableReader::floats::<3>`).
pub fn vec3(v: &[f64; 3]) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::new(v[0], v[1], v[2])
}

/// A position in the configuration text (1-based line and column, in characters).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Location {
    /// 1-based line.
    pub line: usize,
    /// 1-based column (characters).
    pub column: usize,
}

/// Where an error points to, if known; displays as ` (line L, column C)` or nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct At(pub Option<Location>);

impl fmt::Display for At {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(l) => write!(f, " (line {}, column {})", l.line, l.column),
            None => Ok(()),
        }
    }
}

/// A document whose shape does not match a schema: an unknown or missing key, or a value of the
/// wrong type or length. A configuration carries it as [`config_error::ConfigError::Schema`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SchemaError {
    /// A key that the schema does not have.
    #[error("{field}: unknown key ({message}){at}")]
    UnknownKey {
        /// TOML path of the unknown key.
        field: String,
        /// The keys the table accepts (and a suggestion for a near miss).
        message: String,
        /// Position of the key.
        at: At,
    },
    /// A required key is absent.
    #[error("{field}: missing required key{}", in_table(at))]
    MissingKey {
        /// TOML path of the missing key.
        field: String,
        /// Position of the table that lacks it.
        at: At,
    },
    /// A value of the wrong type or shape.
    #[error("{field}: invalid value: {message}{at}")]
    InvalidValue {
        /// TOML path of the value.
        field: String,
        /// What is wrong.
        message: String,
        /// Position of the value.
        at: At,
    },
}

impl SchemaError {
    /// The TOML path of the key or value the error is about.
    pub fn field(&self) -> &str {
        match self {
            SchemaError::UnknownKey { field, .. }
            | SchemaError::MissingKey { field, .. }
            | SchemaError::InvalidValue { field, .. } => field,
        }
    }
}

/// 1-based line and column of byte `offset` in `s`.
pub fn location(s: &str, offset: usize) -> Location {
    let offset = offset.min(s.len());
    let before = s.get(..offset).unwrap_or(s);
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    Location {
        line: before.matches('\n').count() + 1,
        column: before[line_start..].chars().count() + 1,
    }
}

fn is_bare_key(k: &str) -> bool {
    !k.is_empty()
        && k.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// `path.key` as a TOML path, the key quoted unless it is bare (`a.b`, `a."b c"`).
pub(crate) fn join_key(path: &str, key: &str) -> String {
    let key = if is_bare_key(key) {
        key.to_string()
    } else {
        format!("{key:?}")
    };
    if path.is_empty() {
        key
    } else {
        format!("{path}.{key}")
    }
}

/// ` (in the table at line L, column C)`, or nothing when the table's position is unknown.
pub(crate) fn in_table(at: &At) -> String {
    match at.0 {
        Some(l) => format!(" (in the table at line {}, column {})", l.line, l.column),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locations() {
        let s = "a = 1\nbb = 2\n";
        assert_eq!(location(s, 0), Location { line: 1, column: 1 });
        assert_eq!(location(s, 6), Location { line: 2, column: 1 });
        assert_eq!(location(s, 11), Location { line: 2, column: 6 });
    }

    #[test]
    fn quoted_keys_in_paths() {
        assert_eq!(join_key("", "hub"), "hub");
        assert_eq!(join_key("server", "a.b"), "server.\"a.b\"");
    }
}
