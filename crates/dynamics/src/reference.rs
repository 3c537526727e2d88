//! The reference spacecraft of `scenarios/reference.toml` (a 750 kg hub with two dual-hinged
//! wings), built in code so a program, a test or a benchmark can vary one thing (gravity,
//! damping, pair count, hub mass, wheels), and the conservation measure the physics is checked
//! with: the largest relative drift of the rotational and orbital energy and angular momentum
//! over a run ([`run_drift`]).
//!
//! The physics tests (`tests/`), the root package's benchmarks and the examples use it, instead
//! of each carrying a copy.

use crate::{
    GravityModel, HubInitial, HubParams, InitialTranslation, PanelPair, PanelPairInitial,
    PanelPairParams, PanelParams, ReactionWheel, ReactionWheelParams, Spacecraft, StateEffector,
};
use nalgebra::{Matrix3, Vector3};

/// μ of the Earth [m³/s²], as in the reference config.
pub const MU_EARTH: f64 = 3.986004415e14;

/// The hub: 750 kg, inertia diag(900, 800, 600) kg m² about its centre of mass, which lies 1 m
/// along +b3 from point B.
pub fn reference_hub() -> HubParams {
    HubParams {
        mass_kg: 750.0,
        inertia_bc_b_kg_m2: Matrix3::from_diagonal(&Vector3::new(900.0, 800.0, 600.0)),
        r_bcb_b_m: Vector3::new(0.0, 0.0, 1.0),
    }
}

/// One panel: 50 kg, 0.75 m from its hinge, hinge stiffness 100 N m/rad and damping
/// `c_nm_s_rad`.
pub fn reference_panel(c_nm_s_rad: f64) -> PanelParams {
    PanelParams {
        mass_kg: 50.0,
        inertia_s_kg_m2: Vector3::new(50.0, 25.0, 25.0),
        d_m: 0.75,
        k_nm_rad: 100.0,
        c_nm_s_rad,
        width_m: None,
        thickness_m: None,
    }
}

/// A dual-hinged pair of two reference panels (1.5 m apart) hinged at `r_h1b_b_m` with hinge
/// frame `dcm_h1b` and damping `c` \[N m s/rad\].
pub fn pair_params(
    name: &str,
    r_h1b_b_m: Vector3<f64>,
    dcm_h1b: Matrix3<f64>,
    c: f64,
) -> PanelPairParams {
    PanelPairParams {
        name: name.into(),
        r_h1b_b_m,
        dcm_h1b,
        theta_h2s1_rad: 0.0,
        l1_m: 1.5,
        panel1: reference_panel(c),
        panel2: reference_panel(c),
        motor_torque_nm: [0.0; 2],
    }
}

/// The two wings of the reference spacecraft with their initial deflections.
pub fn reference_pairs(c: f64) -> Vec<(PanelPairParams, PanelPairInitial)> {
    vec![
        (
            pair_params(
                "wing_px",
                Vector3::new(0.5, 0.0, 1.0),
                Matrix3::from_diagonal(&Vector3::new(-1.0, -1.0, 1.0)),
                c,
            ),
            PanelPairInitial {
                theta1_rad: 5f64.to_radians(),
                theta1_dot_rad_s: 0.0,
                theta2_rad: -3f64.to_radians(),
                theta2_dot_rad_s: 0.0,
            },
        ),
        (
            pair_params(
                "wing_mx",
                Vector3::new(-0.5, 0.0, 1.0),
                Matrix3::identity(),
                c,
            ),
            PanelPairInitial {
                theta1_rad: -2f64.to_radians(),
                theta1_dot_rad_s: 0.0,
                theta2_rad: 4f64.to_radians(),
                theta2_dot_rad_s: 0.0,
            },
        ),
    ]
}

/// `n` pairs spread evenly around the hub's b3 axis (the benchmark and scaling tests use it),
/// with the reference wing geometry and small distinct deflections.
pub fn ring_pairs(n: usize, c: f64) -> Vec<(PanelPairParams, PanelPairInitial)> {
    (0..n)
        .map(|k| {
            let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            let (s, co) = a.sin_cos();
            // H1 axes: ĥ1 points inward (the panel extends along −ĥ1, outward), ĥ3 = b̂3.
            let dcm_h1b = Matrix3::new(-co, -s, 0.0, s, -co, 0.0, 0.0, 0.0, 1.0);
            let params = pair_params(
                &format!("wing{k}"),
                Vector3::new(0.5 * co, 0.5 * s, 1.0),
                dcm_h1b,
                c,
            );
            let init = PanelPairInitial {
                theta1_rad: 0.05 * (1.0 + k as f64).sin(),
                theta1_dot_rad_s: 0.0,
                theta2_rad: -0.04 * (2.0 + k as f64).cos(),
                theta2_dot_rad_s: 0.0,
            };
            (params, init)
        })
        .collect()
}

/// The reference spacecraft's initial state: the system centre of mass on a ~10 000 km orbit,
/// attitude N, tumbling at (0.05, −0.05, 0.05) rad/s.
pub fn reference_initial() -> HubInitial {
    HubInitial {
        translation: InitialTranslation::CenterOfMass {
            r_cn_n_m: Vector3::new(-4020338.69, 7490566.74, 5248299.04),
            v_cn_n_m_s: Vector3::new(-5199.77710904, -3436.68156331, 1041.57627160),
        },
        sigma_bn: Vector3::zeros(),
        omega_bn_b_rad_s: Vector3::new(0.05, -0.05, 0.05),
    }
}

/// Point B at the origin of N, at rest, attitude N, not turning: the start of the tests that
/// watch one effect on a free vehicle (a slosh mode, a burn).
pub fn at_rest() -> HubInitial {
    HubInitial {
        translation: InitialTranslation::PointB {
            r_bn_n_m: Vector3::zeros(),
            v_bn_n_m_s: Vector3::zeros(),
        },
        sigma_bn: Vector3::zeros(),
        omega_bn_b_rad_s: Vector3::zeros(),
    }
}

/// A spacecraft of `hub` and `pairs` (hinge names `panel_pairs[i]`).
///
/// # Panics
/// If a pair or the spacecraft is invalid: the fixtures here are valid by construction.
pub fn build(
    hub: HubParams,
    gravity: GravityModel,
    pairs: Vec<(PanelPairParams, PanelPairInitial)>,
    initial: HubInitial,
    step_ns: u64,
) -> Spacecraft {
    let effectors: Vec<Box<dyn StateEffector>> = pairs
        .into_iter()
        .enumerate()
        .map(|(i, (p, init))| {
            Box::new(PanelPair::new(p, init, &format!("panel_pairs[{i}]")).expect("valid pair"))
                as Box<dyn StateEffector>
        })
        .collect();
    Spacecraft::new(hub, gravity, effectors, initial, step_ns).expect("valid spacecraft")
}

/// The reference spacecraft with the given gravity model and hinge damping, 1 ms step.
pub fn reference(gravity: GravityModel, c: f64) -> Spacecraft {
    build(
        reference_hub(),
        gravity,
        reference_pairs(c),
        reference_initial(),
        1_000_000,
    )
}

/// Largest relative drift max_t |x(t) − x(0)| / |x(0)| of scalars and vectors.
#[derive(Debug, Default, Clone, Copy)]
pub struct Drift {
    /// Rotational + spring energy.
    pub rot_energy: f64,
    /// Angular momentum about the system's centre of mass C.
    pub rot_ang_mom: f64,
    /// Orbital energy (0 when the initial one is 0).
    pub orb_energy: f64,
    /// Orbital angular momentum (0 when the initial one is 0).
    pub orb_ang_mom: f64,
}

impl Drift {
    /// Asserts the rotational + spring energy and the angular momentum about C each drifted by at
    /// most `bound` (a test's check: it panics, naming the quantity, when one did not). The energy is checked on its own: summed with the orbital energy, erratum E1
    /// would hide at the 1e-11 level (ERRATA.md).
    pub fn assert_rotational(&self, bound: f64) {
        assert!(
            self.rot_energy <= bound,
            "rotational + spring energy drift {:e}",
            self.rot_energy
        );
        assert!(
            self.rot_ang_mom <= bound,
            "angular momentum about C drift {:e}",
            self.rot_ang_mom
        );
    }

    /// [`Self::assert_rotational`] plus the orbital energy and orbital angular momentum.
    pub fn assert_all(&self, bound: f64) {
        self.assert_rotational(bound);
        assert!(
            self.orb_energy <= bound,
            "orbital energy drift {:e}",
            self.orb_energy
        );
        assert!(
            self.orb_ang_mom <= bound,
            "orbital angular momentum drift {:e}",
            self.orb_ang_mom
        );
    }
}

/// Steps `n` times, tracking the relative drift of every conserved quantity.
pub fn run_drift(sc: &mut Spacecraft, n: usize) -> Drift {
    let c0 = sc.conserved();
    let mut d = Drift::default();
    for _ in 0..n {
        sc.step();
        let c = sc.conserved();
        d.rot_energy = d
            .rot_energy
            .max(((c.rot_energy_j - c0.rot_energy_j) / c0.rot_energy_j).abs());
        d.rot_ang_mom = d
            .rot_ang_mom
            .max((c.rot_ang_mom_c_n - c0.rot_ang_mom_c_n).norm() / c0.rot_ang_mom_c_n.norm());
        if c0.orb_energy_j != 0.0 {
            d.orb_energy = d
                .orb_energy
                .max(((c.orb_energy_j - c0.orb_energy_j) / c0.orb_energy_j).abs());
        }
        if c0.orb_ang_mom_n.norm() != 0.0 {
            d.orb_ang_mom = d
                .orb_ang_mom
                .max((c.orb_ang_mom_n - c0.orb_ang_mom_n).norm() / c0.orb_ang_mom_n.norm());
        }
    }
    d
}

/// The reference spacecraft's effectors (two pairs, no damping) plus `n` frictionless wheels at
/// 100 rad/s on a pyramid's axes (elevation 30°, azimuths 45° + 90° j, repeated), as the
/// benches build them; `wheel` may change each wheel's parameters (friction) before it is built.
pub fn reference_effectors_with_wheels(
    n: usize,
    wheel: impl Fn(&mut ReactionWheelParams),
) -> Vec<Box<dyn StateEffector>> {
    let mut effectors: Vec<Box<dyn StateEffector>> = reference_pairs(0.0)
        .into_iter()
        .enumerate()
        .map(|(i, (p, init))| {
            Box::new(PanelPair::new(p, init, &format!("panel_pairs[{i}]")).unwrap())
                as Box<dyn StateEffector>
        })
        .collect();
    let e = 30f64.to_radians();
    for j in 0..n {
        let az = (45.0 + 90.0 * j as f64).to_radians();
        let axis = Vector3::new(e.cos() * az.cos(), e.cos() * az.sin(), e.sin());
        let mut w = ReactionWheelParams::balanced(
            &format!("rw{j}"),
            axis,
            Vector3::new(0.4 * az.cos(), 0.4 * az.sin(), 0.5),
            4.0,
            0.05,
            0.03,
            100.0,
            0.2,
            600.0,
        );
        wheel(&mut w);
        effectors.push(Box::new(
            ReactionWheel::new(w, &format!("reaction_wheels[{j}]")).unwrap(),
        ));
    }
    effectors
}

/// Median ns per step of `sc` over `batches` batches of `steps` steps, after `steps` warm-up
/// steps (the benches' timer).
pub fn median_ns_per_step(sc: &mut Spacecraft, batches: usize, steps: usize) -> f64 {
    for _ in 0..steps {
        sc.step();
    }
    let mut per_step: Vec<f64> = (0..batches)
        .map(|_| {
            let t = std::time::Instant::now();
            for _ in 0..steps {
                sc.step();
            }
            std::hint::black_box(sc.state().omega_bn_b);
            t.elapsed().as_secs_f64() * 1e9 / steps as f64
        })
        .collect();
    per_step.sort_by(|a, b| a.total_cmp(b));
    per_step[per_step.len() / 2]
}

/// A chain of `n` unequal panels hinged at the reference `wing_px` hinge (H1 at (0.5, 0, 1) m,
/// ĥ1 = −b̂1, so the chain extends along +b̂1), with damping `c` \[N m s/rad\] on every hinge
/// and small distinct initial deflections. Panel k (0-based) has mass 40 − 3k kg, inertia
/// (30 − 2k, 15 − k, 16 − k) kg m², length 1.5 − 0.05k m, d = 0.45 l + 0.02k m, stiffness
/// 100 + 15k N m/rad, θ = 0.06 sin(1 + k) rad and θ̇ = 0.02 cos(2 + k) rad/s: every parameter
/// differs from panel to panel (`tools/peers/mujoco_chain.py` builds the same chain). Valid
/// for 1 ≤ n ≤ 10.
pub fn unequal_chain(n: usize, c: f64) -> crate::effectors::panel_chain::PanelChainParams {
    use crate::effectors::panel_chain::{ChainPanelParams, PanelChainParams};
    PanelChainParams {
        name: format!("chain{n}"),
        r_h1b_b_m: Vector3::new(0.5, 0.0, 1.0),
        dcm_h1b: Matrix3::from_diagonal(&Vector3::new(-1.0, -1.0, 1.0)),
        panels: (0..n)
            .map(|k| {
                let kf = k as f64;
                let l_m = 1.5 - 0.05 * kf;
                ChainPanelParams {
                    mass_kg: 40.0 - 3.0 * kf,
                    inertia_s_kg_m2: Vector3::new(30.0 - 2.0 * kf, 15.0 - kf, 16.0 - kf),
                    d_m: 0.45 * l_m + 0.02 * kf,
                    l_m,
                    k_nm_rad: 100.0 + 15.0 * kf,
                    c_nm_s_rad: c,
                    theta_h_rad: 0.0,
                    motor_torque_nm: 0.0,
                    theta_rad: 0.06 * (1.0 + kf).sin(),
                    theta_dot_rad_s: 0.02 * (2.0 + kf).cos(),
                }
            })
            .collect(),
    }
}

/// The reference hub with one [`unequal_chain`] of `n` panels (no pairs) and the reference
/// initial state, 1 ms step.
///
/// # Panics
/// If `n` is outside 1 … 10 (the fixture's panels stay valid only there).
pub fn reference_with_chain(gravity: GravityModel, n: usize, c: f64) -> Spacecraft {
    let chain =
        crate::effectors::panel_chain::PanelChain::new(unequal_chain(n, c), "panel_chains[0]")
            .expect("valid chain");
    Spacecraft::new(
        reference_hub(),
        gravity,
        vec![Box::new(chain)],
        reference_initial(),
        1_000_000,
    )
    .expect("valid spacecraft")
}
