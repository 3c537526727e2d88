//! From a description's TOML to a [`Behaviour`]: every name resolved against the catalog,
//! every unit converted, every rate checked against the frame period. Each refusal names the
//! file, the key path (`message[2].field[3].source`, indices from 0) and the problem.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Duration;

use super::schema::{
    ChecksumSpec, DescriptionFile, FieldSpec, FramingSpec, MessageSpec, SpeedLoopSpec,
};
use super::DescriptionError;
use crate::ccsds::{CucEpoch, CucFormat};
use crate::checksum::{presets, Checksum, Crc, CrcParams};
use crate::device::catalog::Catalog;
use crate::device::ccsds_framing::{CcsdsFraming, CucSource};
use crate::device::engine::Behaviour;
use crate::device::field::{Codec, Dest, Field, Numeric, Scalar, Source, Validity};
use crate::device::message::{Direction, IdField, Message, Schedule};
use crate::device::nmea_device::{GpsChannels, NmeaDevice, SentenceKind};
use crate::device::speed_loop::SpeedLoop;
use crate::device::time::TimeSource;
use crate::device::units::{factor_from_si, known_units, UnitMismatch};
use crate::device::wire::{Wire, MAX_PAYLOAD_BYTES};
use crate::framing::hdlc::HdlcFraming;
use crate::framing::length::{LengthCounts, LengthField, LengthFraming, LengthFramingConfig};
use crate::framing::FrameCheck;
use crate::nmea::{NmeaStyle, Talker};
use crate::ByteOrder;

/// A description built: its engine, latency, lockstep time-out and message names.
#[derive(Debug)]
pub struct Built {
    /// The engine.
    pub behaviour: Behaviour,
    /// \[ns\] declared output latency.
    pub latency_ns: u64,
    /// Lockstep time-out.
    pub timeout: Duration,
    /// Message (or sentence) names.
    pub message_names: Vec<String>,
}

/// What a description is built against.
pub struct Context<'a> {
    /// The description file (for errors).
    pub file: &'a Path,
    /// The catalog.
    pub catalog: &'a Catalog,
    /// The device list's `bind` values for `{param}`s.
    pub bind: &'a BTreeMap<String, String>,
}

/// The lockstep time-out when no message declares one.
const DEFAULT_TIMEOUT: Duration = Duration::from_secs(1);
/// How many choices an error lists at most.
const CHOICES: usize = 12;

type Result<T> = std::result::Result<T, DescriptionError>;

impl Context<'_> {
    fn err<T>(&self, key: impl Into<String>, problem: impl Into<String>) -> Result<T> {
        Err(DescriptionError::invalid(self.file, key, problem))
    }

    /// `text` with every `{param}` replaced by its bound value.
    fn substitute(&self, key: &str, text: &str) -> Result<String> {
        let mut out = String::new();
        let mut rest = text;
        while let Some(open) = rest.find('{') {
            out.push_str(&rest[..open]);
            let Some(close) = rest[open..].find('}') else {
                return self.err(key, format!("`{text}` has a `{{` with no `}}`"));
            };
            let param = &rest[open + 1..open + close];
            match self.bind.get(param) {
                Some(value) => out.push_str(value),
                None => {
                    let bound: Vec<&str> = self.bind.keys().map(String::as_str).collect();
                    return self.err(
                        key,
                        format!(
                            "`{{{param}}}` is not bound: the device list's `bind` gives [{}]",
                            bound.join(", ")
                        ),
                    );
                }
            }
            rest = &rest[open + close + 1..];
        }
        out.push_str(rest);
        Ok(out)
    }

    fn channel(&self, key: &str, text: &str) -> Result<usize> {
        let name = self.substitute(key, text)?;
        self.catalog.channel_index(&name).map_or_else(
            || {
                let near = Catalog::suggestions(
                    self.catalog.channels().iter().map(|c| c.name.as_str()),
                    &name,
                    CHOICES,
                );
                self.err(
                    key,
                    format!(
                        "unknown channel `{name}`; channels offered: [{}]",
                        near.join(", ")
                    ),
                )
            },
            Ok,
        )
    }

    fn group(&self, key: &str, text: &str) -> Result<usize> {
        let name = self.substitute(key, text)?;
        self.catalog.group_index(&name).map_or_else(
            || {
                let near = Catalog::suggestions(
                    self.catalog.groups().iter().map(|g| g.name.as_str()),
                    &name,
                    CHOICES,
                );
                self.err(
                    key,
                    format!(
                        "unknown group `{name}`; groups offered: [{}]",
                        near.join(", ")
                    ),
                )
            },
            Ok,
        )
    }

    fn input(&self, key: &str, text: &str) -> Result<usize> {
        let name = self.substitute(key, text)?;
        self.catalog.input_index(&name).map_or_else(
            || {
                let near = Catalog::suggestions(
                    self.catalog.inputs().iter().map(|i| i.name.as_str()),
                    &name,
                    CHOICES,
                );
                self.err(
                    key,
                    format!(
                        "unknown input `{name}`; inputs offered: [{}] (or `speed_loop.setpoint`)",
                        near.join(", ")
                    ),
                )
            },
            Ok,
        )
    }

    fn order(&self, key: &str, text: Option<&str>, default: ByteOrder) -> Result<ByteOrder> {
        match text {
            None => Ok(default),
            Some("big") => Ok(ByteOrder::BigEndian),
            Some("little") => Ok(ByteOrder::LittleEndian),
            Some(other) => self.err(
                key,
                format!("byte order `{other}`: expected `big` or `little`"),
            ),
        }
    }

    /// A period in frames: `seconds` must be a whole, positive number of frame periods.
    fn period_ticks(&self, key: &str, seconds: f64) -> Result<u64> {
        let frame_ns = self.catalog.frame_ns();
        let frame_s = frame_ns as f64 * 1e-9;
        let ns = seconds * 1e9;
        let whole_ns = ns.round();
        // A decimal period such as 0.1 s is not exact in binary: allow 1 ppb of rounding.
        let exact = (ns - whole_ns).abs() <= 1e-9 * ns.abs().max(1.0);
        if !seconds.is_finite() || seconds <= 0.0 || !exact || frame_ns == 0 {
            return self.err(
                key,
                format!("{seconds} s is not a positive whole number of frames ({frame_s} s each)"),
            );
        }
        let whole_ns = whole_ns as u64;
        if !whole_ns.is_multiple_of(frame_ns) {
            return self.err(
                key,
                format!(
                    "{seconds} s is not a whole number of frames ({frame_s} s each): \
                     use a multiple of {frame_s} s"
                ),
            );
        }
        Ok(whole_ns / frame_ns)
    }

    fn checksum(&self, key: &str, spec: &ChecksumSpec) -> Result<Checksum> {
        let params = match spec {
            ChecksumSpec::Name(name) => match name.to_ascii_lowercase().as_str() {
                "xor8" | "xor" => return Ok(Checksum::Xor8),
                "sum8" => return Ok(Checksum::Sum8),
                "fletcher16" | "fletcher-16" => return Ok(Checksum::Fletcher16),
                "fletcher32" | "fletcher-32" => {
                    return Ok(Checksum::Fletcher32(ByteOrder::LittleEndian))
                }
                _ => match presets::by_name(name) {
                    Some(params) => params,
                    None => {
                        let names: Vec<&str> = presets::ALL.iter().map(|p| p.name).collect();
                        return self.err(
                            key,
                            format!(
                                "unknown checksum `{name}`: expected xor8, sum8, fletcher16, \
                                 fletcher32, a CRC's parameters \
                                 {{ width, poly, init, refin, refout, xorout }}, or one of [{}] \
                                 (and the aliases CRC-16/CCITT-FALSE, CRC-32, CRC-32C)",
                                names.join(", ")
                            ),
                        );
                    }
                },
            },
            ChecksumSpec::Crc(c) => CrcParams {
                name: "CRC (description parameters)",
                width_bits: c.width,
                poly: c.poly,
                init: c.init,
                refin: c.refin,
                refout: c.refout,
                xorout: c.xorout,
            },
        };
        match Crc::new(params) {
            Ok(crc) if crc.width_bytes() * 8 == usize::from(params.width_bits) => {
                Ok(Checksum::Crc(Box::new(crc)))
            }
            Ok(_) => self.err(
                key,
                format!(
                    "a {}-bit CRC is not a whole number of octets: a frame cannot carry it",
                    params.width_bits
                ),
            ),
            Err(e) => self.err(key, e.to_string()),
        }
    }

    fn unit_factor(&self, key: &str, si: &str, unit: Option<&str>, of: &str) -> Result<f64> {
        let Some(unit) = unit else {
            return Ok(1.0);
        };
        factor_from_si(si, unit).or_else(|mismatch| match mismatch {
            UnitMismatch::Unknown => self.err(
                key,
                format!(
                    "unknown unit `{unit}`; known units: [{}]",
                    known_units().collect::<Vec<_>>().join(", ")
                ),
            ),
            UnitMismatch::Incompatible => self.err(
                key,
                format!("unit `{unit}` is incompatible with `{si}`, the unit of {of}"),
            ),
        })
    }
}

/// Builds a description read from `text`.
pub fn build(text: &str, ctx: &Context<'_>) -> Result<Built> {
    let file: DescriptionFile = toml::from_str(text).map_err(|e| DescriptionError::Syntax {
        file: ctx.file.to_owned(),
        what: "device description",
        message: e.to_string(),
    })?;
    let latency_ns = match file.output_latency_ms {
        None => 0,
        Some(ms) if ms.is_finite() && ms >= 0.0 => (ms * 1e6).round() as u64,
        Some(ms) => return ctx.err("output_latency_ms", format!("{ms}: must be ≥ 0")),
    };
    match file.protocol.as_deref().unwrap_or("binary") {
        "binary" => build_binary(file, latency_ns, ctx),
        "nmea0183" => build_nmea(file, latency_ns, ctx),
        other => ctx.err(
            "protocol",
            format!("unknown protocol `{other}`: expected `binary` or `nmea0183`"),
        ),
    }
}

fn build_nmea(file: DescriptionFile, latency_ns: u64, ctx: &Context<'_>) -> Result<Built> {
    for (key, present) in [
        ("framing", file.framing.is_some()),
        ("id", file.id.is_some()),
        ("message", !file.message.is_empty()),
        ("speed_loop", file.speed_loop.is_some()),
        ("byte_order", file.byte_order.is_some()),
    ] {
        if present {
            return ctx.err(
                key,
                "not used by protocol `nmea0183` (its framing is NMEA 0183's own)",
            );
        }
    }
    let Some(gps) = &file.gps else {
        return ctx.err(
            "gps",
            "missing: the GPS receiver's catalog group, e.g. `gps.{gps}`",
        );
    };
    let group = ctx.group("gps", gps)?;
    let field = |name: &str| {
        ctx.catalog.field_of(group, name).map_or_else(
            || {
                ctx.err(
                    "gps",
                    format!(
                        "group `{}` has no field `{name}` (a GPS group has gps_week, \
                         gps_seconds_of_week, r_be_e_m[0..2], v_be_e_m_s[0..2], valid)",
                        ctx.catalog.groups()[group].name
                    ),
                )
            },
            Ok,
        )
    };
    let channels = GpsChannels {
        group,
        gps_week: field("gps_week")?,
        gps_seconds_of_week: field("gps_seconds_of_week")?,
        r_be_e_m: [
            field("r_be_e_m[0]")?,
            field("r_be_e_m[1]")?,
            field("r_be_e_m[2]")?,
        ],
        v_be_e_m_s: [
            field("v_be_e_m_s[0]")?,
            field("v_be_e_m_s[1]")?,
            field("v_be_e_m_s[2]")?,
        ],
        valid: field("valid")?,
    };
    let talker = match &file.talker {
        None => Talker::GP,
        Some(t) => Talker::new(t).or_else(|e| ctx.err("talker", e.to_string()))?,
    };
    let hdop = file.hdop.unwrap_or(1.0);
    if !(hdop.is_finite() && hdop >= 0.0) {
        return ctx.err("hdop", format!("{hdop}: must be ≥ 0"));
    }
    if file.sentence.is_empty() {
        return ctx.err(
            "sentence",
            "no sentence: give at least one [[sentence]] (GGA, RMC, ZDA)",
        );
    }
    let mut sentences = Vec::new();
    let mut names = Vec::new();
    for (i, s) in file.sentence.iter().enumerate() {
        let Some(kind) = SentenceKind::by_name(&s.type_) else {
            return ctx.err(
                format!("sentence[{i}].type"),
                format!("unknown sentence `{}`: expected GGA, RMC or ZDA", s.type_),
            );
        };
        let period = ctx.period_ticks(&format!("sentence[{i}].every_s"), s.every_s)?;
        sentences.push((kind, period));
        names.push(s.type_.to_ascii_uppercase());
    }
    let style = NmeaStyle {
        talker,
        ..NmeaStyle::default()
    };
    Ok(Built {
        behaviour: Behaviour::Nmea(NmeaDevice::new(
            channels,
            style,
            file.satellites.unwrap_or(8),
            hdop,
            sentences,
        )),
        latency_ns,
        timeout: DEFAULT_TIMEOUT,
        message_names: names,
    })
}

fn build_binary(file: DescriptionFile, latency_ns: u64, ctx: &Context<'_>) -> Result<Built> {
    for (key, present) in [
        ("gps", file.gps.is_some()),
        ("talker", file.talker.is_some()),
        ("satellites", file.satellites.is_some()),
        ("hdop", file.hdop.is_some()),
        ("sentence", !file.sentence.is_empty()),
    ] {
        if present {
            return ctx.err(key, "only used by protocol = \"nmea0183\"");
        }
    }
    let order = ctx.order(
        "byte_order",
        file.byte_order.as_deref(),
        ByteOrder::BigEndian,
    )?;
    let Some(framing) = &file.framing else {
        return ctx.err(
            "framing",
            "missing: every binary description has a [framing]",
        );
    };
    let is_ccsds = framing.kind == "ccsds";
    let id_field = match &file.id {
        None => None,
        Some(id) => match Scalar::by_name(&id.type_) {
            Some(Scalar::Unsigned(width)) => Some(IdField { width, order }),
            _ => {
                return ctx.err(
                    "id.type",
                    format!(
                        "`{}`: the id is an unsigned integer (u8, u16, u32, u64)",
                        id.type_
                    ),
                )
            }
        },
    };
    let speed_loop = match &file.speed_loop {
        Some(spec) => Some(speed_loop(spec, ctx)?),
        None => None,
    };
    let mut messages = messages(
        &file.message,
        id_field,
        is_ccsds,
        order,
        speed_loop.as_ref(),
        ctx,
    )?;
    let max_payload = messages.iter().map(|m| m.payload_len).max().unwrap_or(0);
    let apids: Vec<u16> = messages.iter().filter_map(|m| m.apid).collect();
    let wire = wire(framing, order, max_payload, &apids, ctx)?;
    let timeout = messages
        .iter()
        .filter_map(|m| m.timeout)
        .max()
        .unwrap_or(DEFAULT_TIMEOUT);
    for m in &mut messages {
        m.decoded = vec![0.0; m.fields.len()];
    }
    let names = messages.iter().map(|m| m.name.clone()).collect();
    Ok(Built {
        behaviour: Behaviour::Binary(crate::device::binary::BinaryDevice::new(
            wire, id_field, messages, speed_loop,
        )),
        latency_ns,
        timeout,
        message_names: names,
    })
}

fn speed_loop(spec: &SpeedLoopSpec, ctx: &Context<'_>) -> Result<SpeedLoop> {
    let measured = ctx.channel("speed_loop.measured", &spec.measured)?;
    let unit = &ctx.catalog.channels()[measured].unit;
    if factor_from_si(unit, "rad/s") != Ok(1.0) {
        return ctx.err(
            "speed_loop.measured",
            format!(
                "the measured speed must be in rad/s; `{}` is in `{unit}`",
                spec.measured
            ),
        );
    }
    let torque = ctx.input("speed_loop.torque", &spec.torque)?;
    let unit = &ctx.catalog.inputs()[torque].unit;
    if factor_from_si(unit, "N m") != Ok(1.0) {
        return ctx.err(
            "speed_loop.torque",
            format!(
                "the torque input must be in N m; `{}` is in `{unit}`",
                spec.torque
            ),
        );
    }
    if !(spec.gain_nm_per_rad_s.is_finite() && spec.gain_nm_per_rad_s >= 0.0) {
        return ctx.err("speed_loop.gain_nm_per_rad_s", "must be finite and ≥ 0");
    }
    if !(spec.max_torque_nm.is_finite() && spec.max_torque_nm > 0.0) {
        return ctx.err("speed_loop.max_torque_nm", "must be finite and > 0");
    }
    Ok(SpeedLoop::new(
        measured,
        torque,
        spec.gain_nm_per_rad_s,
        spec.max_torque_nm,
    ))
}

fn wire(
    spec: &FramingSpec,
    order: ByteOrder,
    max_payload: usize,
    apids: &[u16],
    ctx: &Context<'_>,
) -> Result<Wire> {
    let check_order = ctx.order(
        "framing.checksum_order",
        spec.checksum_order.as_deref(),
        order,
    )?;
    let check = match &spec.checksum {
        Some(c) => Some(FrameCheck {
            checksum: ctx.checksum("framing.checksum", c)?,
            order: check_order,
        }),
        None => None,
    };
    let only = |allowed: &[&str]| -> Result<()> {
        for (key, present) in [
            ("sync", spec.sync.is_some()),
            ("header", spec.header.is_some()),
            ("length", spec.length.is_some()),
            ("checksum_from", spec.checksum_from.is_some()),
            ("accm", spec.accm.is_some()),
            ("secondary_header", spec.secondary_header.is_some()),
        ] {
            if present && !allowed.contains(&key) {
                return ctx.err(
                    format!("framing.{key}"),
                    format!("not used by framing `{}`", spec.kind),
                );
            }
        }
        Ok(())
    };
    match spec.kind.as_str() {
        "sync_length" => {
            only(&["sync", "header", "length", "checksum_from"])?;
            let sync = spec.sync.clone().unwrap_or_default();
            if sync.is_empty() {
                return ctx.err(
                    "framing.sync",
                    "missing or empty: a frame start is found by its sync octets",
                );
            }
            let header = spec.header.clone().unwrap_or_default();
            let Some(length) = &spec.length else {
                return ctx.err(
                    "framing.length",
                    "missing: { offset, size, counts, adjust }",
                );
            };
            if length.offset != sync.len() + header.len() {
                return ctx.err(
                    "framing.length.offset",
                    format!(
                        "{}: the length field follows the {} sync and {} header octets, \
                         at offset {}",
                        length.offset,
                        sync.len(),
                        header.len(),
                        sync.len() + header.len()
                    ),
                );
            }
            let counts = match length.counts.as_str() {
                "payload" => LengthCounts::Payload,
                "after_field" => LengthCounts::AfterField,
                "frame" => LengthCounts::WholeFrame,
                other => {
                    return ctx.err(
                        "framing.length.counts",
                        format!("`{other}`: expected `payload`, `after_field` or `frame`"),
                    )
                }
            };
            let check_len = check.as_ref().map_or(0, FrameCheck::len_bytes);
            let config = LengthFramingConfig {
                sync,
                length: LengthField {
                    offset_bytes: length.offset,
                    width_bytes: length.size,
                    order: ctx.order(
                        "framing.length.byte_order",
                        length.byte_order.as_deref(),
                        order,
                    )?,
                    counts,
                    adjust: length.adjust,
                },
                check,
                check_from_bytes: spec.checksum_from.unwrap_or(0),
                max_frame_bytes: length.offset + length.size + max_payload + check_len,
            };
            let framing =
                LengthFraming::new(config).or_else(|e| ctx.err("framing", e.to_string()))?;
            Ok(Wire::Length { framing, header })
        }
        "slip" => {
            only(&[])?;
            Ok(Wire::Slip(check))
        }
        "cobs" => {
            only(&[])?;
            Ok(Wire::Cobs(check))
        }
        "hdlc" => {
            only(&["accm"])?;
            // RFC 1662 §C: the FCS goes least significant octet first, unless told otherwise.
            let hdlc_order = ctx.order(
                "framing.checksum_order",
                spec.checksum_order.as_deref(),
                ByteOrder::LittleEndian,
            )?;
            let fcs = check.map(|c| FrameCheck {
                checksum: c.checksum,
                order: hdlc_order,
            });
            Ok(Wire::Hdlc(HdlcFraming {
                fcs,
                accm: spec.accm.unwrap_or(0xFFFF_FFFF),
            }))
        }
        "ccsds" => {
            only(&["secondary_header"])?;
            let secondary = match &spec.secondary_header {
                None => None,
                Some(s) => {
                    let (epoch, source) = match s.epoch.as_deref().unwrap_or("tai1958") {
                        "tai1958" => (CucEpoch::Tai1958, CucSource::Tai1958),
                        "met" => (CucEpoch::Agency, CucSource::Met),
                        other => {
                            return ctx.err(
                                "framing.secondary_header.epoch",
                                format!("`{other}`: expected `tai1958` or `met`"),
                            )
                        }
                    };
                    let (coarse, fine) = (s.cuc_coarse_octets, s.cuc_fine_octets);
                    let format = CucFormat::new(epoch, coarse, fine, s.p_field)
                        .or_else(|e| ctx.err("framing.secondary_header", e.to_string()))?;
                    Some((format, source))
                }
            };
            Ok(Wire::Ccsds(CcsdsFraming::new(secondary, check, apids)))
        }
        "lines" => ctx.err(
            "framing.kind",
            "`lines` carry text, not binary fields: \
             a GPS speaking NMEA 0183 is `protocol = \"nmea0183\"`",
        ),
        other => ctx.err(
            "framing.kind",
            format!("unknown framing `{other}`: expected sync_length, slip, cobs, hdlc or ccsds"),
        ),
    }
}

fn messages(
    specs: &[MessageSpec],
    id_field: Option<IdField>,
    is_ccsds: bool,
    order: ByteOrder,
    speed_loop: Option<&SpeedLoop>,
    ctx: &Context<'_>,
) -> Result<Vec<Message>> {
    if specs.is_empty() {
        return ctx.err("message", "no message: give at least one [[message]]");
    }
    let mut messages: Vec<Message> = Vec::new();
    for (i, spec) in specs.iter().enumerate() {
        let key = |k: &str| format!("message[{i}].{k}");
        if messages.iter().any(|m| m.name == spec.name) {
            return ctx.err(key("name"), format!("`{}` is used twice", spec.name));
        }
        let direction = match spec.direction.as_str() {
            "in" => Direction::In,
            "out" => Direction::Out,
            other => {
                return ctx.err(
                    key("direction"),
                    format!(
                        "`{other}`: expected `in` (driver → device) or `out` (device → driver)"
                    ),
                )
            }
        };
        match (id_field, spec.id) {
            (Some(id), Some(value)) => {
                if id.width < 8 && value >> (8 * id.width) != 0 {
                    return ctx.err(
                        key("id"),
                        format!("{value} does not fit the {}-octet id field", id.width),
                    );
                }
            }
            (Some(_), None) => {
                return ctx.err(key("id"), "missing: the description has an [id] field")
            }
            (None, Some(_)) => {
                return ctx.err(
                    key("id"),
                    "given, but the description has no [id] field (add `[id] type = \"u8\"`)",
                )
            }
            (None, None) => {}
        }
        let apid = match (is_ccsds, spec.apid) {
            (true, Some(apid)) if apid <= 0x7FF => Some(apid),
            (true, Some(apid)) => {
                return ctx.err(key("apid"), format!("{apid} is above 2047 (11 bits)"))
            }
            (true, None) => {
                return ctx.err(
                    key("apid"),
                    "missing: Space Packet framing needs each message's APID",
                )
            }
            (false, Some(_)) => return ctx.err(key("apid"), "only used with framing `ccsds`"),
            (false, None) => None,
        };
        // Frames are told apart by id (and APID) within a direction: a reply may carry its
        // request's id. Without an id field there can be one in-message (or one per APID).
        let clash = messages.iter().any(|m| {
            m.direction == direction
                && (id_field.is_none() || m.id == spec.id)
                && (apid.is_none() || m.apid == apid)
        });
        if clash && (direction == Direction::In || id_field.is_some()) {
            let what = if id_field.is_some() {
                "id"
            } else if apid.is_some() {
                "apid"
            } else {
                "direction"
            };
            return ctx.err(
                key(what),
                "another message of this direction has the same id/APID: a received frame \
                 could not be told apart (without an [id] field there can be one in-message, \
                 or one per APID)",
            );
        }
        let mut schedule = Schedule::Never;
        let (mut due_period_ticks, mut timeout) = (None, None);
        match direction {
            Direction::Out => {
                for (k, present) in [
                    ("response", spec.response.is_some()),
                    ("due_every_s", spec.due_every_s.is_some()),
                    ("timeout_ms", spec.timeout_ms.is_some()),
                ] {
                    if present {
                        return ctx.err(key(k), "only for an in-message");
                    }
                }
                schedule = match (spec.every_s, &spec.on_sample) {
                    (Some(_), Some(_)) => {
                        return ctx.err(key("every_s"), "give `every_s` or `on_sample`, not both")
                    }
                    (Some(s), None) => Schedule::Every {
                        period_ticks: ctx.period_ticks(&key("every_s"), s)?,
                    },
                    (None, Some(g)) => Schedule::OnSample {
                        group: ctx.group(&key("on_sample"), g)?,
                    },
                    (None, None) => Schedule::Never,
                };
            }
            Direction::In => {
                for (k, present) in [
                    ("every_s", spec.every_s.is_some()),
                    ("on_sample", spec.on_sample.is_some()),
                ] {
                    if present {
                        return ctx.err(key(k), "only for an out-message");
                    }
                }
                if let Some(s) = spec.due_every_s {
                    due_period_ticks = Some(ctx.period_ticks(&key("due_every_s"), s)?);
                    timeout = Some(Duration::from_millis(spec.timeout_ms.unwrap_or(1000)));
                } else if spec.timeout_ms.is_some() {
                    return ctx.err(key("timeout_ms"), "only with `due_every_s`");
                }
            }
        }
        let mut offset = id_field.map_or(0, |id| id.width);
        let mut fields = Vec::new();
        for (j, field_spec) in spec.field.iter().enumerate() {
            let field = field(
                field_spec,
                &format!("message[{i}].field[{j}]"),
                direction,
                offset,
                order,
                speed_loop,
                ctx,
            )?;
            offset += field.width();
            fields.push(field);
        }
        if offset == 0 || offset > MAX_PAYLOAD_BYTES {
            return ctx.err(
                key("field"),
                format!("the payload is {offset} octets: 1 to {MAX_PAYLOAD_BYTES} are allowed"),
            );
        }
        messages.push(Message {
            name: spec.name.clone(),
            direction,
            id: spec.id,
            apid,
            fields,
            payload_len: offset,
            schedule,
            response: None,
            due_period_ticks,
            timeout,
            count: 0,
            decoded: Vec::new(),
        });
    }
    // Responses, once every name is known.
    for (i, spec) in specs.iter().enumerate() {
        let Some(name) = &spec.response else {
            continue;
        };
        let found = messages
            .iter()
            .position(|m| &m.name == name && m.direction == Direction::Out);
        let Some(response) = found else {
            let outs: Vec<&str> = messages
                .iter()
                .filter(|m| m.direction == Direction::Out)
                .map(|m| m.name.as_str())
                .collect();
            return ctx.err(
                format!("message[{i}].response"),
                format!(
                    "`{name}` is not an out-message; out-messages: [{}]",
                    outs.join(", ")
                ),
            );
        };
        messages[i].response = Some(response);
    }
    for (i, m) in messages.iter().enumerate() {
        let answered = messages.iter().any(|r| r.response == Some(i));
        if m.direction == Direction::Out && m.schedule == Schedule::Never && !answered {
            return ctx.err(
                format!("message[{i}]"),
                format!(
                    "out-message `{}` is never sent: give `every_s`, `on_sample`, \
                     or name it as an in-message's `response`",
                    m.name
                ),
            );
        }
    }
    Ok(messages)
}

#[allow(clippy::too_many_arguments)]
fn field(
    spec: &FieldSpec,
    key: &str,
    direction: Direction,
    offset: usize,
    order: ByteOrder,
    speed_loop: Option<&SpeedLoop>,
    ctx: &Context<'_>,
) -> Result<Field> {
    let k = |name: &str| format!("{key}.{name}");
    let name = spec
        .name
        .clone()
        .unwrap_or_else(|| format!("field {offset}"));
    if let Some(bytes) = &spec.const_bytes {
        for (other, present) in [
            ("type", spec.type_.is_some()),
            ("source", spec.source.is_some()),
            ("valid", spec.valid.is_some()),
            ("value", spec.value.is_some()),
            ("dest", spec.dest.is_some()),
            ("unit", spec.unit.is_some()),
            ("scale", spec.scale.is_some()),
        ] {
            if present {
                return ctx.err(k(other), "not used with `const_bytes`");
            }
        }
        if bytes.is_empty() {
            return ctx.err(k("const_bytes"), "empty");
        }
        return Ok(Field {
            name,
            offset,
            codec: Codec::Const(bytes.clone()),
            source: Source::None,
            dest: Dest::Ignore,
        });
    }
    let Some(type_name) = &spec.type_ else {
        return ctx.err(
            k("type"),
            "missing: u8, u16, u32, u64, i8, i16, i32, i64, f32, f64 (or `const_bytes`)",
        );
    };
    let Some(scalar) = Scalar::by_name(type_name) else {
        return ctx.err(
            k("type"),
            format!(
                "unknown type `{type_name}`: \
                 expected u8, u16, u32, u64, i8, i16, i32, i64, f32 or f64"
            ),
        );
    };
    let scale = spec.scale.unwrap_or(1.0);
    if !scale.is_finite() || scale == 0.0 {
        return ctx.err(k("scale"), format!("{scale}: must be finite and not 0"));
    }
    let value_offset = spec.offset.unwrap_or(0.0);
    if !value_offset.is_finite() {
        return ctx.err(k("offset"), "must be finite");
    }
    for (bound, v) in [("min", spec.min), ("max", spec.max)] {
        if v.is_some_and(|v| !v.is_finite()) {
            return ctx.err(k(bound), "must be finite");
        }
    }
    if let (Some(lo), Some(hi)) = (spec.min, spec.max) {
        if lo > hi {
            return ctx.err(k("min"), format!("min {lo} is above max {hi}"));
        }
    }
    let order = ctx.order(&k("byte_order"), spec.byte_order.as_deref(), order)?;
    let unit = spec.unit.as_deref();
    let (source, dest, factor) = match direction {
        Direction::Out => {
            if spec.dest.is_some() {
                return ctx.err(
                    k("dest"),
                    "an out-message's field has a `source`, `valid` or `value`, not a `dest`",
                );
            }
            match (&spec.source, &spec.valid, spec.value) {
                (Some(s), None, None) if s == "counter" => {
                    if !scalar.is_integer() {
                        return ctx.err(k("type"), "a counter is an integer field");
                    }
                    (Source::Counter, Dest::Ignore, 1.0)
                }
                (Some(s), None, None) if s.starts_with("time.") => {
                    let Some((time, si)) = TimeSource::by_name(s) else {
                        let names: Vec<&str> = TimeSource::ALL.iter().map(|t| t.0).collect();
                        let problem = format!("unknown time `{s}`; times: [{}]", names.join(", "));
                        return ctx.err(k("source"), problem);
                    };
                    let factor = ctx.unit_factor(&k("unit"), si, unit, &format!("`{s}`"))?;
                    (Source::Time(time), Dest::Ignore, factor)
                }
                (Some(s), None, None) => {
                    let channel = ctx.channel(&k("source"), s)?;
                    let c = &ctx.catalog.channels()[channel];
                    let of = format!("`{}`", c.name);
                    let factor = ctx.unit_factor(&k("unit"), &c.unit, unit, &of)?;
                    (Source::Channel(channel), Dest::Ignore, factor)
                }
                (None, Some(g), None) => {
                    let group = ctx.group(&k("valid"), g)?;
                    let gr = &ctx.catalog.groups()[group];
                    let validity = Validity {
                        first_channel: gr.first_channel,
                        channel_count: gr.channel_count,
                        flag: ctx.catalog.field_of(group, "valid"),
                    };
                    let factor = ctx.unit_factor(&k("unit"), "1", unit, "a validity flag")?;
                    (Source::Valid(validity), Dest::Ignore, factor)
                }
                (None, None, Some(v)) => {
                    if !v.is_finite() {
                        return ctx.err(k("value"), "must be finite");
                    }
                    // A constant is given in the field's unit.
                    (Source::Constant(v), Dest::Ignore, 1.0)
                }
                _ => return ctx.err(
                    k("source"),
                    "an out-message's field needs exactly one of `source` (a channel, `time.…` \
                         or `counter`), `valid` (a group) or `value`",
                ),
            }
        }
        Direction::In => {
            for (other, present) in [
                ("source", spec.source.is_some()),
                ("valid", spec.valid.is_some()),
                ("value", spec.value.is_some()),
            ] {
                if present {
                    return ctx.err(
                        k(other),
                        "an in-message's field has a `dest` (or none, to be ignored)",
                    );
                }
            }
            match spec.dest.as_deref() {
                None => (Source::None, Dest::Ignore, 1.0),
                Some("speed_loop.setpoint") => {
                    if speed_loop.is_none() {
                        return ctx.err(k("dest"), "`speed_loop.setpoint` needs a [speed_loop]");
                    }
                    let factor =
                        ctx.unit_factor(&k("unit"), "rad/s", unit, "the speed setpoint")?;
                    (Source::None, Dest::SpeedSetpoint, factor)
                }
                Some(d) => {
                    let input = ctx.input(&k("dest"), d)?;
                    let i = &ctx.catalog.inputs()[input];
                    let factor =
                        ctx.unit_factor(&k("unit"), &i.unit, unit, &format!("`{}`", i.name))?;
                    (Source::None, Dest::Input(input), factor)
                }
            }
        }
    };
    Ok(Field {
        name,
        offset,
        codec: Codec::Number(Numeric {
            scalar,
            order,
            scale,
            offset: value_offset,
            factor,
            min: spec.min,
            max: spec.max,
        }),
        source,
        dest,
    })
}
