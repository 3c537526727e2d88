//! The `[environment]` keys that set each model's constants (`environment::model::constants`),
//! from a configuration file to the sample and the wrench, against closed forms and published
//! values:
//! - a given dipole in a uniformly rotating Earth is the dipole formula
//!   B = (a/r)³ [3 (k·r̂) r̂ − k] rotated by R3(θ₀ + ω t)ᵀ, and its moment form is the same field;
//! - the exponential atmosphere's band and altitude definition: ρ0 exp(−(h − h0)/H) with
//!   h = |r| − R or the geodetic height (21.4 km more at the pole), and Vallado's Example 8-4;
//! - the wind on and off, a fixed Sun, the shadow's radii;
//! - the cannonball SRP against Basilisk's published unit-test case, and the irradiance's
//!   linear scaling of the facet SRP;
//! - a run with only date-free models gives the same samples at any epoch.

use flexdyn_dynamics::EnvironmentSource;
use flexdyn_environment::EnvironmentSample;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use nalgebra::{Matrix3, Vector3};

/// A rigid 100 kg hub with B at its centre of mass and the identity attitude (so B = N), at
/// `r_bn_n_m`, with `environment` as its `[environment]` table (and its facets) at `epoch`.
fn config_at(epoch: &str, r_bn_n_m: [f64; 3], environment: &str) -> SimConfig {
    let text = format!(
        "panel_pairs = []\n[simulation]\nstep_s = 0.001\nframe_hz = 100.0\n\
         [gravity]\nmodel = \"point_mass\"\nmu_m3_s2 = 3.986004415e14\n\
         [epoch]\nutc = \"{epoch}\"\n\
         [hub]\nmass_kg = 100.0\n\
         inertia_bc_b_kg_m2 = [[10.0, 0.0, 0.0], [0.0, 12.0, 0.0], [0.0, 0.0, 14.0]]\n\
         r_bcb_b_m = [0.0, 0.0, 0.0]\n\
         [initial]\nr_bn_n_m = [{}, {}, {}]\nv_bn_n_m_s = [0.0, 7500.0, 0.0]\n\
         sigma_bn = [0.0, 0.0, 0.0]\nomega_bn_b_rad_s = [0.0, 0.0, 0.0]\n{environment}\n",
        r_bn_n_m[0], r_bn_n_m[1], r_bn_n_m[2]
    );
    SimConfig::from_toml_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn config(r_bn_n_m: [f64; 3], environment: &str) -> SimConfig {
    config_at("2026-11-24T06:00:00Z", r_bn_n_m, environment)
}

/// The sample the configured models give at `t_sim_ns` for B at `r_bn_n_m` (velocity irrelevant
/// to every model here).
fn sample_of(cfg: &SimConfig, t_sim_ns: u64, r_bn_n_m: Vector3<f64>) -> EnvironmentSample {
    let model = cfg.environment_model().unwrap().expect("models on");
    let mut out = EnvironmentSample::NONE;
    model.fill(
        t_sim_ns,
        &r_bn_n_m,
        &Vector3::new(0.0, 7500.0, 0.0),
        &mut out,
    );
    out
}

/// The IERS passive rotation R3(θ), written out (not the crate's).
fn r3(theta_rad: f64) -> Matrix3<f64> {
    let (s, c) = theta_rad.sin_cos();
    Matrix3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0)
}

fn close(got: &Vector3<f64>, want: &Vector3<f64>, rel: f64) -> bool {
    (got - want).norm() <= rel * want.norm()
}

/// IGRF-13's degree-1 coefficients for 1925.0 \[nT\] (Alken et al. 2021, the coefficient
/// table), which Basilisk's `simSetPlanetEnvironment.centeredDipoleMagField` ships as "Earth".
const G10_NT: f64 = -30926.0;
const G11_NT: f64 = -2318.0;
const H11_NT: f64 = 5817.0;
/// \[m\] IGRF's reference radius.
const A_M: f64 = 6_371_200.0;
const DIPOLE: &str = "[environment]\nmagnetic = \"dipole\"\ndipole_g10_nt = -30926.0\n\
    dipole_g11_nt = -2318.0\ndipole_h11_nt = 5817.0\nearth_rotation = \"uniform\"\n\
    earth_rotation_angle_rad = 0.5\nearth_rotation_rate_rad_s = 7.2921159e-5\n";

#[test]
fn given_dipole_in_a_uniformly_rotating_earth_is_the_closed_form() {
    let r_m = A_M + 500e3;
    let cfg = config([r_m, 0.0, 0.0], DIPOLE);
    let k_t = Vector3::new(G11_NT, H11_NT, G10_NT) * 1e-9;
    // On E's pole (which is N's: the rotation is about it) the closed form is
    // (a/r)³ (−g₁¹, −h₁¹, 2 g₁⁰) in E: [1847.9039, −4637.2980, −49308.2618] nT at 500 km.
    let s = sample_of(&cfg, 0, Vector3::new(0.0, 0.0, r_m));
    let b_e_t = r3(0.5) * s.b_field_n_t;
    let want_nt = Vector3::new(1847.9039, -4637.2980, -49308.2618);
    assert!(close(&(b_e_t * 1e9), &want_nt, 2e-8), "{:?}", b_e_t * 1e9);
    // Anywhere and at any time: B_N = R3(θ₀ + ω t)ᵀ (a/r)³ [3 (k·r̂_E) r̂_E − k].
    for (t_sim_ns, r_n_m) in [
        (0_u64, Vector3::new(r_m, 0.0, 0.0)),
        (
            1_000_000_000,
            Vector3::new(0.3, -0.5, 0.7).normalize() * r_m,
        ),
        (
            5_400_000_000_000,
            Vector3::new(-0.8, 0.1, -0.2).normalize() * (r_m + 3e7),
        ),
    ] {
        let theta = 0.5 + 7.2921159e-5 * t_sim_ns as f64 * 1e-9;
        let r_e_m = r3(theta) * r_n_m;
        let rh = r_e_m.normalize();
        let b_e_t = (A_M / r_e_m.norm()).powi(3) * (3.0 * k_t.dot(&rh) * rh - k_t);
        let want = r3(theta).transpose() * b_e_t;
        let got = sample_of(&cfg, t_sim_ns, r_n_m).b_field_n_t;
        assert!(
            close(&got, &want, 1e-12),
            "t = {t_sim_ns} ns: {got:?} vs {want:?}"
        );
    }
}

#[test]
fn a_dipole_given_by_its_moment_is_the_same_dipole() {
    // m = (4π/μ0) a³ k: the same dipole as the coefficients (module docs of magnetic::dipole).
    let k_nt = Vector3::new(G11_NT, H11_NT, G10_NT);
    let m_am2 = k_nt.norm() * 1e-9 * A_M.powi(3) / 1e-7;
    let axis = k_nt.normalize();
    let moment = format!(
        "[environment]\nmagnetic = \"dipole\"\ndipole_moment_am2 = {m_am2:e}\n\
         dipole_axis_e = [{:e}, {:e}, {:e}]\nearth_rotation = \"uniform\"\n\
         earth_rotation_angle_rad = 0.5\nearth_rotation_rate_rad_s = 7.2921159e-5\n",
        axis.x, axis.y, axis.z
    );
    let r = Vector3::new(4e6, -5e6, 3e6);
    let a = sample_of(&config([7e6, 0.0, 0.0], DIPOLE), 7_000_000_000, r);
    let b = sample_of(&config([7e6, 0.0, 0.0], &moment), 7_000_000_000, r);
    assert!(close(&b.b_field_n_t, &a.b_field_n_t, 1e-14));
    // The moment from these coefficients: (4π/μ0) |k| a³ = 1e7 · 31553.6e-9 T · (6371.2 km)³
    // = 8.16e22 A·m² (1925; IGRF-14's 2025 coefficients give 7.7e22).
    assert!((8.15e22..8.17e22).contains(&m_am2), "{m_am2:e}");
}

#[test]
fn exponential_band_over_a_spherical_altitude_is_the_closed_form() {
    // Basilisk's `exponentialAtmosphere` Earth preset: ρ0 = 1.217 kg/m³ at the surface of a
    // sphere of 6378136.6 m, H = 8500 m; h = |r| − R in every direction.
    let env = "[environment]\natmosphere = \"exponential\"\n\
        exponential_base_density_kg_m3 = 1.217\nexponential_scale_height_m = 8500.0\n\
        exponential_altitude = \"spherical\"\nexponential_radius_m = 6378136.6\n";
    let r_m = 6_378_136.6 + 200e3;
    let cfg = config([r_m, 0.0, 0.0], env);
    let want = 1.217 * (-200e3_f64 / 8500.0).exp();
    for dir in [
        Vector3::x(),
        Vector3::z(),
        Vector3::new(1.0, -2.0, 2.0) / 3.0,
    ] {
        let rho = sample_of(&cfg, 0, dir * r_m).density_kg_m3;
        assert!((rho - want).abs() <= 1e-12 * want, "{rho:e} vs {want:e}");
    }
    // A base altitude moves the curve: ρ(h0) = ρ0 and ρ(h0 + H) = ρ0/e.
    let env = "[environment]\natmosphere = \"exponential\"\nexponential_base_altitude_m = 4e5\n\
        exponential_base_density_kg_m3 = 3.725e-12\nexponential_scale_height_m = 58515.0\n\
        exponential_altitude = \"spherical\"\nexponential_radius_m = 6.4e6\n";
    let cfg = config([7e6, 0.0, 0.0], env);
    let at = |h: f64| sample_of(&cfg, 0, Vector3::new(0.0, 6.4e6 + h, 0.0)).density_kg_m3;
    assert!((at(4e5) - 3.725e-12).abs() <= 1e-15 * 3.725e-12);
    let ratio = at(4e5 + 58515.0) / at(4e5);
    assert!((ratio - (-1.0_f64).exp()).abs() < 1e-9, "{ratio}");
}

#[test]
fn vallado_example_8_4_and_the_altitude_definitions() {
    // Vallado (2013) Example 8-4: ρ(747.2119 km) = 2.1219854e-14 kg/m³ from Table 8-4's
    // 700 km band (3.614e-14 kg/m³, H = 88.667 km): 3.614e-14 exp(−47.2119/88.667).
    let h_m = 747_211.9;
    let spherical = "[environment]\natmosphere = \"exponential\"\n\
        exponential_altitude = \"spherical\"\nexponential_radius_m = 6378137.0\n";
    let r_m = 6_378_137.0 + h_m;
    let cfg = config([r_m, 0.0, 0.0], spherical);
    let rho = sample_of(&cfg, 0, Vector3::new(0.0, 0.0, r_m)).density_kg_m3;
    assert!((rho / 2.1219854e-14 - 1.0).abs() < 5e-8, "{rho:e}");
    // The default, geodetic: on the equator the height is |r| − a, the same density; over the
    // pole it is |r| − b, 21384.685 m higher (WGS-84 a − b), so the density is the table's at
    // 768.5966 km.
    let geodetic = config(
        [r_m, 0.0, 0.0],
        "[environment]\natmosphere = \"exponential\"\n",
    );
    let equator = sample_of(&geodetic, 0, Vector3::new(r_m, 0.0, 0.0)).density_kg_m3;
    // The equator lies on N's x axis only up to the Earth's orientation (a 0.36° pole offset in
    // 2026: a 10 m height change at most, 1e-4 of the density).
    assert!((equator / 2.1219854e-14 - 1.0).abs() < 2e-4, "{equator:e}");
    let pole = sample_of(&geodetic, 0, Vector3::new(0.0, 0.0, r_m)).density_kg_m3;
    let want = 3.614e-14 * (-(h_m + 21_384.685 - 700e3) / 88_667.0_f64).exp();
    assert!((pole / want - 1.0).abs() < 1e-4, "{pole:e} vs {want:e}");
}

#[test]
fn the_wind_co_rotates_or_is_still() {
    let env = |wind: &str| {
        format!(
            "[environment]\natmosphere = \"exponential\"\nearth_rotation = \"uniform\"\n\
             earth_rotation_rate_rad_s = 7.0e-5\n{wind}"
        )
    };
    let r = Vector3::new(5e6, 4e6, 3e6);
    let on = sample_of(&config([7e6, 0.0, 0.0], &env("")), 0, r);
    let off = sample_of(
        &config([7e6, 0.0, 0.0], &env("corotating_wind = false\n")),
        0,
        r,
    );
    // ω × r with ω = (0, 0, 7e-5): (−7e-5 y, 7e-5 x, 0).
    assert_eq!(on.wind_n_m_s, Vector3::new(-7e-5 * 4e6, 7e-5 * 5e6, 0.0));
    assert_eq!(off.wind_n_m_s, Vector3::zeros());
    assert_eq!(off.density_kg_m3, on.density_kg_m3);
    assert!(on.density_kg_m3 > 0.0);
}

#[test]
fn a_fixed_sun_and_the_shadow_radii() {
    let env = |radius: &str| {
        format!(
            "[environment]\nsun = true\nsun_direction_n = [1.0, 0.0, 0.0]\n\
             sun_distance_m = 1.5e11\nshadow = \"cylindrical\"\n{radius}"
        )
    };
    // Behind the Earth, 6100 km from the Earth–Sun line.
    let r = Vector3::new(-7e6, 6.1e6, 0.0);
    let default = sample_of(&config([7e6, 0.0, 0.0], &env("")), 123_000_000_000, r);
    assert_eq!(default.r_sun_b_n_m, Vector3::new(1.5e11, 0.0, 0.0) - r);
    assert_eq!(default.shadow_factor, 0.0, "inside WGS-84 a = 6378 km");
    let small = sample_of(
        &config([7e6, 0.0, 0.0], &env("shadow_earth_radius_m = 6.0e6\n")),
        0,
        r,
    );
    assert_eq!(small.shadow_factor, 1.0, "outside a 6000 km Earth");
    // Conical: a Sun of 1 m radius has no penumbra worth the name; the umbra edge is then the
    // Earth's radius to within the Sun's apparent size (1e-11 rad at 1.5e11 m).
    let conical = |y: f64| {
        let e = "[environment]\nsun = true\nsun_direction_n = [1.0, 0.0, 0.0]\n\
                 shadow = \"conical\"\nshadow_sun_radius_m = 1.0\n";
        sample_of(&config([7e6, 0.0, 0.0], e), 0, Vector3::new(-7e6, y, 0.0)).shadow_factor
    };
    // From (−7000 km, y) the Earth's disc has the apparent radius asin(R⊕/|r|) and its centre
    // is atan(y/7000 km) from the Sun's direction (+x): y = 5500 km gives 45.8° against 38.2°
    // (umbra), y = 7500 km 38.4° against 47.0° (full Sun).
    assert_eq!(conical(5.5e6), 0.0);
    assert_eq!(conical(7.5e6), 1.0);
}

/// Basilisk's `RadiationPressure` cannonball unit test (`test_radiationPressure.py`, as of
/// 2026-07): spacecraft, Sun, area, C_R and the expected force in N, with Φ = 1361 W/m², as
/// `scenarios/srp_cannonball_basilisk.toml` sets them.
#[test]
fn cannonball_srp_matches_basilisks_unit_test_case() {
    // The shipped scenario sets the case up (its Sun is Basilisk's sun_r_N as a unit vector and
    // a distance, B starts at Basilisk's r_N with the identity attitude).
    let path = format!("{}/scenarios/srp_cannonball_basilisk.toml", crate::REPO);
    let cfg = SimConfig::from_toml_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let r_sun: Vector3<f64> = Vector3::new(507128401.716, 22652490.9092, -14854379.6232);
    let want_sun_n_m = cfg
        .environment
        .as_ref()
        .unwrap()
        .models
        .ephemeris
        .sun_fixed_n_m
        .unwrap();
    assert!(close(&want_sun_n_m, &r_sun, 1e-15), "{want_sun_n_m:?}");
    let mut sim = Simulation::new(&cfg).unwrap();
    sim.step();
    let sample = *sim.spacecraft().environment();
    let w = sim.spacecraft_mut().environment_wrenches(&sample)
        [EnvironmentSource::SolarPressure as usize];
    // B = N at the identity attitude (the hub does not turn in one step from rest). The digits
    // are Basilisk's, as published.
    #[expect(
        clippy::excessive_precision,
        reason = "Basilisk's digits, as published"
    )]
    let want = Vector3::new(
        -2.4263722557462318e-06,
        -1.9257945167191118e-05,
        -8.3504083188649253e-06,
    );
    // Basilisk's au is 149597870693 m, the IAU's (used here) 149597870700 m: a relative 9.4e-11
    // in P ∝ au²; the Sun direction passes through a unit vector and its length (1e-16).
    let got = w.force_b_newton;
    assert!(close(&got, &want, 1e-9), "{got:?} vs {want:?}");
    assert_eq!(w.torque_b_nm, Vector3::zeros(), "centre of pressure at B");
}

#[test]
fn the_irradiance_scales_the_facet_srp() {
    let env = |phi: &str| {
        format!(
            "[environment]\nsun = true\nsun_direction_n = [0.6, 0.8, 0.0]\n\
             solar_pressure = true\n{phi}\n[[environment.facets]]\narea_m2 = 2.0\n\
             normal_b = [1.0, 0.0, 0.0]\nr_cp_b_m = [0.0, 0.5, 0.0]\ndrag_coefficient = 2.2\n\
             absorbed = 0.5\nspecular = 0.3\ndiffuse = 0.2\n"
        )
    };
    let wrench = |phi: &str| {
        let mut sim = Simulation::new(&config([7e6, 0.0, 0.0], &env(phi))).unwrap();
        sim.step();
        let s = *sim.spacecraft().environment();
        sim.spacecraft_mut().environment_wrenches(&s)[EnvironmentSource::SolarPressure as usize]
    };
    let nominal = wrench("");
    let scaled = wrench("solar_irradiance_1au_w_m2 = 1000.0");
    assert!(nominal.force_b_newton.norm() > 0.0);
    // P is linear in Φ; the two runs round Φ/c and the facet sums separately (a few ulps on a
    // sum of three terms of either sign).
    let want = nominal.force_b_newton * (1000.0 / 1361.0);
    assert!(
        close(&scaled.force_b_newton, &want, 1e-13),
        "{:?} vs {want:?}",
        scaled.force_b_newton
    );
}

#[test]
fn date_free_models_give_the_same_samples_at_any_epoch() {
    let env = "[environment]\nmagnetic = \"dipole\"\ndipole_g10_nt = -29350.0\n\
        atmosphere = \"exponential\"\nexponential_altitude = \"spherical\"\n\
        earth_rotation = \"uniform\"\nsun = true\nsun_direction_n = [0.0, 1.0, 0.0]\n\
        shadow = \"conical\"\n";
    let r = Vector3::new(-1e6, -6.9e6, 2e5);
    let a = sample_of(
        &config_at("1980-01-01T00:00:00Z", [7e6, 0.0, 0.0], env),
        9e9 as u64,
        r,
    );
    let b = sample_of(
        &config_at("2090-06-30T12:00:00Z", [7e6, 0.0, 0.0], env),
        9e9 as u64,
        r,
    );
    assert_eq!(a, b);
    assert!(a.b_field_n_t.norm() > 0.0 && a.density_kg_m3 > 0.0);
    assert!(
        a.shadow_factor < 1.0,
        "behind the Earth from a Sun along +y"
    );
}
