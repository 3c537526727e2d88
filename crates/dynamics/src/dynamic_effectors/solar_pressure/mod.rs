//! Solar radiation pressure and its torque from the flat-plate model of the vehicle's surfaces.
//!
//! At each RK4 stage the direction to the Sun in B is \[BN\] r_Sun/B (the held
//! [`EnvironmentSample`]'s Sun position relative to B), and the pressure is
//! P = (Φ/c) (1 AU / |r_Sun/B|)² ν ([`flexdyn_environment::facets::solar_pressure_n_m2`]), with
//! ν the sample's shadow factor (0 in umbra, the visible fraction of the disc in penumbra). The
//! facet forces F = −P A cos θ [(ρa + ρd) ŝ + (2 ρs cos θ + ⅔ ρd) n̂] (Montenbruck & Gill,
//! *Satellite Orbits*, §3.4.1, with Lambert's law for the diffuse part) are summed at B with
//! their moments about B.
//!
//! **Modelled and neglected.** One facet shadowing another and multiple reflections (exact for a
//! convex body); the Earth's albedo and infrared; the Sun's direction changing within an
//! environment update (the sample is held: 10⁻⁷ rad per second of orbit motion at 1 AU). No Sun
//! configured (a zero vector) gives no force.

use nalgebra::Vector3;

use crate::dynamic_effector::{DynamicEffector, EnvironmentSource, StageState};
use crate::params::Wrench;
use flexdyn_environment::facets::{solar_pressure_n_m2, FacetModel};
use flexdyn_environment::EnvironmentSample;

/// Solar radiation pressure on the configured facets.
#[derive(Debug, Clone)]
pub struct SolarPressure {
    /// The vehicle's surfaces.
    pub facets: FacetModel,
    /// \[W/m²\] total solar irradiance at 1 AU (nominally
    /// [`flexdyn_environment::facets::SOLAR_IRRADIANCE_1AU_W_M2`]).
    pub irradiance_1au_w_m2: f64,
    /// What the held sample gives at every stage until the next environment update, computed
    /// at the first stage that sees it: the stages then only rotate the unit vector.
    held: HeldSun,
}

/// The solar-pressure inputs of one held [`EnvironmentSample`] (shared with the cannonball,
/// [`super::cannonball_srp`]).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct HeldSun {
    /// \[m\] the sample's r_Sun/B (N components) these were computed from.
    r_sun_b_n_m: Vector3<f64>,
    /// \[-\] the sample's shadow factor they were computed with.
    shadow_factor: f64,
    /// \[W/m²\] the irradiance at 1 AU they were computed with.
    irradiance_1au_w_m2: f64,
    /// \[-\] r̂_Sun/B, N components (zero when the sample has no Sun).
    pub(crate) sun_hat_n: Vector3<f64>,
    /// \[N/m²\] the radiation pressure P (zero in umbra or without a Sun).
    pub(crate) pressure_n_m2: f64,
}

impl SolarPressure {
    /// The effector on `facets` at the irradiance `irradiance_1au_w_m2` \[W/m²\] at 1 AU.
    pub fn new(facets: FacetModel, irradiance_1au_w_m2: f64) -> Self {
        SolarPressure {
            facets,
            irradiance_1au_w_m2,
            held: HeldSun::default(),
        }
    }

    /// The held Sun direction and pressure for `env` ([`HeldSun::refresh`]).
    #[inline]
    fn held_for(&mut self, env: &EnvironmentSample) -> &HeldSun {
        self.held.refresh(env, self.irradiance_1au_w_m2)
    }
}

impl HeldSun {
    /// These inputs for `env` at the irradiance `irradiance_1au_w_m2`, recomputed only when its
    /// Sun or its shadow factor (an environment update) or the irradiance changed: the norm and
    /// the division by it are per update, not per stage.
    #[inline]
    pub(crate) fn refresh(&mut self, env: &EnvironmentSample, irradiance_1au_w_m2: f64) -> &Self {
        if env.r_sun_b_n_m != self.r_sun_b_n_m
            || env.shadow_factor != self.shadow_factor
            || irradiance_1au_w_m2 != self.irradiance_1au_w_m2
        {
            let distance_m = env.r_sun_b_n_m.norm();
            let lit = distance_m > 0.0 && env.shadow_factor != 0.0;
            *self = HeldSun {
                r_sun_b_n_m: env.r_sun_b_n_m,
                shadow_factor: env.shadow_factor,
                irradiance_1au_w_m2,
                sun_hat_n: if lit {
                    env.r_sun_b_n_m / distance_m
                } else {
                    Vector3::zeros()
                },
                pressure_n_m2: if lit {
                    solar_pressure_n_m2(distance_m, env.shadow_factor, irradiance_1au_w_m2)
                } else {
                    0.0
                },
            };
        }
        self
    }
}

impl DynamicEffector for SolarPressure {
    fn name(&self) -> &str {
        "solar_pressure"
    }

    fn environment_source(&self) -> Option<EnvironmentSource> {
        Some(EnvironmentSource::SolarPressure)
    }

    fn add_force_torque(&mut self, stage: &StageState, env: &EnvironmentSample, sum: &mut Wrench) {
        let held = *self.held_for(env);
        if held.pressure_n_m2 == 0.0 {
            return;
        }
        // [BN] is orthonormal: the rotated unit vector is a unit vector (to round-off).
        let sun_hat_b = stage.dcm_bn * held.sun_hat_n;
        let w = self
            .facets
            .srp_wrench_unit_b(&sun_hat_b, held.pressure_n_m2);
        sum.force_b_newton += w.force_b_newton;
        sum.torque_b_nm += w.torque_b_nm;
    }

    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        self.facets.parameters(out);
        out.push((
            "environment.solar_irradiance_1au_w_m2".into(),
            self.irradiance_1au_w_m2,
        ));
    }

    /// Nothing: its parameters are configuration (a held Sun is memoised from its inputs).
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
}
