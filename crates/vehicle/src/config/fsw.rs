//! `[[fsw_streams]]`: the dictionary of the flight code's own telemetry streams.
//!
//! Flight code publishes samples of its stream `<name>` as [`FswMsg`] on
//! `flexdyn/<sc-id>/fsw/<name>` (protocol 10). The configuration declares each stream: its modes
//! (a sample's `mode` is an index in them), its events (a sample's `events` are indices in them,
//! each event with a severity) and its values (a sample's `values` hold one 8-byte word per
//! element of them, in declaration order):
//!
//! ```toml
//! [[fsw_streams]]
//! name = "acs"                     # 1–64 characters of [A-Za-z0-9_-]: a key chunk
//! modes = ["detumble", "sun_acquisition", "inertial_hold"]   # optional
//! events = [                       # optional; severity "info" (default), "warning", "error"
//!   { name = "gyro_fault", severity = "error" },             # or "critical"
//!   { name = "detumbled" },
//! ]
//! values = [                       # optional; type "f64", "i64" or "bool"; len ≥ 1 (default
//!   { name = "h_wheels_b_nms", type = "f64", len = 3, unit = "N·m·s" },   # 1); unit optional
//!   { name = "fdir_flags", type = "i64" },
//!   { name = "sun_valid", type = "bool" },
//! ]
//! ```
//!
//! Stream names are unique across the list; mode, event and value names are unique within their
//! stream and are 1–64 characters of `[A-Za-z0-9_.-]` (they become CSV column names and JSON
//! keys). A stream's value lengths add up to at most [`MAX_FSW_VALUES`] words.
//!
//! The file is read in the configuration's passes: keys and types in pass 2, then names, choices,
//! lengths and limits in pass 4 (errors name the field, e.g. `fsw_streams[0].values[1].type`).
//! [`FswStreamDecl::check`] then checks each sample the server receives against its stream's
//! declaration.

use std::collections::HashSet;

use toml::de::DeValue;
use toml::Spanned;

use flexdyn_kernel::schema::{SchemaError, TableReader};
use flexdyn_proto::keys::validate_sensor_name;
use flexdyn_proto::view::FswView;
use flexdyn_proto::{fsw_flags, FswMsg, KeyError, MAX_FSW_VALUES};

use super::{ConfigError, SourceMap};

/// The most streams one configuration declares.
pub const MAX_FSW_STREAMS: usize = 64;

/// The most modes one stream declares.
pub const MAX_FSW_DECLARED_MODES: usize = 65_536;

/// The most events one stream declares (an event index is a `u16`).
pub const MAX_FSW_DECLARED_EVENTS: usize = 1 << 16;

/// The longest mode, event or value name (and stream name, [`flexdyn_proto::MAX_ID_LEN`]).
pub const MAX_FSW_NAME_LEN: usize = 64;

/// Keys of an `[[fsw_streams]]` entry.
pub(super) const KEYS: [&str; 4] = ["name", "modes", "events", "values"];

/// Keys of an entry of a stream's `events`.
const EVENT_KEYS: [&str; 2] = ["name", "severity"];

/// Keys of an entry of a stream's `values`.
const VALUE_KEYS: [&str; 4] = ["name", "type", "len", "unit"];

// ---------------------------------------------------------------------------------------------
// The dictionary.

/// How serious a flight-code event is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FswSeverity {
    /// `"info"` (the default).
    Info,
    /// `"warning"`.
    Warning,
    /// `"error"`.
    Error,
    /// `"critical"`.
    Critical,
}

impl FswSeverity {
    /// Every severity, least serious first.
    pub const ALL: [FswSeverity; 4] = [Self::Info, Self::Warning, Self::Error, Self::Critical];

    /// The severity's name, as in the configuration file.
    pub fn name(self) -> &'static str {
        match self {
            Self::Info => "info",
            Self::Warning => "warning",
            Self::Error => "error",
            Self::Critical => "critical",
        }
    }

    /// The severity named `name` (as in the configuration file), if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}

/// The type of a declared value: how each of its 8-byte words is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FswValueType {
    /// `"f64"`: the word is the IEEE-754 bits of an f64 ([`f64::from_bits`]); it must be finite.
    F64,
    /// `"i64"`: the word is an i64 in two's complement (`as i64`).
    I64,
    /// `"bool"`: the word is 0 (false) or 1 (true).
    Bool,
}

impl FswValueType {
    /// Every type, in the order the configuration's messages list them.
    pub const ALL: [FswValueType; 3] = [Self::F64, Self::I64, Self::Bool];

    /// The type's name, as in the configuration file.
    pub fn name(self) -> &'static str {
        match self {
            Self::F64 => "f64",
            Self::I64 => "i64",
            Self::Bool => "bool",
        }
    }

    /// The type named `name` (as in the configuration file), if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }
}

/// One declared event of a stream.
#[derive(Clone, Debug, PartialEq)]
pub struct FswEventDecl {
    /// The event's name (unique in its stream).
    pub name: String,
    /// How serious it is.
    pub severity: FswSeverity,
}

/// One declared value of a stream: `len` consecutive words of a sample's `values`.
#[derive(Clone, Debug, PartialEq)]
pub struct FswValueDecl {
    /// The value's name (unique in its stream).
    pub name: String,
    /// How its words are read.
    pub ty: FswValueType,
    /// Its number of elements (words), ≥ 1.
    pub len: usize,
    /// Its unit as written (`""` if none was given), e.g. `"N·m·s"`.
    pub unit: String,
    /// The index of its first word in a sample's `values` (the lengths of the values declared
    /// before it, added).
    pub offset: usize,
}

impl FswValueDecl {
    /// The name of element `k`: the value's name if it has one element, else `name[k]` (e.g.
    /// `h_wheels_b_nms[2]`); a recorder's column name.
    pub fn element_name(&self, k: usize) -> String {
        if self.len == 1 {
            self.name.clone()
        } else {
            format!("{}[{k}]", self.name)
        }
    }

    /// This value's words among a sample's `values`, or `None` if they are too few.
    pub fn words_of<'w>(&self, values: &'w [u64]) -> Option<&'w [u64]> {
        values.get(self.offset..self.offset.checked_add(self.len)?)
    }

    /// This value's elements decoded from a sample's `values` (as [`Self::words_of`]).
    pub fn decode(&self, values: &[u64]) -> Option<FswValues> {
        let words = self.words_of(values)?;
        Some(match self.ty {
            FswValueType::F64 => FswValues::F64(words.iter().map(|&w| f64::from_bits(w)).collect()),
            FswValueType::I64 => FswValues::I64(words.iter().map(|&w| w as i64).collect()),
            FswValueType::Bool => FswValues::Bool(words.iter().map(|&w| w != 0).collect()),
        })
    }
}

/// The elements of one declared value of a sample, decoded by its type.
#[derive(Clone, Debug, PartialEq)]
pub enum FswValues {
    /// An `"f64"` value's elements.
    F64(Vec<f64>),
    /// An `"i64"` value's elements.
    I64(Vec<i64>),
    /// A `"bool"` value's elements (any nonzero word is true).
    Bool(Vec<bool>),
}

/// One word of a value of type `ty` as an f64: an f64's bits as the f64, an i64 converted
/// (`as f64`, rounded beyond 2⁵³), a bool as 0.0 or 1.0 (any nonzero word is 1.0).
pub fn word_as_f64(ty: FswValueType, word: u64) -> f64 {
    match ty {
        FswValueType::F64 => f64::from_bits(word),
        FswValueType::I64 => word as i64 as f64,
        FswValueType::Bool => {
            if word == 0 {
                0.0
            } else {
                1.0
            }
        }
    }
}

/// One declared flight-code telemetry stream (`[[fsw_streams]]` entry), validated.
#[derive(Clone, Debug, PartialEq)]
pub struct FswStreamDecl {
    /// The stream's name: the last chunk of its key `flexdyn/<sc-id>/fsw/<name>`.
    pub name: String,
    /// Its modes: a sample's `mode` is an index here.
    pub modes: Vec<String>,
    /// Its events: a sample's `events` are indices here.
    pub events: Vec<FswEventDecl>,
    /// Its values, in declaration order, each with its offset in a sample's `values`.
    pub values: Vec<FswValueDecl>,
}

impl FswStreamDecl {
    /// The number of words a sample's `values` hold: the declared lengths, added (at most
    /// [`MAX_FSW_VALUES`]).
    pub fn words(&self) -> usize {
        self.values.iter().map(|v| v.len).sum()
    }

    /// The value named `name`, if declared.
    pub fn value(&self, name: &str) -> Option<&FswValueDecl> {
        self.values.iter().find(|v| v.name == name)
    }

    /// The index of mode `name` (a sample's `mode`), if declared.
    pub fn mode_index(&self, name: &str) -> Option<u32> {
        let i = self.modes.iter().position(|m| m == name)?;
        u32::try_from(i).ok()
    }

    /// The index of event `name` (an entry of a sample's `events`), if declared.
    pub fn event_index(&self, name: &str) -> Option<u16> {
        let i = self.events.iter().position(|e| e.name == name)?;
        u16::try_from(i).ok()
    }

    /// Checks a sample of this stream against the declaration: the mode (when `flags` has
    /// [`fsw_flags::MODE`]) and each event are declared, `values` holds [`Self::words`] words,
    /// each f64 word is finite, each bool word is 0 or 1, and [`fsw_flags::COVARIANCE`] comes
    /// with [`fsw_flags::ESTIMATE`]. The first problem found, in that order, is the refusal.
    ///
    /// It allocates nothing unless it refuses.
    pub fn check(&self, msg: &FswMsg) -> Result<(), FswRefusal> {
        self.check_sample(
            msg.flags,
            msg.mode,
            msg.event_indices(),
            msg.values.len(),
            |i| msg.values.get(i).copied().unwrap_or(0),
        )
    }

    /// [`Self::check`] of a sample read in place (what the server runs for every sample it
    /// receives, on a thread that may step the frames): allocates nothing unless it refuses.
    pub fn check_view(&self, v: &FswView<'_>) -> Result<(), FswRefusal> {
        let events = v.events();
        let values = v.values();
        self.check_sample(
            v.flags(),
            v.mode(),
            &events[..usize::from(v.event_count()).min(events.len())],
            values.len(),
            |i| values.get(i).unwrap_or(0),
        )
    }

    /// [`Self::check`] of a sample's parts: its flags, mode, event indices, and `n` value
    /// words, word `i` being `word(i)`.
    fn check_sample(
        &self,
        flags: u8,
        mode: u32,
        events: &[u16],
        n: usize,
        word: impl Fn(usize) -> u64,
    ) -> Result<(), FswRefusal> {
        if flags & fsw_flags::MODE != 0
            && usize::try_from(mode).map_or(true, |m| m >= self.modes.len())
        {
            return Err(FswRefusal::UnknownMode {
                index: mode,
                declared: self.modes.len(),
            });
        }
        if let Some(&index) = events
            .iter()
            .find(|&&e| usize::from(e) >= self.events.len())
        {
            return Err(FswRefusal::UnknownEvent {
                index,
                declared: self.events.len(),
            });
        }
        let declared = self.words();
        if n != declared {
            return Err(FswRefusal::WrongCount { got: n, declared });
        }
        // Exactly the declared words: walk them in declaration order.
        for v in &self.values {
            for k in 0..v.len {
                let w = word(v.offset + k);
                match v.ty {
                    FswValueType::F64 if !f64::from_bits(w).is_finite() => {
                        return Err(FswRefusal::NonFinite {
                            value: v.element_name(k),
                        });
                    }
                    FswValueType::Bool if w > 1 => {
                        return Err(FswRefusal::NotBool {
                            value: v.element_name(k),
                            word: w,
                        });
                    }
                    _ => {}
                }
            }
        }
        if flags & fsw_flags::COVARIANCE != 0 && flags & fsw_flags::ESTIMATE == 0 {
            return Err(FswRefusal::CovarianceWithoutEstimate);
        }
        Ok(())
    }
}

/// Why [`FswStreamDecl::check`] refused a sample.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FswRefusal {
    /// `flags` has MODE and `mode` is not an index in the stream's modes.
    #[error("mode {index} is not declared (the stream declares {declared} modes)")]
    UnknownMode {
        /// The sample's `mode`.
        index: u32,
        /// How many modes the stream declares.
        declared: usize,
    },
    /// An event index is not an index in the stream's events.
    #[error("event {index} is not declared (the stream declares {declared} events)")]
    UnknownEvent {
        /// The first undeclared event index.
        index: u16,
        /// How many events the stream declares.
        declared: usize,
    },
    /// `values` does not hold the declared number of words.
    #[error("{got} value words, the stream declares {declared}")]
    WrongCount {
        /// How many words the sample holds.
        got: usize,
        /// How many the stream declares ([`FswStreamDecl::words`]).
        declared: usize,
    },
    /// An f64 element is NaN or infinite.
    #[error("{value} is not finite")]
    NonFinite {
        /// The element, by [`FswValueDecl::element_name`] (e.g. `h_wheels_b_nms[2]`).
        value: String,
    },
    /// A bool element is neither 0 nor 1.
    #[error("{value} is a bool, but its word is {word} (not 0 or 1)")]
    NotBool {
        /// The element, by [`FswValueDecl::element_name`].
        value: String,
        /// Its word.
        word: u64,
    },
    /// `flags` has COVARIANCE without ESTIMATE.
    #[error("COVARIANCE is set without ESTIMATE (the variances are of an estimate)")]
    CovarianceWithoutEstimate,
}

impl FswRefusal {
    /// The refusal's short snake_case reason (`unknown_mode`, `unknown_event`, `wrong_count`,
    /// `non_finite`, `not_bool`, `covariance_without_estimate`), for logs and counters.
    pub fn reason(&self) -> &'static str {
        match self {
            Self::UnknownMode { .. } => "unknown_mode",
            Self::UnknownEvent { .. } => "unknown_event",
            Self::WrongCount { .. } => "wrong_count",
            Self::NonFinite { .. } => "non_finite",
            Self::NotBool { .. } => "not_bool",
            Self::CovarianceWithoutEstimate => "covariance_without_estimate",
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Pass 2: keys and types.

/// One `[[fsw_streams]]` entry as written.
pub(super) struct RawFswStream {
    name: String,
    modes: Vec<String>,
    events: Vec<RawEvent>,
    values: Vec<RawValue>,
}

/// One entry of a stream's `events` as written.
struct RawEvent {
    name: String,
    severity: Option<String>,
}

/// One entry of a stream's `values` as written.
struct RawValue {
    name: String,
    ty: String,
    len: Option<i64>,
    unit: Option<String>,
}

/// An optional string at `key`.
fn opt_string(t: &TableReader<'_, '_>, key: &str) -> Result<Option<String>, SchemaError> {
    t.get(key).map(|_| t.string(key)).transpose()
}

/// A TOML value's kind, as the schema reader's messages name it.
fn kind(v: &Spanned<DeValue<'_>>) -> &'static str {
    match v.get_ref() {
        DeValue::String(_) => "a string",
        DeValue::Integer(_) => "an integer",
        DeValue::Float(_) => "a float",
        DeValue::Boolean(_) => "a boolean",
        DeValue::Datetime(_) => "a datetime",
        DeValue::Array(_) => "an array",
        DeValue::Table(_) => "a table",
    }
}

/// An optional array of strings at `key` (empty if absent).
fn string_list(
    t: &TableReader<'_, '_>,
    key: &str,
    map: &SourceMap,
) -> Result<Vec<String>, ConfigError> {
    let Some(v) = t.get(key) else {
        return Ok(Vec::new());
    };
    let wrong = |field: String, what: &str, v: &Spanned<DeValue<'_>>| {
        ConfigError::Schema(SchemaError::InvalidValue {
            message: format!("expected {what}, got {}", kind(v)),
            at: map.at(&field),
            field,
        })
    };
    let field = t.field(key);
    let DeValue::Array(a) = v.get_ref() else {
        return Err(wrong(field, "an array of strings", v));
    };
    a.iter()
        .enumerate()
        .map(|(i, e)| match e.get_ref() {
            DeValue::String(s) => Ok(s.to_string()),
            _ => Err(wrong(format!("{field}[{i}]"), "a string", e)),
        })
        .collect()
}

impl RawFswStream {
    /// Pass 2: the entry's keys and types (opened with [`KEYS`]).
    pub(super) fn read(t: &TableReader<'_, '_>, map: &SourceMap) -> Result<Self, ConfigError> {
        Ok(Self {
            name: t.string("name")?,
            modes: string_list(t, "modes", map)?,
            events: t.read_tables("events", &EVENT_KEYS, |e| {
                Ok::<_, SchemaError>(RawEvent {
                    name: e.string("name")?,
                    severity: opt_string(e, "severity")?,
                })
            })?,
            values: t.read_tables("values", &VALUE_KEYS, |v| {
                Ok::<_, SchemaError>(RawValue {
                    name: v.string("name")?,
                    ty: v.string("type")?,
                    // Any integer here; pass 4 says what is wrong with it.
                    len: v
                        .get("len")
                        .map(|_| v.int_in("len", i64::MIN, i64::MAX))
                        .transpose()?,
                    unit: opt_string(v, "unit")?,
                })
            })?,
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Pass 4: names, choices, lengths and limits.

/// `field` is invalid because of `problem`, located at the field or, when the file leaves it
/// out (a default), at its table.
fn invalid(map: &SourceMap, field: &str, problem: String) -> ConfigError {
    ConfigError::Invalid {
        field: field.to_string(),
        problem,
        at: map.near(field),
    }
}

/// Checks the mode, event or value name at `field`: 1–[`MAX_FSW_NAME_LEN`] characters of
/// `[A-Za-z0-9_.-]`, not already in `seen` (then adds it).
fn check_name<'n>(
    map: &SourceMap,
    field: &str,
    name: &'n str,
    seen: &mut HashSet<&'n str>,
    what: &str,
) -> Result<(), ConfigError> {
    if name.is_empty() {
        return Err(invalid(map, field, "must not be empty".into()));
    }
    if let Some(c) = name
        .chars()
        .find(|&c| !(c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-')))
    {
        return Err(invalid(
            map,
            field,
            format!(
                "`{name}` contains {c:?}: a {what} name is 1 to {MAX_FSW_NAME_LEN} characters of \
                 A-Z, a-z, 0-9, `_`, `.` and `-` (it becomes a CSV column name and a JSON key)"
            ),
        ));
    }
    if name.len() > MAX_FSW_NAME_LEN {
        return Err(invalid(
            map,
            field,
            format!(
                "`{name}` is {} characters long: a {what} name is at most {MAX_FSW_NAME_LEN}",
                name.len()
            ),
        ));
    }
    if !seen.insert(name) {
        return Err(invalid(
            map,
            field,
            format!("duplicate {what} name `{name}` (names must be unique within the stream)"),
        ));
    }
    Ok(())
}

/// `allowed` as a message lists them: `"a", "b", "c"`.
fn quoted(allowed: impl Iterator<Item = &'static str>) -> String {
    allowed
        .map(|a| format!("\"{a}\""))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Pass 4: validates every stream; errors name the entry and the field.
/// The `[[fsw_streams]]` of the configuration text `source` alone, read and validated as
/// [`super::SimConfig`] reads them (the same errors), without reading or building the rest:
/// what the readers of a recording need, where the configuration's relative file paths may not
/// resolve and its vehicle need not be built.
pub fn read_streams(source: &str) -> Result<Vec<FswStreamDecl>, ConfigError> {
    let doc = super::parse_document(source)?;
    let map = SourceMap::new(source, doc.get_ref());
    // Every other root key is the rest of the configuration's, not checked here.
    let keys: Vec<&str> = doc.get_ref().keys().map(|k| k.get_ref().as_ref()).collect();
    let root = TableReader::root(source, doc.get_ref(), &keys)?;
    let raw = root.read_tables("fsw_streams", &KEYS, |t| RawFswStream::read(t, &map))?;
    resolve(&raw, &map)
}

pub(super) fn resolve(
    raw: &[RawFswStream],
    map: &SourceMap,
) -> Result<Vec<FswStreamDecl>, ConfigError> {
    if raw.len() > MAX_FSW_STREAMS {
        return Err(invalid(
            map,
            "fsw_streams",
            format!(
                "{} streams declared: a configuration declares at most {MAX_FSW_STREAMS}",
                raw.len()
            ),
        ));
    }
    let mut stream_names = HashSet::new();
    let mut streams = Vec::with_capacity(raw.len());
    for (i, s) in raw.iter().enumerate() {
        let path = format!("fsw_streams[{i}]");
        let field = format!("{path}.name");
        if let Err(e) = validate_sensor_name(&s.name) {
            let rule = format!(
                "a stream name is 1 to {} characters of A-Z, a-z, 0-9, `_` and `-` (the last \
                 chunk of the key flexdyn/<sc-id>/fsw/<name>)",
                flexdyn_proto::MAX_ID_LEN
            );
            let problem = match e {
                KeyError::Empty { .. } => "must not be empty".to_string(),
                KeyError::InvalidChar { ch, .. } => format!("`{}` contains {ch:?}: {rule}", s.name),
                e => format!("`{}` is not a valid stream name ({e}): {rule}", s.name),
            };
            return Err(invalid(map, &field, problem));
        }
        if !stream_names.insert(s.name.as_str()) {
            return Err(invalid(
                map,
                &field,
                format!(
                    "duplicate stream name `{}` (stream names must be unique)",
                    s.name
                ),
            ));
        }

        if s.modes.len() > MAX_FSW_DECLARED_MODES {
            return Err(invalid(
                map,
                &format!("{path}.modes"),
                format!(
                    "{} modes declared: a stream declares at most {MAX_FSW_DECLARED_MODES}",
                    s.modes.len()
                ),
            ));
        }
        let mut seen = HashSet::new();
        for (j, m) in s.modes.iter().enumerate() {
            check_name(map, &format!("{path}.modes[{j}]"), m, &mut seen, "mode")?;
        }

        if s.events.len() > MAX_FSW_DECLARED_EVENTS {
            return Err(invalid(
                map,
                &format!("{path}.events"),
                format!(
                    "{} events declared: a stream declares at most {MAX_FSW_DECLARED_EVENTS} \
                     (an event index is 16 bits)",
                    s.events.len()
                ),
            ));
        }
        let mut seen = HashSet::new();
        let mut events = Vec::with_capacity(s.events.len());
        for (j, e) in s.events.iter().enumerate() {
            let epath = format!("{path}.events[{j}]");
            check_name(map, &format!("{epath}.name"), &e.name, &mut seen, "event")?;
            let severity = match e.severity.as_deref() {
                None => FswSeverity::Info,
                Some(name) => FswSeverity::from_name(name).ok_or_else(|| {
                    invalid(
                        map,
                        &format!("{epath}.severity"),
                        format!(
                            "must be one of {}, got \"{name}\"",
                            quoted(FswSeverity::ALL.iter().map(|s| s.name()))
                        ),
                    )
                })?,
            };
            events.push(FswEventDecl {
                name: e.name.clone(),
                severity,
            });
        }

        let mut seen = HashSet::new();
        let mut values = Vec::with_capacity(s.values.len());
        let mut offset = 0usize;
        for (j, v) in s.values.iter().enumerate() {
            let vpath = format!("{path}.values[{j}]");
            check_name(map, &format!("{vpath}.name"), &v.name, &mut seen, "value")?;
            let ty = FswValueType::from_name(&v.ty).ok_or_else(|| {
                invalid(
                    map,
                    &format!("{vpath}.type"),
                    format!(
                        "must be one of {}, got \"{}\"",
                        quoted(FswValueType::ALL.iter().map(|t| t.name())),
                        v.ty
                    ),
                )
            })?;
            let len_field = format!("{vpath}.len");
            let len = match v.len {
                None => 1,
                Some(n) if n >= 1 => usize::try_from(n).unwrap_or(usize::MAX),
                Some(n) => {
                    return Err(invalid(
                        map,
                        &len_field,
                        format!("must be at least 1, got {n}"),
                    ))
                }
            };
            // offset ≤ MAX_FSW_VALUES here, so this neither overflows nor lets the sum past it.
            if len > MAX_FSW_VALUES - offset {
                return Err(invalid(
                    map,
                    &len_field,
                    format!(
                        "the stream's values take {} words up to this one, more than one FswMsg \
                         carries ({MAX_FSW_VALUES}): the value lengths of a stream add up to at \
                         most that",
                        offset.saturating_add(len)
                    ),
                ));
            }
            values.push(FswValueDecl {
                name: v.name.clone(),
                ty,
                len,
                unit: v.unit.clone().unwrap_or_default(),
                offset,
            });
            offset += len;
        }

        streams.push(FswStreamDecl {
            name: s.name.clone(),
            modes: s.modes.clone(),
            events,
            values,
        });
    }
    Ok(streams)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{SimConfig, DEFAULT_CONFIG_TOML};

    /// The example of the module documentation.
    const ACS: &str = r#"
[[fsw_streams]]
name = "acs"
modes = ["detumble", "sun_acquisition", "inertial_hold"]
events = [
  { name = "gyro_fault", severity = "error" },
  { name = "detumbled" },
]
values = [
  { name = "h_wheels_b_nms", type = "f64", len = 3, unit = "N·m·s" },
  { name = "fdir_flags", type = "i64" },
  { name = "sun_valid", type = "bool" },
]
"#;

    /// `read_streams` reads the streams alone, exactly as the whole configuration does: the
    /// same declarations, the same errors; and a configuration the vehicle of which does not
    /// build (here a negative hub mass) still gives its streams.
    #[test]
    fn the_streams_are_read_alone_as_the_configuration_reads_them() {
        let whole = parse(ACS).unwrap();
        assert_eq!(read_streams(&text(ACS)).unwrap(), whole.fsw_streams);
        assert_eq!(read_streams(DEFAULT_CONFIG_TOML).unwrap(), Vec::new());
        let broken = text(ACS).replacen("mass_kg = 750.0", "mass_kg = -750.0", 1);
        assert!(
            SimConfig::from_toml_str(&broken).is_err(),
            "the hub mass is refused"
        );
        assert_eq!(read_streams(&broken).unwrap(), whole.fsw_streams);
        let bad = ACS.replace("type = \"i64\"", "type = \"i32\"");
        assert_eq!(
            read_streams(&text(&bad)).unwrap_err().to_string(),
            parse(&bad).unwrap_err().to_string()
        );
        let e = read_streams("[[fsw_streams]\n").unwrap_err();
        assert!(matches!(e, ConfigError::Syntax { line: 1, .. }), "{e}");
    }

    /// The reference configuration with `extra` appended.
    fn text(extra: &str) -> String {
        format!("{DEFAULT_CONFIG_TOML}\n{extra}")
    }

    fn parse(extra: &str) -> Result<SimConfig, ConfigError> {
        SimConfig::from_toml_str(&text(extra))
    }

    /// The error's message, which must be about `field`.
    fn error(extra: &str, field: &str) -> String {
        let e = parse(extra).expect_err("must be refused");
        assert_eq!(e.field(), Some(field), "{e}");
        e.to_string()
    }

    /// ` (line L, column C)` of byte `offset` of `extra` in the configuration it makes.
    fn at_offset(extra: &str, offset: usize) -> String {
        let t = text(extra);
        let before = &t[..DEFAULT_CONFIG_TOML.len() + 1 + offset];
        let line = before.matches('\n').count() + 1;
        let column = before[before.rfind('\n').map_or(0, |i| i + 1)..]
            .chars()
            .count()
            + 1;
        format!(" (line {line}, column {column})")
    }

    /// The position of the first occurrence of `needle` in `extra`, as [`at_offset`].
    fn at(extra: &str, needle: &str) -> String {
        at_offset(extra, extra.find(needle).expect("needle in extra"))
    }

    /// The position of the last occurrence of `needle` in `extra`, as [`at_offset`].
    fn at_last(extra: &str, needle: &str) -> String {
        at_offset(extra, extra.rfind(needle).expect("needle in extra"))
    }

    fn acs() -> FswStreamDecl {
        let cfg = parse(ACS).expect("the example parses");
        cfg.fsw_stream("acs").expect("stream acs").clone()
    }

    /// A sample of `acs` that its declaration accepts.
    fn good_sample() -> FswMsg {
        FswMsg {
            flags: fsw_flags::MODE | fsw_flags::ESTIMATE | fsw_flags::COVARIANCE,
            mode: 2,
            event_count: 2,
            events: [1, 0, 0, 0, 0, 0, 0, 0],
            values: vec![
                0.5f64.to_bits(),
                (-0.25f64).to_bits(),
                0.0f64.to_bits(),
                (-7i64) as u64,
                1,
            ],
            ..Default::default()
        }
    }

    #[test]
    fn example_dictionary_parses() {
        let cfg = parse(ACS).expect("the example parses");
        assert_eq!(cfg.fsw_streams.len(), 1);
        let s = &cfg.fsw_streams[0];
        assert_eq!(s.name, "acs");
        assert_eq!(s.modes, ["detumble", "sun_acquisition", "inertial_hold"]);
        let offsets: Vec<usize> = s.values.iter().map(|v| v.offset).collect();
        assert_eq!(offsets, [0, 3, 4]);
        let lens: Vec<usize> = s.values.iter().map(|v| v.len).collect();
        assert_eq!(lens, [3, 1, 1]);
        assert_eq!(s.words(), 5);
        let types: Vec<FswValueType> = s.values.iter().map(|v| v.ty).collect();
        assert_eq!(
            types,
            [FswValueType::F64, FswValueType::I64, FswValueType::Bool]
        );
        assert_eq!(s.values[0].unit, "N·m·s");
        assert_eq!(s.values[1].unit, "");
        assert_eq!(
            s.events,
            [
                FswEventDecl {
                    name: "gyro_fault".into(),
                    severity: FswSeverity::Error
                },
                FswEventDecl {
                    name: "detumbled".into(),
                    severity: FswSeverity::Info
                },
            ]
        );
        assert_eq!(s.mode_index("inertial_hold"), Some(2));
        assert_eq!(s.mode_index("safe"), None);
        assert_eq!(s.event_index("detumbled"), Some(1));
        assert_eq!(s.event_index("gyro_fault"), Some(0));
        assert_eq!(s.event_index("nothing"), None);
        assert_eq!(s.value("fdir_flags").map(|v| v.offset), Some(3));
        assert_eq!(s.value("nothing"), None);
        assert_eq!(cfg.fsw_stream("acs"), Some(s));
        assert_eq!(cfg.fsw_stream("gnc"), None);
    }

    #[test]
    fn absent_section_and_empty_lists() {
        let cfg = parse("").expect("reference parses");
        assert!(cfg.fsw_streams.is_empty());
        let cfg = parse("[[fsw_streams]]\nname = \"bare\"\n").expect("a bare stream parses");
        let s = &cfg.fsw_streams[0];
        assert!(s.modes.is_empty() && s.events.is_empty() && s.values.is_empty());
        assert_eq!(s.words(), 0);
        // Several streams, each with its own offsets; the last word fits exactly.
        let cfg = parse(&format!(
            "{ACS}\n[[fsw_streams]]\nname = \"gnc-2\"\nvalues = [{{ name = \"a.b\", type = \
             \"f64\", len = 255 }}, {{ name = \"c\", type = \"bool\" }}]\n"
        ))
        .expect("two streams parse");
        let gnc = cfg.fsw_stream("gnc-2").expect("second stream");
        assert_eq!(gnc.values[1].offset, 255);
        assert_eq!(gnc.words(), MAX_FSW_VALUES);
    }

    #[test]
    fn refuses_duplicate_stream_name() {
        let extra = format!("{ACS}\n[[fsw_streams]]\nname = \"acs\"\n");
        let msg = error(&extra, "fsw_streams[1].name");
        assert_eq!(
            msg,
            format!(
                "fsw_streams[1].name: duplicate stream name `acs` (stream names must be \
                 unique){}",
                at_last(&extra, "\"acs\"")
            )
        );
    }

    #[test]
    fn refuses_duplicate_value_mode_and_event_names() {
        let extra = ACS.replace("\"fdir_flags\"", "\"h_wheels_b_nms\"");
        let msg = error(&extra, "fsw_streams[0].values[1].name");
        assert!(
            msg.starts_with("fsw_streams[0].values[1].name: duplicate value name `h_wheels_b_nms`"),
            "{msg}"
        );
        let extra = ACS.replace("\"inertial_hold\"", "\"detumble\"");
        let msg = error(&extra, "fsw_streams[0].modes[2]");
        assert!(msg.contains("duplicate mode name `detumble`"), "{msg}");
        let extra = ACS.replace("\"detumbled\"", "\"gyro_fault\"");
        let msg = error(&extra, "fsw_streams[0].events[1].name");
        assert!(msg.contains("duplicate event name `gyro_fault`"), "{msg}");
        // The same name in two streams is fine.
        parse(&format!(
            "{ACS}\n[[fsw_streams]]\nname = \"b\"\nmodes = [\"detumble\"]\n"
        ))
        .expect("mode names are per stream");
    }

    #[test]
    fn refuses_bad_type_with_its_location() {
        let extra = ACS.replace("type = \"i64\"", "type = \"f32\"");
        let msg = error(&extra, "fsw_streams[0].values[1].type");
        let expected = format!(
            "fsw_streams[0].values[1].type: must be one of \"f64\", \"i64\", \"bool\", got \
             \"f32\"{}",
            at(&extra, "\"f32\"")
        );
        assert_eq!(msg, expected);
    }

    #[test]
    fn refuses_len_below_one() {
        for len in ["0", "-2"] {
            let extra = ACS.replace("len = 3", &format!("len = {len}"));
            let msg = error(&extra, "fsw_streams[0].values[0].len");
            assert_eq!(
                msg,
                format!(
                    "fsw_streams[0].values[0].len: must be at least 1, got {len}{}",
                    at(&extra, &format!("{len}, unit"))
                )
            );
        }
        let extra = ACS.replace("len = 3", "len = 2.5");
        let e = parse(&extra).expect_err("a float length");
        assert_eq!(e.field(), Some("fsw_streams[0].values[0].len"), "{e}");
    }

    #[test]
    fn refuses_too_many_words() {
        let extra = "[[fsw_streams]]\nname = \"big\"\nvalues = [{ name = \"x\", type = \"f64\", \
                     len = 257 }]\n";
        let msg = error(extra, "fsw_streams[0].values[0].len");
        assert!(msg.contains("257 words"), "{msg}");
        assert!(msg.contains("(256)"), "{msg}");
        // The overflow by a defaulted length names the value that crosses the limit.
        let extra = "[[fsw_streams]]\nname = \"big\"\nvalues = [{ name = \"x\", type = \"f64\", \
                     len = 256 }, { name = \"y\", type = \"bool\" }]\n";
        let msg = error(extra, "fsw_streams[0].values[1].len");
        assert!(msg.contains("257 words"), "{msg}");
        assert!(msg.ends_with(&at(extra, "{ name = \"y\"")), "{msg}");
    }

    #[test]
    fn refuses_bad_severity() {
        let extra = ACS.replace("severity = \"error\"", "severity = \"fatal\"");
        let msg = error(&extra, "fsw_streams[0].events[0].severity");
        assert_eq!(
            msg,
            format!(
                "fsw_streams[0].events[0].severity: must be one of \"info\", \"warning\", \
                 \"error\", \"critical\", got \"fatal\"{}",
                at(&extra, "\"fatal\"")
            )
        );
    }

    #[test]
    fn refuses_unknown_keys() {
        let extra = ACS.replace("name = \"acs\"", "name = \"acs\"\nmax_rate_hz = 1000.0");
        let msg = error(&extra, "fsw_streams[0].max_rate_hz");
        assert!(msg.contains("unknown key"), "{msg}");
        let extra = ACS.replace("type = \"bool\"", "type = \"bool\", scale = 2.0");
        let msg = error(&extra, "fsw_streams[0].values[2].scale");
        assert!(msg.contains("unknown key"), "{msg}");
        let extra = ACS.replace(
            "{ name = \"detumbled\" }",
            "{ name = \"detumbled\", level = 1 }",
        );
        let msg = error(&extra, "fsw_streams[0].events[1].level");
        assert!(msg.contains("unknown key"), "{msg}");
    }

    #[test]
    fn refuses_bad_stream_names() {
        let long = "s".repeat(65);
        for (bad, problem) in [
            (
                "acs/x",
                "`acs/x` contains '/': a stream name is 1 to 64 characters",
            ),
            ("a*", "`a*` contains '*'"),
            ("", "must not be empty"),
            (
                long.as_str(),
                "is not a valid stream name (sensor name is 65 bytes long (max 64))",
            ),
        ] {
            let extra = ACS.replace("name = \"acs\"", &format!("name = \"{bad}\""));
            let msg = error(&extra, "fsw_streams[0].name");
            assert!(msg.starts_with("fsw_streams[0].name: "), "{msg}");
            assert!(msg.contains(problem), "{msg}");
            assert!(msg.ends_with(&at(&extra, &format!("\"{bad}\""))), "{msg}");
        }
        // 64 characters, dashes and underscores are fine; a dot is not (it is for values).
        parse(&ACS.replace("name = \"acs\"", &format!("name = \"{}\"", "s".repeat(64))))
            .expect("64 characters");
        let msg = error(
            &ACS.replace("name = \"acs\"", "name = \"a.b\""),
            "fsw_streams[0].name",
        );
        assert!(msg.contains("'.'"), "{msg}");
    }

    #[test]
    fn refuses_bad_member_names_and_shapes() {
        let msg = error(
            &ACS.replace("\"sun_valid\"", "\"sun valid\""),
            "fsw_streams[0].values[2].name",
        );
        assert!(msg.contains("contains ' '"), "{msg}");
        let msg = error(
            &ACS.replace("\"detumble\",", "\"\","),
            "fsw_streams[0].modes[0]",
        );
        assert!(msg.contains("must not be empty"), "{msg}");
        let long = "m".repeat(65);
        let msg = error(
            &ACS.replace("\"detumble\",", &format!("\"{long}\",")),
            "fsw_streams[0].modes[0]",
        );
        assert!(msg.contains("65 characters long"), "{msg}");
        let msg = error(
            &ACS.replace("\"detumble\",", "1,"),
            "fsw_streams[0].modes[0]",
        );
        assert!(msg.contains("expected a string, got an integer"), "{msg}");
        let msg = error(
            "[[fsw_streams]]\nname = \"s\"\nmodes = \"detumble\"\n",
            "fsw_streams[0].modes",
        );
        assert!(
            msg.contains("expected an array of strings, got a string"),
            "{msg}"
        );
        let e = parse("[[fsw_streams]]\nname = \"s\"\nvalues = [{ name = \"x\" }]\n")
            .expect_err("a value without a type");
        assert_eq!(e.field(), Some("fsw_streams[0].values[0].type"), "{e}");
        assert!(e.to_string().contains("missing required key"), "{e}");
    }

    #[test]
    fn refuses_too_many_streams() {
        let many: String = (0..=MAX_FSW_STREAMS)
            .map(|i| format!("[[fsw_streams]]\nname = \"s{i}\"\n"))
            .collect();
        let msg = error(&many, "fsw_streams");
        assert!(msg.contains("65 streams"), "{msg}");
        let fits: String = (0..MAX_FSW_STREAMS)
            .map(|i| format!("[[fsw_streams]]\nname = \"s{i}\"\n"))
            .collect();
        assert_eq!(parse(&fits).expect("64 streams").fsw_streams.len(), 64);
    }

    #[test]
    fn check_accepts_a_good_sample() {
        let s = acs();
        assert_eq!(s.check(&good_sample()), Ok(()));
        // Without MODE the mode field is not looked at; i64 words may be anything.
        let mut m = good_sample();
        m.flags = 0;
        m.mode = 99;
        m.values[3] = u64::MAX;
        assert_eq!(s.check(&m), Ok(()));
        // Events beyond event_count are not looked at.
        let mut m = good_sample();
        m.event_count = 1;
        m.events[1] = 500;
        assert_eq!(s.check(&m), Ok(()));
    }

    #[test]
    fn check_refuses_unknown_mode() {
        let mut m = good_sample();
        m.mode = 3;
        let r = acs().check(&m).expect_err("mode 3 of 3");
        assert_eq!(
            r,
            FswRefusal::UnknownMode {
                index: 3,
                declared: 3
            }
        );
        assert_eq!(r.reason(), "unknown_mode");
    }

    #[test]
    fn check_refuses_unknown_event() {
        let mut m = good_sample();
        m.event_count = 3;
        m.events[2] = 2;
        let r = acs().check(&m).expect_err("event 2 of 2");
        assert_eq!(
            r,
            FswRefusal::UnknownEvent {
                index: 2,
                declared: 2
            }
        );
        assert_eq!(r.reason(), "unknown_event");
    }

    #[test]
    fn check_refuses_wrong_count() {
        let s = acs();
        for n in [0, 4, 6] {
            let mut m = good_sample();
            m.values.resize(n, 0);
            let r = s.check(&m).expect_err("wrong count");
            assert_eq!(
                r,
                FswRefusal::WrongCount {
                    got: n,
                    declared: 5
                }
            );
            assert_eq!(r.reason(), "wrong_count");
        }
    }

    #[test]
    fn check_refuses_non_finite() {
        let s = acs();
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut m = good_sample();
            m.values[2] = bad.to_bits();
            let r = s.check(&m).expect_err("non-finite");
            assert_eq!(
                r,
                FswRefusal::NonFinite {
                    value: "h_wheels_b_nms[2]".into()
                }
            );
            assert_eq!(r.reason(), "non_finite");
        }
    }

    #[test]
    fn check_refuses_not_bool() {
        let mut m = good_sample();
        m.values[4] = 2;
        let r = acs().check(&m).expect_err("bool word 2");
        assert_eq!(
            r,
            FswRefusal::NotBool {
                value: "sun_valid".into(),
                word: 2
            }
        );
        assert_eq!(r.reason(), "not_bool");
        assert_eq!(
            r.to_string(),
            "sun_valid is a bool, but its word is 2 (not 0 or 1)"
        );
    }

    #[test]
    fn check_refuses_covariance_without_estimate() {
        let mut m = good_sample();
        m.flags = fsw_flags::MODE | fsw_flags::COVARIANCE;
        let r = acs().check(&m).expect_err("covariance alone");
        assert_eq!(r, FswRefusal::CovarianceWithoutEstimate);
        assert_eq!(r.reason(), "covariance_without_estimate");
    }

    #[test]
    fn words_decode_by_type() {
        assert_eq!(word_as_f64(FswValueType::F64, 1.5f64.to_bits()), 1.5);
        assert_eq!(word_as_f64(FswValueType::I64, (-3i64) as u64), -3.0);
        assert_eq!(word_as_f64(FswValueType::Bool, 1), 1.0);
        assert_eq!(word_as_f64(FswValueType::Bool, 0), 0.0);
        let s = acs();
        let m = good_sample();
        let h = s.value("h_wheels_b_nms").expect("declared");
        assert_eq!(
            h.decode(&m.values),
            Some(FswValues::F64(vec![0.5, -0.25, 0.0]))
        );
        assert_eq!(h.element_name(0), "h_wheels_b_nms[0]");
        let f = s.value("fdir_flags").expect("declared");
        assert_eq!(f.decode(&m.values), Some(FswValues::I64(vec![-7])));
        assert_eq!(f.element_name(0), "fdir_flags");
        let b = s.value("sun_valid").expect("declared");
        assert_eq!(b.decode(&m.values), Some(FswValues::Bool(vec![true])));
        assert_eq!(b.decode(&m.values[..4]), None);
        assert_eq!(
            FswSeverity::from_name("critical"),
            Some(FswSeverity::Critical)
        );
        assert_eq!(FswSeverity::Warning.name(), "warning");
        assert_eq!(FswValueType::from_name("f32"), None);
    }
}
