//! A propellant tank: the propellant its thrusters burn leaves the vehicle, and the vehicle's
//! mass, centre of mass and inertia move with it. The tank is an appended body
//! ([`StateEffector`]) whose one integrated state is its propellant mass m_p; the thrusters
//! that name it (`tank = "…"` in `[[thrusters]]`,
//! [`crate::dynamic_effectors::thruster`]) draw from it.
//!
//! # Source
//! Panicucci, Allard & Schaub, "Spacecraft Dynamics Employing a General Multi-tank and
//! Multi-thruster Mass Depletion Formulation", *The Journal of the Astronautical Sciences* 65
//! (2018), as reproduced (in shortened form) by Basilisk's technical note
//! `Basilisk-FUELTANK-20171203` (`src/simulation/dynamics/FuelTank/_Documentation`). The
//! equation labels cited below are that note's LaTeX labels (`eq:eq30`, …); the journal's own
//! numbering was not at hand. The derivation is written here in this file's notation and
//! numbered (D1)–(D7); the code cites those numbers.
//!
//! # Derivation
//! Notation: r_T = r_Tc/B the tank's propellant centroid relative to B (fixed in B), r_N the
//! nozzle point of thruster j, ω = ω_B/N, ′ the derivative in B, ṁ_p = dm_p/dt ≤ 0 the tank's
//! mass rate and ṁ_j ≥ 0 the mass flow out of nozzle j (Σ_j ṁ_j = −ṁ_p, mass is conserved).
//!
//! - **(D1) Mass flow.** Thrust and flow are tied by the specific impulse, F_j = I_sp,j g₀ ṁ_j
//!   (note, Eq. `eq:IspRel`, which folds the nozzle's pressure thrust into I_sp; Sutton &
//!   Biblarz, *Rocket Propulsion Elements*, 9th ed., Eq. 2-5), so
//!   **ṁ_p = −Σ_j s F̄_j / (I_sp,j g₀)**, summed over the thrusters that draw from the tank,
//!   with F̄_j the step-average thrust the thruster solves in closed form and s the supply
//!   fraction of (D5). F̄_j is constant over a step, so m_p falls linearly within it: every
//!   Runge–Kutta method integrates it exactly, and the propellant used equals ∫F/(I_sp g₀) dt
//!   to round-off.
//! - **(D2) Mass properties** about B (note, Eqs. `eq:def_rCB`, `eq:eq45`, `eq:eq46`): the
//!   propellant adds m_p, the first moment m_p r_T and the inertia
//!   \[I_T,B\] = [I_Tc(m_p)] + m_p [r̃_T]\[r̃_T\]ᵀ, where \[I_Tc\] is the tank model's inertia about
//!   its centroid (D6). The hub sums them with every other body's each evaluation, so m_sc, c
//!   and \[I_sc,B\] of the equations of motion follow the propellant.
//! - **(D3) Translational equation.** The linear momentum of the control volume (hub, bodies and
//!   the propellant still aboard) changes by the external force less the momentum flux out of
//!   the nozzles (the note's Reynolds-transport form, Eq. `eq:ComplTranslEOM`). With the first
//!   moment S = m_sc c, its B-frame rate is S′ = P′ + ṁ_p r_T, where P′ = Σ m r′ is the bodies'
//!   own motion the hub already carries (its −2ω × P′ term): the propellant vanishes from the
//!   tank at r_T and leaves the vehicle at r_N with the velocity ṙ_B + ω × r_N + v_exh. Taking
//!   the N-frame derivative of m_sc ṙ_B + ω × S + P′ and adding the flux, the mass terms
//!   ṁ_p ṙ_B and Σ ṁ_j ṙ_B cancel, −Σ ṁ_j v_exh is the thrust, and what is left beside the
//!   rigid-body equation is
//!   **m_sc r̈_B − m_sc [c̃] ω̇ = … − ṁ_p ω × r_T − Σ_j ṁ_j ω × r_N,j**:
//!   a force −ṁ_p ω × r_T at the tank (added here to v_trans) and a force −ṁ_j ω × r_N,j at each
//!   nozzle (added by the thruster). Their sum, ṁ_j ω × (r_T − r_N) for one thruster, does not
//!   depend on where B is. Eq. `eq:eq30` carries the same physics grouped through the
//!   depleting centre of mass's c′ and c″ (Eqs. `eq:eq17`, `eq:eq18`) and m̈ terms, which
//!   vanish inside a step here (ṁ is constant over a step).
//! - **(D4) Rotational equation** (note, Eqs. `eq:HscB_dot`, `eq:eq48`, `eq:eq53`, `eq:eq55`):
//!   \[I_sc,B\] ω̇ + m_sc [c̃] r̈_B = −ω × \[I_sc,B\] ω − \[K\] ω + L_B, with
//!   \[K\] = Σ_tanks \[I_T,B\]′ + Σ_j ṁ_j [r̃_N,j]\[r̃_N,j\]ᵀ, and for a centroid fixed in B
//!   \[I_T,B\]′ = \[I_Tc\]′ + ṁ_p [r̃_T]\[r̃_T\]ᵀ. The tank adds its share −\[I_T,B\]′ ω to v_rot, as
//!   every body adds its −[I′]ω; since r_T × (ω × r_T) = [r̃_T]\[r̃_T\]ᵀ ω, its point-mass part is
//!   exactly the moment of the force of (D3) at T, so the tank adds
//!   **v_rot += −\[I_Tc\]′ ω + r_T × (−ṁ_p ω × r_T)**. The nozzle's part −ṁ_j [r̃_N]\[r̃_N\]ᵀ ω (the
//!   *jet damping*) is likewise the moment of the nozzle's force of (D3) at r_N, which the
//!   thruster applies there.
//! - **(D5) Running dry.** Each step the spacecraft sums the demand D = Σ_j F̄_j/(I_sp,j g₀) of
//!   a tank's thrusters and compares D h with the propellant m_p at the step's start: s = 1 if
//!   it suffices, s = m_p/(D h) in the step it does not (the tank then empties exactly at the
//!   step's end), s = 0 once it is empty. Every thruster it feeds delivers s times its force
//!   and flow, so the impulse stays I_sp g₀ times the propellant used and m_p never goes
//!   negative (a residue of round-off below 1e-12 of the load counts as empty).
//! - **(D6) Tank inertia models** (note, "Tank models"; Panicucci et al., the same section),
//!   both a sphere of propellant about its centre, so \[I_Tc\] = I(m_p) \[1\]:
//!   - `constant_volume` (the propellant stays spread uniformly through a sphere of fixed
//!     radius R and its density falls as it is used, the "uniform burn" limit):
//!     I = (2/5) m_p R², I′ = (2/5) ṁ_p R² — the inertia is proportional to the mass;
//!   - `constant_density` (a sphere of propellant at density ρ that shrinks about its fixed
//!     centre as it is used, as in a bladder or diaphragm tank): R(m_p) = (3 m_p / (4π ρ))^(1/3),
//!     I = (2/5) m_p R², and since R² ∝ m_p^(2/3), I′ = (5/3)(2/5) ṁ_p R² = (2/3) ṁ_p R² (the
//!     note's constant-density result). It falls faster than the mass (I ∝ m_p^(5/3)).
//!
//!   The propellant's centroid is fixed in both (r′_T = r″_T = 0), so the tank adds nothing to
//!   \[A\], \[B\], \[C\], \[D\] and has no accelerations to back-substitute.
//! - **(D7) Energy and momentum**: a rigid body of mass m_p at r_T with inertia [I_Tc(m_p)],
//!   rotating with the hub. With no thrust m_p is constant and the tank is a rigid part of the
//!   hub: the conserved quantities stay conserved.
//!
//! # What is neglected
//! - The flow inside the feed lines and the tank (the note makes the same assumption): its
//!   relative momentum ṁ ℓ over a line of length ℓ would add a Coriolis force of order
//!   2 ṁ ω ℓ, the same order as (D3)'s terms — 9e-5 N for 1 N at I_sp 220 s (ṁ = 4.6e-4 kg/s),
//!   ω = 0.1 rad/s and ℓ = 1 m, 1e-4 of the thrust — and it depends on the plumbing's routing,
//!   which the configuration does not describe.
//! - The nozzle-exit term of \[K\], ṁ_j (A_noz/4π) \[BM\] diag(2, 1, 1) \[BM\]ᵀ (Eq. `eq:eq53`'s
//!   second integral): A_noz/(4π) ≈ 2e-5 m² for a 1 N nozzle against |r_N|² ≈ 1 m², 1e-5 of the
//!   jet damping, which is itself ~1e-4 of the thrust's torque.
//! - The propellant's own motion in the tank: its slosh is the separate `[[slosh_linear]]` /
//!   `[[slosh_pendulums]]` models, whose masses stay constant. A vehicle with both splits the
//!   propellant between them by configuration.
//!
//! Integrated state: `[m_p]` (kg).

use nalgebra::{Matrix3, Vector3};

use crate::effector::{
    BackSubContributions, EffectorKind, EffectorMassProps, EnergyMomentum, HubAccel, HubKinematics,
    StateEffector,
};
use flexdyn_kernel::validate::{check_finite, check_non_negative, check_positive, ParamError};

pub mod kind;
pub mod schema;
#[cfg(test)]
mod tests;

/// The propellant tank kind: wire tag `effector_kind::PROPELLANT_TANK`, CSV columns `tank<k>_…`.
pub const KIND: EffectorKind = EffectorKind {
    name: "propellant_tank",
    wire_tag: flexdyn_proto::effector_kind::PROPELLANT_TANK,
    column_prefix: "tank",
};

/// State order: m_p \[kg\].
pub const STATE_NAMES: [&str; 1] = ["propellant_mass_kg"];
/// Outputs: dm_p/dt over the current step (≤ 0), the fraction of the initial load left, and
/// the propellant used so far.
pub const OUTPUT_NAMES: [&str; 3] = ["mdot_kg_s", "fraction_remaining", "propellant_used_kg"];

/// Flag bit 0: the tank holds no propellant; the thrusters it feeds produce no thrust.
pub const EMPTY: u32 = flexdyn_proto::propellant_tank_flags::EMPTY;

/// \[-\] below this fraction of its initial load a tank counts as empty (D5): the round-off
/// left by the step that drains it.
pub const EMPTY_FRACTION: f64 = 1e-12;

/// Index of m_p in the tank's state slice.
pub const MASS: usize = 0;

/// How the propellant's inertia about its centroid follows its mass (D6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TankInertiaModel {
    /// A sphere of fixed radius whose density falls: I = (2/5) m_p R².
    ConstantVolume {
        /// \[m\] the sphere's radius R.
        radius_m: f64,
    },
    /// A sphere of constant density that shrinks: R = (3 m_p/(4π ρ))^(1/3), I = (2/5) m_p R².
    ConstantDensity {
        /// \[kg/m³\] the propellant's density ρ.
        density_kg_m3: f64,
    },
}

impl TankInertiaModel {
    /// The configuration spellings, in the order of the enum.
    pub const NAMES: [&'static str; 2] = ["constant_volume", "constant_density"];

    /// \[m²\] R² at propellant mass `m_kg` (≥ 0).
    #[inline]
    pub fn radius_sq_m2(&self, m_kg: f64) -> f64 {
        match *self {
            Self::ConstantVolume { radius_m } => radius_m * radius_m,
            Self::ConstantDensity { density_kg_m3 } => (3.0 * m_kg
                / (4.0 * std::f64::consts::PI * density_kg_m3))
                .cbrt()
                .powi(2),
        }
    }

    /// (D6): \[kg·m²\] the principal moment I of propellant mass `m_kg` about its centroid and
    /// \[kg·m²/s\] its rate I′ when the mass changes at `mdot_kg_s`.
    #[inline]
    pub fn inertia_and_rate(&self, m_kg: f64, mdot_kg_s: f64) -> (f64, f64) {
        self.inertia_and_rate_at(m_kg, self.radius_sq_m2(m_kg), mdot_kg_s)
    }

    /// [`Self::inertia_and_rate`] with R² = `r2` at `m_kg` already known.
    #[inline]
    fn inertia_and_rate_at(&self, m_kg: f64, r2: f64, mdot_kg_s: f64) -> (f64, f64) {
        let rate = match self {
            Self::ConstantVolume { .. } => 0.4 * mdot_kg_s * r2,
            Self::ConstantDensity { .. } => (2.0 / 3.0) * mdot_kg_s * r2,
        };
        (0.4 * m_kg * r2, rate)
    }
}

/// One propellant tank (`[[propellant_tanks]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct PropellantTankParams {
    /// Name used in logs, messages and telemetry, and by the thrusters that draw from it.
    pub name: String,
    /// \[m\] the propellant's centroid Tc relative to B, B components (fixed).
    pub r_tcb_b_m: Vector3<f64>,
    /// \[kg\] the propellant loaded at the start.
    pub propellant_mass_kg: f64,
    /// How its inertia follows its mass.
    pub inertia: TankInertiaModel,
}

impl PropellantTankParams {
    /// Validates the tank (`path` is e.g. `propellant_tanks[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_finite(path, "r_tcb_b_m", self.r_tcb_b_m.as_slice())?;
        check_non_negative(path, "propellant_mass_kg", self.propellant_mass_kg)?;
        match self.inertia {
            TankInertiaModel::ConstantVolume { radius_m } => {
                check_positive(path, "radius_m", radius_m)
            }
            TankInertiaModel::ConstantDensity { density_kg_m3 } => {
                check_positive(path, "density_kg_m3", density_kg_m3)
            }
        }
    }
}

/// A built propellant tank ([`StateEffector`]); see the module docs.
#[derive(Debug, Clone)]
pub struct PropellantTank {
    params: PropellantTankParams,
    /// \[kg\] below this it counts as empty (D5).
    empty_below_kg: f64,
    /// \[kg/s\] dm_p/dt over the step being integrated (D1), set by the spacecraft.
    mdot_kg_s: f64,
    /// (m_p, R²(m_p)) of the last evaluation: a tank nothing draws from keeps its mass, and
    /// the constant-density radius costs a cube root.
    radius_sq_at: (f64, f64),
}

impl PropellantTank {
    /// A tank from validated parameters; `path` prefixes error fields (`propellant_tanks[0]`).
    pub fn new(params: PropellantTankParams, path: &str) -> Result<Self, ParamError> {
        params.validate(path)?;
        Ok(Self {
            empty_below_kg: params.propellant_mass_kg * EMPTY_FRACTION,
            radius_sq_at: (
                params.propellant_mass_kg,
                params.inertia.radius_sq_m2(params.propellant_mass_kg),
            ),
            params,
            mdot_kg_s: 0.0,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &PropellantTankParams {
        &self.params
    }

    /// (D6) at mass state `m_kg` (≥ 0) with the step's ṁ_p: (I, I′), R² computed once per mass.
    #[inline]
    fn inertia_now(&mut self, m_kg: f64) -> (f64, f64) {
        if self.radius_sq_at.0 != m_kg {
            self.radius_sq_at = (m_kg, self.params.inertia.radius_sq_m2(m_kg));
        }
        self.params
            .inertia
            .inertia_and_rate_at(m_kg, self.radius_sq_at.1, self.mdot_kg_s)
    }

    /// \[kg\] the propellant it can still deliver at mass state `m_kg`: 0 once empty (D5).
    #[inline]
    fn held_kg(&self, m_kg: f64) -> f64 {
        if m_kg > self.empty_below_kg {
            m_kg
        } else {
            0.0
        }
    }
}

impl StateEffector for PropellantTank {
    fn name(&self) -> &str {
        &self.params.name
    }

    fn kind(&self) -> EffectorKind {
        KIND
    }

    fn state_names(&self) -> &'static [&'static str] {
        &STATE_NAMES
    }

    fn output_names(&self) -> &'static [&'static str] {
        &OUTPUT_NAMES
    }

    fn outputs(&self, x: &[f64], out: &mut [f64]) -> u32 {
        let m0 = self.params.propellant_mass_kg;
        let m = x[MASS].max(0.0);
        out[0] = self.mdot_kg_s;
        out[1] = if m0 > 0.0 { m / m0 } else { 0.0 };
        out[2] = m0 - m;
        if self.held_kg(m) == 0.0 {
            EMPTY
        } else {
            0
        }
    }

    fn parameters(&self, x0: &[f64], out: &mut Vec<(String, f64)>) {
        let p = &self.params;
        for i in 0..3 {
            out.push((format!("r_tcb_b_m[{i}]"), p.r_tcb_b_m[i]));
        }
        out.push(("propellant_mass_kg".into(), x0[MASS]));
        match p.inertia {
            TankInertiaModel::ConstantVolume { radius_m } => {
                out.push(("radius_m".into(), radius_m));
            }
            TankInertiaModel::ConstantDensity { density_kg_m3 } => {
                out.push(("density_kg_m3".into(), density_kg_m3));
            }
        }
    }

    fn initial_state(&self, x: &mut [f64]) {
        x[MASS] = self.params.propellant_mass_kg;
    }

    fn update_mass_props(&mut self, x: &[f64], sum: &mut EffectorMassProps) {
        // (D2): m_p, m_p r_T, [I_Tc] + m_p [r̃_T][r̃_T]ᵀ; never a negative mass.
        let m = x[MASS].max(0.0);
        let (i_tc, _) = self.inertia_now(m);
        sum.add_point_mass(m, &self.params.r_tcb_b_m, &Vector3::zeros());
        sum.inertia_pnt_b_b_kg_m2 += Matrix3::from_diagonal_element(i_tc);
    }

    fn update_contributions(
        &mut self,
        x: &[f64],
        hub: &HubKinematics,
        sum: &mut BackSubContributions,
    ) {
        let mdot = self.mdot_kg_s;
        if mdot == 0.0 {
            // Not drawn from: a rigid mass of the hub, with nothing to add.
            return;
        }
        let (_, i_tc_prime) = self.inertia_now(x[MASS].max(0.0));
        let w = &hub.omega_bn_b;
        let r = &self.params.r_tcb_b_m;
        // (D3): the propellant leaving the tank at r_T, −ṁ_p ω × r_T.
        let f_b = -w.cross(r) * mdot;
        sum.vec_trans += f_b;
        // (D4): −[I_Tc]′ω and the moment of that force, r_T × f = −ṁ_p [r̃_T][r̃_T]ᵀ ω.
        sum.vec_rot += r.cross(&f_b) - w * i_tc_prime;
    }

    fn compute_derivatives(&mut self, _x: &[f64], _hub_accel: &HubAccel, dx: &mut [f64]) {
        // (D1): ṁ_p, constant over the step.
        dx[MASS] = self.mdot_kg_s;
    }

    fn energy_momentum(&self, x: &[f64], omega_bn_b: &Vector3<f64>) -> EnergyMomentum {
        // (D7)
        let m = x[MASS].max(0.0);
        let (i_tc, _) = self.params.inertia.inertia_and_rate(m, 0.0);
        EnergyMomentum::rigid_body(
            m,
            &self.params.r_tcb_b_m,
            &Vector3::zeros(),
            &Matrix3::from_diagonal_element(i_tc),
            omega_bn_b,
            omega_bn_b,
        )
    }

    fn propellant_kg(&self, x: &[f64]) -> Option<f64> {
        Some(self.held_kg(x[MASS]))
    }

    fn set_propellant_outflow(&mut self, outflow_kg_s: f64) {
        // (D1): dm_p/dt = −Σ s F̄/(I_sp g₀).
        self.mdot_kg_s = -outflow_kg_s;
    }

    /// The mass flow set for the step under way (the propellant itself is an integrated
    /// state; the radius is memoised from it).
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        let Self {
            params: _,
            empty_below_kg: _,
            mdot_kg_s,
            radius_sq_at: _,
        } = self;
        a.put(mdot_kg_s);
    }
}
