//! The wire table against what it describes, and the mirrors against the table.
//!
//! - Every generated file in the tree is what the table gives today (a mirror cannot lag).
//! - The table against the hand-derived golden vectors of `proto/golden/`, which are not
//!   generated from it: read as a decoder (field by field, in its order and types, with no
//!   bincode or serde) the table turns every golden into the same values, under the same names,
//!   as the Rust decoder (bincode over the generated types). A field the generator misplaces,
//!   or a golden the table does not describe byte for byte, fails here.
//! - Mistakes in the table are refused with the entry and field named, by the table's checks or
//!   by the generator of the mirror that cannot be written.

use std::path::{Path, PathBuf};

use flexdyn_proto::WireMessage;
use flexdyn_wiregen::table::{Prim, Table, Ty};
use serde_json::{json, Map, Value};

mod shapes;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn table() -> Table {
    flexdyn_wiregen::read_table(&root()).expect("the wire table reads")
}

#[test]
fn every_mirror_is_what_the_table_gives() {
    let stale = flexdyn_wiregen::stale(&root()).expect("the mirrors are generated");
    assert!(
        stale.is_empty(),
        "{stale:?} differ from proto/schema/messages.toml: run `cargo run -p flexdyn-wiregen` and \
         commit the result (never edit a generated file by hand)"
    );
}

/// Reads `ty` at `*pos` of `bytes` as the table says, into the JSON the Rust types serialize
/// to (serde's human-readable form: unit enums by name, a union as `{variant: fields}`, text as
/// a string up to its first NUL).
fn read(table: &Table, ty: &Ty, text: bool, bytes: &[u8], pos: &mut usize) -> Value {
    let mut take = |n: usize| -> &[u8] {
        let s = &bytes[*pos..*pos + n];
        *pos += n;
        s
    };
    match ty {
        Ty::Prim(p) => {
            let b = take(p.size());
            match p {
                Prim::U8 => json!(b[0]),
                Prim::Bool => {
                    assert!(b[0] <= 1, "a bool byte {}", b[0]);
                    json!(b[0] == 1)
                }
                Prim::U16 => json!(u16::from_le_bytes([b[0], b[1]])),
                Prim::U32 => json!(u32::from_le_bytes(b.try_into().unwrap())),
                Prim::I32 => json!(i32::from_le_bytes(b.try_into().unwrap())),
                Prim::U64 => json!(u64::from_le_bytes(b.try_into().unwrap())),
                Prim::F64 => json!(f64::from_le_bytes(b.try_into().unwrap())),
            }
        }
        Ty::Array(p, n) => {
            if text {
                let b = take(*n);
                let end = b.iter().position(|&x| x == 0).unwrap_or(*n);
                return json!(String::from_utf8_lossy(&b[..end]));
            }
            Value::Array(
                (0..*n)
                    .map(|_| read(table, &Ty::Prim(*p), false, bytes, pos))
                    .collect(),
            )
        }
        Ty::Struct(i) => read_fields(table, &table.structs[*i].fields, bytes, pos),
        Ty::Enum(i) => {
            let tag = u32::from_le_bytes(take(4).try_into().unwrap());
            let e = &table.enums[*i];
            json!(e.values[tag as usize].name)
        }
        Ty::Union(i) => {
            let tag = u32::from_le_bytes(take(4).try_into().unwrap());
            let v = &table.unions[*i].variants[tag as usize];
            if v.fields.is_empty() {
                json!(v.name)
            } else {
                let fields = read_fields(table, &v.fields, bytes, pos);
                let mut m = Map::new();
                m.insert(v.name.clone(), fields);
                Value::Object(m)
            }
        }
        Ty::Vec(inner) => {
            let n = u64::from_le_bytes(take(8).try_into().unwrap());
            Value::Array(
                (0..n)
                    .map(|_| read(table, inner, false, bytes, pos))
                    .collect(),
            )
        }
    }
}

fn read_fields(
    table: &Table,
    fields: &[flexdyn_wiregen::table::Field],
    bytes: &[u8],
    pos: &mut usize,
) -> Value {
    let mut m = Map::new();
    for f in fields {
        let ty = table.resolve(&f.ty).expect("checked");
        m.insert(f.name.clone(), read(table, &ty, f.text, bytes, pos));
    }
    Value::Object(m)
}

/// The Rust decoder's view of golden `name` as JSON, and its table-driven reading.
fn both<T: WireMessage>(table: &Table, name: &str) -> (Value, Value) {
    let bytes = std::fs::read(root().join(format!("proto/golden/{name}.bin"))).unwrap();
    let rust: T = flexdyn_proto::decode(&bytes).unwrap();
    let msg = table
        .message(T::NAME)
        .unwrap_or_else(|| panic!("the table has no message {}", T::NAME));
    let mut pos = 0;
    let by_table = read_fields(table, &msg.fields, &bytes, &mut pos);
    assert_eq!(
        pos,
        bytes.len(),
        "{name}: the table reads {pos} of {} bytes",
        bytes.len()
    );
    (serde_json::to_value(&rust).unwrap(), by_table)
}

/// Checks one message type against the table: every golden of it. (Its lengths are not checked
/// here: the codec's come from the table, `proto/src/wire.rs`; the goldens pin them.)
fn agree<T: WireMessage>(table: &Table, goldens: &[&str], seen: &mut Vec<&'static str>) {
    for g in goldens {
        let (rust, by_table) = both::<T>(table, g);
        assert_eq!(
            rust, by_table,
            "golden {g}: the Rust decoder (left) and the table (right)"
        );
    }
    seen.push(T::NAME);
}

#[test]
fn the_table_reads_every_golden_as_the_rust_decoder_does() {
    use flexdyn_proto::*;
    let t = table();
    assert_eq!(t.protocol_version, PROTOCOL_VERSION);
    let mut seen = Vec::new();
    agree::<StateMsg>(&t, &["state"], &mut seen);
    agree::<ImuMsg>(&t, &["imu"], &mut seen);
    agree::<StarTrackerMsg>(&t, &["star_tracker"], &mut seen);
    agree::<MagnetometerMsg>(&t, &["magnetometer"], &mut seen);
    agree::<CssMsg>(&t, &["css"], &mut seen);
    agree::<FssMsg>(&t, &["fss"], &mut seen);
    agree::<GpsMsg>(&t, &["gps"], &mut seen);
    agree::<CommandMsg>(
        &t,
        &["command_wrench", "command_no_command", "command_actuators"],
        &mut seen,
    );
    agree::<TimeMsg>(&t, &["time"], &mut seen);
    agree::<EnvironmentMsg>(&t, &["environment"], &mut seen);
    agree::<OperatorMsg>(&t, &["operator", "operator_checkpoint"], &mut seen);
    agree::<FaultEventMsg>(&t, &["fault_event"], &mut seen);
    agree::<FaultCommandMsg>(&t, &["fault_command"], &mut seen);
    agree::<RelativeStateMsg>(&t, &["relative_state"], &mut seen);
    agree::<flexdyn_proto::FswMsg>(&t, &["fsw"], &mut seen);
    agree::<StatusMsg>(&t, &["status"], &mut seen);
    // Every message of the table is a Rust message checked here, and the reverse.
    let mut in_table: Vec<&str> = t.messages.iter().map(|m| m.name.as_str()).collect();
    in_table.sort_unstable();
    seen.sort_unstable();
    assert_eq!(in_table, seen);
    // Every golden file is read above (MANIFEST.tsv lists them).
    let manifest = std::fs::read_to_string(root().join("proto/golden/MANIFEST.tsv")).unwrap();
    let goldens = manifest
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .count();
    assert_eq!(goldens, 19, "a golden was added: read it above");
}

#[test]
fn the_keys_are_the_rust_keys() {
    use flexdyn_proto::Topics;
    let t = table();
    let topics = Topics::new("sc1").unwrap();
    let key = |c: &str, name: &str| -> String {
        let m = t.messages.iter().find(|m| m.c_name == c).unwrap();
        let base = format!("flexdyn/sc1/{}", m.key_tail());
        if m.named() {
            format!("{base}/{name}")
        } else {
            base
        }
    };
    assert_eq!(key("state", ""), topics.state());
    assert_eq!(key("imu", "hub"), topics.imu("hub").unwrap());
    assert_eq!(
        key("star_tracker", "st1"),
        topics.star_tracker("st1").unwrap()
    );
    for (c, prefix) in [
        ("magnetometer", flexdyn_proto::MAGNETOMETER_PREFIX),
        ("css", flexdyn_proto::CSS_PREFIX),
        ("fss", flexdyn_proto::FSS_PREFIX),
        ("gps", flexdyn_proto::GPS_PREFIX),
    ] {
        assert_eq!(key(c, "x1"), topics.sensor(prefix, "x1").unwrap(), "{c}");
    }
    assert_eq!(key("command", "7"), topics.cmd(7));
    assert_eq!(key("time", ""), topics.time());
    assert_eq!(key("environment", ""), topics.environment());
    assert_eq!(key("operator", ""), topics.operator());
    assert_eq!(key("fault_event", ""), topics.fault_events());
    assert_eq!(key("fault_command", ""), topics.fault());
    assert_eq!(
        key("relative_state", "chief"),
        topics.relative_state("chief").unwrap()
    );
    assert_eq!(key("status", ""), topics.status());
    assert_eq!(
        key("fsw", "acs"),
        flexdyn_proto::fsw_key("sc1", "acs").unwrap()
    );
}

/// The table with `from` replaced by `to` (once).
fn edited(from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(root().join(flexdyn_wiregen::TABLE_PATH)).unwrap();
    assert!(text.contains(from), "{from:?} is not in the table");
    text.replacen(from, to, 1)
}

#[test]
fn mistakes_in_the_table_are_named() {
    let cases = [
        (
            edited(
                r#"{ name = "b_s_t", type = "f64[3]""#,
                r#"{ name = "b_s_t", type = "f65[3]""#,
            ),
            "message MagnetometerMsg, field \"b_s_t\"",
        ),
        (
            edited(
                r#"{ name = "saturation_flags", type = "u8", flags = "magnetometer_flags""#,
                r#"{ name = "saturation_flags", type = "u8", flags = "magnetometer_bits""#,
            ),
            "no [[flags]] table \"magnetometer_bits\"",
        ),
        (
            edited(
                r#"{ name = "effectors", type = "vec<EffectorState>", max = 1024"#,
                r#"{ name = "effectors", type = "vec<EffectorState>""#,
            ),
            "a vec needs `max`",
        ),
        (
            edited(
                r#"{ name = "alpha_rad", type = "f64""#,
                r#"{ name = "beta_rad", type = "f64""#,
            ),
            "message FssMsg, field \"beta_rad\": the name is used twice",
        ),
        (
            edited(r#"c_name = "gps""#, r#"c_name = "css""#),
            "message GpsMsg, c_name",
        ),
        (
            edited(
                r#"{ value = 1, name = "Resume""#,
                r#"{ value = 2, name = "Resume""#,
            ),
            "enum OperatorAction, value \"Resume\"",
        ),
        (
            edited("since = 9", "since = 13"),
            "message RelativeStateMsg, since",
        ),
        (
            // A vec that is not last would move every field after it.
            edited(
                r#"  { name = "command_flags", type = "u8", flags = "command_flags""#,
                r#"  { name = "extra", type = "vec<f64>", max = 4, doc = "" },
  { name = "command_flags", type = "u8", flags = "command_flags""#,
            ),
            "message StateMsg, field \"extra\": a vec is the last field",
        ),
        (
            edited(
                r#"{ name = "range_m", type = "f64""#,
                r#"{ name = "range_m", type = "f64", c_flatten = """#,
            ),
            "`c_flatten` is for a struct-typed field",
        ),
        (
            edited(r#"value = "0xFFFFFFFFFFFFFFFF""#, r#"value = "FFFF""#),
            "constant \"AT_NEXT_TICK\"",
        ),
        (
            edited(r#"default = "AT_NEXT_TICK""#, r#"default = "AT_NEXT_TOCK""#),
            "field \"at_tick\": `default`: no [[constant]] named \"AT_NEXT_TOCK\"",
        ),
        (
            edited(r#"default = "NoCommand""#, r#"default = "Nothing""#),
            "`default`: union CommandKind has no variant \"Nothing\"",
        ),
        (
            edited(
                r#"{ name = "drag", type = "AppliedWrench","#,
                r#"{ name = "drag", type = "AppliedWrench", py_tuple = true,"#,
            ),
            "field \"drag\": `py_tuple` is for a struct of numbers",
        ),
        (
            edited(
                r#"{ name = "range_m", type = "f64""#,
                r#"{ name = "type", type = "f64""#,
            ),
            "field \"type\": a field name does not start with a digit and is not a word",
        ),
        (
            // A union variant's field and the message's share one C struct and Python class.
            edited(
                r#"{ name = "sender_id", type = "u32""#,
                r#"{ name = "torque_b_nm", type = "u32""#,
            ),
            "message CommandMsg: two members named \"torque_b_nm\"",
        ),
        (
            // CommandStatus holds a bool and an enum: nested whole, no codec would check them.
            edited(
                r#"{ name = "command", type = "CommandStatus", c_flatten = "","#,
                r#"{ name = "command", type = "CommandStatus","#,
            ),
            "struct CommandStatus has a bool, an enum",
        ),
        (
            edited(
                r#"{ name = "states", type = "vec<f64>""#,
                r#"{ name = "states", type = "vec<bool>""#,
            ),
            "field \"effectors\": a vec's element is a number (not a bool)",
        ),
        (
            edited(
                r#"{ name = "orb_energy_j", type = "f64""#,
                r#"{ name = "orb_energy_j", type = "SysTime""#,
            ),
            "struct Conserved, field \"orb_energy_j\": a struct refers only to structs defined before it",
        ),
        (
            edited(r#"value = 65536"#, r#"value = -1"#),
            "constant \"MAX_MESSAGE_BYTES\": -1 is negative",
        ),
        (
            // The Rust type of a text field is a hand-written newtype: it must be named.
            edited(
                r#"text = true, rust_type = "FaultTarget","#,
                r#"text = true,"#,
            ),
            "field \"target\": a text field, and only a text field, names its Rust newtype",
        ),
        (
            edited(
                r#"{ name = "range_m", type = "f64""#,
                r#"{ name = "range_m", type = "f64", rust_type = "Range""#,
            ),
            "field \"range_m\": a text field, and only a text field",
        ),
        (
            edited(r#"rust_default = 0.0,"#, r#"rust_default = "ZERO","#),
            "field \"shadow_factor\": `rust_default`: \"ZERO\" does not suit",
        ),
        (
            edited(r#"rust_derive = ["Hash"]"#, r#"rust_derive = ["Ord"]"#),
            "struct Header, rust_derive: the only extra derive is \"Hash\"",
        ),
        (
            edited(
                r#"of = "EffectorState.kind""#,
                r#"of = "EffectorState.kinds""#,
            ),
            "codes EffectorKind, of: EffectorState has no field \"kinds\"",
        ),
        (
            edited(r#"of = "EnvironmentMsg.eclipse""#, r#"of = "EnvironmentMsg.b_n_t""#),
            "codes Eclipse, of: EnvironmentMsg.b_n_t is not a u8, u16 or u32",
        ),
        (
            // Bits no field names in `flags` say which field carries them.
            edited(
                "name = \"wheel_flags\"\nof = \"EffectorState.flags\"\n",
                "name = \"wheel_flags\"\n",
            ),
            "flags wheel_flags: bits are carried by the fields that name them",
        ),
    ];
    for (text, expected) in cases {
        let err = Table::parse("messages.toml", &text).expect_err(expected);
        let shown = err.to_string();
        assert!(
            shown.starts_with("messages.toml: ") && shown.contains(expected),
            "{shown}"
        );
    }
}

#[test]
fn what_the_rust_types_cannot_be_written_from_is_named() {
    let rust = |text: &str| {
        let t = Table::parse("messages.toml", text).expect("the table's own checks pass");
        flexdyn_wiregen::rust_types::module(&t, "messages.toml")
            .expect_err("the Rust generator refuses it")
            .to_string()
    };
    // A public field needs docs (the crate denies missing ones).
    let err = rust(&edited(r#"doc = "e.g. 2016""#, r#"doc = """#));
    assert!(
        err.starts_with("messages.toml: struct UtcTime, field \"year\": no `doc` or `note`"),
        "{err}"
    );
    // Rust has one Default per union: its fields must not default to different variants.
    let second = r#"
[[message]]
name = "ProbeCommandMsg"
c_name = "probe_command"
title = "probe command"
key = "flexdyn/<sc-id>/probe_command"
direction = "client"
since = 9
doc = "a second message with a command"
fields = [
  { name = "header", type = "Header" },
  { name = "kind", type = "union<CommandKind>", default = "Wrench" },
]
"#;
    let text = std::fs::read_to_string(root().join(flexdyn_wiregen::TABLE_PATH)).unwrap();
    let err = rust(&format!("{text}\n{second}"));
    assert!(
        err.starts_with("messages.toml: union CommandKind: the fields of this union default to"),
        "{err}"
    );
}

#[test]
fn a_readme_without_a_message_block_is_refused() {
    let t = table();
    let readme = std::fs::read_to_string(root().join(flexdyn_wiregen::README_PATH)).unwrap();
    let cut = readme.replacen("<!-- wire-table: message GpsMsg -->", "", 1);
    let err = flexdyn_wiregen::readme::splice(&t, "README.md", &cut).unwrap_err();
    assert!(err.contains("GpsMsg"), "{err}");
    let typo = readme.replacen(
        "<!-- wire-table: message GpsMsg -->",
        "<!-- wire-table: message GspMsg -->",
        1,
    );
    let err = flexdyn_wiregen::readme::splice(&t, "README.md", &typo).unwrap_err();
    assert!(err.contains("no message GspMsg"), "{err}");
}

/// The README's byte tables (readme.rs walks the fields) and the Rust constants (sizes.rs
/// computes them) are two computations from the same table: they must agree. That the
/// constants are the real layout is what the hand-derived goldens show (`proto/tests/golden.rs`
/// checks each golden's length and fields).
#[test]
fn the_readme_offsets_are_the_generated_constants() {
    let t = table();
    let state = flexdyn_wiregen::readme::block(&t, "message StateMsg").unwrap();
    assert!(state.contains(&format!(
        "| {} | 8 | u64 | `effectors` count n_effectors |",
        flexdyn_proto::STATE_EFFECTOR_COUNT_OFFSET
    )));
    let time = flexdyn_wiregen::readme::block(&t, "message TimeMsg").unwrap();
    assert!(time.contains(&format!(
        "| {} | 8 | u8[8] | `cuc_tai` |",
        flexdyn_proto::TIME_CUC_OFFSET
    )));
    let cmd = flexdyn_wiregen::readme::block(&t, "message CommandMsg").unwrap();
    assert!(cmd.contains(&format!(
        "| {} | 4 | u32 | `kind` tag |",
        flexdyn_proto::COMMAND_KIND_OFFSET
    )));
}

/// A JSON Schema validator for the keywords the generated schemas use (type, properties,
/// required, additionalProperties, items, minItems, maxItems, minimum, maximum, maxLength, enum,
/// const, oneOf): the error names the path of the first value that breaks its schema. Any
/// other keyword fails the check, so a schema cannot use one this validator ignores.
fn validate(schema: &Value, value: &Value, path: &str) -> Result<(), String> {
    let obj = schema
        .as_object()
        .ok_or_else(|| format!("{path}: the schema is not an object"))?;
    for (key, rule) in obj {
        let bad = |what: &str| Err(format!("{path}: {what} ({key} = {rule})"));
        match key.as_str() {
            "$schema" | "title" | "description" => {}
            "type" => {
                let ok = match rule.as_str().unwrap_or_default() {
                    "object" => value.is_object(),
                    "array" => value.is_array(),
                    "string" => value.is_string(),
                    "boolean" => value.is_boolean(),
                    "number" => value.is_number(),
                    "integer" => value.is_u64() || value.is_i64(),
                    _ => false,
                };
                if !ok {
                    return bad(&format!("{value} is not of the type"));
                }
            }
            "properties" => {
                for (name, sub) in rule.as_object().unwrap() {
                    if let Some(v) = value.get(name) {
                        validate(sub, v, &format!("{path}.{name}"))?;
                    }
                }
            }
            "required" => {
                for name in rule.as_array().unwrap() {
                    if value.get(name.as_str().unwrap()).is_none() {
                        return bad(&format!("{name} is missing"));
                    }
                }
            }
            "additionalProperties" => {
                let known = obj["properties"].as_object().unwrap();
                if let Some(extra) = value
                    .as_object()
                    .and_then(|o| o.keys().find(|k| !known.contains_key(*k)))
                {
                    return bad(&format!("{extra:?} is not a property"));
                }
            }
            "items" => {
                for (i, v) in value.as_array().into_iter().flatten().enumerate() {
                    validate(rule, v, &format!("{path}[{i}]"))?;
                }
            }
            "minItems" | "maxItems" => {
                let n = value.as_array().map_or(0, Vec::len) as u64;
                let limit = rule.as_u64().unwrap();
                if (key == "minItems" && n < limit) || (key == "maxItems" && n > limit) {
                    return bad(&format!("{n} items"));
                }
            }
            "maxLength" => {
                let n = value.as_str().map_or(0, |s| s.chars().count()) as u64;
                if n > rule.as_u64().unwrap() {
                    return bad(&format!("{n} characters"));
                }
            }
            "minimum" | "maximum" => {
                let within = match (value.as_i64(), value.as_u64(), rule.as_i64(), rule.as_u64()) {
                    (_, Some(v), _, Some(r)) => {
                        (key == "minimum" && v >= r) || (key == "maximum" && v <= r)
                    }
                    (Some(v), _, Some(r), _) => {
                        (key == "minimum" && v >= r) || (key == "maximum" && v <= r)
                    }
                    (Some(v), _, None, Some(_)) => key == "maximum" || v >= 0,
                    (None, Some(_), Some(r), None) => key == "minimum" || r >= 0,
                    _ => false,
                };
                if !within {
                    return bad(&format!("{value} is out of range"));
                }
            }
            "enum" => {
                if !rule.as_array().unwrap().contains(value) {
                    return bad(&format!("{value} is not one of them"));
                }
            }
            "const" => {
                if rule != value {
                    return bad(&format!("{value} is not it"));
                }
            }
            "oneOf" => {
                let fits = rule
                    .as_array()
                    .unwrap()
                    .iter()
                    .filter(|s| validate(s, value, path).is_ok())
                    .count();
                if fits != 1 {
                    return bad(&format!("{value} fits {fits} of the variants"));
                }
            }
            other => return Err(format!("{path}: the validator does not know {other:?}")),
        }
    }
    Ok(())
}

/// The generated JSON Schemas accept the JSON of every golden message, as the recorder and
/// the viewer write it (serde's JSON of the Rust types), and refuse a JSON that is not one.
#[test]
fn the_json_schemas_accept_every_golden_and_refuse_broken_json() {
    let t = table();
    for (golden, name) in GOLDENS {
        // The file the wire crate embeds is the generated schema.
        let text = flexdyn_proto::json_schema_text(name).expect(name);
        let schema: Value = serde_json::from_str(text).unwrap();
        assert_eq!(
            Some(&schema),
            flexdyn_wiregen::json_schema::schema_value(&t, name).as_ref()
        );
        let bytes = std::fs::read(root().join(format!("proto/golden/{golden}.bin"))).unwrap();
        let json = rust_json(name, &bytes);
        validate(&schema, &json, name).unwrap_or_else(|e| panic!("golden {golden}: {e}"));
    }
    // Broken JSON is refused, with the path named.
    let schema: Value =
        serde_json::from_str(flexdyn_proto::json_schema_text("CommandMsg").unwrap()).unwrap();
    let bytes = std::fs::read(root().join("proto/golden/command_actuators.bin")).unwrap();
    let good = rust_json("CommandMsg", &bytes);
    let broken = |edit: &dyn Fn(&mut Value)| -> String {
        let mut v = good.clone();
        edit(&mut v);
        validate(&schema, &v, "CommandMsg").unwrap_err()
    };
    assert!(broken(&|v| v["extra"] = json!(1)).contains("\"extra\" is not a property"));
    assert!(broken(&|v| {
        v["header"].as_object_mut().unwrap().remove("tick");
    })
    .contains("CommandMsg.header: \"tick\" is missing"));
    // Two torque components: no variant of the union fits.
    assert!(
        broken(&|v| v["kind"]["Actuators"]["torque_b_nm"] = json!([0.0, 1.0]))
            .contains("CommandMsg.kind: {\"Actuators\"")
    );
    assert!(broken(&|v| v["kind"] = json!("Nothing")).contains("fits 0 of the variants"));
    assert!(broken(&|v| v["sender_id"] = json!(-1)).contains("out of range"));
    assert!(broken(&|v| v["sender_id"] = json!(1.5)).contains("is not of the type"));
}

/// The serde JSON of the golden `bytes` of message `name`, decoded by the Rust codec.
fn rust_json(name: &str, bytes: &[u8]) -> Value {
    rust(name, bytes).unwrap()
}

/// Every f64 of a message's bytes as the table lays them out: (path, offset, `finite`).
fn floats(
    table: &Table,
    fields: &[flexdyn_wiregen::table::Field],
    bytes: &[u8],
    pos: &mut usize,
    prefix: &str,
    out: &mut Vec<(String, usize, bool)>,
) {
    for f in fields {
        let ty = table.resolve(&f.ty).expect("checked");
        float_of(
            table,
            &ty,
            f.finite,
            bytes,
            pos,
            &format!("{prefix}{}", f.name),
            out,
        );
    }
}

fn float_of(
    table: &Table,
    ty: &Ty,
    finite: bool,
    bytes: &[u8],
    pos: &mut usize,
    path: &str,
    out: &mut Vec<(String, usize, bool)>,
) {
    let count = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
    match ty {
        Ty::Prim(Prim::F64) => {
            out.push((path.to_owned(), *pos, finite));
            *pos += 8;
        }
        Ty::Array(Prim::F64, n) => {
            for i in 0..*n {
                out.push((format!("{path}[{i}]"), *pos + 8 * i, finite));
            }
            *pos += 8 * n;
        }
        Ty::Struct(i) => floats(
            table,
            &table.structs[*i].fields,
            bytes,
            pos,
            &format!("{path}."),
            out,
        ),
        Ty::Union(i) => {
            let tag = u32::from_le_bytes(bytes[*pos..*pos + 4].try_into().unwrap()) as usize;
            *pos += 4;
            let v = &table.unions[*i].variants[tag];
            floats(table, &v.fields, bytes, pos, &format!("{path}."), out);
        }
        Ty::Vec(inner) => {
            let n = count(*pos);
            *pos += 8;
            for k in 0..n {
                float_of(
                    table,
                    inner,
                    finite,
                    bytes,
                    pos,
                    &format!("{path}[{k}]"),
                    out,
                );
            }
        }
        other => *pos += table.fixed_size(other).expect("fixed"),
    }
}

/// The table's `finite` marks are the Rust decoder's checks: a NaN written into each f64 of
/// every golden, one at a time, is refused (NonFinite) exactly where the table says `finite`,
/// and accepted everywhere else.
#[test]
fn finite_marks_are_the_decoders_non_finite_checks() {
    use flexdyn_proto::DecodeError;
    let t = table();
    let (mut checked, mut refused) = (0, 0);
    for (golden, name) in GOLDENS {
        let bytes = std::fs::read(root().join(format!("proto/golden/{golden}.bin"))).unwrap();
        let msg = t.message(name).unwrap();
        let mut out = Vec::new();
        floats(&t, &msg.fields, &bytes, &mut 0, "", &mut out);
        for (path, at, finite) in out {
            let mut b = bytes.clone();
            b[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
            let result = rust(name, &b);
            let decoded = result.is_ok();
            let non_finite = matches!(result, Err(DecodeError::NonFinite { .. }));
            assert_eq!(non_finite, finite, "golden {golden}, {path} at {at}: NaN");
            assert_eq!(decoded, !finite, "golden {golden}, {path} at {at}: NaN");
            checked += 1;
            refused += usize::from(finite);
        }
    }
    // Torque and force of the two wrench-carrying commands (12); the actuators golden's input
    // values: 134 = 94 + (12 + 8 v1) + (12 + 8 v2) bytes, so v1 + v2 = 2; two fault parameters;
    // FswMsg's estimate (4), target (4) and variances (3).
    assert_eq!(refused, 12 + 2 + 2 + 11, "{checked} values checked");
    assert!(checked > 150, "{checked}");
}

/// The golden files and their messages (proto/golden/MANIFEST.tsv).
const GOLDENS: [(&str, &str); 19] = [
    ("state", "StateMsg"),
    ("imu", "ImuMsg"),
    ("star_tracker", "StarTrackerMsg"),
    ("magnetometer", "MagnetometerMsg"),
    ("css", "CssMsg"),
    ("fss", "FssMsg"),
    ("gps", "GpsMsg"),
    ("command_wrench", "CommandMsg"),
    ("command_no_command", "CommandMsg"),
    ("command_actuators", "CommandMsg"),
    ("time", "TimeMsg"),
    ("environment", "EnvironmentMsg"),
    ("operator", "OperatorMsg"),
    ("operator_checkpoint", "OperatorMsg"),
    ("fault_event", "FaultEventMsg"),
    ("fault_command", "FaultCommandMsg"),
    ("relative_state", "RelativeStateMsg"),
    ("status", "StatusMsg"),
    ("fsw", "FswMsg"),
];

/// The Rust decoder on `bytes` as message `name`: its serde JSON, or why it refused them.
fn rust(name: &str, bytes: &[u8]) -> Result<Value, flexdyn_proto::DecodeError> {
    use flexdyn_proto::*;
    fn d<T: WireMessage>(b: &[u8]) -> Result<Value, DecodeError> {
        decode::<T>(b).map(|m| serde_json::to_value(m).unwrap())
    }
    match name {
        "StateMsg" => d::<StateMsg>(bytes),
        "ImuMsg" => d::<ImuMsg>(bytes),
        "StarTrackerMsg" => d::<StarTrackerMsg>(bytes),
        "MagnetometerMsg" => d::<MagnetometerMsg>(bytes),
        "CssMsg" => d::<CssMsg>(bytes),
        "FssMsg" => d::<FssMsg>(bytes),
        "GpsMsg" => d::<GpsMsg>(bytes),
        "CommandMsg" => d::<CommandMsg>(bytes),
        "TimeMsg" => d::<TimeMsg>(bytes),
        "EnvironmentMsg" => d::<EnvironmentMsg>(bytes),
        "OperatorMsg" => d::<OperatorMsg>(bytes),
        "FaultEventMsg" => d::<FaultEventMsg>(bytes),
        "FaultCommandMsg" => d::<FaultCommandMsg>(bytes),
        "RelativeStateMsg" => d::<RelativeStateMsg>(bytes),
        "StatusMsg" => d::<StatusMsg>(bytes),
        "FswMsg" => d::<FswMsg>(bytes),
        other => panic!("{other}"),
    }
}
