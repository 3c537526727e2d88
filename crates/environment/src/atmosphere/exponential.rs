//! The piecewise exponential atmosphere of Vallado, *Fundamentals of Astrodynamics and
//! Applications*, 4th ed. (2013), §8.6.2, Table 8-4: ρ(h) = ρ0 exp(−(h − h0)/H) with the band
//! (h0, ρ0, H) whose base is the highest one at or below h (Vallado takes the values from the
//! U.S. Standard Atmosphere 1976 and CIRA-72). The scale heights make the bands
//! meet to 1e-4 (1.4e-3 at 25 km), which `crates/environment/tests/atmosphere.rs` checks as the
//! transcription's invariant.
//!
//! It has no time, solar or geomagnetic dependence: a mean, not a forecast (the true density at
//! 400 km varies by a factor of about 10 over a solar cycle; use [`super::nrlmsise`] for that).

/// One band of the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExponentialBand {
    /// \[m\] base altitude h0 of the band.
    pub base_altitude_m: f64,
    /// [kg/m³] nominal density ρ0 at the base.
    pub density_kg_m3: f64,
    /// \[m\] scale height H.
    pub scale_height_m: f64,
}

impl ExponentialBand {
    /// [kg/m³] ρ0 exp(−(h − h0)/H) at `altitude_m` \[m\]. Allocation-free and panic-free.
    pub fn density_at_kg_m3(&self, altitude_m: f64) -> f64 {
        self.density_kg_m3 * (-(altitude_m - self.base_altitude_m) / self.scale_height_m).exp()
    }
}

const fn band(base_km: f64, density_kg_m3: f64, scale_height_km: f64) -> ExponentialBand {
    ExponentialBand {
        base_altitude_m: base_km * 1e3,
        density_kg_m3,
        scale_height_m: scale_height_km * 1e3,
    }
}

/// Vallado (2013) Table 8-4: base altitude \[km\], nominal density [kg/m³], scale height \[km\].
#[rustfmt::skip]
pub const VALLADO_TABLE_8_4: [ExponentialBand; 28] = [
    band(0.0, 1.225, 7.249),
    band(25.0, 3.899e-2, 6.349),
    band(30.0, 1.774e-2, 6.682),
    band(40.0, 3.972e-3, 7.554),
    band(50.0, 1.057e-3, 8.382),
    band(60.0, 3.206e-4, 7.714),
    band(70.0, 8.770e-5, 6.549),
    band(80.0, 1.905e-5, 5.799),
    band(90.0, 3.396e-6, 5.382),
    band(100.0, 5.297e-7, 5.877),
    band(110.0, 9.661e-8, 7.263),
    band(120.0, 2.438e-8, 9.473),
    band(130.0, 8.484e-9, 12.636),
    band(140.0, 3.845e-9, 16.149),
    band(150.0, 2.070e-9, 22.523),
    band(180.0, 5.464e-10, 29.740),
    band(200.0, 2.789e-10, 37.105),
    band(250.0, 7.248e-11, 45.546),
    band(300.0, 2.418e-11, 53.628),
    band(350.0, 9.518e-12, 53.298),
    band(400.0, 3.725e-12, 58.515),
    band(450.0, 1.585e-12, 60.828),
    band(500.0, 6.967e-13, 63.822),
    band(600.0, 1.454e-13, 71.835),
    band(700.0, 3.614e-14, 88.667),
    band(800.0, 1.170e-14, 124.64),
    band(900.0, 5.245e-15, 181.05),
    band(1000.0, 3.019e-15, 268.00),
];

/// [kg/m³] the density at `altitude_m` \[m\] above the ellipsoid (use the geodetic height). Below
/// 0 m the first band is extended downward and above 1000 km the last band upward, as the table
/// gives no more. Allocation-free and panic-free (a NaN altitude gives NaN).
pub fn exponential_density_kg_m3(altitude_m: f64) -> f64 {
    let i = VALLADO_TABLE_8_4
        .partition_point(|b| b.base_altitude_m <= altitude_m)
        .saturating_sub(1);
    VALLADO_TABLE_8_4[i].density_at_kg_m3(altitude_m)
}

/// What "altitude" means for the exponential atmosphere (`environment.exponential_altitude`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AltitudeDefinition {
    /// The height above the WGS-84 ellipsoid ([`crate::geodetic`]): the default, and what
    /// Vallado's table is tabulated against.
    Geodetic,
    /// |r| − R over a sphere of radius R (the definition of simpler tools, e.g. a spherical
    /// planet of equatorial radius). Needs no Earth orientation.
    Spherical {
        /// \[m\] the sphere's radius R.
        radius_m: f64,
    },
}

/// The exponential atmosphere as configured: Vallado's bands or one given band, over the
/// chosen altitude.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExponentialAtmosphere {
    /// One band ρ = ρ0 exp(−(h − h0)/H) for every altitude (`exponential_base_altitude_m`,
    /// `exponential_base_density_kg_m3`, `exponential_scale_height_m`), or `None`: the bands of
    /// [`VALLADO_TABLE_8_4`].
    pub band: Option<ExponentialBand>,
    /// The altitude h the density is a function of.
    pub altitude: AltitudeDefinition,
}

impl ExponentialAtmosphere {
    /// Vallado's bands on the geodetic height (the model without options).
    pub const VALLADO: Self = Self {
        band: None,
        altitude: AltitudeDefinition::Geodetic,
    };

    /// [kg/m³] the density at altitude `altitude_m` \[m\] (already in this model's
    /// definition). Allocation-free and panic-free.
    pub fn density_at_altitude_kg_m3(&self, altitude_m: f64) -> f64 {
        match &self.band {
            None => exponential_density_kg_m3(altitude_m),
            Some(b) => b.density_at_kg_m3(altitude_m),
        }
    }

    /// Checks a given band (`None` is always valid); the error names the key.
    pub fn validate(&self) -> Result<(), super::AtmosphereError> {
        let invalid = |field, value, expected| super::AtmosphereError::Invalid {
            field,
            value,
            expected,
        };
        if let Some(b) = &self.band {
            if !(b.density_kg_m3 > 0.0 && b.density_kg_m3 <= 100.0) {
                return Err(invalid(
                    "exponential_base_density_kg_m3",
                    b.density_kg_m3,
                    "a density > 0 and <= 100 kg/m³ (sea level is 1.225)",
                ));
            }
            if !(b.scale_height_m >= 1.0 && b.scale_height_m <= 1e7) {
                return Err(invalid(
                    "exponential_scale_height_m",
                    b.scale_height_m,
                    "a scale height from 1 m to 1e7 m (the Earth's is 6–300 km)",
                ));
            }
            if b.base_altitude_m.is_nan() || b.base_altitude_m.abs() > 1e8 {
                return Err(invalid(
                    "exponential_base_altitude_m",
                    b.base_altitude_m,
                    "an altitude within ±1e8 m",
                ));
            }
        }
        if let AltitudeDefinition::Spherical { radius_m } = self.altitude {
            if !(radius_m > 0.0 && radius_m <= 1e8) {
                return Err(invalid(
                    "exponential_radius_m",
                    radius_m,
                    "a radius > 0 and <= 1e8 m (the Earth's equatorial radius is 6378137 m)",
                ));
            }
        }
        Ok(())
    }
}
