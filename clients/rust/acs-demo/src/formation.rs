//! Formation flying, the deputy's side: a relative station in the chief's Hill frame held with
//! a body force, and an attitude that points a body axis at the chief.
//!
//! - Hill (LVLH) frame H of the chief (Clohessy & Wiltshire 1960; Schaub & Junkins,
//!   *Analytical Mechanics of Space Systems*, 4th ed., §14.2): x̂ = r_c/|r_c| (radial),
//!   ẑ = (r_c × v_c)/|r_c × v_c| (orbit normal), ŷ = ẑ × x̂ (along-track); it turns at
//!   ω_HN = (r_c × v_c)/|r_c|². The deputy relative to the chief: ρ_H = \[HN\](r_d − r_c) and
//!   ρ̇_H = \[HN\](v_d − v_c) − ω_HN × ρ (the transport theorem).
//! - Station keeping: a PD law on the Hill-frame error, a_H = −ω_c² (ρ − ρ*) − 2 ζ ω_c ρ̇, as a
//!   body force F_B = m \[BN\]\[NH\] a_H. With ω_c ≫ n the CW coupling (at most 3n²|ρ − ρ*| and
//!   2n|ρ̇|) is a small perturbation of the closed loop's ω_c² + 2ζω_c s + s² (ρ* on the
//!   along-track axis is a CW equilibrium, so the station needs no force).
//! - Pointing: the reference frame R has r̂₁ = the unit vector from the deputy to the chief,
//!   r̂₂ = ẑ × r̂₁ normalised, r̂₃ = r̂₁ × r̂₂; the MRP PD law of the demo controller
//!   (L = −Kσ_BR − P(ω_BN − ω_RN)) turns body x̂ onto r̂₁, with ω_RN ≈ ω_HN (the line of sight
//!   to a chief on station turns with the Hill frame).
//! - Centres of mass: the state message gives point B; each vehicle's centre of mass C is
//!   r_C = r_B + \[NB\] r_CB_B with r_CB_B from the served configuration's masses (panels at
//!   their hinge angle 0: [`com_offset_b`]).

use flexdyn_proto::attitude::{dcm_to_mrp, mrp_error, mrp_to_dcm};
use flexdyn_proto::client::vehicle::VehicleConfig;
use nalgebra::{Matrix3, Vector3};

/// The total mass \[kg\] and the centre of mass relative to B, in B \[m\], of a served
/// configuration (hub, and every panel at hinge angle 0: panel 1's centre of mass `d_m` along
/// −ĥ₁ from hinge 1, panel 2's at `l_m + d_m`).
pub fn com_offset_b(cfg: &VehicleConfig) -> (f64, Vector3<f64>) {
    let mut m = cfg.hub.mass_kg;
    let mut first = cfg.hub.mass_kg * Vector3::from(cfg.hub.r_bcb_b_m);
    for p in &cfg.panel_pairs {
        let h1 = Vector3::from(p.dcm_h1b[0]);
        let hinge = Vector3::from(p.r_h1b_b_m);
        let l1 = p.panel1.l_m.unwrap_or(0.0);
        first += p.panel1.mass_kg * (hinge - p.panel1.d_m * h1);
        first += p.panel2.mass_kg * (hinge - (l1 + p.panel2.d_m) * h1);
        m += p.panel1.mass_kg + p.panel2.mass_kg;
    }
    (m, first / m)
}

/// A vehicle's centre of mass position and velocity in N from its state (B's, its attitude
/// and rate) and its centre-of-mass offset `r_cb_b` (rigid: ṙ = ω × r).
pub fn com_state_n(
    r_bn_n: &Vector3<f64>,
    v_bn_n: &Vector3<f64>,
    sigma_bn: &Vector3<f64>,
    omega_bn_b: &Vector3<f64>,
    r_cb_b: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    let nb = mrp_to_dcm(sigma_bn).transpose();
    (r_bn_n + nb * r_cb_b, v_bn_n + nb * omega_bn_b.cross(r_cb_b))
}

/// The chief's Hill frame: \[HN\] and ω_HN in N. `None` without an orbit plane.
pub fn hill_frame(r_c: &Vector3<f64>, v_c: &Vector3<f64>) -> Option<(Matrix3<f64>, Vector3<f64>)> {
    let h = r_c.cross(v_c);
    let (rn, hn) = (r_c.norm(), h.norm());
    if rn == 0.0 || hn == 0.0 {
        return None;
    }
    let x = r_c / rn;
    let z = h / hn;
    let y = z.cross(&x);
    let hn_dcm = Matrix3::from_rows(&[x.transpose(), y.transpose(), z.transpose()]);
    Some((hn_dcm, h / (rn * rn)))
}

/// The deputy relative to the chief in the chief's Hill frame: (ρ_H, ρ̇_H, \[HN\], ω_HN in N).
pub type HillRelative = (Vector3<f64>, Vector3<f64>, Matrix3<f64>, Vector3<f64>);

/// The deputy at (`r_d`, `v_d`) relative to the chief at (`r_c`, `v_c`): [`HillRelative`].
/// `None` if the chief has no orbit plane.
pub fn relative_hill(
    r_c: &Vector3<f64>,
    v_c: &Vector3<f64>,
    r_d: &Vector3<f64>,
    v_d: &Vector3<f64>,
) -> Option<HillRelative> {
    let (hn, omega_hn_n) = hill_frame(r_c, v_c)?;
    let rho_n = r_d - r_c;
    let rho_dot_n = v_d - v_c - omega_hn_n.cross(&rho_n);
    Some((hn * rho_n, hn * rho_dot_n, hn, omega_hn_n))
}

/// The station-keeping gains: natural frequency ω_c \[rad/s\] and damping ratio ζ.
#[derive(Clone, Copy, Debug)]
pub struct StationGains {
    /// \[rad/s\]
    pub omega_c: f64,
    /// Damping ratio.
    pub zeta: f64,
}

/// The body force \[N\] that holds the station `rho_star_h` (see the module docs).
pub fn station_force_b(
    gains: StationGains,
    mass_kg: f64,
    rho_h: &Vector3<f64>,
    rho_dot_h: &Vector3<f64>,
    rho_star_h: &Vector3<f64>,
    hn: &Matrix3<f64>,
    sigma_bn: &Vector3<f64>,
) -> Vector3<f64> {
    let w = gains.omega_c;
    let a_h = -w * w * (rho_h - rho_star_h) - 2.0 * gains.zeta * w * rho_dot_h;
    mass_kg * (mrp_to_dcm(sigma_bn) * hn.transpose() * a_h)
}

/// The attitude error σ_BR and the rate error ω_BR in B of pointing body x̂ from the deputy at
/// `r_d` to the chief at `r_c` (orbit normal `z_n`, reference rate `omega_rn_n`).
pub fn pointing_errors(
    r_c: &Vector3<f64>,
    r_d: &Vector3<f64>,
    z_n: &Vector3<f64>,
    omega_rn_n: &Vector3<f64>,
    sigma_bn: &Vector3<f64>,
    omega_bn_b: &Vector3<f64>,
) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let los = r_c - r_d;
    let r1 = los.try_normalize(0.0)?;
    let r2 = z_n.cross(&r1).try_normalize(1e-9)?;
    let r3 = r1.cross(&r2);
    let rn = Matrix3::from_rows(&[r1.transpose(), r2.transpose(), r3.transpose()]);
    let sigma_rn = dcm_to_mrp(&rn);
    let sigma_br = mrp_error(sigma_bn, &sigma_rn);
    let omega_br_b = omega_bn_b - mrp_to_dcm(sigma_bn) * omega_rn_n;
    Some((sigma_br, omega_br_b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hill_frame_of_a_circular_orbit_turns_at_the_mean_motion() {
        let mu = 3.986004415e14_f64;
        let r = 7.0e6;
        let v = (mu / r).sqrt();
        let (r_c, v_c) = (Vector3::new(r, 0.0, 0.0), Vector3::new(0.0, v, 0.0));
        let (hn, w) = hill_frame(&r_c, &v_c).unwrap();
        assert_eq!(hn, Matrix3::identity());
        assert!((w.z - (mu / r.powi(3)).sqrt()).abs() < 1e-15);
        // A deputy 100 m behind on the same circular orbit is at rest in H.
        let th = -100.0 / r;
        let r_d = r * Vector3::new(th.cos(), th.sin(), 0.0);
        let v_d = v * Vector3::new(-th.sin(), th.cos(), 0.0);
        let (rho, rho_dot, _, _) = relative_hill(&r_c, &v_c, &r_d, &v_d).unwrap();
        assert!(
            (rho - Vector3::new(0.0, -100.0, 0.0)).norm() < 1e-3,
            "{rho}"
        );
        assert!(rho_dot.norm() < 1e-9, "{rho_dot}");
    }

    #[test]
    fn pointing_is_zero_error_when_body_x_looks_at_the_chief() {
        // Chief along +y of the deputy, orbit normal +z: R = [ŷ, −x̂, ẑ] in N.
        let rn = Matrix3::new(0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let sigma = dcm_to_mrp(&rn);
        let (e, w) = pointing_errors(
            &Vector3::new(0.0, 5.0, 0.0),
            &Vector3::zeros(),
            &Vector3::z(),
            &Vector3::zeros(),
            &sigma,
            &Vector3::zeros(),
        )
        .unwrap();
        assert!(e.norm() < 1e-12 && w.norm() == 0.0, "{e} {w}");
    }
}
