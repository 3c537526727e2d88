//! The wind of an atmosphere that co-rotates with the Earth, and the velocity of the spacecraft
//! relative to it: v_rel = v − ω⊕ × r (Vallado, *Fundamentals of Astrodynamics and
//! Applications*, 4th ed., §8.6.2; Montenbruck & Gill, *Satellite Orbits*, §3.5.2).
//!
//! The Earth's angular velocity is an argument so that the caller can pass the true pole from its
//! Earth-rotation model; `[0, 0, OMEGA_EARTH_RAD_S]` in N neglects precession and
//! nutation of the pole (0.3° in 2025), an error of 2 m/s in a 7.7 km/s relative wind (3e-4).
//! Winds relative to the co-rotating atmosphere (up to a few hundred m/s in the thermosphere) are
//! not modelled.

use nalgebra::Vector3;

/// [m/s] the velocity of the co-rotating atmosphere at `r_n_m` \[m\], ω⊕ × r, in the frame of the
/// arguments (N, with `omega_earth_n_rad_s` the Earth's angular velocity in N).
pub fn corotation_wind_n_m_s(
    r_n_m: &Vector3<f64>,
    omega_earth_n_rad_s: &Vector3<f64>,
) -> Vector3<f64> {
    omega_earth_n_rad_s.cross(r_n_m)
}

/// [m/s] the spacecraft's velocity relative to the co-rotating atmosphere, v − ω⊕ × r, in N. The
/// drag force opposes it.
pub fn velocity_relative_to_air_n_m_s(
    r_n_m: &Vector3<f64>,
    v_n_m_s: &Vector3<f64>,
    omega_earth_n_rad_s: &Vector3<f64>,
) -> Vector3<f64> {
    v_n_m_s - corotation_wind_n_m_s(r_n_m, omega_earth_n_rad_s)
}
