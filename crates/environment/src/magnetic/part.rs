//! The magnetic field as an environment model ([`crate::model::part`]): `b_field_n_t` of the
//! sample, the planet's field at B rotated from the Earth-fixed frame to N.

use super::schema::{self, MagneticSetting};
use super::{CentredDipole, Igrf};
use crate::epoch::SimEpoch;
use crate::model::part::{put_v3, v3, At, EnvironmentPart, Needs};
use crate::model::{EnvironmentBuildError, EnvironmentSettings, ModelsOn};
use crate::{EnvironmentSample, ModelSettings};
use flexdyn_kernel::archive::Archive;
use flexdyn_kernel::schema::{SchemaError, TableReader};

/// The magnetic field, built.
#[derive(Debug, Clone)]
pub enum MagneticField {
    /// IGRF-14 to its degree, at the sample's decimal year.
    Igrf(Box<Igrf>),
    /// A centred dipole (IGRF's degree 1 at the epoch, or given).
    Dipole(CentredDipole),
}

impl EnvironmentPart for MagneticField {
    type Settings = MagneticSetting;
    const KEYS: &'static [&'static str] = &schema::KEYS;
    const WORDS: usize = 3;

    fn read(t: &TableReader<'_, '_>, _: &ModelSettings) -> Result<MagneticSetting, SchemaError> {
        schema::read(t)
    }

    fn needs_epoch(settings: &MagneticSetting) -> Option<&'static str> {
        (*settings != MagneticSetting::Off).then_some("magnetic")
    }

    fn build(
        settings: &MagneticSetting,
        _: &EnvironmentSettings,
        epoch: &SimEpoch,
    ) -> Result<Option<Self>, EnvironmentBuildError> {
        let year = epoch.utc_calendar(0).decimal_year();
        Ok(match *settings {
            MagneticSetting::Off => None,
            MagneticSetting::Igrf14 { degree } => {
                let igrf = Igrf::igrf14(degree)?;
                igrf.check_date(year)?;
                Some(Self::Igrf(Box::new(igrf)))
            }
            MagneticSetting::GivenDipole(d) => Some(Self::Dipole(d)),
            MagneticSetting::Dipole { tilted } => {
                let igrf = Igrf::igrf14(1)?;
                igrf.check_date(year)?;
                let c = igrf.coefficients_at(year);
                Some(Self::Dipole(if tilted {
                    CentredDipole::tilted(&c)
                } else {
                    CentredDipole::axial(&c)
                }))
            }
        })
    }

    fn needs(&self) -> Needs {
        Needs {
            frame: true,
            ..Needs::default()
        }
    }

    fn fill(&self, at: &At<'_>, out: &mut EnvironmentSample) {
        let b_e_t = match self {
            Self::Igrf(igrf) => {
                let year = at.epoch.utc_calendar(at.t_sim_ns).decimal_year();
                igrf.field_ecef_t(year, &at.r_e_m)
            }
            Self::Dipole(d) => d.field_ecef_t(&at.r_e_m),
        };
        out.b_field_n_t = at.earth.dcm_en.tr_mul(&b_e_t);
    }

    fn models_on(&self, on: &mut ModelsOn) {
        on.set("magnetic");
    }

    fn to_words(s: &EnvironmentSample, w: &mut [u64]) -> usize {
        put_v3(w, 0, &s.b_field_n_t);
        3
    }

    fn from_words(w: &[u64], s: &mut EnvironmentSample) -> usize {
        s.b_field_n_t = v3(w, 0);
        3
    }

    fn archive(s: &mut EnvironmentSample, a: &mut Archive<'_>) {
        a.put(&mut s.b_field_n_t);
    }
}
