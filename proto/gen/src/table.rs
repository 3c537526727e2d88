//! The wire table (`proto/schema/messages.toml`): read, checked and laid out.
//!
//! Every check names the table entry and the field it is about, so a mistake in the table is a
//! one-line error, never a wrong mirror.

use std::collections::BTreeSet;
use std::fmt;

use serde::Deserialize;

/// The whole table.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Table {
    /// The protocol version every header carries.
    pub protocol_version: u16,
    /// Named constants every codec shares.
    #[serde(rename = "constant", default)]
    pub constants: Vec<Constant>,
    /// Named codes of integer fields that are not enumerations.
    #[serde(default)]
    pub codes: Vec<Codes>,
    /// Enumerations (a u32 tag on the wire).
    #[serde(rename = "enum", default)]
    pub enums: Vec<Enum>,
    /// Bit fields.
    #[serde(default)]
    pub flags: Vec<Flags>,
    /// Structs nested in messages.
    #[serde(rename = "struct", default)]
    pub structs: Vec<Struct>,
    /// Tagged unions.
    #[serde(rename = "union", default)]
    pub unions: Vec<Union>,
    /// The messages.
    #[serde(rename = "message", default)]
    pub messages: Vec<Message>,
}

/// A named constant.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Constant {
    /// Its name, SCREAMING_SNAKE (`FD_<name>` in C).
    pub name: String,
    /// Its value.
    pub value: ConstValue,
    /// Its Rust type: `usize` (a size or count), `u64` or `u8`.
    pub rust_type: String,
    /// What it is.
    pub doc: String,
}

/// A constant's value as the table writes it.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum ConstValue {
    /// A TOML integer.
    Int(i64),
    /// A hexadecimal string (`"0xFFFFFFFFFFFFFFFF"`), for values above `i64::MAX`.
    Hex(String),
}

impl Constant {
    /// The value, or why it is not one.
    pub fn value(&self) -> Result<u64, String> {
        match &self.value {
            ConstValue::Int(v) => {
                u64::try_from(*v).map_err(|_| format!("{v} is negative: a constant is unsigned"))
            }
            ConstValue::Hex(h) => h
                .strip_prefix("0x")
                .and_then(|d| u64::from_str_radix(d, 16).ok())
                .ok_or_else(|| format!("{h:?} is not 0x followed by at most 16 hex digits")),
        }
    }
}

/// Named codes of an integer field that a decoder does not refuse when unknown.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Codes {
    /// Its name.
    pub name: String,
    /// The C macro prefix (`FD_<c_prefix>_<VALUE>`).
    pub c_prefix: String,
    /// Which field it names.
    pub doc: String,
    /// The field it codes, `Owner.field` (a struct's or message's integer field): the Rust
    /// constants take its type.
    pub of: String,
    /// Rust documentation only (Markdown, links resolve in `proto/src/messages.rs`): prose
    /// that follows `doc` on docs.rs; the other mirrors keep to `doc`.
    #[serde(default)]
    pub note: String,
    /// Its codes.
    pub values: Vec<EnumValue>,
}

/// An enumeration.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Enum {
    /// Its name (`enum<Name>` in a field's type).
    pub name: String,
    /// The C macro prefix of its values, `FD_<c_prefix>_<VALUE>`; the name in
    /// SCREAMING_SNAKE when absent.
    #[serde(default)]
    pub c_prefix: Option<String>,
    /// What it is.
    pub doc: String,
    /// Its values, in tag order.
    pub values: Vec<EnumValue>,
    /// Rust documentation only (Markdown, links resolve in `proto/src/messages.rs`): prose
    /// that follows `doc` on docs.rs; the other mirrors keep to `doc`.
    #[serde(default)]
    pub note: String,
}

/// One value of an [`Enum`].
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnumValue {
    /// The u32 tag.
    pub value: u32,
    /// Its name.
    pub name: String,
    /// What it means.
    #[serde(default)]
    pub doc: String,
    /// Rust documentation only (Markdown, links resolve in `proto/src/messages.rs`): prose
    /// that follows `doc` on docs.rs; the other mirrors keep to `doc`.
    #[serde(default)]
    pub note: String,
}

/// A bit field.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Flags {
    /// Its name (a field's `flags`).
    pub name: String,
    /// The C macro prefix of its bits, `FD_<c_prefix>_<BIT>`.
    pub c_prefix: String,
    /// The field that carries the bits when no field names them in its `flags` (bits that
    /// depend on another field, as an effector's on its kind): `Owner.field`.
    #[serde(default)]
    pub of: Option<String>,
    /// Rust documentation only (Markdown, links resolve in `proto/src/messages.rs`): prose
    /// that follows `doc` on docs.rs; the other mirrors keep to `doc`.
    #[serde(default)]
    pub note: String,
    /// Its bits.
    pub bits: Vec<Bit>,
}

/// One bit of a [`Flags`].
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bit {
    /// Bit number (0 = least significant).
    pub bit: u32,
    /// Its name.
    pub name: String,
    /// What it means when set.
    pub doc: String,
    /// Rust documentation only (Markdown, links resolve in `proto/src/messages.rs`): prose
    /// that follows `doc` on docs.rs; the other mirrors keep to `doc`.
    #[serde(default)]
    pub note: String,
}

/// A struct nested in messages.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Struct {
    /// Its name (a field's type).
    pub name: String,
    /// Its C name, `fd_<c_name>`; the name in snake_case when absent.
    #[serde(default)]
    pub c_name: Option<String>,
    /// What it is.
    pub doc: String,
    /// Rust documentation only (Markdown, links resolve in `proto/src/messages.rs`): prose
    /// that follows `doc` on docs.rs; the other mirrors keep to `doc`.
    #[serde(default)]
    pub note: String,
    /// Rust derives beyond those its fields allow (`Hash`).
    #[serde(default)]
    pub rust_derive: Vec<String>,
    /// Its fields in wire order.
    pub fields: Vec<Field>,
}

/// A tagged union.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Union {
    /// Its name (`union<Name>`).
    pub name: String,
    /// The C macro prefix of its tags, `FD_<c_prefix>_<VARIANT>`.
    pub c_prefix: String,
    /// What it is.
    pub doc: String,
    /// Rust documentation only (Markdown, links resolve in `proto/src/messages.rs`): prose
    /// that follows `doc` on docs.rs; the other mirrors keep to `doc`.
    #[serde(default)]
    pub note: String,
    /// Its variants, in tag order.
    pub variants: Vec<Variant>,
}

/// One variant of a [`Union`].
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Variant {
    /// The u32 tag.
    pub tag: u32,
    /// Its name.
    pub name: String,
    /// What it does.
    pub doc: String,
    /// Rust documentation only (Markdown, links resolve in `proto/src/messages.rs`): prose
    /// that follows `doc` on docs.rs; the other mirrors keep to `doc`.
    #[serde(default)]
    pub note: String,
    /// The fields after the tag.
    pub fields: Vec<Field>,
}

/// A message.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Message {
    /// Its Rust type name (`ImuMsg`).
    pub name: String,
    /// Its C name: `fd_<c_name>_msg`, `fd_decode_<c_name>`, `decode_<c_name>`.
    pub c_name: String,
    /// Its name in prose (`IMU`).
    pub title: String,
    /// Its Zenoh key pattern.
    pub key: String,
    /// Who publishes it.
    pub direction: Direction,
    /// The configuration section whose samples a lockstep tick carries, if any.
    #[serde(default)]
    pub lockstep: Option<String>,
    /// The protocol version that introduced it.
    pub since: u16,
    /// What it is.
    pub doc: String,
    /// Rust documentation only (Markdown, links resolve in `proto/src/messages.rs`): prose
    /// that follows `doc` on docs.rs; the other mirrors keep to `doc`.
    #[serde(default)]
    pub note: String,
    /// Rust derives beyond those its fields allow (`Hash`).
    #[serde(default)]
    pub rust_derive: Vec<String>,
    /// Its fields in wire order; the first is the header.
    pub fields: Vec<Field>,
}

/// Who publishes a message.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// The server publishes it.
    Server,
    /// Flight code or an operator publishes it; the server takes it.
    Client,
}

/// A field.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Field {
    /// Its name.
    pub name: String,
    /// Its type, as written in the table.
    #[serde(rename = "type")]
    pub ty: String,
    /// Its unit.
    #[serde(default)]
    pub unit: Option<String>,
    /// The frame its components are in.
    #[serde(default)]
    pub frame: Option<String>,
    /// What it means.
    #[serde(default)]
    pub doc: String,
    /// Rust documentation only (Markdown, links resolve in `proto/src/messages.rs`): prose
    /// that follows `doc` on docs.rs; the other mirrors keep to `doc`.
    #[serde(default)]
    pub note: String,
    /// The [`Flags`] of its bits.
    #[serde(default)]
    pub flags: Option<String>,
    /// A `u8[n]` that holds UTF-8 text, NUL-padded.
    #[serde(default)]
    pub text: bool,
    /// The bound of a `vec` count or of a `u8` count.
    #[serde(default)]
    pub max: Option<u64>,
    /// Decoders refuse a NaN or infinite value here (NonFinite): an f64, f64\[n\] or vec\<f64>.
    #[serde(default)]
    pub finite: bool,
    /// C only: a struct-typed field whose members are the C struct's own, each name prefixed
    /// with this (`rejected_malformed`), instead of a nested C struct.
    #[serde(default)]
    pub c_flatten: Option<String>,
    /// Python only: a struct-typed field held as a tuple of the struct's fields in wire order
    /// (`utc`: `(year, month, …)`), instead of a class of its own.
    #[serde(default)]
    pub py_tuple: bool,
    /// The value a new message holds before it is set, where it is not zero: a number, an array
    /// of numbers, a `[[constant]]`'s name, or (for an enum or union field) a value's name.
    #[serde(default)]
    pub default: Option<toml::Value>,
    /// Rust only: the value of the type's `Default` where it differs from `default` (the Rust
    /// API's value, older than the table's).
    #[serde(default)]
    pub rust_default: Option<toml::Value>,
    /// Rust only: the type of a `text` field, a hand-written newtype of its bytes (`.0`) with
    /// `check_padding` (`FaultTarget`).
    #[serde(default)]
    pub rust_type: Option<String>,
}

/// A primitive wire type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Prim {
    /// u8.
    U8,
    /// u16 LE.
    U16,
    /// u32 LE.
    U32,
    /// u64 LE.
    U64,
    /// i32 LE.
    I32,
    /// IEEE-754 binary64 LE.
    F64,
    /// One byte, 0 or 1.
    Bool,
}

impl Prim {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "u8" => Self::U8,
            "u16" => Self::U16,
            "u32" => Self::U32,
            "u64" => Self::U64,
            "i32" => Self::I32,
            "f64" => Self::F64,
            "bool" => Self::Bool,
            _ => return None,
        })
    }

    /// Encoded size (bytes).
    pub fn size(self) -> usize {
        match self {
            Self::U8 | Self::Bool => 1,
            Self::U16 => 2,
            Self::U32 | Self::I32 => 4,
            Self::U64 | Self::F64 => 8,
        }
    }

    /// Its name in the table.
    pub fn name(self) -> &'static str {
        match self {
            Self::U8 => "u8",
            Self::U16 => "u16",
            Self::U32 => "u32",
            Self::U64 => "u64",
            Self::I32 => "i32",
            Self::F64 => "f64",
            Self::Bool => "bool",
        }
    }
}

/// A field's type, resolved.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Ty {
    /// A primitive.
    Prim(Prim),
    /// A fixed array of primitives.
    Array(Prim, usize),
    /// A nested struct, by index into [`Table::structs`].
    Struct(usize),
    /// An enumeration's u32 tag, by index into [`Table::enums`].
    Enum(usize),
    /// A tagged union, by index into [`Table::unions`].
    Union(usize),
    /// A u64 count then the elements.
    Vec(Box<Ty>),
}

/// A mistake in the table: where it is and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TableError {
    /// The file.
    pub file: String,
    /// The entry and field (`message ImuMsg, field omega_p_rad_s`).
    pub place: String,
    /// What is wrong.
    pub problem: String,
}

impl fmt::Display for TableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}: {}", self.file, self.place, self.problem)
    }
}

impl std::error::Error for TableError {}

/// Names a field may not have: words of C, C++, Python and Rust, and the locals of the generated
/// decoders that a field name could shadow.
const RESERVED: &[&str] = &[
    // C and C++
    "auto",
    "break",
    "case",
    "char",
    "const",
    "continue",
    "default",
    "do",
    "double",
    "else",
    "enum",
    "extern",
    "float",
    "for",
    "goto",
    "if",
    "inline",
    "int",
    "long",
    "register",
    "restrict",
    "return",
    "short",
    "signed",
    "sizeof",
    "static",
    "struct",
    "switch",
    "typedef",
    "union",
    "unsigned",
    "void",
    "volatile",
    "while",
    "bool",
    "class",
    "delete",
    "new",
    "operator",
    "private",
    "protected",
    "public",
    "template",
    "this",
    "throw",
    "try",
    "catch",
    "virtual",
    "namespace",
    "using",
    "and",
    "or",
    "not",
    "xor",
    "friend",
    "mutable",
    "explicit",
    "export",
    "typename",
    "nullptr",
    "true",
    "false",
    // Python
    "None",
    "True",
    "False",
    "as",
    "assert",
    "async",
    "await",
    "def",
    "del",
    "elif",
    "except",
    "finally",
    "from",
    "global",
    "import",
    "in",
    "is",
    "lambda",
    "nonlocal",
    "pass",
    "raise",
    "with",
    "yield",
    "print",
    "self",
    "cls",
    // Rust
    "crate",
    "dyn",
    "fn",
    "impl",
    "let",
    "loop",
    "match",
    "mod",
    "move",
    "mut",
    "pub",
    "ref",
    "Self",
    "super",
    "trait",
    "type",
    "unsafe",
    "use",
    "where",
    "abstract",
    "become",
    "box",
    "final",
    "macro",
    "override",
    "priv",
    "typeof",
    "unsized",
    "yield",
    // locals of the generated code
    "buf",
    "len",
    "out",
    "m",
    "e",
    "w",
    "n",
    "i",
    "j",
    "c",
    "at",
    "tag",
    "expected",
    "need",
    "cap",
    "el",
    "f",
    "struct",
    "math",
];

/// The table's path in the repository.
pub const TABLE_PATH: &str = "proto/schema/messages.toml";

impl Table {
    /// Reads and checks the table text (`file` names it in errors).
    pub fn parse(file: &str, text: &str) -> Result<Self, TableError> {
        let table: Table = toml::from_str(text).map_err(|e| TableError {
            file: file.to_owned(),
            place: "the file".to_owned(),
            problem: e.to_string(),
        })?;
        table.check(file)?;
        Ok(table)
    }

    fn err(file: &str, place: String, problem: impl Into<String>) -> TableError {
        TableError {
            file: file.to_owned(),
            place,
            problem: problem.into(),
        }
    }

    /// Resolves a type written in the table.
    pub fn resolve(&self, ty: &str) -> Result<Ty, String> {
        let ty = ty.trim();
        if let Some(p) = Prim::parse(ty) {
            return Ok(Ty::Prim(p));
        }
        if let Some(inner) = ty.strip_prefix("vec<").and_then(|t| t.strip_suffix('>')) {
            return Ok(Ty::Vec(Box::new(self.resolve(inner)?)));
        }
        if let Some(name) = ty.strip_prefix("enum<").and_then(|t| t.strip_suffix('>')) {
            return self
                .enums
                .iter()
                .position(|e| e.name == name)
                .map(Ty::Enum)
                .ok_or_else(|| format!("no [[enum]] named {name:?}"));
        }
        if let Some(name) = ty.strip_prefix("union<").and_then(|t| t.strip_suffix('>')) {
            return self
                .unions
                .iter()
                .position(|u| u.name == name)
                .map(Ty::Union)
                .ok_or_else(|| format!("no [[union]] named {name:?}"));
        }
        if let Some((elem, rest)) = ty.split_once('[') {
            let n = rest
                .strip_suffix(']')
                .and_then(|n| n.parse::<usize>().ok())
                .filter(|&n| n > 0)
                .ok_or_else(|| format!("{ty:?}: an array is T[n] with n ≥ 1"))?;
            let p = Prim::parse(elem)
                .ok_or_else(|| format!("{ty:?}: an array's element is a primitive"))?;
            return Ok(Ty::Array(p, n));
        }
        self.structs
            .iter()
            .position(|s| s.name == ty)
            .map(Ty::Struct)
            .ok_or_else(|| {
                format!(
                    "unknown type {ty:?} (a primitive, T[n], vec<T>, enum<Name>, union<Name> or a \
                     [[struct]] name)"
                )
            })
    }

    /// The encoded size of a type when it is fixed.
    pub fn fixed_size(&self, ty: &Ty) -> Option<usize> {
        match ty {
            Ty::Prim(p) => Some(p.size()),
            Ty::Array(p, n) => Some(p.size() * n),
            Ty::Struct(i) => self.fields_size(&self.structs[*i].fields),
            Ty::Enum(_) => Some(4),
            Ty::Union(i) => {
                let sizes: Vec<Option<usize>> = self.unions[*i]
                    .variants
                    .iter()
                    .map(|v| self.fields_size(&v.fields))
                    .collect();
                match sizes.first() {
                    Some(Some(first)) if sizes.iter().all(|s| *s == Some(*first)) => {
                        Some(4 + first)
                    }
                    _ => None,
                }
            }
            Ty::Vec(_) => None,
        }
    }

    /// The encoded size of fields when every one is fixed.
    pub fn fields_size(&self, fields: &[Field]) -> Option<usize> {
        fields
            .iter()
            .map(|f| self.resolve(&f.ty).ok().and_then(|t| self.fixed_size(&t)))
            .sum()
    }

    /// The shortest encoding of a type (every vec empty, the shortest union variant).
    pub fn min_size(&self, ty: &Ty) -> usize {
        match ty {
            Ty::Struct(i) => self.fields_min_size(&self.structs[*i].fields),
            Ty::Union(i) => {
                4 + self.unions[*i]
                    .variants
                    .iter()
                    .map(|v| self.fields_min_size(&v.fields))
                    .min()
                    .unwrap_or(0)
            }
            Ty::Vec(_) => 8,
            other => self.fixed_size(other).unwrap_or(0),
        }
    }

    /// The shortest encoding of fields.
    pub fn fields_min_size(&self, fields: &[Field]) -> usize {
        fields
            .iter()
            .map(|f| self.resolve(&f.ty).map(|t| self.min_size(&t)).unwrap_or(0))
            .sum()
    }

    /// A message by its Rust name.
    pub fn message(&self, name: &str) -> Option<&Message> {
        self.messages.iter().find(|m| m.name == name)
    }

    fn check_fields(&self, file: &str, owner: &str, fields: &[Field]) -> Result<(), TableError> {
        let mut names = BTreeSet::new();
        for f in fields {
            let place = format!("{owner}, field {:?}", f.name);
            if f.name.is_empty()
                || !f
                    .name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_')
            {
                return Err(Self::err(
                    file,
                    place,
                    "a field name is [A-Za-z0-9_], not empty",
                ));
            }
            if !names.insert(f.name.as_str()) {
                return Err(Self::err(file, place, "the name is used twice"));
            }
            if f.name.starts_with(|c: char| c.is_ascii_digit())
                || RESERVED.contains(&f.name.as_str())
            {
                return Err(Self::err(
                    file,
                    place,
                    "a field name does not start with a digit and is not a word of C, C++, \
                     Python or Rust, nor a local of the generated code",
                ));
            }
            let ty = self
                .resolve(&f.ty)
                .map_err(|e| Self::err(file, place.clone(), e))?;
            if let Some(flags) = &f.flags {
                if !matches!(ty, Ty::Prim(Prim::U8 | Prim::U16 | Prim::U32)) {
                    return Err(Self::err(file, place, "`flags` is for a u8, u16 or u32"));
                }
                if !self.flags.iter().any(|x| &x.name == flags) {
                    return Err(Self::err(
                        file,
                        place,
                        format!("`flags` names no [[flags]] table {flags:?}"),
                    ));
                }
            }
            let floats = match &ty {
                Ty::Prim(Prim::F64) | Ty::Array(Prim::F64, _) => true,
                Ty::Vec(inner) => **inner == Ty::Prim(Prim::F64),
                _ => false,
            };
            if f.finite && !floats {
                return Err(Self::err(
                    file,
                    place,
                    "`finite` is for an f64, f64[n] or vec<f64>",
                ));
            }
            if f.text && !matches!(ty, Ty::Array(Prim::U8, _)) {
                return Err(Self::err(file, place, "`text` is for a u8[n]"));
            }
            match (&ty, f.max) {
                (Ty::Vec(_), None) => {
                    return Err(Self::err(
                        file,
                        place,
                        "a vec needs `max`, its count's bound",
                    ))
                }
                (Ty::Vec(_) | Ty::Prim(Prim::U8), _) | (_, None) => {}
                (_, Some(_)) => {
                    return Err(Self::err(file, place, "`max` is for a vec or a u8 count"))
                }
            }
            if f.c_flatten.is_some() && !matches!(ty, Ty::Struct(_)) {
                return Err(Self::err(
                    file,
                    place,
                    "`c_flatten` is for a struct-typed field",
                ));
            }
            if f.py_tuple {
                let prims = match &ty {
                    Ty::Struct(s) => self.structs[*s]
                        .fields
                        .iter()
                        .all(|g| matches!(self.resolve(&g.ty), Ok(Ty::Prim(p)) if p != Prim::Bool)),
                    _ => false,
                };
                if !prims {
                    return Err(Self::err(
                        file,
                        place,
                        "`py_tuple` is for a struct of numbers",
                    ));
                }
            }
            for (key, d) in [("default", &f.default), ("rust_default", &f.rust_default)] {
                if let Some(d) = d {
                    self.check_default(&ty, d)
                        .map_err(|e| Self::err(file, place.clone(), format!("`{key}`: {e}")))?;
                }
            }
            let rust_type_ok = |n: &str| {
                n.starts_with(|c: char| c.is_ascii_uppercase())
                    && n.chars().all(|c| c.is_ascii_alphanumeric())
            };
            match (&f.rust_type, f.text) {
                (Some(n), true) if rust_type_ok(n) => {}
                (None, false) => {}
                _ => {
                    return Err(Self::err(
                        file,
                        place,
                        "a text field, and only a text field, names its Rust newtype in \
                         `rust_type` (CamelCase)",
                    ))
                }
            }
            if let Ty::Vec(inner) = &ty {
                if self.fixed_size(inner).is_none() && !matches!(**inner, Ty::Struct(_)) {
                    return Err(Self::err(
                        file,
                        place,
                        "a vec's element is a primitive or a struct",
                    ));
                }
            }
        }
        Ok(())
    }

    /// Whether `d` is a default a field of type `ty` can hold.
    fn check_default(&self, ty: &Ty, d: &toml::Value) -> Result<(), String> {
        use toml::Value as V;
        match (ty, d) {
            (Ty::Prim(Prim::F64), V::Float(_) | V::Integer(_)) => Ok(()),
            (Ty::Prim(p), V::Integer(_)) if *p != Prim::Bool => Ok(()),
            (Ty::Prim(Prim::Bool), V::Boolean(_)) => Ok(()),
            (Ty::Prim(p), V::String(name)) if *p != Prim::F64 && *p != Prim::Bool => {
                (name == "PROTOCOL_VERSION" || self.constants.iter().any(|c| &c.name == name))
                    .then_some(())
                    .ok_or_else(|| format!("no [[constant]] named {name:?}"))
            }
            (Ty::Array(p, n), V::Array(items)) => {
                if items.len() != *n {
                    return Err(format!("{} values for {n} entries", items.len()));
                }
                items
                    .iter()
                    .try_for_each(|i| self.check_default(&Ty::Prim(*p), i))
            }
            (Ty::Enum(e), V::String(name)) => self.enums[*e]
                .values
                .iter()
                .any(|v| &v.name == name)
                .then_some(())
                .ok_or_else(|| format!("enum {} has no value {name:?}", self.enums[*e].name)),
            (Ty::Union(u), V::String(name)) => self.unions[*u]
                .variants
                .iter()
                .any(|v| &v.name == name)
                .then_some(())
                .ok_or_else(|| format!("union {} has no variant {name:?}", self.unions[*u].name)),
            _ => Err(format!("{d} does not suit this field's type")),
        }
    }

    /// The shapes every generator writes (C, Python, Rust), checked so that a table the
    /// generators cannot mirror is refused here with the entry's name, never half-generated:
    /// - only the last field of a message or of a union variant varies in size (a vec), so every
    ///   other field sits at a fixed offset; a union is only ever a message's last field;
    /// - a vec's element is a number (not a bool) or a struct of numbers and vecs of numbers
    ///   (no bool, enum, array, text, bound or nested struct: the elements are walked, and their
    ///   only rule is `finite`);
    /// - a struct nested whole (not `c_flatten`) carries no rule (no bool, enum, text, bound or
    ///   `finite`); `c_flatten`, `py_tuple` and `text` are for a message's own fields;
    /// - a struct refers only to structs defined before it.
    fn check_layout(
        &self,
        file: &str,
        owner: &str,
        fields: &[Field],
        in_message: bool,
    ) -> Result<(), TableError> {
        let numeric = |t: &Ty| matches!(t, Ty::Prim(p) if *p != Prim::Bool);
        for (i, f) in fields.iter().enumerate() {
            let place = format!("{owner}, field {:?}", f.name);
            let ty = self
                .resolve(&f.ty)
                .map_err(|e| Self::err(file, place.clone(), e))?;
            let last = i + 1 == fields.len();
            if !in_message && (f.c_flatten.is_some() || f.py_tuple || f.text) {
                return Err(Self::err(
                    file,
                    place,
                    "`c_flatten`, `py_tuple` and `text` are for a message's own fields",
                ));
            }
            match &ty {
                Ty::Struct(s) => {
                    let st = &self.structs[*s];
                    if self.fixed_size(&ty).is_none() {
                        return Err(Self::err(
                            file,
                            place,
                            format!(
                                "struct {} varies in size: it may only be a vec's element",
                                st.name
                            ),
                        ));
                    }
                    if f.c_flatten.is_none() && self.has_rules(&st.fields, true) {
                        return Err(Self::err(
                            file,
                            place,
                            format!(
                                "struct {} has a bool, an enum, a text field, a bound or a finite \
                                 value: give the field `c_flatten` so every codec checks them in \
                                 place",
                                st.name
                            ),
                        ));
                    }
                }
                Ty::Vec(inner) => {
                    if !last {
                        return Err(Self::err(file, place, "a vec is the last field"));
                    }
                    let elem_ok = match &**inner {
                        Ty::Struct(s) => self.structs[*s].fields.iter().all(|g| {
                            !g.text
                                && match self.resolve(&g.ty) {
                                    Ok(Ty::Vec(e)) => numeric(&e),
                                    Ok(t) => g.max.is_none() && numeric(&t),
                                    Err(_) => false,
                                }
                        }),
                        other => numeric(other),
                    };
                    if !elem_ok {
                        return Err(Self::err(
                            file,
                            place,
                            "a vec's element is a number (not a bool) or a struct of numbers and \
                             vecs of numbers",
                        ));
                    }
                }
                Ty::Union(u) => {
                    if !in_message || !last {
                        return Err(Self::err(file, place, "a union is a message's last field"));
                    }
                    for v in &self.unions[*u].variants {
                        self.check_layout(
                            file,
                            &format!("union {}, variant {}", self.unions[*u].name, v.name),
                            &v.fields,
                            false,
                        )?;
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// The members a message has in C and Python (flattened structs and a union's variants
    /// spread out), each with its type as written; a name shared by union variants must have
    /// one type.
    fn flat_members(
        &self,
        fields: &[Field],
        prefix: &str,
        out: &mut Vec<(String, String)>,
    ) -> Result<(), String> {
        for f in fields {
            let name = format!("{prefix}{}", f.name);
            match (self.resolve(&f.ty), &f.c_flatten) {
                (Ok(Ty::Struct(s)), Some(p)) => {
                    self.flat_members(&self.structs[s].fields, &format!("{prefix}{p}"), out)?
                }
                (Ok(Ty::Union(u)), _) => {
                    out.push((name, f.ty.clone()));
                    let mut shared: Vec<(String, String)> = Vec::new();
                    for v in &self.unions[u].variants {
                        let mut vm = Vec::new();
                        self.flat_members(&v.fields, prefix, &mut vm)?;
                        for (n, t) in vm {
                            match shared.iter().find(|(m, _)| *m == n) {
                                Some((_, t0)) if *t0 != t => {
                                    return Err(format!(
                                        "{n:?} has two types across the variants of union {}",
                                        self.unions[u].name
                                    ))
                                }
                                Some(_) => {}
                                None => shared.push((n, t)),
                            }
                        }
                    }
                    out.extend(shared);
                }
                _ => out.push((name, f.ty.clone())),
            }
        }
        Ok(())
    }

    /// Whether fields carry a step-4 rule (bool, enum, text, bound), or with `finite` a step-5
    /// one, nested structs included.
    fn has_rules(&self, fields: &[Field], finite: bool) -> bool {
        fields.iter().any(|f| {
            f.text
                || f.max.is_some()
                || (finite && f.finite)
                || match self.resolve(&f.ty) {
                    Ok(Ty::Prim(Prim::Bool) | Ty::Array(Prim::Bool, _) | Ty::Enum(_)) => true,
                    Ok(Ty::Struct(s)) => self.has_rules(&self.structs[s].fields, finite),
                    _ => false,
                }
        })
    }

    /// Checks names, references and the messages' rules.
    fn check(&self, file: &str) -> Result<(), TableError> {
        let screaming = |s: &str| {
            !s.is_empty()
                && s.chars()
                    .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
        };
        let mut c_macros = BTreeSet::new();
        for c in &self.constants {
            let place = format!("constant {:?}", c.name);
            if !screaming(&c.name) || !c_macros.insert(c.name.clone()) {
                return Err(Self::err(
                    file,
                    place,
                    "a constant's name is SCREAMING_SNAKE and used once",
                ));
            }
            let v = c.value().map_err(|e| Self::err(file, place.clone(), e))?;
            let fits = match c.rust_type.as_str() {
                "u8" => v <= u64::from(u8::MAX),
                "u16" => v <= u64::from(u16::MAX),
                "u32" => v <= u64::from(u32::MAX),
                "u64" => true,
                "usize" => v <= u64::from(u32::MAX),
                _ => false,
            };
            if !fits {
                return Err(Self::err(
                    file,
                    place,
                    format!(
                        "rust_type {:?}: a u8, u16, u32, u64 or usize that holds {v}",
                        c.rust_type
                    ),
                ));
            }
        }
        for c in &self.codes {
            let mut seen = BTreeSet::new();
            for v in &c.values {
                if !screaming(&v.name) || !seen.insert(v.value) {
                    return Err(Self::err(
                        file,
                        format!("codes {}, value {:?}", c.name, v.name),
                        "a code's name is SCREAMING_SNAKE and its value appears once",
                    ));
                }
            }
        }
        let mut types = BTreeSet::new();
        for name in self
            .enums
            .iter()
            .map(|e| &e.name)
            .chain(self.structs.iter().map(|s| &s.name))
            .chain(self.unions.iter().map(|u| &u.name))
            .chain(self.messages.iter().map(|m| &m.name))
        {
            if !types.insert(name.as_str()) {
                return Err(Self::err(
                    file,
                    format!("type {name:?}"),
                    "two entries have this name",
                ));
            }
        }
        for e in &self.enums {
            for (i, v) in e.values.iter().enumerate() {
                if v.value as usize != i {
                    return Err(Self::err(
                        file,
                        format!("enum {}, value {:?}", e.name, v.name),
                        format!("tags run 0, 1, 2, … in order: expected {i}"),
                    ));
                }
            }
        }
        for fl in &self.flags {
            let mut seen = BTreeSet::new();
            for b in &fl.bits {
                if b.bit >= 32 || !seen.insert(b.bit) {
                    return Err(Self::err(
                        file,
                        format!("flags {}, bit {:?}", fl.name, b.name),
                        "a bit is 0..=31 and appears once",
                    ));
                }
            }
        }
        for (i, s) in self.structs.iter().enumerate() {
            self.check_fields(file, &format!("struct {}", s.name), &s.fields)?;
            for f in &s.fields {
                let later = match self.resolve(&f.ty) {
                    Ok(Ty::Struct(j)) => j >= i,
                    Ok(Ty::Vec(inner)) => matches!(*inner, Ty::Struct(j) if j >= i),
                    _ => false,
                };
                if later {
                    return Err(Self::err(
                        file,
                        format!("struct {}, field {:?}", s.name, f.name),
                        "a struct refers only to structs defined before it",
                    ));
                }
            }
        }
        for u in &self.unions {
            for (i, v) in u.variants.iter().enumerate() {
                let owner = format!("union {}, variant {}", u.name, v.name);
                if v.tag as usize != i {
                    return Err(Self::err(
                        file,
                        owner,
                        format!("tags run 0, 1, 2, … in order: expected {i}"),
                    ));
                }
                self.check_fields(file, &owner, &v.fields)?;
            }
        }
        let mut c_names = BTreeSet::new();
        for m in &self.messages {
            let owner = format!("message {}", m.name);
            self.check_fields(file, &owner, &m.fields)?;
            self.check_layout(file, &owner, &m.fields, true)?;
            let mut members = Vec::new();
            self.flat_members(&m.fields, "", &mut members)
                .map_err(|e| Self::err(file, owner.clone(), e))?;
            let mut seen = BTreeSet::new();
            for (n, _) in &members {
                if !seen.insert(n.as_str()) {
                    return Err(Self::err(
                        file,
                        owner,
                        format!(
                            "two members named {n:?} once flattened (c_flatten prefixes and union \
                             variants share the message's C struct and Python class)"
                        ),
                    ));
                }
            }
            if !c_names.insert(m.c_name.as_str())
                || !m.c_name.chars().all(|c| c.is_ascii_lowercase() || c == '_')
            {
                return Err(Self::err(
                    file,
                    format!("{owner}, c_name"),
                    "a c_name is [a-z_] and names one message",
                ));
            }
            match m.fields.first() {
                Some(f) if f.name == "header" && f.ty == "Header" => {}
                _ => {
                    return Err(Self::err(
                        file,
                        owner,
                        "a message starts with `header`, of type Header",
                    ))
                }
            }
            if !m.key.starts_with("flexdyn/") || m.key.contains("//") {
                return Err(Self::err(
                    file,
                    format!("{owner}, key"),
                    "a key is flexdyn/<sc-id>/…",
                ));
            }
            let chunks = key_chunks(&m.key);
            if chunks
                .iter()
                .skip(2)
                .any(|c| c.starts_with('<') && c != chunks.last().unwrap_or(c))
            {
                return Err(Self::err(
                    file,
                    format!("{owner}, key"),
                    "only the vehicle (second) and the last chunk of a key may be a placeholder",
                ));
            }
            if m.lockstep.is_some() && (m.direction != Direction::Server || !m.named()) {
                return Err(Self::err(
                    file,
                    format!("{owner}, lockstep"),
                    "only a server message with a name in its key is a lockstep sensor",
                ));
            }
            if m.since > self.protocol_version {
                return Err(Self::err(
                    file,
                    format!("{owner}, since"),
                    "later than protocol_version",
                ));
            }
        }
        self.check_rust(file)
    }

    /// Checks what only the Rust types read: extra derives, and the fields that carry codes and
    /// bits.
    fn check_rust(&self, file: &str) -> Result<(), TableError> {
        let float = |t: &Ty| matches!(t, Ty::Prim(Prim::F64) | Ty::Array(Prim::F64, _));
        let typed = self
            .structs
            .iter()
            .map(|s| (format!("struct {}", s.name), &s.rust_derive, &s.fields))
            .chain(
                self.messages
                    .iter()
                    .map(|m| (format!("message {}", m.name), &m.rust_derive, &m.fields)),
            );
        for (owner, derives, fields) in typed {
            if derives.iter().any(|d| d != "Hash")
                || (!derives.is_empty() && self.holds(fields, &float))
            {
                return Err(Self::err(
                    file,
                    format!("{owner}, rust_derive"),
                    "the only extra derive is \"Hash\", for a type without f64",
                ));
            }
        }
        for c in &self.codes {
            self.field_at(&c.of)
                .map_err(|e| Self::err(file, format!("codes {}, of", c.name), e))?;
        }
        for fl in &self.flags {
            let place = format!("flags {}", fl.name);
            let named = self.flag_fields(&fl.name);
            let carriers =
                match (&fl.of, named.is_empty()) {
                    (Some(of), true) => vec![self
                        .field_at(of)
                        .map_err(|e| Self::err(file, format!("{place}, of"), e))?],
                    (None, false) => named,
                    _ => return Err(Self::err(
                        file,
                        place,
                        "bits are carried by the fields that name them in `flags`, or, when none \
                         does, by the field `of` names (one of the two)",
                    )),
                };
            if carriers.iter().any(|(_, f)| f.ty != carriers[0].1.ty) {
                return Err(Self::err(
                    file,
                    place,
                    "the fields that carry the bits have one type",
                ));
            }
        }
        Ok(())
    }

    /// Whether a type in `fields` (nested structs, union variants and vec elements included) is
    /// one `is` accepts.
    pub fn holds(&self, fields: &[Field], is: &dyn Fn(&Ty) -> bool) -> bool {
        fields
            .iter()
            .any(|f| self.resolve(&f.ty).is_ok_and(|ty| self.ty_holds(&ty, is)))
    }

    /// Whether `ty` is, or holds, a type `is` accepts.
    pub fn ty_holds(&self, ty: &Ty, is: &dyn Fn(&Ty) -> bool) -> bool {
        is(ty)
            || match ty {
                Ty::Struct(s) => self.holds(&self.structs[*s].fields, is),
                Ty::Union(u) => self.unions[*u]
                    .variants
                    .iter()
                    .any(|v| self.holds(&v.fields, is)),
                Ty::Vec(inner) => self.ty_holds(inner, is),
                _ => false,
            }
    }

    /// The integer field `Owner.field` of a struct or message: its owner's name and the field.
    pub fn field_at(&self, path: &str) -> Result<(&str, &Field), String> {
        let (owner, name) = path
            .split_once('.')
            .ok_or_else(|| format!("{path:?} is not Owner.field"))?;
        let (owner, fields) = self
            .structs
            .iter()
            .map(|s| (s.name.as_str(), &s.fields))
            .chain(self.messages.iter().map(|m| (m.name.as_str(), &m.fields)))
            .find(|(n, _)| *n == owner)
            .ok_or_else(|| format!("no struct or message named {owner:?}"))?;
        let f = fields
            .iter()
            .find(|f| f.name == name)
            .ok_or_else(|| format!("{owner} has no field {name:?}"))?;
        match self.resolve(&f.ty) {
            Ok(Ty::Prim(Prim::U8 | Prim::U16 | Prim::U32)) => Ok((owner, f)),
            _ => Err(format!("{path} is not a u8, u16 or u32")),
        }
    }

    /// The fields that name [\[flags\]] `name` in their `flags`, with their owners' names.
    pub fn flag_fields(&self, name: &str) -> Vec<(&str, &Field)> {
        let owners = self
            .structs
            .iter()
            .map(|s| (s.name.as_str(), &s.fields))
            .chain(self.messages.iter().map(|m| (m.name.as_str(), &m.fields)))
            .chain(
                self.unions
                    .iter()
                    .flat_map(|u| u.variants.iter().map(move |v| (u.name.as_str(), &v.fields))),
            );
        owners
            .flat_map(|(o, fields)| fields.iter().map(move |f| (o, f)))
            .filter(|(_, f)| f.flags.as_deref() == Some(name))
            .collect()
    }

    /// The fields that carry [\[flags\]] `name` (checked: at least one, of one type).
    pub fn flag_carriers(&self, name: &str) -> Vec<(&str, &Field)> {
        let named = self.flag_fields(name);
        if !named.is_empty() {
            return named;
        }
        self.flags
            .iter()
            .find(|f| f.name == name)
            .and_then(|f| f.of.as_deref())
            .and_then(|of| self.field_at(of).ok())
            .into_iter()
            .collect()
    }
}

/// The `/`-separated chunks of a key.
pub fn key_chunks(key: &str) -> Vec<&str> {
    key.split('/').collect()
}

/// `RunTicks` → `RUN_TICKS`, `command_flags` → `COMMAND_FLAGS`.
pub fn screaming_snake(name: &str) -> String {
    snake(name).to_ascii_uppercase()
}

/// `source_wrench` → `SourceWrench`.
pub fn camel(name: &str) -> String {
    name.split('_')
        .map(|w| {
            let mut c = w.chars();
            c.next()
                .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
                .unwrap_or_default()
        })
        .collect()
}

/// `EffectorState` → `effector_state`; a name already in snake_case is kept.
pub fn snake(name: &str) -> String {
    let mut out = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() {
            if i > 0 && !out.ends_with('_') {
                out.push('_');
            }
            out.push(c.to_ascii_lowercase());
        } else {
            out.push(c);
        }
    }
    out
}

impl Enum {
    /// `FD_<this>_<VALUE>` in C.
    pub fn c_prefix(&self) -> String {
        self.c_prefix
            .clone()
            .unwrap_or_else(|| screaming_snake(&self.name))
    }
}

impl Struct {
    /// `fd_<this>` in C.
    pub fn c_name(&self) -> String {
        self.c_name.clone().unwrap_or_else(|| snake(&self.name))
    }
}

impl Message {
    /// Whether the key's last chunk is a placeholder (a sensor's name, the chief's id, the
    /// sender's id).
    pub fn named(&self) -> bool {
        key_chunks(&self.key)
            .last()
            .is_some_and(|c| c.starts_with('<'))
    }

    /// The key after the vehicle chunk, up to (not including) a last placeholder:
    /// `tlm/imu` for `flexdyn/<sc-id>/tlm/imu/<name>`, `status` for `flexdyn/<sc-id>/status`.
    pub fn key_tail(&self) -> String {
        let chunks = key_chunks(&self.key);
        let end = if self.named() {
            chunks.len() - 1
        } else {
            chunks.len()
        };
        chunks[2..end].join("/")
    }

    /// The C macro suffix: `MAGNETOMETER`.
    pub fn upper(&self) -> String {
        self.c_name.to_ascii_uppercase()
    }
}
