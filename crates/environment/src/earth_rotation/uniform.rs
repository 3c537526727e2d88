//! A uniform rotation of the Earth about N's third axis, for comparisons with tools that model
//! the Earth this way (and for studies that want no precession, nutation or polar motion):
//!
//! θ(t) = θ₀ + ω t,   `[E N]` = R3(θ(t)),   ω_E/N = (0, 0, ω) in N,
//!
//! with t the simulation time since the epoch, ω the configured rate
//! (`environment.earth_rotation_rate_rad_s`, by default [`super::OMEGA_EARTH_RAD_S`]) and θ₀ the
//! angle of E's first axis from N's at t = 0 (`environment.earth_rotation_angle_rad`, default 0).
//! R3 is the IERS passive rotation of [`super`]. The pole is N's third axis exactly, so against
//! the IAU 2006/2000B model of [`super::EarthRotation`] this neglects precession since J2000
//! (0.36° in 2026), nutation (≤ 20″) and polar motion (≤ 0.6″), and θ₀ stands in for the
//! sidereal time. The date never enters: the same run at any epoch gives the same frame.

use nalgebra::Vector3;

use super::{r3, EarthFrame};

/// A uniform rotation about N's third axis at a constant rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniformRotation {
    /// \[rad/s\] ω, the rate of E relative to N (positive: the Earth's sense).
    pub rate_rad_s: f64,
    /// \[rad\] θ₀, the angle of E's first axis from N's at t = 0, about N's third axis.
    pub angle_at_t0_rad: f64,
}

impl UniformRotation {
    /// The Earth-fixed frame at `t_sim_ns` since the epoch. Allocation-free; `gast_rad` holds
    /// θ(t) reduced to [0, 2π).
    pub fn at(&self, t_sim_ns: u64) -> EarthFrame {
        // Whole seconds and the remainder separately, so that θ keeps its precision over long
        // runs (t up to 584 years in u64 ns; ω t itself is reduced only once).
        let t_s = (t_sim_ns / 1_000_000_000) as f64 + (t_sim_ns % 1_000_000_000) as f64 * 1e-9;
        let theta_rad =
            (self.angle_at_t0_rad + self.rate_rad_s * t_s).rem_euclid(std::f64::consts::TAU);
        EarthFrame {
            dcm_en: r3(theta_rad),
            omega_en_n_rad_s: Vector3::new(0.0, 0.0, self.rate_rad_s),
            gast_rad: theta_rad,
        }
    }
}
