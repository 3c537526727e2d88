//! Gravity gradient: the torque (and the matching second-order force) a central gravity field
//! exerts on a vehicle of finite size.
//!
//! # Model
//! Expand the point-mass potential of every mass element about the system centre of mass C to
//! second order in its distance from C (MacCullagh's formula; Schaub & Junkins, *Analytical
//! Mechanics of Space Systems*, 4th ed., §4.5 "Gravity gradient torque"; Hughes, *Spacecraft
//! Attitude Dynamics*, §8.2). With R = r_C/N and \[I_C\] the vehicle's inertia about C, both in B
//! components, R = |R| and μ the gravitational parameter:
//!
//! - potential beyond the point-mass term (GG1):
//!   V = μ/(2R⁵) (3 Rᵀ\[I_C\]R − R² tr\[I_C\]);
//! - torque about C (GG2): L_C = −R × ∂V/∂R|attitude = (3μ/R⁵) R × \[I_C\]R;
//! - force on C (GG3): F = −∂V/∂R = (3μ/(2R⁵)) [(5 Rᵀ\[I_C\]R/R² − tr\[I_C\]) R − 2 \[I_C\]R].
//!
//! The point-mass part −μm/R is the uniform field the spacecraft already applies at C. GG3 is
//! the force that goes with GG2: R × F = −L_C, so the pair moves angular momentum between the
//! orbit and the attitude and leaves the total about the planet's centre unchanged, and the sum
//! orbital + rotational + spring + V is conserved. It is ~I/(mR²) ≈ 10⁻¹¹ of the point-mass
//! force for a 1000 kg, 1000 kg·m² vehicle in LEO, but without it neither invariant holds to
//! round-off, which is how the tests check the model.
//!
//! \[I_C\] is the whole vehicle's inertia *at the stage*: flexing panels and spinning wheels are
//! in it as they are ([`StageState::inertia_pnt_c_b_kg_m2`]). Higher-order terms (O((size/R)³))
//! are neglected: for a 10 m vehicle at 7000 km they are ~10⁻⁶ of GG2.
//!
//! **What is neglected on appended bodies.** The torque and force act on the vehicle as a whole.
//! The gradient also pulls each panel about its own hinge (a generalized force on θ); the seam
//! does not pass external generalized forces to the hinge equations, so that share is left out.
//! Its size is of the order of the panel's own GG torque, 3μ/R³ ΔI ≈ 3·10⁻⁵ N·m for a
//! 25 kg·m² panel in LEO, against hinge stiffnesses of 10–1000 N·m/rad: a θ offset below
//! 3·10⁻⁶ rad. With rigid or locked panels the model is complete to second order.
//!
//! **Basilisk's `GravityGradientEffector`** evaluates GG2 per planet about the CoM with the
//! spacecraft's current inertia, and applies no force (its docs list the torque only). This
//! model adds GG3 so that the energy and the momentum about the planet are invariants to
//! round-off, and evaluates at every RK4 stage.

use nalgebra::{Matrix3, Vector3};

use crate::dynamic_effector::{DynamicEffector, EnvironmentSource, StageState};
use crate::params::Wrench;
use flexdyn_environment::EnvironmentSample;

/// Gravity gradient of a point-mass planet at the origin of N.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GravityGradient {
    /// \[m³/s²\] the planet's gravitational parameter μ.
    pub mu_m3_s2: f64,
}

/// (R², R⁵) of `r_cn_b_m`, the powers every term of GG1–GG3 divides by.
#[inline]
fn r2_r5(r_cn_b_m: &Vector3<f64>) -> (f64, f64) {
    let r2 = r_cn_b_m.norm_squared();
    (r2, r2 * r2 * r2.sqrt())
}

/// (GG3 force, GG2 torque about C) from R = `r_cn_b_m`, [I_C]R = `i_r` and tr[I_C] = `trace`:
/// the only place the two formulas are written.
#[inline]
fn force_and_torque_c(
    mu_m3_s2: f64,
    r_cn_b_m: &Vector3<f64>,
    i_r: &Vector3<f64>,
    trace: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    // One division and one square root: 1/R² and 1/R⁵ = (1/R²)² √(1/R²).
    let inv_r2 = r_cn_b_m.norm_squared().recip();
    let k = 1.5 * mu_m3_s2 * (inv_r2 * inv_r2 * inv_r2.sqrt());
    let radial = 5.0 * r_cn_b_m.dot(i_r) * inv_r2 - trace;
    (
        (r_cn_b_m * radial - i_r * 2.0) * k,
        r_cn_b_m.cross(i_r) * (2.0 * k),
    )
}

/// \[N·m\] GG2: the torque about C for the CoM at `r_cn_b_m` (R, B components) and the inertia
/// about C `inertia_c_b_kg_m2` (B components): (3μ/R⁵) R × \[I_C\]R.
#[inline]
pub fn torque_c_b_nm(
    mu_m3_s2: f64,
    r_cn_b_m: &Vector3<f64>,
    inertia_c_b_kg_m2: &Matrix3<f64>,
) -> Vector3<f64> {
    let i_r = inertia_c_b_kg_m2 * r_cn_b_m;
    force_and_torque_c(mu_m3_s2, r_cn_b_m, &i_r, inertia_c_b_kg_m2.trace()).1
}

/// \[N\] GG3: the second-order force on C, B components:
/// (3μ/(2R⁵)) [(5 Rᵀ\[I_C\]R/R² − tr\[I_C\]) R − 2 \[I_C\]R].
#[inline]
pub fn force_b_newton(
    mu_m3_s2: f64,
    r_cn_b_m: &Vector3<f64>,
    inertia_c_b_kg_m2: &Matrix3<f64>,
) -> Vector3<f64> {
    let i_r = inertia_c_b_kg_m2 * r_cn_b_m;
    force_and_torque_c(mu_m3_s2, r_cn_b_m, &i_r, inertia_c_b_kg_m2.trace()).0
}

/// \[J\] GG1: the potential beyond the point-mass term, μ/(2R⁵) (3 Rᵀ\[I_C\]R − R² tr\[I_C\]).
pub fn potential_j(
    mu_m3_s2: f64,
    r_cn_b_m: &Vector3<f64>,
    inertia_c_b_kg_m2: &Matrix3<f64>,
) -> f64 {
    let (r2, r5) = r2_r5(r_cn_b_m);
    0.5 * mu_m3_s2 / r5
        * (3.0 * r_cn_b_m.dot(&(inertia_c_b_kg_m2 * r_cn_b_m)) - r2 * inertia_c_b_kg_m2.trace())
}

impl GravityGradient {
    /// \[J\] GG1 at `stage`.
    pub fn potential_at(&self, stage: &StageState) -> f64 {
        potential_j(
            self.mu_m3_s2,
            &(stage.dcm_bn * stage.r_cn_n_m),
            &stage.inertia_pnt_c_b_kg_m2(),
        )
    }
}

impl DynamicEffector for GravityGradient {
    fn name(&self) -> &str {
        "gravity_gradient"
    }

    fn environment_source(&self) -> Option<EnvironmentSource> {
        Some(EnvironmentSource::GravityGradient)
    }

    fn add_force_torque(&mut self, stage: &StageState, _env: &EnvironmentSample, sum: &mut Wrench) {
        let r_cn_b = stage.dcm_bn * stage.r_cn_n_m;
        // [I_C] is needed only as [I_C]R and tr[I_C]. By the parallel-axis theorem
        // [I_C] = [I_B] − m (|c|² 𝟙 − c cᵀ) (see `StageState::inertia_pnt_c_b_kg_m2`), so
        // [I_C]R = [I_B]R − m (|c|² R − c (c·R)) and tr[I_C] = tr[I_B] − 2 m |c|², without
        // forming the matrix.
        let c = &stage.r_cb_b_m;
        let m = stage.mass_kg;
        let c2 = c.norm_squared();
        let i_r = stage.inertia_pnt_b_b_kg_m2 * r_cn_b - (r_cn_b * c2 - c * c.dot(&r_cn_b)) * m;
        let trace = stage.inertia_pnt_b_b_kg_m2.trace() - 2.0 * m * c2;
        let (force, torque_c) = force_and_torque_c(self.mu_m3_s2, &r_cn_b, &i_r, trace);
        // GG3 acts at C: at B it is the same force plus the couple c × F.
        sum.force_b_newton += force;
        sum.torque_b_nm += torque_c + c.cross(&force);
    }

    /// Nothing: its parameters are configuration (a held Sun is memoised from its inputs).
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    const MU: f64 = 3.986004418e14;

    /// Schaub & Junkins' component form in principal axes, with the direction cosines
    /// c = R̂: L = 3μ/R³ [(I3 − I2) c2 c3, (I1 − I3) c1 c3, (I2 − I1) c1 c2].
    #[test]
    fn torque_matches_the_principal_axis_component_form() {
        let (i1, i2, i3) = (120.0, 90.0, 45.0);
        let inertia = Matrix3::from_diagonal(&Vector3::new(i1, i2, i3));
        let r = 7.0e6;
        let c = Vector3::new(0.3, -0.5, 0.2).normalize();
        let l = torque_c_b_nm(MU, &(c * r), &inertia);
        let k = 3.0 * MU / (r * r * r);
        let expected = Vector3::new(
            k * (i3 - i2) * c.y * c.z,
            k * (i1 - i3) * c.x * c.z,
            k * (i2 - i1) * c.x * c.y,
        );
        assert!(
            (l - expected).norm() <= 1e-14 * expected.norm(),
            "{l:?} vs {expected:?}"
        );
    }

    /// GG2 and GG3 are the derivatives of GG1: F = −∂V/∂R by central differences, and a small
    /// rotation δφ of the body changes V by −L·δφ.
    #[test]
    fn force_and_torque_are_the_gradients_of_the_potential() {
        let inertia = Matrix3::new(110.0, 3.0, -2.0, 3.0, 95.0, 4.0, -2.0, 4.0, 60.0);
        let r = Vector3::new(4.1e6, -3.3e6, 4.4e6);
        let f = force_b_newton(MU, &r, &inertia);
        let dr = 1.0;
        for k in 0..3 {
            let mut e = Vector3::zeros();
            e[k] = dr;
            let dv = (potential_j(MU, &(r + e), &inertia) - potential_j(MU, &(r - e), &inertia))
                / (2.0 * dr);
            assert!(
                (f[k] + dv).abs() <= 1e-6 * f.norm(),
                "axis {k}: F = {}, −∂V = {}",
                f[k],
                -dv
            );
        }
        // Rotating the body by δφ (B components) maps R (in B) to R − δφ × R.
        let l = torque_c_b_nm(MU, &r, &inertia);
        let dphi = 1e-6;
        for k in 0..3 {
            let mut e = Vector3::zeros();
            e[k] = dphi;
            let dv = (potential_j(MU, &(r - e.cross(&r)), &inertia)
                - potential_j(MU, &(r + e.cross(&r)), &inertia))
                / (2.0 * dphi);
            assert!(
                (l[k] + dv).abs() <= 1e-6 * l.norm(),
                "axis {k}: L = {}, −∂V/∂φ = {}",
                l[k],
                -dv
            );
        }
        // R × F = −L: the pair conserves the angular momentum about the planet's centre.
        assert!((r.cross(&f) + l).norm() <= 1e-12 * l.norm());
    }

    /// The stage path forms neither [I_C] nor a second [I_C]R: it must agree with the matrix
    /// formulas (GG2, GG3 with [I_C] from the parallel-axis theorem) and the couple c × F.
    #[test]
    fn the_stage_path_equals_the_matrix_formulas() {
        let sigma = Vector3::new(0.1, -0.25, 0.3);
        let stage = StageState {
            t_step_ns: 0,
            dt_stage_s: 0.0,
            r_bn_n_m: Vector3::new(4.1e6, -3.3e6, 4.4e6),
            v_bn_n_m_s: Vector3::zeros(),
            sigma_bn: sigma,
            dcm_bn: flexdyn_kernel::attitude::mrp_to_dcm(&sigma),
            omega_bn_b_rad_s: Vector3::zeros(),
            mass_kg: 850.0,
            r_cb_b_m: Vector3::new(0.4, -0.3, 1.2),
            r_cn_n_m: Vector3::new(4.1e6 + 0.5, -3.3e6 + 0.9, 4.4e6 - 0.2),
            inertia_pnt_b_b_kg_m2: Matrix3::new(
                1900.0, 35.0, -20.0, 35.0, 1650.0, 44.0, -20.0, 44.0, 900.0,
            ),
        };
        let mut sum = Wrench::default();
        GravityGradient { mu_m3_s2: MU }.add_force_torque(
            &stage,
            &EnvironmentSample::default(),
            &mut sum,
        );
        let r = stage.dcm_bn * stage.r_cn_n_m;
        let i_c = stage.inertia_pnt_c_b_kg_m2();
        let force = force_b_newton(MU, &r, &i_c);
        let torque = torque_c_b_nm(MU, &r, &i_c) + stage.r_cb_b_m.cross(&force);
        assert!((sum.force_b_newton - force).norm() <= 1e-13 * force.norm());
        assert!((sum.torque_b_nm - torque).norm() <= 1e-13 * torque.norm());
        assert!(torque.norm() > 0.0 && force.norm() > 0.0);
    }

    #[test]
    fn a_sphere_feels_no_torque_and_no_force() {
        let inertia = Matrix3::from_diagonal_element(100.0);
        let r: Vector3<f64> = Vector3::new(4.1e6, -3.3e6, 4.4e6);
        // Zero up to the rounding of [I]R: relative to the torque scale 3μ I/R³ and the force
        // scale 3μ I/R⁴ of an unbalanced body.
        let r3 = r.norm().powi(3);
        assert!(torque_c_b_nm(MU, &r, &inertia).norm() <= 1e-14 * 3.0 * MU * 100.0 / r3);
        // F = (3μ/2R⁵)(5 I − 3 I − 2 I) R = 0.
        assert!(
            force_b_newton(MU, &r, &inertia).norm() <= 1e-14 * 3.0 * MU * 100.0 / (r3 * r.norm())
        );
    }
}
