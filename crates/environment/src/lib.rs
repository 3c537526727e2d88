//! The world around the spacecraft: field and ephemeris models, one folder per model, and the
//! [`EnvironmentSample`] they fill for the dynamic effectors (`flexdyn_dynamics::DynamicEffector`)
//! and the sensors.
//!
//! Every model here is a leaf: it takes plain inputs (a time as Julian centuries of TT since
//! J2000.0, a decimal year, or a day of year and UT seconds; positions in the frame its
//! argument names) and imports nothing from `flexdyn_dynamics`, `flexdyn_vehicle::config` or the server.
//! The functions the stepping loop calls allocate nothing, lock nothing and cannot panic; what can
//! be wrong with a model's parameters is checked once, when it is built, and reported as a typed
//! error.
//!
//! # Frames
//! - **N**: the inertial frame, GCRF. The models below give their positions in the mean equator
//!   and equinox of J2000.0 (EME2000), which differs from the GCRF by the frame bias, a fixed
//!   rotation of 0.02″ (23 mas); every model here is at least 100 times coarser than that, so the
//!   two are used as one.
//! - **ECEF**: the Earth-fixed frame (ITRF); the magnetic field and the atmosphere take their
//!   positions in it (`r_ecef_m`). The rotation from N to ECEF is [`earth_rotation`]'s (which
//!   calls it E, and carries the frame bias, so it maps from the GCRF proper).
//! - **TEME** (true equator, mean equinox of date): the frame of SGP4's output; see
//!   [`earth_rotation::dcm_n_teme`].
//! - **NED**: local north-east-down at a point, geodetic (WGS-84) or geocentric as the function
//!   says.
//! - **B**: the body frame of the hub; the facet model works in it.
//!
//! # Layout
//! - [`epoch`]: the simulation epoch (hifitime) and the time scales at `epoch + t_sim_ns` (TAI,
//!   TT, UTC with leap seconds, GPS week and seconds, UT1), and the `[epoch]` schema.
//! - [`earth_rotation`]: the DCM from N to the Earth-fixed frame (IAU 2006 precession, IAU 2000B
//!   nutation, sidereal time, optional polar motion) with its error bound, and TEME → N.
//! - [`orbit`]: initial orbits as alternatives to r/v — classical Keplerian elements, and TLE /
//!   CCSDS OMM mean elements propagated to the epoch with SGP4.
//! - [`common`]: the position-independent part of an update (the Earth's orientation, the Sun
//!   and the Moon), evaluated once per instant for every vehicle of a world.
//! - [`prefetch`]: the worker thread that evaluates the next update ahead of time, so the models
//!   stay off the physics thread, with bit-identical samples.
//! - [`sample`]: the [`EnvironmentSample`] the dynamic effectors and sensors read, held between
//!   model updates.
//! - [`geodetic`]: WGS-84 ECEF ↔ geodetic latitude, longitude and height; the NED frame.
//! - [`ephemeris`]: Sun and Moon positions in N (Meeus, *Astronomical Algorithms*, ch. 25 and 47).
//! - [`shadow`]: the fraction of the solar disc visible from the spacecraft (conical with
//!   penumbra, or cylindrical).
//! - [`magnetic`]: IGRF-14 to a chosen degree, the centred tilted dipole of its degree-1
//!   coefficients, and the torque on a residual dipole.
//! - [`atmosphere`]: exponential (Vallado Table 8-4) and NRLMSISE-00 densities, and the wind of a
//!   co-rotating atmosphere.
//! - [`albedo`]: sunlight reflected by the Earth (a Lambertian sphere of uniform albedo), the
//!   visible cap discretised for the coarse sun sensors.
//! - [`cannonball`]: the cannonball model of solar radiation pressure (a sphere of area A and
//!   coefficient C_R).
//! - [`facets`]: the flat-plate model of the vehicle's surfaces: drag and solar-radiation-pressure
//!   forces and torques about B.
//!
//! # The registry of environment models
//! Each model that fills part of the [`EnvironmentSample`] is a folder here whose `part.rs`
//! implements [`model::part::EnvironmentPart`] (its keys of `[environment]`, its settings, its
//! build, its part of an update, its fields in the prefetch slot and in a checkpoint), and one
//! line of the registry below. The order of the lines is the order of the sample's fields in
//! the prefetch slot and in a checkpoint: append a new model at the end.
//!
//! # Layer
//! Above `flexdyn-kernel`. It depends on the kernel, `nalgebra`, and the field's own crates
//! (`hifitime` for time scales, `sgp4` for mean elements, `tobari` for NRLMSISE-00). It must never
//! depend on the dynamics, the sensors or anything above them, nor on any I/O stack (`zenoh`,
//! `tokio`, `foxglove`, `plotters`, `mcap`): `.ci/layers` (run by `.ci/run`) checks the dependency
//! graph.

#![warn(missing_docs)]

pub mod albedo;
pub mod atmosphere;
pub mod cannonball;
pub mod common;
pub mod earth_rotation;
pub mod ephemeris;
pub mod epoch;
pub mod facets;
pub mod geodetic;
pub mod magnetic;
pub mod model;
pub mod orbit;
pub mod prefetch;
pub mod sample;
pub mod shadow;

pub use sample::EnvironmentSample;

model::part::environment_models! {
    /// The magnetic field (`magnetic`, …): `b_field_n_t`.
    magnetic: magnetic::MagneticField,
    /// The Sun and the Moon (`sun`, `moon`, a fixed Sun): `r_sun_b_n_m`, `r_moon_b_n_m`.
    ephemeris: ephemeris::Ephemeris,
    /// The Earth's shadow (`shadow` and its radii): `shadow_factor`.
    shadow: shadow::ShadowGeometry,
    /// The atmosphere and its wind (`atmosphere`, …): `density_kg_m3`, `wind_n_m_s`.
    atmosphere: atmosphere::Atmosphere,
    /// The Earth's albedo (`albedo`, `albedo_coefficient`): `albedo`.
    albedo: albedo::Albedo,
}
