//! Validated physical parameters of the spacecraft: the hub, gravity and the forcing (the
//! validation helpers they use live in the leaf module [`flexdyn_kernel::validate`]).
//!
//! These are plain data. They are built by `flexdyn_vehicle::config` (which validates them and reports
//! errors that name the field) or directly in code, and consumed once by
//! [`crate::Spacecraft::new`], which validates them again (cheaply) so a hand-built
//! parameter set can never reach the stepping hot path unchecked.

use nalgebra::{Matrix3, Vector3};

/// Rigid hub parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct HubParams {
    /// \[kg\] hub mass.
    pub mass_kg: f64,
    /// [kg·m²] hub inertia about its own centre of mass Bc, in B components (symmetric positive-definite).
    pub inertia_bc_b_kg_m2: Matrix3<f64>,
    /// \[m\] position of the hub centre of mass Bc relative to point B, in B components.
    pub r_bcb_b_m: Vector3<f64>,
}

/// Gravity model. The field is evaluated at the system centre of mass C and applied uniformly
/// (no gravity-gradient torque), as the paper and Basilisk do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GravityModel {
    /// Free space.
    None,
    /// Point-mass central body.
    PointMass {
        /// [m³/s²] gravitational parameter μ.
        mu_m3_s2: f64,
    },
    /// Point mass plus the J2 zonal term (N frame ẑ is the body's pole).
    J2 {
        /// [m³/s²] gravitational parameter μ.
        mu_m3_s2: f64,
        /// [-] J2 coefficient.
        j2: f64,
        /// \[m\] equatorial radius.
        r_eq_m: f64,
    },
}

/// A point fixed on the hub where a sensor (an IMU) sits, with its platform frame P.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorPoint {
    /// \[m\] sensor location S relative to B, in B components.
    pub r_sb_b_m: Vector3<f64>,
    /// DCM \[PB\]: maps B components to platform P components.
    pub dcm_pb: Matrix3<f64>,
}

/// An external wrench on the hub: a force applied at point B and a torque, both in B
/// components. Built with named fields only, so force and torque cannot be swapped silently
/// (the wire carries torque first, the old API took force first).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wrench {
    /// \[N\] force on the hub, applied at point B, B components.
    pub force_b_newton: Vector3<f64>,
    /// [N·m] torque on the hub, B components.
    pub torque_b_nm: Vector3<f64>,
}

impl Wrench {
    /// No force and no torque.
    pub const ZERO: Wrench = Wrench {
        force_b_newton: Vector3::new(0.0, 0.0, 0.0),
        torque_b_nm: Vector3::new(0.0, 0.0, 0.0),
    };
}

impl std::ops::Add for Wrench {
    type Output = Wrench;
    fn add(self, rhs: Wrench) -> Wrench {
        Wrench {
            force_b_newton: self.force_b_newton + rhs.force_b_newton,
            torque_b_nm: self.torque_b_nm + rhs.torque_b_nm,
        }
    }
}

/// One row of the piecewise-constant external wrench schedule on the hub.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WrenchSegment {
    /// \[ns\] time from which this row applies (until the next row).
    pub t_start_ns: u64,
    /// \[N\] force on the hub, B components, applied at point B.
    pub force_b_newton: Vector3<f64>,
    /// [N·m] torque on the hub, B components.
    pub torque_b_nm: Vector3<f64>,
}

impl WrenchSegment {
    /// The row's wrench.
    pub fn wrench(&self) -> Wrench {
        Wrench {
            force_b_newton: self.force_b_newton,
            torque_b_nm: self.torque_b_nm,
        }
    }
}

use flexdyn_kernel::validate::{
    check_dcm, check_finite, check_inertia_matrix, check_positive, join, ParamError,
};

impl HubParams {
    /// Validates the hub: positive mass, SPD inertia obeying the triangle inequality, finite offset.
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_positive(path, "mass_kg", self.mass_kg)?;
        check_inertia_matrix(path, "inertia_bc_b_kg_m2", &self.inertia_bc_b_kg_m2)?;
        check_finite(path, "r_bcb_b_m", self.r_bcb_b_m.as_slice())
    }
}

impl GravityModel {
    /// Validates the gravity parameters (`path` is e.g. `gravity`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        match *self {
            GravityModel::None => Ok(()),
            GravityModel::PointMass { mu_m3_s2 } => check_positive(path, "mu_m3_s2", mu_m3_s2),
            GravityModel::J2 {
                mu_m3_s2,
                j2,
                r_eq_m,
            } => {
                check_positive(path, "mu_m3_s2", mu_m3_s2)?;
                check_finite(path, "j2", &[j2])?;
                // J2 = (C − A)/(M R²) (Vallado, 4th ed., Eq. 8-19 with the moments of inertia,
                // MacCullagh's formula). The expansion holds outside the body, so its mass lies
                // within R = r_eq_m, where 0 ≤ A, C ≤ M R²: |J2| ≤ 1. Earth's is 1.08e-3.
                if j2.abs() > 1.0 {
                    return Err(ParamError::Invalid {
                        field: join(path, "j2"),
                        problem: format!(
                            "|{j2}| exceeds 1: J2 = (C − A)/(M r_eq²) of a body within r_eq is \
                             at most 1 in magnitude (Earth's is 1.08e-3)"
                        ),
                    });
                }
                check_positive(path, "r_eq_m", r_eq_m)
            }
        }
    }
}

impl SensorPoint {
    /// Validates the sensor point (`path` is e.g. `imus[0]`): finite position, orthonormal DCM.
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_finite(path, "r_sb_b_m", self.r_sb_b_m.as_slice())?;
        check_dcm(path, "dcm_pb", &self.dcm_pb)
    }
}

impl WrenchSegment {
    /// Validates one schedule row (finite force and torque).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_finite(path, "force_b_newton", self.force_b_newton.as_slice())?;
        check_finite(path, "torque_b_nm", self.torque_b_nm.as_slice())
    }
}
