//! The Earth's albedo as an environment model ([`crate::model::part`]): `albedo` of the sample,
//! the visible cap discretised ((A3)–(A6) of [`super`]).

use super::schema;
use super::{Albedo, AlbedoCap};
use crate::epoch::SimEpoch;
use crate::model::part::{f, At, EnvironmentPart};
use crate::model::{EnvironmentBuildError, EnvironmentSettings, ModelsOn};
use crate::{EnvironmentSample, ModelSettings};
use flexdyn_kernel::archive::Archive;
use flexdyn_kernel::schema::{SchemaError, TableReader};
use nalgebra::Vector3;

impl EnvironmentPart for Albedo {
    /// The coefficient a when on.
    type Settings = Option<f64>;
    const KEYS: &'static [&'static str] = &schema::KEYS;
    /// Whether there is a cap, then its words.
    const WORDS: usize = 1 + AlbedoCap::WORDS;
    const IRRADIANCE_USER: Option<&'static str> = Some("albedo = \"lambertian\"");

    fn read(t: &TableReader<'_, '_>, before: &ModelSettings) -> Result<Option<f64>, SchemaError> {
        schema::read(t, &before.ephemeris)
    }

    fn uses_irradiance(settings: &Option<f64>) -> bool {
        settings.is_some()
    }

    /// The sphere is the shadow's, the irradiance the one solar pressure uses.
    fn build(
        settings: &Option<f64>,
        all: &EnvironmentSettings,
        _: &SimEpoch,
    ) -> Result<Option<Self>, EnvironmentBuildError> {
        Ok(settings.map(|coefficient| Albedo {
            coefficient,
            earth_radius_m: all.models.shadow.earth_radius_m,
            irradiance_1au_w_m2: all.solar_irradiance_1au_w_m2,
        }))
    }

    fn fill(&self, at: &At<'_>, out: &mut EnvironmentSample) {
        if let Some(r_sun_n_m) = &at.r_sun_n_m {
            out.albedo = self.cap(at.r_bn_n_m, r_sun_n_m);
        }
    }

    fn models_on(&self, on: &mut ModelsOn) {
        on.set("albedo");
    }

    /// The cap's words only when there is one, so that without albedo the prefetch slot moves
    /// one word for it.
    fn to_words(s: &EnvironmentSample, w: &mut [u64]) -> usize {
        w[0] = u64::from(s.albedo.is_some());
        match &s.albedo {
            Some(cap) => {
                let mut x = [0.0; AlbedoCap::WORDS];
                cap.to_words(&mut x);
                for (o, x) in w[1..Self::WORDS].iter_mut().zip(x) {
                    *o = x.to_bits();
                }
                Self::WORDS
            }
            None => 1,
        }
    }

    fn from_words(w: &[u64], s: &mut EnvironmentSample) -> usize {
        if w[0] == 0 {
            s.albedo = None;
            return 1;
        }
        s.albedo = Some(AlbedoCap::from_words(&std::array::from_fn(|i| f(w, 1 + i))));
        Self::WORDS
    }

    fn archive(s: &mut EnvironmentSample, a: &mut Archive<'_>) {
        let albedo = &mut s.albedo;
        let mut has_albedo = albedo.is_some();
        a.put(&mut has_albedo);
        if has_albedo {
            let cap = albedo.get_or_insert(AlbedoCap {
                nadir_n: Vector3::zeros(),
                x_n: Vector3::zeros(),
                y_n: Vector3::zeros(),
                cos_eta: [0.0; super::ALBEDO_RINGS],
                sin_eta: [0.0; super::ALBEDO_RINGS],
                weight: [0.0; super::ALBEDO_ELEMENTS],
                solar_irradiance_w_m2: 0.0,
            });
            // Named field by field: a new field does not compile until it is listed here.
            let AlbedoCap {
                nadir_n,
                x_n,
                y_n,
                cos_eta,
                sin_eta,
                weight,
                solar_irradiance_w_m2,
            } = cap;
            a.put(nadir_n);
            a.put(x_n);
            a.put(y_n);
            a.put(cos_eta);
            a.put(sin_eta);
            a.put(weight);
            a.put(solar_irradiance_w_m2);
        } else {
            *albedo = None;
        }
    }
}
