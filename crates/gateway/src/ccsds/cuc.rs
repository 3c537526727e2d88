//! The CCSDS Unsegmented time Code, CUC (CCSDS 301.0-B-4 §3.2): a binary count of seconds
//! since an epoch (the coarse time, 1 to 4 octets) and of fractions of a second (the fine
//! time, 0 to 3 octets, in units of 2^(−8·fine octets) s), most significant octet first,
//! optionally preceded by its one-octet P-field:
//!
//! ```text
//! bit 0     extension flag (0: no second P-field octet; extensions are not written here)
//! bits 1–3  time code identification: 001 = epoch 1958-01-01 TAI (level 1),
//!                                     010 = agency-defined epoch (level 2)
//! bits 4–5  coarse time octets − 1
//! bits 6–7  fine time octets
//! ```
//!
//! The fine time is the fraction of the second truncated to its unit (a clock's count of whole
//! ticks): fine = ⌊ns_of_second · 2^(8·n) / 10⁹⌋.

use super::CcsdsError;

/// Nanoseconds per second.
const NS_PER_S: u64 = 1_000_000_000;

/// The epoch the time code counts from (P-field bits 1–3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CucEpoch {
    /// Level 1: 1958 January 1, TAI (code 001).
    Tai1958,
    /// Level 2: an epoch the agency defines (code 010).
    Agency,
}

/// The layout of a CUC time code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CucFormat {
    epoch: CucEpoch,
    coarse_octets: u8,
    fine_octets: u8,
    with_p_field: bool,
}

/// A decoded time code: whole seconds and fine-time units since the epoch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CucTime {
    /// Whole seconds since the epoch.
    pub coarse_s: u64,
    /// Fraction of the second in units of 2^(−8·fine octets) s.
    pub fine: u32,
    /// Fine time octets (the unit of `fine`).
    pub fine_octets: u8,
}

impl CucTime {
    /// Nanoseconds since the epoch, the fraction truncated to whole nanoseconds.
    pub fn to_ns(&self) -> u128 {
        let fraction_ns =
            (u128::from(self.fine) * u128::from(NS_PER_S)) >> (8 * u32::from(self.fine_octets));
        u128::from(self.coarse_s) * u128::from(NS_PER_S) + fraction_ns
    }
}

impl CucFormat {
    /// A layout of 1–4 coarse octets and 0–3 fine octets (the basic time unit without a
    /// P-field extension), with or without the P-field in the time code.
    pub fn new(
        epoch: CucEpoch,
        coarse_octets: u8,
        fine_octets: u8,
        with_p_field: bool,
    ) -> Result<Self, CcsdsError> {
        if !(1..=4).contains(&coarse_octets) {
            return Err(CcsdsError::CoarseOctets {
                octets: coarse_octets,
            });
        }
        if fine_octets > 3 {
            return Err(CcsdsError::FineOctets {
                octets: fine_octets,
            });
        }
        Ok(Self {
            epoch,
            coarse_octets,
            fine_octets,
            with_p_field,
        })
    }

    /// The layout a P-field octet describes (the time code then carries it).
    pub fn from_p_field(p_field: u8) -> Result<Self, CcsdsError> {
        if p_field & 0x80 != 0 {
            return Err(CcsdsError::PField {
                p_field,
                reason: "extension octet not supported",
            });
        }
        let epoch = match (p_field >> 4) & 0b111 {
            0b001 => CucEpoch::Tai1958,
            0b010 => CucEpoch::Agency,
            _ => {
                return Err(CcsdsError::PField {
                    p_field,
                    reason: "time code id is not CUC (001 or 010)",
                })
            }
        };
        Self::new(epoch, ((p_field >> 2) & 0b11) + 1, p_field & 0b11, true)
    }

    /// The P-field octet.
    pub fn p_field(&self) -> u8 {
        let id = match self.epoch {
            CucEpoch::Tai1958 => 0b001,
            CucEpoch::Agency => 0b010,
        };
        (id << 4) | ((self.coarse_octets - 1) << 2) | self.fine_octets
    }

    /// Octets of the time code (P-field included if carried).
    pub fn len_bytes(&self) -> usize {
        usize::from(self.with_p_field)
            + usize::from(self.coarse_octets)
            + usize::from(self.fine_octets)
    }

    /// Appends the time code of `time_ns` nanoseconds since the epoch. Nothing is appended on
    /// error (a time before the epoch or beyond the coarse time's range).
    pub fn encode(&self, time_ns: i64, out: &mut Vec<u8>) -> Result<(), CcsdsError> {
        let ns = u64::try_from(time_ns).map_err(|_| CcsdsError::NegativeTime { time_ns })?;
        let seconds = ns / NS_PER_S;
        let coarse_bits = 8 * u32::from(self.coarse_octets);
        if seconds >> coarse_bits != 0 {
            return Err(CcsdsError::CoarseOverflow {
                seconds,
                octets: self.coarse_octets,
            });
        }
        let fine_bits = 8 * u32::from(self.fine_octets);
        let fine = (u128::from(ns % NS_PER_S) << fine_bits) / u128::from(NS_PER_S);
        if self.with_p_field {
            out.push(self.p_field());
        }
        out.extend_from_slice(&seconds.to_be_bytes()[8 - usize::from(self.coarse_octets)..]);
        out.extend_from_slice(&(fine as u32).to_be_bytes()[4 - usize::from(self.fine_octets)..]);
        Ok(())
    }

    /// Reads a time code of this layout from the start of `octets`. With a P-field, the
    /// octet read must be this layout's.
    pub fn decode(&self, octets: &[u8]) -> Result<CucTime, CcsdsError> {
        if octets.len() < self.len_bytes() {
            return Err(CcsdsError::TooShort {
                what: "a CUC time code",
                needed_bytes: self.len_bytes(),
                got_bytes: octets.len(),
            });
        }
        let mut rest = octets;
        if self.with_p_field {
            let p_field = rest[0];
            if p_field != self.p_field() {
                return Err(CcsdsError::PField {
                    p_field,
                    reason: "not the layout expected",
                });
            }
            rest = &rest[1..];
        }
        let (coarse, rest) = rest.split_at(usize::from(self.coarse_octets));
        let fine = &rest[..usize::from(self.fine_octets)];
        let be = |octets: &[u8]| {
            octets
                .iter()
                .fold(0u64, |acc, &b| (acc << 8) | u64::from(b))
        };
        Ok(CucTime {
            coarse_s: be(coarse),
            fine: be(fine) as u32,
            fine_octets: self.fine_octets,
        })
    }
}
