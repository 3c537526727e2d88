//! Source map: TOML paths ↔ text positions, and the whole-document finiteness pass.

use std::ops::Range;

use toml::de::{DeTable, DeValue};
use toml::Spanned;

use super::config_error::{param_field, ConfigError};
use super::{join_key, location, At};
use crate::validate::ParamError;

struct SpanEntry {
    span: Range<usize>,
    path: String,
    is_key: bool,
}

/// Every key and value of the document with its TOML path and byte span.
pub struct SourceMap<'s> {
    source: &'s str,
    entries: Vec<SpanEntry>,
}

impl<'s> SourceMap<'s> {
    /// The map of the parsed document `doc` of the text `source`.
    pub fn new(source: &'s str, doc: &DeTable<'_>) -> Self {
        let mut map = Self {
            source,
            entries: Vec::new(),
        };
        map.index_table(doc, "");
        map
    }

    fn index_table(&mut self, t: &DeTable<'_>, path: &str) {
        for (k, v) in t.iter() {
            let p = join_key(path, k.get_ref());
            self.entries.push(SpanEntry {
                span: k.span(),
                path: p.clone(),
                is_key: true,
            });
            self.index_value(v, p);
        }
    }

    fn index_value(&mut self, v: &Spanned<DeValue<'_>>, path: String) {
        self.entries.push(SpanEntry {
            span: v.span(),
            path: path.clone(),
            is_key: false,
        });
        match v.get_ref() {
            DeValue::Table(t) => self.index_table(t, &path),
            DeValue::Array(a) => {
                for (i, e) in a.iter().enumerate() {
                    self.index_value(e, format!("{path}[{i}]"));
                }
            }
            _ => {}
        }
    }

    /// Position of the value at `path` (or of its key) in the TOML text `source`, if it parses
    /// and has it: for errors found after the document was read (`[server]`, campaigns).
    pub fn locate(source: &str, path: &str) -> At {
        DeTable::parse(source)
            .map(|doc| SourceMap::new(source, doc.get_ref()).at(path))
            .unwrap_or_default()
    }

    /// Position of the key at `path` in `source` (an unknown key points at itself, as the
    /// schema reader's do).
    pub fn locate_key(source: &str, path: &str) -> At {
        let Ok(doc) = DeTable::parse(source) else {
            return At::default();
        };
        let map = SourceMap::new(source, doc.get_ref());
        let entry = map.entries.iter().find(|e| e.is_key && e.path == path);
        At(entry.map(|e| location(source, e.span.start)))
    }

    /// Position of the value at `path` (or of its key), if the document has it.
    pub fn at(&self, path: &str) -> At {
        let entry = self
            .entries
            .iter()
            .find(|e| !e.is_key && e.path == path)
            .or_else(|| self.entries.iter().find(|e| e.path == path));
        At(entry.map(|e| location(self.source, e.span.start)))
    }

    /// Rejects NaN and ±Inf anywhere in the document (including `[server]` and `[[imus]]`).
    pub fn check_all_finite(&self, doc: &DeTable<'_>) -> Result<(), ConfigError> {
        match self.first_non_finite(doc) {
            None => Ok(()),
            Some((field, at)) => Err(ConfigError::Param {
                source: ParamError::NotFinite { field },
                at,
            }),
        }
    }

    /// The TOML path and position of the first NaN or ±Inf in the document, if any (TOML
    /// accepts `nan` and `inf` literals; no flexdyn file does).
    pub fn first_non_finite(&self, doc: &DeTable<'_>) -> Option<(String, At)> {
        fn walk_table(t: &DeTable<'_>, path: &str, out: &mut Option<(String, usize)>) {
            for (k, v) in t.iter() {
                if out.is_some() {
                    return;
                }
                walk_value(v, join_key(path, k.get_ref()), out);
            }
        }
        fn walk_value(v: &Spanned<DeValue<'_>>, path: String, out: &mut Option<(String, usize)>) {
            match v.get_ref() {
                DeValue::Float(f) => {
                    let s = f.as_str().to_ascii_lowercase();
                    let finite = !s.contains("nan")
                        && !s.contains("inf")
                        && s.replace('_', "").parse::<f64>().is_ok_and(f64::is_finite);
                    if !finite && out.is_none() {
                        *out = Some((path, v.span().start));
                    }
                }
                DeValue::Table(t) => walk_table(t, &path, out),
                DeValue::Array(a) => {
                    for (i, e) in a.iter().enumerate() {
                        if out.is_some() {
                            return;
                        }
                        walk_value(e, format!("{path}[{i}]"), out);
                    }
                }
                _ => {}
            }
        }
        let mut found = None;
        walk_table(doc, "", &mut found);
        found.map(|(field, offset)| (field, At(Some(location(self.source, offset)))))
    }

    /// A parameter error, located at the field it names.
    pub fn param_error(&self, source: ParamError) -> ConfigError {
        let at = param_field(&source).map(|f| self.at(f)).unwrap_or_default();
        ConfigError::Param { source, at }
    }

    /// A timing error at `field`, located.
    pub fn timing(&self, field: &str, problem: String) -> ConfigError {
        ConfigError::Timing {
            field: field.to_string(),
            problem,
            at: self.at(field),
        }
    }

    /// A gravity-model error at `field`, located.
    pub fn gravity(&self, field: &str, problem: String) -> ConfigError {
        ConfigError::Gravity {
            field: field.to_string(),
            problem,
            at: self.at(field),
        }
    }

    /// A wrench-schedule error at `field`, located.
    pub fn wrench_order(&self, field: &str, problem: String) -> ConfigError {
        ConfigError::WrenchSchedule {
            field: field.to_string(),
            problem,
            at: self.at(field),
        }
    }

    /// Position of `field`, or of its nearest enclosing table the document has (for an absent
    /// key); a field such as `epoch.utc (or epoch.tai)` is looked up by its first word.
    pub fn near(&self, field: &str) -> At {
        let mut path = field.split(' ').next().unwrap_or(field);
        loop {
            let at = self.at(path);
            if at.0.is_some() {
                return at;
            }
            match path.rfind(['.', '[']) {
                Some(i) => path = &path[..i],
                None => return at,
            }
        }
    }

    /// A map of no document (errors then carry no position): a live fault command's checks.
    pub fn empty() -> SourceMap<'static> {
        SourceMap {
            source: "",
            entries: Vec::new(),
        }
    }

    /// `field` is invalid because of `problem`, located.
    pub fn invalid(&self, field: &str, problem: String) -> ConfigError {
        ConfigError::Invalid {
            field: field.to_string(),
            problem,
            at: self.at(field),
        }
    }
}
