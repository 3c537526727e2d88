//! A typed reader over the parsed TOML document, used by every schema in place of `serde`.
//!
//! `serde`'s derive accepts shapes the file format should not (an over-long array for `[f64; 3]`,
//! a positional array for a struct) and its messages name Rust types (`struct RawGravity`,
//! `i128`, `$__toml_private_datetime`). This reader checks each key against the schema itself,
//! in the file's own words:
//!
//! - unknown keys: `hub.colour: unknown key (expected one of: mass_kg, …)`, checked when a
//!   table is opened, before any of its values;
//! - missing keys: `hub.mass_kg: missing required key (in the table at line 18, column 1)`;
//! - types, in TOML's vocabulary: `expected a number, got a string`, `… got a datetime`;
//! - exact lengths: `expected 3 elements, got 5`, and each element by its own path (`x[3]`);
//! - tables must have named keys: a positional array where a table is expected is an error;
//! - integers outside TOML's 64-bit range are named as such.
//!
//! Non-finite floats (`nan`, `inf`) are read as such; the whole-document finiteness pass that
//! runs after the structure pass reports them (see the module docs of `flexdyn_vehicle::config`).

use toml::de::{DeTable, DeValue};
use toml::Spanned;

use super::{join_key, location, At, SchemaError};

/// A TOML value as this reader describes it in messages ("a string", "an array of 5 elements").
pub(crate) fn describe(v: &DeValue<'_>) -> String {
    match v {
        DeValue::String(s) => format!("a string ({s:?})"),
        DeValue::Integer(i) => format!("an integer ({i})"),
        DeValue::Float(f) => format!("a float ({f})"),
        DeValue::Boolean(b) => format!("a boolean ({b})"),
        DeValue::Datetime(d) => format!("a datetime ({d})"),
        DeValue::Array(a) => match a.len() {
            1 => "an array of 1 element".to_string(),
            n => format!("an array of {n} elements"),
        },
        DeValue::Table(_) => "a table".to_string(),
    }
}

/// One table of the document, opened with the keys its schema allows.
pub struct TableReader<'a, 'i> {
    source: &'a str,
    path: String,
    table: &'a DeTable<'i>,
    at: At,
}

impl<'a, 'i> TableReader<'a, 'i> {
    /// The document's root table.
    pub fn root(
        source: &'a str,
        doc: &'a DeTable<'i>,
        allowed: &[&str],
    ) -> Result<Self, SchemaError> {
        let r = Self {
            source,
            path: String::new(),
            table: doc,
            at: At(None),
        };
        r.check_keys(allowed)?;
        Ok(r)
    }

    /// The TOML path of `key` in this table.
    pub fn field(&self, key: &str) -> String {
        join_key(&self.path, key)
    }

    /// An error at `key` of this table, located at its value (or at the table when absent):
    /// for a key that is well-formed but not allowed beside the others.
    pub fn refuse(&self, key: &str, message: String) -> SchemaError {
        SchemaError::InvalidValue {
            field: self.field(key),
            message,
            at: self
                .get(key)
                .map_or(self.at, |v| self.at_span(v.span().start)),
        }
    }

    fn at_span(&self, start: usize) -> At {
        At(Some(location(self.source, start)))
    }

    fn check_keys(&self, allowed: &[&str]) -> Result<(), SchemaError> {
        // Report the unknown key that comes first in the file.
        let unknown = self
            .table
            .iter()
            .filter(|(k, _)| !allowed.contains(&k.get_ref().as_ref()))
            .min_by_key(|(k, _)| k.span().start);
        match unknown {
            None => Ok(()),
            Some((k, _)) => {
                let name: &str = k.get_ref();
                let message = match closest(name, allowed) {
                    Some(s) => format!(
                        "did you mean `{s}`? expected one of: {}",
                        allowed.join(", ")
                    ),
                    None => format!("expected one of: {}", allowed.join(", ")),
                };
                Err(SchemaError::UnknownKey {
                    field: self.field(name),
                    message,
                    at: self.at_span(k.span().start),
                })
            }
        }
    }

    /// The raw value of `key`, if present.
    pub fn get(&self, key: &str) -> Option<&'a Spanned<DeValue<'i>>> {
        self.table.get(key)
    }

    fn missing(&self, key: &str) -> SchemaError {
        SchemaError::MissingKey {
            field: self.field(key),
            at: self.at,
        }
    }

    fn required(&self, key: &str) -> Result<&'a Spanned<DeValue<'i>>, SchemaError> {
        self.get(key).ok_or_else(|| self.missing(key))
    }

    fn invalid(&self, field: String, v: &Spanned<DeValue<'_>>, message: String) -> SchemaError {
        SchemaError::InvalidValue {
            field,
            message,
            at: self.at_span(v.span().start),
        }
    }

    /// An optional string at `key` that must be one of `allowed`: its index there, or `None`
    /// when absent. Any other string is an error that lists the choices.
    pub fn opt_choice(&self, key: &str, allowed: &[&str]) -> Result<Option<usize>, SchemaError> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        let s = self.string(key)?;
        match allowed.iter().position(|a| *a == s) {
            Some(i) => Ok(Some(i)),
            None => Err(self.invalid(
                self.field(key),
                v,
                format!("`{s}` is not one of: {}", allowed.join(", ")),
            )),
        }
    }

    fn expected(&self, field: String, v: &Spanned<DeValue<'_>>, what: &str) -> SchemaError {
        let message = format!("expected {what}, got {}", describe(v.get_ref()));
        self.invalid(field, v, message)
    }

    /// A number (float or integer) at `field`.
    fn number(&self, field: String, v: &Spanned<DeValue<'_>>) -> Result<f64, SchemaError> {
        match v.get_ref() {
            DeValue::Float(f) => {
                let s = f.as_str().replace('_', "").to_ascii_lowercase();
                Ok(if s.contains("nan") {
                    f64::NAN
                } else if s.contains("inf") {
                    if s.starts_with('-') {
                        f64::NEG_INFINITY
                    } else {
                        f64::INFINITY
                    }
                } else {
                    s.parse::<f64>()
                        .map_err(|_| self.expected(field, v, "a number"))?
                })
            }
            DeValue::Integer(_) => Ok(self.integer(field, v)? as f64),
            _ => Err(self.expected(field, v, "a number")),
        }
    }

    /// A TOML integer (64-bit signed) at `field`.
    fn integer(&self, field: String, v: &Spanned<DeValue<'_>>) -> Result<i64, SchemaError> {
        match v.get_ref() {
            DeValue::Integer(i) => {
                let digits = i.as_str().replace('_', "");
                i64::from_str_radix(&digits, i.radix()).map_err(|_| {
                    self.invalid(
                        field,
                        v,
                        format!(
                            "the integer {i} is outside TOML's 64-bit integer range \
                             (-9223372036854775808 to 9223372036854775807); write a large \
                             number as a float, e.g. 1e20"
                        ),
                    )
                })
            }
            _ => Err(self.expected(field, v, "an integer")),
        }
    }

    /// Required number.
    pub fn f64(&self, key: &str) -> Result<f64, SchemaError> {
        self.number(self.field(key), self.required(key)?)
    }

    /// Optional number.
    pub fn opt_f64(&self, key: &str) -> Result<Option<f64>, SchemaError> {
        self.get(key)
            .map(|v| self.number(self.field(key), v))
            .transpose()
    }

    /// Optional boolean.
    pub fn opt_bool(&self, key: &str) -> Result<Option<bool>, SchemaError> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => match v.get_ref() {
                DeValue::Boolean(b) => Ok(Some(*b)),
                _ => Err(self.expected(self.field(key), v, "true or false")),
            },
        }
    }

    /// Required integer within `lo..=hi`.
    pub fn int_in(&self, key: &str, lo: i64, hi: i64) -> Result<i64, SchemaError> {
        let v = self.required(key)?;
        let i = self.integer(self.field(key), v)?;
        if !(lo..=hi).contains(&i) {
            return Err(self.invalid(
                self.field(key),
                v,
                format!("must be an integer from {lo} to {hi} (got {i})"),
            ));
        }
        Ok(i)
    }

    /// Required string.
    pub fn string(&self, key: &str) -> Result<String, SchemaError> {
        let v = self.required(key)?;
        match v.get_ref() {
            DeValue::String(s) => Ok(s.to_string()),
            _ => Err(self.expected(self.field(key), v, "a string")),
        }
    }

    fn array_of<'v>(
        &self,
        field: &str,
        v: &'v Spanned<DeValue<'i>>,
        n: usize,
    ) -> Result<&'v [Spanned<DeValue<'i>>], SchemaError> {
        match v.get_ref() {
            DeValue::Array(a) if a.len() == n => Ok(a),
            DeValue::Array(a) => Err(self.invalid(
                field.to_string(),
                v,
                format!("expected {n} elements, got {}", a.len()),
            )),
            _ => Err(self.expected(field.to_string(), v, &format!("an array of {n} numbers"))),
        }
    }

    fn floats_of<const N: usize>(
        &self,
        field: &str,
        v: &Spanned<DeValue<'i>>,
    ) -> Result<[f64; N], SchemaError> {
        let a = self.array_of(field, v, N)?;
        let mut out = [0.0; N];
        for (i, (o, e)) in out.iter_mut().zip(a).enumerate() {
            *o = self.number(format!("{field}[{i}]"), e)?;
        }
        Ok(out)
    }

    /// Required array of exactly `N` numbers.
    pub fn floats<const N: usize>(&self, key: &str) -> Result<[f64; N], SchemaError> {
        self.floats_of(&self.field(key), self.required(key)?)
    }

    /// Optional array of exactly `N` numbers.
    pub fn opt_floats<const N: usize>(&self, key: &str) -> Result<Option<[f64; N]>, SchemaError> {
        self.get(key)
            .map(|v| self.floats_of(&self.field(key), v))
            .transpose()
    }

    /// Required array of numbers of any length (its length is checked by the caller, which
    /// knows what it must be).
    pub fn float_list(&self, key: &str) -> Result<Vec<f64>, SchemaError> {
        let field = self.field(key);
        let v = self.required(key)?;
        let DeValue::Array(a) = v.get_ref() else {
            return Err(self.expected(field, v, "an array of numbers"));
        };
        a.iter()
            .enumerate()
            .map(|(i, e)| self.number(format!("{field}[{i}]"), e))
            .collect()
    }

    /// Required array of 3-vectors of any length (`[[x, y, z], …]`; the caller checks the
    /// length).
    pub fn vec3_list(&self, key: &str) -> Result<Vec<[f64; 3]>, SchemaError> {
        let field = self.field(key);
        let v = self.required(key)?;
        let DeValue::Array(a) = v.get_ref() else {
            return Err(self.expected(field, v, "an array of [x, y, z] vectors"));
        };
        a.iter()
            .enumerate()
            .map(|(i, e)| self.floats_of::<3>(&format!("{field}[{i}]"), e))
            .collect()
    }

    fn mat3_of(&self, field: &str, v: &Spanned<DeValue<'i>>) -> Result<[[f64; 3]; 3], SchemaError> {
        let rows = match v.get_ref() {
            DeValue::Array(a) if a.len() == 3 => a,
            DeValue::Array(a) => {
                return Err(self.invalid(
                    field.to_string(),
                    v,
                    format!("expected 3 rows (a 3×3 matrix), got {}", a.len()),
                ))
            }
            _ => {
                return Err(self.expected(
                    field.to_string(),
                    v,
                    "a 3×3 matrix (an array of 3 rows of 3 numbers)",
                ))
            }
        };
        let mut out = [[0.0; 3]; 3];
        for (i, (o, row)) in out.iter_mut().zip(rows.iter()).enumerate() {
            *o = self.floats_of::<3>(&format!("{field}[{i}]"), row)?;
        }
        Ok(out)
    }

    /// Required 3×3 matrix, as an array of 3 rows of 3 numbers.
    pub fn mat3(&self, key: &str) -> Result<[[f64; 3]; 3], SchemaError> {
        self.mat3_of(&self.field(key), self.required(key)?)
    }

    /// Optional 3×3 matrix.
    pub fn opt_mat3(&self, key: &str) -> Result<Option<[[f64; 3]; 3]>, SchemaError> {
        self.get(key)
            .map(|v| self.mat3_of(&self.field(key), v))
            .transpose()
    }

    fn open(
        &self,
        path: String,
        v: &'a Spanned<DeValue<'i>>,
        allowed: &[&str],
    ) -> Result<TableReader<'a, 'i>, SchemaError> {
        match v.get_ref() {
            DeValue::Table(t) => {
                let r = TableReader {
                    source: self.source,
                    path,
                    table: t,
                    at: self.at_span(v.span().start),
                };
                r.check_keys(allowed)?;
                Ok(r)
            }
            DeValue::Array(_) => Err(self.invalid(
                path,
                v,
                format!(
                    "expected a table with named keys, got {} (a positional list is not \
                     accepted: write `{{ key = value, … }}` or a [table] section)",
                    describe(v.get_ref())
                ),
            )),
            _ => Err(self.expected(path, v, "a table")),
        }
    }

    /// Whether `key` is present; an error if it is present and not a table.
    pub fn is_table(&self, key: &str) -> Result<bool, SchemaError> {
        match self.get(key) {
            None => Ok(false),
            Some(v) if matches!(v.get_ref(), DeValue::Table(_)) => Ok(true),
            Some(v) => Err(self.expected(self.field(key), v, "a table")),
        }
    }

    /// Required sub-table (a `[section]` or an inline `{ … }` table).
    pub fn table(&self, key: &str, allowed: &[&str]) -> Result<TableReader<'a, 'i>, SchemaError> {
        self.open(self.field(key), self.required(key)?, allowed)
    }

    /// Optional sub-table.
    pub fn opt_table(
        &self,
        key: &str,
        allowed: &[&str],
    ) -> Result<Option<TableReader<'a, 'i>>, SchemaError> {
        self.get(key)
            .map(|v| self.open(self.field(key), v, allowed))
            .transpose()
    }

    /// An array of tables (`[[key]]` sections, or an array of inline tables); `None` if absent.
    pub fn tables(
        &self,
        key: &str,
        allowed: &[&str],
    ) -> Result<Option<Vec<TableReader<'a, 'i>>>, SchemaError> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        let field = self.field(key);
        let DeValue::Array(a) = v.get_ref() else {
            return Err(self.expected(field, v, "an array of tables"));
        };
        a.iter()
            .enumerate()
            .map(|(i, e)| self.open(format!("{field}[{i}]"), e, allowed))
            .collect::<Result<Vec<_>, _>>()
            .map(Some)
    }

    /// An optional array of tables, each entry read by `read`, in file order (empty if absent):
    /// the shape of every optional `[[section]]` of the configuration.
    pub fn read_tables<T, E: From<SchemaError>>(
        &self,
        key: &str,
        allowed: &[&str],
        read: impl Fn(&TableReader<'a, 'i>) -> Result<T, E>,
    ) -> Result<Vec<T>, E> {
        self.tables(key, allowed)?
            .unwrap_or_default()
            .iter()
            .map(read)
            .collect()
    }

    /// A required array of tables (may be empty: `key = []`).
    pub fn req_tables(
        &self,
        key: &str,
        allowed: &[&str],
    ) -> Result<Vec<TableReader<'a, 'i>>, SchemaError> {
        self.tables(key, allowed)?.ok_or_else(|| self.missing(key))
    }
}

/// The allowed key closest to `name` by edit distance, if it is a plausible typo.
fn closest<'k>(name: &str, allowed: &[&'k str]) -> Option<&'k str> {
    fn distance(a: &str, b: &str) -> usize {
        let b: Vec<char> = b.chars().collect();
        let mut prev: Vec<usize> = (0..=b.len()).collect();
        for (i, ca) in a.chars().enumerate() {
            let mut cur = vec![i + 1; b.len() + 1];
            for (j, cb) in b.iter().enumerate() {
                let sub = prev[j] + usize::from(ca != *cb);
                cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
            }
            prev = cur;
        }
        prev[b.len()]
    }
    allowed
        .iter()
        .map(|k| (distance(name, k), *k))
        .filter(|(d, k)| *d <= 3.max(k.len() / 4) && *d < k.len())
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggestions() {
        assert_eq!(closest("mass_lb", &["mass_kg", "d_m"]), Some("mass_kg"));
        assert_eq!(closest("colour", &["mass_kg", "r_bcb_b_m"]), None);
    }
}
