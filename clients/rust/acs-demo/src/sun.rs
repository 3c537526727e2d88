//! Sun acquisition: the Sun direction from an array of coarse sun sensors (cosine detectors),
//! and a wheel law that turns a body axis (a panel normal) onto it while damping the rate.
//!
//! - **Sun vector.** A cosine detector with normal n̂_i reads I_i = I₀ max(0, n̂_i · ŝ). With
//!   detectors in opposite pairs along three axes, the pair along ±ê_k reads I₀|ŝ_k| on one side
//!   and 0 on the other, so Σ I_i n̂_i = I₀ ŝ exactly (Wertz, *Spacecraft Attitude Determination
//!   and Control*, §7.1.1). For other layouts the normalised sum is the usual estimate.
//! - **Law.** τ = k_p (n̂ × ŝ) − k_d ω: the first term is a torque about the axis that turns n̂
//!   towards ŝ, with magnitude k_p sin θ for the angle θ between them; the second damps the
//!   rate (Sidi §7.2). In eclipse (no reading above the threshold) only the damping acts.

use nalgebra::Vector3;

/// The Sun direction in B from detector normals `normals_b` and readings `currents` (any unit),
/// or `None` when every reading is at or below `threshold` (eclipse, or the Sun outside every
/// field of view).
pub fn sun_direction_b(
    normals_b: &[Vector3<f64>],
    currents: &[f64],
    threshold: f64,
) -> Option<Vector3<f64>> {
    if !currents.iter().any(|&c| c > threshold) {
        return None;
    }
    let sum: Vector3<f64> = normals_b
        .iter()
        .zip(currents)
        .map(|(n, &c)| n * c.max(0.0))
        .sum();
    (sum.norm() > 0.0).then(|| sum.normalize())
}

/// The sun-acquisition torque on the hub: k_p (n̂ × ŝ) − k_d ω, or rate damping alone without
/// a Sun direction.
pub fn sun_acquisition_torque_b_nm(
    k_p_nm: f64,
    k_d_nms: f64,
    axis_b: &Vector3<f64>,
    sun_b: Option<&Vector3<f64>>,
    omega_bn_b_rad_s: &Vector3<f64>,
) -> Vector3<f64> {
    let point = sun_b.map_or(Vector3::zeros(), |s| axis_b.cross(s) * k_p_nm);
    point - omega_bn_b_rad_s * k_d_nms
}

/// \[rad\] the angle between a body axis and the Sun direction.
pub fn angle_to_sun_rad(axis_b: &Vector3<f64>, sun_b: &Vector3<f64>) -> f64 {
    axis_b
        .normalize()
        .dot(&sun_b.normalize())
        .clamp(-1.0, 1.0)
        .acos()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Six detectors on ±x, ±y, ±z recover the Sun direction exactly (module docs).
    #[test]
    fn opposite_pairs_give_the_sun_direction_exactly() {
        let normals: Vec<Vector3<f64>> = [1.0, -1.0]
            .iter()
            .flat_map(|s| (0..3).map(move |k| Vector3::ith(k, *s)))
            .collect();
        let sun = Vector3::new(0.3, -0.5, 0.81).normalize();
        let currents: Vec<f64> = normals.iter().map(|n| 2.5 * n.dot(&sun).max(0.0)).collect();
        let s = sun_direction_b(&normals, &currents, 0.01).unwrap();
        assert!((s - sun).norm() < 1e-15, "{s:?} vs {sun:?}");
        assert!(
            sun_direction_b(&normals, &[0.0; 6], 0.01).is_none(),
            "eclipse"
        );
    }

    /// The pointing torque turns the axis towards the Sun: about n̂ × ŝ, of size k_p sin θ; with
    /// the axis on the Sun only the damping remains.
    #[test]
    fn the_torque_turns_the_axis_onto_the_sun_and_damps_the_rate() {
        let n = Vector3::new(0.0, 1.0, 0.0);
        let s = Vector3::new(1.0, 1.0, 0.0).normalize();
        let tau = sun_acquisition_torque_b_nm(2.0, 0.0, &n, Some(&s), &Vector3::zeros());
        let theta = angle_to_sun_rad(&n, &s);
        assert!((theta - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
        assert!((tau.norm() - 2.0 * theta.sin()).abs() < 1e-15);
        // A small rotation about τ moves n̂ towards ŝ: d(n̂·ŝ) = (τ̂ × n̂)·ŝ > 0.
        assert!(tau.normalize().cross(&n).dot(&s) > 0.0);
        let w = Vector3::new(0.01, -0.02, 0.03);
        let tau = sun_acquisition_torque_b_nm(2.0, 50.0, &s, Some(&s), &w);
        assert!((tau + w * 50.0).norm() < 1e-15);
        let tau = sun_acquisition_torque_b_nm(2.0, 50.0, &n, None, &w);
        assert_eq!(tau, -w * 50.0);
    }
}
