//! Drag, solar radiation pressure and the residual dipole through the dynamic-effector seam.
//!
//! - **Work and energy.** With drag on (and gravity a point mass, nothing else dissipative), the
//!   change of the total energy (orbital + rotational) equals the work the drag wrench does,
//!   ∫ (F·v_B + τ·ω) dt, integrated with the RK4 weights of the stages the effector was called
//!   at, to round-off plus RK4 truncation.
//! - **Single plates at known incidence**, through the effector with the attitude rotating N
//!   into B: the analytic drag and SRP forces, and the torque of a plate off B.
//! - **m × B** in B components for a rotated attitude.

use std::sync::{Arc, Mutex};

use flexdyn_dynamics::dynamic_effectors::aero_drag::AeroDrag;
use flexdyn_dynamics::dynamic_effectors::residual_dipole::ResidualDipole;
use flexdyn_dynamics::dynamic_effectors::solar_pressure::SolarPressure;
use flexdyn_dynamics::{DynamicEffector, Spacecraft, StageState, Wrench};
use flexdyn_environment::ephemeris::AU_M;
use flexdyn_environment::facets::{
    Facet, FacetModel, SOLAR_IRRADIANCE_1AU_W_M2, SPEED_OF_LIGHT_M_S,
};
use flexdyn_environment::EnvironmentSample;
use flexdyn_kernel::attitude::dcm_to_mrp;
use nalgebra::{Matrix3, Vector3};

use crate::rigid_hub::rigid_hub;

const MU_EARTH: f64 = 3.986004418e14;

fn plate(normal_b: Vector3<f64>, r_cp_b_m: Vector3<f64>, area_m2: f64) -> Facet {
    Facet {
        area_m2,
        normal_b,
        r_cp_b_m,
        drag_coefficient: 2.2,
        absorbed: 0.5,
        specular: 0.3,
        diffuse: 0.2,
    }
}

/// A 1 m box whose face centres are offset from B by `offset_b_m` (so drag has a torque about
/// B), plus one 2 m² plate 3 m out along +y.
fn box_with_wing(offset_b_m: Vector3<f64>) -> FacetModel {
    let mut facets: Vec<Facet> = (0..6)
        .map(|i| {
            let n = if i % 2 == 0 { 1.0 } else { -1.0 } * Vector3::ith(i / 2, 1.0);
            plate(n, offset_b_m + 0.5 * n, 1.0)
        })
        .collect();
    facets.push(plate(
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 1.5, 0.0),
        2.0,
    ));
    FacetModel::new(facets).unwrap()
}

/// A rigid hub (500 kg, its centre of mass 0.39 m from B, so a force at the wrong point would
/// show) on a LEO orbit about a point mass, tumbling.
fn rigid_leo(step_s: f64) -> Spacecraft {
    let r = 6.878e6;
    let v = (MU_EARTH / r).sqrt();
    let initial = format!(
        "r_cn_n_m = [{r:?}, 0.0, 0.0]\nv_cn_n_m_s = [0.0, {:?}, {:?}]\n\
         sigma_bn = [0.1, -0.2, 0.3]\nomega_bn_b_rad_s = [0.15, -0.2, 0.1]",
        v * 0.98,
        v * 0.2
    );
    rigid_hub(
        MU_EARTH,
        [300.0, 250.0, 180.0],
        [0.2, -0.1, 0.3],
        &initial,
        step_s,
    )
}

/// Work done by a wrapped effector: Σ over steps of h/6 (P₁ + 2P₂ + 2P₃ + P₄), P = F·v_B + τ·ω
/// at each stage (the RK4 quadrature of the power, as the integrator sees it).
#[derive(Debug, Default)]
struct Meter {
    counting: bool,
    work_j: f64,
    /// The torque's share, ∫ τ·ω dt.
    torque_work_j: f64,
    evaluations: u64,
}

#[derive(Debug)]
struct Metered {
    inner: Box<dyn DynamicEffector>,
    meter: Arc<Mutex<Meter>>,
    step_s: f64,
}

impl DynamicEffector for Metered {
    fn name(&self) -> &str {
        "metered"
    }
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
    fn add_force_torque(&mut self, s: &StageState, env: &EnvironmentSample, sum: &mut Wrench) {
        let mut own = Wrench::default();
        self.inner.add_force_torque(s, env, &mut own);
        sum.force_b_newton += own.force_b_newton;
        sum.torque_b_nm += own.torque_b_nm;
        let mut m = self.meter.lock().unwrap();
        if m.counting {
            let v_b = s.dcm_bn * s.v_bn_n_m_s;
            let power_w = own.force_b_newton.dot(&v_b) + own.torque_b_nm.dot(&s.omega_bn_b_rad_s);
            // Stage 1 and 4 sit at 0 and h, stages 2 and 3 at h/2.
            let weight = if (s.dt_stage_s - 0.5 * self.step_s).abs() < 1e-12 {
                2.0
            } else {
                1.0
            };
            m.work_j += self.step_s / 6.0 * weight * power_w;
            m.torque_work_j +=
                self.step_s / 6.0 * weight * own.torque_b_nm.dot(&s.omega_bn_b_rad_s);
            m.evaluations += 1;
        }
    }
}

/// (ΔE, W, the torque's share of W, round-off allowance) over `seconds` of drag at density `rho` with a constant wind.
fn energy_and_work(step_s: f64, seconds: f64, rho: f64) -> (f64, f64, f64, f64) {
    let mut sc = rigid_leo(step_s);
    let meter = Arc::new(Mutex::new(Meter::default()));
    sc.add_dynamic_effector(Box::new(Metered {
        inner: Box::new(AeroDrag {
            facets: box_with_wing(Vector3::new(0.3, -0.2, 0.4)),
        }),
        meter: meter.clone(),
        step_s,
    }));
    sc.set_environment(&EnvironmentSample {
        density_kg_m3: rho,
        wind_n_m_s: Vector3::new(0.0, 450.0, 0.0),
        ..EnvironmentSample::NONE
    });
    let energy = |sc: &Spacecraft| {
        let c = sc.conserved();
        c.orb_energy_j + c.rot_energy_j
    };
    let e0 = energy(&sc);
    let n = (seconds / step_s).round() as u64;
    meter.lock().unwrap().counting = true;
    for _ in 0..n {
        sc.step();
    }
    let m = meter.lock().unwrap();
    assert_eq!(m.evaluations, 4 * n, "one call per RK4 stage");
    // Round-off: 8 ulp of the orbital energy, growing as √n (the steps' rounding errors are
    // independent, so they add like a random walk).
    let allowance = (n as f64).sqrt() * 8.0 * f64::EPSILON * e0.abs();
    (energy(&sc) - e0, m.work_j, m.torque_work_j, allowance)
}

#[test]
fn energy_lost_equals_the_work_done_by_drag() {
    // ρ = 1e-9 kg/m³ (about 150 km; 100× a 400 km orbit's, so the loss stands far above the
    // orbital energy's round-off) over 100 s at 10 ms.
    let (de, w, w_torque, allowance) = energy_and_work(0.01, 100.0, 1e-9);
    let (de_coarse, w_coarse, _, _) = energy_and_work(0.04, 100.0, 1e-9);
    let (err, err_coarse) = ((de - w).abs(), (de_coarse - w_coarse).abs());
    println!(
        "drag, 100 s: ΔE {de:.6} J, W {w:.6} J (torque share {w_torque:.4} J), |ΔE − W| \
         {err:.3e} J ({:.2e} of W); at 40 ms {err_coarse:.3e} J; round-off allowance \
         {allowance:.3e} J",
        err / w.abs()
    );
    assert!(w < -1e3, "drag must take energy out: W = {w}");
    // The mismatch is round-off of the orbital energy (1.5e10 J: one ulp is 2e-6 J) plus RK4
    // truncation; the allowance is 8 ulp of it per step, as in crates/vehicle/tests/gravity_gradient.rs.
    assert!(
        err <= allowance,
        "|ΔE − W| = {err} J, allowance {allowance} J"
    );
    assert!(err_coarse <= allowance / 4.0, "40 ms: {err_coarse} J");
    // The test can tell a torque applied wrongly: the torque's work alone stands well above
    // the allowance.
    assert!(w_torque.abs() > 5.0 * allowance, "torque work {w_torque} J");
}

/// The stage of a vehicle at `r`, moving at `v`, with attitude [BN] = `dcm_bn`, not rotating.
fn stage(dcm_bn: Matrix3<f64>, v_n: Vector3<f64>) -> StageState {
    StageState {
        t_step_ns: 0,
        dt_stage_s: 0.0,
        r_bn_n_m: Vector3::new(6.878e6, 0.0, 0.0),
        v_bn_n_m_s: v_n,
        sigma_bn: dcm_to_mrp(&dcm_bn),
        dcm_bn,
        omega_bn_b_rad_s: Vector3::zeros(),
        mass_kg: 500.0,
        r_cb_b_m: Vector3::zeros(),
        r_cn_n_m: Vector3::new(6.878e6, 0.0, 0.0),
        inertia_pnt_b_b_kg_m2: Matrix3::identity(),
    }
}

/// [BN] of a rotation of B by `angle` about N's z axis.
fn dcm_bn_about_z(angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    Matrix3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0)
}

fn wrench_of(e: &mut dyn DynamicEffector, s: &StageState, env: &EnvironmentSample) -> Wrench {
    let mut w = Wrench::default();
    e.add_force_torque(s, env, &mut w);
    w
}

#[test]
fn drag_on_one_plate_at_known_incidence() {
    // B is N turned 30° about z; the plate's normal is x_B. The velocity relative to the air is
    // v − wind = (7500, 0, 0) − (300, 0, 0) m/s in N, so cos θ = n̂·v̂ = cos 30°.
    let angle = 30_f64.to_radians();
    let dcm_bn = dcm_bn_about_z(angle);
    let r_cp = Vector3::new(0.0, 0.8, 0.0);
    let mut drag = AeroDrag {
        facets: FacetModel::new(vec![plate(Vector3::x(), r_cp, 1.5)]).unwrap(),
    };
    let env = EnvironmentSample {
        density_kg_m3: 3e-12,
        wind_n_m_s: Vector3::new(300.0, 0.0, 0.0),
        ..EnvironmentSample::NONE
    };
    let w = wrench_of(
        &mut drag,
        &stage(dcm_bn, Vector3::new(7500.0, 0.0, 0.0)),
        &env,
    );
    // F = −½ ρ C_D A |v|² cos θ v̂, v = 7200 m/s along x_N.
    let magnitude = 0.5 * 3e-12 * 2.2 * 1.5 * 7200.0_f64.powi(2) * angle.cos();
    let expected_n = Vector3::new(-magnitude, 0.0, 0.0);
    let force_n: Vector3<f64> = dcm_bn.transpose() * w.force_b_newton;
    assert!(
        (force_n - expected_n).norm() < 1e-12 * magnitude,
        "{force_n}"
    );
    // τ = r_cp × F up to round-off: a few ulps of |r_cp| |F| (the model sums C_D A (n̂·v) r_cp
    // and crosses with v, a different order of the same products).
    let moment_nm = r_cp.norm() * w.force_b_newton.norm();
    assert!((w.torque_b_nm - r_cp.cross(&w.force_b_newton)).norm() < 1e-15 * moment_nm);
    assert!(moment_nm > 0.0);
    // Turned past 90°, the plate faces away from the flow: no force.
    let away = wrench_of(
        &mut drag,
        &stage(
            dcm_bn_about_z(100_f64.to_radians()),
            Vector3::new(7500.0, 0.0, 0.0),
        ),
        &env,
    );
    assert_eq!(away.force_b_newton, Vector3::zeros());
    // Vacuum: nothing.
    let vacuum = wrench_of(
        &mut drag,
        &stage(dcm_bn, Vector3::new(7500.0, 0.0, 0.0)),
        &EnvironmentSample::NONE,
    );
    assert_eq!(vacuum.force_b_newton, Vector3::zeros());
}

#[test]
fn solar_pressure_on_one_plate_at_known_incidence_and_in_shadow() {
    // The Sun 1 AU away along x_N; B is N turned 45° about z; the plate's normal is x_B, so
    // cos θ = cos 45°. Half the disc is visible (penumbra).
    let angle = 45_f64.to_radians();
    let dcm_bn = dcm_bn_about_z(angle);
    let mut srp = SolarPressure::new(
        FacetModel::new(vec![plate(Vector3::x(), Vector3::zeros(), 2.0)]).unwrap(),
        SOLAR_IRRADIANCE_1AU_W_M2,
    );
    let env = EnvironmentSample {
        r_sun_b_n_m: Vector3::new(AU_M, 0.0, 0.0),
        shadow_factor: 0.5,
        ..EnvironmentSample::NONE
    };
    let w = wrench_of(&mut srp, &stage(dcm_bn, Vector3::zeros()), &env);
    // F = −P A cos θ [(ρa + ρd) ŝ + (2 ρs cos θ + ⅔ ρd) n̂], P = ν Φ/c at 1 AU.
    let p = 0.5 * SOLAR_IRRADIANCE_1AU_W_M2 / SPEED_OF_LIGHT_M_S;
    let c = angle.cos();
    let s_hat_n = Vector3::x();
    let n_hat_n = dcm_bn.transpose() * Vector3::x();
    let expected_n: Vector3<f64> =
        -p * 2.0 * c * ((0.5 + 0.2) * s_hat_n + (2.0 * 0.3 * c + 2.0 / 3.0 * 0.2) * n_hat_n);
    let force_n: Vector3<f64> = dcm_bn.transpose() * w.force_b_newton;
    assert!(
        (force_n - expected_n).norm() < 1e-12 * expected_n.norm(),
        "{force_n} vs {expected_n}"
    );
    // At 2 AU the pressure is a quarter.
    let far = EnvironmentSample {
        r_sun_b_n_m: Vector3::new(2.0 * AU_M, 0.0, 0.0),
        ..env
    };
    let w_far = wrench_of(&mut srp, &stage(dcm_bn, Vector3::zeros()), &far);
    assert!((w_far.force_b_newton * 4.0 - w.force_b_newton).norm() < 1e-12 * expected_n.norm());
    // The effector holds P and ŝ per environment sample; a changed irradiance (a campaign's
    // dispersed value set on a built effector) must not reuse them: twice Φ, twice the force.
    srp.irradiance_1au_w_m2 *= 2.0;
    let w_bright = wrench_of(&mut srp, &stage(dcm_bn, Vector3::zeros()), &env);
    assert!(
        (w_bright.force_b_newton - w.force_b_newton * 2.0).norm() < 1e-12 * expected_n.norm(),
        "{} vs 2 × {}",
        w_bright.force_b_newton,
        w.force_b_newton
    );
    srp.irradiance_1au_w_m2 /= 2.0;
    // Umbra, and no Sun configured: nothing.
    for dark in [
        EnvironmentSample {
            shadow_factor: 0.0,
            ..env
        },
        EnvironmentSample::NONE,
    ] {
        let w = wrench_of(&mut srp, &stage(dcm_bn, Vector3::zeros()), &dark);
        assert_eq!(w.force_b_newton, Vector3::zeros());
    }
}

#[test]
fn residual_dipole_torque_in_body_components() {
    // m = 0.5 A·m² along z_B; B = 30 µT along x_N; B is N turned 90° about z, so the field is
    // along −y_B and τ = m × B = 0.5 ẑ × (−30e-6 ŷ) = +1.5e-5 x̂ (N·m).
    let mut dipole = ResidualDipole {
        m_b_am2: Vector3::new(0.0, 0.0, 0.5),
    };
    let env = EnvironmentSample {
        b_field_n_t: Vector3::new(30e-6, 0.0, 0.0),
        ..EnvironmentSample::NONE
    };
    let w = wrench_of(
        &mut dipole,
        &stage(dcm_bn_about_z(90_f64.to_radians()), Vector3::zeros()),
        &env,
    );
    assert!(
        (w.torque_b_nm - Vector3::new(1.5e-5, 0.0, 0.0)).norm() < 1e-18,
        "{}",
        w.torque_b_nm
    );
    assert_eq!(w.force_b_newton, Vector3::zeros());
}
