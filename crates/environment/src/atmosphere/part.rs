//! The atmosphere as an environment model ([`crate::model::part`]): `density_kg_m3` and
//! `wind_n_m_s` of the sample.

use super::schema::{self, AirSetting, AtmosphereSetting};
use super::{AltitudeDefinition, ExponentialAtmosphere, Nrlmsise00Model};
use crate::epoch::SimEpoch;
use crate::geodetic::geodetic_from_ecef;
use crate::model::part::{f, put_v3, v3, At, EnvironmentPart, Needs};
use crate::model::{EnvironmentBuildError, EnvironmentSettings, ModelsOn};
use crate::{EnvironmentSample, ModelSettings};
use flexdyn_kernel::archive::Archive;
use flexdyn_kernel::schema::{SchemaError, TableReader};

/// The density model, built.
#[derive(Debug, Clone)]
pub enum Air {
    /// Exponential (Vallado's bands or one band).
    Exponential(ExponentialAtmosphere),
    /// NRLMSISE-00 with constant space weather.
    Nrlmsise00(Nrlmsise00Model),
}

/// The atmosphere, built: its density model and whether it co-rotates.
#[derive(Debug, Clone)]
pub struct Atmosphere {
    /// The density model.
    pub air: Air,
    /// Co-rotating with the Earth (Vallado §8.6.2), or still air in N.
    pub corotating_wind: bool,
}

impl EnvironmentPart for Atmosphere {
    type Settings = AirSetting;
    const KEYS: &'static [&'static str] = &schema::KEYS;
    const WORDS: usize = 4;

    fn read(t: &TableReader<'_, '_>, _: &ModelSettings) -> Result<AirSetting, SchemaError> {
        schema::read(t)
    }

    fn needs_epoch(settings: &AirSetting) -> Option<&'static str> {
        (settings.atmosphere != AtmosphereSetting::Off).then_some("atmosphere")
    }

    fn build(
        settings: &AirSetting,
        _: &EnvironmentSettings,
        _: &SimEpoch,
    ) -> Result<Option<Self>, EnvironmentBuildError> {
        let air = match settings.atmosphere {
            AtmosphereSetting::Off => return Ok(None),
            AtmosphereSetting::Exponential(e) => Air::Exponential(e),
            AtmosphereSetting::Nrlmsise00(w) => Air::Nrlmsise00(Nrlmsise00Model::new(w)?),
        };
        Ok(Some(Self {
            air,
            corotating_wind: settings.corotating_wind,
        }))
    }

    fn needs(&self) -> Needs {
        let frame = match &self.air {
            Air::Exponential(e) => {
                self.corotating_wind || e.altitude == AltitudeDefinition::Geodetic
            }
            Air::Nrlmsise00(_) => true,
        };
        Needs {
            frame,
            ..Needs::default()
        }
    }

    fn fill(&self, at: &At<'_>, out: &mut EnvironmentSample) {
        out.density_kg_m3 = match &self.air {
            Air::Exponential(e) => {
                let altitude_m = match e.altitude {
                    AltitudeDefinition::Geodetic => geodetic_from_ecef(&at.r_e_m).height_m,
                    // |r| is the same in every frame: no Earth orientation needed.
                    AltitudeDefinition::Spherical { radius_m } => at.r_bn_n_m.norm() - radius_m,
                };
                e.density_at_altitude_kg_m3(altitude_m)
            }
            Air::Nrlmsise00(m) => {
                let cal = at.epoch.utc_calendar(at.t_sim_ns);
                let ut_s = f64::from(cal.hour) * 3600.0
                    + f64::from(cal.minute) * 60.0
                    + f64::from(cal.second.min(59))
                    + f64::from(cal.nanosecond) * 1e-9;
                m.drag_density_kg_m3(day_of_year(cal.year, cal.month, cal.day), ut_s, &at.r_e_m)
            }
        };
        // Co-rotating atmosphere (Vallado §8.6.2): v_wind = ω⊕ × r, N components; or still air
        // in N when `corotating_wind = false`.
        if self.corotating_wind {
            out.wind_n_m_s = at.earth.omega_en_n_rad_s.cross(at.r_bn_n_m);
        }
    }

    fn models_on(&self, on: &mut ModelsOn) {
        on.set("atmosphere");
    }

    /// `environment.f107_sfu`, `environment.f107a_sfu`, `environment.ap` with NRLMSISE-00; the
    /// `environment.exponential_*` band of an exponential atmosphere given one.
    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        if let Air::Exponential(ExponentialAtmosphere { band: Some(b), .. }) = &self.air {
            out.push((
                "environment.exponential_base_altitude_m".into(),
                b.base_altitude_m,
            ));
            out.push((
                "environment.exponential_base_density_kg_m3".into(),
                b.density_kg_m3,
            ));
            out.push((
                "environment.exponential_scale_height_m".into(),
                b.scale_height_m,
            ));
        }
        if let Air::Nrlmsise00(m) = &self.air {
            let w = m.weather();
            out.push(("environment.f107_sfu".into(), w.f107_sfu));
            out.push(("environment.f107a_sfu".into(), w.f107a_sfu));
            out.push(("environment.ap".into(), w.ap));
        }
    }

    fn to_words(s: &EnvironmentSample, w: &mut [u64]) -> usize {
        w[0] = s.density_kg_m3.to_bits();
        put_v3(w, 1, &s.wind_n_m_s);
        4
    }

    fn from_words(w: &[u64], s: &mut EnvironmentSample) -> usize {
        s.density_kg_m3 = f(w, 0);
        s.wind_n_m_s = v3(w, 1);
        4
    }

    fn archive(s: &mut EnvironmentSample, a: &mut Archive<'_>) {
        a.put(&mut s.density_kg_m3);
        a.put(&mut s.wind_n_m_s);
    }
}

/// Day of the year, 1 on 1 January (Gregorian).
fn day_of_year(year: i32, month: u8, day: u8) -> u32 {
    const CUM: [u32; 12] = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334];
    let leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    let m = usize::from(month.clamp(1, 12)) - 1;
    CUM[m] + u32::from(leap && month > 2) + u32::from(day)
}

#[cfg(test)]
mod tests {
    use super::day_of_year;

    #[test]
    fn day_of_year_counts_from_one() {
        assert_eq!(day_of_year(2026, 1, 1), 1);
        assert_eq!(day_of_year(2026, 11, 24), 328);
        assert_eq!(day_of_year(2024, 12, 31), 366);
        assert_eq!(day_of_year(2023, 3, 1), 60);
    }
}
