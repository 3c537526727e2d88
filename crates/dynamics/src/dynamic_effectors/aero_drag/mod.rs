//! Aerodynamic drag and its torque from the flat-plate model of the vehicle's surfaces.
//!
//! At each RK4 stage the velocity of the hub point B relative to the local atmosphere is
//! v_rel = v_B/N − v_wind (Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed.,
//! §8.6.2), with the wind from the held [`EnvironmentSample`] (a co-rotating atmosphere's
//! ω⊕ × r, or zero) and the density from the same sample. Rotated into B by the stage's \[BN\], it
//! drives the facet forces F = −½ ρ C_D A |v_rel|² cos θ v̂_rel of
//! [`flexdyn_environment::facets`], summed at B with their moments about B.
//!
//! **Modelled and neglected.**
//! - Every facet sees the velocity of B. The rotation adds ω × r_cp at a facet's centre of
//!   pressure: 0.01 m/s for 1°/s at 0.5 m, 1.3·10⁻⁶ of a 7.6 km/s relative wind, so the
//!   aerodynamic damping torque it would add is neglected.
//! - The facets are those configured, fixed in B. A panel's own facets do not follow its hinge
//!   angle; the force on a panel acts on the vehicle as a whole (see
//!   [`crate::dynamic_effector`], "Where the forces act").
//! - The density and the wind are held between environment updates (the sample's rate).
//!
//! Because the force is applied at B and the torque about B, the power it puts into the vehicle
//! is F·v_B + τ·ω_B/N exactly; `crates/vehicle/tests/surface_forces.rs` checks that the energy lost equals that
//! work.

use crate::dynamic_effector::{DynamicEffector, EnvironmentSource, StageState};
use crate::params::Wrench;
use flexdyn_environment::facets::FacetModel;
use flexdyn_environment::EnvironmentSample;

/// Drag on the configured facets.
#[derive(Debug, Clone)]
pub struct AeroDrag {
    /// The vehicle's surfaces.
    pub facets: FacetModel,
}

impl DynamicEffector for AeroDrag {
    fn name(&self) -> &str {
        "aero_drag"
    }

    fn environment_source(&self) -> Option<EnvironmentSource> {
        Some(EnvironmentSource::Drag)
    }

    fn add_force_torque(&mut self, stage: &StageState, env: &EnvironmentSample, sum: &mut Wrench) {
        if env.density_kg_m3 == 0.0 {
            return;
        }
        let v_rel_b_m_s = stage.dcm_bn * (stage.v_bn_n_m_s - env.wind_n_m_s);
        let w = self.facets.drag_wrench_b(&v_rel_b_m_s, env.density_kg_m3);
        sum.force_b_newton += w.force_b_newton;
        sum.torque_b_nm += w.torque_b_nm;
    }

    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        self.facets.parameters(out);
    }

    /// Nothing: its parameters are configuration (a held Sun is memoised from its inputs).
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
}
