//! Independent cross-check of the back-substitution dynamics against a dense Kane formulation.
//!
//! The library (`flexdyn_dynamics`) solves the hub + dual-hinged-panel equations by the
//! back-substitution of Section V of Allard & Schaub (citation in `docs/errata.md`). This file
//! re-derives the same dynamics from first principles with Kane's method (Section IV of the
//! paper, corrected as `docs/errata.md` lists), builds the
//! *full* system mass matrix and forcing vector, and solves them with a dense LU. Nothing here is
//! taken from the library's dynamics code: the only library items used are the parameter types and
//! the public `Spacecraft::derivatives` entry point being checked. The DCM/MRP helpers are written
//! again below, too.
//!
//! # Kinematics (all vectors in B components, positions relative to point B)
//! Per pair i (index dropped), with the conventions of ERRATA.md "Conventions":
//! - [S1 B] = M2(θ1)[H1 B], [S2 B] = M2(θ2) M2(θ_H2S1)[S1 B]; the rows of [Sk B] are ŝk1, ŝk2, ŝk3.
//!   Both hinge axes are ŝ12 = ŝ22 = ĥ2, fixed in B.
//! - r1 = r_Sc1/B = r_H1 − d1 ŝ11, r2 = r_Sc2/B = r_H1 − l1 ŝ11 − d2 ŝ21.
//! - B-frame rates of the panel axes (panel k spins relative to B about ŝ12 at Θ̇k, with
//!   Θ̇1 = θ̇1, Θ̇2 = θ̇1 + θ̇2): ŝk1′ = Θ̇k ŝ12 × ŝk1 = −Θ̇k ŝk3, ŝk3′ = Θ̇k ŝk1. Hence
//!   - r1′ = d1 θ̇1 ŝ13,                      r1″ = d1 θ̈1 ŝ13 + d1 θ̇1² ŝ11,
//!   - r2′ = l1 θ̇1 ŝ13 + d2 Θ̇2 ŝ23,           r2″ = l1 θ̈1 ŝ13 + d2 Θ̈2 ŝ23 + l1 θ̇1² ŝ11 + d2 Θ̇2² ŝ21.
//!
//!   (Eqs. 85–86 of the paper; `validate_dense_kane_kinematics_fd` checks these by finite
//!   differences of the position functions, so the sign of every ŝ3 term is verified, not assumed.)
//! - ω_S1/N = ω + θ̇1 ŝ12, ω_S2/N = ω + Θ̇2 ŝ12 (Eqs. 87–88); their inertial derivatives are
//!   ω̇ + θ̈1 ŝ12 + ω × θ̇1 ŝ12 and ω̇ + Θ̈2 ŝ12 + ω × Θ̇2 ŝ12 (ŝ12 is fixed in B).
//!
//! # Generalized speeds and unknowns
//! u = [v_B (B components of ṙ_B/N); ω_B/N (B); θ̇_11; θ̇_12; …; θ̇_N1; θ̇_N2] (Eq. 82).
//! Because v_B is taken in the rotating B frame, u̇_1..3 is *not* the inertial acceleration; the
//! unknown solved for here is instead q̈ = [a_B; ω̇; θ̈…] with a_B = r̈_B/N in B components (the
//! inertial acceleration, = [BN]·dx.v_bn_n in the library's terms). The partial velocities — and
//! hence the mass matrix — are the same whichever of the two is used; only the velocity-product
//! remainders differ, and those below are written for a_B. For ω, the B-frame and inertial
//! derivatives coincide, so ω̇ in B components is unambiguous.
//!
//! # Partial velocities (Table 1 of the paper, with its empty columns filled per ERRATA.md)
//! Columns are [v (3) | ω (3) | θ̇1 | θ̇2] of this pair; zero for other pairs' θ̇ columns.
//! - hub CoM Bc:  v = [I, −[r̃_Bc/B], 0, 0],                      ω = [0, I, 0, 0]
//! - panel 1 Sc1: v = [I, −[r̃1], d1 ŝ13, 0],                     ω = [0, I, ŝ12, 0]
//! - panel 2 Sc2: v = [I, −[r̃2], l1 ŝ13 + d2 ŝ23, d2 ŝ23],       ω = [0, I, ŝ12, ŝ12]
//! - point B (where F_ext acts): v = [I, 0, 0, 0].
//!
//! # Kane's equations F_r + F_r* = 0 (Eqs. 91, 93, 95)
//! Every body's CoM acceleration and angular acceleration are affine in q̈:
//! a_body = V q̈ + a_vp, α_body = W q̈ + α_vp, with the velocity-product remainders
//! - hub:     a_vp = ω×(ω×r_Bc/B),                          α_vp = 0
//! - panel k: a_vp = ω×(ω×rk) + 2 ω×rk′ + rk″|θ̈=0,          α_vp = ω × Θ̇k ŝ12
//!
//! With T* = −[I_c]α − ω_body × [I_c]ω_body (Eq. 102, [I_c] about the body's own CoM — the
//! ERRATA.md Section IV note on Eqs. 103–107 that the hub term must use [I_hub,Bc]), Kane gives
//! `M q̈ = f` with
//! - M = Σ_bodies (m Vᵀ V + Wᵀ [I_c] W)   (symmetric positive-definite),
//! - f = Σ_bodies [Vᵀ (F_body − m a_vp) + Wᵀ (T_body − [I_c] α_vp − ω_body × [I_c] ω_body)]
//!   + [F_ext; 0; 0…] (point B's partial velocity).
//!
//! Forces and torques on the bodies:
//! - hub: external torque L, uniform gravity m_hub g, and the hinge-1 reactions −τ_i1 ŝ_i12;
//! - panel 1: τ1 ŝ12 from hinge 1 and −τ2 ŝ12 (reaction of hinge 2), gravity m1 g;
//! - panel 2: τ2 ŝ12, gravity m2 g;
//! - τ1 = −k1 θ1 − c1 θ̇1 + u1, τ2 = −k2 θ2 − c2 θ̇2 + u2 (u = motor torques);
//! - g = gravity at the system CoM C (uniform field, ERRATA.md "Conventions").
//!
//! The internal hinge torques are put on the bodies and projected by the partial angular
//! velocities like any other torque, so their generalized forces (τ1 on the θ1 row, τ2 on the θ2
//! row, nothing on the hub rows) come out of the algebra rather than being written in by hand.
//!
//! Expanded, the hub rows reproduce Eqs. 100 and 111 (with E2's m_sc[c̃] coupling appearing as
//! Σ m Vωᵀ Vv = −Σ m [r̃]… = m_sc[c̃]), and the θ rows reproduce Eq. 117 per panel. Per ERRATA.md
//! Section IV, Kane's θ_i1 row equals the paper's Eq. 119 + Eq. 120 and its θ_i2 row equals
//! Eq. 120 with erratum E1 applied (ω̇ coefficient I_s22 ŝ22ᵀ − m2 d2 ŝ23ᵀ[r̃_Sc2/B]). The solution
//! q̈ is the same either way; only the dense matrix here is the symmetric (Kane) one.

use flexdyn_dynamics::integrator::{ButcherTableau, METHODS, RK8};
use flexdyn_dynamics::{
    GravityModel, HubInitial, HubParams, InitialTranslation, PanelPair, PanelPairInitial,
    PanelPairParams, PanelParams, ReactionWheel, ReactionWheelParams, Spacecraft, State,
    StateEffector,
};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

pub(crate) type V3 = Vector3<f64>;
pub(crate) type M3 = Matrix3<f64>;

/// Earth's gravitational parameter [m³/s²], for the point-mass gravity cases.
pub(crate) const MU_EARTH: f64 = 3.986_004_418e14;

// ---------------------------------------------------------------------------------------------
// Small independent helpers
// ---------------------------------------------------------------------------------------------

/// [ã] with [ã] b = a × b.
pub(crate) fn skew(a: &V3) -> M3 {
    M3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// Principal rotation about axis 2: M2(a) = [[c, 0, −s], [0, 1, 0], [s, 0, c]].
pub(crate) fn rot2(a: f64) -> M3 {
    let (s, c) = a.sin_cos();
    M3::new(c, 0.0, -s, 0.0, 1.0, 0.0, s, 0.0, c)
}

/// [BN] from the MRP σ_B/N, written from the Euler parameters (β0 = (1−σ²)/(1+σ²),
/// βi = 2σi/(1+σ²)) rather than the closed MRP form the library uses.
pub(crate) fn dcm_bn_from_mrp(s: &V3) -> M3 {
    let s2 = s.norm_squared();
    let b0 = (1.0 - s2) / (1.0 + s2);
    let b = s * (2.0 / (1.0 + s2));
    let (b1, b2, b3) = (b.x, b.y, b.z);
    M3::new(
        b0 * b0 + b1 * b1 - b2 * b2 - b3 * b3,
        2.0 * (b1 * b2 + b0 * b3),
        2.0 * (b1 * b3 - b0 * b2),
        2.0 * (b1 * b2 - b0 * b3),
        b0 * b0 - b1 * b1 + b2 * b2 - b3 * b3,
        2.0 * (b2 * b3 + b0 * b1),
        2.0 * (b1 * b3 + b0 * b2),
        2.0 * (b2 * b3 - b0 * b1),
        b0 * b0 - b1 * b1 - b2 * b2 + b3 * b3,
    )
}

/// Row k of a DCM as a column vector (the k-th axis of the frame, in the other frame's components).
pub(crate) fn axis(c: &M3, k: usize) -> V3 {
    c.row(k).transpose()
}

/// Seeded uniform sampler.
pub(crate) struct Rng(ChaCha8Rng);

impl Rng {
    pub(crate) fn new(seed: u64) -> Self {
        Self(ChaCha8Rng::seed_from_u64(seed))
    }
    /// Uniform in [0, 1).
    pub(crate) fn unit(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    pub(crate) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    /// Log-uniform in [lo, hi].
    pub(crate) fn log_range(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp()
    }
    pub(crate) fn vec(&mut self, half: f64) -> V3 {
        V3::new(
            self.range(-half, half),
            self.range(-half, half),
            self.range(-half, half),
        )
    }
    /// A uniformly distributed proper rotation matrix (from a uniformly distributed unit quaternion).
    pub(crate) fn rotation(&mut self) -> M3 {
        loop {
            let q = [
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            ];
            let n2: f64 = q.iter().map(|x| x * x).sum();
            if !(0.01..=1.0).contains(&n2) {
                continue;
            }
            let n = n2.sqrt();
            let (w, x, y, z) = (q[0] / n, q[1] / n, q[2] / n, q[3] / n);
            return M3::new(
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            );
        }
    }
    /// Principal moments of a random mass distribution: (B+C, A+C, A+B) with A, B, C > 0 the
    /// second moments along the three axes, so the triangle inequality holds by construction.
    /// One of the three may be nearly zero (a thin plate, I3 ≈ I1 + I2); two may not (a rod is
    /// neither a hub nor a panel).
    pub(crate) fn principal_moments(&mut self, scale: f64) -> V3 {
        let a = scale * self.log_range(0.05, 1.0);
        let b = scale * self.log_range(0.05, 1.0);
        let c = scale * self.log_range(1e-4, 1.0);
        V3::new(b + c, a + c, a + b)
    }
}

// ---------------------------------------------------------------------------------------------
// Random test cases
// ---------------------------------------------------------------------------------------------

#[derive(Debug, Clone)]
pub(crate) struct Config {
    pub(crate) hub: HubParams,
    pub(crate) pairs: Vec<PanelPairParams>,
    /// None: free space; Some(μ): point-mass gravity.
    pub(crate) mu: Option<f64>,
    pub(crate) force_b: V3,
    pub(crate) torque_b: V3,
    /// Reaction wheels and their commanded motor torques [N·m] (after the panel pairs in the
    /// library's effector order).
    pub(crate) wheels: Vec<(ReactionWheelParams, f64)>,
}

#[derive(Debug, Clone)]
struct Sample {
    r_bn_n: V3,
    v_bn_n: V3,
    sigma_bn: V3,
    omega_bn_b: V3,
    /// θ1, θ̇1, θ2, θ̇2 per pair (the library's layout).
    eff: Vec<f64>,
    /// [rad/s] wheel speeds Ω relative to the hub, one per wheel.
    wheel_omega: Vec<f64>,
}

/// Sampling ranges. `Plausible` spacecraft (hub 100–2000 kg, panels 1–200 kg) are what the
/// product simulates; `Extreme` ones (every mass independently 1–1000 kg, so a 1 kg hub may carry
/// a 200 kg panel on a 5 m arm) probe the ill-conditioned corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Ranges {
    Plausible,
    Extreme,
}

impl Ranges {
    fn hub_mass_kg(self) -> (f64, f64) {
        match self {
            Ranges::Plausible => (100.0, 2000.0),
            Ranges::Extreme => (1.0, 1000.0),
        }
    }
    fn panel_mass_kg(self) -> (f64, f64) {
        match self {
            Ranges::Plausible => (1.0, 200.0),
            Ranges::Extreme => (1.0, 1000.0),
        }
    }
}

pub(crate) fn random_panel(rng: &mut Rng, size_m: f64, ranges: Ranges) -> PanelParams {
    let (lo, hi) = ranges.panel_mass_kg();
    let mass_kg = rng.log_range(lo, hi);
    PanelParams {
        mass_kg,
        inertia_s_kg_m2: rng.principal_moments(mass_kg * size_m * size_m),
        d_m: 0.0, // set by the caller
        k_nm_rad: if rng.unit() < 0.15 {
            0.0
        } else {
            rng.log_range(0.1, 1000.0)
        },
        c_nm_s_rad: if rng.unit() < 0.15 {
            0.0
        } else {
            rng.log_range(0.01, 100.0)
        },
        width_m: None,
        thickness_m: None,
    }
}

pub(crate) fn random_config(
    rng: &mut Rng,
    n_pairs: usize,
    gravity: bool,
    ranges: Ranges,
) -> Config {
    let (lo, hi) = ranges.hub_mass_kg();
    let hub_mass = rng.log_range(lo, hi);
    let hub_size = rng.range(0.3, 3.0);
    let rot = rng.rotation();
    let moments = rng.principal_moments(hub_mass * hub_size * hub_size);
    let i_hub = rot * M3::from_diagonal(&moments) * rot.transpose();
    let i_hub = (i_hub + i_hub.transpose()) * 0.5;
    let hub = HubParams {
        mass_kg: hub_mass,
        inertia_bc_b_kg_m2: i_hub,
        r_bcb_b_m: rng.vec(1.0),
    };
    let pairs = (0..n_pairs)
        .map(|i| {
            let l1 = rng.range(0.2, 5.0);
            let mut panel1 = random_panel(rng, l1, ranges);
            panel1.d_m = l1 * rng.range(0.05, 1.0);
            let l2 = rng.range(0.2, 5.0);
            let mut panel2 = random_panel(rng, l2, ranges);
            panel2.d_m = l2 * rng.range(0.05, 1.0);
            PanelPairParams {
                name: format!("pair{i}"),
                r_h1b_b_m: rng.vec(2.5),
                dcm_h1b: rng.rotation(),
                theta_h2s1_rad: rng.range(-std::f64::consts::PI, std::f64::consts::PI),
                l1_m: l1,
                panel1,
                panel2,
                motor_torque_nm: [rng.range(-20.0, 20.0), rng.range(-20.0, 20.0)],
            }
        })
        .collect();
    Config {
        hub,
        pairs,
        mu: gravity.then_some(MU_EARTH),
        force_b: rng.vec(200.0),
        torque_b: rng.vec(200.0),
        wheels: Vec::new(),
    }
}

/// `n` random balanced wheels with friction and a commanded torque within the motor's limit.
/// The rotor: J_s = ½ m ρ² (a disk of radius ρ), J_t between ½ J_s and J_s (so the rotor's
/// principal moments obey the triangle inequality).
fn random_wheels(rng: &mut Rng, n: usize) -> Vec<(ReactionWheelParams, f64)> {
    (0..n)
        .map(|j| {
            let axis = loop {
                let a = rng.vec(1.0);
                if (0.1..=1.0).contains(&a.norm()) {
                    break a.normalize();
                }
            };
            let mass = rng.log_range(0.5, 20.0);
            let rho = rng.range(0.05, 0.25);
            let j_s = 0.5 * mass * rho * rho;
            let mut p = ReactionWheelParams::balanced(
                &format!("rw{j}"),
                axis,
                rng.vec(1.5),
                mass,
                j_s,
                j_s * rng.range(0.5, 1.0),
                0.0,
                1.0,
                600.0,
            );
            if rng.unit() < 0.8 {
                p.viscous_friction_nm_s_rad = rng.log_range(1e-6, 1e-3);
                p.coulomb_friction_nm = rng.log_range(1e-4, 1e-2);
            }
            (p, rng.range(-0.9, 0.9))
        })
        .collect()
}

fn random_sample(rng: &mut Rng, n_pairs: usize) -> Sample {
    // Random MRP with |σ| ≤ 1 (full attitude coverage).
    let sigma_bn = loop {
        let s = rng.vec(1.0);
        if s.norm() <= 1.0 {
            break s;
        }
    };
    // Low-Earth-orbit-like position (only matters under gravity).
    let dir = loop {
        let d = rng.vec(1.0);
        let n = d.norm();
        if (0.1..=1.0).contains(&n) {
            break d / n;
        }
    };
    let mut eff = Vec::with_capacity(4 * n_pairs);
    for _ in 0..n_pairs {
        eff.push(rng.range(-1.0, 1.0));
        eff.push(rng.range(-1.0, 1.0));
        eff.push(rng.range(-1.0, 1.0));
        eff.push(rng.range(-1.0, 1.0));
    }
    let omega = loop {
        let w = rng.vec(0.5);
        if w.norm() <= 0.5 {
            break w;
        }
    };
    Sample {
        r_bn_n: dir * rng.range(6.6e6, 8.0e6),
        v_bn_n: rng.vec(8000.0),
        sigma_bn,
        omega_bn_b: omega,
        eff,
        wheel_omega: Vec::new(),
    }
}

/// Number of configurations × states per configuration = 420 × 3 = 1260 random states.
const N_CONFIGS: usize = 420;
const STATES_PER_CONFIG: usize = 3;

/// The deterministic set of random cases: 1, 2 or 3 pairs in turn; every fourth configuration
/// under point-mass gravity, the rest in free space.
fn cases(seed: u64, ranges: Ranges) -> Vec<(Config, Vec<Sample>)> {
    let mut rng = Rng::new(seed);
    (0..N_CONFIGS)
        .map(|k| {
            let n_pairs = 1 + k % 3;
            let cfg = random_config(&mut rng, n_pairs, k % 4 == 3, ranges);
            let samples = (0..STATES_PER_CONFIG)
                .map(|_| random_sample(&mut rng, n_pairs))
                .collect();
            (cfg, samples)
        })
        .collect()
}

/// Cases with reaction wheels: 1 or 2 pairs and 1–4 wheels, wheel speeds up to ±590 rad/s
/// (within the motor's speed limit, so the commanded torque applies unclipped), 1 in 4 under
/// point-mass gravity.
fn cases_with_wheels(seed: u64) -> Vec<(Config, Vec<Sample>)> {
    let mut rng = Rng::new(seed);
    (0..N_CONFIGS)
        .map(|k| {
            let n_pairs = 1 + k % 2;
            let mut cfg = random_config(&mut rng, n_pairs, k % 4 == 3, Ranges::Plausible);
            cfg.wheels = random_wheels(&mut rng, 1 + k % 4);
            let samples = (0..STATES_PER_CONFIG)
                .map(|_| {
                    let mut x = random_sample(&mut rng, n_pairs);
                    x.wheel_omega = (0..cfg.wheels.len())
                        .map(|_| rng.range(-590.0, 590.0))
                        .collect();
                    x
                })
                .collect();
            (cfg, samples)
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// The dense Kane model
// ---------------------------------------------------------------------------------------------

/// Panel-pair kinematics at (θ1, θ2): frames and CoM positions, B components.
struct PairGeom {
    /// [S1 B]; rows ŝ11, ŝ12, ŝ13.
    c1: M3,
    /// [S2 B]; rows ŝ21, ŝ22, ŝ23.
    c2: M3,
    /// r_Sc1/B.
    r1: V3,
    /// r_Sc2/B.
    r2: V3,
}

fn pair_geom(p: &PanelPairParams, th1: f64, th2: f64) -> PairGeom {
    let c1 = rot2(th1) * p.dcm_h1b;
    let c2 = rot2(th2) * rot2(p.theta_h2s1_rad) * c1;
    let s11 = axis(&c1, 0);
    let s21 = axis(&c2, 0);
    let r1 = p.r_h1b_b_m - s11 * p.panel1.d_m;
    let r2 = p.r_h1b_b_m - s11 * p.l1_m - s21 * p.panel2.d_m;
    PairGeom { c1, c2, r1, r2 }
}

/// Which (deliberately wrong, for the negative controls) variant of the dense model to build.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Variant {
    /// The correct model.
    Exact,
    /// Erratum E1 reproduced: the θ_i2 row's ω̇ coefficient gets +m2 d2 ŝ23ᵀ[r̃_Sc2/B] instead of −.
    PrintedE1,
    /// Every panel-2 mass scaled by (1 + 1e-6) in the dense model only.
    Mass2Perturbed,
}

/// The dense system M q̈ = f, q̈ = [a_B (B); ω̇ (B); θ̈_11; θ̈_12; …].
pub(crate) struct Dense {
    pub(crate) m: DMatrix<f64>,
    pub(crate) f: DVector<f64>,
    /// The uniform gravity field at the system CoM, B components.
    pub(crate) g_b: V3,
}

/// Accumulates one rigid body's contribution to M and f (see the module docs).
pub(crate) struct Assembler {
    pub(crate) m: DMatrix<f64>,
    pub(crate) f: DVector<f64>,
}

/// One rigid body's Kane data.
pub(crate) struct Body<'a> {
    pub(crate) mass: f64,
    /// Inertia about the body's CoM, B components.
    pub(crate) i_c: M3,
    /// Partial velocities of the CoM (3 × n).
    pub(crate) v: &'a DMatrix<f64>,
    /// Partial angular velocities (3 × n).
    pub(crate) w: &'a DMatrix<f64>,
    /// Velocity-product part of the CoM's inertial acceleration.
    pub(crate) a_vp: V3,
    /// Inertial angular velocity of the body.
    pub(crate) omega: V3,
    /// Velocity-product part of the body's angular acceleration.
    pub(crate) alpha_vp: V3,
    /// Resultant applied force (through the CoM) and torque.
    pub(crate) force: V3,
    pub(crate) torque: V3,
    /// ω_body × [I_c] ω_body when given in an expanded form (a spinning rotor: see the wheel
    /// bodies); `None` computes it directly.
    pub(crate) gyroscopic: Option<V3>,
}

impl Assembler {
    pub(crate) fn add(&mut self, b: &Body<'_>) {
        let v = b.v;
        let w = b.w;
        let i_c = DMatrix::from_column_slice(3, 3, b.i_c.as_slice());
        self.m += v.transpose() * v * b.mass + w.transpose() * (&i_c * w);
        let lin = b.force - b.a_vp * b.mass;
        let gyro = b
            .gyroscopic
            .unwrap_or_else(|| b.omega.cross(&(b.i_c * b.omega)));
        let ang = b.torque - b.i_c * b.alpha_vp - gyro;
        self.f += v.transpose() * DVector::from_column_slice(lin.as_slice())
            + w.transpose() * DVector::from_column_slice(ang.as_slice());
    }
}

pub(crate) fn set_block(m: &mut DMatrix<f64>, col: usize, block: &M3) {
    m.fixed_view_mut::<3, 3>(0, col).copy_from(block);
}

pub(crate) fn set_col(m: &mut DMatrix<f64>, col: usize, v: &V3) {
    m.fixed_view_mut::<3, 1>(0, col).copy_from(v);
}

/// Adds the hub (rigid, CoM at r_Bc/B, angular velocity `w`) with the torque `torque` on it and
/// its weight in the uniform field `g_b`: partial velocities [I, −[r̃_Bc/B], 0…] and [0, I, 0…].
pub(crate) fn add_hub(asm: &mut Assembler, hub: &HubParams, w: &V3, g_b: &V3, torque: &V3) {
    let n = asm.m.nrows();
    let mut v = DMatrix::zeros(3, n);
    let mut wm = DMatrix::zeros(3, n);
    set_block(&mut v, 0, &M3::identity());
    set_block(&mut v, 3, &(-skew(&hub.r_bcb_b_m)));
    set_block(&mut wm, 3, &M3::identity());
    asm.add(&Body {
        mass: hub.mass_kg,
        i_c: hub.inertia_bc_b_kg_m2,
        v: &v,
        w: &wm,
        a_vp: w.cross(&w.cross(&hub.r_bcb_b_m)),
        omega: *w,
        alpha_vp: V3::zeros(),
        force: g_b * hub.mass_kg,
        torque: *torque,
        gyroscopic: None,
    });
}

fn dense_kane(cfg: &Config, x: &Sample, variant: Variant) -> Dense {
    let np = cfg.pairs.len();
    let nw = cfg.wheels.len();
    let n = 6 + 2 * np + nw;
    let w = x.omega_bn_b;
    let hub = &cfg.hub;

    let mass2 = |p: &PanelPairParams| match variant {
        Variant::Mass2Perturbed => p.panel2.mass_kg * (1.0 + 1e-6),
        _ => p.panel2.mass_kg,
    };

    // Geometry and the uniform gravity field at the system CoM.
    let geoms: Vec<PairGeom> = cfg
        .pairs
        .iter()
        .enumerate()
        .map(|(i, p)| pair_geom(p, x.eff[4 * i], x.eff[4 * i + 2]))
        .collect();
    let mut m_sc = hub.mass_kg;
    let mut first = hub.r_bcb_b_m * hub.mass_kg;
    for (p, g) in cfg.pairs.iter().zip(&geoms) {
        m_sc += p.panel1.mass_kg + mass2(p);
        first += g.r1 * p.panel1.mass_kg + g.r2 * mass2(p);
    }
    for (wp, _) in &cfg.wheels {
        m_sc += wp.mass_kg;
        first += wp.r_wb_b_m * wp.mass_kg;
    }
    // Wheel spin torques on the rotors (motor + friction), about +ĝ_s: the rotor's generalized
    // speed is Ω, its partial angular velocity ĝ_s; the hub takes the reaction.
    let wheel_taus: Vec<f64> = cfg
        .wheels
        .iter()
        .zip(&x.wheel_omega)
        .map(|((wp, u), &om)| {
            let coulomb = wp.coulomb_friction_nm * (om / wp.coulomb_band_rad_s).clamp(-1.0, 1.0);
            u - wp.viscous_friction_nm_s_rad * om - coulomb
        })
        .collect();
    let dcm_bn = dcm_bn_from_mrp(&x.sigma_bn);
    let g_b = match cfg.mu {
        None => V3::zeros(),
        Some(mu) => {
            let r_cn_n = x.r_bn_n + dcm_bn.transpose() * (first / m_sc);
            dcm_bn * (-r_cn_n * (mu / r_cn_n.norm().powi(3)))
        }
    };

    let mut asm = Assembler {
        m: DMatrix::zeros(n, n),
        f: DVector::zeros(n),
    };
    // External force at point B: partial velocity of B is [I, 0, 0…].
    for k in 0..3 {
        asm.f[k] += cfg.force_b[k];
    }

    // Hinge torques τ1, τ2 per pair (on the outboard body, about +ŝ12).
    let taus: Vec<(f64, f64)> = cfg
        .pairs
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let e = &x.eff[4 * i..4 * i + 4];
            (
                -p.panel1.k_nm_rad * e[0] - p.panel1.c_nm_s_rad * e[1] + p.motor_torque_nm[0],
                -p.panel2.k_nm_rad * e[2] - p.panel2.c_nm_s_rad * e[3] + p.motor_torque_nm[1],
            )
        })
        .collect();

    // Hub.
    {
        let mut torque = cfg.torque_b;
        for (g, (tau1, _)) in geoms.iter().zip(&taus) {
            torque -= axis(&g.c1, 1) * *tau1; // reaction of hinge 1
        }
        for ((wp, _), tau) in cfg.wheels.iter().zip(&wheel_taus) {
            torque -= wp.spin_axis_b * *tau; // reaction of the wheel motor and bearing
        }
        add_hub(&mut asm, hub, &w, &g_b, &torque);
    }

    // Panels.
    for (i, ((p, g), (tau1, tau2))) in cfg.pairs.iter().zip(&geoms).zip(&taus).enumerate() {
        let (c1i, c2i) = (6 + 2 * i, 7 + 2 * i);
        let th1d = x.eff[4 * i + 1];
        let th2d = x.eff[4 * i + 3];
        let big_th2d = th1d + th2d; // Θ̇2: panel 2's rate relative to B
        let (s11, s12, s13) = (axis(&g.c1, 0), axis(&g.c1, 1), axis(&g.c1, 2));
        let (s21, s23) = (axis(&g.c2, 0), axis(&g.c2, 2));
        let (d1, d2, l1) = (p.panel1.d_m, p.panel2.d_m, p.l1_m);
        let m1 = p.panel1.mass_kg;
        let m2 = mass2(p);

        // Panel 1.
        let i1 = g.c1.transpose() * M3::from_diagonal(&p.panel1.inertia_s_kg_m2) * g.c1;
        let mut v1 = DMatrix::zeros(3, n);
        let mut w1 = DMatrix::zeros(3, n);
        set_block(&mut v1, 0, &M3::identity());
        set_block(&mut v1, 3, &(-skew(&g.r1)));
        set_col(&mut v1, c1i, &(s13 * d1));
        set_block(&mut w1, 3, &M3::identity());
        set_col(&mut w1, c1i, &s12);
        let r1p = s13 * (d1 * th1d);
        let r1pp = s11 * (d1 * th1d * th1d);
        asm.add(&Body {
            mass: m1,
            i_c: i1,
            v: &v1,
            w: &w1,
            a_vp: w.cross(&w.cross(&g.r1)) + w.cross(&r1p) * 2.0 + r1pp,
            omega: w + s12 * th1d,
            alpha_vp: w.cross(&(s12 * th1d)),
            force: g_b * m1,
            torque: s12 * (tau1 - tau2),
            gyroscopic: None,
        });

        // Panel 2.
        let i2 = g.c2.transpose() * M3::from_diagonal(&p.panel2.inertia_s_kg_m2) * g.c2;
        let mut v2 = DMatrix::zeros(3, n);
        let mut w2 = DMatrix::zeros(3, n);
        set_block(&mut v2, 0, &M3::identity());
        set_block(&mut v2, 3, &(-skew(&g.r2)));
        set_col(&mut v2, c1i, &(s13 * l1 + s23 * d2));
        set_col(&mut v2, c2i, &(s23 * d2));
        set_block(&mut w2, 3, &M3::identity());
        set_col(&mut w2, c1i, &s12);
        set_col(&mut w2, c2i, &s12);
        let r2p = s13 * (l1 * th1d) + s23 * (d2 * big_th2d);
        let r2pp = s11 * (l1 * th1d * th1d) + s21 * (d2 * big_th2d * big_th2d);
        asm.add(&Body {
            mass: m2,
            i_c: i2,
            v: &v2,
            w: &w2,
            a_vp: w.cross(&w.cross(&g.r2)) + w.cross(&r2p) * 2.0 + r2pp,
            omega: w + s12 * big_th2d,
            alpha_vp: w.cross(&(s12 * big_th2d)),
            force: g_b * m2,
            torque: s12 * *tau2,
            gyroscopic: None,
        });

        if variant == Variant::PrintedE1 {
            // Correct θ_i2 row, ω̇ columns: I_s22 ŝ22ᵀ − m2 d2 ŝ23ᵀ[r̃2]. Printed: … + m2 d2 ŝ23ᵀ[r̃2].
            let delta = (skew(&g.r2).transpose() * s23) * (2.0 * m2 * d2); // = 2 m2 d2 ([r̃2]ᵀ ŝ23)
            for k in 0..3 {
                asm.m[(c2i, 3 + k)] += delta[k];
            }
        }
    }

    // Wheel rotors: CoM fixed in B at r_W, angular velocity ω + Ω ĝ_s (ĝ_s fixed in B, so
    // its inertial rate is ω × Ω ĝ_s), inertia J_s ĝĝᵀ + J_t (I − ĝĝᵀ) about the CoM. Each rotor
    // adds one generalized speed Ω (partial velocity 0, partial angular velocity ĝ_s).
    for (j, ((wp, _), tau)) in cfg.wheels.iter().zip(&wheel_taus).enumerate() {
        let col = 6 + 2 * np + j;
        let g = wp.spin_axis_b;
        let om = x.wheel_omega[j];
        let ggt = g * g.transpose();
        let i_w = ggt * wp.j_s_kg_m2 + (M3::identity() - ggt) * wp.j_t_kg_m2;
        let mut v = DMatrix::zeros(3, n);
        let mut wm = DMatrix::zeros(3, n);
        set_block(&mut v, 0, &M3::identity());
        set_block(&mut v, 3, &(-skew(&wp.r_wb_b_m)));
        set_block(&mut wm, 3, &M3::identity());
        set_col(&mut wm, col, &g);
        asm.add(&Body {
            mass: wp.mass_kg,
            i_c: i_w,
            v: &v,
            w: &wm,
            a_vp: w.cross(&w.cross(&wp.r_wb_b_m)),
            omega: w + g * om,
            alpha_vp: w.cross(&(g * om)),
            force: g_b * wp.mass_kg,
            torque: g * *tau,
            // (ω + Ωĝ) × [I_W](ω + Ωĝ), expanded with [I_W]ĝ = J_s ĝ so the Ω² ĝ × ĝ term, zero
            // exactly, is not formed: at Ω ~ 500 rad/s its round-off alone would move Ω̇ by ~1e-11.
            gyroscopic: Some(
                w.cross(&(i_w * w)) + (w.cross(&g) * wp.j_s_kg_m2 + g.cross(&(i_w * w))) * om,
            ),
        });
    }

    Dense {
        m: asm.m,
        f: asm.f,
        g_b,
    }
}

/// Dense LU solve of M q̈ = f.
pub(crate) fn dense_solve(d: &Dense) -> DVector<f64> {
    d.m.clone()
        .lu()
        .solve(&d.f)
        .expect("dense Kane mass matrix is singular")
}

// ---------------------------------------------------------------------------------------------
// The library under test
// ---------------------------------------------------------------------------------------------

fn build_library(cfg: &Config) -> Spacecraft {
    build_library_with_step(cfg, 1_000_000)
}

fn build_library_with_step(cfg: &Config, step_ns: u64) -> Spacecraft {
    let effectors: Vec<Box<dyn StateEffector>> = cfg
        .pairs
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let pair = PanelPair::new(
                p.clone(),
                PanelPairInitial::default(),
                &format!("panel_pairs[{i}]"),
            )
            .expect("valid random pair");
            Box::new(pair) as Box<dyn StateEffector>
        })
        .chain(cfg.wheels.iter().enumerate().map(|(j, (wp, _))| {
            let wheel = ReactionWheel::new(wp.clone(), &format!("reaction_wheels[{j}]"))
                .expect("valid random wheel");
            Box::new(wheel) as Box<dyn StateEffector>
        }))
        .collect();
    let mut sc = spacecraft_of(cfg, effectors, step_ns);
    let u: Vec<f64> = cfg.wheels.iter().map(|(_, u)| *u).collect();
    sc.set_effector_inputs(&u).expect("one input per wheel");
    sc
}

/// The library spacecraft of `cfg`'s hub, gravity and wrench with `effectors` (the states are
/// set per sample, so the initial state is arbitrary).
pub(crate) fn spacecraft_of(
    cfg: &Config,
    effectors: Vec<Box<dyn StateEffector>>,
    step_ns: u64,
) -> Spacecraft {
    let gravity = match cfg.mu {
        None => GravityModel::None,
        Some(mu) => GravityModel::PointMass { mu_m3_s2: mu },
    };
    let initial = HubInitial {
        translation: InitialTranslation::PointB {
            r_bn_n_m: V3::new(7.0e6, 0.0, 0.0),
            v_bn_n_m_s: V3::zeros(),
        },
        sigma_bn: V3::zeros(),
        omega_bn_b_rad_s: V3::zeros(),
    };
    let mut sc = Spacecraft::new(cfg.hub.clone(), gravity, effectors, initial, step_ns)
        .expect("valid random spacecraft");
    sc.set_wrench(flexdyn_dynamics::Wrench {
        force_b_newton: cfg.force_b,
        torque_b_nm: cfg.torque_b,
    });
    sc
}

/// The library's generalized accelerations [a_B (B); ω̇ (B); θ̈…] and its non-gravitational
/// hub acceleration (B components).
fn library_accel(sc: &mut Spacecraft, x: &Sample) -> (DVector<f64>, V3) {
    let state = State {
        r_bn_n: x.r_bn_n,
        v_bn_n: x.v_bn_n,
        sigma_bn: x.sigma_bn,
        omega_bn_b: x.omega_bn_b,
        effectors: x.eff.iter().chain(&x.wheel_omega).copied().collect(),
    };
    let mut dx = state.clone();
    let out = sc.derivatives(&state, &mut dx);
    let np = x.eff.len() / 4;
    let nw = x.wheel_omega.len();
    let a_b = dcm_bn_from_mrp(&x.sigma_bn) * dx.v_bn_n;
    let mut q = DVector::zeros(6 + 2 * np + nw);
    for j in 0..nw {
        q[6 + 2 * np + j] = dx.effectors[4 * np + j];
    }
    q.fixed_rows_mut::<3>(0).copy_from(&a_b);
    q.fixed_rows_mut::<3>(3).copy_from(&dx.omega_bn_b);
    for i in 0..np {
        // The θ derivatives must be the θ̇ states themselves.
        assert_eq!(dx.effectors[4 * i], x.eff[4 * i + 1]);
        assert_eq!(dx.effectors[4 * i + 2], x.eff[4 * i + 3]);
        q[6 + 2 * i] = dx.effectors[4 * i + 1];
        q[7 + 2 * i] = dx.effectors[4 * i + 3];
    }
    assert_eq!(
        out.omega_dot_bn_b, dx.omega_bn_b,
        "HubOutputs.omega_dot_bn_b vs dx.omega_bn_b"
    );
    (q, out.nongrav_accel_bn_b)
}

pub(crate) fn inf_norm(v: &DVector<f64>) -> f64 {
    v.iter().fold(0.0_f64, |a, x| a.max(x.abs()))
}

pub(crate) fn rel_err(lib: &DVector<f64>, dense: &DVector<f64>) -> f64 {
    inf_norm(&(lib - dense)) / inf_norm(dense).max(1e-300)
}

/// 2-norm condition number of a (small) matrix.
fn cond(m: &DMatrix<f64>) -> f64 {
    let sv = m.clone().singular_values();
    sv.max() / sv.min()
}

/// Skeel's (componentwise) condition number of the solve M q = f at the solution q:
/// ‖ |M⁻¹| (|M| |q| + |f|) ‖∞ / ‖q‖∞. A componentwise relative perturbation ε of the entries of M
/// and f — which is what rounding while *assembling* them produces, in the library as here —
/// moves q by up to about κ_S·ε relative. So two correct f64 implementations that assemble the
/// same equations in a different order can differ by O(κ_S·eps), whatever solver either uses.
pub(crate) fn skeel_cond(d: &Dense, q: &DVector<f64>) -> f64 {
    let m_inv = d.m.clone().try_inverse().expect("invertible").abs();
    inf_norm(&(m_inv * (d.m.abs() * q.abs() + d.f.abs()))) / inf_norm(q)
}

/// Normwise backward error of a candidate solution q of the dense system:
/// ‖M q − f‖∞ / (‖M‖∞ ‖q‖∞ + ‖f‖∞). It measures how far (relatively) M and f would have to be
/// perturbed for q to be their exact solution, so it is independent of the conditioning: a
/// correct library answer scores O(eps) even where the forward error is amplified by κ, while any
/// wrong term in the library's equations scores at least its own relative size.
pub(crate) fn backward_error(d: &Dense, q: &DVector<f64>) -> f64 {
    let m_norm =
        d.m.row_iter()
            .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max);
    inf_norm(&(&d.m * q - &d.f)) / (m_norm * inf_norm(q) + inf_norm(&d.f))
}

pub(crate) fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

// ---------------------------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------------------------

/// The kinematic formulas the dense model is built on (r′, r″ and the partial angular velocities,
/// i.e. every ŝ3 sign of Table 1 / Eqs. 85–88), checked by central finite differences of the
/// position and DCM functions alone.
#[test]
fn validate_dense_kane_kinematics_fd() {
    let mut rng = Rng::new(0xF1D0);
    let mut worst = 0.0_f64;
    for _ in 0..200 {
        let cfg = random_config(&mut rng, 1, false, Ranges::Extreme);
        let p = &cfg.pairs[0];
        let (t1, t2) = (rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
        let (t1d, t2d) = (rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
        let g = pair_geom(p, t1, t2);
        let (s11, s12, s13) = (axis(&g.c1, 0), axis(&g.c1, 1), axis(&g.c1, 2));
        let (s21, s22, s23) = (axis(&g.c2, 0), axis(&g.c2, 1), axis(&g.c2, 2));
        let (d1, d2, l1) = (p.panel1.d_m, p.panel2.d_m, p.l1_m);
        let scale = l1 + d2;

        // ŝ12 = ŝ22 (common hinge axis).
        assert!((s12 - s22).norm() < 1e-14);

        // Along the path θ(t) = θ + θ̇ t (θ̈ = 0).
        let at = |h: f64| pair_geom(p, t1 + t1d * h, t2 + t2d * h);
        let h1 = 1e-6;
        let (gp, gm) = (at(h1), at(-h1));
        let r1p_fd = (gp.r1 - gm.r1) / (2.0 * h1);
        let r2p_fd = (gp.r2 - gm.r2) / (2.0 * h1);
        let r1p = s13 * (d1 * t1d);
        let r2p = s13 * (l1 * t1d) + s23 * (d2 * (t1d + t2d));
        let h2 = 1e-4;
        let (gp2, gm2) = (at(h2), at(-h2));
        let r1pp_fd = (gp2.r1 - g.r1 * 2.0 + gm2.r1) / (h2 * h2);
        let r2pp_fd = (gp2.r2 - g.r2 * 2.0 + gm2.r2) / (h2 * h2);
        let r1pp = s11 * (d1 * t1d * t1d);
        let r2pp = s11 * (l1 * t1d * t1d) + s21 * (d2 * (t1d + t2d).powi(2));

        // Angular velocity of Sk relative to B, B components: vee([B Sk]′ [Sk B]).
        let vee = |m: M3| {
            V3::new(
                m[(2, 1)] - m[(1, 2)],
                m[(0, 2)] - m[(2, 0)],
                m[(1, 0)] - m[(0, 1)],
            ) * 0.5
        };
        let w1_fd = vee((gp.c1 - gm.c1).transpose() / (2.0 * h1) * g.c1);
        let w2_fd = vee((gp.c2 - gm.c2).transpose() / (2.0 * h1) * g.c2);

        let errs = [
            (r1p_fd - r1p).norm() / scale,
            (r2p_fd - r2p).norm() / scale,
            (r1pp_fd - r1pp).norm() / scale,
            (r2pp_fd - r2pp).norm() / scale,
            (w1_fd - s12 * t1d).norm(),
            (w2_fd - s12 * (t1d + t2d)).norm(),
        ];
        for e in errs {
            worst = worst.max(e);
        }
    }
    eprintln!("kinematics vs finite differences: worst error {worst:.2e}");
    assert!(
        worst < 1e-6,
        "kinematics disagree with finite differences: {worst:e}"
    );
}

/// Kane's mass matrix must be symmetric positive-definite at every random state.
#[test]
fn validate_dense_kane_mass_matrix_spd() {
    let mut n_states = 0;
    let mut worst_asym = 0.0_f64;
    let mut worst_cond = 0.0_f64;
    for (cfg, samples) in cases(0xD3E5E, Ranges::Extreme) {
        for x in &samples {
            let d = dense_kane(&cfg, x, Variant::Exact);
            let scale = d.m.amax();
            let asym = (&d.m - d.m.transpose()).amax() / scale;
            worst_asym = worst_asym.max(asym);
            assert!(asym < 1e-14, "mass matrix not symmetric: {asym:e}");
            assert!(
                d.m.clone().cholesky().is_some(),
                "mass matrix not positive-definite"
            );
            worst_cond = worst_cond.max(cond(&d.m));
            n_states += 1;
        }
    }
    eprintln!(
        "dense Kane mass matrix: {n_states} states, max relative asymmetry {worst_asym:.2e}, \
         max 2-norm condition number {worst_cond:.2e}; Cholesky succeeded for all"
    );
}

/// Skeel condition number up to which the plain 1e-12 bound is asserted. Its round-off floor
/// κ_S·eps is 2.2e-13, 4.5× below the tolerance.
const WELL_CONDITIONED_KAPPA: f64 = 1e3;
/// Round-off envelope for the ill-conditioned tail: rel err ≤ this × κ_S × eps (measured ≤ 4.4
/// here; ≤ 12 when rod-like inertias are also sampled).
pub(crate) const ROUNDOFF_FACTOR: f64 = 32.0;

/// The main cross-check: library back-substitution vs dense Kane LU, 1260 random states.
///
/// The plain relative error ‖q̈_lib − q̈_dense‖∞ / ‖q̈_dense‖∞ is reported over every state (max
/// and median) and asserted ≤ 1e-12 on every state whose Skeel condition number κ_S ≤ 1e3 (at
/// least 1000 of them). The sampled ranges (every mass independently 1–1000 kg, hub inertia
/// down to ~5e-3 kg·m²) include a few very ill-conditioned spacecraft — e.g. a 1 kg hub carrying a
/// 211 kg panel on a 5 m arm (κ₂(M) ≈ 2e4) — where any two f64 implementations of the same
/// equations differ by O(κ·eps) ≈ 1e-12 from the rounding of the assembled coefficients alone.
/// There the plain error is instead held to the round-off envelope 32·κ_S·eps (the measured
/// ratio stays below 12; about 1.5 against κ₂·eps), and — for every state, whatever its
/// conditioning — the normwise backward error of the library's answer in the dense Kane system
/// must be ≤ 1e-14 (measured ≤ 5e-16): the library's accelerations exactly solve a system within
/// 1e-14 of this independent one, which rules out any missing or mis-signed term of that size.
#[test]
fn validate_dense_kane_matches_library() {
    compare_with_library(Ranges::Plausible);
}

/// The same comparison on extreme spacecraft (see [`Ranges::Extreme`]): the plain 1e-12 bound is
/// asserted where κ_S ≤ 1e3, the round-off envelope and the backward error everywhere.
#[test]
fn validate_dense_kane_extreme_spacecraft() {
    compare_with_library(Ranges::Extreme);
}

/// Back-substitution with reaction wheels and panel pairs together (balanced wheels with
/// commanded motor torques and viscous + Coulomb friction) against the dense Kane model with
/// each rotor as a body: ≤ 1e-12 relative on every state.
#[test]
fn validate_dense_kane_with_wheels() {
    compare_cases(
        Ranges::Plausible,
        cases_with_wheels(0x3EE1),
        "with reaction wheels",
    );
}

fn compare_with_library(ranges: Ranges) {
    compare_cases(ranges, cases(0xD3E5E, ranges), "panel pairs");
}

fn compare_cases(ranges: Ranges, cases: Vec<(Config, Vec<Sample>)>, label: &str) {
    let t0 = std::time::Instant::now();
    struct Row {
        err: f64,
        err_nongrav: f64,
        backward: f64,
        kappa_s: f64,
        kappa_2: f64,
        n_pairs: usize,
        gravity: bool,
    }
    let mut rows = Vec::new();
    for (cfg, samples) in cases {
        let mut sc = build_library(&cfg);
        for x in &samples {
            let d = dense_kane(&cfg, x, Variant::Exact);
            let q_dense = dense_solve(&d);
            let (q_lib, nongrav_lib) = library_accel(&mut sc, x);
            // HubOutputs.nongrav_accel_bn_b = a_B − g (B components).
            let a_dense = V3::new(q_dense[0], q_dense[1], q_dense[2]);
            rows.push(Row {
                err: rel_err(&q_lib, &q_dense),
                err_nongrav: (nongrav_lib - (a_dense - d.g_b)).amax() / inf_norm(&q_dense),
                backward: backward_error(&d, &q_lib),
                kappa_s: skeel_cond(&d, &q_dense),
                kappa_2: cond(&d.m),
                n_pairs: cfg.pairs.len(),
                gravity: cfg.mu.is_some(),
            });
        }
    }
    let elapsed = t0.elapsed().as_secs_f64();
    let max_of = |it: &mut dyn Iterator<Item = f64>| it.fold(0.0_f64, f64::max);
    let stats = |sel: &dyn Fn(&Row) -> bool| {
        let mut e: Vec<f64> = rows.iter().filter(|r| sel(r)).map(|r| r.err).collect();
        let n = e.len();
        let mx = max_of(&mut e.iter().cloned());
        (n, mx, median(&mut e))
    };
    let (n_all, max_all, med_all) = stats(&|_| true);
    let (n_free, max_free, med_free) = stats(&|r| !r.gravity);
    let (n_grav, max_grav, med_grav) = stats(&|r| r.gravity);
    let (n_wc, max_wc, med_wc) = stats(&|r| r.kappa_s <= WELL_CONDITIONED_KAPPA);
    let worst = rows.iter().max_by(|a, b| a.err.total_cmp(&b.err)).unwrap();
    let over: Vec<&Row> = rows.iter().filter(|r| r.err > 1e-12).collect();
    let max_bw = max_of(&mut rows.iter().map(|r| r.backward));
    let max_ng = max_of(&mut rows.iter().map(|r| r.err_nongrav));
    let max_ratio_s = max_of(&mut rows.iter().map(|r| r.err / (r.kappa_s * f64::EPSILON)));
    let max_ratio_2 = max_of(&mut rows.iter().map(|r| r.err / (r.kappa_2 * f64::EPSILON)));
    let max_ks = max_of(&mut rows.iter().map(|r| r.kappa_s));
    eprintln!(
        "dense Kane vs library ({label}), {ranges:?} spacecraft, {n_all} states ({n_free} free space, {n_grav} point-mass gravity), {elapsed:.3} s:\n  \
         all states:        max rel err {max_all:.3e}, median {med_all:.3e}\n  \
         free space:        max rel err {max_free:.3e}, median {med_free:.3e}\n  \
         with gravity:      max rel err {max_grav:.3e}, median {med_grav:.3e}\n  \
         kappa_S <= 1e3:    max rel err {max_wc:.3e}, median {med_wc:.3e} ({n_wc} states)\n  \
         worst state:       rel err {:.3e}, {} pair(s), kappa_S {:.2e}, kappa_2(M) {:.2e}\n  \
         states > 1e-12:    {} (kappa_S {:?})\n  \
         max err/(kappa_S eps) {max_ratio_s:.2}, max err/(kappa_2 eps) {max_ratio_2:.2}, max kappa_S {max_ks:.2e}\n  \
         max backward error of the library answer {max_bw:.2e}\n  \
         nongrav_accel_bn_b: max rel err {max_ng:.3e}",
        worst.err,
        worst.n_pairs,
        worst.kappa_s,
        worst.kappa_2,
        over.len(),
        over.iter().map(|r| format!("{:.1e}", r.kappa_s)).collect::<Vec<_>>(),
    );
    assert!(n_all >= 1000, "too few states: {n_all}");
    // Primary: plain relative error on the generalized accelerations — on every state for
    // plausible spacecraft, on the well-conditioned ones for extreme spacecraft.
    let primary = if ranges == Ranges::Plausible {
        max_all
    } else {
        max_wc
    };
    assert!(
        primary <= 1e-12,
        "library disagrees with the dense Kane model: max rel err {primary:e}"
    );
    for r in &rows {
        let bound = 1e-12_f64.max(ROUNDOFF_FACTOR * r.kappa_s * f64::EPSILON);
        assert!(
            r.err <= bound,
            "rel err {:e} above the round-off envelope {bound:e}",
            r.err
        );
        assert!(
            r.err_nongrav <= bound,
            "nongrav_accel_bn_b rel err {:e} > {bound:e}",
            r.err_nongrav
        );
        assert!(r.backward <= 1e-14, "backward error {:e}", r.backward);
    }
}

/// Negative controls: the same comparison with a deliberately wrong dense model must fail by
/// orders of magnitude, on both metrics, which shows the tolerances are meaningful.
#[test]
fn validate_dense_kane_negative_control() {
    let mut e1 = (Vec::new(), Vec::new());
    let mut mass = (Vec::new(), Vec::new());
    for (cfg, samples) in cases(0xBAD, Ranges::Plausible).into_iter().take(60) {
        let mut sc = build_library(&cfg);
        for x in &samples {
            let (q_lib, _) = library_accel(&mut sc, x);
            for (variant, out) in [
                (Variant::PrintedE1, &mut e1),
                (Variant::Mass2Perturbed, &mut mass),
            ] {
                let d = dense_kane(&cfg, x, variant);
                out.0.push(rel_err(&q_lib, &dense_solve(&d)));
                out.1.push(backward_error(&d, &q_lib));
            }
        }
    }
    let n = e1.0.len();
    let min_of = |v: &[f64]| v.iter().cloned().fold(f64::INFINITY, f64::min);
    let (min_e1, min_e1_bw) = (min_of(&e1.0), min_of(&e1.1));
    let (min_m, min_m_bw) = (min_of(&mass.0), min_of(&mass.1));
    let (med_e1, med_e1_bw) = (median(&mut e1.0), median(&mut e1.1));
    let (med_m, med_m_bw) = (median(&mut mass.0), median(&mut mass.1));
    eprintln!(
        "negative controls over {n} states:\n  \
         printed E1:     rel err min {min_e1:.3e} median {med_e1:.3e}; backward error min {min_e1_bw:.3e} median {med_e1_bw:.3e}\n  \
         m2 x (1+1e-6):  rel err min {min_m:.3e} median {med_m:.3e}; backward error min {min_m_bw:.3e} median {med_m_bw:.3e}"
    );
    assert!(
        min_e1 > 1e-8 && min_e1_bw > 1e-10,
        "the printed-E1 model should disagree in every state"
    );
    assert!(
        med_m > 1e-8 && med_m_bw > 1e-10,
        "a 1e-6 mass perturbation should be visible"
    );
}

// ---------------------------------------------------------------------------------------------
// Trajectories: every integrator against the dense Kane ODE
// ---------------------------------------------------------------------------------------------
//
// The dense model above, with the MRP kinematics written again here, is an ODE of its own. It is
// integrated by a classical RK4 written in this file (not the library's tableaux) at 2048 and
// 4096 steps and Richardson-extrapolated, y* = y_fine + (y_fine − y_coarse)/15, which removes the
// h⁴ term: the reference is then good to ~1e-13 (its own two estimates agree to the printed
// figure). Each library method must converge to it at its own order: halving the step divides
// the error by 2^p, measured and asserted. A method that integrated different dynamics (or mixed
// up a stage time or weight) would stall at the discrepancy, with ratio → 1.

/// The dense Kane model as an ODE on a [`Sample`]: (ṙ, v̇, σ̇, ω̇, (θ̇, θ̈) per panel, Ω̇).
fn dense_rate(cfg: &Config, x: &Sample) -> Sample {
    let q = dense_solve(&dense_kane(cfg, x, Variant::Exact));
    let np = cfg.pairs.len();
    let (s, w) = (x.sigma_bn, x.omega_bn_b);
    // σ̇ = ¼[(1 − σᵀσ)I + 2[σ̃] + 2σσᵀ]ω (Schaub & Junkins, Analytical Mechanics of Space
    // Systems, 4th ed., Eq. 3.154).
    let sigma_dot =
        (w * (1.0 - s.norm_squared()) + s.cross(&w) * 2.0 + s * (2.0 * s.dot(&w))) * 0.25;
    let mut eff = vec![0.0; 4 * np];
    for i in 0..np {
        eff[4 * i] = x.eff[4 * i + 1];
        eff[4 * i + 1] = q[6 + 2 * i];
        eff[4 * i + 2] = x.eff[4 * i + 3];
        eff[4 * i + 3] = q[7 + 2 * i];
    }
    Sample {
        r_bn_n: x.v_bn_n,
        v_bn_n: dcm_bn_from_mrp(&s).transpose() * V3::new(q[0], q[1], q[2]),
        sigma_bn: sigma_dot,
        omega_bn_b: V3::new(q[3], q[4], q[5]),
        eff,
        wheel_omega: (0..cfg.wheels.len()).map(|j| q[6 + 2 * np + j]).collect(),
    }
}

/// x + h·k.
fn sample_axpy(x: &Sample, h: f64, k: &Sample) -> Sample {
    let lin = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a + h * b).collect();
    Sample {
        r_bn_n: x.r_bn_n + k.r_bn_n * h,
        v_bn_n: x.v_bn_n + k.v_bn_n * h,
        sigma_bn: x.sigma_bn + k.sigma_bn * h,
        omega_bn_b: x.omega_bn_b + k.omega_bn_b * h,
        eff: lin(&x.eff, &k.eff),
        wheel_omega: lin(&x.wheel_omega, &k.wheel_omega),
    }
}

/// `n` classical RK4 steps of the dense ODE over `t_s` (Kutta 1901); no MRP switch (the test
/// keeps |σ| < 1 and compares attitudes as DCMs).
fn dense_rk4(cfg: &Config, x0: &Sample, t_s: f64, n: usize) -> Sample {
    let h = t_s / n as f64;
    let mut x = x0.clone();
    for _ in 0..n {
        let k1 = dense_rate(cfg, &x);
        let k2 = dense_rate(cfg, &sample_axpy(&x, h / 2.0, &k1));
        let k3 = dense_rate(cfg, &sample_axpy(&x, h / 2.0, &k2));
        let k4 = dense_rate(cfg, &sample_axpy(&x, h, &k3));
        let mut incr = sample_axpy(&k1, 2.0, &k2);
        incr = sample_axpy(&incr, 2.0, &k3);
        incr = sample_axpy(&incr, 1.0, &k4);
        x = sample_axpy(&x, h / 6.0, &incr);
    }
    x
}

/// Differences between two trajectories' end states: (rotational and flexible part — max over ω
/// [rad/s], the DCM [BN] entries, θ [rad], θ̇ [rad/s] and Ω [rad/s] — , |Δr| [m], |Δv| [m/s]).
fn traj_diff(a: &Sample, b: &Sample) -> (f64, f64, f64) {
    let max_abs = |x: &[f64], y: &[f64]| {
        x.iter()
            .zip(y)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    };
    let dcm = (dcm_bn_from_mrp(&a.sigma_bn) - dcm_bn_from_mrp(&b.sigma_bn)).amax();
    let rot = dcm
        .max((a.omega_bn_b - b.omega_bn_b).amax())
        .max(max_abs(&a.eff, &b.eff))
        .max(max_abs(&a.wheel_omega, &b.wheel_omega));
    (
        rot,
        (a.r_bn_n - b.r_bn_n).amax(),
        (a.v_bn_n - b.v_bn_n).amax(),
    )
}

/// A fixed flexible spacecraft for the trajectory tests: one damped panel pair whose modes are
/// near 0.5–2 rad/s, a spinning wheel (no friction: Coulomb friction is not smooth, and order
/// is only defined for smooth right-hand sides), hinge and wheel motor torques and a small
/// constant wrench; free space or point-mass gravity in LEO.
fn trajectory_case(gravity: bool) -> (Config, Sample) {
    let mut rng = Rng::new(0x7AC7);
    let rot = rng.rotation();
    let hub = HubParams {
        mass_kg: 500.0,
        inertia_bc_b_kg_m2: {
            let i = rot * M3::from_diagonal(&V3::new(400.0, 300.0, 250.0)) * rot.transpose();
            (i + i.transpose()) * 0.5
        },
        r_bcb_b_m: V3::new(0.1, -0.05, 0.2),
    };
    let panel = |mass_kg: f64, inertia: V3, k: f64, c: f64| PanelParams {
        mass_kg,
        inertia_s_kg_m2: inertia,
        d_m: 1.0,
        k_nm_rad: k,
        c_nm_s_rad: c,
        width_m: None,
        thickness_m: None,
    };
    let pair = PanelPairParams {
        name: "wing".into(),
        r_h1b_b_m: V3::new(1.0, 0.1, -0.2),
        // H1 = B turned 180° about b3, so the wing (along −ĥ1 at θ = 0) points out along +b1.
        dcm_h1b: M3::from_diagonal(&V3::new(-1.0, -1.0, 1.0)),
        theta_h2s1_rad: 0.2,
        l1_m: 2.0,
        panel1: panel(20.0, V3::new(2.0, 7.0, 5.0), 50.0, 2.0),
        panel2: panel(15.0, V3::new(1.5, 5.0, 3.5), 30.0, 1.0),
        motor_torque_nm: [0.5, -0.3],
    };
    let wheel = ReactionWheelParams::balanced(
        "rw",
        V3::new(0.3, 0.5, 0.8).normalize(),
        V3::new(0.2, 0.3, -0.1),
        5.0,
        0.05,
        0.03,
        0.0,
        1.0,
        600.0,
    );
    let cfg = Config {
        hub,
        pairs: vec![pair],
        mu: gravity.then_some(MU_EARTH),
        force_b: V3::new(2.0, -1.0, 0.5),
        torque_b: V3::new(0.3, -0.2, 0.1),
        wheels: vec![(wheel, 0.05)],
    };
    let x0 = Sample {
        r_bn_n: V3::new(7.0e6, 1.0e5, -2.0e5),
        v_bn_n: if gravity {
            V3::new(0.0, 7.5e3, 1.0e2)
        } else {
            V3::new(0.3, -0.2, 0.1)
        },
        sigma_bn: V3::new(0.1, 0.2, -0.3),
        omega_bn_b: V3::new(0.02, -0.03, 0.05),
        eff: vec![0.1, 0.05, -0.2, 0.1],
        wheel_omega: vec![15.0],
    };
    (cfg, x0)
}

/// The library's end state after `t_s` at step `step_ns` with `method`, as a [`Sample`].
fn library_run(
    cfg: &Config,
    x0: &Sample,
    method: &'static ButcherTableau,
    t_s: f64,
    step_ns: u64,
) -> Sample {
    let mut sc = build_library_with_step(cfg, step_ns);
    sc.set_integrator(method);
    sc.set_state(&State {
        r_bn_n: x0.r_bn_n,
        v_bn_n: x0.v_bn_n,
        sigma_bn: x0.sigma_bn,
        omega_bn_b: x0.omega_bn_b,
        effectors: x0.eff.iter().chain(&x0.wheel_omega).copied().collect(),
    })
    .expect("state lengths");
    let n = (t_s * 1e9 / step_ns as f64).round() as u64;
    assert_eq!(n * step_ns, (t_s * 1e9) as u64, "whole number of steps");
    for _ in 0..n {
        sc.step();
    }
    let s = sc.state();
    let np = cfg.pairs.len();
    Sample {
        r_bn_n: s.r_bn_n,
        v_bn_n: s.v_bn_n,
        sigma_bn: s.sigma_bn,
        omega_bn_b: s.omega_bn_b,
        eff: s.effectors[..4 * np].to_vec(),
        wheel_omega: s.effectors[4 * np..].to_vec(),
    }
}

/// [s] Simulated span of the trajectory tests.
const TRAJECTORY_T_S: f64 = 8.0;

/// Step pairs (h, h/2) [ns] at which each method's order is measured, in its asymptotic range
/// for [`trajectory_case`] over [`TRAJECTORY_T_S`] (modes ≲ 2 rad/s): below them the error
/// meets the ~1e-13 floor of the reference, above them ω h ≳ 0.5 and higher terms dominate.
fn order_steps_ns(method: &ButcherTableau) -> &'static [(u64, u64)] {
    match method.name {
        "rk4" => &[(62_500_000, 31_250_000), (31_250_000, 15_625_000)],
        "rk8" => &[(250_000_000, 125_000_000), (200_000_000, 100_000_000)],
        other => panic!("no order ladder for integrator {other}: add one"),
    }
}

/// Smallest accepted measured order: p − 0.2 (RK4 ≥ 3.8); for RK8 ≥ 7, since its error
/// constant still changes between the steps that stay above the reference's floor.
fn min_measured_order(method: &ButcherTableau) -> f64 {
    if method.order >= 8 {
        7.0
    } else {
        method.order as f64 - 0.2
    }
}

#[test]
fn validate_dense_kane_trajectories_converge_at_each_method_order() {
    for gravity in [false, true] {
        let (cfg, x0) = trajectory_case(gravity);
        let coarse = dense_rk4(&cfg, &x0, TRAJECTORY_T_S, 4096);
        let fine = dense_rk4(&cfg, &x0, TRAJECTORY_T_S, 8192);
        let oracle = sample_axpy(&fine, 1.0 / 15.0, &sample_axpy(&fine, -1.0, &coarse));
        let (oracle_corr, _, _) = traj_diff(&oracle, &fine);
        eprintln!(
            "gravity {gravity}: Richardson correction of the dense RK4 reference {oracle_corr:.2e}"
        );
        assert!(
            oracle_corr < 1e-11,
            "reference not converged: {oracle_corr:e}"
        );
        for m in METHODS {
            let err =
                |step_ns| traj_diff(&library_run(&cfg, &x0, m, TRAJECTORY_T_S, step_ns), &oracle);
            for &(h, h2) in order_steps_ns(m) {
                let (e1, _, _) = err(h);
                let (e2, r2, v2) = err(h2);
                let p = (e1 / e2).log2();
                eprintln!(
                    "  {}: h = {} s err {e1:.3e}, h/2 err {e2:.3e} (|dr| {r2:.1e} m, |dv| {v2:.1e} \
                     m/s): measured order {p:.2}",
                    m.name,
                    h as f64 * 1e-9
                );
                assert!(
                    p >= min_measured_order(m),
                    "{}: measured order {p:.2} < {} against the dense Kane reference",
                    m.name,
                    min_measured_order(m)
                );
                // The translational state follows the same dynamics: its error is at most the
                // round-off of |r| ≈ 7e6 m over the run (a few 1e-8 m).
                assert!(
                    r2 < 1e-7 && v2 < 1e-6,
                    "{}: |dr| {r2:e} m, |dv| {v2:e} m/s",
                    m.name
                );
            }
        }
        // At a step 1/4 of its coarsest, RK8 reaches the reference's own accuracy; |Δv| is
        // then round-off of |v| (7.5 km/s in orbit): ε·|v|·steps ≈ 1.1e-16 · 7.5e3 · 128 ≈ 1e-10.
        let (e, _, v) = traj_diff(
            &library_run(&cfg, &x0, &RK8, TRAJECTORY_T_S, 62_500_000),
            &oracle,
        );
        eprintln!("  rk8 at 1/16 s: err {e:.2e}, |dv| {v:.2e} m/s");
        assert!(e < 1e-12 && v < 1e-10, "rk8 at 1/16 s: {e:e}, {v:e}");
    }
}
