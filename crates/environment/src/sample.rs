//! One sample of the environment: what the dynamic effectors and the sensors read of the world.
//!
//! A sample is filled by the environment models at their update rate (slow fields such as the
//! magnetic field, the ephemerides and the density) and held between updates; the dynamic
//! effectors combine it with the hub state of each RK4 stage (attitude, position, velocity).
//! A quantity whose model is off keeps its neutral value ([`EnvironmentSample::NONE`]): no field,
//! no Sun (a zero vector), full sunlight, vacuum, no wind, no albedo. That way an effector never has to ask
//! whether a model exists: a magnetic torque in a zero field is zero.

use nalgebra::Vector3;

use crate::albedo::AlbedoCap;

/// The environment at one instant, in the inertial frame N unless a name says otherwise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvironmentSample {
    /// \[ns\] simulation time of the sample (since the epoch).
    pub t_sim_ns: u64,
    /// \[T\] the planet's magnetic field at the spacecraft, N components (zero when off).
    pub b_field_n_t: Vector3<f64>,
    /// \[m\] the Sun's position relative to the spacecraft's hub point B, N components (zero
    /// when no ephemeris is configured).
    pub r_sun_b_n_m: Vector3<f64>,
    /// \[m\] the Moon's position relative to B, N components (zero when off).
    pub r_moon_b_n_m: Vector3<f64>,
    /// \[-\] fraction of the solar disc visible from the spacecraft: 1 in full sunlight, 0 in
    /// umbra, in between in penumbra.
    pub shadow_factor: f64,
    /// \[kg/m³\] atmospheric mass density at the spacecraft (0 in vacuum).
    pub density_kg_m3: f64,
    /// \[m/s\] velocity of the local atmosphere relative to N, N components (e.g. a co-rotating
    /// atmosphere's ω_E × r).
    pub wind_n_m_s: Vector3<f64>,
    /// The Earth's visible cap discretised for albedo ([`crate::albedo`]); `None` when albedo is
    /// off (or B is not above the Earth).
    pub albedo: Option<AlbedoCap>,
}

impl EnvironmentSample {
    /// No environment: no field, no Sun or Moon, full sunlight, vacuum, no wind, no albedo.
    pub const NONE: EnvironmentSample = EnvironmentSample {
        t_sim_ns: 0,
        b_field_n_t: Vector3::new(0.0, 0.0, 0.0),
        r_sun_b_n_m: Vector3::new(0.0, 0.0, 0.0),
        r_moon_b_n_m: Vector3::new(0.0, 0.0, 0.0),
        shadow_factor: 1.0,
        density_kg_m3: 0.0,
        wind_n_m_s: Vector3::new(0.0, 0.0, 0.0),
        albedo: None,
    };
}

impl Default for EnvironmentSample {
    fn default() -> Self {
        Self::NONE
    }
}

impl flexdyn_kernel::archive::Archived for EnvironmentSample {
    /// Every field, for a checkpoint (a held sample is state: it is what the effectors and the
    /// sensors read until the next update): the time, then each registered model's fields in
    /// registry order (`crate::lib`; [`crate::model::part::EnvironmentPart::archive`]).
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        a.section("environment sample", |a| {
            a.put(&mut self.t_sim_ns);
            crate::archive_models(self, a);
        });
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::EnvironmentSample;
    use crate::albedo::Albedo;

    /// A sample whose every field differs from [`EnvironmentSample::NONE`].
    fn full() -> EnvironmentSample {
        let albedo = Albedo {
            coefficient: 0.3,
            earth_radius_m: 6.378e6,
            irradiance_1au_w_m2: 1361.0,
        };
        let r = Vector3::new(7.0e6, 1.0, 2.0);
        // Named field by field: a new field does not compile until it is given here, and the
        // round trips below then fail until a registered model carries it.
        EnvironmentSample {
            t_sim_ns: 123,
            b_field_n_t: Vector3::new(1e-5, -2e-5, 3e-5),
            r_sun_b_n_m: Vector3::new(1.5e11, 2.0e10, -3.0),
            r_moon_b_n_m: Vector3::new(3.8e8, -1.0, 2.0),
            shadow_factor: 0.25,
            density_kg_m3: 1e-12,
            wind_n_m_s: Vector3::new(-10.0, 500.0, 0.5),
            albedo: albedo.cap(&r, &Vector3::new(1.5e11, 2.0e10, 0.0)),
        }
    }

    #[test]
    fn every_field_travels_through_the_prefetch_words() {
        for s in [full(), EnvironmentSample::NONE] {
            let mut w = [0u64; crate::SAMPLE_WORDS];
            let n = crate::sample_to_words(&s, &mut w);
            assert!(n <= crate::SAMPLE_WORDS);
            assert_eq!(crate::sample_from_words(&w[..n]), s);
        }
        assert!(full().albedo.is_some());
    }
}
