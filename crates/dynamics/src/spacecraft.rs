//! The spacecraft: a rigid hub plus any number of [`StateEffector`]s, propagated by a fixed-step
//! Runge–Kutta method of [`super::integrator`] (RK4 by default).
//!
//! Per derivative evaluation the hub sums the effectors' mass properties and back-substitution
//! contributions, assembles Eqs. 145–150 (with erratum E2: \[C\] = m_sc[c̃] + \[C_contr\]) and solves
//! Eq. 151 by the Schur complement of Eqs. 152–153, using LU factorisations — never explicit
//! inverses. Gravity is evaluated at the system centre of mass C and applied as a uniform field.

use std::ops::Range;

use nalgebra::{Matrix3, Vector3};

use super::dynamic_effector::{
    DynamicEffector, EnvironmentSource, EnvironmentWrenches, StageState,
};
use super::effector::{
    BackSubContributions, EffectorKind, EffectorMassProps, EnergyMomentum, HubAccel, HubKinematics,
    StateEffector,
};
use super::integrator::{ButcherTableau, Combine, RK4};
use super::params::{GravityModel, HubParams, Wrench};
use super::stage_hook::{NoHook, StageCombine, StageHook};
use flexdyn_environment::EnvironmentSample;
use flexdyn_kernel::archive::{Archive, Archived};
use flexdyn_kernel::attitude::{mrp_rate, mrp_switch, mrp_to_dcm, tilde};
use flexdyn_kernel::validate::{check_finite, ParamError};

/// The integrated state (also used for its time derivative).
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// \[m\] r_B/N in N components (derivative: ṙ = v).
    pub r_bn_n: Vector3<f64>,
    /// [m/s] v_B/N in N components (derivative: r̈_B/N in N).
    pub v_bn_n: Vector3<f64>,
    /// MRP σ_B/N (derivative: σ̇).
    pub sigma_bn: Vector3<f64>,
    /// [rad/s] ω_B/N in B components (derivative: ω̇).
    pub omega_bn_b: Vector3<f64>,
    /// Effector states, concatenated in effector order (for a panel pair: θ1, θ̇1, θ2, θ̇2).
    pub effectors: Vec<f64>,
}

impl State {
    fn zeros(n: usize) -> Self {
        Self {
            r_bn_n: Vector3::zeros(),
            v_bn_n: Vector3::zeros(),
            sigma_bn: Vector3::zeros(),
            omega_bn_b: Vector3::zeros(),
            effectors: vec![0.0; n],
        }
    }

    /// self = x + h Σ_j a_ij k_j for stage `i` of `method`, summed as
    /// ((k_j1·(a h) + k_j2·(a h)) + …) + x over the non-zero a_ij, one whole-state pass per term
    /// (no allocation; all lengths are equal by construction). For RK4's one-term rows this is
    /// `x + k·(a h)`, the historical expression, bit for bit.
    #[inline(always)]
    fn set_stage(&mut self, x: &State, method: &ButcherTableau, i: usize, k: &[State], h: f64) {
        let mut first = true;
        for (kj, &a) in k.iter().zip(method.a[i]) {
            if a != 0.0 {
                self.scale_add(kj, a * h, !first);
                first = false;
            }
        }
        if first {
            self.clone_from(x);
        } else {
            self.add(x);
        }
    }

    /// self = k·s (`accumulate` false) or self + k·s (true), elementwise.
    #[inline(always)]
    fn scale_add(&mut self, k: &State, s: f64, accumulate: bool) {
        if accumulate {
            self.r_bn_n += k.r_bn_n * s;
            self.v_bn_n += k.v_bn_n * s;
            self.sigma_bn += k.sigma_bn * s;
            self.omega_bn_b += k.omega_bn_b * s;
            for (o, ki) in self.effectors.iter_mut().zip(&k.effectors) {
                *o += ki * s;
            }
        } else {
            self.r_bn_n = k.r_bn_n * s;
            self.v_bn_n = k.v_bn_n * s;
            self.sigma_bn = k.sigma_bn * s;
            self.omega_bn_b = k.omega_bn_b * s;
            for (o, ki) in self.effectors.iter_mut().zip(&k.effectors) {
                *o = ki * s;
            }
        }
    }

    /// self = self + x, elementwise.
    #[inline(always)]
    fn add(&mut self, x: &State) {
        self.r_bn_n += x.r_bn_n;
        self.v_bn_n += x.v_bn_n;
        self.sigma_bn += x.sigma_bn;
        self.omega_bn_b += x.omega_bn_b;
        for (o, xi) in self.effectors.iter_mut().zip(&x.effectors) {
            *o += xi;
        }
    }

    /// self += h Σ_i b_i k_i, elementwise: the end of a step of `method`, with `scratch` (a
    /// state of the same lengths) as workspace. RK4 combines each quantity in its historical
    /// expression ([`super::stage_hook::rk4_combine`], as the stage hooks do); a weighted
    /// method sums (Σ b_i k_i) one whole-state pass per weight, then adds it times h — the same
    /// arithmetic as [`ButcherTableau::combine`], in a cache-friendly order.
    #[inline(always)]
    fn add_step(&mut self, method: &ButcherTableau, k: &[State], h: f64, scratch: &mut State) {
        match method.combine {
            Combine::ClassicRk4 => {
                self.r_bn_n += method.combine(|i| k[i].r_bn_n, h);
                self.v_bn_n += method.combine(|i| k[i].v_bn_n, h);
                self.sigma_bn += method.combine(|i| k[i].sigma_bn, h);
                self.omega_bn_b += method.combine(|i| k[i].omega_bn_b, h);
                for (n, o) in self.effectors.iter_mut().enumerate() {
                    *o += method.combine(|i| k[i].effectors[n], h);
                }
            }
            Combine::Weighted => {
                let mut first = true;
                for (ki, &b) in k.iter().zip(method.b) {
                    if b != 0.0 {
                        scratch.scale_add(ki, b, !first);
                        first = false;
                    }
                }
                if !first {
                    self.scale_add(scratch, h, true);
                }
            }
        }
    }
}

/// How the initial translational state is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InitialTranslation {
    /// Position \[m\] and velocity [m/s] of point B relative to N, N components.
    PointB {
        /// r_B/N.
        r_bn_n_m: Vector3<f64>,
        /// v_B/N.
        v_bn_n_m_s: Vector3<f64>,
    },
    /// Position \[m\] and velocity [m/s] of the system centre of mass C relative to N, N components.
    CenterOfMass {
        /// r_C/N.
        r_cn_n_m: Vector3<f64>,
        /// v_C/N.
        v_cn_n_m_s: Vector3<f64>,
    },
}

/// The hub's initial state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HubInitial {
    /// Translational initial condition.
    pub translation: InitialTranslation,
    /// MRP σ_B/N.
    pub sigma_bn: Vector3<f64>,
    /// [rad/s] ω_B/N in B components.
    pub omega_bn_b_rad_s: Vector3<f64>,
}

/// Conserved quantities (Basilisk's totOrbEnergy, totRotEnergy, totOrbAngMomPntN_N and
/// totRotAngMomPntC_N), computed from the state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conserved {
    /// \[J\] orbital energy of the centre of mass: ½ m_sc |v_C/N|² + m_sc U(r_C/N).
    pub orb_energy_j: f64,
    /// \[J\] rotational kinetic energy about C plus spring energy.
    pub rot_energy_j: f64,
    /// [kg·m²/s] orbital angular momentum of C about N, m_sc r_C/N × v_C/N, N components.
    pub orb_ang_mom_n: Vector3<f64>,
    /// [kg·m²/s] angular momentum about C, N components.
    pub rot_ang_mom_c_n: Vector3<f64>,
}

/// Accelerations of the hub at one state, from one derivative evaluation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HubOutputs {
    /// [m/s²] non-gravitational acceleration of point B, B components.
    pub nongrav_accel_bn_b: Vector3<f64>,
    /// [rad/s²] ω̇_B/N, B components.
    pub omega_dot_bn_b: Vector3<f64>,
    /// [m/s²] gravitational acceleration at the system CoM, N components.
    pub gravity_n: Vector3<f64>,
}

/// 3×3 LU factorisation with partial pivoting, on the stack, infallible.
///
/// Callers only factor matrices that are non-singular by construction (the hub mass matrix
/// blocks of a validated spacecraft); a zero pivot would yield non-finite results, not a panic.
#[derive(Debug, Clone, Copy)]
struct Lu3 {
    lu: Matrix3<f64>,
    perm: [usize; 3],
}

impl Lu3 {
    #[inline(always)]
    fn factor(m: &Matrix3<f64>) -> Self {
        let mut lu = *m;
        let mut perm = [0usize, 1, 2];
        for k in 0..3 {
            let mut p = k;
            for i in (k + 1)..3 {
                if lu[(i, k)].abs() > lu[(p, k)].abs() {
                    p = i;
                }
            }
            if p != k {
                lu.swap_rows(p, k);
                perm.swap(p, k);
            }
            let inv_pivot = 1.0 / lu[(k, k)];
            for i in (k + 1)..3 {
                let f = lu[(i, k)] * inv_pivot;
                lu[(i, k)] = f;
                for j in (k + 1)..3 {
                    lu[(i, j)] -= f * lu[(k, j)];
                }
            }
        }
        Self { lu, perm }
    }

    /// Forward and back substitution for `N` right-hand sides side by side: lane `l` of the
    /// rows `b0`, `b1`, `b2` (already in pivot order) is one right-hand side, and each lane
    /// takes exactly the same operations in the same order, so a lane's bits do not depend on
    /// `N`. Written lane-wise so that several right-hand sides run as one vector pass whose
    /// divisions overlap. Returns the rows x0, x1, x2 of the solutions.
    #[inline(always)]
    fn solve_lanes<const N: usize>(
        &self,
        b0: [f64; N],
        b1: [f64; N],
        b2: [f64; N],
    ) -> [[f64; N]; 3] {
        let lu = &self.lu;
        let mut x = [[0.0; N]; 3];
        for l in 0..N {
            let y0 = b0[l];
            let y1 = b1[l] - lu[(1, 0)] * y0;
            let y2 = b2[l] - lu[(2, 0)] * y0 - lu[(2, 1)] * y1;
            x[2][l] = y2 / lu[(2, 2)];
            x[1][l] = (y1 - lu[(1, 2)] * x[2][l]) / lu[(1, 1)];
            x[0][l] = (y0 - lu[(0, 1)] * x[1][l] - lu[(0, 2)] * x[2][l]) / lu[(0, 0)];
        }
        x
    }

    #[inline(always)]
    fn solve(&self, b: &Vector3<f64>) -> Vector3<f64> {
        let [p0, p1, p2] = self.perm;
        let [[x0], [x1], [x2]] = self.solve_lanes([b[p0]], [b[p1]], [b[p2]]);
        Vector3::new(x0, x1, x2)
    }

    /// A⁻¹[B | v]: the three columns of `b` and `v`, four lanes of [`Self::solve_lanes`].
    #[inline(always)]
    fn solve_matrix_and(&self, b: &Matrix3<f64>, v: &Vector3<f64>) -> (Matrix3<f64>, Vector3<f64>) {
        let rhs = |row: usize| [b[(row, 0)], b[(row, 1)], b[(row, 2)], v[row]];
        let [p0, p1, p2] = self.perm;
        let [x0, x1, x2] = self.solve_lanes(rhs(p0), rhs(p1), rhs(p2));
        (
            Matrix3::new(
                x0[0], x0[1], x0[2], x1[0], x1[1], x1[2], x2[0], x2[1], x2[2],
            ),
            Vector3::new(x0[3], x1[3], x2[3]),
        )
    }
}

/// [m/s²] specific force (non-gravitational acceleration) of a point fixed on the hub at
/// `r_sb_b` from B: f = a_B,nongrav + ω̇ × r + ω × (ω × r), all B components.
#[inline(always)]
pub fn specific_force_b(
    nongrav_accel_bn_b: &Vector3<f64>,
    omega_bn_b: &Vector3<f64>,
    omega_dot_bn_b: &Vector3<f64>,
    r_sb_b: &Vector3<f64>,
) -> Vector3<f64> {
    nongrav_accel_bn_b + omega_dot_bn_b.cross(r_sb_b) + omega_bn_b.cross(&omega_bn_b.cross(r_sb_b))
}

/// Gravitational acceleration [m/s²] at `r_n` (N components) for `model`.
#[inline]
pub fn gravity_accel_n(model: &GravityModel, r_n: &Vector3<f64>) -> Vector3<f64> {
    match *model {
        GravityModel::None => Vector3::zeros(),
        GravityModel::PointMass { mu_m3_s2 } => {
            let r2 = r_n.norm_squared();
            -r_n * (mu_m3_s2 / (r2 * r2.sqrt()))
        }
        GravityModel::J2 {
            mu_m3_s2,
            j2,
            r_eq_m,
        } => {
            let r2 = r_n.norm_squared();
            let r = r2.sqrt();
            let point = -r_n * (mu_m3_s2 / (r2 * r));
            // a_J2 = −(3/2) μ J2 R² / r⁵ [ r (1 − 5 z²/r²) + 2 z ẑ ]
            let z2_r2 = r_n.z * r_n.z / r2;
            let f = -1.5 * mu_m3_s2 * j2 * r_eq_m * r_eq_m / (r2 * r2 * r);
            let mut a = r_n * (f * (1.0 - 5.0 * z2_r2));
            a.z += f * 2.0 * r_n.z;
            point + a
        }
    }
}

/// Gravitational potential per unit mass [J/kg] at `r_n`, consistent with [`gravity_accel_n`].
pub fn gravity_potential(model: &GravityModel, r_n: &Vector3<f64>) -> f64 {
    match *model {
        GravityModel::None => 0.0,
        GravityModel::PointMass { mu_m3_s2 } => -mu_m3_s2 / r_n.norm(),
        GravityModel::J2 {
            mu_m3_s2,
            j2,
            r_eq_m,
        } => {
            let r = r_n.norm();
            let z2_r2 = r_n.z * r_n.z / (r * r);
            -mu_m3_s2 / r
                + 0.5 * mu_m3_s2 * j2 * r_eq_m * r_eq_m / (r * r * r) * (3.0 * z2_r2 - 1.0)
        }
    }
}

/// Stage buffers: one derivative per stage of the integrator and the stage state, sized when
/// the integrator is chosen (construction time), never on the stepping path.
#[derive(Debug, Clone)]
struct StageWorkspace {
    k: Vec<State>,
    stage: State,
}

/// The equations of motion: the hub, its effectors, gravity and the applied wrench. Split from
/// the integrator state so the integrator can evaluate it while borrowing its stage buffers.
#[derive(Debug)]
struct EquationsOfMotion {
    /// The external forces and torques evaluated at every stage, in registration order.
    dynamic: Vec<Box<dyn DynamicEffector>>,
    /// Indices of the dynamic effectors whose [`DynamicEffector::uses_begin_step`] is true.
    dynamic_stepped: Vec<usize>,
    /// Indices of the listed dynamic effectors (the actuators,
    /// [`DynamicEffector::listed_kind`]): effector entries `effectors.len()..`, in this order.
    listed: Vec<usize>,
    /// The environment the dynamic effectors read, held until the next
    /// [`Spacecraft::set_environment`].
    env: EnvironmentSample,
    hub: HubParams,
    /// Hub mass properties about B (constant): m r_Bc/B and [I_hub,B] = [I_hub,Bc] + m[r̃][r̃]ᵀ.
    hub_first_moment_b: Vector3<f64>,
    hub_inertia_pnt_b_b: Matrix3<f64>,
    gravity: GravityModel,
    effectors: Vec<Box<dyn StateEffector>>,
    ranges: Vec<Range<usize>>,
    force_b_newton: Vector3<f64>,
    torque_b_nm: Vector3<f64>,
    /// Indices of the effectors whose [`StateEffector::uses_begin_step`] is true.
    stepped: Vec<usize>,
    /// Range of each effector entry's inputs in the flat input vector of
    /// [`Spacecraft::set_effector_inputs`], and of its outputs in [`Spacecraft::effector_outputs`]:
    /// the state effectors, then the listed dynamic effectors (cold: after the fields every
    /// evaluation reads).
    input_ranges: Vec<Range<usize>>,
    output_ranges: Vec<Range<usize>>,
    /// Each propellant tank and the dynamic effectors that draw from it (empty without tanks:
    /// then stepping does exactly what it did before tanks existed).
    feeds: Vec<PropellantFeed>,
    /// \[s\] the integration step, over which a tank's outflow is held.
    step_s: f64,
}

/// A propellant tank (an index into the state effectors) and the dynamic effectors (indices
/// into the dynamic list) that draw from it.
#[derive(Debug)]
struct PropellantFeed {
    tank: usize,
    thrusters: Vec<usize>,
}

/// The fraction (0 … 1) of a demand of `demand_kg_s` held over `step_s` that `available_kg`
/// of propellant can deliver: 1 while it suffices; in the step the tank runs dry the fraction
/// that empties it exactly at the step's end (so its mass reaches 0, never below); 0 when it
/// is empty.
#[inline]
fn propellant_supply(available_kg: f64, demand_kg_s: f64, step_s: f64) -> f64 {
    let wanted_kg = demand_kg_s * step_s;
    if wanted_kg <= available_kg {
        1.0
    } else if available_kg > 0.0 {
        available_kg / wanted_kg
    } else {
        0.0
    }
}

/// One entry of the vehicle's effector list ([`Spacecraft::effector_entries`]): an appended body
/// or a listed dynamic effector (an actuator), as the telemetry and the commands see it.
#[derive(Debug, Clone)]
pub struct EffectorEntry<'a> {
    /// Its kind (wire tag, CSV prefix).
    pub kind: EffectorKind,
    /// Its name from the configuration.
    pub name: &'a str,
    /// Its integrated states' names (empty for a dynamic effector).
    pub state_names: &'static [&'static str],
    /// Its states' range in [`State::effectors`] (empty for a dynamic effector).
    pub state_range: Range<usize>,
    /// Its inputs' names.
    pub input_names: &'static [&'static str],
    /// Its outputs' names.
    pub output_names: &'static [&'static str],
}

/// A rigid hub with appended state effectors, integrated with a fixed-step Runge–Kutta method.
#[derive(Debug)]
pub struct Spacecraft {
    eom: EquationsOfMotion,
    state: State,
    t_sim_ns: u64,
    step_ns: u64,
    /// The fixed-step Runge–Kutta method ([`integrator`](super::integrator); RK4 by default).
    method: &'static ButcherTableau,
    ws: StageWorkspace,
}

/// The vehicle at state `x` as the dynamic effectors see it, from the stage's summed mass
/// properties `mp` (centre of mass `c_b` = c, r_C/N = `r_cn_n`).
#[inline(always)]
fn stage_state(
    x: &State,
    t_step_ns: u64,
    dt_stage_s: f64,
    dcm_nb: &Matrix3<f64>,
    mp: &EffectorMassProps,
    c_b: &Vector3<f64>,
    r_cn_n: &Vector3<f64>,
) -> StageState {
    StageState {
        t_step_ns,
        dt_stage_s,
        r_bn_n_m: x.r_bn_n,
        v_bn_n_m_s: x.v_bn_n,
        sigma_bn: x.sigma_bn,
        dcm_bn: dcm_nb.transpose(),
        omega_bn_b_rad_s: x.omega_bn_b,
        mass_kg: mp.mass_kg,
        r_cb_b_m: *c_b,
        r_cn_n_m: *r_cn_n,
        inertia_pnt_b_b_kg_m2: mp.inertia_pnt_b_b_kg_m2,
    }
}

impl EquationsOfMotion {
    /// Runs [`StateEffector::begin_step`] at state `x`, and [`DynamicEffector::begin_step`] at
    /// the step's start time `t_step_ns`, on the effectors that use them.
    #[inline]
    fn begin_step(&mut self, x: &State, t_step_ns: u64) {
        for &i in &self.stepped {
            self.effectors[i].begin_step(&x.effectors[self.ranges[i].clone()]);
        }
        for &i in &self.dynamic_stepped {
            self.dynamic[i].begin_step(t_step_ns);
        }
        // Each tank's outflow over the step: what its thrusters' step-average forces burn,
        // limited to what it holds (`propellant_tank` module docs, (D1) and (D5)).
        for feed in &self.feeds {
            let xe = &x.effectors[self.ranges[feed.tank].clone()];
            let available_kg = self.effectors[feed.tank].propellant_kg(xe).unwrap_or(0.0);
            let mut demand_kg_s = 0.0;
            for &i in &feed.thrusters {
                demand_kg_s += self.dynamic[i].propellant_demand_kg_s();
            }
            let supply = propellant_supply(available_kg, demand_kg_s, self.step_s);
            for &i in &feed.thrusters {
                self.dynamic[i].set_propellant_supply(supply);
            }
            self.effectors[feed.tank].set_propellant_outflow(demand_kg_s * supply);
        }
    }

    /// Evaluates the state derivative `dx` at state `x`, the stage `dt_stage_s` into the step
    /// that starts at `t_step_ns`, with the current wrench, and returns the hub accelerations
    /// (Eqs. 145–153 with the effector passes around them).
    #[inline(always)]
    fn eval(&mut self, x: &State, dx: &mut State, t_step_ns: u64, dt_stage_s: f64) -> HubOutputs {
        let omega = x.omega_bn_b;
        // Pass 1: mass properties (Eqs. 3, 4, 19): m_sc, c, c′, [I_sc,B].
        let mut mp = EffectorMassProps {
            mass_kg: self.hub.mass_kg,
            first_moment_b_kg_m: self.hub_first_moment_b,
            inertia_pnt_b_b_kg_m2: self.hub_inertia_pnt_b_b,
            ..EffectorMassProps::default()
        };
        // Pass 2: effector contributions (Eqs. 139–144). They need ω but not the summed mass
        // properties, so each effector runs both passes back to back while its geometry is hot.
        let kin = HubKinematics { omega_bn_b: omega };
        let mut contr = BackSubContributions::default();
        for (e, r) in self.effectors.iter_mut().zip(&self.ranges) {
            let xe = &x.effectors[r.clone()];
            e.update_mass_props(xe, &mut mp);
            e.update_contributions(xe, &kin, &mut contr);
        }
        let m_sc = mp.mass_kg;
        let c_b = mp.first_moment_b_kg_m / m_sc;
        let c_prime_b = mp.first_moment_prime_b_kg_m_s / m_sc;
        let dcm_nb = mrp_to_dcm(&x.sigma_bn).transpose();
        // The system CoM, where the uniform gravity field acts: r_C/N = r_B/N + [NB] c.
        let r_cn_n = x.r_bn_n + dcm_nb * c_b;

        // External forces and torques: the held wrench, then every dynamic effector at this
        // stage (force at B, torque about B, B components).
        let mut ext = Wrench {
            force_b_newton: self.force_b_newton,
            torque_b_nm: self.torque_b_nm,
        };
        if !self.dynamic.is_empty() {
            let stage = stage_state(x, t_step_ns, dt_stage_s, &dcm_nb, &mp, &c_b, &r_cn_n);
            for e in &mut self.dynamic {
                e.add_force_torque(&stage, &self.env, &mut ext);
            }
        }

        // Eqs. 145–150, with erratum E2 in Eq. 148.
        let c_tilde = tilde(&c_b);
        let matrix_a = Matrix3::from_diagonal_element(m_sc) + contr.matrix_a;
        let matrix_b = -c_tilde * m_sc + contr.matrix_b;
        let matrix_c = c_tilde * m_sc + contr.matrix_c;
        let matrix_d = mp.inertia_pnt_b_b_kg_m2 + contr.matrix_d;
        let v_trans = ext.force_b_newton
            - omega.cross(&c_prime_b) * (2.0 * m_sc)
            - omega.cross(&omega.cross(&c_b)) * m_sc
            + contr.vec_trans;
        // The hub is rigid ([I′_hub] = 0); each effector's −[I′]ω is in its vec_rot.
        let v_rot =
            -omega.cross(&(mp.inertia_pnt_b_b_kg_m2 * omega)) + ext.torque_b_nm + contr.vec_rot;

        // Eqs. 152–153 by factorisation: A = LU; X = A⁻¹B and y = A⁻¹v_trans by solves;
        // S = D − C X factored; ω̇ = S⁻¹(v_rot − C y); r̈ = y − X ω̇.
        let lu_a = Lu3::factor(&matrix_a);
        let (a_inv_b, a_inv_vt) = lu_a.solve_matrix_and(&matrix_b, &v_trans);
        let lu_s = Lu3::factor(&(matrix_d - matrix_c * a_inv_b));
        let omega_dot = lu_s.solve(&(v_rot - matrix_c * a_inv_vt));
        let accel_b = a_inv_vt - a_inv_b * omega_dot;

        // Pass 3: effector back-substitution (Eqs. 131–132).
        let hub_accel = HubAccel {
            nongrav_accel_bn_b: accel_b,
            omega_dot_bn_b: omega_dot,
        };
        for (e, r) in self.effectors.iter_mut().zip(&self.ranges) {
            e.compute_derivatives(
                &x.effectors[r.clone()],
                &hub_accel,
                &mut dx.effectors[r.clone()],
            );
        }

        // Uniform gravity evaluated at the system CoM.
        let gravity_n = gravity_accel_n(&self.gravity, &r_cn_n);
        dx.r_bn_n = x.v_bn_n;
        dx.v_bn_n = dcm_nb * accel_b + gravity_n;
        dx.sigma_bn = mrp_rate(&x.sigma_bn, &omega);
        dx.omega_bn_b = omega_dot;
        HubOutputs {
            nongrav_accel_bn_b: accel_b,
            omega_dot_bn_b: omega_dot,
            gravity_n,
        }
    }
}

impl Spacecraft {
    /// Builds the spacecraft after validating every parameter; the effectors validate their own
    /// at their construction. Fails with an error naming the field.
    pub fn new(
        hub: HubParams,
        gravity: GravityModel,
        effectors: Vec<Box<dyn StateEffector>>,
        initial: HubInitial,
        step_ns: u64,
    ) -> Result<Self, ParamError> {
        hub.validate("hub")?;
        gravity.validate("gravity")?;
        check_finite("initial", "sigma_bn", initial.sigma_bn.as_slice())?;
        check_finite(
            "initial",
            "omega_bn_b_rad_s",
            initial.omega_bn_b_rad_s.as_slice(),
        )?;
        match initial.translation {
            InitialTranslation::PointB {
                r_bn_n_m,
                v_bn_n_m_s,
            } => {
                check_finite("initial", "r_bn_n_m", r_bn_n_m.as_slice())?;
                check_finite("initial", "v_bn_n_m_s", v_bn_n_m_s.as_slice())?;
            }
            InitialTranslation::CenterOfMass {
                r_cn_n_m,
                v_cn_n_m_s,
            } => {
                check_finite("initial", "r_cn_n_m", r_cn_n_m.as_slice())?;
                check_finite("initial", "v_cn_n_m_s", v_cn_n_m_s.as_slice())?;
            }
        }
        if step_ns == 0 {
            return Err(ParamError::NotPositive {
                field: "simulation.step_s".into(),
                value: 0.0,
            });
        }
        let layout = |len: &dyn Fn(&dyn StateEffector) -> usize| {
            let mut ranges = Vec::with_capacity(effectors.len());
            let mut n = 0;
            for e in &effectors {
                ranges.push(n..n + len(e.as_ref()));
                n += len(e.as_ref());
            }
            (ranges, n)
        };
        let (ranges, n) = layout(&|e| e.state_len());
        let (input_ranges, _) = layout(&|e| e.input_len());
        let (output_ranges, _) = layout(&|e| e.output_names().len());
        let stepped = (0..effectors.len())
            .filter(|&i| effectors[i].uses_begin_step())
            .collect();
        let hub_first_moment_b = hub.r_bcb_b_m * hub.mass_kg;
        let r = hub.r_bcb_b_m;
        let hub_inertia_pnt_b_b = hub.inertia_bc_b_kg_m2
            + (Matrix3::from_diagonal_element(r.norm_squared()) - r * r.transpose()) * hub.mass_kg;
        let zero = State::zeros(n);
        let mut sc = Self {
            eom: EquationsOfMotion {
                dynamic: Vec::new(),
                dynamic_stepped: Vec::new(),
                listed: Vec::new(),
                env: EnvironmentSample::NONE,
                hub,
                hub_first_moment_b,
                hub_inertia_pnt_b_b,
                gravity,
                effectors,
                ranges,
                input_ranges,
                output_ranges,
                stepped,
                force_b_newton: Vector3::zeros(),
                torque_b_nm: Vector3::zeros(),
                feeds: Vec::new(),
                step_s: step_ns as f64 * 1e-9,
            },
            state: zero.clone(),
            t_sim_ns: 0,
            step_ns,
            method: &RK4,
            ws: StageWorkspace {
                k: vec![zero.clone(); RK4.stages()],
                stage: zero,
            },
        };
        for (e, r) in sc.eom.effectors.iter().zip(&sc.eom.ranges) {
            e.initial_state(&mut sc.state.effectors[r.clone()]);
        }
        sc.state.sigma_bn = initial.sigma_bn;
        mrp_switch(&mut sc.state.sigma_bn);
        sc.state.omega_bn_b = initial.omega_bn_b_rad_s;
        match initial.translation {
            InitialTranslation::PointB {
                r_bn_n_m,
                v_bn_n_m_s,
            } => {
                sc.state.r_bn_n = r_bn_n_m;
                sc.state.v_bn_n = v_bn_n_m_s;
            }
            InitialTranslation::CenterOfMass {
                r_cn_n_m,
                v_cn_n_m_s,
            } => {
                // r_B/N = r_C/N − [NB] c;  v_B/N = v_C/N − [NB] ċ, ċ = c′ + ω × c (relative to B).
                let em = sc.energy_momentum_sum(&sc.state);
                let c_b = em.first_moment_b_kg_m / em.mass_kg;
                let c_dot_b = em.lin_mom_rel_b_kg_m_s / em.mass_kg;
                let dcm_nb = mrp_to_dcm(&sc.state.sigma_bn).transpose();
                sc.state.r_bn_n = r_cn_n_m - dcm_nb * c_b;
                sc.state.v_bn_n = v_cn_n_m_s - dcm_nb * c_dot_b;
            }
        }
        Ok(sc)
    }

    /// The current state.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// Replaces the state (e.g. to restore a snapshot). Lengths must match [`Self::state`]'s.
    pub fn set_state(&mut self, state: &State) -> Result<(), ParamError> {
        if state.effectors.len() != self.state.effectors.len() {
            return Err(ParamError::StateLength {
                expected: self.state.effectors.len(),
                found: state.effectors.len(),
            });
        }
        self.state.clone_from(state);
        Ok(())
    }

    /// \[ns\] simulation time.
    pub fn t_sim_ns(&self) -> u64 {
        self.t_sim_ns
    }

    /// \[ns\] integration step.
    pub fn step_ns(&self) -> u64 {
        self.step_ns
    }

    /// The effectors, in state order.
    pub fn effectors(&self) -> &[Box<dyn StateEffector>] {
        &self.eom.effectors
    }

    /// Range of each effector's states within [`State::effectors`].
    pub fn effector_ranges(&self) -> &[Range<usize>] {
        &self.eom.ranges
    }

    /// Range of each effector's inputs within the flat vector of [`Self::set_effector_inputs`].
    pub fn effector_input_ranges(&self) -> &[Range<usize>] {
        &self.eom.input_ranges
    }

    /// Total number of effector inputs (the length [`Self::set_effector_inputs`] takes).
    pub fn effector_input_len(&self) -> usize {
        self.eom.input_ranges.last().map_or(0, |r| r.end)
    }

    /// Range of each effector's outputs within the flat vector of [`Self::effector_outputs`].
    pub fn effector_output_ranges(&self) -> &[Range<usize>] {
        &self.eom.output_ranges
    }

    /// Total number of effector outputs.
    pub fn effector_output_len(&self) -> usize {
        self.eom.output_ranges.last().map_or(0, |r| r.end)
    }

    /// Sets every effector's commanded inputs from one flat vector laid out by
    /// [`Self::effector_input_ranges`], held until the next call. Allocates nothing.
    pub fn set_effector_inputs(&mut self, u: &[f64]) -> Result<(), ParamError> {
        self.check_effector_inputs(u)?;
        let eom = &mut self.eom;
        let (state_ranges, listed_ranges) = eom.input_ranges.split_at(eom.effectors.len());
        for (e, r) in eom.effectors.iter_mut().zip(state_ranges) {
            if !r.is_empty() {
                e.set_inputs(&u[r.clone()]);
            }
        }
        for (&i, r) in eom.listed.iter().zip(listed_ranges) {
            if !r.is_empty() {
                eom.dynamic[i].set_inputs(&u[r.clone()]);
            }
        }
        Ok(())
    }

    /// Whether `u` fits [`Self::set_effector_inputs`]: [`Self::effector_input_len`] values, each
    /// finite.
    pub fn check_effector_inputs(&self, u: &[f64]) -> Result<(), ParamError> {
        if u.len() != self.effector_input_len() {
            return Err(ParamError::InputLength {
                expected: self.effector_input_len(),
                found: u.len(),
            });
        }
        if let Some(i) = u.iter().position(|v| !v.is_finite()) {
            return Err(ParamError::NotFinite {
                field: format!("effector input {i}"),
            });
        }
        Ok(())
    }

    /// Every effector entry's outputs at the current state into `out` (laid out by
    /// [`Self::effector_output_ranges`]) and its status flags into `flags` (one per entry,
    /// [`Self::effector_count`]). Extra room is left untouched; allocates nothing.
    pub fn effector_outputs(&mut self, out: &mut [f64], flags: &mut [u32]) {
        self.begin_step();
        let eom = &self.eom;
        let n = eom.effectors.len();
        for (((e, r), o), f) in eom
            .effectors
            .iter()
            .zip(&eom.ranges)
            .zip(&eom.output_ranges)
            .zip(flags.iter_mut())
        {
            if let Some(out) = out.get_mut(o.clone()) {
                *f = e.outputs(&self.state.effectors[r.clone()], out);
            }
        }
        for ((&i, o), f) in eom
            .listed
            .iter()
            .zip(&eom.output_ranges[n..])
            .zip(flags.iter_mut().skip(n))
        {
            if let Some(out) = out.get_mut(o.clone()) {
                *f = eom.dynamic[i].outputs(out);
            }
        }
    }

    /// Number of effector entries: the state effectors, then the listed dynamic effectors (the
    /// actuators). The state record carries one entry each, in this order.
    pub fn effector_count(&self) -> usize {
        self.eom.effectors.len() + self.eom.listed.len()
    }

    /// Every effector entry, in wire order: what the state record, the CSV, the input schedule
    /// and the command checks name.
    pub fn effector_entries(&self) -> impl Iterator<Item = EffectorEntry<'_>> + '_ {
        let eom = &self.eom;
        let bodies = eom
            .effectors
            .iter()
            .zip(&eom.ranges)
            .map(|(e, r)| EffectorEntry {
                kind: e.kind(),
                name: e.name(),
                state_names: e.state_names(),
                state_range: r.clone(),
                input_names: e.input_names(),
                output_names: e.output_names(),
            });
        let end = eom.ranges.last().map_or(0, |r| r.end);
        let actuators = eom.listed.iter().map(move |&i| {
            let e = &eom.dynamic[i];
            EffectorEntry {
                kind: e
                    .listed_kind()
                    .expect("only dynamic effectors with a listed kind are listed"),
                name: e.name(),
                state_names: &[],
                state_range: end..end,
                input_names: e.input_names(),
                output_names: e.output_names(),
            }
        });
        bodies.chain(actuators)
    }

    /// Each effector's own mass properties about B at the current state (pass 1 of the
    /// equations of motion, one effector at a time) into `out`, one per effector (extra room is
    /// left untouched). Not on the stepping path.
    pub fn effector_mass_props(&mut self, out: &mut [EffectorMassProps]) {
        let eom = &mut self.eom;
        for ((e, r), o) in eom
            .effectors
            .iter_mut()
            .zip(&eom.ranges)
            .zip(out.iter_mut())
        {
            *o = EffectorMassProps::default();
            e.update_mass_props(&self.state.effectors[r.clone()], o);
        }
    }

    /// Runs every effector's [`StateEffector::begin_step`] at the current state and time.
    fn begin_step(&mut self) {
        self.eom.begin_step(&self.state, self.t_sim_ns);
    }

    /// Adds a dynamic effector (an external force and torque evaluated at every integrator stage);
    /// returns its index. Construction-time only.
    ///
    /// # Panics
    /// If the effector draws from a propellant tank the spacecraft does not have (see
    /// [`Self::try_add_dynamic_effector`], which says so as an error).
    pub fn add_dynamic_effector(&mut self, effector: Box<dyn DynamicEffector>) -> usize {
        self.try_add_dynamic_effector(effector)
            .unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`Self::add_dynamic_effector`], failing if the effector names a propellant tank
    /// ([`DynamicEffector::propellant_tank`]) that is not among the state effectors (a body
    /// whose [`StateEffector::propellant_kg`] is `Some`, of that name). Construction-time only.
    pub fn try_add_dynamic_effector(
        &mut self,
        effector: Box<dyn DynamicEffector>,
    ) -> Result<usize, ParamError> {
        if let Some(tank_name) = effector.propellant_tank() {
            let eom = &mut self.eom;
            let x = &self.state.effectors;
            let tank = (0..eom.effectors.len())
                .find(|&i| {
                    let e = &eom.effectors[i];
                    e.name() == tank_name && e.propellant_kg(&x[eom.ranges[i].clone()]).is_some()
                })
                .ok_or_else(|| ParamError::Invalid {
                    field: format!("{}.tank", effector.name()),
                    problem: format!("no propellant tank is named `{tank_name}`"),
                })?;
            let index = eom.dynamic.len();
            match eom.feeds.iter_mut().find(|f| f.tank == tank) {
                Some(feed) => feed.thrusters.push(index),
                None => eom.feeds.push(PropellantFeed {
                    tank,
                    thrusters: vec![index],
                }),
            }
        }
        if effector.uses_begin_step() {
            self.eom.dynamic_stepped.push(self.eom.dynamic.len());
        }
        if effector.listed_kind().is_some() {
            let eom = &mut self.eom;
            eom.listed.push(eom.dynamic.len());
            let append = |ranges: &mut Vec<Range<usize>>, len: usize| {
                let start = ranges.last().map_or(0, |r| r.end);
                ranges.push(start..start + len);
            };
            append(&mut eom.input_ranges, effector.input_names().len());
            append(&mut eom.output_ranges, effector.output_names().len());
        }
        self.eom.dynamic.push(effector);
        Ok(self.eom.dynamic.len() - 1)
    }

    /// The dynamic effectors, in registration order.
    pub fn dynamic_effectors(&self) -> &[Box<dyn DynamicEffector>] {
        &self.eom.dynamic
    }

    /// Sets the environment the dynamic effectors read, held until the next call.
    pub fn set_environment(&mut self, env: &EnvironmentSample) {
        self.eom.env = *env;
    }

    /// The environment the dynamic effectors currently read.
    pub fn environment(&self) -> &EnvironmentSample {
        &self.eom.env
    }

    /// Each environment source's force (at B) and torque (about B), B components, evaluated by
    /// its own dynamic effector ([`DynamicEffector::environment_source`]) at the current state
    /// and time in `env`: what that effector adds at the first stage of a step starting now.
    /// Two effectors of one source add into its slot; a source with no effector stays zero.
    /// For telemetry, outside the stepping path (one mass-properties pass and one evaluation
    /// per source); allocates nothing.
    pub fn environment_wrenches(&mut self, env: &EnvironmentSample) -> EnvironmentWrenches {
        let mut out = [Wrench::ZERO; EnvironmentSource::COUNT];
        let eom = &mut self.eom;
        if !eom.dynamic.iter().any(|e| e.environment_source().is_some()) {
            return out;
        }
        let x = &self.state;
        let mut mp = EffectorMassProps {
            mass_kg: eom.hub.mass_kg,
            first_moment_b_kg_m: eom.hub_first_moment_b,
            inertia_pnt_b_b_kg_m2: eom.hub_inertia_pnt_b_b,
            ..EffectorMassProps::default()
        };
        for (e, r) in eom.effectors.iter_mut().zip(&eom.ranges) {
            e.update_mass_props(&x.effectors[r.clone()], &mut mp);
        }
        let c_b = mp.first_moment_b_kg_m / mp.mass_kg;
        let dcm_nb = mrp_to_dcm(&x.sigma_bn).transpose();
        let r_cn_n = x.r_bn_n + dcm_nb * c_b;
        let stage = stage_state(x, self.t_sim_ns, 0.0, &dcm_nb, &mp, &c_b, &r_cn_n);
        for e in &mut eom.dynamic {
            if let Some(source) = e.environment_source() {
                e.add_force_torque(&stage, env, &mut out[source as usize]);
            }
        }
        out
    }

    /// The hub parameters.
    pub fn hub(&self) -> &HubParams {
        &self.eom.hub
    }

    /// The gravity model.
    pub fn gravity(&self) -> &GravityModel {
        &self.eom.gravity
    }

    /// Sets the external wrench on the hub, held constant until the next call.
    pub fn set_wrench(&mut self, w: Wrench) {
        self.eom.force_b_newton = w.force_b_newton;
        self.eom.torque_b_nm = w.torque_b_nm;
    }

    /// The external wrench currently applied.
    pub fn wrench(&self) -> Wrench {
        Wrench {
            force_b_newton: self.eom.force_b_newton,
            torque_b_nm: self.eom.torque_b_nm,
        }
    }

    /// Evaluates the state derivative `dx` at state `x` with the current wrench and effector
    /// inputs (each effector's [`StateEffector::begin_step`] runs at `x` first, as at the start
    /// of a step), and returns the hub accelerations. This is the equation-of-motion function the
    /// integrator integrates: it allocates nothing and cannot fail.
    pub fn derivatives(&mut self, x: &State, dx: &mut State) -> HubOutputs {
        self.eom.begin_step(x, self.t_sim_ns);
        self.eom.eval(x, dx, self.t_sim_ns, 0.0)
    }

    /// Advances one step of [`Self::step_ns`] with the chosen [`Self::integrator`] (RK4 by
    /// default) and the current wrench and effector inputs (each effector's
    /// [`StateEffector::begin_step`] runs first, at the step's initial state; stage `i` is
    /// evaluated at t₀ + c_i h), then switches σ to its shadow set if |σ| > 1. Allocates nothing.
    pub fn step(&mut self) {
        self.step_with(&mut NoHook);
    }

    /// [`Self::step`], handing every stage's evaluation to `hook` and closing the step with the
    /// integrator's own combination of stage values ([`super::stage_hook`]). Allocates nothing
    /// (if `hook` allocates nothing).
    pub fn step_with<H: StageHook + ?Sized>(&mut self, hook: &mut H) {
        self.begin_step();
        let h = self.step_ns as f64 * 1e-9;
        let t0 = self.t_sim_ns;
        let Self {
            eom,
            state,
            ws,
            method,
            ..
        } = self;
        let StageWorkspace { k, stage } = ws;
        let out = eom.eval(state, &mut k[0], t0, 0.0);
        hook.stage(0, state, &out);
        for i in 1..k.len() {
            let (done, rest) = k.split_at_mut(i);
            stage.set_stage(state, method, i, done, h);
            let out = eom.eval(stage, &mut rest[0], t0, method.c[i] * h);
            hook.stage(i, stage, &out);
        }
        state.add_step(method, k, h, stage);
        hook.end_step(&StageCombine::new(method, h));
        mrp_switch(&mut state.sigma_bn);
        self.t_sim_ns += self.step_ns;
    }

    /// Lists the vehicle's mutable state for a checkpoint ([`flexdyn_kernel::archive`]): the
    /// time, the integrated state, the applied wrench, the environment sample the dynamic
    /// effectors read, then each appended body and each dynamic effector in its own section
    /// (named by kind and name, so a restore into another vehicle stops there). The stage
    /// buffers are scratch, overwritten by every step. Not on the stepping path.
    pub fn archive(&mut self, a: &mut Archive<'_>) {
        a.section("spacecraft", |a| {
            a.put(&mut self.t_sim_ns);
            // Named field by field: a new field does not compile until it is listed here.
            let State {
                r_bn_n,
                v_bn_n,
                sigma_bn,
                omega_bn_b,
                effectors,
            } = &mut self.state;
            a.put(r_bn_n);
            a.put(v_bn_n);
            a.put(sigma_bn);
            a.put(omega_bn_b);
            a.expect_count("effector states", effectors.len());
            a.put(&mut effectors[..]);
            let eom = &mut self.eom;
            a.put(&mut eom.force_b_newton);
            a.put(&mut eom.torque_b_nm);
            eom.env.archive(a);
            a.expect_count("appended bodies", eom.effectors.len());
            for e in &mut eom.effectors {
                let name = format!("{} {}", e.kind().name, e.name());
                a.section(&name, |a| e.archive(a));
            }
            a.expect_count("dynamic effectors", eom.dynamic.len());
            for e in &mut eom.dynamic {
                let name = e.name().to_string();
                a.section(&name, |a| e.archive(a));
            }
        });
    }

    /// Chooses the integration method (construction time: it resizes the stage buffers). The
    /// state and time are kept.
    pub fn set_integrator(&mut self, method: &'static ButcherTableau) {
        self.method = method;
        self.ws.k.resize(method.stages(), self.ws.stage.clone());
    }

    /// The integration method.
    pub fn integrator(&self) -> &'static ButcherTableau {
        self.method
    }

    /// Hub accelerations at the current state with the current wrench (one derivative evaluation;
    /// the result is not cached, so call it once per output).
    pub fn hub_outputs(&mut self) -> HubOutputs {
        self.begin_step();
        self.eom
            .eval(&self.state, &mut self.ws.stage, self.t_sim_ns, 0.0)
    }

    fn energy_momentum_sum(&self, x: &State) -> EnergyMomentum {
        let omega = x.omega_bn_b;
        let mut em = EnergyMomentum::rigid_body(
            self.eom.hub.mass_kg,
            &self.eom.hub.r_bcb_b_m,
            &Vector3::zeros(),
            &self.eom.hub.inertia_bc_b_kg_m2,
            &omega,
            &omega,
        );
        for (e, r) in self.eom.effectors.iter().zip(&self.eom.ranges) {
            em += e.energy_momentum(&x.effectors[r.clone()], &omega);
        }
        em
    }

    /// Conserved quantities at state `x`, in N components.
    pub fn conserved_at(&self, x: &State) -> Conserved {
        let em = self.energy_momentum_sum(x);
        let m = em.mass_kg;
        let c_b = em.first_moment_b_kg_m / m;
        let c_dot_b = em.lin_mom_rel_b_kg_m_s / m;
        let dcm_nb = mrp_to_dcm(&x.sigma_bn).transpose();
        // Shift from B to C: H_C = H_B − c × p, T_C = T_B − |p|²/(2m), with p = m ċ.
        let h_c_b = em.ang_mom_pnt_b_b_kg_m2_s - c_b.cross(&em.lin_mom_rel_b_kg_m_s);
        let t_c = em.kinetic_rel_b_j - em.lin_mom_rel_b_kg_m_s.norm_squared() / (2.0 * m);
        let r_cn_n = x.r_bn_n + dcm_nb * c_b;
        let v_cn_n = x.v_bn_n + dcm_nb * c_dot_b;
        Conserved {
            orb_energy_j: 0.5 * m * v_cn_n.norm_squared()
                + m * gravity_potential(&self.eom.gravity, &r_cn_n),
            rot_energy_j: t_c + em.potential_j,
            orb_ang_mom_n: r_cn_n.cross(&v_cn_n) * m,
            rot_ang_mom_c_n: dcm_nb * h_c_b,
        }
    }

    /// Conserved quantities at the current state.
    pub fn conserved(&self) -> Conserved {
        self.conserved_at(&self.state)
    }

    /// \[kg\] total mass, \[m\] centre of mass relative to B (B components), and [m/s] its velocity
    /// relative to B's translation (B components) at the current state.
    pub fn center_of_mass(&self) -> (f64, Vector3<f64>, Vector3<f64>) {
        let em = self.energy_momentum_sum(&self.state);
        (
            em.mass_kg,
            em.first_moment_b_kg_m / em.mass_kg,
            em.lin_mom_rel_b_kg_m_s / em.mass_kg,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The four right-hand sides solved side by side are each the one-lane solve's bits, and the
    /// solves invert the matrix: A·X = B and A·y = v to rounding, for matrices whose pivoting
    /// takes each row order (a small splitmix sequence supplies the entries).
    #[test]
    fn side_by_side_solves_are_the_single_solves_bit_for_bit() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = seed;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut perms = std::collections::BTreeSet::new();
        for _ in 0..200 {
            let a = Matrix3::from_fn(|_, _| next()) + Matrix3::identity() * 0.5;
            let b = Matrix3::from_fn(|_, _| next());
            let v = Vector3::new(next(), next(), next());
            let lu = Lu3::factor(&a);
            perms.insert(lu.perm);
            let (x, y) = lu.solve_matrix_and(&b, &v);
            for j in 0..3 {
                let single = lu.solve(&b.column(j).into_owned());
                for i in 0..3 {
                    assert_eq!(x[(i, j)].to_bits(), single[i].to_bits());
                }
            }
            let single = lu.solve(&v);
            for i in 0..3 {
                assert_eq!(y[i].to_bits(), single[i].to_bits());
            }
            let scale = a.norm() * x.norm().max(y.norm());
            assert!((a * x - b).norm() <= 1e-12 * scale.max(1.0), "A X ≠ B");
            assert!((a * y - v).norm() <= 1e-12 * scale.max(1.0), "A y ≠ v");
        }
        assert!(perms.len() >= 4, "pivot orders seen: {perms:?}");
    }
}
