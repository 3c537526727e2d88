//! Solar radiation pressure and its torque from the flat-plate model of the vehicle's surfaces.
//!
//! At each RK4 stage the direction to the Sun in B is [BN] r_Sun/B (the held
//! [`EnvironmentSample`]'s Sun position relative to B), and the pressure is
//! P = (Φ/c) (1 AU / |r_Sun/B|)² ν ([`crate::environment::facets::solar_pressure_n_m2`]), with
//! ν the sample's shadow factor (0 in umbra, the visible fraction of the disc in penumbra). The
//! facet forces F = −P A cos θ [(ρa + ρd) ŝ + (2 ρs cos θ + ⅔ ρd) n̂] (Montenbruck & Gill,
//! *Satellite Orbits*, §3.4.1, with Lambert's law for the diffuse part) are summed at B with
//! their moments about B.
//!
//! **Modelled and neglected.** One facet shadowing another and multiple reflections (exact for a
//! convex body); the Earth's albedo and infrared; the Sun's direction changing within an
//! environment update (the sample is held: 10⁻⁷ rad per second of orbit motion at 1 AU). No Sun
//! configured (a zero vector) gives no force.

use crate::dynamics::dynamic_effector::{DynamicEffector, EnvironmentSource, StageState};
use crate::dynamics::params::Wrench;
use crate::environment::facets::{solar_pressure_n_m2, FacetModel};
use crate::environment::EnvironmentSample;

/// Solar radiation pressure on the configured facets.
#[derive(Debug, Clone)]
pub struct SolarPressure {
    /// The vehicle's surfaces.
    pub facets: FacetModel,
    /// \[W/m²\] total solar irradiance at 1 AU (nominally
    /// [`crate::environment::facets::SOLAR_IRRADIANCE_1AU_W_M2`]).
    pub irradiance_1au_w_m2: f64,
}

impl DynamicEffector for SolarPressure {
    fn name(&self) -> &str {
        "solar_pressure"
    }

    fn environment_source(&self) -> Option<EnvironmentSource> {
        Some(EnvironmentSource::SolarPressure)
    }

    fn add_force_torque(&mut self, stage: &StageState, env: &EnvironmentSample, sum: &mut Wrench) {
        let distance_m = env.r_sun_b_n_m.norm();
        if distance_m == 0.0 || env.shadow_factor == 0.0 {
            return;
        }
        let pressure_n_m2 =
            solar_pressure_n_m2(distance_m, env.shadow_factor, self.irradiance_1au_w_m2);
        let sun_dir_b = stage.dcm_bn * env.r_sun_b_n_m;
        let w = self.facets.srp_wrench_b(&sun_dir_b, pressure_n_m2);
        sum.force_b_newton += w.force_b_newton;
        sum.torque_b_nm += w.torque_b_nm;
    }

    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        self.facets.parameters(out);
    }
}
