//! The flat-plate (facet) model of the vehicle's surfaces: aerodynamic drag and solar radiation
//! pressure (SRP) as forces and torques about point B.
//!
//! Each [`Facet`] is a one-sided flat plate: an area A, an outward unit normal n̂ in B, a centre
//! of pressure r_cp relative to B, a drag coefficient C_D and the fractions of incident sunlight
//! it absorbs (ρa), reflects specularly (ρs) and reflects diffusely (ρd), ρa + ρs + ρd = 1. A
//! thin panel is two facets, one per side. A facet contributes only when its normal faces the
//! flow (drag) or the Sun (SRP); shadowing of one facet by another and multiple reflections are
//! neglected, which is exact for a convex body and an approximation otherwise.
//!
//! **Drag** (Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed., §8.6.2: the drag
//! force −½ ρ C_D A |v_rel|² v̂_rel, applied per plate with its projected area; Montenbruck &
//! Gill, *Satellite Orbits*, §3.5): with v the velocity of B relative to the air and
//! cos θ = n̂·v̂ > 0,
//!
//! F = −½ ρ C_D A |v|² cos θ v̂,
//!
//! so the plate's projected area A cos θ sets the force and the force opposes the motion.
//!
//! **SRP** (Montenbruck & Gill §3.4.1 give absorption and specular reflection; the diffuse term
//! follows from Lambert's law, below): with ŝ the unit vector from the spacecraft to the Sun,
//! cos θ = n̂·ŝ > 0 and P the radiation pressure at the spacecraft,
//!
//! F = −P A cos θ [(ρa + ρd) ŝ + (2 ρs cos θ + ⅔ ρd) n̂].
//!
//! It follows from the photons' momentum: the absorbed part pushes along −ŝ; the specular part
//! reverses the normal momentum, −2 cos θ n̂; the diffuse part is absorbed (−ŝ) and re-emitted
//! with a cosine (Lambert) distribution, whose mean recoil is ⅔ along −n̂.
//!
//! **Torque** about B: τ = Σ r_cp × F over the lit or wetted facets (the moment of the facet
//! forces; Wie, *Space Vehicle Dynamics and Control*, 2nd ed., 2008, environmental disturbance
//! torques). B is the hub's reference point, so the lead's dynamic effector can apply the force at
//! B and the torque as given.
//!
//! Checked in `crates/environment/tests/facets.rs`: single plates at known incidence against the
//! momentum balance above (the ⅔ by numerical integration of Lambert's law), and a closed cube
//! giving zero torque about its centre for every flow and Sun direction.

use nalgebra::Vector3;

use super::ephemeris::AU_M;

/// [W/m²] nominal total solar irradiance at 1 AU (IAU 2015 Resolution B3).
pub const SOLAR_IRRADIANCE_1AU_W_M2: f64 = 1361.0;
/// [m/s] the speed of light.
pub const SPEED_OF_LIGHT_M_S: f64 = 299_792_458.0;

/// [N/m²] the solar radiation pressure at `sun_distance_m` \[m\] from the Sun's centre, for a
/// visible fraction `shadow_factor` of the solar disc: P = (Φ/c) (1 AU / r)² ν, with Φ the
/// irradiance at 1 AU (`irradiance_1au_w_m2`, nominally [`SOLAR_IRRADIANCE_1AU_W_M2`]).
pub fn solar_pressure_n_m2(
    sun_distance_m: f64,
    shadow_factor: f64,
    irradiance_1au_w_m2: f64,
) -> f64 {
    let au_over_r = AU_M / sun_distance_m;
    irradiance_1au_w_m2 / SPEED_OF_LIGHT_M_S * au_over_r * au_over_r * shadow_factor
}

/// One flat plate of the vehicle's surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Facet {
    /// \[m²\] area A.
    pub area_m2: f64,
    /// [-] outward unit normal n̂, B components.
    pub normal_b: Vector3<f64>,
    /// \[m\] centre of pressure relative to point B, B components.
    pub r_cp_b_m: Vector3<f64>,
    /// [-] drag coefficient C_D (2.2 is the usual value for a flat plate in free molecular flow).
    pub drag_coefficient: f64,
    /// [-] absorbed fraction ρa of the incident sunlight.
    pub absorbed: f64,
    /// [-] specularly reflected fraction ρs.
    pub specular: f64,
    /// [-] diffusely (Lambertian) reflected fraction ρd.
    pub diffuse: f64,
}

/// A force applied at point B and a torque about B, both in B components.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FacetWrench {
    /// \[N\] force, applied at B, B components.
    pub force_b_newton: Vector3<f64>,
    /// [N·m] torque about B, B components.
    pub torque_b_nm: Vector3<f64>,
}

/// A facet parameter that fails validation; names the facet and the field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FacetError {
    /// A field outside its range.
    #[error("facets[{index}].{field} = {value}: expected {expected}")]
    Invalid {
        /// The facet's position in the list.
        index: usize,
        /// The field's name.
        field: &'static str,
        /// The value given (for a vector, its norm or the offending component).
        value: f64,
        /// What is accepted.
        expected: &'static str,
    },
}

/// [-] how far from 1 a normal's length and the optical fractions' sum may be.
const UNIT_TOLERANCE: f64 = 1e-6;

impl Facet {
    /// Checks the facet's fields; `index` is its position, for the error.
    pub fn validate(&self, index: usize) -> Result<(), FacetError> {
        let invalid = |field, value, expected| FacetError::Invalid {
            index,
            field,
            value,
            expected,
        };
        if !(self.area_m2.is_finite() && self.area_m2 >= 0.0) {
            return Err(invalid("area_m2", self.area_m2, "a finite area >= 0 m²"));
        }
        let norm = self.normal_b.norm();
        if !(norm.is_finite() && (norm - 1.0).abs() <= UNIT_TOLERANCE) {
            return Err(invalid("normal_b", norm, "a unit vector (length 1 ± 1e-6)"));
        }
        if let Some(c) = self.r_cp_b_m.iter().find(|c| !c.is_finite()) {
            return Err(invalid("r_cp_b_m", *c, "finite components"));
        }
        // A plate's free-molecular drag coefficient is at most 4 (every molecule reflected
        // straight back at normal incidence: twice the incoming momentum, over q·A = ½ρv²A);
        // 10 leaves room for conventions that fold other factors in.
        if !(self.drag_coefficient.is_finite() && (0.0..=10.0).contains(&self.drag_coefficient)) {
            return Err(invalid(
                "drag_coefficient",
                self.drag_coefficient,
                "a coefficient in [0, 10] (a flat plate's is at most 4)",
            ));
        }
        for (field, value) in [
            ("absorbed", self.absorbed),
            ("specular", self.specular),
            ("diffuse", self.diffuse),
        ] {
            if !(value.is_finite() && (0.0..=1.0).contains(&value)) {
                return Err(invalid(field, value, "a fraction in [0, 1]"));
            }
        }
        let sum = self.absorbed + self.specular + self.diffuse;
        if (sum - 1.0).abs() > UNIT_TOLERANCE {
            return Err(invalid(
                "absorbed + specular + diffuse",
                sum,
                "fractions that sum to 1 (± 1e-6)",
            ));
        }
        Ok(())
    }

    /// \[N\] this facet's drag force for the velocity of B relative to the air `v_rel_b_m_s`
    /// [m/s] and the density `density_kg_m3`; zero when the facet faces away from the flow.
    pub fn drag_force_b_newton(
        &self,
        v_rel_b_m_s: &Vector3<f64>,
        density_kg_m3: f64,
    ) -> Vector3<f64> {
        let speed = v_rel_b_m_s.norm();
        if speed == 0.0 {
            return Vector3::zeros();
        }
        self.drag_force_facing(&(v_rel_b_m_s / speed), speed, density_kg_m3)
            .unwrap_or_else(Vector3::zeros)
    }

    /// The drag force for the flow direction `v_hat` (unit) and speed `speed_m_s` > 0, or `None`
    /// when the facet faces away.
    fn drag_force_facing(
        &self,
        v_hat: &Vector3<f64>,
        speed_m_s: f64,
        density_kg_m3: f64,
    ) -> Option<Vector3<f64>> {
        let cos_theta = self.normal_b.dot(v_hat);
        (cos_theta > 0.0).then(|| {
            -0.5 * density_kg_m3
                * self.drag_coefficient
                * self.area_m2
                * speed_m_s
                * speed_m_s
                * cos_theta
                * v_hat
        })
    }

    /// \[N\] this facet's SRP force for the unit vector to the Sun `sun_hat_b` and the radiation
    /// pressure `pressure_n_m2` [N/m²]; zero when the facet faces away from the Sun.
    pub fn srp_force_b_newton(&self, sun_hat_b: &Vector3<f64>, pressure_n_m2: f64) -> Vector3<f64> {
        self.srp_force_facing(sun_hat_b, pressure_n_m2)
            .unwrap_or_else(Vector3::zeros)
    }

    /// The SRP force, or `None` when the facet faces away from the Sun.
    fn srp_force_facing(
        &self,
        sun_hat_b: &Vector3<f64>,
        pressure_n_m2: f64,
    ) -> Option<Vector3<f64>> {
        let cos_theta = self.normal_b.dot(sun_hat_b);
        (cos_theta > 0.0).then(|| {
            -pressure_n_m2
                * self.area_m2
                * cos_theta
                * ((self.absorbed + self.diffuse) * sun_hat_b
                    + (2.0 * self.specular * cos_theta + 2.0 / 3.0 * self.diffuse) * self.normal_b)
        })
    }
}

/// A validated set of facets, with the per-facet constants the whole-model sums use.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FacetModel {
    facets: Vec<Facet>,
    /// Per facet, in the same order: the products of its parameters that the factored sums
    /// below need, computed once at build.
    prepared: Vec<Prepared>,
}

/// A facet's constants for [`FacetModel::drag_wrench_b`] and [`FacetModel::srp_wrench_b`].
#[derive(Debug, Clone, Copy, PartialEq)]
struct Prepared {
    /// [-] n̂, B components.
    normal_b: Vector3<f64>,
    /// [m] r_cp, B components.
    r_cp_b_m: Vector3<f64>,
    /// [m] r_cp × n̂, B components (the moment arm of the normal SRP term).
    r_cp_cross_normal_b_m: Vector3<f64>,
    /// [m²] C_D A.
    cd_area_m2: f64,
    /// [m²] A (ρa + ρd): the coefficient of cos θ in the ŝ term of SRP.
    area_along_sun_m2: f64,
    /// [m²] 2 A ρs: the coefficient of cos² θ in the n̂ term.
    area_specular_m2: f64,
    /// [m²] ⅔ A ρd: the coefficient of cos θ in the n̂ term.
    area_diffuse_m2: f64,
}

impl Prepared {
    fn of(f: &Facet) -> Self {
        Prepared {
            normal_b: f.normal_b,
            r_cp_b_m: f.r_cp_b_m,
            r_cp_cross_normal_b_m: f.r_cp_b_m.cross(&f.normal_b),
            cd_area_m2: f.drag_coefficient * f.area_m2,
            area_along_sun_m2: f.area_m2 * (f.absorbed + f.diffuse),
            area_specular_m2: 2.0 * f.area_m2 * f.specular,
            area_diffuse_m2: 2.0 / 3.0 * f.area_m2 * f.diffuse,
        }
    }
}

impl FacetModel {
    /// The model of `facets`, each checked by [`Facet::validate`].
    pub fn new(facets: Vec<Facet>) -> Result<Self, FacetError> {
        for (index, facet) in facets.iter().enumerate() {
            facet.validate(index)?;
        }
        let prepared = facets.iter().map(Prepared::of).collect();
        Ok(FacetModel { facets, prepared })
    }

    /// The facets.
    pub fn facets(&self) -> &[Facet] {
        &self.facets
    }

    /// Every facet's numbers under `environment.facets[k].` (their configuration paths), for a
    /// campaign's read-back.
    pub fn parameters(&self, out: &mut Vec<(String, f64)>) {
        for (k, f) in self.facets.iter().enumerate() {
            let key = |name: &str| format!("environment.facets[{k}].{name}");
            out.push((key("area_m2"), f.area_m2));
            out.push((key("drag_coefficient"), f.drag_coefficient));
            out.push((key("absorbed"), f.absorbed));
            out.push((key("specular"), f.specular));
            out.push((key("diffuse"), f.diffuse));
            for i in 0..3 {
                out.push((format!("{}[{i}]", key("normal_b")), f.normal_b[i]));
                out.push((format!("{}[{i}]", key("r_cp_b_m")), f.r_cp_b_m[i]));
            }
        }
    }

    /// Drag on the whole model: the sum of the facet forces, applied at B, and of their moments
    /// about B, for the velocity of B relative to the air `v_rel_b_m_s` [m/s] (B components) and
    /// the density `density_kg_m3`. Allocation-free and panic-free.
    ///
    /// Every facet's drag is along −v̂, so with q = ½ ρ |v|² and w_k = C_D,k A_k cos θ_k over the
    /// facets facing the flow, the sums factor (the same forces, one cross product in all):
    /// F = −q (Σ w_k) v̂ and τ = Σ r_k × F_k = −q (Σ w_k r_k) × v̂. With cos θ_k = n̂_k·v / |v|
    /// the speed cancels: q w_k v̂ = ½ ρ C_D,k A_k (n̂_k·v) v, so
    /// F = −½ ρ (Σ u_k) v and τ = −½ ρ (Σ u_k r_k) × v with u_k = C_D,k A_k (n̂_k·v) over the
    /// facets with n̂_k·v > 0: no square root and no division at a stage. At rest every n̂_k·v
    /// is 0 and the wrench is zero.
    #[inline]
    pub fn drag_wrench_b(&self, v_rel_b_m_s: &Vector3<f64>, density_kg_m3: f64) -> FacetWrench {
        let mut u_sum_m3_s = 0.0;
        let mut u_r_sum_m4_s = Vector3::zeros();
        for p in &self.prepared {
            let n_dot_v_m_s = p.normal_b.dot(v_rel_b_m_s);
            if n_dot_v_m_s > 0.0 {
                let u_m3_s = p.cd_area_m2 * n_dot_v_m_s;
                u_sum_m3_s += u_m3_s;
                u_r_sum_m4_s += p.r_cp_b_m * u_m3_s;
            }
        }
        let minus_half_rho_kg_m3 = -0.5 * density_kg_m3;
        FacetWrench {
            force_b_newton: v_rel_b_m_s * (minus_half_rho_kg_m3 * u_sum_m3_s),
            torque_b_nm: u_r_sum_m4_s.cross(v_rel_b_m_s) * minus_half_rho_kg_m3,
        }
    }

    /// Solar radiation pressure on the whole model for the direction from the spacecraft to the
    /// Sun `sun_dir_b` (B components, any non-zero length) and the pressure `pressure_n_m2`
    /// ([`solar_pressure_n_m2`], which carries the 1/r² and the shadow factor).
    /// Allocation-free and panic-free; a zero direction gives no force.
    ///
    /// Each lit facet's force is −P (a_k ŝ + b_k n̂_k) with a_k = A_k cos θ_k (ρa + ρd) and
    /// b_k = A_k cos θ_k (2 ρs cos θ_k + ⅔ ρd), so the sums factor as
    /// F = −P [(Σ a_k) ŝ + Σ b_k n̂_k] and τ = −P [(Σ a_k r_k) × ŝ + Σ b_k (r_k × n̂_k)], with
    /// r_k × n̂_k fixed in B and computed once.
    pub fn srp_wrench_b(&self, sun_dir_b: &Vector3<f64>, pressure_n_m2: f64) -> FacetWrench {
        let norm = sun_dir_b.norm();
        if norm == 0.0 {
            return FacetWrench::default();
        }
        self.srp_wrench_unit_b(&(sun_dir_b * norm.recip()), pressure_n_m2)
    }

    /// [`Self::srp_wrench_b`] for a direction to the Sun `sun_hat_b` already of unit length (the
    /// stage path: the solar-pressure effector normalises the held Sun direction once per
    /// environment sample, in N, and only rotates it at a stage).
    #[inline]
    pub fn srp_wrench_unit_b(&self, sun_hat_b: &Vector3<f64>, pressure_n_m2: f64) -> FacetWrench {
        let mut a_sum_m2 = 0.0;
        let mut a_r_sum_m3 = Vector3::zeros();
        let mut b_n_sum_m2 = Vector3::zeros();
        let mut b_rn_sum_m3 = Vector3::zeros();
        for p in &self.prepared {
            let cos_theta = p.normal_b.dot(sun_hat_b);
            if cos_theta > 0.0 {
                let a_m2 = p.area_along_sun_m2 * cos_theta;
                let b_m2 = (p.area_specular_m2 * cos_theta + p.area_diffuse_m2) * cos_theta;
                a_sum_m2 += a_m2;
                a_r_sum_m3 += p.r_cp_b_m * a_m2;
                b_n_sum_m2 += p.normal_b * b_m2;
                b_rn_sum_m3 += p.r_cp_cross_normal_b_m * b_m2;
            }
        }
        FacetWrench {
            force_b_newton: (sun_hat_b * a_sum_m2 + b_n_sum_m2) * -pressure_n_m2,
            torque_b_nm: (a_r_sum_m3.cross(sun_hat_b) + b_rn_sum_m3) * -pressure_n_m2,
        }
    }
}
