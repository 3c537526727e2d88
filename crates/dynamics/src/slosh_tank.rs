//! Fuel-slosh parameters from a tank's fill level: the first lateral sloshing mode of the liquid
//! in an upright circular cylindrical tank with a flat bottom, as the equivalent mechanical model
//! that [`crate::effectors::slosh_linear`] (spring-mass) and [`crate::effectors::slosh_pendulum`]
//! (pendulum) integrate.
//!
//! # Source
//! The equivalent mechanical model of linear lateral slosh in a flat-bottomed upright cylinder:
//! H. N. Abramson (ed.), *The Dynamic Behavior of Liquids in Moving Containers*, NASA SP-106, 1966,
//! Chapter 6 (mechanical models), and its update F. T. Dodge, *The New "Dynamic Behavior of
//! Liquids in Moving Containers"*, Southwest Research Institute, 2000, Chapter 3 (the tables of the
//! spring-mass and pendulum parameters for a cylindrical tank with a flat bottom). The natural
//! frequency is Lamb's, *Hydrodynamics* (6th ed., 1932), §191 (waves in a circular basin). The
//! steps below re-derive each parameter from the linear potential-flow mode, so that each formula
//! in the code is checked rather than copied; the numbers (T1)–(T6) are this file's own.
//!
//! # Derivation
//! Tank radius R, liquid depth h (the fill level), density ρ_L, settling acceleration a along
//! the tank's axis (the thrust acceleration; the liquid lies at the bottom, the end the axis
//! points away from). z is the height above the bottom. The first antisymmetric mode has the
//! velocity potential φ = A J₁(ξ r/R) cos ϑ cosh(ξ z/R) e^{iωt}, with ξ = ξ₁ = 1.841 18… the first
//! root of J₁′(ξ) = 0 (no flow through the wall).
//!
//! - (T1) Frequency, from the free-surface condition φ_tt + a φ_z = 0 at z = h:
//!   **ω₁² = (a ξ/R) tanh(ξ h/R)**.
//! - (T2) Sloshing mass: the mode's force on a fixed tank, F = ρ_L ω A J₁(ξ) π (R²/ξ) sinh(ξh/R),
//!   and its peak kinetic energy, T = ρ_L A² π (R/ξ) sinh cosh (ξ² − 1) J₁(ξ)²/4 (with
//!   ∫₀^ξ s J₁(s)² ds = ½(ξ² − 1)J₁(ξ)² at a root of J₁′), are those of a mass m₁ on a spring of
//!   frequency ω₁ when F² = 2 m₁ ω₁² T: **m₁ = m_L · 2R tanh(ξh/R) / (ξ (ξ² − 1) h)**, with
//!   m_L = ρ_L π R² h the liquid mass.
//! - (T3) Spring-mass model: **k₁ = m₁ ω₁²**. Pendulum model: the same frequency in the same
//!   acceleration, **L₁ = a/ω₁² = R / (ξ tanh(ξh/R))**, independent of a.
//! - (T4) Height of the slosh mass: the mode's moment about the bottom's centre, from the wall's
//!   and the bottom's pressure (∫₀^R r² J₁(ξr/R) dr = R³ J₂(ξ)/ξ = R³ J₁(ξ)/ξ² at a root of J₁′),
//!   is F·H with H = h − (R/ξ)(cosh x − 2)/sinh x, x = ξh/R. In the spring-mass model the same
//!   moment is the spring force at the mass's height h₁ plus the moment of its displaced weight,
//!   m₁ω₁²X h₁ + m₁ a X, so **h₁ = H − L₁ = h − (2R/ξ) tanh(ξh/(2R))** (Abramson's and Dodge's
//!   form; measured from the liquid's centre of mass it is h/2 − (2R/ξ) tanh(ξh/2R)).
//! - (T5) Pendulum hinge: the rod carries the moment as a lateral force at the hinge, so the hinge
//!   is at height H and the bob hangs at h₁: **h_hinge = h₁ + L₁**.
//! - (T6) The non-sloshing remainder m₀ = m_L − m₁ is rigid with the tank, at the height h₀ that
//!   keeps the liquid's centre of mass at h/2: **h₀ = (m_L h/2 − m₁ h₁)/m₀**. It belongs to the
//!   hub's mass properties (the depletion of the tank is tracked there, not here).
//!
//! A tank's fill level thus sets every parameter of its slosh model: when the level changes
//! (propellant used), [`CylindricalTank::first_mode`] gives the new mass, stiffness or length and
//! location.

use nalgebra::Vector3;

use flexdyn_kernel::validate::{check_finite, check_positive, check_unit_axis, ParamError};

/// ξ₁, the first root of J₁′(ξ) = 0 (Abramson 1966, Chapter 6; Lamb 1932, §191).
pub const XI_1: f64 = 1.841_183_781_340_659;

/// An upright circular cylindrical tank with a flat bottom, partly filled with liquid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylindricalTank {
    /// \[m\] inner radius R.
    pub radius_m: f64,
    /// \[m\] liquid depth h above the bottom (the fill level).
    pub fill_height_m: f64,
    /// \[kg/m³\] liquid density ρ_L.
    pub density_kg_m3: f64,
    /// \[m\] the centre of the tank's bottom relative to B, B components.
    pub r_bottom_b_m: Vector3<f64>,
    /// The tank's axis in B (unit), from the bottom towards the free surface: the settling
    /// acceleration (thrust) points along it, the apparent gravity against it.
    pub axis_b: Vector3<f64>,
}

/// The first lateral slosh mode of a [`CylindricalTank`] at one fill level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SloshMode {
    /// \[kg\] the liquid's mass m_L.
    pub liquid_mass_kg: f64,
    /// \[kg\] the sloshing mass m₁ (T2).
    pub slosh_mass_kg: f64,
    /// \[kg\] the non-sloshing mass m₀ = m_L − m₁ (T6).
    pub fixed_mass_kg: f64,
    /// \[m\] the pendulum's length L₁ (T3).
    pub pendulum_length_m: f64,
    /// \[m\] height of the slosh mass above the bottom, h₁ (T4).
    pub slosh_height_m: f64,
    /// \[m\] height of the pendulum's hinge above the bottom, h₁ + L₁ (T5).
    pub hinge_height_m: f64,
    /// \[m\] height of the non-sloshing mass above the bottom, h₀ (T6).
    pub fixed_height_m: f64,
}

impl SloshMode {
    /// \[rad/s\] ω₁ at settling acceleration `accel_m_s2` (T1): ω₁² = a / L₁.
    pub fn omega_rad_s(&self, accel_m_s2: f64) -> f64 {
        (accel_m_s2 / self.pendulum_length_m).sqrt()
    }

    /// \[N/m\] the spring-mass model's stiffness at settling acceleration `accel_m_s2` (T3).
    pub fn k_n_m(&self, accel_m_s2: f64) -> f64 {
        self.slosh_mass_kg * accel_m_s2 / self.pendulum_length_m
    }
}

impl CylindricalTank {
    /// Validates the tank (`path` is e.g. `slosh_linear[0].tank`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_positive(path, "radius_m", self.radius_m)?;
        check_positive(path, "fill_height_m", self.fill_height_m)?;
        check_positive(path, "density_kg_m3", self.density_kg_m3)?;
        check_finite(path, "r_bottom_b_m", self.r_bottom_b_m.as_slice())?;
        check_unit_axis(path, "axis_b", &self.axis_b)
    }

    /// The first lateral mode at this fill level, Eqs. (T2)–(T6).
    pub fn first_mode(&self) -> SloshMode {
        let (r, h) = (self.radius_m, self.fill_height_m);
        let x = XI_1 * h / r;
        let liquid = self.density_kg_m3 * std::f64::consts::PI * r * r * h;
        // (T2)
        let slosh = liquid * 2.0 * r * x.tanh() / (XI_1 * (XI_1 * XI_1 - 1.0) * h);
        // (T3)
        let length = r / (XI_1 * x.tanh());
        // (T4)
        let h1 = h - 2.0 * r / XI_1 * (0.5 * x).tanh();
        // (T6)
        let fixed = liquid - slosh;
        SloshMode {
            liquid_mass_kg: liquid,
            slosh_mass_kg: slosh,
            fixed_mass_kg: fixed,
            pendulum_length_m: length,
            slosh_height_m: h1,
            // (T5)
            hinge_height_m: h1 + length,
            fixed_height_m: (liquid * 0.5 * h - slosh * h1) / fixed,
        }
    }

    /// \[m\] the point at `height_m` above the bottom on the tank's axis, relative to B.
    pub fn on_axis_b_m(&self, height_m: f64) -> Vector3<f64> {
        self.r_bottom_b_m + self.axis_b * height_m
    }
}

/// The keys of a `tank = { … }` table of a slosh entry (all required).
pub const TANK_KEYS: [&str; 5] = [
    "radius_m",
    "fill_height_m",
    "density_kg_m3",
    "r_bottom_b_m",
    "axis_b",
];

/// The keys of a spring-mass entry's `tank` table: [`TANK_KEYS`] plus the settling acceleration
/// that sets the spring (T3).
pub const TANK_KEYS_WITH_ACCEL: [&str; 6] = [
    "radius_m",
    "fill_height_m",
    "density_kg_m3",
    "r_bottom_b_m",
    "axis_b",
    "settling_accel_m_s2",
];

/// Reads the `tank` table of entry `t` (shape only; [`CylindricalTank::validate`] checks the
/// values), with the settling acceleration when `with_accel`. `None` when the entry has no
/// `tank`; an error when it has one and also any of `direct_keys` (the values the tank sets).
pub fn read_tank(
    t: &flexdyn_kernel::schema::TableReader<'_, '_>,
    with_accel: bool,
    direct_keys: &[&str],
) -> Result<Option<(CylindricalTank, f64)>, flexdyn_kernel::schema::SchemaError> {
    use flexdyn_kernel::schema::{vec3, At, SchemaError};
    let keys: &[&str] = if with_accel {
        &TANK_KEYS_WITH_ACCEL
    } else {
        &TANK_KEYS
    };
    let Some(tt) = t.opt_table("tank", keys)? else {
        return Ok(None);
    };
    if let Some(k) = direct_keys.iter().find(|k| t.get(k).is_some()) {
        return Err(SchemaError::InvalidValue {
            field: t.field(k),
            message: format!(
                "give either {} (the tank's fill level sets it) or {}, not both",
                t.field("tank"),
                direct_keys.join(", ")
            ),
            at: At(None),
        });
    }
    let tank = CylindricalTank {
        radius_m: tt.f64("radius_m")?,
        fill_height_m: tt.f64("fill_height_m")?,
        density_kg_m3: tt.f64("density_kg_m3")?,
        r_bottom_b_m: vec3(&tt.floats("r_bottom_b_m")?),
        axis_b: vec3(&tt.floats("axis_b")?),
    };
    let accel = if with_accel {
        tt.f64("settling_accel_m_s2")?
    } else {
        0.0
    };
    Ok(Some((tank, accel)))
}

/// The registry entry of a slosh kind and its [`crate::component::ComponentParams`]: both slosh
/// kinds are appended bodies configured through the generic list whose entry resolves (a tank
/// mapped, [`read_tank`]) to the parameters their effector is built from. `$entry` has
/// `name: String` and `resolve(&self, path) -> Result<$params, ParamError>`, the resolved
/// `$params` have `validate(path)` and `mass_kg`, and `$body::new($params, path)` builds the
/// effector.
macro_rules! slosh_component {
    ($(#[$doc:meta])* $entry:ty => $body:ident, section $section:literal, noun $noun:literal) => {
        $(#[$doc])*
        pub static COMPONENT: $crate::component::ComponentKind = $crate::component::ComponentKind {
            effector: super::KIND,
            section: $section,
            noun: $noun,
            wire_names: |_, _| Some((&super::STATE_NAMES, &[])),
            reader: Some($crate::component::ComponentReader {
                keys: &super::schema::KEYS,
                read: |t| $crate::component::read_boxed(t, super::schema::read),
            }),
            fault_modes: &[],
        };

        impl $crate::component::ComponentParams for $entry {
            fn component_kind() -> &'static $crate::component::ComponentKind {
                &COMPONENT
            }
            fn name(&self) -> &str {
                &self.name
            }
            fn validate(
                &self,
                path: &str,
                _timing: $crate::component::StepTiming,
            ) -> Result<(), flexdyn_kernel::validate::ParamError> {
                self.resolve(path)?.validate(path)
            }
            fn wire_counts(&self) -> (usize, usize) {
                (super::STATE_NAMES.len(), 0)
            }
            fn mass_kg(&self) -> f64 {
                // Validated before this is asked; an invalid entry adds nothing.
                self.resolve("").map_or(0.0, |p| p.mass_kg)
            }
            fn build(
                &self,
                path: &str,
                _timing: $crate::component::StepTiming,
            ) -> Result<$crate::component::BuiltComponent, flexdyn_kernel::validate::ParamError>
            {
                Ok($crate::component::BuiltComponent::Body(Box::new(super::$body::new(
                    self.resolve(path)?,
                    path,
                )?)))
            }
        }
    };
}
pub(crate) use slosh_component;

#[cfg(test)]
mod tests {
    use super::*;

    fn tank(h_over_r: f64) -> CylindricalTank {
        CylindricalTank {
            radius_m: 0.5,
            fill_height_m: 0.5 * h_over_r,
            density_kg_m3: 1000.0,
            r_bottom_b_m: Vector3::zeros(),
            axis_b: Vector3::z(),
        }
    }

    /// ξ₁ is a root of J₁′ = J₀ − J₁/x: evaluated with the power series of J₀ and J₁.
    #[test]
    fn xi_1_is_the_first_root_of_the_derivative_of_j1() {
        let (mut j0, mut j1) = (0.0, 0.0);
        let x2 = XI_1 * XI_1 / 4.0;
        let mut term0 = 1.0; // (−x²/4)^k / (k!)²
        for k in 0..40 {
            let kf = k as f64;
            if k > 0 {
                term0 *= -x2 / (kf * kf);
            }
            j0 += term0;
            j1 += term0 * (XI_1 / 2.0) / (kf + 1.0);
        }
        assert!(
            (j0 - j1 / XI_1).abs() < 1e-15,
            "J1'(ξ1) = {}",
            j0 - j1 / XI_1
        );
    }

    /// Deep and shallow limits: the sloshing mass fraction tends to 2R/(ξ(ξ²−1)h) in a deep
    /// tank and to 2/(ξ²−1) (all but the liquid the mode cannot move) in a shallow one; the
    /// pendulum length to R/ξ; the mass heights keep the liquid's centre of mass at h/2.
    #[test]
    fn first_mode_limits_and_centre_of_mass() {
        let deep = tank(20.0).first_mode();
        let frac = deep.slosh_mass_kg / deep.liquid_mass_kg;
        assert!((frac - 2.0 / (XI_1 * (XI_1 * XI_1 - 1.0) * 20.0)).abs() < 1e-12);
        assert!((deep.pendulum_length_m - 0.5 / XI_1).abs() < 1e-12);
        // The slosh mass sits 2R/ξ below the free surface, the hinge R/ξ below it.
        assert!((deep.slosh_height_m - (10.0 - 1.0 / XI_1)).abs() < 1e-12);
        assert!((deep.hinge_height_m - (10.0 - 0.5 / XI_1)).abs() < 1e-12);
        let shallow = tank(1e-4).first_mode();
        let frac = shallow.slosh_mass_kg / shallow.liquid_mass_kg;
        assert!((frac - 2.0 / (XI_1 * XI_1 - 1.0)).abs() < 1e-6, "{frac}");
        for m in [deep, shallow, tank(1.0).first_mode()] {
            let cm = m.slosh_mass_kg * m.slosh_height_m + m.fixed_mass_kg * m.fixed_height_m;
            let h = m.liquid_mass_kg / (1000.0 * std::f64::consts::PI * 0.25);
            assert!((cm / m.liquid_mass_kg - 0.5 * h).abs() < 1e-12 * h.max(1.0));
            assert!(m.fixed_mass_kg > 0.0);
        }
    }

    /// (T1) at h = R: ω² = (a ξ/R) tanh ξ, and k = m₁ω².
    #[test]
    fn frequency_and_stiffness() {
        let m = tank(1.0).first_mode();
        let a = 0.2;
        let w2 = a * XI_1 / 0.5 * XI_1.tanh();
        assert!((m.omega_rad_s(a).powi(2) - w2).abs() < 1e-14 * w2);
        assert!((m.k_n_m(a) - m.slosh_mass_kg * w2).abs() < 1e-12 * m.k_n_m(a));
    }
}
