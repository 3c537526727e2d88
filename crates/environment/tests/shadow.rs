//! The shadow factor against an independent computation: the visible fraction of the solar disc
//! found by tracing rays from the spacecraft to a grid of points on the Sun's disc and testing
//! each against the Earth's sphere (exact spherical geometry, uniform disc brightness).

use flexdyn_environment::ephemeris::{AU_M, SUN_RADIUS_M};
use flexdyn_environment::shadow::{shadow_factor, ShadowModel, EARTH_SHADOW_RADIUS_M};
use nalgebra::Vector3;

/// The Sun at 1 AU on +x.
fn sun() -> Vector3<f64> {
    Vector3::new(AU_M, 0.0, 0.0)
}

/// Visible fraction of the solar disc from `r_sat`, by ray tracing: the disc is the cone of
/// half-angle a = asin(R☉/d) about the Sun's direction, sampled on a polar grid weighted by solid
/// angle; a ray is blocked when it meets the Earth's sphere in front of the spacecraft.
fn visible_fraction_ray_traced(r_sat: &Vector3<f64>, r_sun: &Vector3<f64>) -> f64 {
    let to_sun = r_sun - r_sat;
    let w = to_sun.normalize();
    let a = (SUN_RADIUS_M / to_sun.norm()).asin();
    // An orthonormal basis (u, v, w) about the Sun's direction.
    let u = w.cross(&Vector3::z()).normalize();
    let v = w.cross(&u);
    let (n_rho, n_phi) = (1500, 720);
    let (mut lit, mut total) = (0.0, 0.0);
    for i in 0..n_rho {
        let rho = a * (f64::from(i) + 0.5) / f64::from(n_rho);
        let weight = rho.sin();
        for j in 0..n_phi {
            let phi = std::f64::consts::TAU * (f64::from(j) + 0.5) / f64::from(n_phi);
            let dir = rho.cos() * w + rho.sin() * (phi.cos() * u + phi.sin() * v);
            // |r_sat + s dir|² = R² has a root with s > 0?
            let bq = r_sat.dot(&dir);
            let cq = r_sat.norm_squared() - EARTH_SHADOW_RADIUS_M * EARTH_SHADOW_RADIUS_M;
            let disc = bq * bq - cq;
            let blocked = disc >= 0.0 && (-bq + disc.sqrt()) > 0.0 && cq > 0.0 && bq < 0.0;
            total += weight;
            if !blocked {
                lit += weight;
            }
        }
    }
    lit / total
}

/// The spacecraft at `radius_m` in the x–y plane, `angle_rad` from the anti-Sun direction.
fn sat(radius_m: f64, angle_rad: f64) -> Vector3<f64> {
    radius_m * Vector3::new(-angle_rad.cos(), angle_rad.sin(), 0.0)
}

/// The angle from the anti-Sun direction at which the apparent separation c of the Sun's and the
/// Earth's centres equals `c`, for a spacecraft at `radius_m` (found by bisection on c itself).
fn angle_for_separation(radius_m: f64, c_target: f64) -> f64 {
    let separation = |angle: f64| {
        let r = sat(radius_m, angle);
        let s = sun() - r;
        (-r.dot(&s) / (r.norm() * s.norm())).acos()
    };
    let (mut lo, mut hi) = (0.0, std::f64::consts::FRAC_PI_2);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if separation(mid) < c_target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn full_sun_and_umbra() {
    let r = EARTH_SHADOW_RADIUS_M + 500e3;
    for model in [ShadowModel::Conical, ShadowModel::Cylindrical] {
        // Sub-solar side, and the dawn/dusk terminator seen from above the pole.
        assert_eq!(
            shadow_factor(model, &Vector3::new(r, 0.0, 0.0), &sun()),
            1.0
        );
        assert_eq!(
            shadow_factor(model, &Vector3::new(0.0, 0.0, r), &sun()),
            1.0
        );
        // Straight behind the Earth.
        assert_eq!(
            shadow_factor(model, &Vector3::new(-r, 0.0, 0.0), &sun()),
            0.0
        );
        // Inside the Earth: no sunlight, no panic.
        assert_eq!(
            shadow_factor(model, &Vector3::new(-1e6, 0.0, 0.0), &sun()),
            0.0
        );
    }
}

#[test]
fn validate_conical_penumbra_against_ray_tracing() {
    // Across the whole penumbra at 500 km and at GEO: the conical model within 1e-3 of the ray
    // traced fraction (its plane-disc approximation of the Earth's limb is the difference).
    let mut worst = 0.0_f64;
    for radius_m in [EARTH_SHADOW_RADIUS_M + 500e3, 42_164e3] {
        let b = (EARTH_SHADOW_RADIUS_M / radius_m).asin();
        let a = (SUN_RADIUS_M / AU_M).asin();
        for k in 1..10 {
            let c = b - a + 2.0 * a * f64::from(k) / 10.0;
            let r = sat(radius_m, angle_for_separation(radius_m, c));
            let model = shadow_factor(ShadowModel::Conical, &r, &sun());
            let reference = visible_fraction_ray_traced(&r, &sun());
            assert!(
                model > 0.0 && model < 1.0,
                "inside the penumbra ν = {model}"
            );
            worst = worst.max((model - reference).abs());
        }
    }
    println!("conical vs ray tracing, worst |Δν| = {worst:.2e}");
    assert!(worst < 1e-3, "worst |Δν| = {worst}");
}

#[test]
fn validate_annular_shadow_far_behind_the_earth() {
    // At 2e9 m behind the Earth (past the umbra's tip at ≈ 1.38e9 m) the Earth's disc lies inside
    // the Sun's: ν = 1 − b²/a², and the ray tracing agrees.
    let r = Vector3::new(-2e9, 0.0, 0.0);
    let model = shadow_factor(ShadowModel::Conical, &r, &sun());
    let a = (SUN_RADIUS_M / (AU_M + 2e9)).asin();
    let b = (EARTH_SHADOW_RADIUS_M / 2e9_f64).asin();
    assert!((model - (1.0 - b * b / (a * a))).abs() < 1e-12);
    let reference = visible_fraction_ray_traced(&r, &sun());
    assert!((model - reference).abs() < 1e-3, "{model} vs {reference}");
    // The cylinder knows no such thing.
    assert_eq!(shadow_factor(ShadowModel::Cylindrical, &r, &sun()), 0.0);
}

#[test]
fn conical_is_continuous_and_monotone_across_both_boundaries() {
    // Walk the spacecraft at 500 km through the penumbra in steps of 1e-6 rad of orbit angle
    // (7 m): ν falls from 1 to 0 without a jump larger than the slope allows.
    let radius_m = EARTH_SHADOW_RADIUS_M + 500e3;
    let b = (EARTH_SHADOW_RADIUS_M / radius_m).asin();
    let a = (SUN_RADIUS_M / AU_M).asin();
    let outer = angle_for_separation(radius_m, b + a) + 2e-4;
    let inner = angle_for_separation(radius_m, b - a) - 2e-4;
    let steps = ((outer - inner) / 1e-6) as usize;
    let mut previous = shadow_factor(ShadowModel::Conical, &sat(radius_m, outer), &sun());
    assert_eq!(previous, 1.0);
    let mut max_jump = 0.0_f64;
    for i in 1..=steps {
        let angle = outer - (outer - inner) * i as f64 / steps as f64;
        let nu = shadow_factor(ShadowModel::Conical, &sat(radius_m, angle), &sun());
        assert!(nu <= previous + 1e-12, "ν rose from {previous} to {nu}");
        max_jump = max_jump.max(previous - nu);
        previous = nu;
    }
    assert_eq!(previous, 0.0);
    // Slope bound: dν/dc ≤ 2/(π a) per radian of separation (the widest chord), and c moves
    // by less than one radian per radian of orbit angle, so a step moves ν by < 2e-6/(π a).
    let bound = 2e-6 / (std::f64::consts::PI * a) * 1.1;
    assert!(
        max_jump < bound,
        "largest step in ν: {max_jump} (bound {bound})"
    );
}

#[test]
fn cylindrical_boundary_is_the_cylinder() {
    // Behind the Earth, just inside and just outside R⊕ from the Earth–Sun line.
    let x = -(EARTH_SHADOW_RADIUS_M + 500e3);
    let inside = Vector3::new(x, EARTH_SHADOW_RADIUS_M - 1.0, 0.0);
    let outside = Vector3::new(x, EARTH_SHADOW_RADIUS_M + 1.0, 0.0);
    assert_eq!(
        shadow_factor(ShadowModel::Cylindrical, &inside, &sun()),
        0.0
    );
    assert_eq!(
        shadow_factor(ShadowModel::Cylindrical, &outside, &sun()),
        1.0
    );
    // In front of the terminator plane nothing is shadowed, however close to the line.
    let front = Vector3::new(1.0, 0.0, EARTH_SHADOW_RADIUS_M + 500e3);
    assert_eq!(shadow_factor(ShadowModel::Cylindrical, &front, &sun()), 1.0);
}
