//! Solar radiation pressure on a cannonball ([`flexdyn_environment::cannonball`]): the force
//! −P C_R A ŝ, with P = (Φ/c) (1 AU / |r_Sun/B|)² ν from the held [`EnvironmentSample`]'s Sun
//! position relative to B and shadow factor ν, applied at the configured centre of pressure.
//!
//! It fills the same wrench slot as the flat-plate model ([`EnvironmentSource::SolarPressure`]):
//! a configuration has one solar-pressure model or the other. No Sun configured (a zero vector)
//! or the umbra gives no force.

use super::solar_pressure::HeldSun;
use crate::dynamic_effector::{DynamicEffector, EnvironmentSource, StageState};
use crate::params::Wrench;
use flexdyn_environment::cannonball::Cannonball;
use flexdyn_environment::EnvironmentSample;

/// Cannonball solar radiation pressure.
#[derive(Debug, Clone)]
pub struct CannonballSrp {
    /// The sphere's parameters.
    pub ball: Cannonball,
    /// \[W/m²\] total solar irradiance at 1 AU.
    pub irradiance_1au_w_m2: f64,
    /// The held Sun direction and pressure, per environment update (as the facet model's).
    held: HeldSun,
}

impl CannonballSrp {
    /// The effector on `ball` at the irradiance `irradiance_1au_w_m2` \[W/m²\] at 1 AU.
    pub fn new(ball: Cannonball, irradiance_1au_w_m2: f64) -> Self {
        Self {
            ball,
            irradiance_1au_w_m2,
            held: HeldSun::default(),
        }
    }
}

impl DynamicEffector for CannonballSrp {
    fn name(&self) -> &str {
        "solar_pressure"
    }

    fn environment_source(&self) -> Option<EnvironmentSource> {
        Some(EnvironmentSource::SolarPressure)
    }

    fn add_force_torque(&mut self, stage: &StageState, env: &EnvironmentSample, sum: &mut Wrench) {
        let held = *self.held.refresh(env, self.irradiance_1au_w_m2);
        if held.pressure_n_m2 == 0.0 {
            return;
        }
        let sun_hat_b = stage.dcm_bn * held.sun_hat_n;
        let w = self.ball.wrench_unit_b(&sun_hat_b, held.pressure_n_m2);
        sum.force_b_newton += w.force_b_newton;
        sum.torque_b_nm += w.torque_b_nm;
    }

    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        out.push(("environment.cannonball_area_m2".into(), self.ball.area_m2));
        out.push((
            "environment.cannonball_reflectivity_coefficient".into(),
            self.ball.reflectivity_coefficient,
        ));
        out.push((
            "environment.solar_irradiance_1au_w_m2".into(),
            self.irradiance_1au_w_m2,
        ));
    }

    /// Nothing: its parameters are configuration (a held Sun is memoised from its inputs).
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
}
