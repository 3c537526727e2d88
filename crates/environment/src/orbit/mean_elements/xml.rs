//! CCSDS OMM in XML (the NDM/XML schema, CCSDS 505.0-B-2, as CelesTrak and Space-Track serve
//! it): `<ndm><omm>…</omm>…</ndm>` or a bare `<omm>`. Each `<omm>`'s leaf elements
//! (`<EPOCH>`, `<MEAN_MOTION>`, `<BSTAR>`, …) become the fields of one element set; a `units`
//! attribute is the field's unit.
//!
//! The reader is a small, strict XML 1.0 parser for what these documents use: the XML
//! declaration, comments, processing instructions, elements with quoted attributes, character
//! data with the five predefined entities and numeric character references, and CDATA. It
//! checks well-formedness (every tag closed, in order; one root) and rejects a DOCTYPE (no
//! entity expansion). Namespace prefixes are dropped from element names.

use super::fields::{RawField, RawSet};

/// An element: name (prefix dropped), `units` attribute, text, children, line.
#[derive(Debug, Default)]
struct Element {
    name: String,
    units: Option<String>,
    text: String,
    children: Vec<Element>,
    line: usize,
}

struct Parser<'a> {
    s: &'a str,
    i: usize,
    /// (byte offset, line) of the last line computed: the offset only grows, so counting
    /// from there keeps the whole parse linear.
    line_cache: std::cell::Cell<(usize, usize)>,
}

impl<'a> Parser<'a> {
    fn line(&self) -> usize {
        let (at, line) = self.line_cache.get();
        let i = self.i.min(self.s.len());
        let line = line + self.s[at.min(i)..i].matches('\n').count();
        self.line_cache.set((i, line));
        line
    }
    fn err<T>(&self, m: impl Into<String>) -> Result<T, String> {
        Err(format!("line {}: {}", self.line(), m.into()))
    }
    fn rest(&self) -> &'a str {
        &self.s[self.i..]
    }
    fn skip_ws(&mut self) {
        let r = self.rest();
        self.i += r.len() - r.trim_start().len();
    }
    /// Skips `<?…?>`, `<!--…-->` and whitespace; errors on a DOCTYPE.
    fn skip_misc(&mut self) -> Result<(), String> {
        loop {
            self.skip_ws();
            let r = self.rest();
            if r.starts_with("<?") {
                match r.find("?>") {
                    Some(k) => self.i += k + 2,
                    None => return self.err("unterminated `<?`"),
                }
            } else if let Some(body) = r.strip_prefix("<!--") {
                match body.find("-->") {
                    Some(k) => self.i += 4 + k + 3,
                    None => return self.err("unterminated comment"),
                }
            } else if r.starts_with("<!DOCTYPE") {
                return self.err("a DOCTYPE is not accepted in an OMM document");
            } else {
                return Ok(());
            }
        }
    }
    fn name(&mut self) -> Result<&'a str, String> {
        let r = self.rest();
        let n = r
            .find(|c: char| c.is_whitespace() || c == '>' || c == '/' || c == '=')
            .unwrap_or(r.len());
        if n == 0 {
            return self.err("expected a name");
        }
        self.i += n;
        Ok(&r[..n])
    }
    fn element(&mut self, depth: usize) -> Result<Element, String> {
        if depth > 64 {
            return self.err("elements nested more than 64 deep");
        }
        let line = self.line();
        if !self.rest().starts_with('<') {
            return self.err("expected `<`");
        }
        self.i += 1;
        let qname = self.name()?;
        let name = qname.rsplit(':').next().unwrap_or(qname).to_string();
        let mut el = Element {
            name,
            line,
            ..Element::default()
        };
        // Attributes.
        loop {
            self.skip_ws();
            let r = self.rest();
            if r.starts_with("/>") {
                self.i += 2;
                return Ok(el);
            }
            if r.starts_with('>') {
                self.i += 1;
                break;
            }
            if r.is_empty() {
                return self.err(format!("unterminated tag <{qname}>"));
            }
            let attr = self.name()?;
            self.skip_ws();
            if !self.rest().starts_with('=') {
                return self.err(format!("expected `=` after attribute {attr:?}"));
            }
            self.i += 1;
            self.skip_ws();
            let q = match self.rest().chars().next() {
                Some(c @ ('"' | '\'')) => c,
                _ => return self.err(format!("attribute {attr:?}: expected a quoted value")),
            };
            self.i += 1;
            let Some(end) = self.rest().find(q) else {
                return self.err(format!("attribute {attr:?}: unterminated value"));
            };
            let raw = &self.rest()[..end];
            let value = unescape(raw).map_err(|m| format!("line {}: {m}", self.line()))?;
            self.i += end + 1;
            if attr.rsplit(':').next() == Some("units") {
                el.units = Some(value);
            }
        }
        // Content.
        loop {
            let r = self.rest();
            if r.starts_with("</") {
                self.i += 2;
                let close = self.name()?;
                if close != qname {
                    return self.err(format!(
                        "</{close}> closes <{qname}> (opened at line {line})"
                    ));
                }
                self.skip_ws();
                if !self.rest().starts_with('>') {
                    return self.err(format!("expected `>` after </{close}"));
                }
                self.i += 1;
                return Ok(el);
            } else if let Some(body) = r.strip_prefix("<!--") {
                match body.find("-->") {
                    Some(k) => self.i += 4 + k + 3,
                    None => return self.err("unterminated comment"),
                }
            } else if let Some(rest) = r.strip_prefix("<![CDATA[") {
                match rest.find("]]>") {
                    Some(k) => {
                        el.text.push_str(&rest[..k]);
                        self.i += 9 + k + 3;
                    }
                    None => return self.err("unterminated CDATA section"),
                }
            } else if r.starts_with("<?") {
                match r.find("?>") {
                    Some(k) => self.i += k + 2,
                    None => return self.err("unterminated `<?`"),
                }
            } else if r.starts_with('<') {
                el.children.push(self.element(depth + 1)?);
            } else if r.is_empty() {
                return self.err(format!("<{qname}> (line {line}) is never closed"));
            } else {
                let k = r.find('<').unwrap_or(r.len());
                let text = unescape(&r[..k]).map_err(|m| format!("line {}: {m}", self.line()))?;
                el.text.push_str(&text);
                self.i += k;
            }
        }
    }
}

/// Replaces the predefined entities and character references.
fn unescape(s: &str) -> Result<String, String> {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(k) = rest.find('&') {
        out.push_str(&rest[..k]);
        let after = &rest[k + 1..];
        let Some(end) = after.find(';') else {
            return Err("`&` without a closing `;`".to_string());
        };
        let ent = &after[..end];
        let c = match ent {
            "lt" => '<',
            "gt" => '>',
            "amp" => '&',
            "quot" => '"',
            "apos" => '\'',
            _ => {
                let code = if let Some(h) = ent.strip_prefix("#x").or(ent.strip_prefix("#X")) {
                    u32::from_str_radix(h, 16).ok()
                } else if let Some(d) = ent.strip_prefix('#') {
                    d.parse::<u32>().ok()
                } else {
                    None
                };
                code.and_then(char::from_u32)
                    .ok_or_else(|| format!("unknown entity `&{ent};`"))?
            }
        };
        out.push(c);
        rest = &after[end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Collects the leaf elements under `el` as fields.
fn leaves(el: &Element, out: &mut Vec<RawField>) {
    for c in &el.children {
        if c.children.is_empty() {
            out.push(RawField {
                key: c.name.clone(),
                value: c.text.trim().to_string(),
                unit: c.units.clone(),
                line: c.line,
            });
        } else {
            leaves(c, out);
        }
    }
}

fn find_omm<'e>(el: &'e Element, out: &mut Vec<&'e Element>) {
    if el.name == "omm" {
        out.push(el);
    } else {
        for c in &el.children {
            find_omm(c, out);
        }
    }
}

/// The element sets of an XML text.
pub(crate) fn read(text: &str) -> Result<Vec<RawSet>, String> {
    let mut p = Parser {
        s: text,
        i: 0,
        line_cache: std::cell::Cell::new((0, 1)),
    };
    p.skip_misc()?;
    let root = p.element(0)?;
    p.skip_misc()?;
    if !p.rest().is_empty() {
        return p.err("content after the root element");
    }
    let mut omms = Vec::new();
    find_omm(&root, &mut omms);
    if omms.is_empty() {
        return Err(format!(
            "no <omm> element (the root is <{}>): not a CCSDS OMM document",
            root.name
        ));
    }
    Ok(omms
        .into_iter()
        .map(|o| {
            let mut fields = Vec::new();
            leaves(o, &mut fields);
            // USER_DEFINED elements carry their keyword in an attribute; CCSDS_OMM_VERS is the
            // <omm version> attribute, not an element.
            fields.retain(|f| f.key != "USER_DEFINED");
            RawSet { fields }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn well_formedness() {
        assert!(read("<omm><a>1</b></omm>")
            .unwrap_err()
            .contains("</b> closes <a>"));
        assert!(read("<omm><a>1</a>").unwrap_err().contains("never closed"));
        assert!(read("<!DOCTYPE x><omm/>").unwrap_err().contains("DOCTYPE"));
        assert!(read("<omm/><omm/>").unwrap_err().contains("after the root"));
        assert!(read("<x/>").unwrap_err().contains("no <omm>"));
        let sets = read(
            "<?xml version=\"1.0\"?>\n<!-- c -->\n<ndm:ndm xmlns:ndm='u'><ndm:omm>\n<A units=\"deg\">1&amp;2</A>\n<B><![CDATA[<x>]]></B><C/></ndm:omm></ndm:ndm>",
        )
        .unwrap();
        let f = &sets[0].fields;
        assert_eq!((f[0].key.as_str(), f[0].value.as_str()), ("A", "1&2"));
        assert_eq!((f[0].unit.as_deref(), f[0].line), (Some("deg"), 4));
        assert_eq!(f[1].value, "<x>");
        assert_eq!((f[2].key.as_str(), f[2].value.as_str()), ("C", ""));
    }
}
