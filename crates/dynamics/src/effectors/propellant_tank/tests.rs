//! Unit tests of the propellant tank: the inertia models of (D6), the mass properties of (D2),
//! and parameter errors that name the field.

use nalgebra::{Matrix3, Vector3};

use super::*;

fn params(inertia: TankInertiaModel) -> PropellantTankParams {
    PropellantTankParams {
        name: "main".into(),
        r_tcb_b_m: Vector3::new(0.2, -0.1, 0.5),
        propellant_mass_kg: 40.0,
        inertia,
    }
}

/// (D6) constant volume: I = (2/5) m R², I′ = (2/5) ṁ R². For m = 40 kg, R = 0.3 m:
/// I = 0.4 · 40 · 0.09 = 1.44 kg·m²; with ṁ = −0.01 kg/s, I′ = 0.4 · (−0.01) · 0.09 =
/// −3.6e-4 kg·m²/s.
#[test]
fn constant_volume_inertia_is_proportional_to_mass() {
    let m = TankInertiaModel::ConstantVolume { radius_m: 0.3 };
    let (i, di) = m.inertia_and_rate(40.0, -0.01);
    assert!((i - 1.44).abs() < 1e-15, "{i}");
    assert!((di + 3.6e-4).abs() < 1e-18, "{di}");
    let (i2, _) = m.inertia_and_rate(20.0, 0.0);
    assert!((i2 - 0.72).abs() < 1e-15, "{i2}");
}

/// (D6) constant density: a 4/3 π R³ ρ sphere. With ρ = 1000 kg/m³ and m = 4/3 π 0.001 · 1000
/// = 4.18879 kg, R = 0.1 m and I = 0.4 m R² = 0.4 · 4.18879 · 0.01. The rate (2/3) ṁ R² is
/// dI/dm · ṁ: I ∝ m^(5/3), so dI/dm = (5/3) I/m = (5/3)(2/5) R² = (2/3) R² — checked against a
/// central difference of I(m).
#[test]
fn constant_density_inertia_follows_the_shrinking_sphere() {
    let model = TankInertiaModel::ConstantDensity {
        density_kg_m3: 1000.0,
    };
    let m = 4.0 / 3.0 * std::f64::consts::PI * 1e-3 * 1000.0;
    let (i, di) = model.inertia_and_rate(m, -0.5);
    assert!((i - 0.4 * m * 0.01).abs() < 1e-15, "{i}");
    assert!((di - (2.0 / 3.0) * (-0.5) * 0.01).abs() < 1e-15, "{di}");
    let dm = 1e-5;
    let fd = (model.inertia_and_rate(m + dm, 0.0).0 - model.inertia_and_rate(m - dm, 0.0).0)
        / (2.0 * dm);
    assert!((fd * -0.5 - di).abs() < 1e-10, "{fd}");
    // An empty tank has no inertia (and no NaN from the cube root of 0).
    assert_eq!(model.inertia_and_rate(0.0, 0.0), (0.0, 0.0));
}

/// (D2): mass, first moment and inertia about B of 40 kg at r = (0.2, −0.1, 0.5) m in a 0.3 m
/// constant-volume sphere: m r = (8, −4, 20) kg·m; [I_B] = 1.44 [1] + 40 (|r|² [1] − r rᵀ),
/// |r|² = 0.30 m².
#[test]
fn mass_properties_about_b() {
    let mut tank = PropellantTank::new(
        params(TankInertiaModel::ConstantVolume { radius_m: 0.3 }),
        "propellant_tanks[0]",
    )
    .unwrap();
    let mut x = [0.0];
    tank.initial_state(&mut x);
    assert_eq!(x, [40.0]);
    let mut mp = EffectorMassProps::default();
    tank.update_mass_props(&x, &mut mp);
    let r = Vector3::new(0.2, -0.1, 0.5);
    assert_eq!(mp.mass_kg, 40.0);
    assert!((mp.first_moment_b_kg_m - Vector3::new(8.0, -4.0, 20.0)).norm() < 1e-14);
    let want = Matrix3::from_diagonal_element(1.44)
        + (Matrix3::from_diagonal_element(0.30) - r * r.transpose()) * 40.0;
    assert!(
        (mp.inertia_pnt_b_b_kg_m2 - want).norm() < 1e-13,
        "{}",
        mp.inertia_pnt_b_b_kg_m2
    );
    assert_eq!(mp.first_moment_prime_b_kg_m_s, Vector3::zeros());
    // A round-off residue below zero adds no negative mass, and reads as empty.
    let mut mp = EffectorMassProps::default();
    tank.update_mass_props(&[-1e-18], &mut mp);
    assert_eq!(mp.mass_kg, 0.0);
    assert_eq!(tank.propellant_kg(&[-1e-18]), Some(0.0));
    assert_eq!(
        tank.propellant_kg(&[1e-12]),
        Some(0.0),
        "below 1e-12 of the load"
    );
    let mut out = [0.0; 3];
    assert_eq!(tank.outputs(&[0.0], &mut out), EMPTY);
    assert_eq!(tank.outputs(&[10.0], &mut out), 0);
    assert_eq!(out, [0.0, 0.25, 30.0]);
}

#[test]
fn errors_name_the_field() {
    let err = PropellantTank::new(
        params(TankInertiaModel::ConstantVolume { radius_m: 0.0 }),
        "propellant_tanks[1]",
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("propellant_tanks[1].radius_m"), "{err}");
    let mut p = params(TankInertiaModel::ConstantDensity {
        density_kg_m3: 1000.0,
    });
    p.propellant_mass_kg = -1.0;
    let err = PropellantTank::new(p, "propellant_tanks[0]")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("propellant_tanks[0].propellant_mass_kg"),
        "{err}"
    );
}
