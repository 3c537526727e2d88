//! The neutral atmosphere: density models and the wind of a co-rotating atmosphere.
//!
//! - [`exponential`]: Vallado Table 8-4, a function of altitude alone.
//! - [`nrlmsise`]: NRLMSISE-00 through the `tobari` crate, with F10.7, its 81-day average and
//!   Ap from the configuration ([`SpaceWeather`]); read its docs for what `tobari` 0.2.0 gets
//!   wrong and how it is corrected or bounded.
//! - [`wind`]: v_rel = v − ω⊕ × r.
//!
//! Densities take the geodetic height ([`crate::geodetic`]; the exponential model optionally a
//! spherical altitude, [`AltitudeDefinition`]); NRLMSISE-00 also the
//! day of year and UT. Both are slow fields in time, but the density changes by a factor e over
//! one scale height (60 km at 500 km), so along a low orbit it is evaluated at the environment
//! sample's rate, not held for long.

pub mod exponential;
pub mod nrlmsise;
pub mod part;
pub mod schema;
pub mod wind;

pub use exponential::{
    exponential_density_kg_m3, AltitudeDefinition, ExponentialAtmosphere, ExponentialBand,
    VALLADO_TABLE_8_4,
};
pub use nrlmsise::{
    AtmosphereState, Composition, Nrlmsise00Model, SpaceWeather, LOWEST_THERMOSPHERE_ALTITUDE_M,
};
pub use part::Atmosphere;
pub use schema::{AirSetting, AtmosphereSetting};
pub use wind::{corotation_wind_n_m_s, velocity_relative_to_air_n_m_s};

/// An invalid atmosphere parameter. Every variant names the field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AtmosphereError {
    /// A parameter outside its range.
    #[error("{field} = {value}: expected {expected}")]
    Invalid {
        /// The parameter's name (`f107_sfu`, `f107a_sfu`, `ap`).
        field: &'static str,
        /// The value given.
        value: f64,
        /// What is accepted.
        expected: &'static str,
    },
}
