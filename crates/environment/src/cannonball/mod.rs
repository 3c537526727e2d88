//! The cannonball model of solar radiation pressure: the vehicle as a sphere of cross-section A
//! and radiation-pressure coefficient C_R (Montenbruck & Gill, *Satellite Orbits*, 2000, §3.4.1,
//! Eq. (3.75), written as a force):
//!
//! F = −P C_R A ŝ,
//!
//! with ŝ the unit vector from the spacecraft to the Sun and P the radiation pressure at the
//! spacecraft, (Φ/c) (1 AU / |r_Sun/B|)² ν ([`crate::facets::solar_pressure_n_m2`]). C_R = 1
//! is a black body (every photon absorbed), 2 a flat mirror facing the Sun; a sphere with a
//! diffuse fraction ρd has C_R = 1 + 4/9 ρd. The force has no attitude dependence. It acts at the
//! configured centre of pressure (B by default), so its torque about B is r_cp × F (zero when
//! the centre of pressure is at B, as for the usual cannonball at the centre of mass).
//!
//! Use it to compare with tools that model SRP this way (`solar_pressure_model =
//! "cannonball"`); the flat-plate model of [`crate::facets`] is the attitude-dependent one.

use nalgebra::Vector3;

use crate::facets::FacetWrench;

/// The cannonball's parameters (`[environment]`'s `cannonball_*` keys).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cannonball {
    /// \[m²\] cross-section A facing the Sun.
    pub area_m2: f64,
    /// \[-\] the radiation-pressure coefficient C_R, from 0 (transparent) to 2 (a mirror).
    pub reflectivity_coefficient: f64,
    /// \[m\] the centre of pressure relative to point B, B components.
    pub r_cp_b_m: Vector3<f64>,
}

/// \[m\] the largest |r_cp| accepted (the bound of every body-fixed point).
const MAX_BODY_EXTENT_M: f64 = 1e4;

impl Cannonball {
    /// Checks the parameters: `Err((key, message))` names the offending key of `[environment]`.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        if !(self.area_m2 > 0.0 && self.area_m2 <= 1e6) {
            return Err((
                "cannonball_area_m2",
                format!("{} m²: expected an area > 0 and <= 1e6 m²", self.area_m2),
            ));
        }
        if !(0.0..=2.0).contains(&self.reflectivity_coefficient) {
            return Err((
                "cannonball_reflectivity_coefficient",
                format!(
                    "{}: expected C_R from 0 to 2 (1 absorbs every photon, 2 is a mirror facing \
                     the Sun)",
                    self.reflectivity_coefficient
                ),
            ));
        }
        if self.r_cp_b_m.norm().is_nan() || self.r_cp_b_m.norm() > MAX_BODY_EXTENT_M {
            return Err((
                "cannonball_r_cp_b_m",
                format!(
                    "|r_cp| = {} m: expected a point within {MAX_BODY_EXTENT_M} m of B",
                    self.r_cp_b_m.norm()
                ),
            ));
        }
        Ok(())
    }

    /// The force at B and the torque about B for the unit Sun direction `sun_hat_b` (B
    /// components) and the pressure `pressure_n_m2` \[N/m²\]: F = −P C_R A ŝ, τ = r_cp × F.
    /// Allocation-free.
    pub fn wrench_unit_b(&self, sun_hat_b: &Vector3<f64>, pressure_n_m2: f64) -> FacetWrench {
        let force_b_newton =
            -(pressure_n_m2 * self.reflectivity_coefficient * self.area_m2) * sun_hat_b;
        FacetWrench {
            force_b_newton,
            torque_b_nm: self.r_cp_b_m.cross(&force_b_newton),
        }
    }
}
