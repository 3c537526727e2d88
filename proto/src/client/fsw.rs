//! The flight code's own telemetry (protocol 10): a stream declared in the served
//! configuration's `[[fsw_streams]]`, published as [`FswMsg`] on `flexdyn/<sc>/fsw/<name>`.
//!
//! [`FswStream::declare`] reads the stream's declaration from the server's configuration, so
//! flight code names its modes, events and values as the configuration does. Its
//! [`FswSampler`] (an [`FswStream`] dereferences to it; it needs no Zenoh) builds one sample at a
//! time and refuses, before anything is sent and with a message naming the stream and the
//! field, what the server would refuse: a name the stream does not declare, a wrong type or
//! length, a non-finite f64, another spacecraft's stamp, more events than a sample carries
//! ([`FswError::Sample`]); a setter with no sample begun, a tick not after the last one
//! published, a declared value left out, a variance without an estimate ([`FswError::Order`]).
//! A refusal changes nothing: the sample begun stays as it was. The server checks each sample
//! against the same declaration, records it beside the truth, and applies nothing from it to
//! the physics (`proto/README.md`, "FswMsg"). The C library's `flexdyn_fsw_*` calls are this
//! module with C return codes (`clients/c/src/fsw.rs`).
//!
//! ```no_run
//! # fn demo(session: &zenoh::Session, topics: &flexdyn_proto::Topics,
//! #         vehicle: &flexdyn_proto::client::vehicle::Vehicle) -> Result<(), Box<dyn std::error::Error>> {
//! use flexdyn_proto::client::fsw::FswStream;
//! let mut acs = FswStream::declare(session, topics, vehicle, "acs")?;
//! // Once per tick answered, before the answer (the stream of scenarios/acs_full.toml):
//! acs.begin(42, 420_000_000)?;
//! acs.mode("detumble")?;
//! acs.f64s("rate_b_rad_s", &[0.01, 0.0, -0.02])?;
//! acs.f64s("wheel_momentum_b_nms", &[0.1, 0.0, -0.2])?;
//! acs.bools("sun_visible", &[true])?;
//! acs.publish()?;
//! # Ok(()) }
//! ```
//!
//! After [`FswStream::declare`] nothing allocates but an error: the sample and its encoding
//! buffer are kept.

use std::fmt;
use std::ops::{Deref, DerefMut};

use serde::Deserialize;
use zenoh::pubsub::Publisher;
use zenoh::{Session, Wait as _};

use super::transport::clean_zenoh_message;
use super::vehicle::Vehicle;
use crate::{encode_into, fsw_flags, FswMsg, Header, Topics, MAX_FSW_EVENTS, MAX_FSW_VALUES};

/// Why a stream cannot be declared or a sample cannot be sent.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FswError {
    /// The served configuration declares no such stream.
    #[error(
        "the server's configuration declares no [[fsw_streams]] named \"{stream}\" (declared: \
         {declared})"
    )]
    NoStream {
        /// The stream asked for.
        stream: String,
        /// The streams it declares, quoted (`"acs", "nav"`), or `none`.
        declared: String,
    },
    /// The served configuration's `[[fsw_streams]]` cannot be read, or declare a stream no
    /// sample can carry.
    #[error("the served configuration's [[fsw_streams]]: {0}")]
    Config(String),
    /// A call's argument is wrong: a name the stream does not declare, a value of another type
    /// or length, a non-finite f64, another spacecraft's stamp, more events than a sample
    /// carries.
    #[error("stream `{stream}`: {problem}")]
    Sample {
        /// The stream.
        stream: String,
        /// What is wrong, naming the field.
        problem: String,
    },
    /// A call out of order: a setter or a publish with no sample begun, a tick not after the
    /// last one published, a publish before the sample is complete (a declared value not set,
    /// a variance without an estimate).
    #[error("stream `{stream}`: {problem}")]
    Order {
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

impl fmt::Display for FswType {
    /// As the configuration spells it: `f64`, `i64`, `bool`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::F64 => "f64",
            Self::I64 => "i64",
            Self::Bool => "bool",
        })
    }
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

/// `"a", "b"`, or `none`.
fn quoted<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let v: Vec<String> = names.map(|n| format!("\"{n}\"")).collect();
    if v.is_empty() {
        "none".to_owned()
    } else {
        v.join(", ")
    }
}

impl FswDeclaration {
    /// Every stream the configuration text `config_toml` declares.
    pub fn all_from_config_toml(config_toml: &str) -> Result<Vec<Self>, FswError> {
        let all = toml::from_str::<Streams>(config_toml)
            .map(|s| s.fsw_streams)
            .map_err(|e| FswError::Config(e.message().to_owned()))?;
        for s in &all {
            s.check()?;
        }
        Ok(all)
    }

    /// Stream `stream` of the configuration text `config_toml`, checked to fit a sample:
    /// [`FswError::NoStream`] naming the declared streams when there is none.
    pub fn from_config_toml(config_toml: &str, stream: &str) -> Result<Self, FswError> {
        let all = Self::all_from_config_toml(config_toml)?;
        let declared = quoted(all.iter().map(|s| s.name.as_str()));
        let s = all
            .into_iter()
            .find(|s| s.name == stream)
            .ok_or_else(|| FswError::NoStream {
                stream: stream.to_owned(),
                declared,
            })?;
        Ok(s)
    }

    /// What a sample needs of its declaration (the server checked the rest): no value of length
    /// 0, at most [`MAX_FSW_VALUES`] words, event and mode indices that fit their words.
    fn check(&self) -> Result<(), FswError> {
        let bad = |what: String| FswError::Config(format!("stream `{}`: {what}", self.name));
        if let Some(i) = self.values.iter().position(|v| v.len == 0) {
            return Err(bad(format!("values[{i}].len = 0")));
        }
        let words = self.words();
        if words > MAX_FSW_VALUES {
            return Err(bad(format!(
                "its values hold {words} words, more than a sample carries ({MAX_FSW_VALUES})"
            )));
        }
        if u16::try_from(self.events.len().saturating_sub(1)).is_err() {
            return Err(bad(format!(
                "{} events, more than 65536",
                self.events.len()
            )));
        }
        if u32::try_from(self.modes.len().saturating_sub(1)).is_err() {
            return Err(bad(format!("{} modes, more than 2^32", self.modes.len())));
        }
        Ok(())
    }

    /// The value words of one sample (the sum of the lengths).
    pub fn words(&self) -> usize {
        self.values.iter().fold(0, |n, v| n.saturating_add(v.len))
    }
}

/// A declared stream's samples, built one at a time by name and numbered (`header.seq`), with
/// no transport: [`Self::encode`] hands out the bytes to send and [`Self::published`] says
/// they were sent. See the module docs for what it refuses.
#[derive(Clone, Debug)]
pub struct FswSampler {
    declaration: FswDeclaration,
    /// The first word of each value.
    offsets: Vec<usize>,
    /// Whether each value is set in the sample begun.
    set: Vec<bool>,
    /// The server's numeric spacecraft id (every sample's header carries it).
    spacecraft_id: u32,
    /// The next sample's `header.seq`: the samples published so far.
    seq: u64,
    /// The tick of the last sample published (the server records at most one per tick).
    last_tick: Option<u64>,
    /// Whether `msg` is a sample begun and not published.
    begun: bool,
    msg: FswMsg,
    buf: Vec<u8>,
}

impl FswSampler {
    /// The samples of `declaration` (from [`FswDeclaration::from_config_toml`]) for the server
    /// whose headers carry `spacecraft_id`.
    pub fn new(declaration: FswDeclaration, spacecraft_id: u32) -> Self {
        let words = declaration.words();
        let offsets = declaration
            .values
            .iter()
            .scan(0usize, |at, v| {
                let first = *at;
                *at = at.saturating_add(v.len);
                Some(first)
            })
            .collect();
        Self {
            offsets,
            set: vec![false; declaration.values.len()],
            declaration,
            spacecraft_id,
            seq: 0,
            last_tick: None,
            begun: false,
            msg: FswMsg {
                values: vec![0; words],
                ..FswMsg::default()
            },
            buf: Vec::with_capacity(crate::FSW_FIXED_LEN + 8 * words),
        }
    }

    /// The stream's declaration.
    pub fn declaration(&self) -> &FswDeclaration {
        &self.declaration
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

    /// Starts the sample of `tick` (the tick this flight code answers) at `sim_time_ns`,
    /// nothing set yet; a sample begun and not published is dropped. [`FswError::Order`] for a
    /// tick not after the last one published (the server records at most one sample per tick
    /// per stream, in tick order).
    pub fn begin(&mut self, tick: u64, sim_time_ns: u64) -> Result<(), FswError> {
        if let Some(last) = self.last_tick.filter(|&t| tick <= t) {
            return Err(self.order(format!(
                "a sample for tick {tick} after tick {last} was published (the server records \
                 at most one sample per tick per stream, in tick order)"
            )));
        }
        let values = std::mem::take(&mut self.msg.values);
        self.msg = FswMsg {
            header: Header::new(self.spacecraft_id, tick, sim_time_ns, self.seq),
            values,
            ..FswMsg::default()
        };
        self.set.iter_mut().for_each(|s| *s = false);
        self.begun = true;
        Ok(())
    }

    /// [`Self::begin`] at the tick and time of `stamp`, the header of the server's message
    /// answered (its seq is ignored); [`FswError::Sample`] for another spacecraft's header.
    pub fn begin_stamped(&mut self, stamp: &Header) -> Result<(), FswError> {
        if stamp.spacecraft_id != self.spacecraft_id {
            return Err(self.sample(format!(
                "the stamp's spacecraft_id is {}, the server's is {} (stamp the sample with the \
                 header of the state you answer)",
                stamp.spacecraft_id, self.spacecraft_id
            )));
        }
        self.begin(stamp.tick, stamp.sim_time_ns)
    }

    fn sample(&self, problem: String) -> FswError {
        FswError::Sample {
            stream: self.declaration.name.clone(),
            problem,
        }
    }

    fn order(&self, problem: String) -> FswError {
        FswError::Order {
            stream: self.declaration.name.clone(),
            problem,
        }
    }

    /// Ok while a sample is begun and not published.
    fn begun(&self) -> Result<(), FswError> {
        if self.begun {
            Ok(())
        } else {
            Err(self.order("no sample begun (call begin first)".to_owned()))
        }
    }

    /// The mode the flight code is in at the sample's tick.
    pub fn mode(&mut self, name: &str) -> Result<(), FswError> {
        self.begun()?;
        let Some(i) = self.declaration.modes.iter().position(|m| m == name) else {
            return Err(self.sample(format!(
                "no mode \"{name}\" is declared (modes: {})",
                quoted(self.declaration.modes.iter().map(String::as_str))
            )));
        };
        // Fits: the declaration was checked.
        self.msg.mode = i as u32;
        self.msg.flags |= fsw_flags::MODE;
        Ok(())
    }

    /// An event raised at the sample's tick (at most [`MAX_FSW_EVENTS`] per sample).
    pub fn event(&mut self, name: &str) -> Result<(), FswError> {
        self.begun()?;
        let events = &self.declaration.events;
        let Some(i) = events.iter().position(|e| e.name == name) else {
            return Err(self.sample(format!(
                "no event \"{name}\" is declared (events: {})",
                quoted(events.iter().map(|e| e.name.as_str()))
            )));
        };
        let n = usize::from(self.msg.event_count);
        if n >= MAX_FSW_EVENTS {
            return Err(self.sample(format!(
                "event \"{name}\": this sample holds {MAX_FSW_EVENTS} events already, the most \
                 one carries"
            )));
        }
        // Fits: the declaration was checked.
        self.msg.events[n] = i as u16;
        self.msg.event_count += 1;
        Ok(())
    }

    /// Ok when every element of `what` `name` is finite.
    fn finite(&self, what: &str, name: &str, v: &[f64]) -> Result<(), FswError> {
        match v.iter().position(|x| !x.is_finite()) {
            Some(k) => Err(self.sample(format!(
                "{what} `{name}[{k}]` = {} is not finite (the server refuses it)",
                v[k]
            ))),
            None => Ok(()),
        }
    }

    /// The attitude estimate: the quaternion q_BN (maps N → B), scalar first.
    pub fn estimate(&mut self, q_bn: [f64; 4]) -> Result<(), FswError> {
        self.begun()?;
        self.finite("estimate", "q_bn", &q_bn)?;
        self.msg.q_est_bn = q_bn;
        self.msg.flags |= fsw_flags::ESTIMATE;
        Ok(())
    }

    /// The target attitude: the quaternion q_RN (maps N → R), scalar first.
    pub fn target(&mut self, q_rn: [f64; 4]) -> Result<(), FswError> {
        self.begun()?;
        self.finite("target", "q_rn", &q_rn)?;
        self.msg.q_target_rn = q_rn;
        self.msg.flags |= fsw_flags::TARGET;
        Ok(())
    }

    /// \[rad²\] the variances of the estimate's attitude error about the body axes (needs an
    /// [`Self::estimate`] in the same sample).
    pub fn variance(&mut self, var_b_rad2: [f64; 3]) -> Result<(), FswError> {
        self.begun()?;
        self.finite("variance", "var_b_rad2", &var_b_rad2)?;
        self.msg.att_var_b_rad2 = var_b_rad2;
        self.msg.flags |= fsw_flags::COVARIANCE;
        Ok(())
    }

    /// The index of value `name`, checked to be declared with type `ty` and `n` elements, in
    /// the sample begun.
    fn value(&self, name: &str, ty: FswType, n: usize) -> Result<usize, FswError> {
        self.begun()?;
        let values = &self.declaration.values;
        let Some(i) = values.iter().position(|v| v.name == name) else {
            let declared: Vec<String> = values
                .iter()
                .map(|v| match v.len {
                    1 => format!("\"{}\" {}", v.name, v.ty),
                    len => format!("\"{}\" {}[{len}]", v.name, v.ty),
                })
                .collect();
            return Err(self.sample(format!(
                "no value \"{name}\" is declared (values: {})",
                if declared.is_empty() {
                    "none".to_owned()
                } else {
                    declared.join(", ")
                }
            )));
        };
        let v = &values[i];
        if v.ty != ty {
            return Err(self.sample(format!("value `{name}` is {}, not {ty}", v.ty)));
        }
        if v.len != n {
            return Err(self.sample(format!(
                "value `{name}` has {} element{}, got {n}",
                v.len,
                if v.len == 1 { "" } else { "s" }
            )));
        }
        Ok(i)
    }

    /// The words of value `i`, now set.
    fn words_of(&mut self, i: usize) -> &mut [u64] {
        self.set[i] = true;
        let at = self.offsets[i];
        &mut self.msg.values[at..at + self.declaration.values[i].len]
    }

    /// Sets f64 value `name`: all its elements, every one finite.
    pub fn f64s(&mut self, name: &str, v: &[f64]) -> Result<(), FswError> {
        let i = self.value(name, FswType::F64, v.len())?;
        self.finite("value", name, v)?;
        for (w, x) in self.words_of(i).iter_mut().zip(v) {
            *w = x.to_bits();
        }
        Ok(())
    }

    /// Sets i64 value `name`: all its elements.
    pub fn i64s(&mut self, name: &str, v: &[i64]) -> Result<(), FswError> {
        let i = self.value(name, FswType::I64, v.len())?;
        for (w, x) in self.words_of(i).iter_mut().zip(v) {
            *w = *x as u64;
        }
        Ok(())
    }

    /// Sets bool value `name`: all its elements.
    pub fn bools(&mut self, name: &str, v: &[bool]) -> Result<(), FswError> {
        self.bools_iter(name, v.iter().copied())
    }

    /// [`Self::bools`] from an iterator (e.g. C ints, anything but 0 true).
    pub fn bools_iter(
        &mut self,
        name: &str,
        v: impl ExactSizeIterator<Item = bool>,
    ) -> Result<(), FswError> {
        let i = self.value(name, FswType::Bool, v.len())?;
        for (w, x) in self.words_of(i).iter_mut().zip(v) {
            *w = u64::from(x);
        }
        Ok(())
    }

    /// The encoded sample begun, to send; it stays begun until [`Self::published`].
    /// [`FswError::Order`], and nothing to send, when no sample is begun, a declared value is
    /// not set or a variance has no estimate.
    pub fn encode(&mut self) -> Result<&[u8], FswError> {
        self.begun()?;
        let tick = self.msg.header.tick;
        let missing: Vec<String> = (self.set.iter().zip(&self.declaration.values))
            .filter(|(set, _)| !**set)
            .map(|(_, v)| format!("`{}`", v.name))
            .collect();
        if !missing.is_empty() {
            return Err(self.order(format!(
                "the sample of tick {tick} lacks value{} {} (nothing sent: every declared value \
                 is in every sample)",
                if missing.len() == 1 { "" } else { "s" },
                missing.join(", ")
            )));
        }
        let flags = self.msg.flags;
        if flags & fsw_flags::COVARIANCE != 0 && flags & fsw_flags::ESTIMATE == 0 {
            return Err(self.order(format!(
                "the sample of tick {tick} has a variance without an estimate (nothing sent: \
                 set the estimate too)"
            )));
        }
        encode_into(&self.msg, &mut self.buf);
        Ok(&self.buf)
    }

    /// The sample [`Self::encode`] handed out was sent: the next needs a [`Self::begin`] with a
    /// later tick, and is numbered next.
    pub fn published(&mut self) {
        if std::mem::take(&mut self.begun) {
            self.last_tick = Some(self.msg.header.tick);
            self.seq += 1;
        }
    }
}

/// A declared stream's [`FswSampler`] (which it dereferences to: begin and the setters) bound to
/// its publisher; see the module docs.
pub struct FswStream {
    sampler: FswSampler,
    publisher: Publisher<'static>,
}

impl FswStream {
    /// Stream `stream` of the configuration `vehicle` serves, with a publisher on
    /// `flexdyn/<sc>/fsw/<stream>`: blocking congestion control (this end never drops a
    /// sample) and batched (not express). A sample published before a lockstep answer from the
    /// same session reaches the server before the answer: both go through the session's one
    /// queue per priority in order, and an express answer flushes the batch that holds the
    /// sample, so the two leave in one write. (Express, each took a write of its own: the demo's
    /// lockstep loop at 1 kHz ran at 0.90 of its rate without telemetry, batched at 0.97;
    /// `cargo bench -p flexdyn-tools --bench lockstep`.)
    pub fn declare(
        session: &Session,
        topics: &Topics,
        vehicle: &Vehicle,
        stream: &str,
    ) -> Result<Self, FswError> {
        let declaration = FswDeclaration::from_config_toml(&vehicle.config_toml, stream)?;
        let key = crate::fsw_key(topics.sc_id(), stream).map_err(|e| FswError::Sample {
            stream: stream.to_owned(),
            problem: e.to_string(),
        })?;
        let declared =
            super::transport::declared_key(session, key.clone()).map_err(|e| FswError::Zenoh {
                message: clean_zenoh_message(&e.to_string()),
                key: key.clone(),
            })?;
        let publisher = session
            .declare_publisher(declared)
            .congestion_control(zenoh::qos::CongestionControl::Block)
            .express(false)
            .wait()
            .map_err(|e| FswError::Zenoh {
                message: clean_zenoh_message(&e.to_string()),
                key,
            })?;
        Ok(Self::new(
            FswSampler::new(declaration, vehicle.spacecraft_id),
            publisher,
        ))
    }

    /// `sampler` bound to `publisher` (declared on the stream's key, blocking, batched).
    fn new(sampler: FswSampler, publisher: Publisher<'static>) -> Self {
        Self { sampler, publisher }
    }

    /// Its key, `flexdyn/<sc>/fsw/<name>`.
    pub fn key(&self) -> &str {
        self.publisher.key_expr().as_str()
    }

    /// Sends the sample begun with [`FswSampler::begin`] (see [`FswSampler::encode`] for what
    /// it refuses: nothing is sent then, and the sample stays begun, as it does when Zenoh
    /// refuses the put).
    pub fn publish(&mut self) -> Result<(), FswError> {
        let bytes = self.sampler.encode()?;
        self.publisher
            .put(bytes)
            .wait()
            .map_err(|e| FswError::Zenoh {
                key: self.publisher.key_expr().to_string(),
                message: clean_zenoh_message(&e.to_string()),
            })?;
        self.sampler.published();
        Ok(())
    }
}

impl Deref for FswStream {
    type Target = FswSampler;

    fn deref(&self) -> &FswSampler {
        &self.sampler
    }
}

impl DerefMut for FswStream {
    fn deref_mut(&mut self) -> &mut FswSampler {
        &mut self.sampler
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode_fsw;

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

    fn sampler(stream: &str) -> FswSampler {
        FswSampler::new(FswDeclaration::from_config_toml(CONFIG, stream).unwrap(), 7)
    }

    /// A sample of tick `tick` with every value of `acs` set.
    fn complete(s: &mut FswSampler, tick: u64) {
        s.begin(tick, tick * 10_000_000).unwrap();
        s.f64s("h_b_nms", &[0.0; 3]).unwrap();
        s.i64s("flags", &[0]).unwrap();
        s.bools("ok", &[false]).unwrap();
    }

    #[test]
    fn the_declaration_reads_from_the_served_toml() {
        let d = FswDeclaration::from_config_toml(CONFIG, "acs").unwrap();
        assert_eq!(d.modes, ["detumble", "point"]);
        assert_eq!(d.events[0].severity, "error");
        assert_eq!(d.events[1].severity, "info");
        assert_eq!(d.values[0].ty, FswType::F64);
        assert_eq!((d.values[1].len, d.values[2].len), (1, 1));
        assert_eq!(d.words(), 5);
        assert_eq!(sampler("acs").offsets, [0, 3, 4]);
        let nav = FswDeclaration::from_config_toml(CONFIG, "nav").unwrap();
        assert_eq!(nav.words(), 0);
        let err = FswDeclaration::from_config_toml(CONFIG, "gnc").unwrap_err();
        assert_eq!(
            err.to_string(),
            "the server's configuration declares no [[fsw_streams]] named \"gnc\" (declared: \
             \"acs\", \"nav\")"
        );
        let none = FswDeclaration::from_config_toml("[simulation]\n", "acs").unwrap_err();
        assert!(none.to_string().ends_with("(declared: none)"), "{none}");
        let unread = FswDeclaration::from_config_toml("x = [", "acs").unwrap_err();
        assert!(matches!(unread, FswError::Config(_)), "{unread}");
    }

    #[test]
    fn a_declaration_no_sample_can_carry_is_refused() {
        let refused = |values: &str| {
            let toml = format!("[[fsw_streams]]\nname = \"s\"\nvalues = [{values}]\n");
            match FswDeclaration::from_config_toml(&toml, "s") {
                Err(FswError::Config(m)) => m,
                other => panic!("{other:?}"),
            }
        };
        assert_eq!(
            refused(r#"{ name = "a", type = "f64", len = 0 }"#),
            "stream `s`: values[0].len = 0"
        );
        assert_eq!(
            refused(
                r#"{ name = "a", type = "i64", len = 200 }, { name = "b", type = "bool", len = 57 }"#
            ),
            "stream `s`: its values hold 257 words, more than a sample carries (256)"
        );
        assert!(refused(r#"{ name = "a", type = "u8" }"#).contains("u8"));
    }

    #[test]
    fn a_sample_filled_by_name_decodes_to_the_words_declared() {
        let mut s = sampler("acs");
        for tick in [4u64, 5] {
            // Stamped from the server's header (its seq ignored), numbered by the stream.
            s.begin_stamped(&Header::new(7, tick, tick * 10_000_000, 99))
                .unwrap();
            s.mode("point").unwrap();
            s.event("detumbled").unwrap();
            s.event("gyro_fault").unwrap();
            s.estimate([0.6, 0.8, 0.0, 0.0]).unwrap();
            s.target([0.0, 0.0, 0.6, 0.8]).unwrap();
            s.variance([1e-6, 2e-6, 3e-6]).unwrap();
            s.f64s("h_b_nms", &[0.5, -1.0, 0.25]).unwrap();
            s.i64s("flags", &[-3]).unwrap();
            s.bools_iter("ok", [7].iter().map(|&x| x != 0)).unwrap();
            let m = decode_fsw(s.encode().unwrap()).unwrap();
            s.published();
            assert_eq!(m.header, Header::new(7, tick, tick * 10_000_000, tick - 4));
            let all = fsw_flags::MODE | fsw_flags::ESTIMATE | fsw_flags::TARGET;
            assert_eq!(m.flags, all | fsw_flags::COVARIANCE);
            assert_eq!((m.mode, m.event_indices()), (1, &[1u16, 0][..]));
            assert_eq!(m.q_est_bn, [0.6, 0.8, 0.0, 0.0]);
            assert_eq!(m.q_target_rn, [0.0, 0.0, 0.6, 0.8]);
            assert_eq!(m.att_var_b_rad2, [1e-6, 2e-6, 3e-6]);
            let words = [0.5f64.to_bits(), (-1.0f64).to_bits(), 0.25f64.to_bits()];
            assert_eq!(m.values, [words[0], words[1], words[2], (-3i64) as u64, 1]);
        }
        // The next sample starts from nothing: no flag, mode or event of the last one.
        complete(&mut s, 6);
        let m = decode_fsw(s.encode().unwrap()).unwrap();
        assert_eq!((m.flags, m.event_count, m.header.seq), (0, 0, 2));
    }

    #[test]
    fn nothing_allocates_after_the_first_sample() {
        let mut s = sampler("acs");
        complete(&mut s, 0);
        let first = s.encode().unwrap().as_ptr();
        let values = s.msg.values.as_ptr();
        s.published();
        for tick in 1..50 {
            complete(&mut s, tick);
            s.event("gyro_fault").unwrap();
            assert_eq!(s.encode().unwrap().as_ptr(), first);
            assert_eq!(s.msg.values.as_ptr(), values);
            s.published();
        }
    }

    /// `r`'s error: Sample (`true`) or Order (`false`), and its message.
    fn refusal(r: Result<(), FswError>) -> (bool, String) {
        match r {
            Err(e @ FswError::Sample { .. }) => (true, e.to_string()),
            Err(e @ FswError::Order { .. }) => (false, e.to_string()),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn refuses_what_the_server_would_refuse_naming_stream_and_field() {
        let mut s = sampler("acs");
        assert_eq!(
            refusal(s.mode("point")),
            (
                false,
                "stream `acs`: no sample begun (call begin first)".to_owned()
            )
        );
        assert!(!refusal(s.encode().map(drop)).0);
        let (argument, m) = refusal(s.begin_stamped(&Header::new(8, 1, 0, 0)));
        assert!(
            argument && m.contains("spacecraft_id is 8, the server's is 7"),
            "{m}"
        );
        s.begin(1, 10_000_000).unwrap();
        let cases = [
            (
                s.mode("safe"),
                "no mode \"safe\" is declared (modes: \"detumble\", \"point\")",
            ),
            (
                s.event("nope"),
                "no event \"nope\" is declared (events: \"gyro_fault\", \"detumbled\")",
            ),
            (
                s.f64s("nope", &[1.0]),
                "no value \"nope\" is declared (values: \"h_b_nms\" f64[3], \"flags\" i64, \
                 \"ok\" bool)",
            ),
            (s.f64s("flags", &[1.0]), "value `flags` is i64, not f64"),
            (
                s.f64s("h_b_nms", &[1.0, 2.0]),
                "value `h_b_nms` has 3 elements, got 2",
            ),
            (
                s.f64s("h_b_nms", &[1.0, f64::NAN, 0.0]),
                "value `h_b_nms[1]` = NaN is not finite (the server refuses it)",
            ),
            (
                s.estimate([1.0, 0.0, f64::INFINITY, 0.0]),
                "estimate `q_bn[2]` = inf is not finite (the server refuses it)",
            ),
            (
                s.target([f64::NAN, 0.0, 0.0, 1.0]),
                "target `q_rn[0]` = NaN is not finite (the server refuses it)",
            ),
            (
                s.variance([0.0, f64::NEG_INFINITY, 0.0]),
                "variance `var_b_rad2[1]` = -inf is not finite (the server refuses it)",
            ),
            (
                s.bools("ok", &[true, false]),
                "value `ok` has 1 element, got 2",
            ),
        ];
        for (r, expected) in cases {
            assert_eq!(refusal(r), (true, format!("stream `acs`: {expected}")));
        }
        for _ in 0..MAX_FSW_EVENTS {
            s.event("gyro_fault").unwrap();
        }
        let (argument, m) = refusal(s.event("gyro_fault"));
        assert!(argument && m.contains("holds 8 events already"), "{m}");
        // The refusals changed nothing, nor does a refused begin: still the sample of tick 1.
        assert!(refusal(s.begin_stamped(&Header::new(8, 2, 0, 0))).0);
        s.i64s("flags", &[1]).unwrap();
        // A value left out: nothing to send, and the sample stays begun.
        let (argument, m) = refusal(s.encode().map(drop));
        assert!(!argument);
        assert_eq!(
            m,
            "stream `acs`: the sample of tick 1 lacks values `h_b_nms`, `ok` (nothing sent: \
             every declared value is in every sample)"
        );
        s.f64s("h_b_nms", &[0.0; 3]).unwrap();
        s.bools("ok", &[false]).unwrap();
        s.variance([1.0; 3]).unwrap();
        let (argument, m) = refusal(s.encode().map(drop));
        assert!(
            !argument && m.contains("tick 1 has a variance without an estimate"),
            "{m}"
        );
        s.estimate([1.0, 0.0, 0.0, 0.0]).unwrap();
        let m = decode_fsw(s.encode().unwrap()).unwrap();
        assert_eq!((m.header.tick, m.header.seq, m.event_count), (1, 0, 8));
        assert_eq!(m.values[3], 1);
        s.published();
        // Once published, the sample is gone, and its tick cannot be sent again.
        assert!(!refusal(s.mode("point")).0);
        assert!(!refusal(s.encode().map(drop)).0);
        let (argument, m) = refusal(s.begin(1, 10_000_000));
        assert!(!argument && m.contains("tick 1 after tick 1"), "{m}");
        assert!(m.contains("at most one sample per tick per stream"), "{m}");
        assert!(!refusal(s.begin(0, 0)).0);
        s.published(); // with no sample begun: nothing
        complete(&mut s, 2);
        assert_eq!(decode_fsw(s.encode().unwrap()).unwrap().header.seq, 1);
    }

    #[test]
    fn a_stream_without_values_publishes_an_empty_sample() {
        let mut s = sampler("nav");
        s.begin(0, 0).unwrap();
        let m = decode_fsw(s.encode().unwrap()).unwrap();
        assert_eq!((m.flags, m.values.len()), (0, 0));
        let (argument, m) = refusal(s.mode("detumble"));
        assert!(argument && m.ends_with("(modes: none)"), "{m}");
        let (_, m) = refusal(s.f64s("x", &[]));
        assert!(m.ends_with("(values: none)"), "{m}");
    }
}
