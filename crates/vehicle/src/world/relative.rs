//! Relative motion of one vehicle (the deputy) about another (the chief) in the chief's Hill
//! frame H (also called LVLH or RSW): x̂ radial (along r_C), ẑ along the orbit normal
//! (along h = r_C × v_C), ŷ = ẑ × x̂ (along-track, the velocity direction on a circular orbit).
//! Vallado, *Fundamentals of Astrodynamics and Applications* (4th ed.), §6.8 (the RSW frame and
//! the Hill/Clohessy–Wiltshire equations); Schaub & Junkins, *Analytical Mechanics of Space
//! Systems* (4th ed.), §14.2 (eq. 14.5–14.8 for the frame and its rate).
//!
//! Every point here is a vehicle's system centre of mass C (the point whose motion an orbit
//! is), not its body point B.
//!
//! The frame's angular velocity is taken as ω_H/N = (|h| / |r|²) ẑ, the rate of the radial
//! direction about the orbit normal. It is exact when the chief's acceleration lies in its
//! orbit plane (point-mass gravity). An out-of-plane acceleration a (J2, drag) adds a roll rate
//! ω_x = |r| (a·ĥ)/|h| (Schaub & Junkins eq. 14.8), which this leaves out: it only changes the
//! relative *velocity*, by ω_x × ρ (up to ≈ 1.5 mm/s per km of separation under J2 at 7000 km, where
//! a·ĥ ≤ 1.5 J2 μ R²/r⁴ ≈ 0.011 m/s²).

use nalgebra::{Matrix3, Vector3};

use flexdyn_dynamics::Spacecraft;

/// The deputy's state relative to the chief, both taken at their centres of mass.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RelativeState {
    /// \[m\] r_Cd/Cc, the deputy's centre of mass relative to the chief's, H components.
    pub r_dc_h_m: Vector3<f64>,
    /// \[m/s\] its time derivative as seen in the rotating frame H, H components.
    pub v_dc_h_m_s: Vector3<f64>,
    /// \[m\] |r_Cd/Cc|.
    pub range_m: f64,
    /// \[m/s\] d|r_Cd/Cc|/dt (frame-independent: a rotation does not change a length).
    pub range_rate_m_s: f64,
}

/// C_HN, the direction cosine matrix from N to the Hill frame of an orbit at (r, v) in N: its
/// rows are x̂, ŷ, ẑ in N components. `None` if r and v are parallel (no orbit plane).
pub fn dcm_hn(r_n_m: &Vector3<f64>, v_n_m_s: &Vector3<f64>) -> Option<Matrix3<f64>> {
    let h = r_n_m.cross(v_n_m_s);
    let (r, h_norm) = (r_n_m.norm(), h.norm());
    if !(r > 0.0 && h_norm > 0.0) {
        return None;
    }
    let x = r_n_m / r;
    let z = h / h_norm;
    let y = z.cross(&x);
    Some(Matrix3::from_rows(&[
        x.transpose(),
        y.transpose(),
        z.transpose(),
    ]))
}

/// \[rad/s\] ω_H/N in H components: (0, 0, |h|/|r|²).
fn omega_hn_h(r_n_m: &Vector3<f64>, v_n_m_s: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(0.0, 0.0, r_n_m.cross(v_n_m_s).norm() / r_n_m.norm_squared())
}

/// The deputy (r_d, v_d) relative to the chief (r_c, v_c), all centre-of-mass states in N.
/// The transport theorem gives the rate seen in H: ρ' = C_HN (v_d − v_c) − ω_H/N × ρ.
/// `None` if the chief has no orbit plane.
pub fn relative_state_hill(
    r_c_n_m: &Vector3<f64>,
    v_c_n_m_s: &Vector3<f64>,
    r_d_n_m: &Vector3<f64>,
    v_d_n_m_s: &Vector3<f64>,
) -> Option<RelativeState> {
    let c_hn = dcm_hn(r_c_n_m, v_c_n_m_s)?;
    let dr_n = r_d_n_m - r_c_n_m;
    let dv_n = v_d_n_m_s - v_c_n_m_s;
    let r_dc_h_m = c_hn * dr_n;
    let v_dc_h_m_s = c_hn * dv_n - omega_hn_h(r_c_n_m, v_c_n_m_s).cross(&r_dc_h_m);
    let range_m = dr_n.norm();
    let range_rate_m_s = if range_m > 0.0 {
        dr_n.dot(&dv_n) / range_m
    } else {
        0.0
    };
    Some(RelativeState {
        r_dc_h_m,
        v_dc_h_m_s,
        range_m,
        range_rate_m_s,
    })
}

/// The inverse of [`relative_state_hill`]: the deputy's (r, v) in N from the chief's and the
/// Hill-frame offset and its rate seen in H. `None` if the chief has no orbit plane.
pub fn deputy_state_n(
    r_c_n_m: &Vector3<f64>,
    v_c_n_m_s: &Vector3<f64>,
    r_dc_h_m: &Vector3<f64>,
    v_dc_h_m_s: &Vector3<f64>,
) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let c_nh = dcm_hn(r_c_n_m, v_c_n_m_s)?.transpose();
    let omega = omega_hn_h(r_c_n_m, v_c_n_m_s);
    Some((
        r_c_n_m + c_nh * r_dc_h_m,
        v_c_n_m_s + c_nh * (v_dc_h_m_s + omega.cross(r_dc_h_m)),
    ))
}

/// \[m\], \[m/s\] the system centre of mass's position and velocity in N at the spacecraft's
/// current state: r_C/N = r_B/N + C_NB c_B, v_C/N = v_B/N + C_NB ċ_B, with c and ċ from
/// [`Spacecraft::center_of_mass`] (as in [`Spacecraft::conserved_at`]).
pub fn com_state_n(sc: &Spacecraft) -> (Vector3<f64>, Vector3<f64>) {
    let (_, c_b, c_dot_b) = sc.center_of_mass();
    let x = sc.state();
    let dcm_nb = flexdyn_kernel::attitude::mrp_to_dcm(&x.sigma_bn).transpose();
    (x.r_bn_n + dcm_nb * c_b, x.v_bn_n + dcm_nb * c_dot_b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hill_round_trip_and_frame() {
        let r_c = Vector3::new(7.0e6, 1.0e5, -2.0e5);
        let v_c = Vector3::new(-100.0, 7.5e3, 1.0e3);
        let rho = Vector3::new(10.0, -200.0, 30.0);
        let rho_dot = Vector3::new(0.01, -0.2, 0.05);
        let (r_d, v_d) = deputy_state_n(&r_c, &v_c, &rho, &rho_dot).unwrap();
        let rel = relative_state_hill(&r_c, &v_c, &r_d, &v_d).unwrap();
        assert!((rel.r_dc_h_m - rho).norm() < 1e-8);
        assert!((rel.v_dc_h_m_s - rho_dot).norm() < 1e-11);
        assert!((rel.range_m - rho.norm()).abs() < 1e-8);
        // d|ρ|/dt = ρ·ρ'/|ρ| in any frame (ρ·(ω × ρ) = 0).
        assert!((rel.range_rate_m_s - rho.dot(&rho_dot) / rho.norm()).abs() < 1e-11);
        // x̂ along r, ẑ along h, right-handed.
        let c = dcm_hn(&r_c, &v_c).unwrap();
        assert!((c * r_c - Vector3::new(r_c.norm(), 0.0, 0.0)).norm() < 1e-6);
        assert!((c.determinant() - 1.0).abs() < 1e-14);
        assert!(dcm_hn(&r_c, &(r_c * 2.0)).is_none());
    }

    #[test]
    fn a_deputy_fixed_in_h_has_no_rate_in_h() {
        // On a circular orbit, a point fixed in H moves with ω × ρ in N: its rate in H is 0.
        let mu: f64 = 3.986004415e14;
        let r = 7.0e6;
        let n = (mu / (r * r * r)).sqrt();
        let r_c = Vector3::new(r, 0.0, 0.0);
        let v_c = Vector3::new(0.0, n * r, 0.0);
        let rho = Vector3::new(0.0, -100.0, 0.0);
        let (_, v_d) = deputy_state_n(&r_c, &v_c, &rho, &Vector3::zeros()).unwrap();
        // ω × ρ = n ẑ × (−100 ŷ) = +100 n x̂.
        assert!((v_d - v_c - Vector3::new(100.0 * n, 0.0, 0.0)).norm() < 1e-12);
    }
}
