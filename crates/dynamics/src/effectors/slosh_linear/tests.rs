//! Unit tests of the linear slosh particle: parameter errors name the field, and the tank
//! mapping puts the particle where (T2)–(T4) say.

use nalgebra::Vector3;

use super::*;
use crate::slosh_tank::CylindricalTank;

fn entry() -> SloshLinearEntry {
    SloshLinearEntry {
        name: "p1".into(),
        p_hat_b: Vector3::x(),
        source: SloshLinearSource::Direct {
            r_pb_b_m: Vector3::new(0.1, 0.0, -0.1),
            mass_kg: 10.0,
            k_n_m: 100.0,
        },
        c_n_s_m: 0.0,
        rho_m: 0.05,
        rho_dot_m_s: 0.0,
    }
}

#[test]
fn errors_name_the_field() {
    let mut e = entry();
    e.p_hat_b = Vector3::new(1.0, 1.0, 0.0);
    let err = SloshLinear::new(e.resolve("slosh_linear[2]").unwrap(), "slosh_linear[2]")
        .unwrap_err()
        .to_string();
    assert!(err.contains("slosh_linear[2].p_hat_b"), "{err}");
    let mut e = entry();
    e.source = SloshLinearSource::Tank {
        tank: CylindricalTank {
            radius_m: 0.5,
            fill_height_m: -1.0,
            density_kg_m3: 1000.0,
            r_bottom_b_m: Vector3::zeros(),
            axis_b: Vector3::z(),
        },
        settling_accel_m_s2: 0.1,
    };
    let err = e.resolve("slosh_linear[0]").unwrap_err().to_string();
    assert!(err.contains("slosh_linear[0].tank.fill_height_m"), "{err}");
}

#[test]
fn a_tank_sets_mass_stiffness_and_rest_point() {
    let tank = CylindricalTank {
        radius_m: 0.4,
        fill_height_m: 0.6,
        density_kg_m3: 1440.0,
        r_bottom_b_m: Vector3::new(0.0, 0.2, -0.5),
        axis_b: Vector3::z(),
    };
    let mut e = entry();
    e.source = SloshLinearSource::Tank {
        tank,
        settling_accel_m_s2: 0.05,
    };
    let p = e.resolve("slosh_linear[0]").unwrap();
    let mode = tank.first_mode();
    assert_eq!(p.mass_kg, mode.slosh_mass_kg);
    assert_eq!(p.k_n_m, mode.slosh_mass_kg * 0.05 / mode.pendulum_length_m);
    assert_eq!(
        p.r_pb_b_m,
        Vector3::new(0.0, 0.2, -0.5 + mode.slosh_height_m)
    );
    // An axis along the tank's is refused: the mode is lateral.
    e.p_hat_b = Vector3::z();
    let err = e.resolve("slosh_linear[0]").unwrap_err().to_string();
    assert!(err.contains("slosh_linear[0].p_hat_b"), "{err}");
}
