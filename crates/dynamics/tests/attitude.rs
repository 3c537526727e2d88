//! Attitude kernels and frame directions, checked against nalgebra's independent rotation code.
//!
//! - MRP ↔ DCM ↔ quaternion round trips (property tests);
//! - the direction of every DCM: [BN] (`dcm_bn * v_n == v_b`), [H1 B], [S1 B] and [S2 B];
//! - the MRP kinematic equation against the DCM kinematics d[BN]/dt = −[ω̃][BN];
//! - shadow-set switching keeps |σ| ≤ 1 while the attitude stays continuous.

use crate::common;

use flexdyn_dynamics::{GravityModel, PanelPair, PanelPairInitial};
use flexdyn_kernel::attitude::*;
use nalgebra::{Matrix3, Rotation3, Unit, UnitQuaternion, Vector3, Vector4};
use proptest::prelude::*;

fn vec3(r: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-r..r, -r..r, -r..r).prop_map(|(a, b, c)| Vector3::new(a, b, c))
}

fn axis_angle() -> impl Strategy<Value = (Unit<Vector3<f64>>, f64)> {
    (
        vec3(1.0).prop_filter("non-zero axis", |v| v.norm() > 1e-3),
        -3.1..3.1f64,
    )
        .prop_map(|(v, a)| (Unit::new_normalize(v), a))
}

/// [BN] of frame B obtained by rotating N by `angle` about `axis` (right hand): nalgebra's active
/// rotation matrix R maps n̂_i to b̂_i, so [BN]_ij = b̂_i·n̂_j = R_ji, i.e. [BN] = Rᵀ.
fn dcm_bn_of(axis: &Unit<Vector3<f64>>, angle: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(axis, angle).matrix().transpose()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn tilde_is_cross_product(a in vec3(10.0), b in vec3(10.0)) {
        prop_assert!((tilde(&a) * b - a.cross(&b)).norm() <= 1e-12 * (1.0 + a.norm() * b.norm()));
    }

    #[test]
    fn mrp_dcm_matches_axis_angle((axis, angle) in axis_angle()) {
        let sigma = axis.into_inner() * (angle / 4.0).tan();
        let c = mrp_to_dcm(&sigma);
        prop_assert!((c - dcm_bn_of(&axis, angle)).abs().max() < 1e-12);
        prop_assert!((c * c.transpose() - Matrix3::identity()).abs().max() < 1e-13);
        prop_assert!((c.determinant() - 1.0).abs() < 1e-13);
    }

    #[test]
    fn quaternion_matches_axis_angle_scalar_first((axis, angle) in axis_angle()) {
        let sigma = axis.into_inner() * (angle / 4.0).tan();
        let q = mrp_to_quat(&sigma);
        let nq = UnitQuaternion::from_axis_angle(&axis, angle);
        let expected = Vector4::new(nq.w, nq.i, nq.j, nq.k);
        prop_assert!((q - expected).norm() < 1e-12 || (q + expected).norm() < 1e-12);
        prop_assert!((quat_to_dcm(&q) - mrp_to_dcm(&sigma)).abs().max() < 1e-12);
    }

    #[test]
    fn mrp_dcm_quat_round_trips(sigma in vec3(3.0)) {
        let c = mrp_to_dcm(&sigma);
        let back = dcm_to_mrp(&c);
        prop_assert!(back.norm() <= 1.0 + 1e-12, "round trip must return the short set");
        // Same attitude, and the same set or its shadow.
        prop_assert!((mrp_to_dcm(&back) - c).abs().max() < 1e-11);
        let shadow = -sigma / sigma.norm_squared();
        prop_assert!((back - sigma).norm() < 1e-9 * (1.0 + sigma.norm()) || (back - shadow).norm() < 1e-9);
        let q = dcm_to_quat(&c);
        prop_assert!((q.norm() - 1.0).abs() < 1e-13 && q[0] >= 0.0);
        prop_assert!((quat_to_dcm(&q) - c).abs().max() < 1e-12);
        prop_assert!((quat_to_mrp(&q) - back).norm() < 1e-11);
    }

    #[test]
    fn dcm_bn_maps_n_components_to_b((axis, angle) in axis_angle(), v_n in vec3(5.0)) {
        // A vector fixed in N has B components b̂_i · v.
        let sigma = axis.into_inner() * (angle / 4.0).tan();
        let r = Rotation3::from_axis_angle(&axis, angle);
        let v_b = Vector3::new((r * Vector3::x()).dot(&v_n), (r * Vector3::y()).dot(&v_n), (r * Vector3::z()).dot(&v_n));
        prop_assert!((mrp_to_dcm(&sigma) * v_n - v_b).norm() < 1e-11 * (1.0 + v_n.norm()));
    }

    #[test]
    fn mrp_rate_matches_dcm_kinematics(sigma in vec3(0.9), omega in vec3(2.0)) {
        // d[BN]/dt = −[ω̃][BN]; central difference of [BN](σ(t)) along σ̇.
        let dt = 1e-6;
        let sd = mrp_rate(&sigma, &omega);
        let dc = (mrp_to_dcm(&(sigma + sd * dt)) - mrp_to_dcm(&(sigma - sd * dt))) / (2.0 * dt);
        let expected = -tilde(&omega) * mrp_to_dcm(&sigma);
        prop_assert!((dc - expected).abs().max() < 1e-7);
    }

    #[test]
    fn panel_frames_rotate_right_handed_about_the_hinge(
        (axis, angle) in axis_angle(), th1 in -3.0..3.0f64, th2 in -3.0..3.0f64, th_h2s1 in -3.0..3.0f64
    ) {
        // ŝ11 = R(ĥ12, θ1) ĥ11 and ŝ21 = R(ĥ12, θ1 + θ_H2S1 + θ2) ĥ11, with R nalgebra's active
        // right-handed rotation; ŝ13 and ŝ23 likewise rotate ĥ13.
        let mut params = common::reference_pairs(0.0).remove(0).0;
        params.dcm_h1b = dcm_bn_of(&axis, angle);
        params.theta_h2s1_rad = th_h2s1;
        let h = params.dcm_h1b;
        let (h1, h2, h3) = (h.row(0).transpose(), h.row(1).transpose(), h.row(2).transpose());
        let pair = PanelPair::new(params, PanelPairInitial::default(), "p").unwrap();
        let [[s11, s12, s13], [s21, s22, s23]] = pair.panel_axes_b(&[th1, 0.0, th2, 0.0]);
        let hinge = Unit::new_normalize(h2);
        let r1 = Rotation3::from_axis_angle(&hinge, th1);
        let r2 = Rotation3::from_axis_angle(&hinge, th1 + th_h2s1 + th2);
        prop_assert!((s11 - r1 * h1).norm() < 1e-12 && (s13 - r1 * h3).norm() < 1e-12);
        prop_assert!((s21 - r2 * h1).norm() < 1e-12 && (s23 - r2 * h3).norm() < 1e-12);
        prop_assert!((s12 - h2).norm() < 1e-15 && (s22 - h2).norm() < 1e-15);
    }
}

#[test]
fn hinge_frame_rows_are_h1_axes_in_b() {
    // The reference wing_px has dcm_h1b = diag(−1, −1, 1): ĥ1 = −b̂1, so at θ = 0 its panels
    // (at −d ŝ1 from the hinge) extend along +b̂1, away from its hinge at x = +0.5 m.
    let (params, _) = common::reference_pairs(0.0).remove(0);
    let pair = PanelPair::new(params, PanelPairInitial::default(), "p").unwrap();
    let [[s11, _, _], _] = pair.panel_axes_b(&[0.0; 4]);
    assert_eq!(s11, Vector3::new(-1.0, 0.0, 0.0));
}

#[test]
fn shadow_set_switching_keeps_sigma_short_and_attitude_continuous() {
    // A fast tumble (with flexing panels) crosses |σ| = 1 many times in 20 s.
    let mut initial = common::reference_initial();
    initial.omega_bn_b_rad_s = Vector3::new(0.9, 2.1, -0.4);
    let mut sc = common::build(
        common::reference_hub(),
        GravityModel::None,
        common::reference_pairs(0.0),
        initial,
        1_000_000,
    );
    let h = 1e-3;
    let mut switches = 0;
    let mut prev_sigma = sc.state().sigma_bn;
    let mut prev = mrp_to_dcm(&prev_sigma);
    for _ in 0..20_000 {
        let omega_before = sc.state().omega_bn_b.norm();
        sc.step();
        let sigma = sc.state().sigma_bn;
        assert!(sigma.norm() <= 1.0 + 1e-15, "|σ| = {} > 1", sigma.norm());
        if (sigma - prev_sigma).norm() > 0.5 {
            switches += 1;
        }
        // The rotation between consecutive attitudes is the small angle |ω| h, whichever set.
        let c = mrp_to_dcm(&sigma);
        let cos_angle = (((c * prev.transpose()).trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
        let angle = cos_angle.acos();
        assert!(
            angle <= 1.05 * omega_before.max(sc.state().omega_bn_b.norm()) * h + 1e-9,
            "attitude jumped by {angle} rad"
        );
        prev = c;
        prev_sigma = sigma;
    }
    assert!(
        switches >= 3,
        "only {switches} shadow-set switches: the test did not exercise switching"
    );
}
