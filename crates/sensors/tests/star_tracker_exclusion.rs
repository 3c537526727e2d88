//! The star tracker's Earth-limb and Moon exclusion against closed-form geometry (module docs of
//! `star_tracker`, "Body exclusion").
//!
//! The tracker looks along +ẑ_N (identity attitude and mounting, boresight +ẑ_C). Each body is
//! placed by construction, not by the model's formula: at angle θ from the boresight, or so that
//! the boresight is the tangent ray from B to the body's sphere, built from the tangent point
//! (|BT|² + R² = d², the right angle at T). The flag must follow η = θ − asin(R/d) against the
//! exclusion half-angle, with η = 0 exactly on the tangent ray.

use flexdyn_proto::star_tracker_flags::{EARTH_EXCLUSION, MOON_EXCLUSION};
use flexdyn_sensors::star_tracker::{
    limb_angle_rad, Sky, StarTracker, StarTrackerConfig, MOON_RADIUS_M,
};
use nalgebra::{Matrix3, Vector3};

const R_EARTH_M: f64 = 6_378_137.0;

fn tracker(
    earth_exclusion_rad: f64,
    earth_atmosphere_m: f64,
    moon_exclusion_rad: f64,
) -> StarTracker {
    let cfg = StarTrackerConfig {
        name: "st".into(),
        dcm_cb: Matrix3::identity(),
        boresight_c: Vector3::z(),
        sigma_cross_boresight_rad: 0.0,
        sigma_about_boresight_rad: 0.0,
        bias_c_rad: Vector3::zeros(),
        every_frames: 1,
        seed: 7,
        sun_direction_n: Vector3::x(),
        sun_from_environment: false,
        sun_exclusion_rad: 0.0,
        max_rate_rad_s: f64::INFINITY,
        earth_exclusion_rad,
        earth_radius_m: R_EARTH_M,
        earth_atmosphere_m,
        moon_exclusion_rad,
    };
    StarTracker::new(cfg, "star_trackers[0]").unwrap()
}

fn flags(st: &mut StarTracker, sky: Sky) -> u8 {
    st.sample_in_sky(&Vector3::zeros(), &Vector3::zeros(), &sky)
        .status_flags
}

/// The unit vector at angle `theta` from +ẑ, in the x–z plane.
fn at_angle(theta: f64) -> Vector3<f64> {
    Vector3::new(theta.sin(), 0.0, theta.cos())
}

/// The spacecraft position that puts the Earth's centre at angle `theta` from the boresight,
/// `d` away.
fn earth_at(theta: f64, d: f64) -> Sky {
    Sky {
        r_bn_n: Some(-at_angle(theta) * d),
        ..Sky::default()
    }
}

#[test]
fn earth_exclusion_follows_the_limb_angle() {
    let eps = 20f64.to_radians();
    for (h, d) in [(0.0, 7.0e6), (100e3, 7.0e6), (60e3, 4.2164e7)] {
        let mut st = tracker(eps, h, 0.0);
        let rho = ((R_EARTH_M + h) / d).asin();
        // Just inside and just outside the exclusion cone about the limb.
        assert_eq!(
            flags(&mut st, earth_at(rho + eps - 1e-7, d)),
            EARTH_EXCLUSION
        );
        assert_eq!(flags(&mut st, earth_at(rho + eps + 1e-7, d)), 0);
        // On the disc, at its centre, and looking straight away.
        assert_eq!(flags(&mut st, earth_at(0.5 * rho, d)), EARTH_EXCLUSION);
        assert_eq!(flags(&mut st, earth_at(0.0, d)), EARTH_EXCLUSION);
        assert_eq!(flags(&mut st, earth_at(std::f64::consts::PI, d)), 0);
        // A sweep: the flag is η < ε wherever η is not within 1e-9 rad of ε.
        for k in 0..=720 {
            let theta = std::f64::consts::PI * f64::from(k) / 720.0;
            let eta = theta - rho;
            if (eta - eps).abs() < 1e-9 {
                continue;
            }
            let want = if eta < eps { EARTH_EXCLUSION } else { 0 };
            assert_eq!(
                flags(&mut st, earth_at(theta, d)),
                want,
                "θ = {theta}, h = {h}"
            );
        }
    }
}

#[test]
fn the_tangent_ray_is_the_limb() {
    // B on the +x axis at d; the tangent point T on the sphere in the x–z plane. The boresight
    // (+ẑ) is along B→T when T − B ∥ ẑ after a rotation: build the geometry in a frame where
    // B→T is +ẑ, by placing the Earth's centre at T + R n̂ with n̂ ⟂ ẑ (the radius at T is
    // perpendicular to the tangent).
    for (radius, d) in [
        (R_EARTH_M, 7.0e6),
        (R_EARTH_M + 80e3, 6.9e6),
        (MOON_RADIUS_M, 3.844e8),
    ] {
        let bt = (d * d - radius * radius).sqrt();
        let centre_from_b = Vector3::new(radius, 0.0, bt);
        assert!((centre_from_b.norm() - d).abs() < 1e-6 * d);
        let eta = limb_angle_rad(&Vector3::z(), &centre_from_b, radius);
        assert!(eta.abs() < 1e-12, "η on the tangent ray = {eta}");
        // Tilting the boresight away from the body by δ gives η = δ.
        for delta in [1e-3_f64, 0.1, 0.5] {
            let b = Vector3::new(-delta.sin(), 0.0, delta.cos());
            let eta = limb_angle_rad(&b, &centre_from_b, radius);
            assert!((eta - delta).abs() < 1e-12, "δ = {delta}: η = {eta}");
        }
    }
}

#[test]
fn inside_the_atmosphere_the_earth_always_excludes() {
    let mut st = tracker(1e-3, 100e3, 0.0);
    // 50 km above the surface, under a 100 km atmosphere: excluded looking straight up.
    let d = R_EARTH_M + 50e3;
    assert_eq!(
        flags(&mut st, earth_at(std::f64::consts::PI, d)),
        EARTH_EXCLUSION
    );
    assert_eq!(
        limb_angle_rad(&Vector3::z(), &-Vector3::z(), 1.0),
        f64::NEG_INFINITY
    );
}

#[test]
fn moon_exclusion_follows_the_moons_limb() {
    let eps = 10f64.to_radians();
    let mut st = tracker(0.0, 0.0, eps);
    let d = 3.844e8;
    let rho = (MOON_RADIUS_M / d).asin();
    // 0.259° at its mean distance (Moon's angular radius, ~15.5 arcmin).
    assert!(
        (rho.to_degrees() - 0.259).abs() < 1e-3,
        "ρ = {}°",
        rho.to_degrees()
    );
    let moon_at = |theta: f64| Sky {
        r_moon_b_n: Some(at_angle(theta) * d),
        ..Sky::default()
    };
    assert_eq!(flags(&mut st, moon_at(rho + eps - 1e-7)), MOON_EXCLUSION);
    assert_eq!(flags(&mut st, moon_at(rho + eps + 1e-7)), 0);
    assert_eq!(flags(&mut st, moon_at(0.0)), MOON_EXCLUSION);
    // No Moon: nothing to exclude.
    assert_eq!(flags(&mut st, Sky::default()), 0);
}

#[test]
fn without_exclusion_angles_the_bodies_change_nothing() {
    let mut off = tracker(0.0, 0.0, 0.0);
    let mut plain = tracker(0.0, 0.0, 0.0);
    // Pointing at the Earth's and the Moon's centres with both checks off: valid, and the same
    // measurement as with no bodies at all (the noise stream does not depend on them).
    let sky = Sky {
        r_bn_n: Some(-Vector3::z() * 7.0e6),
        r_moon_b_n: Some(Vector3::z() * 3.844e8),
        sun_n: None,
    };
    for _ in 0..10 {
        let a = off.sample_in_sky(&Vector3::zeros(), &Vector3::zeros(), &sky);
        let b = plain.sample_in_sky(&Vector3::zeros(), &Vector3::zeros(), &Sky::default());
        assert!(a.valid);
        assert_eq!(a, b);
    }
    // Both bodies at once set both flags, and the output is held (identity before any valid).
    let mut both = tracker(0.1, 0.0, 0.1);
    let s = both.sample_in_sky(&Vector3::zeros(), &Vector3::zeros(), &sky);
    assert!(!s.valid);
    assert_eq!(s.status_flags, EARTH_EXCLUSION | MOON_EXCLUSION);
}
