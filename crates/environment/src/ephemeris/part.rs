//! The Sun and the Moon as an environment model ([`crate::model::part`]): `r_sun_b_n_m` and
//! `r_moon_b_n_m` of the sample. Their geocentric positions come from the update's shared part
//! ([`crate::common`]: one evaluation per instant for a world's vehicles), and the Sun's is an
//! input of the models that need sunlight ([`At::r_sun_n_m`]: the shadow, the albedo).

use nalgebra::Vector3;

use super::schema::{self, EphemerisSetting};
use crate::epoch::SimEpoch;
use crate::model::part::{put_v3, v3, At, EnvironmentPart, Needs};
use crate::model::{EnvironmentBuildError, EnvironmentSettings, ModelsOn};
use crate::{EnvironmentSample, ModelSettings};
use flexdyn_kernel::archive::Archive;
use flexdyn_kernel::schema::{SchemaError, TableReader};

/// The Sun and the Moon, built (at least one of them on).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ephemeris(pub EphemerisSetting);

impl Ephemeris {
    /// \[m\] the Sun's geocentric position, N components, given the ephemeris' (`None` when
    /// the Sun is off; a fixed Sun when configured).
    pub fn sun_n_m(&self, ephemeris_n_m: &Vector3<f64>) -> Option<Vector3<f64>> {
        self.0
            .sun
            .then(|| self.0.sun_fixed_n_m.unwrap_or(*ephemeris_n_m))
    }
}

impl EnvironmentPart for Ephemeris {
    type Settings = EphemerisSetting;
    const KEYS: &'static [&'static str] = &schema::KEYS;
    const WORDS: usize = 6;

    fn read(t: &TableReader<'_, '_>, _: &ModelSettings) -> Result<EphemerisSetting, SchemaError> {
        schema::read(t)
    }

    fn needs_epoch(settings: &EphemerisSetting) -> Option<&'static str> {
        if settings.sun {
            Some("sun")
        } else if settings.moon {
            Some("moon")
        } else {
            None
        }
    }

    fn build(
        settings: &EphemerisSetting,
        _: &EnvironmentSettings,
        _: &SimEpoch,
    ) -> Result<Option<Self>, EnvironmentBuildError> {
        Ok((settings.sun || settings.moon).then_some(Self(*settings)))
    }

    fn needs(&self) -> Needs {
        Needs {
            frame: false,
            sun_ephemeris: self.0.sun && self.0.sun_fixed_n_m.is_none(),
            moon_ephemeris: self.0.moon,
        }
    }

    fn fill(&self, at: &At<'_>, out: &mut EnvironmentSample) {
        if let Some(r_sun_n_m) = &at.r_sun_n_m {
            out.r_sun_b_n_m = r_sun_n_m - at.r_bn_n_m;
        }
        if self.0.moon {
            out.r_moon_b_n_m = at.r_moon_n_m - at.r_bn_n_m;
        }
    }

    fn models_on(&self, on: &mut ModelsOn) {
        if self.0.sun {
            on.set("sun");
        }
        if self.0.moon {
            on.set("moon");
        }
    }

    fn to_words(s: &EnvironmentSample, w: &mut [u64]) -> usize {
        put_v3(w, 0, &s.r_sun_b_n_m);
        put_v3(w, 3, &s.r_moon_b_n_m);
        6
    }

    fn from_words(w: &[u64], s: &mut EnvironmentSample) -> usize {
        s.r_sun_b_n_m = v3(w, 0);
        s.r_moon_b_n_m = v3(w, 3);
        6
    }

    fn archive(s: &mut EnvironmentSample, a: &mut Archive<'_>) {
        a.put(&mut s.r_sun_b_n_m);
        a.put(&mut s.r_moon_b_n_m);
    }
}
