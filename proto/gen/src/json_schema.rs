//! The JSON Schemas (draft 2020-12) of the messages as JSON: what the recorder writes on an MCAP
//! file's decoded channels and the viewer sends to Foxglove. They describe the JSON the wire
//! structs serialize to (serde's human-readable form): a struct is an object of its fields, an
//! enumeration its value's name, a tagged union `{"Variant": {fields}}` (a variant without
//! fields: its name), a text field a string up to its first NUL, an array or a vec a JSON array.
//!
//! Each field's description carries its unit and frame from the table.

use std::fmt::Write as _;

use serde_json::{json, Map, Value};

use crate::table::{Field, Prim, Table, Ty};

/// The description of a field: its meaning, then its unit and frame.
pub(crate) fn description(f: &Field) -> String {
    let mut extra = Vec::new();
    if let Some(u) = &f.unit {
        extra.push(format!("unit {u}"));
    }
    if let Some(fr) = &f.frame {
        extra.push(format!("frame {fr}"));
    }
    if f.finite {
        extra.push("finite".to_owned());
    }
    match (f.doc.is_empty(), extra.is_empty()) {
        (_, true) => f.doc.clone(),
        (true, false) => extra.join(", "),
        (false, false) => format!("{} ({})", f.doc, extra.join(", ")),
    }
}

fn prim(p: Prim) -> Value {
    match p {
        Prim::U8 => json!({"type": "integer", "minimum": 0, "maximum": u8::MAX}),
        Prim::U16 => json!({"type": "integer", "minimum": 0, "maximum": u16::MAX}),
        Prim::U32 => json!({"type": "integer", "minimum": 0, "maximum": u32::MAX}),
        Prim::U64 => json!({"type": "integer", "minimum": 0, "maximum": u64::MAX}),
        Prim::I32 => json!({"type": "integer", "minimum": i32::MIN, "maximum": i32::MAX}),
        Prim::F64 => json!({"type": "number"}),
        Prim::Bool => json!({"type": "boolean"}),
    }
}

/// The schema of a type (`f`: the field it is, for its text flag and its vec bound).
fn of_type(table: &Table, ty: &Ty, f: Option<&Field>) -> Value {
    match ty {
        Ty::Prim(p) => prim(*p),
        Ty::Array(_, n) if f.is_some_and(|f| f.text) => {
            json!({"type": "string", "maxLength": n})
        }
        Ty::Array(p, n) => {
            json!({"type": "array", "items": prim(*p), "minItems": n, "maxItems": n})
        }
        Ty::Struct(i) => object(table, &table.structs[*i].fields),
        Ty::Enum(i) => {
            let names: Vec<&str> = table.enums[*i]
                .values
                .iter()
                .map(|v| v.name.as_str())
                .collect();
            json!({"type": "string", "enum": names})
        }
        Ty::Union(i) => {
            let variants: Vec<Value> = table.unions[*i]
                .variants
                .iter()
                .map(|v| {
                    if v.fields.is_empty() {
                        json!({"const": v.name})
                    } else {
                        let mut props = Map::new();
                        props.insert(v.name.clone(), object(table, &v.fields));
                        json!({
                            "type": "object",
                            "properties": props,
                            "required": [v.name],
                            "additionalProperties": false
                        })
                    }
                })
                .collect();
            json!({ "oneOf": variants })
        }
        Ty::Vec(inner) => json!({
            "type": "array",
            "items": of_type(table, inner, None),
            "maxItems": f.and_then(|f| f.max).unwrap_or(0)
        }),
    }
}

/// An object of `fields`, every one required and no other.
fn object(table: &Table, fields: &[Field]) -> Value {
    let mut props = Map::new();
    for f in fields {
        let ty = table.resolve(&f.ty).expect("checked table");
        let mut field = Map::new();
        let d = description(f);
        if !d.is_empty() {
            field.insert("description".to_owned(), json!(d));
        }
        if let Value::Object(schema) = of_type(table, &ty, Some(f)) {
            field.extend(schema);
        }
        props.insert(f.name.clone(), Value::Object(field));
    }
    let required: Vec<&str> = fields.iter().map(|f| f.name.as_str()).collect();
    json!({
        "type": "object",
        "properties": props,
        "required": required,
        "additionalProperties": false
    })
}

/// The schema of message `name` as a JSON value.
pub fn schema_value(table: &Table, name: &str) -> Option<Value> {
    let m = table.message(name)?;
    let mut out = Map::new();
    out.insert(
        "$schema".to_owned(),
        json!("https://json-schema.org/draft/2020-12/schema"),
    );
    out.insert("title".to_owned(), json!(m.name));
    out.insert(
        "description".to_owned(),
        json!(format!(
            "{} ({}; protocol {})",
            m.doc, m.key, table.protocol_version
        )),
    );
    if let Value::Object(body) = object(table, &m.fields) {
        out.extend(body);
    }
    Some(Value::Object(out))
}

/// The schema of message `name`, as the text of its JSON file.
pub fn schema(table: &Table, name: &str) -> Option<String> {
    let v = schema_value(table, name)?;
    let mut text = serde_json::to_string_pretty(&v).ok()?;
    text.push('\n');
    Some(text)
}

/// `proto/src/json_schemas.rs`: the schemas by message name, for the crates that publish them.
pub fn rust_module(table: &Table) -> String {
    let mut o = String::from(
        "//! The JSON Schemas of the messages' JSON (draft 2020-12), written by flexdyn-wiregen from\n\
         //! proto/schema/messages.toml into proto/schema/json/: do not edit; change the table and run\n\
         //! `cargo run -p flexdyn-wiregen`.\n\n\
         /// The JSON Schema text of the message named `name` (`\"ImuMsg\"`, a\n\
         /// [`crate::WireMessage::NAME`]), `None` for another name.\n\
         pub fn json_schema_text(name: &str) -> Option<&'static str> {\n    match name {\n",
    );
    for m in &table.messages {
        let _ = writeln!(
            o,
            "        {:?} => Some(include_str!(\"../schema/json/{}.json\")),",
            m.name, m.name
        );
    }
    o.push_str("        _ => None,\n    }\n}\n");
    o
}
