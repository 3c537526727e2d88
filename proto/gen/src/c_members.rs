//! The members of the C structs of `proto/c/include/flexdyn_proto.h`, walked once for the header
//! ([`crate::c_proto`] declares them) and for its Rust mirror in the C client library
//! ([`crate::c_ctypes`] declares the same members `#[repr(C)]`), so the two cannot disagree.
//!
//! A struct-typed field with `c_flatten` puts its struct's members in place, each name
//! prefixed; a union is its u32 tag then every variant's members once; a vec of structs is its
//! count, a pointer to the caller's array and that array's capacity; a vec of numbers is its count
//! and a fixed array of `max` entries.

use crate::table::{Field, Prim, Table, Ty};

/// The C type of a member.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CType {
    /// A number (`uint8_t` for a bool; a u32 for an enum's or a union's tag).
    Prim(Prim),
    /// A fixed array of numbers.
    Array(Prim, usize),
    /// A struct of the header, by index into [`Table::structs`] (`fd_<c_name>`).
    Struct(usize),
    /// A pointer to the caller's array of a struct (`fd_<c_name> *`).
    Elements(usize),
    /// The capacity of the caller's array (`size_t`).
    Capacity,
}

/// A member of a C struct.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CMember {
    /// Its name.
    pub name: String,
    /// Its type.
    pub ty: CType,
    /// The text of the comment after it (empty for none), safe inside `/* */`.
    pub comment: String,
}

/// Text safe inside a C comment: no comment terminator, one line.
pub fn comment(s: &str) -> String {
    s.replace("*/", "* /").replace('\n', " ")
}

/// `unit, frame: doc` for a field, empty when the table says nothing.
fn field_comment(f: &Field) -> String {
    let head = [&f.unit, &f.frame]
        .into_iter()
        .flatten()
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    let text = match (head.is_empty(), f.doc.is_empty()) {
        (true, true) => String::new(),
        (true, false) => f.doc.clone(),
        (false, true) => head,
        (false, false) => format!("{head}: {}", f.doc),
    };
    comment(&text)
}

/// The C members of `fields`, names prefixed with `prefix`.
pub fn members(t: &Table, fields: &[Field], prefix: &str) -> Vec<CMember> {
    let mut out = Vec::new();
    let mut push =
        |name: String, ty: CType, comment: String| out.push(CMember { name, ty, comment });
    for f in fields {
        let name = format!("{prefix}{}", f.name);
        match t.ty_of(f) {
            Ty::Prim(p) => push(name, CType::Prim(p), field_comment(f)),
            Ty::Array(p, n) => push(name, CType::Array(p, n), field_comment(f)),
            Ty::Enum(e) => {
                let tags = format!("FD_{}_*", t.enums[e].c_prefix());
                let text = match f.doc.is_empty() {
                    true => tags,
                    false => format!("{tags}: {}", comment(&f.doc)),
                };
                push(name, CType::Prim(Prim::U32), text)
            }
            Ty::Struct(s) => match &f.c_flatten {
                Some(p) => {
                    for m in members(t, &t.structs[s].fields, &format!("{prefix}{p}")) {
                        push(m.name, m.ty, m.comment);
                    }
                }
                None => push(name, CType::Struct(s), field_comment(f)),
            },
            Ty::Union(u) => {
                let un = &t.unions[u];
                push(
                    name,
                    CType::Prim(Prim::U32),
                    format!("FD_{}_*: {}", un.c_prefix, comment(&un.doc)),
                );
                // Every variant's members once (a name the variants share has one type).
                let mut seen: Vec<(String, CType)> = Vec::new();
                for v in &un.variants {
                    for m in members(t, &v.fields, prefix) {
                        if !seen.contains(&(m.name.clone(), m.ty)) {
                            seen.push((m.name.clone(), m.ty));
                            push(m.name, m.ty, m.comment);
                        }
                    }
                }
            }
            Ty::Vec(inner) => {
                push(format!("n_{name}"), CType::Prim(Prim::U64), String::new());
                match *inner {
                    Ty::Struct(s) => {
                        let doc = comment(&f.doc);
                        push(
                            name.clone(),
                            CType::Elements(s),
                            format!("caller storage, n_{name} entries: {doc}"),
                        );
                        push(
                            format!("{name}_capacity"),
                            CType::Capacity,
                            format!("entries {name} can hold"),
                        );
                    }
                    Ty::Prim(p) => push(
                        name,
                        CType::Array(p, f.max.unwrap_or(0) as usize),
                        field_comment(f),
                    ),
                    _ => unreachable!("the table's layout rules: a vec of numbers or structs"),
                }
            }
        }
    }
    out
}

/// Whether a struct is a C type of its own (some field or vec uses it without flattening).
pub fn struct_used(t: &Table, s: usize) -> bool {
    t.struct_used(s, |f, elem| elem || f.c_flatten.is_none())
}
