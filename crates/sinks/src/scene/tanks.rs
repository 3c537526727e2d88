//! The propellant tanks (`[[propellant_tanks]]`) in the 3D scene: each tank a translucent
//! sphere at its propellant's centroid (in the static scene), and the propellant left in it a
//! solid sphere inside, resized with every StateMsg (in the per-state actuator scene, beside the
//! plumes of the thrusters that burn it).
//!
//! # Sizes (`crates/dynamics/src/effectors/propellant_tank/mod.rs`, (D6))
//! - The tank, R_tank: `constant_volume`'s `radius_m`; for `constant_density`, the sphere of
//!   the initial load m_0 at density ρ, R(m_0) = (3 m_0 / (4π ρ))^(1/3).
//! - The propellant at mass m_p: the sphere holding the fraction f = m_p / m_0 of the tank's
//!   volume, r = R_tank f^(1/3). For `constant_density` this is the model's own sphere
//!   (R(m_p) = R(m_0) (m_p/m_0)^(1/3)); for `constant_volume`, whose propellant spreads through
//!   the whole tank at a falling density, it is the volume the propellant left would fill at
//!   its initial density: the fill level, seen as a volume.
//!
//! m_p is the tank's one state in its StateMsg entry (`effector_kind::PROPELLANT_TANK` in the
//! wire table, `proto/schema/messages.toml`); a tank flagged EMPTY (or with f = 0) has an empty
//! entity, which clears its propellant sphere.

use nalgebra::Vector3;
use serde_json::Value;

use super::sphere_entity;
use flexdyn_dynamics::effectors::propellant_tank::{
    PropellantTankParams, TankInertiaModel, EMPTY, MASS,
};
use flexdyn_proto::EffectorState;

/// The tank's shell: light grey, mostly transparent, so the propellant shows through it.
const SHELL_RGBA: [f64; 4] = [0.8, 0.8, 0.85, 0.25];
/// The propellant: the orange of hydrazine's warning labels, nearly opaque.
const PROPELLANT_RGBA: [f64; 4] = [0.95, 0.5, 0.1, 0.9];

/// One tank's fixed geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct TankGeometry {
    /// \[m\] the propellant's centroid relative to B, B components (the spheres' centre).
    pub r_tcb_b_m: Vector3<f64>,
    /// \[kg\] the initial load m_0.
    pub full_kg: f64,
    /// \[m\] R_tank (module docs).
    pub radius_m: f64,
}

impl TankGeometry {
    /// The geometry of a configured tank.
    pub fn new(p: &PropellantTankParams) -> Self {
        let radius_m = match p.inertia {
            TankInertiaModel::ConstantVolume { radius_m } => radius_m,
            TankInertiaModel::ConstantDensity { .. } => {
                p.inertia.radius_sq_m2(p.propellant_mass_kg).sqrt()
            }
        };
        Self {
            r_tcb_b_m: p.r_tcb_b_m,
            full_kg: p.propellant_mass_kg,
            radius_m,
        }
    }

    /// \[m\] the radius of the propellant sphere for the tank's StateMsg `entry`: R_tank f^(1/3),
    /// f = m_p / m_0 clamped to [0, 1]; 0 when the entry is flagged EMPTY, holds no mass, or the
    /// tank was loaded empty.
    pub fn propellant_radius_m(&self, entry: &EffectorState) -> f64 {
        let m_p = entry.states.get(MASS).copied().unwrap_or(0.0);
        if entry.flags & EMPTY != 0 || self.full_kg <= 0.0 || m_p.is_nan() || m_p <= 0.0 {
            return 0.0;
        }
        self.radius_m * (m_p / self.full_kg).min(1.0).cbrt()
    }

    /// The tank's shell entity `<prefix>tank<k>` in B.
    pub fn shell(&self, frame_b: &str, prefix: &str, k: usize, t_ns: u64) -> Value {
        sphere_entity(
            t_ns,
            frame_b,
            &format!("{prefix}tank{k}"),
            &self.r_tcb_b_m,
            2.0 * self.radius_m,
            SHELL_RGBA,
        )
    }

    /// The propellant entity `<prefix>propellant<k>` in B for the tank's StateMsg `entry`.
    pub fn propellant(
        &self,
        frame_b: &str,
        prefix: &str,
        k: usize,
        entry: &EffectorState,
        t_ns: u64,
    ) -> Value {
        sphere_entity(
            t_ns,
            frame_b,
            &format!("{prefix}propellant{k}"),
            &self.r_tcb_b_m,
            2.0 * self.propellant_radius_m(entry),
            PROPELLANT_RGBA,
        )
    }
}
