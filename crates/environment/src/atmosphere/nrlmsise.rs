//! NRLMSISE-00 (Picone, Hedin, Drob & Aikin, "NRLMSISE-00 empirical model of the atmosphere",
//! J. Geophys. Res. 107(A12), 1468, 2002), evaluated by the `tobari` crate (0.2.0) with the
//! standard switches (all variations on; the daily Ap drives the geomagnetic term, switch 9 = 1).
//!
//! The inputs are those of the reference program `gtd7`: day of year, UT seconds, geodetic
//! altitude, latitude and longitude, the local apparent solar time, F10.7 of the previous day,
//! its 81-day centred average, and the daily Ap. [`Nrlmsise00Model::state`] sets the local solar
//! time to `UT/3600 + longitude/15` \[h\], the relation the model's documentation prescribes for
//! physically consistent input (no equation of time).
//!
//! Two densities are given: the total mass density of `gtd7` (He, O, N₂, O₂, Ar, H, N), which the
//! reference test outputs print, and the drag density of `gtd7d`, which adds the anomalous oxygen
//! the model's authors recommend for satellite drag (+23 % at 1000 km, +0.02 % at 400 km).
//!
//! # What `tobari` 0.2.0 gets wrong, and what is done about it
//! Checked against the 15 test cases of the reference C release (D. Brodowski's C version of the
//! NRL model, release 20041227, whose documented output equals the official FORTRAN's) in
//! `crates/environment/tests/atmosphere.rs`:
//! 1. **Anomalous oxygen below 550 km** is not attenuated: `tobari` sets it to the diffusive
//!    profile `dd` when `alt < zmho`, a branch NRL's `gts7` does not have (there
//!    `d[8] = dd exp(−zsht/zsho (exp(−(z − zmho)/zsht) − 1))` at every altitude). At 400 km it is
//!    6.6 times too large, and `tobari`'s total mass density, which includes it, 0.1 % too large.
//!    Corrected here by applying the missing factor (from the model's own coefficients
//!    `pdm[7][4]`, `pdm[7][5]`, `pdm[7][9]`, `pdl[0][6]` and `scalh`), and the total mass density
//!    rebuilt without it; the version is pinned (`=0.2.0`) so an upstream fix cannot be applied
//!    twice unnoticed (the reference test would fail).
//! 2. **Below 72.5 km** `tobari` does not evaluate the model's lower atmosphere (the spline
//!    profiles of `gtd7` below `zn2[0]`): at sea level its density is 1e4 times too small. There
//!    the densities come from [`super::exponential`] instead (within 25 % of NRLMSISE-00 between 0
//!    and 70 km in the test cases) and [`AtmosphereState::composition`] is `None`. A spacecraft
//!    that low is re-entering.
//! 3. **0.01–0.3 % everywhere else**: `tobari` uses exact π/180, 2π/365.25 and π/12 where NRL's
//!    code (and the fit of its coefficients) uses the rounded DGTR = 1.74533e-2, DR = 1.72142e-2
//!    and HR = 0.2618. With those three constants patched into a copy of `tobari` outside this
//!    repository, cases 1–10 match the printed 7 digits (worst 4.8e-7). This cannot be corrected
//!    from outside the crate; it is 100 times smaller than the model's own uncertainty (about
//!    15 %, Picone et al. 2002), and the tests bound it.
//!
//! The two cases of the reference test that use the 3-hour Ap history (switch 9 = −1) are not
//! offered: `tobari` has no switch for it.

use nalgebra::Vector3;
use tobari::nrlmsise00::coefficients::{CORRECTION_PARAMS, DENSITY_BOUNDARY};
use tobari::nrlmsise00::{Nrlmsise00Input, Nrlmsise00Output};
use tobari::{ConstantWeather, Nrlmsise00};

use super::exponential::exponential_density_kg_m3;
use super::AtmosphereError;
use crate::geodetic::{geodetic_from_ecef, Geodetic};

/// [kg] the atomic mass unit as the model uses it (1.66e-24 g in `gtd7`/`gtd7d`).
const MODEL_AMU_KG: f64 = 1.66e-27;
/// \[km\] the bottom of the thermospheric profile (`zn2[0]` of the model); below it `tobari` 0.2.0
/// does not evaluate NRLMSISE-00 (see the module docs).
pub const LOWEST_THERMOSPHERE_ALTITUDE_M: f64 = 72_500.0;

/// Solar and geomagnetic activity, held constant over a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpaceWeather {
    /// \[sfu\] F10.7 of the previous day (1 sfu = 1e-22 W m⁻² Hz⁻¹).
    pub f107_sfu: f64,
    /// \[sfu\] 81-day average of F10.7, centred on the day.
    pub f107a_sfu: f64,
    /// [-] daily planetary geomagnetic index Ap.
    pub ap: f64,
}

impl SpaceWeather {
    /// Checks the indices: F10.7 and its average finite and within (0, 1000] sfu (observed values
    /// lie between 60 and 400), Ap finite and within [0, 400] (its defined range).
    pub fn validated(self) -> Result<Self, AtmosphereError> {
        for (field, value) in [("f107_sfu", self.f107_sfu), ("f107a_sfu", self.f107a_sfu)] {
            if !(value.is_finite() && value > 0.0 && value <= 1000.0) {
                return Err(AtmosphereError::Invalid {
                    field,
                    value,
                    expected: "a finite F10.7 in (0, 1000] sfu",
                });
            }
        }
        if !(self.ap.is_finite() && (0.0..=400.0).contains(&self.ap)) {
            return Err(AtmosphereError::Invalid {
                field: "ap",
                value: self.ap,
                expected: "a finite Ap in [0, 400]",
            });
        }
        Ok(self)
    }
}

/// Temperatures and composition at a point (NRLMSISE-00 proper, 72.5 km and above).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Composition {
    /// \[K\] exospheric temperature.
    pub exospheric_temperature_k: f64,
    /// \[K\] temperature at the altitude.
    pub temperature_k: f64,
    /// [m⁻³] number densities of He, O, N₂, O₂, Ar, H, N and anomalous O, in that order.
    pub number_densities_m3: [f64; 8],
}

/// The atmosphere at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AtmosphereState {
    /// [kg/m³] total mass density of `gtd7` (without anomalous oxygen).
    pub density_kg_m3: f64,
    /// [kg/m³] drag density of `gtd7d`: the total mass density plus anomalous oxygen.
    pub drag_density_kg_m3: f64,
    /// Temperatures and number densities; `None` below 72.5 km, where both densities come from
    /// the exponential model.
    pub composition: Option<Composition>,
}

/// NRLMSISE-00 with fixed space weather.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nrlmsise00Model {
    weather: SpaceWeather,
}

impl Nrlmsise00Model {
    /// The model for `weather` (checked by [`SpaceWeather::validated`]).
    pub fn new(weather: SpaceWeather) -> Result<Self, AtmosphereError> {
        Ok(Nrlmsise00Model {
            weather: weather.validated()?,
        })
    }

    /// The space weather the model was built with.
    pub fn weather(&self) -> SpaceWeather {
        self.weather
    }

    /// The atmosphere at `point` on `day_of_year` (1..=366) at `ut_s` seconds of UT into the day,
    /// with the local solar time `UT/3600 + longitude/15`. Allocation-free and panic-free.
    pub fn state(&self, day_of_year: u32, ut_s: f64, point: &Geodetic) -> AtmosphereState {
        let lst_h = (ut_s / 3600.0 + point.lon_rad.to_degrees() / 15.0).rem_euclid(24.0);
        self.state_at_local_solar_time(day_of_year, ut_s, point, lst_h)
    }

    /// As [`Nrlmsise00Model::state`] with the local apparent solar time `lst_h` \[h\] given
    /// explicitly (the reference test cases use a time inconsistent with UT and longitude, to
    /// exercise the model's terms separately).
    pub fn state_at_local_solar_time(
        &self,
        day_of_year: u32,
        ut_s: f64,
        point: &Geodetic,
        lst_h: f64,
    ) -> AtmosphereState {
        if point.height_m < LOWEST_THERMOSPHERE_ALTITUDE_M {
            let rho = exponential_density_kg_m3(point.height_m);
            return AtmosphereState {
                density_kg_m3: rho,
                drag_density_kg_m3: rho,
                composition: None,
            };
        }
        let latitude_deg = point.lat_rad.to_degrees();
        let input = Nrlmsise00Input {
            day_of_year,
            ut_seconds: ut_s,
            altitude_km: point.height_m * 1e-3,
            latitude_deg,
            longitude_deg: point.lon_rad.to_degrees(),
            local_solar_time_hours: lst_h,
            f107_daily: self.weather.f107_sfu,
            f107_avg: self.weather.f107a_sfu,
            ap_daily: self.weather.ap,
            ap_array: [self.weather.ap; 7],
        };
        // `tobari` wants a space-weather provider, which `calculate` does not consult (the
        // indices travel in `input`); building one is a few stores, no allocation.
        let model = Nrlmsise00::new(ConstantWeather::new(self.weather.f107_sfu, self.weather.ap));
        let output = model.calculate(&input);
        corrected(&output, point.height_m * 1e-3, latitude_deg)
    }

    /// [kg/m³] the drag density (`gtd7d`) at the Earth-fixed position `r_ecef_m` \[m\].
    pub fn drag_density_kg_m3(&self, day_of_year: u32, ut_s: f64, r_ecef_m: &Vector3<f64>) -> f64 {
        self.state(day_of_year, ut_s, &geodetic_from_ecef(r_ecef_m))
            .drag_density_kg_m3
    }
}

/// `tobari`'s output in SI, with the anomalous oxygen attenuated as NRL's `gts7` does below
/// zmho = 550 km, and the `gtd7`/`gtd7d` densities rebuilt from it (module docs, item 1).
fn corrected(o: &Nrlmsise00Output, altitude_km: f64, latitude_deg: f64) -> AtmosphereState {
    let anomalous_o_cm3 =
        o.density_anomalous_o * anomalous_oxygen_factor(altitude_km, latitude_deg);
    // `tobari`'s total includes its own (unattenuated) anomalous oxygen: take it out.
    let density_kg_m3 = o.total_mass_density - 16.0 * MODEL_AMU_KG * 1e6 * o.density_anomalous_o;
    let per_cm3 = [
        o.density_he,
        o.density_o,
        o.density_n2,
        o.density_o2,
        o.density_ar,
        o.density_h,
        o.density_n,
        anomalous_o_cm3,
    ];
    AtmosphereState {
        density_kg_m3,
        drag_density_kg_m3: density_kg_m3 + 16.0 * MODEL_AMU_KG * 1e6 * anomalous_o_cm3,
        composition: Some(Composition {
            exospheric_temperature_k: o.temp_exo,
            temperature_k: o.temp_alt,
            number_densities_m3: per_cm3.map(|n| n * 1e6),
        }),
    }
}

/// The factor exp(−zsht/zsho (exp(−(z − zmho)/zsht) − 1)) that NRL's `gts7` applies to the
/// anomalous-oxygen profile and `tobari` 0.2.0 omits below zmho: zmho = `pdm[7][4]` (550 km),
/// zsht = `pdm[7][5]` (76 km), T_ho = `pdm[7][9]·pdl[0][6]` (4000 K), and zsho the scale height
/// R T_ho / (g(zmho) · 16) of `scalh`, with g from `glatf` (R = 831.4 in the model's units).
fn anomalous_oxygen_factor(altitude_km: f64, latitude_deg: f64) -> f64 {
    let zmho = DENSITY_BOUNDARY[7][4];
    if altitude_km >= zmho {
        return 1.0;
    }
    let zsht = DENSITY_BOUNDARY[7][5];
    let t_ho = DENSITY_BOUNDARY[7][9] * CORRECTION_PARAMS[0][6];
    // glatf: surface gravity [cm/s²] and effective radius [km] at the latitude (DGTR as NRL's).
    let c2 = (2.0 * 1.745_33e-2 * latitude_deg).cos();
    let g_surface = 980.616 * (1.0 - 0.002_637_3 * c2);
    let r_eff = 2.0 * g_surface / (3.085_462e-6 + 2.27e-9 * c2) * 1.0e-5;
    let g = g_surface / (1.0 + zmho / r_eff).powi(2);
    let zsho = 831.4 * t_ho / (g * 16.0);
    (-zsht / zsho * ((-(altitude_km - zmho) / zsht).exp() - 1.0)).exp()
}
