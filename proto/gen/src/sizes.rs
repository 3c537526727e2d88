//! What every generated codec derives from the table the same way: the split of a field list
//! into its fixed part and its variable tail, which structs the messages use, the named encoded
//! sizes and offsets, and the parameters of a key function.

use crate::table::{key_chunks, screaming_snake, Field, Message, Prim, Table, Ty};

impl Table {
    /// A field's type (the table has been checked, so it resolves).
    pub fn ty_of(&self, f: &Field) -> Ty {
        self.resolve(&f.ty).expect("the table was checked")
    }

    /// A field list split into its fixed part and its variable last field, if any (the layout
    /// rules allow only the last field to vary).
    pub fn split_tail<'f>(&self, fields: &'f [Field]) -> (&'f [Field], Option<&'f Field>) {
        match fields.last() {
            Some(f) if self.fixed_size(&self.ty_of(f)).is_none() => {
                (&fields[..fields.len() - 1], Some(f))
            }
            _ => (fields, None),
        }
    }

    /// Whether some field of a message, struct or union variant uses struct `s` in a way
    /// `counts` accepts (given the field and whether it is a vec's element).
    pub fn struct_used(&self, s: usize, counts: impl Fn(&Field, bool) -> bool) -> bool {
        let uses = |fields: &[Field]| {
            fields.iter().any(|f| match self.resolve(&f.ty) {
                Ok(Ty::Struct(i)) => i == s && counts(f, false),
                Ok(Ty::Vec(inner)) => *inner == Ty::Struct(s) && counts(f, true),
                _ => false,
            })
        };
        self.messages.iter().any(|m| uses(&m.fields))
            || self.structs.iter().any(|x| uses(&x.fields))
            || self
                .unions
                .iter()
                .any(|u| u.variants.iter().any(|v| uses(&v.fields)))
    }
}

/// A named encoded size or offset (`STATE_FIXED_LEN`; C adds `FD_`).
pub struct SizeConst {
    /// Its name.
    pub name: String,
    /// Bytes.
    pub value: usize,
    /// What it is.
    pub note: String,
}

/// The name of an encoded size: `<PREFIX>_LEN` when `fixed`, else `<PREFIX>_FIXED_LEN` (the
/// length with every vec empty).
pub fn len_name(prefix: &str, fixed: bool) -> String {
    if fixed {
        format!("{prefix}_LEN")
    } else {
        format!("{prefix}_FIXED_LEN")
    }
}

/// Every named size and offset: each used struct's length (or fixed length), each message's
/// length, or for a variable one its fixed length and the offset of its count or tag and each
/// union variant's length, and the offset of each byte block (`u8[n]`).
pub fn size_constants(t: &Table) -> Vec<SizeConst> {
    let mut out = Vec::new();
    let mut push =
        |name: String, value: usize, note: String| out.push(SizeConst { name, value, note });
    for (i, s) in t.structs.iter().enumerate() {
        if !t.struct_used(i, |_, _| true) {
            continue;
        }
        let c = s.c_name().to_ascii_uppercase();
        match t.fields_size(&s.fields) {
            Some(n) => push(len_name(&c, true), n, s.name.clone()),
            None => push(
                len_name(&c, false),
                t.fields_min_size(&s.fields),
                format!("{} without its vecs' elements", s.name),
            ),
        }
    }
    for m in &t.messages {
        let u = m.upper();
        let (fixed, tail) = t.split_tail(&m.fields);
        let since = if m.since > 1 {
            format!(", since protocol {}", m.since)
        } else {
            String::new()
        };
        let prefix = t.fields_size(fixed).expect("fixed");
        match tail.map(|f| (f, t.ty_of(f))) {
            None => push(len_name(&u, true), prefix, format!("{}{since}", m.name)),
            Some((f, Ty::Vec(_))) => {
                push(
                    len_name(&u, false),
                    prefix + 8,
                    format!("{} with no {}{since}", m.name, f.name),
                );
                push(
                    format!("{u}_{}_COUNT_OFFSET", f.name.to_ascii_uppercase()),
                    prefix,
                    format!("the u64 count of {}", f.name),
                );
            }
            Some((f, Ty::Union(ui))) => {
                push(
                    format!("{u}_{}_OFFSET", f.name.to_ascii_uppercase()),
                    prefix,
                    format!("the u32 tag of {}{since}", f.name),
                );
                for v in &t.unions[ui].variants {
                    let vu = format!("{u}_{}", screaming_snake(&v.name));
                    let (vf, vt) = t.split_tail(&v.fields);
                    let n = prefix + 4 + t.fields_size(vf).expect("fixed");
                    match vt {
                        None => push(len_name(&vu, true), n, format!("{} {}", m.name, v.name)),
                        Some(_) => push(
                            len_name(&vu, false),
                            n + 8,
                            format!("{} {} with no elements", m.name, v.name),
                        ),
                    }
                }
            }
            Some(_) => unreachable!("only a vec or a union varies"),
        }
        // Byte blocks (u8[n]) have a named offset, for code that reads them in place.
        let mut k = 0;
        for f in fixed {
            let ty = t.ty_of(f);
            if let Ty::Array(Prim::U8, _) = ty {
                push(
                    format!("{u}_{}_OFFSET", f.name.to_ascii_uppercase()),
                    k,
                    f.name.clone(),
                );
            }
            k += t.fixed_size(&ty).expect("fixed");
        }
    }
    out
}

/// The last parameter of a key function.
pub enum KeyName {
    /// The key has no name chunk.
    None,
    /// A participant's numeric id (`<sender-id>`), written in decimal.
    SenderId,
    /// A name chunk, by its parameter name (`name`, `chief`).
    Text(String),
}

/// A key function's parameters: the vehicle chunk's (`sc`, `deputy`) and the name chunk's.
pub fn key_params(m: &Message) -> (String, KeyName) {
    let chunks = key_chunks(&m.key);
    let param = |p: &str| {
        p.trim_start_matches('<')
            .trim_end_matches('>')
            .trim_end_matches("-id")
            .replace('-', "_")
    };
    let vehicle = param(chunks.get(1).copied().unwrap_or("<sc-id>"));
    let last = match (m.named(), chunks.last().copied()) {
        (true, Some("<sender-id>")) => KeyName::SenderId,
        (true, Some(p)) => KeyName::Text(param(p)),
        _ => KeyName::None,
    };
    (vehicle, last)
}

/// `text` wrapped at `width` columns, each line after the first starting with `indent`.
pub fn wrap(text: &str, width: usize, indent: &str) -> String {
    let mut out = String::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && line.len() + 1 + word.len() > width {
            out.push_str(&line);
            out.push('\n');
            out.push_str(indent);
            line.clear();
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    out.push_str(&line);
    out
}

/// Each line indented by `n` spaces and ended with a newline (an empty line stays empty).
pub fn indent<'a>(lines: impl Iterator<Item = &'a str>, n: usize) -> String {
    let pad = " ".repeat(n);
    lines
        .map(|l| {
            if l.is_empty() {
                "\n".to_owned()
            } else {
                format!("{pad}{l}\n")
            }
        })
        .collect()
}
