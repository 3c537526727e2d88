//! The centred dipole of the IGRF degree-1 coefficients, and the torque on a magnetic dipole.
//!
//! The degree-1 part of the IGRF potential is V₁ = a³ (g₁¹ x + h₁¹ y + g₁⁰ z) / r³ (the n = 1
//! term of the synthesis in [`super::igrf`], with P₁⁰ = cos θ and P₁¹ = sin θ), which is the
//! potential (μ0/4π) m·r / r³ of a dipole at the Earth's centre with moment
//! m = (4π/μ0) a³ (g₁¹, h₁¹, g₁⁰) (Langel 1987, §4.1; Wertz, *Spacecraft Attitude
//! Determination and Control*, 1978, App. H). Its field is the closed form
//!
//! B = (μ0/4π) [3 (m·r̂) r̂ − m] / r³ = (a/r)³ [3 (k·r̂) r̂ − k], k = (g₁¹, h₁¹, g₁⁰).
//!
//! [`CentredDipole::tilted`] keeps all three degree-1 coefficients (the axis through the
//! geomagnetic poles, 80.9° N 72.8° W in 2025.0 from these coefficients); [`CentredDipole::axial`] keeps g₁⁰ only (the
//! axis along the Earth's rotation axis). μ0/4π is taken as 1e-7 T·m/A, the value the IGRF
//! literature uses for the moment (CODATA 2018 differs by 5.5e-10, relative).

use nalgebra::Vector3;

use super::igrf::{GaussCoefficients, IGRF_REFERENCE_RADIUS_M};

/// [T·m/A] μ0/4π.
const MU0_OVER_4PI: f64 = 1e-7;

/// A magnetic dipole at the Earth's centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentredDipole {
    /// [A·m²] the dipole moment, Earth-fixed components.
    pub m_ecef_am2: Vector3<f64>,
}

impl CentredDipole {
    /// The tilted dipole of `coefficients`' g₁⁰, g₁¹ and h₁¹.
    pub fn tilted(coefficients: &GaussCoefficients) -> Self {
        let c = coefficients;
        Self::from_k_nt(Vector3::new(c.g_nt[1][1], c.h_nt[1][1], c.g_nt[1][0]))
    }

    /// The axial dipole of `coefficients`' g₁⁰ alone (aligned with the rotation axis).
    pub fn axial(coefficients: &GaussCoefficients) -> Self {
        Self::from_k_nt(Vector3::new(0.0, 0.0, coefficients.g_nt[1][0]))
    }

    fn from_k_nt(k_nt: Vector3<f64>) -> Self {
        Self::from_coefficients_nt(k_nt, IGRF_REFERENCE_RADIUS_M)
    }

    /// The dipole of given degree-1 Gauss coefficients `k_nt` = (g₁¹, h₁¹, g₁⁰) \[nT\] at the
    /// reference radius `radius_m` \[m\]: m = (4π/μ0) a³ k (module docs). With IGRF's
    /// a = 6371.2 km and its coefficients at a date this is [`Self::tilted`]'s dipole to the bit.
    pub fn from_coefficients_nt(k_nt: Vector3<f64>, radius_m: f64) -> Self {
        let a3 = radius_m.powi(3);
        CentredDipole {
            m_ecef_am2: k_nt * 1e-9 * a3 / MU0_OVER_4PI,
        }
    }

    /// The dipole of moment `moment_am2` \[A·m²\] along the Earth-fixed unit vector `axis_e`
    /// (the direction of **m**, which for the Earth points to the southern hemisphere: the
    /// field lines leave the Earth in the south).
    pub fn from_moment(moment_am2: f64, axis_e: Vector3<f64>) -> Self {
        CentredDipole {
            m_ecef_am2: axis_e * moment_am2,
        }
    }

    /// \[T\] the dipole's field in Earth-fixed components at `r_ecef_m` \[m\]:
    /// (μ0/4π) [3 (m·r̂) r̂ − m] / r³. Allocation-free; zero at the centre.
    pub fn field_ecef_t(&self, r_ecef_m: &Vector3<f64>) -> Vector3<f64> {
        dipole_field_t(&self.m_ecef_am2, r_ecef_m)
    }
}

/// \[T\] the field of a point dipole of moment `m_am2` [A·m²] at `r_m` \[m\] from it (any frame, the
/// same for both): (μ0/4π) [3 (m·r̂) r̂ − m] / r³ (Jackson, *Classical Electrodynamics*, 3rd ed.,
/// eq. 5.56). Allocation-free; zero at the dipole itself.
pub fn dipole_field_t(m_am2: &Vector3<f64>, r_m: &Vector3<f64>) -> Vector3<f64> {
    let r = r_m.norm();
    if r == 0.0 {
        return Vector3::zeros();
    }
    let r_hat = r_m / r;
    MU0_OVER_4PI * (3.0 * m_am2.dot(&r_hat) * r_hat - m_am2) / (r * r * r)
}

/// [N·m] the torque τ = m × B on a magnetic dipole `m_b_am2` [A·m²] (a spacecraft's residual
/// dipole, or a magnetorquer's commanded moment) in the field `b_b_t` \[T\], both in B components
/// (Griffiths, *Introduction to Electrodynamics*, 4th ed., eq. 6.1). The field is uniform over
/// the vehicle, so there is no force.
#[inline]
pub fn dipole_torque_b_nm(m_b_am2: &Vector3<f64>, b_b_t: &Vector3<f64>) -> Vector3<f64> {
    m_b_am2.cross(b_b_t)
}
