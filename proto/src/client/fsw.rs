//! The flight code's own telemetry (protocol 10): a stream declared in the served
//! configuration's `[[fsw_streams]]`, published as [`FswMsg`] on `flexdyn/<sc>/fsw/<name>`.
//!
//! [`FswStream::declare`] reads the stream's declaration from the server's configuration, so
//! flight code names its modes, events and values as the configuration does; a name the
//! configuration does not declare is an error here, before anything is sent. The server checks
//! each sample against the same declaration, records it beside the truth, and applies nothing
//! from it to the physics (`proto/README.md`, "FswMsg").
//!
//! ```no_run
//! # fn demo(session: &zenoh::Session, topics: &flexdyn_proto::Topics,
//! #         vehicle: &flexdyn_proto::client::vehicle::Vehicle) -> Result<(), Box<dyn std::error::Error>> {
//! use flexdyn_proto::client::fsw::FswStream;
//! let mut acs = FswStream::declare(session, topics, vehicle, "acs")?;
//! // Once per tick answered, before the answer:
//! acs.begin(42, 420_000_000);
//! acs.mode("detumble")?;
//! acs.f64s("h_wheels_b_nms", &[0.1, 0.0, -0.2])?;
//! acs.i64s("fdir_flags", &[0])?;
//! acs.publish()?;
//! # Ok(()) }
//! ```
//!
//! After [`FswStream::declare`] nothing allocates: the sample and its encoding buffer are kept.

use serde::Deserialize;
use zenoh::pubsub::Publisher;
use zenoh::{Session, Wait as _};

use super::vehicle::Vehicle;
use crate::{encode_into, fsw_flags, FswMsg, Header, Topics, MAX_FSW_EVENTS, MAX_FSW_VALUES};

/// Why a stream cannot be declared or a sample cannot be sent.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FswError {
    /// The served configuration declares no such stream.
    #[error(
        "the server's configuration declares no [[fsw_streams]] named `{stream}` (declared: {declared})"
    )]
    NoStream {
        /// The stream asked for.
        stream: String,
        /// The streams it declares.
        declared: String,
    },
    /// The served configuration's `[[fsw_streams]]` cannot be read.
    #[error("the served configuration's [[fsw_streams]]: {0}")]
    Config(String),
    /// A sample names something its stream does not declare, or gives a wrong value.
    #[error("stream `{stream}`: {problem}")]
    Sample {
        /// The stream.
        stream: String,
        /// What is wrong.
        problem: String,
    },
    /// Zenoh refused to declare the publisher or to put the sample.
    #[error("{key}: {message}")]
    Zenoh {
        /// The stream's key.
        key: String,
        /// Zenoh's message.
        message: String,
    },
}

/// The type of a declared value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FswType {
    /// An f64 word (its IEEE-754 bits); finite.
    F64,
    /// An i64 word (two's complement).
    I64,
    /// A bool word (0 or 1).
    Bool,
}

/// A declared value (`values` of `[[fsw_streams]]`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct FswValue {
    /// Its name.
    pub name: String,
    /// Its type.
    #[serde(rename = "type")]
    pub ty: FswType,
    /// Its length in words (default 1).
    #[serde(default = "one")]
    pub len: usize,
    /// Its unit (may be empty).
    #[serde(default)]
    pub unit: String,
}

fn one() -> usize {
    1
}

/// A declared event (`events` of `[[fsw_streams]]`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct FswEvent {
    /// Its name.
    pub name: String,
    /// `info` (default), `warning`, `error` or `critical`.
    #[serde(default = "info")]
    pub severity: String,
}

fn info() -> String {
    "info".to_owned()
}

/// A stream as the served configuration declares it (the server validated it).
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct FswDeclaration {
    /// The stream's name: the last chunk of its key.
    pub name: String,
    /// Its modes (a sample's `mode` is an index in them).
    #[serde(default)]
    pub modes: Vec<String>,
    /// Its events (a sample's `events` are indices in them).
    #[serde(default)]
    pub events: Vec<FswEvent>,
    /// Its values, in word order.
    #[serde(default)]
    pub values: Vec<FswValue>,
}

#[derive(Deserialize)]
struct Streams {
    #[serde(default)]
    fsw_streams: Vec<FswDeclaration>,
}

impl FswDeclaration {
    /// Every stream the configuration text `config_toml` declares.
    pub fn all_from_toml(config_toml: &str) -> Result<Vec<Self>, FswError> {
        toml::from_str::<Streams>(config_toml)
            .map(|s| s.fsw_streams)
            .map_err(|e| FswError::Config(e.message().to_owned()))
    }

    /// Stream `stream` of the configuration text `config_toml`.
    pub fn from_toml(config_toml: &str, stream: &str) -> Result<Self, FswError> {
        let all = Self::all_from_toml(config_toml)?;
        let declared = if all.is_empty() {
            "none".to_owned()
        } else {
            all.iter()
                .map(|s| format!("`{}`", s.name))
                .collect::<Vec<_>>()
                .join(", ")
        };
        all.into_iter()
            .find(|s| s.name == stream)
            .ok_or_else(|| FswError::NoStream {
                stream: stream.to_owned(),
                declared,
            })
    }

    /// The value words of one sample (the sum of the lengths).
    pub fn words(&self) -> usize {
        self.values.iter().map(|v| v.len).sum()
    }
}

/// A declared stream bound to its publisher; see the module docs.
pub struct FswStream {
    declaration: FswDeclaration,
    /// The first word of each value.
    offsets: Vec<usize>,
    /// Whether each value is set in the sample being built.
    set: Vec<bool>,
    publisher: Publisher<'static>,
    key: String,
    spacecraft_id: u32,
    seq: u64,
    msg: FswMsg,
    buf: Vec<u8>,
}

impl FswStream {
    /// Stream `stream` of the configuration `vehicle` serves, with a publisher on
    /// `flexdyn/<sc>/fsw/<stream>`: blocking congestion control (this end never drops a
    /// sample) and express (sent at once, never batched), so a sample published before a
    /// lockstep answer from the same session reaches the server before the answer, whatever
    /// the command publisher's batching.
    pub fn declare(
        session: &Session,
        topics: &Topics,
        vehicle: &Vehicle,
        stream: &str,
    ) -> Result<Self, FswError> {
        let declaration = FswDeclaration::from_toml(&vehicle.config_toml, stream)?;
        let words = declaration.words();
        if words > MAX_FSW_VALUES {
            return Err(FswError::Config(format!(
                "stream `{stream}` declares {words} words, more than {MAX_FSW_VALUES}"
            )));
        }
        let key = crate::fsw_key(topics.sc_id(), stream).map_err(|e| FswError::Sample {
            stream: stream.to_owned(),
            problem: e.to_string(),
        })?;
        let publisher = session
            .declare_publisher(key.clone())
            .congestion_control(zenoh::qos::CongestionControl::Block)
            .express(true)
            .wait()
            .map_err(|e| FswError::Zenoh {
                key: key.clone(),
                message: e.to_string(),
            })?;
        let mut offsets = Vec::with_capacity(declaration.values.len());
        let mut at = 0;
        for v in &declaration.values {
            offsets.push(at);
            at += v.len;
        }
        let msg = FswMsg {
            values: vec![0; words],
            ..FswMsg::default()
        };
        Ok(Self {
            set: vec![false; declaration.values.len()],
            offsets,
            declaration,
            publisher,
            key,
            spacecraft_id: vehicle.spacecraft_id,
            seq: 0,
            msg,
            buf: Vec::with_capacity(crate::FSW_FIXED_LEN + 8 * words),
        })
    }

    /// The stream's declaration.
    pub fn declaration(&self) -> &FswDeclaration {
        &self.declaration
    }

    /// Its key, `flexdyn/<sc>/fsw/<name>`.
    pub fn key(&self) -> &str {
        &self.key
    }

    /// Whether the stream declares value `name`.
    pub fn declares_value(&self, name: &str) -> bool {
        self.declaration.values.iter().any(|v| v.name == name)
    }

    /// Whether the stream declares mode `name`.
    pub fn declares_mode(&self, name: &str) -> bool {
        self.declaration.modes.iter().any(|m| m == name)
    }

    /// Whether the stream declares event `name`.
    pub fn declares_event(&self, name: &str) -> bool {
        self.declaration.events.iter().any(|e| e.name == name)
    }

    /// Starts the sample of `tick` (the tick this flight code answers) at `sim_time_ns`:
    /// nothing set yet.
    pub fn begin(&mut self, tick: u64, sim_time_ns: u64) {
        let values = std::mem::take(&mut self.msg.values);
        self.msg = FswMsg {
            header: Header::new(self.spacecraft_id, tick, sim_time_ns, self.seq),
            values,
            ..FswMsg::default()
        };
        self.set.iter_mut().for_each(|s| *s = false);
    }

    fn problem(&self, problem: String) -> FswError {
        FswError::Sample {
            stream: self.declaration.name.clone(),
            problem,
        }
    }

    /// The mode the flight code is in at the sample's tick.
    pub fn mode(&mut self, name: &str) -> Result<(), FswError> {
        let Some(i) = self.declaration.modes.iter().position(|m| m == name) else {
            return Err(self.problem(format!(
                "mode `{name}` is not declared (modes: {})",
                self.declaration.modes.join(", ")
            )));
        };
        self.msg.mode = i as u32;
        self.msg.flags |= fsw_flags::MODE;
        Ok(())
    }

    /// An event raised at the sample's tick (at most [`MAX_FSW_EVENTS`] per sample).
    pub fn event(&mut self, name: &str) -> Result<(), FswError> {
        let Some(i) = self.declaration.events.iter().position(|e| e.name == name) else {
            let names: Vec<&str> = self
                .declaration
                .events
                .iter()
                .map(|e| e.name.as_str())
                .collect();
            return Err(self.problem(format!(
                "event `{name}` is not declared (events: {})",
                names.join(", ")
            )));
        };
        let n = usize::from(self.msg.event_count);
        if n >= MAX_FSW_EVENTS {
            return Err(self.problem(format!("more than {MAX_FSW_EVENTS} events in one sample")));
        }
        self.msg.events[n] = i as u16;
        self.msg.event_count += 1;
        Ok(())
    }

    fn finite(&self, what: &str, v: &[f64]) -> Result<(), FswError> {
        match v.iter().position(|x| !x.is_finite()) {
            Some(k) => Err(self.problem(format!("{what}[{k}] is {}, not finite", v[k]))),
            None => Ok(()),
        }
    }

    /// The attitude estimate: the quaternion q_BN (maps N → B), scalar first.
    pub fn estimate(&mut self, q_bn: [f64; 4]) -> Result<(), FswError> {
        self.finite("estimate", &q_bn)?;
        self.msg.q_est_bn = q_bn;
        self.msg.flags |= fsw_flags::ESTIMATE;
        Ok(())
    }

    /// The target attitude: the quaternion q_RN (maps N → R), scalar first.
    pub fn target(&mut self, q_rn: [f64; 4]) -> Result<(), FswError> {
        self.finite("target", &q_rn)?;
        self.msg.q_target_rn = q_rn;
        self.msg.flags |= fsw_flags::TARGET;
        Ok(())
    }

    /// \[rad²\] the variances of the estimate's attitude error about the body axes (needs an
    /// [`Self::estimate`] in the same sample).
    pub fn variance(&mut self, var_b_rad2: [f64; 3]) -> Result<(), FswError> {
        self.finite("variance", &var_b_rad2)?;
        self.msg.att_var_b_rad2 = var_b_rad2;
        self.msg.flags |= fsw_flags::COVARIANCE;
        Ok(())
    }

    /// The words of value `name`, checked to be declared with type `ty` and `n` elements.
    fn slot(&mut self, name: &str, ty: FswType, n: usize) -> Result<&mut [u64], FswError> {
        let Some(i) = self.declaration.values.iter().position(|v| v.name == name) else {
            let names: Vec<&str> = self
                .declaration
                .values
                .iter()
                .map(|v| v.name.as_str())
                .collect();
            return Err(self.problem(format!(
                "value `{name}` is not declared (values: {})",
                names.join(", ")
            )));
        };
        let v = &self.declaration.values[i];
        if v.ty != ty || v.len != n {
            return Err(self.problem(format!(
                "value `{name}` is declared {:?} × {}, given {ty:?} × {n}",
                v.ty, v.len
            )));
        }
        self.set[i] = true;
        let at = self.offsets[i];
        Ok(&mut self.msg.values[at..at + n])
    }

    /// Sets f64 value `name` (every element finite).
    pub fn f64s(&mut self, name: &str, v: &[f64]) -> Result<(), FswError> {
        self.finite(name, v)?;
        for (w, x) in self.slot(name, FswType::F64, v.len())?.iter_mut().zip(v) {
            *w = x.to_bits();
        }
        Ok(())
    }

    /// Sets i64 value `name`.
    pub fn i64s(&mut self, name: &str, v: &[i64]) -> Result<(), FswError> {
        for (w, x) in self.slot(name, FswType::I64, v.len())?.iter_mut().zip(v) {
            *w = *x as u64;
        }
        Ok(())
    }

    /// Sets bool value `name`.
    pub fn bools(&mut self, name: &str, v: &[bool]) -> Result<(), FswError> {
        for (w, x) in self.slot(name, FswType::Bool, v.len())?.iter_mut().zip(v) {
            *w = u64::from(*x);
        }
        Ok(())
    }

    /// Sends the sample begun with [`Self::begin`]: every declared value must be set (a
    /// variance needs an estimate). Nothing is sent on an error.
    pub fn publish(&mut self) -> Result<(), FswError> {
        if let Some(i) = self.set.iter().position(|s| !s) {
            return Err(self.problem(format!(
                "value `{}` is not set: every declared value is in every sample",
                self.declaration.values[i].name
            )));
        }
        if self.msg.flags & fsw_flags::COVARIANCE != 0 && self.msg.flags & fsw_flags::ESTIMATE == 0
        {
            return Err(self.problem("a variance needs an estimate".to_owned()));
        }
        encode_into(&self.msg, &mut self.buf);
        self.publisher
            .put(self.buf.as_slice())
            .wait()
            .map_err(|e| FswError::Zenoh {
                key: self.key.clone(),
                message: e.to_string(),
            })?;
        self.seq += 1;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CONFIG: &str = r#"
[simulation]
step_hz = 100.0

[[fsw_streams]]
name = "acs"
modes = ["detumble", "point"]
events = [{ name = "gyro_fault", severity = "error" }, { name = "detumbled" }]
values = [
  { name = "h_b_nms", type = "f64", len = 3, unit = "N·m·s" },
  { name = "flags", type = "i64" },
  { name = "ok", type = "bool" },
]

[[fsw_streams]]
name = "nav"
"#;

    #[test]
    fn the_declaration_reads_from_the_served_toml() {
        let d = FswDeclaration::from_toml(CONFIG, "acs").unwrap();
        assert_eq!(d.modes, ["detumble", "point"]);
        assert_eq!(d.events[0].severity, "error");
        assert_eq!(d.events[1].severity, "info");
        assert_eq!(d.values[0].ty, FswType::F64);
        assert_eq!((d.values[1].len, d.values[2].len), (1, 1));
        assert_eq!(d.words(), 5);
        let nav = FswDeclaration::from_toml(CONFIG, "nav").unwrap();
        assert_eq!(nav.words(), 0);
        let err = FswDeclaration::from_toml(CONFIG, "gnc").unwrap_err();
        assert_eq!(
            err.to_string(),
            "the server's configuration declares no [[fsw_streams]] named `gnc` (declared: \
             `acs`, `nav`)"
        );
        let none = FswDeclaration::from_toml("[simulation]\n", "acs").unwrap_err();
        assert!(none.to_string().ends_with("(declared: none)"), "{none}");
    }
}
