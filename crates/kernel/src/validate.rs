//! Parameter validation shared by every model: the [`ParamError`] that names the offending
//! field by its configuration path, and the checks (finite, positive, an inertia matrix, a
//! DCM). A leaf module (it depends on nalgebra and the number formatter only), so sensors,
//! environment models and dynamics validate without importing one another.

use nalgebra::Matrix3;

use crate::numfmt::Num;

/// A parameter that fails validation. Every variant names the offending field with its
/// configuration path (e.g. `panel_pairs[1].panel1.mass_kg`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    /// NaN or ±Inf.
    #[error("{field}: must be finite (got NaN or Inf)")]
    NotFinite {
        /// Field path.
        field: String,
    },
    /// Must be strictly positive.
    #[error("{field}: must be > 0 (got {})", Num(*.value))]
    NotPositive {
        /// Field path.
        field: String,
        /// The value given.
        value: f64,
    },
    /// Must be ≥ 0.
    #[error("{field}: must be >= 0 (got {})", Num(*.value))]
    Negative {
        /// Field path.
        field: String,
        /// The value given.
        value: f64,
    },
    /// Inertia matrix not symmetric.
    #[error("{field}: inertia matrix is not symmetric (max |I - I^T| = {asymmetry:e})")]
    NotSymmetric {
        /// Field path.
        field: String,
        /// Largest asymmetry.
        asymmetry: f64,
    },
    /// Inertia not positive-definite.
    #[error(
        "{field}: inertia is not positive-definite (smallest principal moment {})",
        Num(*.min_eigenvalue)
    )]
    NotPositiveDefinite {
        /// Field path.
        field: String,
        /// Smallest eigenvalue.
        min_eigenvalue: f64,
    },
    /// Principal moments violate the triangle inequality.
    #[error("{field}: principal moments [{}, {}, {}] violate the triangle inequality (each must be <= the sum of the other two)", Num(.moments[0]), Num(.moments[1]), Num(.moments[2]))]
    TriangleInequality {
        /// Field path.
        field: String,
        /// The principal moments.
        moments: [f64; 3],
    },
    /// DCM not orthonormal (or not proper).
    #[error("{field}: DCM is not proper orthonormal within 1e-9 (error {error:e})")]
    NotOrthonormal {
        /// Field path.
        field: String,
        /// max |C Cᵀ − I| or |det C − 1|.
        error: f64,
    },
    /// Hinge-to-CoM distance beyond the panel length.
    #[error("{field}: d ({} m) exceeds the panel length l ({} m)", Num(*.d_m), Num(*.l_m))]
    DExceedsLength {
        /// Field path.
        field: String,
        /// d.
        d_m: f64,
        /// l.
        l_m: f64,
    },
    /// A direction that must be a unit vector is not.
    #[error("{field}: must be a unit vector (norm {}, expected 1 within 1e-6)", Num(*.norm))]
    NotUnit {
        /// Field path.
        field: String,
        /// Its norm.
        norm: f64,
    },
    /// A value beyond a limit given by another field.
    #[error("{field}: |{}| exceeds {limit_field} = {}", Num(*.value), Num(*.limit))]
    Exceeds {
        /// Field path.
        field: String,
        /// The value.
        value: f64,
        /// The key of the limit (in the same table).
        limit_field: &'static str,
        /// The limit.
        limit: f64,
    },
    /// A value that breaks a rule of its own, said in words.
    #[error("{field}: {problem}")]
    Invalid {
        /// Field path.
        field: String,
        /// What is wrong.
        problem: String,
    },
    /// An effector-input vector of the wrong length was supplied.
    #[error("effector inputs: expected {expected} values, got {found}")]
    InputLength {
        /// Expected length.
        expected: usize,
        /// Given length.
        found: usize,
    },
    /// A state vector of the wrong length was supplied.
    #[error("state: expected {expected} effector states, got {found}")]
    StateLength {
        /// Expected length.
        expected: usize,
        /// Given length.
        found: usize,
    },
}

/// Tolerance on ‖\[C\]\[C\]ᵀ − I‖ (max element) and |det C − 1| for a DCM to count as orthonormal.
pub const DCM_ORTHONORMAL_TOL: f64 = 1e-9;
/// Relative tolerance on the asymmetry of an inertia matrix.
pub const INERTIA_SYMMETRY_TOL: f64 = 1e-9;

/// The field path `path.field` (just `field` when `path` is empty).
pub fn join(path: &str, field: &str) -> String {
    if path.is_empty() {
        field.to_string()
    } else {
        format!("{path}.{field}")
    }
}

/// Checks that every value of `field` (at `path`) is finite.
pub fn check_finite(path: &str, field: &str, values: &[f64]) -> Result<(), ParamError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(ParamError::NotFinite {
            field: join(path, field),
        })
    }
}

/// Largest magnitude of a sensor's error term (a noise σ, a bias, a range, an output LSB), in
/// its unit (rad/s, m/s², T, rad, m, …; a coarse sun sensor's output unit). No sensor errs by a
/// million of its units: such a value is a unit slip. The bound also keeps every output finite:
/// near the float range, σ·z or a sum with the truth overflows (a star tracker with
/// σ = 1e155 rad turned its quaternion into NaN at the first sample).
pub const MAX_SENSOR_TERM_SI: f64 = 1e6;

/// Checks that every value of the error term `field` (at `path`) is finite and within
/// ±[`MAX_SENSOR_TERM_SI`]; with `non_negative`, also ≥ 0 (a σ, a range, an LSB).
pub fn check_sensor_term(
    path: &str,
    field: &str,
    values: &[f64],
    non_negative: bool,
) -> Result<(), ParamError> {
    check_finite(path, field, values)?;
    for (i, &v) in values.iter().enumerate() {
        let at = || {
            if values.len() == 1 {
                join(path, field)
            } else {
                format!("{}[{i}]", join(path, field))
            }
        };
        if non_negative && v < 0.0 {
            return Err(ParamError::Negative {
                field: at(),
                value: v,
            });
        }
        if v.abs() > MAX_SENSOR_TERM_SI {
            return Err(ParamError::Invalid {
                field: at(),
                problem: format!(
                    "{} is beyond {} (in its unit): no sensor errs by this much; check the units",
                    Num(v),
                    Num(MAX_SENSOR_TERM_SI)
                ),
            });
        }
    }
    Ok(())
}

/// \[A·m²\] Largest magnetic dipole a spacecraft carries (a torque rod's or a residual): flown
/// torque rods reach a few hundred A·m²; 1e4 leaves a margin and keeps m × B finite and resolved.
pub const MAX_DIPOLE_AM2: f64 = 1e4;

/// \[N\] Largest thrust of one thruster: the largest rocket engine flown (the F-1) made about
/// 6.8e6 N; 1e8 N is a unit slip, and near the float range the force overflows.
pub const MAX_THRUST_NEWTON: f64 = 1e8;

/// Checks that `v` (at `path.field`) is at most `max` in magnitude (`what` names the bound).
pub fn check_at_most(
    path: &str,
    field: &str,
    v: f64,
    max: f64,
    what: &str,
) -> Result<(), ParamError> {
    check_finite(path, field, &[v])?;
    if v.abs() > max {
        return Err(ParamError::Invalid {
            field: join(path, field),
            problem: format!(
                "{} is beyond {} ({what}): check the units",
                Num(v),
                Num(max)
            ),
        });
    }
    Ok(())
}

/// Tolerance on |‖â‖ − 1| for an axis (a wheel's spin axis, a rod's, a thruster's) to count as
/// a unit vector.
pub const UNIT_AXIS_TOL: f64 = 1e-6;

/// Checks that `v` is a finite unit vector within [`UNIT_AXIS_TOL`].
pub fn check_unit_axis(
    path: &str,
    field: &str,
    v: &nalgebra::Vector3<f64>,
) -> Result<(), ParamError> {
    check_finite(path, field, v.as_slice())?;
    let norm = v.norm();
    if (norm - 1.0).abs() > UNIT_AXIS_TOL {
        return Err(ParamError::NotUnit {
            field: join(path, field),
            norm,
        });
    }
    Ok(())
}

/// Checks that `field` (at `path`) is finite and > 0.
pub fn check_positive(path: &str, field: &str, v: f64) -> Result<(), ParamError> {
    check_finite(path, field, &[v])?;
    if v > 0.0 {
        Ok(())
    } else {
        Err(ParamError::NotPositive {
            field: join(path, field),
            value: v,
        })
    }
}

/// Checks that `field` (at `path`) is finite and ≥ 0.
pub fn check_non_negative(path: &str, field: &str, v: f64) -> Result<(), ParamError> {
    check_finite(path, field, &[v])?;
    if v >= 0.0 {
        Ok(())
    } else {
        Err(ParamError::Negative {
            field: join(path, field),
            value: v,
        })
    }
}

/// Checks that principal moments are positive and satisfy the triangle inequality
/// (each moment ≤ the sum of the other two), which any real mass distribution obeys.
pub fn check_principal_moments(path: &str, field: &str, m: &[f64; 3]) -> Result<(), ParamError> {
    // Positivity first for all three, so a negative moment is never reported as a triangle
    // violation.
    let min = m.iter().copied().fold(f64::INFINITY, f64::min);
    if min <= 0.0 {
        return Err(ParamError::NotPositiveDefinite {
            field: join(path, field),
            min_eigenvalue: min,
        });
    }
    for (i, v) in m.iter().enumerate() {
        let others = m[(i + 1) % 3] + m[(i + 2) % 3];
        // A small relative slack admits thin-plate limits (I3 = I1 + I2) up to round-off.
        if *v > others * (1.0 + 1e-12) {
            return Err(ParamError::TriangleInequality {
                field: join(path, field),
                moments: *m,
            });
        }
    }
    Ok(())
}

/// Validates a full inertia matrix: finite, symmetric, positive-definite, triangle inequality on
/// its principal moments.
pub fn check_inertia_matrix(path: &str, field: &str, i: &Matrix3<f64>) -> Result<(), ParamError> {
    check_finite(path, field, i.as_slice())?;
    let scale = i.abs().max().max(f64::MIN_POSITIVE);
    let asym = (i - i.transpose()).abs().max();
    if asym > INERTIA_SYMMETRY_TOL * scale {
        return Err(ParamError::NotSymmetric {
            field: join(path, field),
            asymmetry: asym,
        });
    }
    let eig = i.symmetric_eigenvalues();
    check_principal_moments(path, field, &[eig[0], eig[1], eig[2]])
}

/// Validates a DCM: finite, orthonormal within [`DCM_ORTHONORMAL_TOL`], proper (det = +1).
pub fn check_dcm(path: &str, field: &str, c: &Matrix3<f64>) -> Result<(), ParamError> {
    check_finite(path, field, c.as_slice())?;
    let err = (c * c.transpose() - Matrix3::identity()).abs().max();
    let det = c.determinant();
    if err > DCM_ORTHONORMAL_TOL || (det - 1.0).abs() > DCM_ORTHONORMAL_TOL {
        return Err(ParamError::NotOrthonormal {
            field: join(path, field),
            error: err.max((det - 1.0).abs()),
        });
    }
    Ok(())
}
