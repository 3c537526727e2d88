//! Attitude kinematics: modified Rodrigues parameters (MRP), direction cosine matrices and
//! quaternions.
//!
//! One implementation for the simulator (`flexdyn_kernel::attitude` re-exports this module) and for
//! flight code (the demo controller `flexdyn-acs-demo`), which needs the same kernels without
//! linking the simulator. Behind the `attitude` feature (nalgebra). The property tests of the
//! kernels against nalgebra's independent rotation code are in the workspace's `crates/dynamics/tests/attitude.rs`.
//!
//! Conventions (Schaub & Junkins, *Analytical Mechanics of Space Systems*):
//! - `sigma_bn` is the MRP set of frame B relative to N: σ = ê tan(Φ/4).
//! - `dcm_bn` = \[BN\] maps N components to B components: `v_b = dcm_bn * v_n`.
//! - `q_bn` = (β0, β1, β2, β3), **scalar first**, the Euler parameters of the same rotation, so
//!   that \[BN\] is the usual Euler-parameter DCM of q_bn.
//! - The shadow set σ_s = −σ/|σ|² describes the same attitude; [`mrp_switch`] swaps to it when
//!   |σ| > 1, which keeps |σ| ≤ 1.

use nalgebra::{Matrix3, Vector3, Vector4};

/// Skew-symmetric ("tilde") matrix: `tilde(a) * b == a.cross(&b)`.
#[inline(always)]
pub fn tilde(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// \[BN\] from the MRP set σ_BN: \[BN\] = I + (8[σ̃]² − 4(1 − σ²)[σ̃]) / (1 + σ²)².
pub fn mrp_to_dcm(sigma_bn: &Vector3<f64>) -> Matrix3<f64> {
    let s2 = sigma_bn.norm_squared();
    let st = tilde(sigma_bn);
    let den = (1.0 + s2) * (1.0 + s2);
    Matrix3::identity() + (st * st * 8.0 - st * (4.0 * (1.0 - s2))) / den
}

/// MRP set (with |σ| ≤ 1) of a proper orthonormal DCM \[BN\], through the quaternion.
pub fn dcm_to_mrp(dcm_bn: &Matrix3<f64>) -> Vector3<f64> {
    quat_to_mrp(&dcm_to_quat(dcm_bn))
}

/// Quaternion (scalar first) of the MRP set: β0 = (1 − σ²)/(1 + σ²), βi = 2σi/(1 + σ²).
pub fn mrp_to_quat(sigma_bn: &Vector3<f64>) -> Vector4<f64> {
    let s2 = sigma_bn.norm_squared();
    let den = 1.0 + s2;
    Vector4::new(
        (1.0 - s2) / den,
        2.0 * sigma_bn.x / den,
        2.0 * sigma_bn.y / den,
        2.0 * sigma_bn.z / den,
    )
}

/// MRP set of a unit quaternion (scalar first), choosing the set with |σ| ≤ 1 (β0 ≥ 0).
pub fn quat_to_mrp(q_bn: &Vector4<f64>) -> Vector3<f64> {
    let q = if q_bn[0] < 0.0 { -q_bn } else { *q_bn };
    let den = 1.0 + q[0];
    Vector3::new(q[1] / den, q[2] / den, q[3] / den)
}

/// \[BN\] from a unit quaternion (scalar first).
pub fn quat_to_dcm(q: &Vector4<f64>) -> Matrix3<f64> {
    let (b0, b1, b2, b3) = (q[0], q[1], q[2], q[3]);
    Matrix3::new(
        b0 * b0 + b1 * b1 - b2 * b2 - b3 * b3,
        2.0 * (b1 * b2 + b0 * b3),
        2.0 * (b1 * b3 - b0 * b2),
        2.0 * (b1 * b2 - b0 * b3),
        b0 * b0 - b1 * b1 + b2 * b2 - b3 * b3,
        2.0 * (b2 * b3 + b0 * b1),
        2.0 * (b1 * b3 + b0 * b2),
        2.0 * (b2 * b3 - b0 * b1),
        b0 * b0 - b1 * b1 - b2 * b2 + b3 * b3,
    )
}

/// Unit quaternion (scalar first, β0 ≥ 0) of a proper orthonormal DCM, by Sheppard's method.
pub fn dcm_to_quat(c: &Matrix3<f64>) -> Vector4<f64> {
    let tr = c.trace();
    let b2 = [
        0.25 * (1.0 + tr),
        0.25 * (1.0 + 2.0 * c[(0, 0)] - tr),
        0.25 * (1.0 + 2.0 * c[(1, 1)] - tr),
        0.25 * (1.0 + 2.0 * c[(2, 2)] - tr),
    ];
    let mut i_max = 0;
    for i in 1..4 {
        if b2[i] > b2[i_max] {
            i_max = i;
        }
    }
    let q = match i_max {
        0 => {
            let b0 = b2[0].sqrt();
            Vector4::new(
                b0,
                (c[(1, 2)] - c[(2, 1)]) / (4.0 * b0),
                (c[(2, 0)] - c[(0, 2)]) / (4.0 * b0),
                (c[(0, 1)] - c[(1, 0)]) / (4.0 * b0),
            )
        }
        1 => {
            let b1 = b2[1].sqrt();
            Vector4::new(
                (c[(1, 2)] - c[(2, 1)]) / (4.0 * b1),
                b1,
                (c[(0, 1)] + c[(1, 0)]) / (4.0 * b1),
                (c[(2, 0)] + c[(0, 2)]) / (4.0 * b1),
            )
        }
        2 => {
            let b2v = b2[2].sqrt();
            Vector4::new(
                (c[(2, 0)] - c[(0, 2)]) / (4.0 * b2v),
                (c[(0, 1)] + c[(1, 0)]) / (4.0 * b2v),
                b2v,
                (c[(1, 2)] + c[(2, 1)]) / (4.0 * b2v),
            )
        }
        _ => {
            let b3 = b2[3].sqrt();
            Vector4::new(
                (c[(0, 1)] - c[(1, 0)]) / (4.0 * b3),
                (c[(2, 0)] + c[(0, 2)]) / (4.0 * b3),
                (c[(1, 2)] + c[(2, 1)]) / (4.0 * b3),
                b3,
            )
        }
    };
    if q[0] < 0.0 {
        -q
    } else {
        q
    }
}

/// MRP kinematic differential equation: σ̇ = ¼ [(1 − σ²) I + 2[σ̃] + 2σσᵀ] ω, with ω = ω_BN in B.
#[inline(always)]
pub fn mrp_rate(sigma_bn: &Vector3<f64>, omega_bn_b: &Vector3<f64>) -> Vector3<f64> {
    let s2 = sigma_bn.norm_squared();
    (omega_bn_b * (1.0 - s2)
        + sigma_bn.cross(omega_bn_b) * 2.0
        + sigma_bn * (2.0 * sigma_bn.dot(omega_bn_b)))
        * 0.25
}

/// Switches σ to its shadow set −σ/|σ|² when |σ| > 1. Returns true if it switched.
#[inline]
pub fn mrp_switch(sigma_bn: &mut Vector3<f64>) -> bool {
    let s2 = sigma_bn.norm_squared();
    if s2 > 1.0 {
        *sigma_bn = -*sigma_bn / s2;
        true
    } else {
        false
    }
}

/// Principal-axis rotation by `angle_rad` about the first axis: M1(a) = [[1, 0, 0], [0, c, s], [0, −s, c]].
#[inline]
pub fn m1(angle_rad: f64) -> Matrix3<f64> {
    let (s, c) = angle_rad.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, s, 0.0, -s, c)
}

/// Principal-axis rotation by `angle_rad` about the second axis: M2(a) = [[c, 0, −s], [0, 1, 0], [s, 0, c]].
#[inline]
pub fn m2(angle_rad: f64) -> Matrix3<f64> {
    let (s, c) = angle_rad.sin_cos();
    Matrix3::new(c, 0.0, -s, 0.0, 1.0, 0.0, s, 0.0, c)
}

/// Principal-axis rotation by `angle_rad` about the third axis: M3(a) = [[c, s, 0], [−s, c, 0], [0, 0, 1]].
#[inline]
pub fn m3(angle_rad: f64) -> Matrix3<f64> {
    let (s, c) = angle_rad.sin_cos();
    Matrix3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0)
}

/// MRP error σ_BR of B relative to R, from σ_BN and σ_RN: \[BR\] = \[BN\]\[RN\]ᵀ, returned with |σ| ≤ 1.
pub fn mrp_error(sigma_bn: &Vector3<f64>, sigma_rn: &Vector3<f64>) -> Vector3<f64> {
    dcm_to_mrp(&(mrp_to_dcm(sigma_bn) * mrp_to_dcm(sigma_rn).transpose()))
}
