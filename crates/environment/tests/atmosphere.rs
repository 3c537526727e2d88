//! Atmosphere models against their references.
//!
//! Oracles: the documented output of the NRLMSISE-00 reference C release (D. Brodowski's C
//! version of the NRL model, release 20041227: `nrlmsise-00_test.c` and the expected output in
//! its DOCUMENTATION file, which equals the official FORTRAN's); Vallado (2013) Table 8-4 and the
//! continuity its scale heights were derived for; the kinematics of a co-rotating atmosphere.

use flexdyn_environment::atmosphere::{
    exponential_density_kg_m3, velocity_relative_to_air_n_m_s, AtmosphereError, Nrlmsise00Model,
    SpaceWeather, VALLADO_TABLE_8_4,
};
use flexdyn_environment::earth_rotation::OMEGA_EARTH_RAD_S;
use flexdyn_environment::geodetic::{ecef_from_geodetic, Geodetic};
use nalgebra::Vector3;

/// The inputs of one reference case: day of year, UT [s], altitude [km], geodetic latitude and
/// longitude [deg], local solar time [h], F10.7A, F10.7, Ap.
struct Case {
    doy: u32,
    sec: f64,
    alt_km: f64,
    lat_deg: f64,
    lon_deg: f64,
    lst_h: f64,
    f107a: f64,
    f107: f64,
    ap: f64,
}

/// `nrlmsise-00_test.c`: every case starts from day 172, 29000 s, 400 km, 60° N, 70° W, 16 h,
/// F10.7A = F10.7 = 150, Ap = 4, and changes one input.
fn case(i: usize) -> Case {
    let mut c = Case {
        doy: 172,
        sec: 29_000.0,
        alt_km: 400.0,
        lat_deg: 60.0,
        lon_deg: -70.0,
        lst_h: 16.0,
        f107a: 150.0,
        f107: 150.0,
        ap: 4.0,
    };
    match i {
        1 => c.doy = 81,
        2 => {
            c.sec = 75_000.0;
            c.alt_km = 1000.0;
        }
        3 => c.alt_km = 100.0,
        4 => c.lat_deg = 0.0,
        5 => c.lon_deg = 0.0,
        6 => c.lst_h = 4.0,
        7 => c.f107a = 70.0,
        8 => c.f107 = 180.0,
        9 => c.ap = 40.0,
        10 => c.alt_km = 0.0,
        11 => c.alt_km = 10.0,
        12 => c.alt_km = 30.0,
        13 => c.alt_km = 50.0,
        14 => c.alt_km = 70.0,
        _ => {}
    }
    c
}

/// The documented output of cases 1–15 (`%E`, 7 significant digits): He, O, N₂, O₂, Ar [cm⁻³],
/// total mass density [g/cm³], H, N, anomalous O [cm⁻³], T∞ and T(alt) [K]. Cases 16 and 17
/// need the 3-hour Ap history (switch 9 = −1), which the model here does not offer.
#[rustfmt::skip]
const EXPECTED: [[f64; 11]; 15] = [
    [6.665177E+05, 1.138806E+08, 1.998211E+07, 4.022764E+05, 3.557465E+03, 4.074714E-15, 3.475312E+04, 4.095913E+06, 2.667273E+04, 1.250540E+03, 1.241416E+03],
    [3.407293E+06, 1.586333E+08, 1.391117E+07, 3.262560E+05, 1.559618E+03, 5.001846E-15, 4.854208E+04, 4.380967E+06, 6.956682E+03, 1.166754E+03, 1.161710E+03],
    [1.123767E+05, 6.934130E+04, 4.247105E+01, 1.322750E-01, 2.618848E-05, 2.756772E-18, 2.016750E+04, 5.741256E+03, 2.374394E+04, 1.239892E+03, 1.239891E+03],
    [5.411554E+07, 1.918893E+11, 6.115826E+12, 1.225201E+12, 6.023212E+10, 3.584426E-10, 1.059880E+07, 2.615737E+05, 2.819879E-42, 1.027318E+03, 2.068878E+02],
    [1.851122E+06, 1.476555E+08, 1.579356E+07, 2.633795E+05, 1.588781E+03, 4.809630E-15, 5.816167E+04, 5.478984E+06, 1.264446E+03, 1.212396E+03, 1.208135E+03],
    [8.673095E+05, 1.278862E+08, 1.822577E+07, 2.922214E+05, 2.402962E+03, 4.355866E-15, 3.686389E+04, 3.897276E+06, 2.667273E+04, 1.220146E+03, 1.212712E+03],
    [5.776251E+05, 6.979139E+07, 1.236814E+07, 2.492868E+05, 1.405739E+03, 2.470651E-15, 5.291986E+04, 1.069814E+06, 2.667273E+04, 1.116385E+03, 1.112999E+03],
    [3.740304E+05, 4.782720E+07, 5.240380E+06, 1.759875E+05, 5.501649E+02, 1.571889E-15, 8.896776E+04, 1.979741E+06, 9.121815E+03, 1.031247E+03, 1.024848E+03],
    [6.748339E+05, 1.245315E+08, 2.369010E+07, 4.911583E+05, 4.578781E+03, 4.564420E-15, 3.244595E+04, 5.370833E+06, 2.667273E+04, 1.306052E+03, 1.293374E+03],
    [5.528601E+05, 1.198041E+08, 3.495798E+07, 9.339618E+05, 1.096255E+04, 4.974543E-15, 2.686428E+04, 4.889974E+06, 2.805445E+04, 1.361868E+03, 1.347389E+03],
    [1.375488E+14, 0.000000E+00, 2.049687E+19, 5.498695E+18, 2.451733E+17, 1.261066E-03, 0.000000E+00, 0.000000E+00, 0.000000E+00, 1.027318E+03, 2.814648E+02],
    [4.427443E+13, 0.000000E+00, 6.597567E+18, 1.769929E+18, 7.891680E+16, 4.059139E-04, 0.000000E+00, 0.000000E+00, 0.000000E+00, 1.027318E+03, 2.274180E+02],
    [2.127829E+12, 0.000000E+00, 3.170791E+17, 8.506280E+16, 3.792741E+15, 1.950822E-05, 0.000000E+00, 0.000000E+00, 0.000000E+00, 1.027318E+03, 2.374389E+02],
    [1.412184E+11, 0.000000E+00, 2.104370E+16, 5.645392E+15, 2.517142E+14, 1.294709E-06, 0.000000E+00, 0.000000E+00, 0.000000E+00, 1.027318E+03, 2.795551E+02],
    [1.254884E+10, 0.000000E+00, 1.874533E+15, 4.923051E+14, 2.239685E+13, 1.147668E-07, 0.000000E+00, 0.000000E+00, 0.000000E+00, 1.027318E+03, 2.190732E+02],
];

/// Relative tolerance for densities and number densities at 100 km and above. The printed
/// precision is 5e-7; `tobari` 0.2.0 uses exact π/180, 2π/365.25 and π/12 where NRL's code uses
/// its rounded DGTR, DR and HR, which moves its output by up to 3.3e-3 (at 100 km; 1.9e-3 at
/// 400 km). With the three constants patched, cases 1–10 match to 4.8e-7 (see
/// `crates/environment/src/atmosphere/nrlmsise.rs`).
const TOBARI_RELATIVE: f64 = 3.5e-3;
/// The same for the temperatures (worst 1.8e-4, at 100 km).
const TOBARI_TEMPERATURE_RELATIVE: f64 = 2e-4;

fn model_for(c: &Case) -> Nrlmsise00Model {
    Nrlmsise00Model::new(SpaceWeather {
        f107_sfu: c.f107,
        f107a_sfu: c.f107a,
        ap: c.ap,
    })
    .unwrap()
}

fn point_of(c: &Case) -> Geodetic {
    Geodetic {
        lat_rad: c.lat_deg.to_radians(),
        lon_rad: c.lon_deg.to_radians(),
        height_m: c.alt_km * 1e3,
    }
}

/// |g/e − 1|, with two values below 1e-30 (nothing, in cm⁻³) counted equal: case 4's anomalous
/// oxygen is 0 in the FORTRAN and 2.8e-42 in C.
fn relative(g: f64, e: f64) -> f64 {
    if g.abs() < 1e-30 && e.abs() < 1e-30 {
        0.0
    } else {
        (g / e - 1.0).abs()
    }
}

#[test]
fn validate_nrlmsise00_reference_test_cases() {
    let (mut worst_density, mut worst_temperature) = (0.0_f64, 0.0_f64);
    for (i, expected) in EXPECTED.iter().enumerate().take(10) {
        let c = case(i);
        let s = model_for(&c).state_at_local_solar_time(c.doy, c.sec, &point_of(&c), c.lst_h);
        let comp = s.composition.expect("composition at 100 km and above");
        let n = comp.number_densities_m3.map(|n| n * 1e-6); // back to cm⁻³
        let densities = [
            (0, n[0]),
            (1, n[1]),
            (2, n[2]),
            (3, n[3]),
            (4, n[4]),
            (5, s.density_kg_m3 * 1e-3), // back to g/cm³
            (6, n[5]),
            (7, n[6]),
            (8, n[7]),
        ];
        for (k, got) in densities {
            let rel = relative(got, expected[k]);
            assert!(
                rel <= TOBARI_RELATIVE,
                "case {}, output {k}: {got:e} vs {:e}",
                i + 1,
                expected[k]
            );
            worst_density = worst_density.max(rel);
        }
        // gtd7d: the drag density adds 16 × 1.66e-24 g per anomalous oxygen atom.
        let drag = expected[5] + 16.0 * 1.66e-24 * expected[8];
        assert!(relative(s.drag_density_kg_m3 * 1e-3, drag) <= TOBARI_RELATIVE);
        for (k, got) in [(9, comp.exospheric_temperature_k), (10, comp.temperature_k)] {
            let rel = relative(got, expected[k]);
            assert!(
                rel <= TOBARI_TEMPERATURE_RELATIVE,
                "case {}, T{k}: {got}",
                i + 1
            );
            worst_temperature = worst_temperature.max(rel);
        }
    }
    println!(
        "NRLMSISE-00 vs the reference output, 100-1000 km: densities {worst_density:.2e}, \
         temperatures {worst_temperature:.2e}"
    );
}

#[test]
fn validate_lower_atmosphere_falls_back_to_the_exponential_model() {
    // Cases 11–15 (0–70 km): `tobari` 0.2.0 has no lower atmosphere, so the density is Vallado's
    // exponential model's, within 25 % of NRLMSISE-00 there, and no composition is claimed.
    let mut worst = 0.0_f64;
    for (i, expected) in EXPECTED.iter().enumerate().skip(10) {
        let c = case(i);
        let s = model_for(&c).state_at_local_solar_time(c.doy, c.sec, &point_of(&c), c.lst_h);
        assert!(s.composition.is_none());
        assert_eq!(s.density_kg_m3, exponential_density_kg_m3(c.alt_km * 1e3));
        assert_eq!(s.drag_density_kg_m3, s.density_kg_m3);
        worst = worst.max(relative(s.density_kg_m3 * 1e-3, expected[5]));
    }
    println!("exponential fallback vs NRLMSISE-00, 0-70 km: worst {worst:.2}");
    assert!(worst < 0.25, "worst relative difference {worst}");
}

#[test]
fn drag_density_adds_anomalous_oxygen() {
    // Case 3 (1000 km): anomalous O (2.374394e4 cm⁻³) adds 23 % to the gtd7 total
    // (2.756772e-18 g/cm³); at 400 km (case 1) it adds 0.02 %.
    let c = case(2);
    let s = model_for(&c).state_at_local_solar_time(c.doy, c.sec, &point_of(&c), c.lst_h);
    let expected_g_cm3 = 2.756772e-18 + 16.0 * 1.66e-24 * 2.374394e4;
    assert!(relative(s.drag_density_kg_m3 * 1e-3, expected_g_cm3) < TOBARI_RELATIVE);
    assert!(s.drag_density_kg_m3 / s.density_kg_m3 > 1.2);
    // The Earth-fixed entry point goes through the geodetic conversion and the local solar time
    // UT/3600 + λ/15: at longitude −70° and 75000 s that is 16.17 h.
    let point = point_of(&c);
    let rho = model_for(&c).drag_density_kg_m3(c.doy, c.sec, &ecef_from_geodetic(&point));
    let lst = 75_000.0 / 3600.0 - 70.0 / 15.0;
    let direct = model_for(&c).state_at_local_solar_time(c.doy, c.sec, &point, lst);
    assert!((rho / direct.drag_density_kg_m3 - 1.0).abs() < 1e-9);
}

#[test]
fn space_weather_is_validated_with_the_field_name() {
    let ok = SpaceWeather {
        f107_sfu: 150.0,
        f107a_sfu: 150.0,
        ap: 4.0,
    };
    assert!(Nrlmsise00Model::new(ok).is_ok());
    for (weather, field) in [
        (
            SpaceWeather {
                f107_sfu: 0.0,
                ..ok
            },
            "f107_sfu",
        ),
        (
            SpaceWeather {
                f107a_sfu: f64::NAN,
                ..ok
            },
            "f107a_sfu",
        ),
        (SpaceWeather { ap: -1.0, ..ok }, "ap"),
        (SpaceWeather { ap: 401.0, ..ok }, "ap"),
    ] {
        match Nrlmsise00Model::new(weather) {
            Err(AtmosphereError::Invalid { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{weather:?}: {other:?}"),
        }
    }
}

#[test]
fn nrlmsise00_never_panics_over_its_input_space() {
    // Altitudes from −10 km to 2000 km, all latitudes, days, times and activity levels: finite,
    // non-negative densities (a model defect shows as NaN or a panic).
    let model = |f107: f64, ap: f64| {
        Nrlmsise00Model::new(SpaceWeather {
            f107_sfu: f107,
            f107a_sfu: f107,
            ap,
        })
        .unwrap()
    };
    for (f107, ap) in [(65.0, 0.0), (150.0, 15.0), (300.0, 400.0)] {
        let m = model(f107, ap);
        for alt_km in [-10.0, 0.0, 85.0, 120.0, 300.0, 500.0, 1000.0, 2000.0] {
            for lat in [-90.0_f64, -45.0, 0.0, 45.0, 90.0] {
                for (doy, ut) in [(1, 0.0), (100, 43_200.0), (366, 86_399.0)] {
                    let p = Geodetic {
                        lat_rad: lat.to_radians(),
                        lon_rad: 2.0,
                        height_m: alt_km * 1e3,
                    };
                    let s = m.state(doy, ut, &p);
                    assert!(
                        s.drag_density_kg_m3.is_finite()
                            && s.drag_density_kg_m3 >= 0.0
                            && s.density_kg_m3 <= s.drag_density_kg_m3,
                        "{alt_km} km {lat}° doy {doy}: {s:?}"
                    );
                }
            }
        }
    }
}

/// Vallado (2013) Table 8-4 as printed: base altitude [km], nominal density [kg/m³].
#[rustfmt::skip]
const TABLE_8_4_PRINTED: [(f64, f64); 28] = [
    (0.0, 1.225), (25.0, 3.899e-2), (30.0, 1.774e-2), (40.0, 3.972e-3), (50.0, 1.057e-3),
    (60.0, 3.206e-4), (70.0, 8.770e-5), (80.0, 1.905e-5), (90.0, 3.396e-6), (100.0, 5.297e-7),
    (110.0, 9.661e-8), (120.0, 2.438e-8), (130.0, 8.484e-9), (140.0, 3.845e-9), (150.0, 2.070e-9),
    (180.0, 5.464e-10), (200.0, 2.789e-10), (250.0, 7.248e-11), (300.0, 2.418e-11),
    (350.0, 9.518e-12), (400.0, 3.725e-12), (450.0, 1.585e-12), (500.0, 6.967e-13),
    (600.0, 1.454e-13), (700.0, 3.614e-14), (800.0, 1.170e-14), (900.0, 5.245e-15),
    (1000.0, 3.019e-15),
];

#[test]
fn validate_exponential_table_at_its_breakpoints() {
    for (h_km, rho) in TABLE_8_4_PRINTED {
        let got = exponential_density_kg_m3(h_km * 1e3);
        assert!((got / rho - 1.0).abs() < 1e-12, "{h_km} km: {got} vs {rho}");
    }
}

#[test]
fn validate_exponential_bands_meet_at_their_boundaries() {
    // Vallado's scale heights are H_i = (h_{i+1} − h_i) / ln(ρ_i / ρ_{i+1}), rounded; so each
    // band, carried to the next base, lands on the next density within the rounding (1.4e-3 at
    // 25 km, 1e-4 elsewhere). A mistyped digit in ρ or H breaks this.
    for w in VALLADO_TABLE_8_4.windows(2) {
        let (lo, hi) = (&w[0], &w[1]);
        let carried = lo.density_kg_m3
            * (-(hi.base_altitude_m - lo.base_altitude_m) / lo.scale_height_m).exp();
        let gap = (carried / hi.density_kg_m3 - 1.0).abs();
        let tolerance = if hi.base_altitude_m == 25e3 {
            1.5e-3
        } else {
            1e-4
        };
        assert!(gap < tolerance, "at {} m: gap {gap:e}", hi.base_altitude_m);
        // Continuous from the left within the same rounding.
        let left = exponential_density_kg_m3(hi.base_altitude_m - 1e-6);
        assert!((left / hi.density_kg_m3 - 1.0).abs() < tolerance);
    }
    // Beyond the table: the end bands extend (no panic, no cliff).
    assert!(exponential_density_kg_m3(-100.0) > 1.225);
    let above = exponential_density_kg_m3(1100e3);
    assert!((above / (3.019e-15 * (-100.0_f64 / 268.0).exp()) - 1.0).abs() < 1e-12);
    assert!(exponential_density_kg_m3(f64::NAN).is_nan());
}

#[test]
fn validate_corotating_wind() {
    let omega = Vector3::new(0.0, 0.0, OMEGA_EARTH_RAD_S);
    // A point moving with the Earth feels no wind.
    let r = Vector3::new(4.0e6, 5.0e6, 2.0e6);
    assert!(velocity_relative_to_air_n_m_s(&r, &omega.cross(&r), &omega).norm() < 1e-12);
    // Prograde equatorial circular orbit at 7000 km: the air moves ω⊕ r = 510.448 m/s the same
    // way (7.292115e-5 rad/s, WGS-84, × 7e6 m; the model's IERS rate differs by 2e-8).
    let v = (3.986_004_418e14_f64 / 7.0e6).sqrt();
    let rel = velocity_relative_to_air_n_m_s(
        &Vector3::new(7.0e6, 0.0, 0.0),
        &Vector3::new(0.0, v, 0.0),
        &omega,
    );
    assert!((rel - Vector3::new(0.0, v - 510.448_05, 0.0)).norm() < 1e-3);
    // Polar orbit over the equator: the air adds a westward (−y) component.
    let rel = velocity_relative_to_air_n_m_s(
        &Vector3::new(7.0e6, 0.0, 0.0),
        &Vector3::new(0.0, 0.0, v),
        &omega,
    );
    assert!((rel - Vector3::new(0.0, -510.448_05, v)).norm() < 1e-3);
}
