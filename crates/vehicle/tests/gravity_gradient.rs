//! Gravity-gradient torque through the dynamic-effector seam, against closed forms and invariants.
//!
//! - **Invariants.** With gravity gradient on and nothing dissipative, the total energy
//!   (orbital + rotational + spring + the gradient potential GG1) and the angular momentum about
//!   the Earth's centre are conserved to round-off plus RK4 truncation.
//! - **Pitch libration** (closed form): a rigid body in a circular orbit, aligned with the local
//!   vertical frame and pitched by a small angle, oscillates in pitch at
//!   ω_lib = n √(3 (I₁ − I₃)/I₂) (Schaub & Junkins, §4.5; Hughes §9.3), 1 = along-track,
//!   2 = orbit normal (negative), 3 = nadir.
//! - **Flexing panels, numerically.** The torque the effector computes from the stage's inertia
//!   about C equals the torque of exact point-mass gravity summed over a mass cloud that
//!   reproduces each body's mass, centre of mass and inertia at the current (flexed) state, to
//!   the (size/R) order the second-order expansion neglects.

use flexdyn_dynamics::dynamic_effectors::gravity_gradient::{self, GravityGradient};
use flexdyn_dynamics::{
    DynamicEffector, EffectorMassProps, GravityModel, Spacecraft, StageState, Wrench,
};
use flexdyn_environment::EnvironmentSample;
use flexdyn_kernel::attitude::{dcm_to_mrp, mrp_to_dcm};
use flexdyn_vehicle::config::SimConfig;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::rigid_hub::rigid_hub;

/// Earth's μ (EGM2008 / WGS 84 value), for the closed-form checks in LEO.
const MU_EARTH: f64 = 3.986004418e14;
/// A small body (μ = 10⁴ m³/s², a 1 km orbit) for the invariants: the orbital energy and
/// momentum are then only 10⁵–10⁶ times the rotational ones, so the orbit's round-off (one ulp
/// of 7.5 km/s per step in LEO would be 10⁻³ J after an orbit, more than the whole exchange)
/// does not hide the exchange between orbit and attitude that the gradient drives, which is
/// strong here (3μ/R³ = 3·10⁻⁵ s⁻²).
const MU_SMALL: f64 = 1.0e4;
const R_SMALL: f64 = 1000.0;

/// A rigid hub (500 kg, principal inertia `inertia` about B = C) about a point mass `mu`, with
/// its gravity gradient.
fn rigid(mu: f64, inertia: [f64; 3], initial: &str, step_s: f64) -> Spacecraft {
    let mut sc = rigid_point_mass_only(mu, inertia, initial, step_s);
    sc.add_dynamic_effector(Box::new(GravityGradient { mu_m3_s2: mu }));
    sc
}

/// The same rigid hub under the point mass alone.
fn rigid_point_mass_only(mu: f64, inertia: [f64; 3], initial: &str, step_s: f64) -> Spacecraft {
    rigid_hub(mu, inertia, [0.0; 3], initial, step_s)
}

/// The initial table of a tumbling body on an inclined, slightly eccentric orbit of radius `r`.
fn tumbling_initial(mu: f64, r: f64) -> String {
    let v = (mu / r).sqrt();
    format!(
        "r_cn_n_m = [{r:?}, 0.0, 0.0]\nv_cn_n_m_s = [0.0, {:?}, {:?}]\n\
         sigma_bn = [0.1, -0.2, 0.3]\nomega_bn_b_rad_s = [0.01, -0.02, 0.015]",
        v * 0.95,
        v * 0.2
    )
}

/// The reference spacecraft (two flexing, undamped wings), on an inclined orbit of radius `r`
/// about a point mass `mu`, with the gravity gradient.
fn reference_orbit(mu: f64, r: f64) -> Spacecraft {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/reference.toml"
    ))
    .unwrap();
    let v = (mu / r).sqrt();
    let text = text
        .lines()
        .map(|l| {
            if l.starts_with("r_cn_n_m") {
                format!("r_cn_n_m = [{r:?}, 0.0, 0.0]")
            } else if l.starts_with("v_cn_n_m_s") {
                format!("v_cn_n_m_s = [0.0, {:?}, {:?}]", v * 0.99, v * 0.1)
            } else if l.starts_with("mu_m3_s2") {
                format!("mu_m3_s2 = {mu:?}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let mut sc = SimConfig::from_toml_str(&text)
        .unwrap()
        .build_spacecraft()
        .unwrap();
    assert!(matches!(sc.gravity(), GravityModel::PointMass { mu_m3_s2 } if *mu_m3_s2 == mu));
    sc.add_dynamic_effector(Box::new(GravityGradient { mu_m3_s2: mu }));
    sc
}

type Seen = std::sync::Arc<std::sync::Mutex<Option<StageState>>>;

/// Captures the stage of every evaluation (a test probe; not a model).
#[derive(Debug, Default)]
struct Probe(Seen);

impl DynamicEffector for Probe {
    fn name(&self) -> &str {
        "probe"
    }
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
    fn add_force_torque(&mut self, s: &StageState, _e: &EnvironmentSample, _w: &mut Wrench) {
        *self.0.lock().unwrap() = Some(*s);
    }
}

/// The stage at the current state (one derivative evaluation through a probe).
fn stage_now(sc: &mut Spacecraft, probe: &Seen) -> StageState {
    sc.hub_outputs();
    probe.lock().unwrap().unwrap()
}

/// Total energy (orbital + rotational + spring + GG1) and angular momentum about N's origin.
fn invariants(mu: f64, sc: &mut Spacecraft, probe: &Seen) -> (f64, Vector3<f64>) {
    let c = sc.conserved();
    let stage = stage_now(sc, probe);
    let v = gravity_gradient::potential_j(
        mu,
        &(stage.dcm_bn * stage.r_cn_n_m),
        &stage.inertia_pnt_c_b_kg_m2(),
    );
    (
        c.orb_energy_j + c.rot_energy_j + v,
        c.orb_ang_mom_n + c.rot_ang_mom_c_n,
    )
}

/// Drift of the invariants after `seconds`: |ΔE| relative to the rotational energy and |ΔH|
/// relative to the rotational momentum (the orbital ones are 10⁵–10⁶ times larger and would
/// hide an attitude error), and the round-off allowance for each: 8 ulp of the largest term
/// per step, n · 8 ε · max(|E_orb|/E_rot, 1) (and the same for H).
fn drift(mu: f64, sc: &mut Spacecraft, seconds: f64) -> (f64, f64, f64, f64) {
    let probe = Seen::default();
    sc.add_dynamic_effector(Box::new(Probe(probe.clone())));
    let (e0, h0) = invariants(mu, sc, &probe);
    let c = sc.conserved();
    let (rot_e, rot_h) = (c.rot_energy_j, c.rot_ang_mom_c_n.norm());
    let n = (seconds / (sc.step_ns() as f64 * 1e-9)).round() as u64;
    let allowance = |orb: f64, rot: f64| n as f64 * 8.0 * f64::EPSILON * (orb / rot).max(1.0);
    let tol_e = allowance(c.orb_energy_j.abs(), rot_e);
    let tol_h = allowance(c.orb_ang_mom_n.norm(), rot_h);
    for _ in 0..n {
        sc.step();
    }
    let (e1, h1) = invariants(mu, sc, &probe);
    (
        (e1 - e0).abs() / rot_e,
        (h1 - h0).norm() / rot_h,
        tol_e,
        tol_h,
    )
}

/// Orbit period 2π √(R³/μ) of the small-body orbit, about 1987 s.
fn small_period_s() -> f64 {
    2.0 * std::f64::consts::PI * (R_SMALL.powi(3) / MU_SMALL).sqrt()
}

#[test]
fn energy_and_momentum_about_the_planet_are_conserved_on_a_rigid_tumbling_body() {
    for (label, seconds) in [("10 s", 10.0), ("one orbit", small_period_s())] {
        let mut sc = rigid(
            MU_SMALL,
            [120.0, 90.0, 40.0],
            &tumbling_initial(MU_SMALL, R_SMALL),
            0.01,
        );
        let (de, dh, tol_e, tol_h) = drift(MU_SMALL, &mut sc, seconds);
        eprintln!(
            "rigid, {label}: |ΔE|/E_rot = {de:.3e} (round-off allowance {tol_e:.1e}), \
             |ΔH|/|H_rot| = {dh:.3e} (allowance {tol_h:.1e})"
        );
        assert!(
            de <= tol_e,
            "{label}: energy drift {de:e} of the rotational energy"
        );
        assert!(
            dh <= tol_h,
            "{label}: momentum drift {dh:e} of the rotational momentum"
        );
    }
}

#[test]
fn without_the_gradient_force_momentum_about_the_planet_is_not_conserved() {
    // The same run with the torque only (as Basilisk applies it): the momentum invariant fails,
    // so the test above can tell.
    #[derive(Debug)]
    struct TorqueOnly;
    impl DynamicEffector for TorqueOnly {
        fn name(&self) -> &str {
            "torque_only"
        }
        fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
        fn add_force_torque(&mut self, s: &StageState, _e: &EnvironmentSample, sum: &mut Wrench) {
            sum.torque_b_nm += gravity_gradient::torque_c_b_nm(
                MU_SMALL,
                &(s.dcm_bn * s.r_cn_n_m),
                &s.inertia_pnt_c_b_kg_m2(),
            );
        }
    }
    let mut sc = rigid_point_mass_only(
        MU_SMALL,
        [120.0, 90.0, 40.0],
        &tumbling_initial(MU_SMALL, R_SMALL),
        0.01,
    );
    sc.add_dynamic_effector(Box::new(TorqueOnly));
    let (_, dh, _, tol_h) = drift(MU_SMALL, &mut sc, small_period_s());
    eprintln!("torque only, one orbit: |ΔH|/|H_rot| = {dh:.3e} (allowance {tol_h:.1e})");
    assert!(dh > 100.0 * tol_h, "torque-only momentum drift {dh:e}");
}

#[test]
fn energy_and_momentum_with_flexing_panels() {
    let mut sc = reference_orbit(MU_SMALL, R_SMALL);
    let seconds = 100.0;
    let (de, dh, tol_e, tol_h) = drift(MU_SMALL, &mut sc, seconds);
    eprintln!(
        "reference wings, 100 s: |ΔE|/E_rot = {de:.3e} (round-off allowance {tol_e:.1e}), \
         |ΔH|/|H_rot| = {dh:.3e} (allowance {tol_h:.1e})"
    );
    // The total external torque and force are exact to second order, so the momentum about the
    // planet holds to round-off.
    assert!(dh <= tol_h, "momentum drift {dh:e}");
    // The energy also misses the work of the gradient on the hinges (module docs of
    // gravity_gradient), bounded by ∫ |Q_θ θ̇| dt ≤ 4 panels × 3μ/R³ × I_hinge × |θ̇|max × T, with
    // I_hinge = I_s2 + m d² = 25 + 50·0.75² kg·m² and |θ̇| ≤ 0.1 rad/s for these wings.
    let i_hinge = 25.0 + 50.0 * 0.75 * 0.75;
    let neglected = 4.0 * 3.0 * MU_SMALL / R_SMALL.powi(3) * i_hinge * 0.1 * seconds;
    let rot_e = sc.conserved().rot_energy_j;
    assert!(
        de <= tol_e + neglected / rot_e,
        "energy drift {de:e}, bound {:e}",
        neglected / rot_e
    );
}

/// Angle of pitch from the local-vertical frame: the rotation of B about the orbit normal.
fn pitch_rad(sc: &Spacecraft) -> f64 {
    let s = sc.state();
    let o3 = -s.r_bn_n.normalize();
    let o2 = -s.r_bn_n.cross(&s.v_bn_n).normalize();
    let o1 = o2.cross(&o3);
    let dcm_nb = mrp_to_dcm(&s.sigma_bn).transpose();
    let b1 = dcm_nb * Vector3::x();
    b1.dot(&o3).atan2(b1.dot(&o1))
}

#[test]
fn pitch_libration_frequency_matches_the_closed_form() {
    let (i1, i2, i3) = (100.0, 80.0, 40.0);
    let r = 7.0e6;
    let n = (MU_EARTH / (r * r * r)).sqrt();
    // LVLH at r = (R, 0, 0), v = (0, V, 0): o1 = +y, o2 = −z, o3 = −x; B = LVLH pitched by θ0
    // about o2.
    let theta0: f64 = 0.01;
    let dcm_on = Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, -1.0, -1.0, 0.0, 0.0);
    let (s, c) = theta0.sin_cos();
    // Rotation about axis 2 by θ0: [BO] = M2(θ0).
    let dcm_bo = Matrix3::new(c, 0.0, -s, 0.0, 1.0, 0.0, s, 0.0, c);
    let sigma = dcm_to_mrp(&(dcm_bo * dcm_on));
    // ω_B/N = ω_O/N = n ĥ = −n ô2, and ô2 = b̂2 after a rotation about axis 2.
    let initial = format!(
        "r_cn_n_m = [{r:?}, 0.0, 0.0]\nv_cn_n_m_s = [0.0, {:?}, 0.0]\n\
         sigma_bn = [{:?}, {:?}, {:?}]\nomega_bn_b_rad_s = [0.0, {:?}, 0.0]",
        n * r,
        sigma.x,
        sigma.y,
        sigma.z,
        -n
    );
    let mut sc = rigid(MU_EARTH, [i1, i2, i3], &initial, 0.1);
    let expected = n * (3.0 * (i1 - i3) / i2).sqrt();
    let period = 2.0 * std::f64::consts::PI / expected;
    // Zero crossings of the pitch over 2.2 periods, by linear interpolation.
    let dt = sc.step_ns() as f64 * 1e-9;
    let mut prev = pitch_rad(&sc);
    let mut crossings = Vec::new();
    let steps = (2.2 * period / dt) as u64;
    for k in 1..=steps {
        sc.step();
        let p = pitch_rad(&sc);
        if prev.signum() != p.signum() {
            crossings.push((k as f64 - 1.0 + prev / (prev - p)) * dt);
        }
        prev = p;
    }
    assert!(crossings.len() >= 4, "{crossings:?}");
    let measured_half =
        (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    let measured = std::f64::consts::PI / measured_half;
    let rel = (measured - expected).abs() / expected;
    eprintln!(
        "pitch libration: measured {measured:.9e} rad/s, closed form {expected:.9e}, rel {rel:.2e}"
    );
    // Amplitude effect ~θ0²/16 ≈ 6e-6; interpolation ≪ that at 0.1 s steps.
    assert!(rel <= 5e-5, "libration frequency off by {rel:e}");
}

/// Six point masses of total `m` at ±a_i along the principal axes reproduce a body's mass,
/// centre of mass and inertia about it: with S_i = Σ m x_i² = (J_j + J_k − J_i)/2,
/// a_i = √(3 S_i / m).
fn mass_cloud(m: f64, com_b: Vector3<f64>, inertia_c_b: Matrix3<f64>) -> Vec<(f64, Vector3<f64>)> {
    let eig = SymmetricEigen::new(inertia_c_b);
    let j = eig.eigenvalues;
    let mut out = Vec::new();
    for i in 0..3 {
        let s = 0.5 * (j[(i + 1) % 3] + j[(i + 2) % 3] - j[i]);
        let a = (3.0 * s.max(0.0) / m).sqrt();
        let axis = eig.eigenvectors.column(i).into_owned();
        out.push((m / 6.0, com_b + axis * a));
        out.push((m / 6.0, com_b - axis * a));
    }
    out
}

#[test]
fn flexed_panels_torque_matches_a_point_mass_sum() {
    let mut sc = reference_orbit(MU_EARTH, 7.0e6);
    // Flex the wings well away from rest.
    for _ in 0..1500 {
        sc.step();
    }
    let probe = std::sync::Arc::new(std::sync::Mutex::new(None));
    sc.add_dynamic_effector(Box::new(Probe(probe.clone())));
    let stage = stage_now(&mut sc, &probe);
    // Each body lump: the hub and every effector, with its mass properties about B.
    let hub = sc.hub().clone();
    let mut lumps = vec![(hub.mass_kg, hub.r_bcb_b_m, hub.inertia_bc_b_kg_m2)];
    let mut per_body = vec![EffectorMassProps::default(); sc.effectors().len()];
    sc.effector_mass_props(&mut per_body);
    for mp in per_body {
        let com = mp.first_moment_b_kg_m / mp.mass_kg;
        let i_c = mp.inertia_pnt_b_b_kg_m2
            - (Matrix3::from_diagonal_element(com.norm_squared()) - com * com.transpose())
                * mp.mass_kg;
        lumps.push((mp.mass_kg, com, i_c));
    }
    let r_cn_b = stage.dcm_bn * stage.r_cn_n_m;
    let mut torque_sum = Vector3::zeros();
    for (m, com, i_c) in lumps {
        for (mk, p_b) in mass_cloud(m, com, i_c) {
            let rho = p_b - stage.r_cb_b_m; // from C
            let r_abs = r_cn_b + rho;
            let g = -r_abs * (MU_EARTH / r_abs.norm().powi(3));
            torque_sum += rho.cross(&(g * mk));
        }
    }
    let closed = gravity_gradient::torque_c_b_nm(MU_EARTH, &r_cn_b, &stage.inertia_pnt_c_b_kg_m2());
    let rel = (torque_sum - closed).norm() / closed.norm();
    eprintln!("flexed: point-mass sum {torque_sum:?}, closed form {closed:?}, rel {rel:.2e}");
    // Third-order terms: ~ (size/R) ≈ 5 m / 7000 km ≈ 1e-6.
    assert!(rel <= 1e-5, "rel {rel:e}");
    // The panels matter: the rigid-hub inertia alone gives a different torque.
    let hub_only = gravity_gradient::torque_c_b_nm(MU_EARTH, &r_cn_b, &hub.inertia_bc_b_kg_m2);
    assert!((hub_only - closed).norm() > 0.1 * closed.norm());
}
