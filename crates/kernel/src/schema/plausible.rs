//! Plausibility: values that are legal but almost surely a unit slip (arcseconds typed as
//! radians, rpm as rad/s, mN·m as N·m). Each model states, beside its own parameters, the range
//! real hardware spans (from datasheets, cited there) and the units its datasheets use; a value
//! outside that range gives a warning that names the units in which it would be plausible.
//! Warnings never reject a configuration: an unusual design stays possible.

use crate::numfmt::{Num, Rounded};

/// A value that is legal but almost surely a unit slip.
#[derive(Clone, Debug, PartialEq)]
pub struct Implausible {
    /// TOML path of the value (`star_trackers[0].sigma_cross_boresight_rad`).
    pub field: String,
    /// What is implausible and, when one fits, the likely intended unit.
    pub message: String,
}

/// A unit a datasheet may give the quantity in: its name and its value in the key's SI unit.
pub type Unit = (&'static str, f64);

/// What real hardware spans for one quantity; a value beyond it gives a warning.
pub struct Range {
    /// What the quantity is, for the message (`a star tracker's noise (1σ)`).
    pub what: &'static str,
    /// The key's SI unit (`rad`).
    pub si: &'static str,
    /// \[SI\] the smallest and the largest magnitude hardware has (the model's docs say whose
    /// datasheets); the largest is where a warning starts.
    pub plausible: (f64, f64),
    /// The units the datasheets use, to suggest.
    pub units: &'static [Unit],
}

impl Range {
    /// A warning if |`value`| is above the plausible range.
    pub fn above(&self, field: String, value: f64) -> Option<Implausible> {
        (value.abs() > self.plausible.1).then(|| self.warning(field, value, "far above"))
    }

    /// A warning if 0 < |`value`| is below the plausible range (0 usually means "off").
    pub fn below(&self, field: String, value: f64) -> Option<Implausible> {
        (value != 0.0 && value.abs() < self.plausible.0)
            .then(|| self.warning(field, value, "below"))
    }

    fn warning(&self, field: String, value: f64, how: &str) -> Implausible {
        let (lo, hi) = self.plausible;
        let si = self.si;
        let mut message = format!(
            "{} {si} is {how} {} ({}–{} {si} on datasheets)",
            Num(value),
            self.what,
            Num(lo),
            Num(hi),
        );
        let fitting: Vec<&Unit> = self
            .units
            .iter()
            .filter(|(_, to_si)| (lo..=hi).contains(&(value.abs() * to_si)))
            .collect();
        if fitting.is_empty() {
            message.push_str("; check its unit");
        } else {
            let names: Vec<&str> = fitting.iter().map(|(unit, _)| *unit).collect();
            let values: Vec<String> = fitting
                .iter()
                .map(|(unit, to_si)| {
                    format!("{} {unit} = {} {si}", Num(value), Rounded(value * to_si, 5))
                })
                .collect();
            message.push_str(&format!(
                "; is it in {}? {}",
                names.join(" or "),
                values.join(", ")
            ));
        }
        Implausible { field, message }
    }
}

/// \[rad\] one degree.
pub const DEG: f64 = std::f64::consts::PI / 180.0;
/// \[rad\] one arcsecond.
pub const ARCSEC: f64 = DEG / 3600.0;
/// \[m/s²\] standard gravity, g₀ (the unit of accelerometer datasheets).
pub const G0: f64 = 9.80665;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slip_names_the_units_that_fit() {
        let r = Range {
            what: "a star tracker's noise (1σ)",
            si: "rad",
            plausible: (1e-7, 5e-3),
            units: &[("arcsec", ARCSEC), ("deg", DEG)],
        };
        let w = r.above("st.sigma".into(), 5.0).expect("5 rad warns");
        assert_eq!(
            w.message,
            "5 rad is far above a star tracker's noise (1σ) (1e-7–0.005 rad on datasheets); \
             is it in arcsec? 5 arcsec = 2.4241e-5 rad"
        );
        assert!(r.above("x".into(), 2.4e-5).is_none());
        // Nothing fits: no suggestion.
        let w = r.above("x".into(), 1e9).unwrap();
        assert!(w.message.ends_with("check its unit"), "{}", w.message);
        // Below: zero is "off", not a slip.
        assert!(r.below("x".into(), 0.0).is_none());
        assert!(r.below("x".into(), 1e-8).is_some());
    }
}
