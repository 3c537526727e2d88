//! A sentence reader: checks the envelope (`$`, printable ASCII, `*hh` matching the XOR of the
//! characters, optional CR LF) and splits the fields; [`Sentence::expect_fields`] checks the
//! field count of GGA, RMC and ZDA, and [`Sentence::angle_deg`] reads a latitude or longitude
//! back into degrees. It allocates the field list: for tests and tools, not for a real-time
//! path.

use super::NmeaError;
use crate::checksum::sums::xor8;

/// A sentence that passed the envelope checks.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sentence<'a> {
    /// The talker id (`GP`).
    pub talker: &'a str,
    /// The sentence formatter (`GGA`).
    pub formatter: &'a str,
    /// The fields after the address, in order (empty fields as `""`).
    pub fields: Vec<&'a str>,
}

impl<'a> Sentence<'a> {
    /// Parses `line` (with or without its CR LF).
    pub fn parse(line: &'a str) -> Result<Self, NmeaError> {
        let text = line
            .strip_suffix("\r\n")
            .or_else(|| line.strip_suffix('\n'))
            .unwrap_or(line);
        if let Some(position) = text.bytes().position(|b| !(0x20..=0x7E).contains(&b)) {
            return Err(NmeaError::NotPrintable { position });
        }
        let body = text
            .strip_prefix('$')
            .ok_or_else(|| NmeaError::NoDollar(text.to_owned()))?;
        let (content, digits) = body
            .rsplit_once('*')
            .ok_or_else(|| NmeaError::NoChecksum(text.to_owned()))?;
        // Exactly two hex digits (`from_str_radix` alone would take "+F").
        let stated = match u8::from_str_radix(digits, 16) {
            Ok(value) if digits.len() == 2 && digits.bytes().all(|b| b.is_ascii_hexdigit()) => {
                value
            }
            _ => return Err(NmeaError::ChecksumDigits(digits.to_owned())),
        };
        let computed = xor8(content.as_bytes());
        if computed != stated {
            return Err(NmeaError::ChecksumMismatch { stated, computed });
        }
        let mut parts = content.split(',');
        let address = parts.next().unwrap_or_default();
        if address.len() != 5 {
            return Err(NmeaError::Address(address.to_owned()));
        }
        let (talker, formatter) = address.split_at(2);
        Ok(Self {
            talker,
            formatter,
            fields: parts.collect(),
        })
    }

    /// Checks the field count of the known formatters: GGA 14, RMC 11 (before NMEA 2.3) or 12,
    /// ZDA 6. Other formatters pass.
    pub fn expect_fields(&self) -> Result<(), NmeaError> {
        let (allowed, expected): (&[usize], &'static str) = match self.formatter {
            "GGA" => (&[14], "14"),
            "RMC" => (&[11, 12], "11 or 12"),
            "ZDA" => (&[6], "6"),
            _ => return Ok(()),
        };
        if allowed.contains(&self.fields.len()) {
            Ok(())
        } else {
            Err(NmeaError::FieldCount {
                formatter: self.formatter.to_owned(),
                expected,
                got: self.fields.len(),
            })
        }
    }

    /// Field `index` (0-based, after the address), or `""` if absent.
    pub fn field(&self, index: usize) -> &'a str {
        self.fields.get(index).copied().unwrap_or_default()
    }

    /// Field `index` as a number.
    pub fn number(&self, index: usize) -> Result<f64, NmeaError> {
        let text = self.field(index);
        text.parse().map_err(|_| NmeaError::Field {
            index,
            text: text.to_owned(),
            what: "number",
        })
    }

    /// The angle of `d…dmm.m…` at `index` and its hemisphere letter at `index + 1` (`S` and
    /// `W` negative), in degrees.
    pub fn angle_deg(&self, index: usize) -> Result<f64, NmeaError> {
        let text = self.field(index);
        let bad = || NmeaError::Field {
            index,
            text: text.to_owned(),
            what: "ddmm.mmmm angle",
        };
        let point = text.find('.').unwrap_or(text.len());
        let split = point.checked_sub(2).ok_or_else(bad)?;
        let degrees: f64 = text[..split].parse().map_err(|_| bad())?;
        let minutes: f64 = text[split..].parse().map_err(|_| bad())?;
        let magnitude = degrees + minutes / 60.0;
        match self.field(index + 1) {
            "N" | "E" => Ok(magnitude),
            "S" | "W" => Ok(-magnitude),
            other => Err(NmeaError::Field {
                index: index + 1,
                text: other.to_owned(),
                what: "hemisphere (N, S, E, W)",
            }),
        }
    }
}
