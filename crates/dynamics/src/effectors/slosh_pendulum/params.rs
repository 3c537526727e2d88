//! Parameters of a spherical-pendulum slosh mass: plain data, validated here with errors that
//! name the configuration path.

use nalgebra::Vector3;

use crate::slosh_tank::CylindricalTank;
use flexdyn_kernel::validate::{
    check_finite, check_non_negative, check_positive, check_unit_axis, join, ParamError,
};

/// \[rad\] largest initial |θ|: the angles are singular at |θ| = 90° (see the module docs), and a
/// slosh pendulum swung that far is outside any equivalent mechanical model's range.
pub const MAX_INITIAL_THETA_RAD: f64 = 80.0 * std::f64::consts::PI / 180.0;

/// One spherical slosh pendulum, resolved (what [`super::SloshPendulum`] integrates).
#[derive(Debug, Clone, PartialEq)]
pub struct SloshPendulumParams {
    /// Name used in logs, messages and telemetry.
    pub name: String,
    /// \[m\] the pivot (hinge) P relative to B, B components.
    pub r_pb_b_m: Vector3<f64>,
    /// p̂1, the direction the rod points at φ = θ = 0, B components (unit): the nominal hang,
    /// against the settling acceleration.
    pub hang_axis_b: Vector3<f64>,
    /// \[m\] rod length l.
    pub l_m: f64,
    /// \[kg\] pendulum (sloshing) mass m.
    pub mass_kg: f64,
    /// \[N·m·s/rad\] damping c: the torque about P opposing the rod's angular velocity relative to
    /// B (Rayleigh function ½ c |ê′|²).
    pub c_nm_s_rad: f64,
    /// \[rad\] initial azimuth φ.
    pub phi_rad: f64,
    /// \[rad/s\] initial φ̇.
    pub phi_dot_rad_s: f64,
    /// \[rad\] initial elevation θ.
    pub theta_rad: f64,
    /// \[rad/s\] initial θ̇.
    pub theta_dot_rad_s: f64,
}

impl SloshPendulumParams {
    /// Validates the pendulum (`path` is e.g. `slosh_pendulums[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_finite(path, "r_pb_b_m", self.r_pb_b_m.as_slice())?;
        check_unit_axis(path, "hang_axis_b", &self.hang_axis_b)?;
        check_positive(path, "l_m", self.l_m)?;
        check_positive(path, "mass_kg", self.mass_kg)?;
        check_non_negative(path, "c_nm_s_rad", self.c_nm_s_rad)?;
        check_finite(path, "phi_rad", &[self.phi_rad])?;
        check_finite(path, "phi_dot_rad_s", &[self.phi_dot_rad_s])?;
        check_finite(path, "theta_rad", &[self.theta_rad])?;
        if self.theta_rad.abs() > MAX_INITIAL_THETA_RAD {
            return Err(ParamError::Invalid {
                field: join(path, "theta_rad"),
                problem: format!(
                    "|θ| = {} rad is beyond 80° (1.396 rad): the angles are singular at 90°, \
                     so start the pendulum nearer its hang axis",
                    self.theta_rad.abs()
                ),
            });
        }
        check_finite(path, "theta_dot_rad_s", &[self.theta_dot_rad_s])
    }
}

/// Where a configured pendulum's pivot, hang, length and mass come from.
#[derive(Debug, Clone, PartialEq)]
pub enum SloshPendulumSource {
    /// Given directly.
    Direct {
        /// \[m\] pivot P relative to B.
        r_pb_b_m: Vector3<f64>,
        /// p̂1 in B (unit).
        hang_axis_b: Vector3<f64>,
        /// \[m\] rod length.
        l_m: f64,
        /// \[kg\] pendulum mass.
        mass_kg: f64,
    },
    /// Set by a tank's fill level ([`crate::slosh_tank`], Eqs. T2, T3, T5): m = m₁, l = L₁, the
    /// pivot on the tank's axis at the hinge height, hanging against the axis.
    Tank(CylindricalTank),
}

/// One `[[slosh_pendulums]]` entry as configured.
#[derive(Debug, Clone, PartialEq)]
pub struct SloshPendulumEntry {
    /// Name used in logs, messages and telemetry.
    pub name: String,
    /// Pivot, hang, length and mass.
    pub source: SloshPendulumSource,
    /// \[N·m·s/rad\] damping c.
    pub c_nm_s_rad: f64,
    /// \[rad\] initial φ.
    pub phi_rad: f64,
    /// \[rad/s\] initial φ̇.
    pub phi_dot_rad_s: f64,
    /// \[rad\] initial θ.
    pub theta_rad: f64,
    /// \[rad/s\] initial θ̇.
    pub theta_dot_rad_s: f64,
}

impl SloshPendulumEntry {
    /// The pendulum's parameters (`path` is e.g. `slosh_pendulums[0]`); a tank is validated and
    /// mapped first (its errors name `path.tank.…`).
    pub fn resolve(&self, path: &str) -> Result<SloshPendulumParams, ParamError> {
        let (r_pb_b_m, hang_axis_b, l_m, mass_kg) = match &self.source {
            SloshPendulumSource::Direct {
                r_pb_b_m,
                hang_axis_b,
                l_m,
                mass_kg,
            } => (*r_pb_b_m, *hang_axis_b, *l_m, *mass_kg),
            SloshPendulumSource::Tank(tank) => {
                tank.validate(&join(path, "tank"))?;
                let mode = tank.first_mode();
                (
                    tank.on_axis_b_m(mode.hinge_height_m),
                    -tank.axis_b,
                    mode.pendulum_length_m,
                    mode.slosh_mass_kg,
                )
            }
        };
        Ok(SloshPendulumParams {
            name: self.name.clone(),
            r_pb_b_m,
            hang_axis_b,
            l_m,
            mass_kg,
            c_nm_s_rad: self.c_nm_s_rad,
            phi_rad: self.phi_rad,
            phi_dot_rad_s: self.phi_dot_rad_s,
            theta_rad: self.theta_rad,
            theta_dot_rad_s: self.theta_dot_rad_s,
        })
    }
}
