//! Fuel slosh as a spherical pendulum: a point mass m on a massless rod of length l from a pivot
//! P fixed in B, free to swing in two angles, with viscous damping. The lumped-mass pendulum model
//! of propellant slosh (Abramson, NASA SP-106, 1966, Chapter 6; Dodge, *The New "Dynamic Behavior
//! of Liquids in Moving Containers"*, SwRI 2000, Chapter 3), coupled to the hub by
//! back-substitution as Basilisk's `sphericalPendulum` module does (technical note
//! `Basilisk-SPHERICALPENDULUM-20180518`, "Model Description": the same angle convention,
//! Eq. `rPcjB`, and the hub equations of its Eqs. `cddot` onward); Allard, Diaz Ramos & Schaub
//! (AIAA/AAS Astrodynamics Specialist Conference, 2016) give the lumped-mass slosh coupling this
//! follows. The equations are derived here (Kane's method with the particle's partial
//! velocities) in this file's notation; the numbers (P1)–(P7) are this file's own and are cited
//! beside the code.
//!
//! # Model and derivation
//! The pendulum frame P = (p̂1, p̂2, p̂3) is fixed in B: p̂1 is the configured hang axis (where the
//! rod points at rest, against the settling acceleration), p̂2 = unit(p̂1 × x̂_B) (or
//! unit(p̂1 × ŷ_B) when p̂1 is within 30° of x̂_B), p̂3 = p̂1 × p̂2.
//!
//! - (P1) Rod direction and position (Basilisk note, Eq. `rPcjB`):
//!   ê = cos θ (cos φ p̂1 + sin φ p̂2) − sin θ p̂3, r = r_Pc/B = r_P/B + l ê. With
//!   ê_φ = −sin φ p̂1 + cos φ p̂2 and ê_θ = −sin θ (cos φ p̂1 + sin φ p̂2) − cos θ p̂3, the triad
//!   (ê, ê_φ, ê_θ) is orthonormal, ∂ê/∂φ = cos θ ê_φ and ∂ê/∂θ = ê_θ.
//! - (P2) r′ = l (cos θ φ̇ ê_φ + θ̇ ê_θ), and
//!   r″ = l (cos θ φ̈ ê_φ + θ̈ ê_θ) − (|r′|²/l) ê + l (sin θ cos θ φ̇² ê_θ − 2 sin θ θ̇ φ̇ ê_φ).
//! - (P3) Kane's equations for the coordinates (φ, θ), whose partial velocities are l cos θ ê_φ
//!   and l ê_θ: m (∂r/∂q)·a_Pc = Q_q, with a_Pc = r̈_B/N + ω̇ × r + w + r″,
//!   w = ω × (ω × r) + 2 ω × r′, and the damping Q = −∂R/∂q̇ of the Rayleigh function
//!   R = ½ c |ê′|² = ½ c (cos²θ φ̇² + θ̇²). Gravity is uniform and drops out (r̈_B/N is the
//!   non-gravitational acceleration, as for every effector). Solved for the accelerations:
//!   **φ̈ = −ê_φ·s / (l cos θ) + 2 tan θ θ̇ φ̇ − (c/(m l²)) φ̇** and
//!   **θ̈ = −ê_θ·s / l − sin θ cos θ φ̇² − (c/(m l²)) θ̇**, with s = r̈_B/N + ω̇ × r + w.
//! - (P4) Substituting (P3) into (P2) gives the particle's relative acceleration in Cartesian form,
//!   free of the angles' singularity: with \[P_t\] = \[1\] − êêᵀ (the plane the mass can move in),
//!   **r″ = −\[P_t\]·(r̈_B/N + ω̇ × r) + g**, **g = −\[P_t\] w − (|r′|²/l) ê − (c/(m l²)) r′**.
//! - (P5) The hub's translational equation gains m r″ (through m_sc c″):
//!   **\[A_contr\] = −m \[P_t\]**, **\[B_contr\] = m \[P_t\]\[r̃\]** (from −\[P_t\]·(ω̇ × r) = \[P_t\]\[r̃\]ω̇),
//!   **v_trans,contr = −m g** (m r″ is on the left of the hub's equation, its free part g moves
//!   to the right).
//! - (P6) The rotational equation about B gains m r × r″, plus −ω × (m r × r′) and the mass's
//!   share of −\[I′_sc,B\]ω: **\[C_contr\] = −m \[r̃\]\[P_t\] = \[B_contr\]ᵀ**,
//!   **\[D_contr\] = m \[r̃\]·\[P_t\]·\[r̃\]**, **v_rot,contr = −m r × g − ω × (m r × r′) − \[I′\]ω**, with
//!   \[I′\]ω = m (2 (r·r′) ω − r′ (r·ω) − r (r′·ω)) as for any point mass.
//! - (P7) Mass properties: a point mass m at r moving at r′; energy ½ m |r′ + ω × r|², no stored
//!   potential (the restoring effect is the hub's acceleration). The rod tension and the damping
//!   are internal: the angular momentum about the system's centre of mass is conserved, and with
//!   c = 0 so is the energy.
//!
//! # The angles' singularity
//! (φ, θ) are azimuth and elevation about p̂3: they are singular where cos θ = 0, i.e. where the
//! rod points along ±p̂3, and (P3)'s φ̈ divides by cos θ there. Only the angles are singular:
//! the hub's terms (P4)–(P6) are regular everywhere. The reference axis p̂3 is chosen
//! perpendicular to the hang axis p̂1, so the nominal hang (θ = 0) is 90° from the singular
//! directions, the farthest any choice can put it. A slosh pendulum swinging near 90° from its
//! hang is far outside the small-amplitude range of the equivalent mechanical model it
//! represents; the initial |θ| is limited to 80° ([`params::MAX_INITIAL_THETA_RAD`]), and the
//! state is not re-charted during a run.
//!
//! # Parameters from a tank's fill level
//! A `tank` table sets the mass, the length and the pivot from the fill level
//! ([`crate::slosh_tank`], Eqs. T2, T3, T5): the pendulum's length does not depend on the
//! settling acceleration, so the pendulum follows whatever acceleration the vehicle has.
//!
//! Integrated state: `[φ, φ̇, θ, θ̇]`.

use nalgebra::{Matrix3, Vector3};

use crate::effector::{
    point_mass_i_prime_omega, BackSubContributions, EffectorKind, EffectorMassProps,
    EnergyMomentum, HubAccel, HubKinematics, StateEffector,
};
use flexdyn_kernel::attitude::tilde;
use flexdyn_kernel::validate::ParamError;

pub mod kind;
mod params;
pub mod schema;
#[cfg(test)]
mod tests;

pub use params::{
    SloshPendulumEntry, SloshPendulumParams, SloshPendulumSource, MAX_INITIAL_THETA_RAD,
};

/// The pendulum slosh kind: wire tag `effector_kind::SLOSH_PENDULUM`, CSV columns
/// `pendulum<k>_…`.
pub const KIND: EffectorKind = EffectorKind {
    name: "slosh_pendulum",
    wire_tag: flexdyn_proto::effector_kind::SLOSH_PENDULUM,
    column_prefix: "pendulum",
};

/// State order: φ \[rad\], φ̇ \[rad/s\], θ \[rad\], θ̇ \[rad/s\].
pub const STATE_NAMES: [&str; 4] = ["phi_rad", "phi_dot_rad_s", "theta_rad", "theta_dot_rad_s"];

/// Index of φ in the pendulum's state slice.
pub const PHI: usize = 0;
/// Index of φ̇.
pub const PHI_DOT: usize = 1;
/// Index of θ.
pub const THETA: usize = 2;
/// Index of θ̇.
pub const THETA_DOT: usize = 3;

/// The rod's geometry at one state (P1)–(P2).
#[derive(Debug, Clone, Copy)]
struct Geometry {
    /// ê, ê_φ, ê_θ in B.
    e: Vector3<f64>,
    e_phi: Vector3<f64>,
    e_theta: Vector3<f64>,
    /// sin θ, cos θ.
    sin_theta: f64,
    cos_theta: f64,
    /// \[m\] r_Pc/B and \[m/s\] r′_Pc/B.
    r: Vector3<f64>,
    r_prime: Vector3<f64>,
}

/// Terms cached between the passes of one evaluation.
#[derive(Debug, Clone, Copy)]
struct Cache {
    g: Geometry,
    /// \[m/s²\] w = ω × (ω × r) + 2 ω × r′ (P3).
    w: Vector3<f64>,
}

/// A spherical slosh pendulum ([`StateEffector`]); see the module docs.
#[derive(Debug, Clone)]
pub struct SloshPendulum {
    params: SloshPendulumParams,
    /// p̂1, p̂2, p̂3 in B.
    p1: Vector3<f64>,
    p2: Vector3<f64>,
    p3: Vector3<f64>,
    /// \[1/s\] c/(m l²).
    damping_rate: f64,
    cache: Cache,
}

impl SloshPendulum {
    /// A pendulum from validated parameters; `path` prefixes error fields
    /// (`slosh_pendulums[0]`).
    pub fn new(params: SloshPendulumParams, path: &str) -> Result<Self, ParamError> {
        params.validate(path)?;
        let p1 = params.hang_axis_b / params.hang_axis_b.norm();
        let x = Vector3::x();
        let helper = if p1.cross(&x).norm() > 0.5 {
            x
        } else {
            Vector3::y()
        };
        let p2 = p1.cross(&helper).normalize();
        let p3 = p1.cross(&p2);
        let damping_rate = params.c_nm_s_rad / (params.mass_kg * params.l_m * params.l_m);
        let mut s = Self {
            p1,
            p2,
            p3,
            damping_rate,
            cache: Cache {
                g: Geometry {
                    e: p1,
                    e_phi: p2,
                    e_theta: -p3,
                    sin_theta: 0.0,
                    cos_theta: 1.0,
                    r: Vector3::zeros(),
                    r_prime: Vector3::zeros(),
                },
                w: Vector3::zeros(),
            },
            params,
        };
        s.cache.g.r = s.params.r_pb_b_m + p1 * s.params.l_m;
        Ok(s)
    }

    /// The parameters.
    pub fn params(&self) -> &SloshPendulumParams {
        &self.params
    }

    /// The pendulum frame's axes p̂1, p̂2, p̂3 in B.
    pub fn frame_b(&self) -> [Vector3<f64>; 3] {
        [self.p1, self.p2, self.p3]
    }

    /// (P1)–(P2): the rod's geometry at state `x`.
    #[inline(always)]
    fn geometry(&self, x: &[f64]) -> Geometry {
        let l = self.params.l_m;
        let (sin_phi, cos_phi) = x[PHI].sin_cos();
        let (sin_theta, cos_theta) = x[THETA].sin_cos();
        let horizontal = self.p1 * cos_phi + self.p2 * sin_phi;
        let e = horizontal * cos_theta - self.p3 * sin_theta;
        let e_phi = self.p2 * cos_phi - self.p1 * sin_phi;
        let e_theta = -(horizontal * sin_theta + self.p3 * cos_theta);
        Geometry {
            e,
            e_phi,
            e_theta,
            sin_theta,
            cos_theta,
            r: self.params.r_pb_b_m + e * l,
            r_prime: (e_phi * (cos_theta * x[PHI_DOT]) + e_theta * x[THETA_DOT]) * l,
        }
    }

    /// \[m\] r_Pc/B, the mass's position relative to B at state `x` (P1).
    pub fn r_pcb_b_m(&self, x: &[f64]) -> Vector3<f64> {
        self.geometry(x).r
    }
}

impl StateEffector for SloshPendulum {
    fn name(&self) -> &str {
        &self.params.name
    }

    fn kind(&self) -> EffectorKind {
        KIND
    }

    fn state_names(&self) -> &'static [&'static str] {
        &STATE_NAMES
    }

    fn parameters(&self, x0: &[f64], out: &mut Vec<(String, f64)>) {
        let p = &self.params;
        let mut put = |k: String, v: f64| out.push((k, v));
        for i in 0..3 {
            put(format!("r_pb_b_m[{i}]"), p.r_pb_b_m[i]);
            put(format!("hang_axis_b[{i}]"), p.hang_axis_b[i]);
        }
        put("l_m".into(), p.l_m);
        put("mass_kg".into(), p.mass_kg);
        put("c_nm_s_rad".into(), p.c_nm_s_rad);
        put("phi_rad".into(), x0[PHI]);
        put("phi_dot_rad_s".into(), x0[PHI_DOT]);
        put("theta_rad".into(), x0[THETA]);
        put("theta_dot_rad_s".into(), x0[THETA_DOT]);
    }

    fn initial_state(&self, x: &mut [f64]) {
        let p = &self.params;
        x[PHI] = p.phi_rad;
        x[PHI_DOT] = p.phi_dot_rad_s;
        x[THETA] = p.theta_rad;
        x[THETA_DOT] = p.theta_dot_rad_s;
    }

    fn update_mass_props(&mut self, x: &[f64], sum: &mut EffectorMassProps) {
        // (P7): a point mass at r moving at r′.
        let g = self.geometry(x);
        self.cache.g = g;
        sum.add_point_mass(self.params.mass_kg, &g.r, &g.r_prime);
    }

    fn update_contributions(
        &mut self,
        _x: &[f64],
        hub: &HubKinematics,
        sum: &mut BackSubContributions,
    ) {
        let m = self.params.mass_kg;
        let l = self.params.l_m;
        let omega = &hub.omega_bn_b;
        let g = &self.cache.g;
        let (e, r, r_prime) = (&g.e, &g.r, &g.r_prime);
        // (P3): w = ω × (ω × r) + 2 ω × r′.
        let w = omega.cross(&omega.cross(r)) + omega.cross(r_prime) * 2.0;
        self.cache.w = w;
        // (P4): g = −[P_t] w − (|r′|²/l) ê − (c/(m l²)) r′, [P_t] = [1] − êêᵀ.
        let free = e * (e.dot(&w) - r_prime.norm_squared() / l) - w - r_prime * self.damping_rate;
        // (P5): [A_contr] = −m[P_t], [B_contr] = m[P_t]·[r̃], v_trans,contr = −m g.
        // (P6): [C_contr] = [B_contr]ᵀ, [D_contr] = m[r̃]·[P_t]·[r̃],
        // v_rot,contr = −m r × g − ω × (m r × r′) − [I′]ω.
        // As rank-one updates: êᵀ[r̃] = (ê × r)ᵀ and [r̃][r̃] = r rᵀ − |r|²[1] give
        // [B_contr] = m([r̃] − ê (ê × r)ᵀ) and [D_contr] = m(r rᵀ − |r|²[1] + q qᵀ), q = r × ê.
        let q = r.cross(e);
        let r_tilde = tilde(r);
        let b_contr = (r_tilde + e * q.transpose()) * m;
        sum.matrix_a += (e * e.transpose() - Matrix3::identity()) * m;
        sum.matrix_b += b_contr;
        sum.matrix_c += b_contr.transpose();
        sum.matrix_d += (r * r.transpose() + q * q.transpose()
            - Matrix3::from_diagonal_element(r.norm_squared()))
            * m;
        sum.vec_trans -= free * m;
        sum.vec_rot -= (r.cross(&free) + omega.cross(&r.cross(r_prime))) * m
            + point_mass_i_prime_omega(m, r, r_prime, omega);
    }

    fn compute_derivatives(&mut self, x: &[f64], hub_accel: &HubAccel, dx: &mut [f64]) {
        // (P3), with s = r̈_B/N + ω̇ × r + w.
        let l = self.params.l_m;
        let c = &self.cache;
        let g = &c.g;
        let s = hub_accel.nongrav_accel_bn_b + hub_accel.omega_dot_bn_b.cross(&g.r) + c.w;
        let (phi_dot, theta_dot) = (x[PHI_DOT], x[THETA_DOT]);
        dx[PHI] = phi_dot;
        dx[THETA] = theta_dot;
        dx[PHI_DOT] = -g.e_phi.dot(&s) / (l * g.cos_theta)
            + 2.0 * g.sin_theta / g.cos_theta * theta_dot * phi_dot
            - self.damping_rate * phi_dot;
        dx[THETA_DOT] = -g.e_theta.dot(&s) / l
            - g.sin_theta * g.cos_theta * phi_dot * phi_dot
            - self.damping_rate * theta_dot;
    }

    fn energy_momentum(&self, x: &[f64], omega_bn_b: &Vector3<f64>) -> EnergyMomentum {
        // (P7)
        let g = self.geometry(x);
        EnergyMomentum::point_mass(self.params.mass_kg, &g.r, &g.r_prime, omega_bn_b)
    }

    /// Nothing beyond the integrated states: the cached geometry is recomputed from `x`.
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
}
