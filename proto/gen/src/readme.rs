//! The byte tables of `proto/README.md`, between markers; the prose around them stays
//! hand-written.
//!
//! A block starts with `<!-- wire-table: message ImuMsg -->` (or `struct EffectorState`) and
//! ends with `<!-- /wire-table -->`. A message's block holds its byte table and the tables of
//! the bit fields it uses; nested structs are flattened with dotted names, except the header
//! and the elements of a vec, which have their own tables.

use crate::table::{Field, Prim, Table, Ty};

/// Where a field starts: a constant plus terms that depend on counts (`8·n_states`), or
/// unknown after a vec of structs.
#[derive(Clone, Debug)]
struct Offset {
    bytes: usize,
    terms: Vec<String>,
    unknown: bool,
}

impl Offset {
    fn zero() -> Self {
        Self {
            bytes: 0,
            terms: Vec::new(),
            unknown: false,
        }
    }

    fn plus(&self, n: usize) -> Self {
        let mut o = self.clone();
        o.bytes += n;
        o
    }

    fn plus_term(&self, term: String) -> Self {
        let mut o = self.clone();
        o.terms.push(term);
        o
    }

    fn unknown() -> Self {
        Self {
            bytes: 0,
            terms: Vec::new(),
            unknown: true,
        }
    }

    fn show(&self) -> String {
        if self.unknown {
            return "…".to_owned();
        }
        let mut parts = Vec::new();
        if self.bytes > 0 || self.terms.is_empty() {
            parts.push(self.bytes.to_string());
        }
        parts.extend(self.terms.iter().cloned());
        parts.join(" + ")
    }
}

struct Row {
    offset: String,
    size: String,
    ty: String,
    field: String,
    unit: String,
    frame: String,
    meaning: String,
}

/// A cell: newlines folded, pipes escaped.
fn cell(s: &str) -> String {
    s.replace('\n', " ").replace('|', "\\|")
}

struct Walk<'t> {
    table: &'t Table,
    rows: Vec<Row>,
    /// The bit fields used, in order of first use.
    flags: Vec<String>,
}

impl<'t> Walk<'t> {
    fn new(table: &'t Table) -> Self {
        Self {
            table,
            rows: Vec::new(),
            flags: Vec::new(),
        }
    }

    fn meaning(&mut self, f: &Field, ty: &Ty) -> String {
        let mut m = f.doc.clone();
        let mut add = |extra: String| {
            if m.is_empty() {
                m = extra;
            } else {
                m = format!("{m}; {extra}");
            }
        };
        if let Ty::Enum(i) = ty {
            let e = &self.table.enums[*i];
            add(e
                .values
                .iter()
                .map(|v| {
                    if v.doc.is_empty() {
                        format!("{} `{}`", v.value, v.name)
                    } else {
                        format!("{} `{}`: {}", v.value, v.name, v.doc)
                    }
                })
                .collect::<Vec<_>>()
                .join("; "));
        }
        if let Some(fl) = &f.flags {
            if !self.flags.contains(fl) {
                self.flags.push(fl.clone());
            }
            add(format!("bits: table `{fl}` below"));
        }
        if f.text {
            add("UTF-8 text padded with NUL bytes (\"Decoder rules\")".to_owned());
        }
        if f.finite {
            add("finite: NaN or ±inf is NonFinite".to_owned());
        }
        if let (Ty::Prim(Prim::U8), Some(max)) = (ty, f.max) {
            add(format!("0 ≤ value ≤ {max}, more is Malformed"));
        }
        m
    }

    /// Walks `fields` from `at`; returns where they end.
    fn fields(&mut self, prefix: &str, fields: &[Field], at: Offset, note: &str) -> Offset {
        let mut at = at;
        for f in fields {
            let ty = self.table.resolve(&f.ty).expect("checked table");
            at = self.field(prefix, f, &ty, at, note);
        }
        at
    }

    fn push(&mut self, at: &Offset, size: String, ty: String, field: String, f: &Field, m: String) {
        self.rows.push(Row {
            offset: at.show(),
            size,
            ty,
            field,
            unit: f.unit.clone().unwrap_or_default(),
            frame: f.frame.clone().unwrap_or_default(),
            meaning: m,
        });
    }

    fn field(&mut self, prefix: &str, f: &Field, ty: &Ty, at: Offset, note: &str) -> Offset {
        let name = format!("{prefix}{}", f.name);
        match ty {
            Ty::Prim(p) => {
                let m = self.meaning(f, ty);
                self.push(
                    &at,
                    p.size().to_string(),
                    p.name().to_owned(),
                    format!("`{name}`{note}"),
                    f,
                    m,
                );
                at.plus(p.size())
            }
            Ty::Array(p, n) => {
                let m = self.meaning(f, ty);
                let size = p.size() * n;
                self.push(
                    &at,
                    size.to_string(),
                    format!("{}[{n}]", p.name()),
                    format!("`{name}`{note}"),
                    f,
                    m,
                );
                at.plus(size)
            }
            Ty::Enum(_) => {
                let m = self.meaning(f, ty);
                self.push(
                    &at,
                    "4".to_owned(),
                    "u32".to_owned(),
                    format!("`{name}` tag{note}"),
                    f,
                    m,
                );
                at.plus(4)
            }
            Ty::Struct(i) => {
                let s = &self.table.structs[*i];
                if s.name == "Header" {
                    let size = self.table.fixed_size(ty).unwrap_or(0);
                    let m = f.doc.clone();
                    self.push(
                        &at,
                        size.to_string(),
                        "Header".to_owned(),
                        format!("`{name}`{note}"),
                        f,
                        m,
                    );
                    return at.plus(size);
                }
                let fields = &self.table.structs[*i].fields;
                let first = self.rows.len();
                let end = self.fields(&format!("{name}."), fields, at, note);
                // The struct field's own meaning heads its first row.
                if let (false, Some(row)) = (f.doc.is_empty(), self.rows.get_mut(first)) {
                    row.meaning = if row.meaning.is_empty() {
                        f.doc.clone()
                    } else {
                        format!("{}: {}", f.doc, row.meaning)
                    };
                }
                end
            }
            Ty::Union(i) => {
                let u = &self.table.unions[*i];
                let tags = u
                    .variants
                    .iter()
                    .map(|v| format!("{} `{}`", v.tag, v.name))
                    .collect::<Vec<_>>()
                    .join(", ");
                let m = if f.doc.is_empty() {
                    tags
                } else {
                    format!("{}: {tags}", f.doc)
                };
                self.push(
                    &at,
                    "4".to_owned(),
                    "u32".to_owned(),
                    format!("`{name}` tag{note}"),
                    f,
                    m,
                );
                let body = at.plus(4);
                // Each variant's rows, then rows equal in every way but the variant merged.
                let mut tagged: Vec<(Row, Vec<u32>)> = Vec::new();
                for v in &u.variants {
                    let mut sub = Walk::new(self.table);
                    sub.fields(prefix, &v.fields, body.clone(), "");
                    for fl in sub.flags {
                        if !self.flags.contains(&fl) {
                            self.flags.push(fl);
                        }
                    }
                    for r in sub.rows {
                        match tagged.iter_mut().find(|(t, _)| {
                            t.offset == r.offset && t.field == r.field && t.ty == r.ty
                        }) {
                            Some((_, tags)) => tags.push(v.tag),
                            None => tagged.push((r, vec![v.tag])),
                        }
                    }
                }
                for (mut r, tags) in tagged {
                    let which = match tags.as_slice() {
                        [t] => format!(" (tag {t} only)"),
                        [init @ .., last] => format!(
                            " (tags {} and {last})",
                            init.iter()
                                .map(u32::to_string)
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                        [] => String::new(),
                    };
                    r.field.push_str(&which);
                    self.rows.push(r);
                }
                Offset::unknown()
            }
            Ty::Vec(inner) => {
                let count = format!("n_{}", f.name);
                let max = f.max.unwrap_or(0);
                self.rows.push(Row {
                    offset: at.show(),
                    size: "8".to_owned(),
                    ty: "u64".to_owned(),
                    field: format!("`{name}` count {count}{note}"),
                    unit: String::new(),
                    frame: String::new(),
                    meaning: format!("0 ≤ {count} ≤ {max}, more is Malformed"),
                });
                let elems = at.plus(8);
                match &**inner {
                    Ty::Prim(p) => {
                        let m = self.meaning(f, inner);
                        let term = format!("{}·{count}", p.size());
                        self.push(
                            &elems,
                            term.clone(),
                            format!("{}[{count}]", p.name()),
                            format!("`{name}`{note}"),
                            f,
                            m,
                        );
                        elems.plus_term(term)
                    }
                    Ty::Struct(i) => {
                        let s = &self.table.structs[*i];
                        let m = if f.doc.is_empty() {
                            format!("table {} below", s.name)
                        } else {
                            format!("{}; table {} below", f.doc, s.name)
                        };
                        self.push(
                            &elems,
                            "…".to_owned(),
                            format!("{} × {count}", s.name),
                            format!("`{name}[i]`{note}"),
                            f,
                            m,
                        );
                        Offset::unknown()
                    }
                    _ => Offset::unknown(),
                }
            }
        }
    }

    fn render(&self) -> String {
        let mut out = String::from(
            "| offset | size | type | field | unit | frame | meaning |\n\
             |---:|---:|---|---|---|---|---|\n",
        );
        for r in &self.rows {
            out.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} |\n",
                r.offset,
                r.size,
                cell(&r.ty),
                cell(&r.field),
                cell(&r.unit),
                cell(&r.frame),
                cell(&r.meaning)
            ));
        }
        out
    }
}

/// The bit table `name`, and the reserved bits of a `width_bits` field.
fn flags_table(table: &Table, name: &str, width_bits: u32) -> String {
    let fl = table
        .flags
        .iter()
        .find(|f| f.name == name)
        .expect("checked table");
    let mut out =
        format!("Bits of `{name}`:\n\n| bit | mask | name | meaning |\n|---:|---:|---|---|\n");
    let mut top = 0;
    for b in &fl.bits {
        let hex = if width_bits <= 8 {
            format!("0x{:02X}", 1u32 << b.bit)
        } else {
            format!("0x{:X}", 1u32 << b.bit)
        };
        out.push_str(&format!(
            "| {} | {hex} | {} | {} |\n",
            b.bit,
            b.name,
            cell(&b.doc)
        ));
        top = top.max(b.bit + 1);
    }
    if top + 1 == width_bits {
        out.push_str(&format!(
            "\nBit {top} is reserved: sent as 0, ignored on receipt.\n"
        ));
    } else if top < width_bits {
        out.push_str(&format!(
            "\nBits {top}–{} are reserved: sent as 0, ignored on receipt.\n",
            width_bits - 1
        ));
    }
    out
}

/// The width in bits of the field that carries bit field `name`.
fn flags_width(table: &Table, name: &str) -> u32 {
    let all_fields = table
        .messages
        .iter()
        .flat_map(|m| m.fields.iter())
        .chain(table.structs.iter().flat_map(|s| s.fields.iter()));
    for f in all_fields {
        if f.flags.as_deref() == Some(name) {
            if let Ok(Ty::Prim(p)) = table.resolve(&f.ty) {
                return 8 * p.size() as u32;
            }
        }
    }
    8
}

/// The block of `what` (`message ImuMsg` or `struct EffectorState`), or why there is none.
pub fn block(table: &Table, what: &str) -> Result<String, String> {
    let (kind, name) = what
        .split_once(' ')
        .ok_or_else(|| format!("{what:?}: a block names `message NAME` or `struct NAME`"))?;
    let (fields, title) = match kind {
        "message" => {
            let m = table
                .message(name)
                .ok_or_else(|| format!("{what:?}: the table has no message {name}"))?;
            (&m.fields, None)
        }
        "struct" => {
            let s = table
                .structs
                .iter()
                .find(|s| s.name == name)
                .ok_or_else(|| format!("{what:?}: the table has no struct {name}"))?;
            (&s.fields, Some(&s.doc))
        }
        _ => {
            return Err(format!(
                "{what:?}: a block names `message NAME` or `struct NAME`"
            ))
        }
    };
    let mut walk = Walk::new(table);
    let end = walk.fields("", fields, Offset::zero(), "");
    let mut out = String::new();
    if let Some(doc) = title {
        out.push_str(&format!(
            "{name} — {doc} Offsets from the start of the element.\n\n"
        ));
    }
    out.push_str(&walk.render());
    if kind == "message" {
        let size = match table.fields_size(fields) {
            Some(n) => format!("{n} bytes, always"),
            None if !end.unknown => format!("{} bytes and up", end.show()),
            None => format!(
                "at least {} bytes (the counts and the tag give the rest)",
                table.fields_min_size(fields)
            ),
        };
        out.push_str(&format!("\nLength: {size}.\n"));
    }
    for fl in &walk.flags {
        out.push('\n');
        out.push_str(&flags_table(table, fl, flags_width(table, fl)));
    }
    Ok(out)
}

/// Opening marker of a generated block.
pub const OPEN: &str = "<!-- wire-table: ";
/// Closing marker of a generated block.
pub const CLOSE: &str = "<!-- /wire-table -->";

/// `readme` with every block rewritten from the table; `file` names it in errors. Every
/// message must have a block.
pub fn splice(table: &Table, file: &str, readme: &str) -> Result<String, String> {
    let mut out = String::new();
    let mut rest = readme;
    let mut seen = Vec::new();
    while let Some(start) = rest.find(OPEN) {
        let after_open = &rest[start + OPEN.len()..];
        let end_of_marker = after_open
            .find("-->")
            .ok_or_else(|| format!("{file}: a wire-table marker is not closed with -->"))?;
        let what = after_open[..end_of_marker].trim();
        let body_start = start + OPEN.len() + end_of_marker + 3;
        let close = rest[body_start..]
            .find(CLOSE)
            .ok_or_else(|| format!("{file}: the block {what:?} has no {CLOSE}"))?;
        out.push_str(&rest[..body_start]);
        out.push('\n');
        out.push_str(&block(table, what).map_err(|e| format!("{file}: {e}"))?);
        out.push_str(CLOSE);
        seen.push(what.to_owned());
        rest = &rest[body_start + close + CLOSE.len()..];
    }
    out.push_str(rest);
    for m in &table.messages {
        if !seen.contains(&format!("message {}", m.name)) {
            return Err(format!(
                "{file}: no block `{OPEN}message {} -->` (every message's table is generated)",
                m.name
            ));
        }
    }
    Ok(out)
}
