//! The shadow as an environment model ([`crate::model::part`]): `shadow_factor` of the sample.

use super::schema::{self, ShadowSetting};
use super::ShadowGeometry;
use crate::epoch::SimEpoch;
use crate::model::part::{f, At, EnvironmentPart};
use crate::model::{EnvironmentBuildError, EnvironmentSettings, ModelsOn};
use crate::{EnvironmentSample, ModelSettings};
use flexdyn_kernel::archive::Archive;
use flexdyn_kernel::schema::{SchemaError, TableReader};

impl EnvironmentPart for ShadowGeometry {
    type Settings = ShadowSetting;
    const KEYS: &'static [&'static str] = &schema::KEYS;
    const WORDS: usize = 1;

    fn read(t: &TableReader<'_, '_>, before: &ModelSettings) -> Result<ShadowSetting, SchemaError> {
        schema::read(t, &before.ephemeris)
    }

    fn needs_epoch(settings: &ShadowSetting) -> Option<&'static str> {
        settings.model.map(|_| "shadow")
    }

    fn build(
        settings: &ShadowSetting,
        _: &EnvironmentSettings,
        _: &SimEpoch,
    ) -> Result<Option<Self>, EnvironmentBuildError> {
        Ok(settings.model.map(|model| ShadowGeometry {
            model,
            earth_radius_m: settings.earth_radius_m,
            sun_radius_m: settings.sun_radius_m,
        }))
    }

    fn fill(&self, at: &At<'_>, out: &mut EnvironmentSample) {
        if let Some(r_sun_n_m) = &at.r_sun_n_m {
            out.shadow_factor = self.factor(at.r_bn_n_m, r_sun_n_m);
        }
    }

    fn models_on(&self, on: &mut ModelsOn) {
        on.set("shadow");
    }

    fn to_words(s: &EnvironmentSample, w: &mut [u64]) -> usize {
        w[0] = s.shadow_factor.to_bits();
        1
    }

    fn from_words(w: &[u64], s: &mut EnvironmentSample) -> usize {
        s.shadow_factor = f(w, 0);
        1
    }

    fn archive(s: &mut EnvironmentSample, a: &mut Archive<'_>) {
        a.put(&mut s.shadow_factor);
    }
}
