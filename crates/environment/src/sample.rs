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
    /// sensors read until the next update).
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        // Named field by field: a new field does not compile until it is listed here.
        let Self {
            t_sim_ns,
            b_field_n_t,
            r_sun_b_n_m,
            r_moon_b_n_m,
            shadow_factor,
            density_kg_m3,
            wind_n_m_s,
            albedo,
        } = self;
        a.section("environment sample", |a| {
            a.put(t_sim_ns);
            a.put(b_field_n_t);
            a.put(r_sun_b_n_m);
            a.put(r_moon_b_n_m);
            a.put(shadow_factor);
            a.put(density_kg_m3);
            a.put(wind_n_m_s);
            let mut has_albedo = albedo.is_some();
            a.put(&mut has_albedo);
            if has_albedo {
                let cap = albedo.get_or_insert(AlbedoCap {
                    nadir_n: Vector3::zeros(),
                    x_n: Vector3::zeros(),
                    y_n: Vector3::zeros(),
                    cos_eta: [0.0; crate::albedo::ALBEDO_RINGS],
                    sin_eta: [0.0; crate::albedo::ALBEDO_RINGS],
                    weight: [0.0; crate::albedo::ALBEDO_ELEMENTS],
                    solar_irradiance_w_m2: 0.0,
                });
                // Named field by field, as above.
                let AlbedoCap {
                    nadir_n,
                    x_n,
                    y_n,
                    cos_eta,
                    sin_eta,
                    weight,
                    solar_irradiance_w_m2,
                } = cap;
                a.put(nadir_n);
                a.put(x_n);
                a.put(y_n);
                a.put(cos_eta);
                a.put(sin_eta);
                a.put(weight);
                a.put(solar_irradiance_w_m2);
            } else {
                *albedo = None;
            }
        });
    }
}
