//! The facet model against the momentum balance of single plates, and a closed cube's symmetry.

use flexdyn_environment::ephemeris::AU_M;
use flexdyn_environment::facets::{
    solar_pressure_n_m2, Facet, FacetError, FacetModel, SOLAR_IRRADIANCE_1AU_W_M2,
    SPEED_OF_LIGHT_M_S,
};
use nalgebra::Vector3;

fn plate(normal_b: Vector3<f64>, absorbed: f64, specular: f64, diffuse: f64) -> Facet {
    Facet {
        area_m2: 2.0,
        normal_b,
        r_cp_b_m: Vector3::new(0.5, -1.0, 2.0),
        drag_coefficient: 2.2,
        absorbed,
        specular,
        diffuse,
    }
}

fn close(a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
    (a - b).norm() <= 1e-12 * (1.0 + b.norm())
}

#[test]
fn validate_drag_on_a_plate_at_known_incidence() {
    // A 2 m² plate, C_D = 2.2, normal along x, flow at 30° from the normal, ρ = 1e-12 kg/m³,
    // |v| = 7500 m/s: F = ½ ρ C_D A v² cos 30° = 1.07171e-4 N against the motion; the torque is
    // the moment of F at the centre of pressure.
    let f = plate(Vector3::x(), 1.0, 0.0, 0.0);
    let model = FacetModel::new(vec![f]).unwrap();
    let (c30, s30) = (30.0_f64.to_radians().cos(), 30.0_f64.to_radians().sin());
    let v = 7500.0 * Vector3::new(c30, s30, 0.0);
    let w = model.drag_wrench_b(&v, 1e-12);
    let magnitude = 0.5 * 1e-12 * 2.2 * 2.0 * 7500.0 * 7500.0 * c30;
    assert!((magnitude - 1.071_706_4e-4).abs() < 1e-11);
    let force = -magnitude * v.normalize();
    assert!(close(&w.force_b_newton, &force), "{}", w.force_b_newton);
    assert!(close(&w.torque_b_nm, &f.r_cp_b_m.cross(&force)));
    // Facing away from the flow, or at grazing incidence: nothing.
    assert_eq!(
        model.drag_wrench_b(&-v, 1e-12).force_b_newton,
        Vector3::zeros()
    );
    assert_eq!(
        model
            .drag_wrench_b(&Vector3::new(0.0, 7500.0, 0.0), 1e-12)
            .force_b_newton,
        Vector3::zeros()
    );
    assert_eq!(
        model.drag_wrench_b(&Vector3::zeros(), 1e-12).force_b_newton,
        Vector3::zeros()
    );
}

#[test]
fn validate_srp_on_a_plate_by_photon_momentum() {
    let p = 4.5e-6;
    let n = Vector3::x();
    let area = 2.0;
    // Normal incidence on a perfect mirror: the photons' momentum reverses, F = −2 P A n̂.
    let mirror = FacetModel::new(vec![plate(n, 0.0, 1.0, 0.0)]).unwrap();
    let w = mirror.srp_wrench_b(&n, p);
    assert!(close(&w.force_b_newton, &(-2.0 * p * area * n)));
    // A mirror at 45°: only the normal momentum reverses, 2 P A cos²45° = P A along −n̂.
    let s45 = Vector3::new(1.0, 1.0, 0.0).normalize();
    let w = mirror.srp_wrench_b(&s45, p);
    assert!(close(&w.force_b_newton, &(-p * area * n)));
    // A black plate at 60°: the intercepted momentum P A cos 60° along −ŝ.
    let s60 = Vector3::new(0.5, 0.75_f64.sqrt(), 0.0);
    let black = FacetModel::new(vec![plate(n, 1.0, 0.0, 0.0)]).unwrap();
    let w = black.srp_wrench_b(&s60, p);
    assert!(close(&w.force_b_newton, &(-p * area * 0.5 * s60)));
    // The direction argument need not be unit length.
    assert!(close(
        &black.srp_wrench_b(&(7.0 * s60), p).force_b_newton,
        &w.force_b_newton
    ));
    // A Lambertian plate at normal incidence: absorbed (1) plus the recoil of the re-emission
    // (the cosine-weighted mean of cos θ over the hemisphere, integrated numerically below).
    let recoil = lambert_mean_normal_recoil();
    assert!((recoil - 2.0 / 3.0).abs() < 1e-9, "{recoil}");
    let lambert = FacetModel::new(vec![plate(n, 0.0, 0.0, 1.0)]).unwrap();
    let w = lambert.srp_wrench_b(&n, p);
    assert!(close(&w.force_b_newton, &(-p * area * (1.0 + recoil) * n)));
    // The torque is the moment at the centre of pressure; behind the plate nothing.
    assert!(close(
        &w.torque_b_nm,
        &Vector3::new(0.5, -1.0, 2.0).cross(&w.force_b_newton)
    ));
    assert_eq!(
        lambert.srp_wrench_b(&-n, p).force_b_newton,
        Vector3::zeros()
    );
    assert_eq!(
        lambert.srp_wrench_b(&Vector3::zeros(), p).force_b_newton,
        Vector3::zeros()
    );
}

/// ∫ cos θ · (cos θ / π) dΩ over the hemisphere (Lambert's law), by the midpoint rule in θ.
fn lambert_mean_normal_recoil() -> f64 {
    let steps = 200_000;
    let d = std::f64::consts::FRAC_PI_2 / f64::from(steps);
    (0..steps)
        .map(|i| {
            let theta = (f64::from(i) + 0.5) * d;
            theta.cos() * theta.cos() / std::f64::consts::PI
                * std::f64::consts::TAU
                * theta.sin()
                * d
        })
        .sum()
}

#[test]
fn validate_solar_pressure() {
    // 1361 W/m² / c = 4.5398e-6 N/m² at 1 AU; 1/r²; the shadow factor scales it.
    let p1 = SOLAR_IRRADIANCE_1AU_W_M2 / SPEED_OF_LIGHT_M_S;
    assert!((p1 - 4.539_81e-6).abs() < 1e-11);
    assert!((solar_pressure_n_m2(AU_M, 1.0, SOLAR_IRRADIANCE_1AU_W_M2) - p1).abs() < 1e-20);
    assert!((solar_pressure_n_m2(0.5 * AU_M, 0.25, 1361.0) - p1).abs() < 1e-20);
    assert_eq!(solar_pressure_n_m2(AU_M, 0.0, 1361.0), 0.0);
}

/// A cube of side `side` centred at `centre`: six outward facets at the face centres.
fn cube(centre: Vector3<f64>, side: f64, absorbed: f64, specular: f64, diffuse: f64) -> Vec<Facet> {
    let mut facets = Vec::new();
    for axis in 0..3 {
        for sign in [1.0, -1.0] {
            let mut n = Vector3::zeros();
            n[axis] = sign;
            facets.push(Facet {
                area_m2: side * side,
                normal_b: n,
                r_cp_b_m: centre + 0.5 * side * n,
                drag_coefficient: 2.2,
                absorbed,
                specular,
                diffuse,
            });
        }
    }
    facets
}

#[test]
fn validate_closed_cube_has_no_torque_about_its_centre() {
    // Any flow and Sun direction: every facet force is either along the flow/Sun line through a
    // point on it or along a face normal through the centre, so the moments cancel about the
    // centre. About another point B the torque is then r_centre × F.
    let centre = Vector3::new(0.3, -0.2, 1.1);
    let side = 1.5;
    let model = FacetModel::new(cube(centre, side, 0.3, 0.5, 0.2)).unwrap();
    let centred = FacetModel::new(cube(Vector3::zeros(), side, 0.3, 0.5, 0.2)).unwrap();
    let directions = [
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(1.0, 2.0, -3.0),
        Vector3::new(-0.2, 0.7, 0.1),
        Vector3::new(-1.0, -1.0, -1.0),
        Vector3::new(0.0, -4.0, 0.5),
    ];
    for d in directions {
        let v = 7600.0 * d.normalize();
        let drag = centred.drag_wrench_b(&v, 3e-12);
        let srp = centred.srp_wrench_b(&d, 4.5e-6);
        assert!(drag.torque_b_nm.norm() < 1e-15 * drag.force_b_newton.norm().max(1e-30));
        assert!(srp.torque_b_nm.norm() < 1e-15 * srp.force_b_newton.norm().max(1e-30));
        // The drag is that of the projected area A (|v̂x| + |v̂y| + |v̂z|).
        let v_hat = v.normalize();
        let projected = side * side * (v_hat.x.abs() + v_hat.y.abs() + v_hat.z.abs());
        let expected = -0.5 * 3e-12 * 2.2 * projected * 7600.0 * 7600.0 * v_hat;
        assert!(close(&drag.force_b_newton, &expected));
        // Shifted cube: same force, torque r_centre × F about B.
        let shifted = model.drag_wrench_b(&v, 3e-12);
        assert!(close(&shifted.force_b_newton, &drag.force_b_newton));
        assert!(close(
            &shifted.torque_b_nm,
            &centre.cross(&drag.force_b_newton)
        ));
        let shifted = model.srp_wrench_b(&d, 4.5e-6);
        assert!(close(
            &shifted.torque_b_nm,
            &centre.cross(&srp.force_b_newton)
        ));
    }
}

#[test]
fn invalid_facets_name_the_facet_and_the_field() {
    let good = plate(Vector3::x(), 0.2, 0.5, 0.3);
    let cases: [(Facet, &str); 7] = [
        (
            Facet {
                area_m2: -1.0,
                ..good
            },
            "area_m2",
        ),
        (
            Facet {
                normal_b: Vector3::new(1.0, 1.0, 0.0),
                ..good
            },
            "normal_b",
        ),
        (
            Facet {
                r_cp_b_m: Vector3::new(0.0, f64::NAN, 0.0),
                ..good
            },
            "r_cp_b_m",
        ),
        (
            Facet {
                drag_coefficient: f64::INFINITY,
                ..good
            },
            "drag_coefficient",
        ),
        (
            Facet {
                specular: 1.5,
                ..good
            },
            "specular",
        ),
        (
            Facet {
                diffuse: -0.1,
                ..good
            },
            "diffuse",
        ),
        (
            Facet {
                absorbed: 0.5,
                ..good
            },
            "absorbed + specular + diffuse",
        ),
    ];
    for (bad, field) in cases {
        match FacetModel::new(vec![good, good, bad]) {
            Err(FacetError::Invalid {
                index, field: f, ..
            }) => {
                assert_eq!((index, f), (2, field));
            }
            other => panic!("{field}: {other:?}"),
        }
    }
    let message = FacetModel::new(vec![Facet {
        area_m2: -1.0,
        ..good
    }])
    .unwrap_err()
    .to_string();
    assert!(message.starts_with("facets[0].area_m2 = -1"), "{message}");
}

/// The whole-model sums are factored (one cross product for drag; r × n̂ fixed in B for SRP's
/// normal term). They must equal the plain per-facet sums Σ F_k and Σ r_k × F_k, built here from
/// the single-plate forces, for facets of mixed optics and attitudes.
#[test]
fn factored_model_sums_equal_the_per_facet_sums() {
    let facets: Vec<Facet> = (0..9)
        .map(|k| {
            let t = k as f64;
            Facet {
                area_m2: 0.5 + 0.4 * t,
                normal_b: Vector3::new((1.3 * t).sin(), (0.7 * t + 0.4).cos(), 0.3 - 0.1 * t)
                    .normalize(),
                r_cp_b_m: Vector3::new(0.2 * t - 0.8, 1.1 - 0.3 * t, 0.5 * (t * 0.9).cos()),
                drag_coefficient: 2.0 + 0.05 * t,
                absorbed: 0.1 + 0.08 * t,
                specular: 0.6 - 0.05 * t,
                diffuse: 0.3 - 0.03 * t,
            }
        })
        .collect();
    let model = FacetModel::new(facets.clone()).unwrap();
    for j in 0..40 {
        let t = j as f64;
        let d = Vector3::new(
            (0.9 * t).cos(),
            (1.7 * t + 0.2).sin(),
            (0.4 * t).cos() - 0.3,
        );
        let (rho, p) = (2.7e-12, 4.56e-6);
        let v = 7600.0 * d.normalize();
        let (mut f_drag, mut t_drag) = (Vector3::zeros(), Vector3::zeros());
        let (mut f_srp, mut t_srp) = (Vector3::zeros(), Vector3::zeros());
        for f in &facets {
            let fd = f.drag_force_b_newton(&v, rho);
            f_drag += fd;
            t_drag += f.r_cp_b_m.cross(&fd);
            let fs = f.srp_force_b_newton(&d.normalize(), p);
            f_srp += fs;
            t_srp += f.r_cp_b_m.cross(&fs);
        }
        let drag = model.drag_wrench_b(&v, rho);
        let srp = model.srp_wrench_b(&d, p);
        let near = |a: &Vector3<f64>, b: &Vector3<f64>, scale: f64| (a - b).norm() <= 1e-14 * scale;
        let drag_scale = f_drag.norm().max(t_drag.norm());
        let srp_scale = f_srp.norm().max(t_srp.norm());
        assert!(
            drag_scale > 0.0 && srp_scale > 0.0,
            "direction {j} lights some facet"
        );
        assert!(
            near(&drag.force_b_newton, &f_drag, drag_scale),
            "drag force, direction {j}"
        );
        assert!(
            near(&drag.torque_b_nm, &t_drag, drag_scale),
            "drag torque, direction {j}"
        );
        assert!(
            near(&srp.force_b_newton, &f_srp, srp_scale),
            "srp force, direction {j}"
        );
        assert!(
            near(&srp.torque_b_nm, &t_srp, srp_scale),
            "srp torque, direction {j}"
        );
    }
}
