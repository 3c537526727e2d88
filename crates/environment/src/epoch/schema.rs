//! The `[epoch]` schema. Keys are checked by the shared reader ([`flexdyn_kernel::schema`]); the
//! date-time and the Earth orientation parameters by [`RawEpoch::build`].
//!
//! ```toml
//! [epoch]
//! utc = "2026-03-20T12:00:00Z"     # or: tai = "2026-03-20T12:00:37" (exactly one of the two)
//! ut1_minus_utc_s = -0.0123        # optional, IERS Bulletin A; default 0 (UT1 ≈ UTC, ≤ 0.9 s)
//! polar_motion_x_arcsec = 0.1234   # optional, IERS Bulletin A; default 0
//! polar_motion_y_arcsec = 0.3456   # optional, IERS Bulletin A; default 0
//! offset_s = 0.0                   # optional: seconds added to the date-time (SI, along TAI);
//!                                  # a campaign disperses it to move a run through the year
//! ```
//!
//! The date-time may be a TOML string or a bare TOML datetime; a UTC one ends with `Z`, a TAI
//! one has no zone. Up to nine fractional digits; `23:59:60` is accepted on a day that ends
//! with a leap second.

use toml::de::DeValue;

use super::{EarthOrientationParams, EpochError, EpochScale, SimEpoch, RAD_PER_ARCSEC};
use flexdyn_kernel::schema::{SchemaError, TableReader};

/// The keys of `[epoch]`.
pub const KEYS: [&str; 6] = [
    "utc",
    "tai",
    "ut1_minus_utc_s",
    "polar_motion_x_arcsec",
    "polar_motion_y_arcsec",
    "offset_s",
];

/// `[epoch]` as written.
#[derive(Debug, Clone, PartialEq)]
pub struct RawEpoch {
    /// The date-time text.
    pub text: String,
    /// Which key gave it.
    pub scale: EpochScale,
    /// TOML path of that key (`epoch.utc` or `epoch.tai`).
    pub field: String,
    /// \[s\] `ut1_minus_utc_s` (0 if absent).
    pub ut1_minus_utc_s: f64,
    /// \[arcsec\] `polar_motion_x_arcsec` (0 if absent).
    pub polar_motion_x_arcsec: f64,
    /// \[arcsec\] `polar_motion_y_arcsec` (0 if absent).
    pub polar_motion_y_arcsec: f64,
    /// \[s\] `offset_s` (0 if absent).
    pub offset_s: f64,
    /// TOML path of `offset_s`.
    pub offset_field: String,
}

/// A string or a TOML datetime at `key`, as text.
fn date_time_text(t: &TableReader<'_, '_>, key: &str) -> Result<Option<String>, SchemaError> {
    match t.get(key).map(|v| v.get_ref()) {
        None => Ok(None),
        Some(DeValue::Datetime(d)) => Ok(Some(d.to_string())),
        // A string, or the reader's typed error for anything else.
        Some(_) => t.string(key).map(Some),
    }
}

/// Reads `[epoch]` (opened with [`KEYS`]).
pub fn read(t: &TableReader<'_, '_>) -> Result<RawEpoch, SchemaError> {
    let utc = date_time_text(t, "utc")?;
    let tai = date_time_text(t, "tai")?;
    let (text, scale, key) = match (utc, tai) {
        (Some(s), None) => (s, EpochScale::Utc, "utc"),
        (None, Some(s)) => (s, EpochScale::Tai, "tai"),
        (Some(_), Some(_)) => {
            return Err(SchemaError::InvalidValue {
                field: t.field("tai"),
                message: format!(
                    "give the epoch once: either `{}` or `{}`, not both",
                    t.field("utc"),
                    t.field("tai")
                ),
                at: flexdyn_kernel::schema::At(None),
            })
        }
        (None, None) => {
            return Err(SchemaError::MissingKey {
                field: format!("{} (or {})", t.field("utc"), t.field("tai")),
                at: flexdyn_kernel::schema::At(None),
            })
        }
    };
    Ok(RawEpoch {
        text,
        scale,
        field: t.field(key),
        ut1_minus_utc_s: t.opt_f64("ut1_minus_utc_s")?.unwrap_or(0.0),
        polar_motion_x_arcsec: t.opt_f64("polar_motion_x_arcsec")?.unwrap_or(0.0),
        polar_motion_y_arcsec: t.opt_f64("polar_motion_y_arcsec")?.unwrap_or(0.0),
        offset_s: t.opt_f64("offset_s")?.unwrap_or(0.0),
        offset_field: t.field("offset_s"),
    })
}

impl RawEpoch {
    /// Validates the date-time and the Earth orientation parameters.
    pub fn build(&self) -> Result<SimEpoch, EpochError> {
        let eop = EarthOrientationParams {
            ut1_minus_utc_s: self.ut1_minus_utc_s,
            polar_motion_x_rad: self.polar_motion_x_arcsec * RAD_PER_ARCSEC,
            polar_motion_y_rad: self.polar_motion_y_arcsec * RAD_PER_ARCSEC,
        };
        let epoch = SimEpoch::parse(&self.text, self.scale, eop, &self.field)?;
        if self.offset_s == 0.0 {
            return Ok(epoch);
        }
        epoch.offset_by(self.offset_s, &self.offset_field)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_str(src: &str) -> Result<RawEpoch, SchemaError> {
        let doc = toml::de::DeTable::parse(src).unwrap();
        let root = TableReader::root(src, doc.get_ref(), &["epoch"]).unwrap();
        let t = root.table("epoch", &KEYS)?;
        read(&t)
    }

    #[test]
    fn string_or_datetime() {
        let a = read_str("[epoch]\nutc = \"2026-03-20T12:00:00Z\"\n").unwrap();
        let b = read_str("[epoch]\nutc = 2026-03-20T12:00:00Z\n").unwrap();
        assert_eq!(a.build().unwrap(), b.build().unwrap());
        let c = read_str("[epoch]\ntai = 2026-03-20T12:00:37\nut1_minus_utc_s = 0.1\n").unwrap();
        assert_eq!(c.field, "epoch.tai");
        assert_eq!(c.build().unwrap().tai_ns(0), a.build().unwrap().tai_ns(0));
    }

    #[test]
    fn offset_moves_the_epoch_and_bad_offsets_name_the_field() {
        let base = read_str("[epoch]\nutc = \"2026-03-20T12:00:00Z\"\n").unwrap();
        let day = read_str("[epoch]\nutc = \"2026-03-20T12:00:00Z\"\noffset_s = 86400.5\n")
            .unwrap()
            .build()
            .unwrap();
        assert_eq!(
            day.tai_ns(0) - base.build().unwrap().tai_ns(0),
            86_400_500_000_000
        );
        assert_eq!(day.offset_s(), 86400.5);
        assert_eq!(day.utc_iso(), "2026-03-21T12:00:00.500000000Z");
        for (offset, problem) in [("1e10", "within ±3.2e9 s"), ("-2e9", "outside 1972-01-01")] {
            let e = read_str(&format!(
                "[epoch]\nutc = \"2026-03-20T12:00:00Z\"\noffset_s = {offset}\n"
            ))
            .unwrap()
            .build()
            .unwrap_err()
            .to_string();
            assert!(e.starts_with("epoch.offset_s: "), "{e}");
            assert!(e.contains(problem), "{e}");
        }
    }

    #[test]
    fn exactly_one_scale() {
        let e =
            read_str("[epoch]\nutc = \"2026-03-20T12:00:00Z\"\ntai = \"2026-03-20T12:00:37\"\n")
                .unwrap_err();
        assert!(e.to_string().starts_with("epoch.tai: "), "{e}");
        let e = read_str("[epoch]\nut1_minus_utc_s = 0.1\n").unwrap_err();
        assert!(e.to_string().contains("epoch.utc (or epoch.tai)"), "{e}");
        let e = read_str("[epoch]\nutc = 5\n").unwrap_err();
        assert!(e.to_string().contains("expected a string"), "{e}");
        let e = read_str("[epoch]\nutx = \"x\"\n").unwrap_err();
        assert!(e.to_string().contains("did you mean `utc`"), "{e}");
    }

    #[test]
    fn semantic_errors_name_the_field() {
        let r = read_str("[epoch]\nutc = \"2026-03-20T12:00:00Z\"\npolar_motion_y_arcsec = 3\n")
            .unwrap();
        let e = r.build().unwrap_err();
        assert!(
            e.to_string().starts_with("epoch.polar_motion_y_arcsec: "),
            "{e}"
        );
        let r = read_str("[epoch]\nutc = \"2026-03-20 12:00:00+02:00\"\n").unwrap();
        let e = r.build().unwrap_err();
        assert!(e.to_string().starts_with("epoch.utc: "), "{e}");
    }
}
