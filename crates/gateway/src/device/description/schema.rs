//! The TOML shape of the device list and of a device description, as `serde` reads it
//! (unknown keys are refused). Meaning and checks are in [`super::build`] and [`super::list`];
//! the keys are documented for users in `scenarios/devices/*.toml` and the book.

use std::collections::BTreeMap;

use serde::Deserialize;

/// The device list file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ListFile {
    /// Non-loopback socket addresses are refused unless true.
    #[serde(default)]
    pub allow_lab_interfaces: bool,
    /// The devices.
    #[serde(default)]
    pub device: Vec<ListDevice>,
}

/// One `[[device]]` of the list.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ListDevice {
    /// Unique name.
    pub name: String,
    /// Path of the description, relative to the list file.
    pub description: String,
    /// Values of the description's `{param}`s.
    #[serde(default)]
    pub bind: BTreeMap<String, String>,
    /// Where the byte stream is exposed.
    pub endpoint: EndpointTable,
}

/// `endpoint = { pty = "..", baud = .. }` or `{ tcp_server = ".." }`, `{ tcp_client = ".." }`,
/// `{ udp_local = "..", udp_remote = ".." }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EndpointTable {
    /// Pty symlink path.
    pub pty: Option<String>,
    /// \[bit/s\] pty line rate.
    pub baud: Option<u32>,
    /// TCP listen address.
    pub tcp_server: Option<String>,
    /// TCP connect address.
    pub tcp_client: Option<String>,
    /// UDP local address.
    pub udp_local: Option<String>,
    /// UDP remote address.
    pub udp_remote: Option<String>,
}

/// A device description.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DescriptionFile {
    /// `"binary"` (the default: framed messages described below) or `"nmea0183"`.
    pub protocol: Option<String>,
    /// The model's name, for people.
    pub model: Option<String>,
    /// `"big"` (default) or `"little"`: the order of every multi-octet field.
    pub byte_order: Option<String>,
    /// \[ms\] declared output latency (real time): bytes go out this long after their tick.
    pub output_latency_ms: Option<f64>,
    /// How frames are delimited and checked (binary protocol).
    pub framing: Option<FramingSpec>,
    /// The id field that selects a message (binary protocol).
    pub id: Option<IdSpec>,
    /// The messages (binary protocol).
    #[serde(default)]
    pub message: Vec<MessageSpec>,
    /// A wheel drive's speed loop.
    pub speed_loop: Option<SpeedLoopSpec>,
    /// NMEA: the GPS receiver's catalog group (`gps.{gps}`).
    pub gps: Option<String>,
    /// NMEA: the talker id (default `GP`).
    pub talker: Option<String>,
    /// NMEA: satellites in use written in GGA (default 8).
    pub satellites: Option<u8>,
    /// NMEA: HDOP written in GGA (default 1.0).
    pub hdop: Option<f64>,
    /// NMEA: the sentences.
    #[serde(default)]
    pub sentence: Vec<SentenceSpec>,
}

/// `[framing]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FramingSpec {
    /// `sync_length`, `slip`, `cobs`, `hdlc` or `ccsds`.
    pub kind: String,
    /// sync_length: the sync octets.
    pub sync: Option<Vec<u8>>,
    /// sync_length: constant octets between the sync and the length field.
    pub header: Option<Vec<u8>>,
    /// sync_length: the length field.
    pub length: Option<LengthSpec>,
    /// The check: a catalogue name (`"CRC-16/CCITT-FALSE"`), `"xor8"`, `"sum8"`,
    /// `"fletcher16"`, `"fletcher32"`, or the CRC's parameters.
    pub checksum: Option<ChecksumSpec>,
    /// sync_length: offset from the frame start where the check's coverage begins (default
    /// 0, the sync included).
    pub checksum_from: Option<usize>,
    /// Octet order of the check value (default: the description's `byte_order`; HDLC's FCS
    /// is always little-endian, RFC 1662).
    pub checksum_order: Option<String>,
    /// hdlc: the ACCM (default 0xFFFFFFFF, RFC 1662 §7.1).
    pub accm: Option<u32>,
    /// ccsds: a CUC secondary header from the tick's TAI.
    pub secondary_header: Option<SecondaryHeaderSpec>,
}

/// `length = { offset, size, counts, adjust }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LengthSpec {
    /// Offset from the frame start.
    pub offset: usize,
    /// 1, 2 or 4 octets.
    pub size: usize,
    /// `payload`, `after_field` or `frame`.
    pub counts: String,
    /// Added to the field's value to get the count.
    #[serde(default)]
    pub adjust: i64,
    /// Octet order (default: the description's).
    pub byte_order: Option<String>,
}

/// A checksum by name or by its Rocksoft-model parameters.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum ChecksumSpec {
    /// A name.
    Name(String),
    /// `{ width, poly, init, refin, refout, xorout }`.
    Crc(CrcSpec),
}

/// A CRC's parameters (RevEng catalogue form).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrcSpec {
    /// Width in bits.
    pub width: u8,
    /// Polynomial, normal form.
    pub poly: u32,
    /// Initial register.
    pub init: u32,
    /// Input reflected.
    pub refin: bool,
    /// Output reflected.
    pub refout: bool,
    /// Final XOR.
    pub xorout: u32,
}

/// `secondary_header = { cuc_coarse_octets, cuc_fine_octets, p_field }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SecondaryHeaderSpec {
    /// 1 to 4.
    pub cuc_coarse_octets: u8,
    /// 0 to 3.
    pub cuc_fine_octets: u8,
    /// The P-field octet precedes the time.
    #[serde(default)]
    pub p_field: bool,
    /// `"tai1958"` (default: TAI since 1958, CUC level 1) or `"met"` (mission elapsed
    /// time, an agency-defined epoch, level 2).
    pub epoch: Option<String>,
}

/// `[id]`: the id field at the start of every payload.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IdSpec {
    /// An unsigned integer type (`u8`, `u16`, `u32`).
    #[serde(rename = "type")]
    pub type_: String,
}

/// `[[message]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MessageSpec {
    /// Unique name.
    pub name: String,
    /// `in` (driver → device) or `out` (device → driver).
    pub direction: String,
    /// The id field's value.
    pub id: Option<u64>,
    /// ccsds: the APID.
    pub apid: Option<u16>,
    /// out: period, a whole number of frames.
    pub every_s: Option<f64>,
    /// out: sent when this catalog group publishes.
    pub on_sample: Option<String>,
    /// in: the out message sent back.
    pub response: Option<String>,
    /// in, lockstep: the driver sends one every this many seconds, from tick 0.
    pub due_every_s: Option<f64>,
    /// in, lockstep: how long the gateway waits for it.
    pub timeout_ms: Option<u64>,
    /// The fields after the id.
    #[serde(default)]
    pub field: Vec<FieldSpec>,
}

/// `[[message.field]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldSpec {
    /// Name, for people and error messages.
    pub name: Option<String>,
    /// `u8`..`u64`, `i8`..`i64`, `f32`, `f64` (absent with `const_bytes`).
    #[serde(rename = "type")]
    pub type_: Option<String>,
    /// Constant octets.
    pub const_bytes: Option<Vec<u8>>,
    /// Order override.
    pub byte_order: Option<String>,
    /// Engineering value = raw · scale + offset.
    pub scale: Option<f64>,
    /// See `scale`.
    pub offset: Option<f64>,
    /// The engineering value's unit (default: the source's or destination's SI unit).
    pub unit: Option<String>,
    /// out: a catalog channel, `time.…` or `counter`.
    pub source: Option<String>,
    /// out: 1 if this group's sample is valid, else 0.
    pub valid: Option<String>,
    /// out: a constant engineering value.
    pub value: Option<f64>,
    /// in: a catalog input or `speed_loop.setpoint`.
    pub dest: Option<String>,
    /// Lower bound of the engineering value (clamped, counted).
    pub min: Option<f64>,
    /// Upper bound of the engineering value (clamped, counted).
    pub max: Option<f64>,
}

/// `[speed_loop]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpeedLoopSpec {
    /// The measured wheel speed channel (rad/s).
    pub measured: String,
    /// The torque input it drives (N m).
    pub torque: String,
    /// \[N m/(rad/s)\] proportional gain.
    pub gain_nm_per_rad_s: f64,
    /// \[N m\] torque limit.
    pub max_torque_nm: f64,
}

/// `[[sentence]]` (NMEA).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SentenceSpec {
    /// `GGA`, `RMC` or `ZDA`.
    #[serde(rename = "type")]
    pub type_: String,
    /// Period, a whole number of frames.
    pub every_s: f64,
}
