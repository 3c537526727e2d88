//! Parameters of a linear spring-mass-damper slosh particle: plain data, validated here with
//! errors that name the configuration path.

use nalgebra::Vector3;

use crate::slosh_tank::CylindricalTank;
use flexdyn_kernel::validate::{
    check_finite, check_non_negative, check_positive, check_unit_axis, join, ParamError,
};

/// \[-\] largest |p̂ · tank axis| for a tank-set particle: its axis must be lateral, since the
/// mode of [`crate::slosh_tank`] is the lateral one.
pub const LATERAL_TOL: f64 = 1e-6;

/// Where a configured particle's mass, stiffness and rest point come from.
#[derive(Debug, Clone, PartialEq)]
pub enum SloshLinearSource {
    /// Given directly.
    Direct {
        /// \[m\] rest point P relative to B, B components.
        r_pb_b_m: Vector3<f64>,
        /// \[kg\] sloshing mass.
        mass_kg: f64,
        /// \[N/m\] spring stiffness.
        k_n_m: f64,
    },
    /// Set by a tank's fill level ([`crate::slosh_tank`], Eqs. T2–T4): m = m₁, k = m₁ω₁² at
    /// `settling_accel_m_s2`, P on the tank's axis at the slosh mass's height h₁.
    Tank {
        /// The tank and its fill level.
        tank: CylindricalTank,
        /// \[m/s²\] the settling (thrust) acceleration along the tank's axis that sets k.
        settling_accel_m_s2: f64,
    },
}

/// One `[[slosh_linear]]` entry as configured: a particle, possibly set by a tank.
#[derive(Debug, Clone, PartialEq)]
pub struct SloshLinearEntry {
    /// Name used in logs, messages and telemetry.
    pub name: String,
    /// The axis p̂ in B (unit); with a tank, perpendicular to the tank's axis.
    pub p_hat_b: Vector3<f64>,
    /// Mass, stiffness and rest point.
    pub source: SloshLinearSource,
    /// \[N·s/m\] damping coefficient c.
    pub c_n_s_m: f64,
    /// \[m\] initial ρ.
    pub rho_m: f64,
    /// \[m/s\] initial ρ̇.
    pub rho_dot_m_s: f64,
}

impl SloshLinearEntry {
    /// The particle's parameters (`path` is e.g. `slosh_linear[0]`); a tank is validated and
    /// mapped first (its errors name `path.tank.…`).
    pub fn resolve(&self, path: &str) -> Result<SloshLinearParams, ParamError> {
        let (r_pb_b_m, mass_kg, k_n_m) = match &self.source {
            SloshLinearSource::Direct {
                r_pb_b_m,
                mass_kg,
                k_n_m,
            } => (*r_pb_b_m, *mass_kg, *k_n_m),
            SloshLinearSource::Tank {
                tank,
                settling_accel_m_s2,
            } => {
                let tank_path = join(path, "tank");
                tank.validate(&tank_path)?;
                check_positive(&tank_path, "settling_accel_m_s2", *settling_accel_m_s2)?;
                check_unit_axis(path, "p_hat_b", &self.p_hat_b)?;
                let along = self.p_hat_b.dot(&tank.axis_b);
                if along.abs() > LATERAL_TOL {
                    return Err(ParamError::Invalid {
                        field: join(path, "p_hat_b"),
                        problem: format!(
                            "must be perpendicular to {tank_path}.axis_b (the tank's lateral \
                             slosh mode), but p_hat_b · axis_b = {along}"
                        ),
                    });
                }
                let mode = tank.first_mode();
                (
                    tank.on_axis_b_m(mode.slosh_height_m),
                    mode.slosh_mass_kg,
                    mode.k_n_m(*settling_accel_m_s2),
                )
            }
        };
        Ok(SloshLinearParams {
            name: self.name.clone(),
            r_pb_b_m,
            p_hat_b: self.p_hat_b,
            mass_kg,
            k_n_m,
            c_n_s_m: self.c_n_s_m,
            rho_m: self.rho_m,
            rho_dot_m_s: self.rho_dot_m_s,
        })
    }
}

/// One slosh particle (`[[slosh_linear]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct SloshLinearParams {
    /// Name used in logs, messages and telemetry.
    pub name: String,
    /// \[m\] the rest point P of the particle (ρ = 0) relative to B, B components.
    pub r_pb_b_m: Vector3<f64>,
    /// The axis p̂ along which the particle moves, B components (a unit vector within
    /// [`flexdyn_kernel::validate::UNIT_AXIS_TOL`]); ρ > 0 displaces it along +p̂.
    pub p_hat_b: Vector3<f64>,
    /// \[kg\] the sloshing mass m (the fixed, non-sloshing part of the propellant belongs to the
    /// hub's mass properties).
    pub mass_kg: f64,
    /// \[N/m\] spring stiffness k.
    pub k_n_m: f64,
    /// \[N·s/m\] damping coefficient c.
    pub c_n_s_m: f64,
    /// \[m\] initial displacement ρ.
    pub rho_m: f64,
    /// \[m/s\] initial rate ρ̇.
    pub rho_dot_m_s: f64,
}

impl SloshLinearParams {
    /// Validates the particle (`path` is e.g. `slosh_linear[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_finite(path, "r_pb_b_m", self.r_pb_b_m.as_slice())?;
        check_unit_axis(path, "p_hat_b", &self.p_hat_b)?;
        check_positive(path, "mass_kg", self.mass_kg)?;
        check_positive(path, "k_n_m", self.k_n_m)?;
        check_non_negative(path, "c_n_s_m", self.c_n_s_m)?;
        check_finite(path, "rho_m", &[self.rho_m])?;
        check_finite(path, "rho_dot_m_s", &[self.rho_dot_m_s])
    }
}
