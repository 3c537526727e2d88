//! Earth albedo: sunlight reflected by the Earth onto a flat detector at the spacecraft (the
//! coarse sun sensors read it, `flexdyn_sensors::coarse_sun_sensor`).
//!
//! # Model
//! The Earth is a sphere of radius R (`[environment] shadow_earth_radius_m`, WGS-84 a by
//! default, the same sphere as the shadow's) whose surface is a Lambertian reflector of uniform
//! albedo coefficient a (`albedo_coefficient`, default [`DEFAULT_ALBEDO_COEFFICIENT`]), lit by
//! the Sun as parallel rays along ŝ, the unit vector from the Earth's centre to the Sun, with
//! irradiance S = S₁ (1 au / |r_Sun|)² (S₁ = `solar_irradiance_1au_w_m2`, 1361 W/m² by default;
//! the same 1/r² as solar pressure, [`crate::facets::solar_pressure_n_m2`]). This is the
//! formulation of Bhanderi & Bak, "Modeling Earth Albedo for Satellites in Earth Orbit", AIAA
//! GNC 2005, §II, with one uniform coefficient instead of their TOMS reflectivity grid.
//!
//! A surface element at P with outward normal n̂_P reflects the irradiance S max(0, n̂_P·ŝ) with
//! the radiance of a Lambertian surface (the same in every direction):
//!
//! ```text
//! (A1)  L(P) = a S max(0, n̂_P·ŝ) / π                                  [W/(m² sr)]
//! ```
//!
//! A detector at B with unit normal n̂ receives from the cap of the Earth visible from B
//! (a point P is visible when (r − P)·P ≥ 0, r the position of B from the Earth's centre)
//!
//! ```text
//! (A2)  E(n̂) = ∫_cap L(P) max(0, n̂·û) dΩ,   dΩ = cos θ_e dA / d²
//! ```
//!
//! with û the unit vector from B to P, d = |P − r| and θ_e the emission angle at P, so that
//! (A2) is the element form E = ∫ a S max(0, n̂_P·ŝ) max(0, n̂_P·(−û)) max(0, n̂·û) dA / (π d²).
//! The Earth's own shadow on itself is the max(0, n̂_P·ŝ) term; the spacecraft's shadow factor
//! ν does not enter: albedo is reflected light, which reaches a detector that faces the lit
//! Earth whatever part of the solar disc B itself sees. (For a spherical Earth and a point Sun
//! a spacecraft in the umbra sees no lit ground: every visible P has P·ŝ < 0 there, so the
//! albedo vanishes in umbra by geometry, not by a gate; in penumbra it is the full albedo.)
//!
//! # The grid
//! The cap is cut by the central angle λ (from the sub-spacecraft point, 0 ≤ λ ≤ λ_max with
//! cos λ_max = R / |r|) and the azimuth φ about the nadir, measured from the Sun's side:
//! [`ALBEDO_RINGS`] rings of equal Δλ = λ_max / N_R and [`ALBEDO_AZIMUTHS`] sectors of equal
//! Δφ = 2π / N_A, one element each, evaluated at its midpoint (λ_k = (k + ½) Δλ,
//! φ_j = (j + ½) Δφ). In the local frame ẑ = nadir (−r̂), x̂ the Sun's direction projected on
//! the horizontal plane, ŷ = ẑ × x̂, the element's direction from B and the Sun's cosine at P are
//!
//! ```text
//! (A3)  d = √(r² + R² − 2 r R cos λ),  cos η = (r − R cos λ) / d,  sin η = R sin λ / d
//!       û = cos η ẑ + sin η (cos φ x̂ + sin φ ŷ)
//! (A4)  n̂_P·ŝ = cos λ (r̂·ŝ) + sin λ cos φ |ŝ − (ŝ·r̂) r̂|
//! ```
//!
//! (η the nadir angle of û). A ring's solid angle is exact, from its edges' nadir angles:
//!
//! ```text
//! (A5)  ΔΩ_k = (cos η(kΔλ) − cos η((k + 1)Δλ)) Δφ
//! ```
//!
//! and each element carries the weight (A1 × ΔΩ over S, so dimensionless)
//!
//! ```text
//! (A6)  w_kj = (a / π) max(0, n̂_P(λ_k, φ_j)·ŝ) ΔΩ_k
//! (A7)  E(n̂) / S ≈ Σ_kj w_kj max(0, n̂·û_kj)
//! ```
//!
//! [`AlbedoCap`] holds the frame, the rings' cos η, sin η and the weights: the environment
//! update (on the prefetch worker, off the physics thread) evaluates (A3)–(A6) once per sample;
//! a detector's sum (A7) is [`AlbedoCap::irradiance_fraction`], 2 multiply-adds per element and no
//! allocation. Its error against the closed forms (`crates/environment/tests/albedo.rs`): far
//! from the Earth (|r| = 1000 R) the nadir-facing plate's sum is within 0.1 % of the Lambert
//! sphere's (2/3) a S (R/r)² Φ(α) at full phase, 0.4 % at α = 90°, 1.3 % at 150° (the thin lit
//! crescent); at 500 km altitude, with the Sun at the zenith or 60° from it, within 0.2 % of an
//! independent 1000 × 1000 quadrature of the element form over the Earth's surface on a nadir
//! plate, 0.3 % on a plate tilted 45° and 1.2 % on one tilted 80° (whose horizon cuts the cap
//! between elements).
//!
//! # Neglected
//! The Earth's oblateness and the atmosphere (limb brightening, refraction into the umbra), the
//! reflectivity's variation with latitude, season and cloud cover (the TOMS data of Bhanderi &
//! Bak; a coefficient of 0.3 is the global mean Bond albedo), non-Lambertian (specular ocean)
//! reflection, the Sun's finite size at the terminator and its parallax across the Earth
//! (R / 1 au = 4e-5 rad).

pub mod part;
pub mod schema;

use nalgebra::Vector3;

use crate::ephemeris::AU_M;

/// Rings of the cap's grid, N_R (module docs, (A3)).
pub const ALBEDO_RINGS: usize = 8;
/// Sectors of the cap's grid, N_A; the azimuth table [`AZIMUTH_COS_SIN`] is written for 16.
pub const ALBEDO_AZIMUTHS: usize = 16;
/// Elements of the cap's grid, N_R × N_A.
pub const ALBEDO_ELEMENTS: usize = ALBEDO_RINGS * ALBEDO_AZIMUTHS;
/// \[-\] the default albedo coefficient when albedo is on: the Earth's global mean Bond
/// albedo is about 0.3.
pub const DEFAULT_ALBEDO_COEFFICIENT: f64 = 0.3;

// cos((2m + 1)π/16) for m = 0..3, to 20 digits (sin of the same angles are these in reverse).
const C1: f64 = 0.980_785_280_403_230_4;
const C3: f64 = 0.831_469_612_302_545_2;
const C5: f64 = 0.555_570_233_019_602_2;
const C7: f64 = 0.195_090_322_016_128_27;

/// (cos φ_j, sin φ_j) at the sectors' midpoints φ_j = (2j + 1)π/16 (module docs), written out so
/// that no trigonometry runs per sample; `tests::azimuth_table_is_the_midpoints` checks it.
pub const AZIMUTH_COS_SIN: [(f64, f64); ALBEDO_AZIMUTHS] = [
    (C1, C7),
    (C3, C5),
    (C5, C3),
    (C7, C1),
    (-C7, C1),
    (-C5, C3),
    (-C3, C5),
    (-C1, C7),
    (-C1, -C7),
    (-C3, -C5),
    (-C5, -C3),
    (-C7, -C1),
    (C7, -C1),
    (C5, -C3),
    (C3, -C5),
    (C1, -C7),
];

/// The albedo model's parameters (`[environment] albedo = true` and its keys).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Albedo {
    /// \[-\] the albedo coefficient a, in \[0, 1\].
    pub coefficient: f64,
    /// \[m\] the Earth's radius R (a sphere).
    pub earth_radius_m: f64,
    /// \[W/m²\] total solar irradiance at 1 au, S₁.
    pub irradiance_1au_w_m2: f64,
}

/// The Earth's cap visible from B, discretised (module docs, (A3)–(A6)): what a detector needs
/// to sum its albedo irradiance (A7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlbedoCap {
    /// \[-\] ẑ: the unit nadir from B (toward the Earth's centre), N components.
    pub nadir_n: Vector3<f64>,
    /// \[-\] x̂: the unit horizontal vector toward the Sun's side, N components.
    pub x_n: Vector3<f64>,
    /// \[-\] ŷ = ẑ × x̂, N components.
    pub y_n: Vector3<f64>,
    /// \[-\] cos η_k of each ring's midpoint (A3).
    pub cos_eta: [f64; ALBEDO_RINGS],
    /// \[-\] sin η_k of each ring's midpoint (A3).
    pub sin_eta: [f64; ALBEDO_RINGS],
    /// \[-\] w_kj (A6) at index k·N_A + j: irradiance per unit solar irradiance.
    pub weight: [f64; ALBEDO_ELEMENTS],
    /// \[W/m²\] S, the solar irradiance at the Earth.
    pub solar_irradiance_w_m2: f64,
}

impl AlbedoCap {
    /// The number of f64 words of a cap (the prefetch slot's layout).
    pub const WORDS: usize = 9 + 2 * ALBEDO_RINGS + ALBEDO_ELEMENTS + 1;

    /// \[-\] E(n̂)/S (A7) on a detector with unit normal `n_n` (N components) that sees the
    /// directions û with n̂·û ≥ `cos_min` (its field of view; 0 for a full hemisphere).
    /// Allocation-free, no branch on anything but the elements' cosines.
    pub fn irradiance_fraction(&self, n_n: &Vector3<f64>, cos_min: f64) -> f64 {
        let nz = n_n.dot(&self.nadir_n);
        let nx = n_n.dot(&self.x_n);
        let ny = n_n.dot(&self.y_n);
        // The horizontal part of n̂·û per sector, cos φ_j n_x + sin φ_j n_y (A3).
        let mut horizontal = [0.0; ALBEDO_AZIMUTHS];
        for (h, (c, s)) in horizontal.iter_mut().zip(AZIMUTH_COS_SIN) {
            *h = c * nx + s * ny;
        }
        let mut sum = 0.0;
        for (k, weights) in self.weight.chunks_exact(ALBEDO_AZIMUTHS).enumerate() {
            let vertical = self.cos_eta[k] * nz;
            let sin_eta = self.sin_eta[k];
            for (w, h) in weights.iter().zip(&horizontal) {
                let cos = vertical + sin_eta * h;
                if cos > 0.0 && cos >= cos_min {
                    sum += w * cos;
                }
            }
        }
        sum
    }

    /// \[W/m²\] the albedo irradiance on a plate facing the nadir with a full hemisphere of
    /// view, S × (A7) with n̂ = ẑ: every element is in front of it (n̂·û = cos η > 0).
    pub fn nadir_irradiance_w_m2(&self) -> f64 {
        let mut sum = 0.0;
        for (k, weights) in self.weight.chunks_exact(ALBEDO_AZIMUTHS).enumerate() {
            sum += self.cos_eta[k] * weights.iter().sum::<f64>();
        }
        self.solar_irradiance_w_m2 * sum
    }

    /// The cap as f64 words, in field order (the prefetch slot).
    pub fn to_words(&self, out: &mut [f64; Self::WORDS]) {
        let vectors = [self.nadir_n, self.x_n, self.y_n];
        let parts = vectors
            .iter()
            .flat_map(|v| v.iter().copied())
            .chain(self.cos_eta)
            .chain(self.sin_eta)
            .chain(self.weight)
            .chain([self.solar_irradiance_w_m2]);
        for (o, v) in out.iter_mut().zip(parts) {
            *o = v;
        }
    }

    /// The cap of [`Self::to_words`]'s words.
    pub fn from_words(w: &[f64; Self::WORDS]) -> Self {
        let v = |i: usize| Vector3::new(w[i], w[i + 1], w[i + 2]);
        let rings = 9 + ALBEDO_RINGS;
        let elements = rings + ALBEDO_RINGS;
        Self {
            nadir_n: v(0),
            x_n: v(3),
            y_n: v(6),
            cos_eta: std::array::from_fn(|k| w[9 + k]),
            sin_eta: std::array::from_fn(|k| w[rings + k]),
            weight: std::array::from_fn(|i| w[elements + i]),
            solar_irradiance_w_m2: w[elements + ALBEDO_ELEMENTS],
        }
    }
}

impl Albedo {
    /// The visible cap seen from B at `r_bn_n_m` (geocentric, N) with the Sun at `r_sun_n_m`
    /// (geocentric, N): (A3)–(A6). `None` when B is not above the sphere or the Sun's position
    /// is zero or not finite. Allocation-free, no panic.
    pub fn cap(&self, r_bn_n_m: &Vector3<f64>, r_sun_n_m: &Vector3<f64>) -> Option<AlbedoCap> {
        let r = r_bn_n_m.norm();
        let sun_distance_m = r_sun_n_m.norm();
        let earth_r = self.earth_radius_m;
        if !(r > earth_r && sun_distance_m > 0.0 && sun_distance_m.is_finite()) {
            return None;
        }
        let up = r_bn_n_m / r;
        let sun = r_sun_n_m / sun_distance_m;
        let s_up = sun.dot(&up);
        let s_horizontal = sun - s_up * up;
        let s_perp = s_horizontal.norm();
        // x̂: the Sun's side; with the Sun at the zenith or nadir any horizontal axis does
        // (A4 then has no φ term): the N axis least aligned with r̂, made horizontal.
        let x_n = if s_perp > 1e-12 {
            s_horizontal / s_perp
        } else {
            let a = up.abs();
            let axis = if a.x <= a.y && a.x <= a.z {
                Vector3::x()
            } else if a.y <= a.z {
                Vector3::y()
            } else {
                Vector3::z()
            };
            (axis - axis.dot(&up) * up).normalize()
        };
        let nadir_n = -up;
        let y_n = nadir_n.cross(&x_n);
        let cos_lambda_max = earth_r / r;
        let d_lambda = cos_lambda_max.acos() / ALBEDO_RINGS as f64;
        let d_phi = std::f64::consts::TAU / ALBEDO_AZIMUTHS as f64;
        // (A3): cos η and sin η of the direction to the point at central angle λ.
        let nadir_angle = |lambda: f64| {
            let (sin_l, cos_l) = lambda.sin_cos();
            let d = (r * r + earth_r * earth_r - 2.0 * r * earth_r * cos_l).sqrt();
            ((r - earth_r * cos_l) / d, earth_r * sin_l / d)
        };
        let au_over_d = AU_M / sun_distance_m;
        let mut cap = AlbedoCap {
            nadir_n,
            x_n,
            y_n,
            cos_eta: [0.0; ALBEDO_RINGS],
            sin_eta: [0.0; ALBEDO_RINGS],
            weight: [0.0; ALBEDO_ELEMENTS],
            solar_irradiance_w_m2: self.irradiance_1au_w_m2 * au_over_d * au_over_d,
        };
        let scale = self.coefficient / std::f64::consts::PI;
        let mut cos_eta_inner = 1.0;
        for k in 0..ALBEDO_RINGS {
            let lambda = (k as f64 + 0.5) * d_lambda;
            (cap.cos_eta[k], cap.sin_eta[k]) = nadir_angle(lambda);
            let cos_eta_outer = nadir_angle((k + 1) as f64 * d_lambda).0;
            // (A5)
            let solid_angle_sr = (cos_eta_inner - cos_eta_outer) * d_phi;
            cos_eta_inner = cos_eta_outer;
            let (sin_l, cos_l) = lambda.sin_cos();
            let weights = &mut cap.weight[k * ALBEDO_AZIMUTHS..(k + 1) * ALBEDO_AZIMUTHS];
            for (w, (cos_phi, _)) in weights.iter_mut().zip(AZIMUTH_COS_SIN) {
                // (A4), (A6)
                let cos_sun = cos_l * s_up + sin_l * cos_phi * s_perp;
                *w = scale * cos_sun.max(0.0) * solid_angle_sr;
            }
        }
        Some(cap)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn azimuth_table_is_the_midpoints() {
        for (j, (c, s)) in AZIMUTH_COS_SIN.iter().enumerate() {
            let phi = (2 * j + 1) as f64 * std::f64::consts::PI / 16.0;
            assert!((c - phi.cos()).abs() < 1e-15, "cos φ_{j}");
            assert!((s - phi.sin()).abs() < 1e-15, "sin φ_{j}");
        }
    }

    #[test]
    fn words_round_trip() {
        let albedo = Albedo {
            coefficient: 0.3,
            earth_radius_m: 6_378_137.0,
            irradiance_1au_w_m2: 1361.0,
        };
        let cap = albedo
            .cap(
                &Vector3::new(7.0e6, 1.0e5, -2.0e5),
                &Vector3::new(1.0e11, 5.0e10, 2.0e10),
            )
            .expect("above the sphere");
        let mut w = [0.0; AlbedoCap::WORDS];
        cap.to_words(&mut w);
        assert_eq!(AlbedoCap::from_words(&w), cap);
    }

    #[test]
    fn no_cap_inside_the_sphere_or_without_a_sun() {
        let albedo = Albedo {
            coefficient: 0.3,
            earth_radius_m: 6_378_137.0,
            irradiance_1au_w_m2: 1361.0,
        };
        let sun = Vector3::new(AU_M, 0.0, 0.0);
        assert!(albedo.cap(&Vector3::new(6.0e6, 0.0, 0.0), &sun).is_none());
        assert!(albedo
            .cap(&Vector3::new(7.0e6, 0.0, 0.0), &Vector3::zeros())
            .is_none());
    }
}
