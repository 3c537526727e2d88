//! A message straight into named columns, without a JSON tree in between: a serde
//! `Serializer` that names each leaf as [`crate::table`] names a JSON value's (the same rules:
//! the header's fields unprefixed, nested fields `<field>_<sub>`, arrays numbered from 1, a
//! quaternion `q_…` from 0, booleans as 0/1, unit variants by name, a non-finite number as NaN).
//!
//! `flexdyn plot` and `export` turn every message of a recording into a row; building a
//! `serde_json::Value` first (an allocation per field and per array) was most of `plot`'s
//! time on a large recording. The unit tests check that both paths give the same row for every
//! wire message.

use serde::ser::{self, Impossible, Serialize};

use crate::table::{Cell, Column};

/// Appends the columns of `msg` named under `prefix`, leaving out the top-level fields in
/// `skip` (as `table` removes `effectors` from a state, or `header` from a sample).
pub fn push_columns<T: Serialize + ?Sized>(
    prefix: &str,
    msg: &T,
    skip: &[&str],
    out: &mut Vec<Column>,
) {
    let mut s = Leaf {
        name: prefix,
        named: true,
        first: 1,
        skip,
        out,
    };
    // Serializing into columns cannot fail: every wire type is plain data.
    let _ = msg.serialize(&mut s);
}

/// The cells [`push_columns`] would append, in the same order, each with an empty name: for a
/// writer that knows the columns already (`simulate` after its header), without building a
/// name per cell per row.
pub fn push_cells<T: Serialize + ?Sized>(msg: &T, skip: &[&str], out: &mut Vec<Column>) {
    let mut s = Leaf {
        name: "",
        named: false,
        first: 1,
        skip,
        out,
    };
    let _ = msg.serialize(&mut s);
}

/// Why a serialization stopped (never, for the wire types).
#[derive(Debug)]
pub struct Unsupported(String);

impl std::fmt::Display for Unsupported {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Unsupported {}

impl ser::Error for Unsupported {
    fn custom<T: std::fmt::Display>(msg: T) -> Self {
        Self(msg.to_string())
    }
}

/// One value to be written under `name`; an array below it numbers its items from `first`.
struct Leaf<'a, 'o> {
    name: &'a str,
    /// Names are built; `false` for [`push_cells`] (every name left empty).
    named: bool,
    first: usize,
    /// Fields left out (top level only; empty below).
    skip: &'a [&'a str],
    out: &'o mut Vec<Column>,
}

impl Leaf<'_, '_> {
    fn cell(&mut self, cell: Cell) {
        self.out.push((self.own_name(), cell));
    }

    fn own_name(&self) -> String {
        if self.named {
            self.name.to_owned()
        } else {
            String::new()
        }
    }
}

/// The name of field `key` of the value named `parent` (the header's fields are not
/// prefixed).
fn child_name(parent: &str, key: &str, named: bool) -> String {
    match (key, parent.is_empty()) {
        _ if !named => String::new(),
        ("header", _) => parent.to_owned(),
        (_, true) => key.to_owned(),
        (_, false) => format!("{parent}_{key}"),
    }
}

/// Serializes `value` as field `key` of the value `parent` names.
fn field<T: Serialize + ?Sized>(
    parent: &str,
    key: &str,
    value: &T,
    named: bool,
    out: &mut Vec<Column>,
) -> Result<(), Unsupported> {
    let name = child_name(parent, key, named);
    let mut leaf = Leaf {
        name: &name,
        named,
        first: if key.starts_with("q_") { 0 } else { 1 },
        skip: &[],
        out,
    };
    value.serialize(&mut leaf)
}

/// The items of an array, numbered from `first`.
struct Items<'o> {
    name: String,
    named: bool,
    first: usize,
    next: usize,
    out: &'o mut Vec<Column>,
}

/// The fields of a struct or map.
struct Fields<'a, 'o> {
    name: String,
    named: bool,
    skip: &'a [&'a str],
    out: &'o mut Vec<Column>,
    /// A map's key, between `serialize_key` and `serialize_value`.
    key: Option<String>,
}

impl<'a, 'o, 'l> ser::Serializer for &'l mut Leaf<'a, 'o> {
    type Ok = ();
    type Error = Unsupported;
    type SerializeSeq = Items<'l>;
    type SerializeTuple = Items<'l>;
    type SerializeTupleStruct = Items<'l>;
    type SerializeTupleVariant = Items<'l>;
    type SerializeMap = Fields<'a, 'l>;
    type SerializeStruct = Fields<'a, 'l>;
    type SerializeStructVariant = Fields<'a, 'l>;

    fn serialize_bool(self, v: bool) -> Result<(), Unsupported> {
        self.cell(Cell::Int(u64::from(v)));
        Ok(())
    }
    fn serialize_i8(self, v: i8) -> Result<(), Unsupported> {
        self.serialize_i64(v.into())
    }
    fn serialize_i16(self, v: i16) -> Result<(), Unsupported> {
        self.serialize_i64(v.into())
    }
    fn serialize_i32(self, v: i32) -> Result<(), Unsupported> {
        self.serialize_i64(v.into())
    }
    fn serialize_i64(self, v: i64) -> Result<(), Unsupported> {
        // As JSON: a non-negative integer is an integer, a negative one a number.
        self.cell(match u64::try_from(v) {
            Ok(u) => Cell::Int(u),
            Err(_) => Cell::Num(v as f64),
        });
        Ok(())
    }
    fn serialize_u8(self, v: u8) -> Result<(), Unsupported> {
        self.serialize_u64(v.into())
    }
    fn serialize_u16(self, v: u16) -> Result<(), Unsupported> {
        self.serialize_u64(v.into())
    }
    fn serialize_u32(self, v: u32) -> Result<(), Unsupported> {
        self.serialize_u64(v.into())
    }
    fn serialize_u64(self, v: u64) -> Result<(), Unsupported> {
        self.cell(Cell::Int(v));
        Ok(())
    }
    fn serialize_f32(self, v: f32) -> Result<(), Unsupported> {
        self.serialize_f64(v.into())
    }
    fn serialize_f64(self, v: f64) -> Result<(), Unsupported> {
        // JSON writes a non-finite number as null, which `table` reads as NaN.
        self.cell(Cell::Num(if v.is_finite() { v } else { f64::NAN }));
        Ok(())
    }
    fn serialize_char(self, v: char) -> Result<(), Unsupported> {
        self.cell(Cell::Text(v.to_string()));
        Ok(())
    }
    fn serialize_str(self, v: &str) -> Result<(), Unsupported> {
        self.cell(Cell::Text(v.to_owned()));
        Ok(())
    }
    fn serialize_bytes(self, v: &[u8]) -> Result<(), Unsupported> {
        // As JSON: an array of numbers.
        for (i, b) in v.iter().enumerate() {
            let name = if self.named {
                format!("{}_{}", self.name, i + self.first)
            } else {
                String::new()
            };
            self.out.push((name, Cell::Int((*b).into())));
        }
        Ok(())
    }
    fn serialize_none(self) -> Result<(), Unsupported> {
        self.serialize_unit()
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<(), Unsupported> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Result<(), Unsupported> {
        self.cell(Cell::Num(f64::NAN));
        Ok(())
    }
    fn serialize_unit_struct(self, _name: &'static str) -> Result<(), Unsupported> {
        self.serialize_unit()
    }
    fn serialize_unit_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
    ) -> Result<(), Unsupported> {
        self.serialize_str(variant)
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        value: &T,
    ) -> Result<(), Unsupported> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), Unsupported> {
        // As JSON: {"<variant>": value}.
        field(self.name, variant, value, self.named, self.out)
    }
    fn serialize_seq(self, _len: Option<usize>) -> Result<Items<'l>, Unsupported> {
        Ok(Items {
            name: self.own_name(),
            named: self.named,
            first: self.first,
            next: 0,
            out: self.out,
        })
    }
    fn serialize_tuple(self, len: usize) -> Result<Items<'l>, Unsupported> {
        self.serialize_seq(Some(len))
    }
    fn serialize_tuple_struct(
        self,
        _name: &'static str,
        len: usize,
    ) -> Result<Items<'l>, Unsupported> {
        self.serialize_seq(Some(len))
    }
    fn serialize_tuple_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
        _len: usize,
    ) -> Result<Items<'l>, Unsupported> {
        // As JSON: {"<variant>": [...]}.
        Ok(Items {
            name: child_name(self.name, variant, self.named),
            named: self.named,
            first: 1,
            next: 0,
            out: self.out,
        })
    }
    fn serialize_map(self, _len: Option<usize>) -> Result<Fields<'a, 'l>, Unsupported> {
        Ok(Fields {
            name: self.own_name(),
            named: self.named,
            skip: self.skip,
            out: self.out,
            key: None,
        })
    }
    fn serialize_struct(
        self,
        _name: &'static str,
        len: usize,
    ) -> Result<Fields<'a, 'l>, Unsupported> {
        self.serialize_map(Some(len))
    }
    fn serialize_struct_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
        _len: usize,
    ) -> Result<Fields<'a, 'l>, Unsupported> {
        // As JSON: {"<variant>": {...}}.
        Ok(Fields {
            name: child_name(self.name, variant, self.named),
            named: self.named,
            skip: &[],
            out: self.out,
            key: None,
        })
    }
}

impl Items<'_> {
    fn item<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Unsupported> {
        let name = if self.named {
            format!("{}_{}", self.name, self.next + self.first)
        } else {
            String::new()
        };
        self.next += 1;
        let mut leaf = Leaf {
            name: &name,
            named: self.named,
            first: 1,
            skip: &[],
            out: self.out,
        };
        value.serialize(&mut leaf)
    }
}

/// The four array-like serde traits, each handing its items to [`Items::item`].
macro_rules! items {
    ($($trait:ident :: $method:ident),*) => {$(
        impl ser::$trait for Items<'_> {
            type Ok = ();
            type Error = Unsupported;
            fn $method<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), Unsupported> {
                self.item(v)
            }
            fn end(self) -> Result<(), Unsupported> {
                Ok(())
            }
        }
    )*};
}

items!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field
);

impl ser::SerializeStruct for Fields<'_, '_> {
    type Ok = ();
    type Error = Unsupported;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Unsupported> {
        if self.skip.contains(&key) {
            return Ok(());
        }
        field(&self.name, key, value, self.named, self.out)
    }
    fn end(self) -> Result<(), Unsupported> {
        Ok(())
    }
}

impl ser::SerializeStructVariant for Fields<'_, '_> {
    type Ok = ();
    type Error = Unsupported;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Unsupported> {
        field(&self.name, key, value, self.named, self.out)
    }
    fn end(self) -> Result<(), Unsupported> {
        Ok(())
    }
}

impl ser::SerializeMap for Fields<'_, '_> {
    type Ok = ();
    type Error = Unsupported;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Unsupported> {
        self.key = Some(key.serialize(KeyName)?);
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Unsupported> {
        let key = self
            .key
            .take()
            .ok_or_else(|| Unsupported("a map value without a key".into()))?;
        if self.skip.contains(&key.as_str()) {
            return Ok(());
        }
        field(&self.name, &key, value, self.named, self.out)
    }
    fn end(self) -> Result<(), Unsupported> {
        Ok(())
    }
}

/// A map key as text (JSON's rule: strings, and numbers written out).
struct KeyName;

fn not_text() -> Unsupported {
    Unsupported("a map key that is not text".into())
}

impl ser::Serializer for KeyName {
    type Ok = String;
    type Error = Unsupported;
    type SerializeSeq = Impossible<String, Unsupported>;
    type SerializeTuple = Impossible<String, Unsupported>;
    type SerializeTupleStruct = Impossible<String, Unsupported>;
    type SerializeTupleVariant = Impossible<String, Unsupported>;
    type SerializeMap = Impossible<String, Unsupported>;
    type SerializeStruct = Impossible<String, Unsupported>;
    type SerializeStructVariant = Impossible<String, Unsupported>;

    fn serialize_str(self, v: &str) -> Result<String, Unsupported> {
        Ok(v.to_owned())
    }
    fn serialize_char(self, v: char) -> Result<String, Unsupported> {
        Ok(v.to_string())
    }
    fn serialize_u64(self, v: u64) -> Result<String, Unsupported> {
        Ok(v.to_string())
    }
    fn serialize_u32(self, v: u32) -> Result<String, Unsupported> {
        Ok(v.to_string())
    }
    fn serialize_u16(self, v: u16) -> Result<String, Unsupported> {
        Ok(v.to_string())
    }
    fn serialize_u8(self, v: u8) -> Result<String, Unsupported> {
        Ok(v.to_string())
    }
    fn serialize_i64(self, v: i64) -> Result<String, Unsupported> {
        Ok(v.to_string())
    }
    fn serialize_i32(self, v: i32) -> Result<String, Unsupported> {
        Ok(v.to_string())
    }
    fn serialize_i16(self, v: i16) -> Result<String, Unsupported> {
        Ok(v.to_string())
    }
    fn serialize_i8(self, v: i8) -> Result<String, Unsupported> {
        Ok(v.to_string())
    }
    fn serialize_unit_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
    ) -> Result<String, Unsupported> {
        Ok(variant.to_owned())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        value: &T,
    ) -> Result<String, Unsupported> {
        value.serialize(self)
    }
    fn serialize_bool(self, _v: bool) -> Result<String, Unsupported> {
        Err(not_text())
    }
    fn serialize_f32(self, _v: f32) -> Result<String, Unsupported> {
        Err(not_text())
    }
    fn serialize_f64(self, _v: f64) -> Result<String, Unsupported> {
        Err(not_text())
    }
    fn serialize_bytes(self, _v: &[u8]) -> Result<String, Unsupported> {
        Err(not_text())
    }
    fn serialize_none(self) -> Result<String, Unsupported> {
        Err(not_text())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, _v: &T) -> Result<String, Unsupported> {
        Err(not_text())
    }
    fn serialize_unit(self) -> Result<String, Unsupported> {
        Err(not_text())
    }
    fn serialize_unit_struct(self, _name: &'static str) -> Result<String, Unsupported> {
        Err(not_text())
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        _value: &T,
    ) -> Result<String, Unsupported> {
        Err(not_text())
    }
    fn serialize_seq(self, _len: Option<usize>) -> Result<Self::SerializeSeq, Unsupported> {
        Err(not_text())
    }
    fn serialize_tuple(self, _len: usize) -> Result<Self::SerializeTuple, Unsupported> {
        Err(not_text())
    }
    fn serialize_tuple_struct(
        self,
        _name: &'static str,
        _len: usize,
    ) -> Result<Self::SerializeTupleStruct, Unsupported> {
        Err(not_text())
    }
    fn serialize_tuple_variant(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        _len: usize,
    ) -> Result<Self::SerializeTupleVariant, Unsupported> {
        Err(not_text())
    }
    fn serialize_map(self, _len: Option<usize>) -> Result<Self::SerializeMap, Unsupported> {
        Err(not_text())
    }
    fn serialize_struct(
        self,
        _name: &'static str,
        _len: usize,
    ) -> Result<Self::SerializeStruct, Unsupported> {
        Err(not_text())
    }
    fn serialize_struct_variant(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        _len: usize,
    ) -> Result<Self::SerializeStructVariant, Unsupported> {
        Err(not_text())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::push_value;
    use flexdyn_proto::*;
    use serde_json::Value;

    /// The row the JSON path gives: `serde_json::to_value`, the `skip` fields removed, then
    /// `table`'s naming.
    fn via_json<T: Serialize>(prefix: &str, msg: &T, skip: &[&str]) -> Vec<Column> {
        let mut json = serde_json::to_value(msg).unwrap();
        if let Value::Object(map) = &mut json {
            for k in skip {
                map.shift_remove(*k);
            }
        }
        let mut out = Vec::new();
        push_value(prefix, &json, &mut out);
        out
    }

    /// Both paths give the same names in the same order and the same cells (NaN equals NaN).
    fn same<T: Serialize>(prefix: &str, msg: &T, skip: &[&str]) {
        let mut direct = Vec::new();
        push_columns(prefix, msg, skip, &mut direct);
        let json = via_json(prefix, msg, skip);
        let names = |r: &[Column]| r.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
        assert_eq!(names(&direct), names(&json));
        for ((n, a), (_, b)) in direct.iter().zip(&json) {
            let equal = match (a, b) {
                (Cell::Num(x), Cell::Num(y)) => x == y || (x.is_nan() && y.is_nan()),
                _ => a == b,
            };
            assert!(equal, "{n}: {a:?} directly, {b:?} through JSON");
        }
        assert!(!direct.is_empty());
    }

    fn header() -> Header {
        Header::new(7, 1234, 12_340_000_000, 99)
    }

    #[test]
    fn every_wire_message_gives_the_row_its_json_gives() {
        let mut state = StateMsg {
            header: header(),
            sigma_bn: [0.1, -0.2, f64::NAN],
            omega_bn_b_rad_s: [1e-3, f64::INFINITY, -3.5],
            ..StateMsg::default()
        };
        state.effectors.push(EffectorState {
            kind: 1,
            states: vec![0.1, 0.2],
            outputs: vec![3.0],
            flags: 2,
        });
        same("", &state, &["effectors"]);
        same("", &state, &[]);
        same(
            "",
            &StatusMsg {
                header: header(),
                run_state: RunState::Finished,
                faults_active_bits: [1, 0, u64::MAX, 3],
                ..StatusMsg::default()
            },
            &[],
        );
        same("", &TimeMsg::default(), &[]);
        for action in [
            OperatorAction::Pause,
            OperatorAction::Resume,
            OperatorAction::RunTicks,
            OperatorAction::Checkpoint,
        ] {
            same(
                "",
                &OperatorMsg {
                    header: header(),
                    action,
                    ..OperatorMsg::default()
                },
                &[],
            );
        }
        same("", &EnvironmentMsg::default(), &[]);
        let event = FaultEventMsg {
            target: FaultTarget::new("imus.hub.gyro").unwrap(),
            ..FaultEventMsg::default()
        };
        same("", &event, &[]);
        same("", &FaultCommandMsg::default(), &[]);
        same("", &RelativeStateMsg::default(), &[]);
        same("imu_hub", &ImuMsg::default(), &["header"]);
        same("st_st1", &StarTrackerMsg::default(), &["header"]);
        same("mag_m", &MagnetometerMsg::default(), &["header"]);
        same("css_c", &CssMsg::default(), &["header"]);
        same("fss_f", &FssMsg::default(), &["header"]);
        same("gps_g", &GpsMsg::default(), &["header"]);
        for cmd in [
            CommandMsg::no_command(header(), 1),
            CommandMsg::wrench(header(), 1, [1.0, 2.0, 3.0], [0.0, -1.0, f64::NAN]),
            CommandMsg::actuators(
                header(),
                1,
                [0.0; 3],
                [0.0; 3],
                vec![EffectorInput {
                    effector_index: 2,
                    values: vec![0.5, -0.5],
                }],
            ),
        ] {
            same("", &cmd, &[]);
        }
    }
}
