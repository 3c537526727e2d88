//! Parameters of a reaction wheel: plain data, validated here with errors that name the
//! configuration path.

use nalgebra::Vector3;

use flexdyn_kernel::validate::{
    check_finite, check_non_negative, check_positive, check_principal_moments, check_unit_axis,
    join, ParamError,
};

/// One reaction wheel (`[[reaction_wheels]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct ReactionWheelParams {
    /// Name used in logs, messages and telemetry.
    pub name: String,
    /// Spin axis ĝ_s in B components (a unit vector within [`flexdyn_kernel::validate::UNIT_AXIS_TOL`]).
    pub spin_axis_b: Vector3<f64>,
    /// \[m\] rotor centre of mass W relative to B, B components.
    pub r_wb_b_m: Vector3<f64>,
    /// \[kg\] rotor mass (the housing belongs to the hub's mass properties).
    pub mass_kg: f64,
    /// [kg·m²] rotor inertia about the spin axis, J_s.
    pub j_s_kg_m2: f64,
    /// [kg·m²] rotor inertia about a transverse axis through W, J_t.
    pub j_t_kg_m2: f64,
    /// [rad/s] initial wheel speed Ω relative to the hub.
    pub omega_rad_s: f64,
    /// [N·m] largest motor torque magnitude.
    pub max_torque_nm: f64,
    /// [rad/s] largest wheel speed magnitude the motor will drive towards.
    pub max_speed_rad_s: f64,
    /// [N·m·s/rad] viscous friction coefficient b.
    pub viscous_friction_nm_s_rad: f64,
    /// [N·m] Coulomb friction torque τ_c.
    pub coulomb_friction_nm: f64,
    /// [rad/s] half-width Ω_c of the linear region of the Coulomb friction.
    pub coulomb_band_rad_s: f64,
    /// [kg·m] static imbalance U_s (0: none).
    pub static_imbalance_kg_m: f64,
    /// [kg·m²] dynamic imbalance U_d (0: none).
    pub dynamic_imbalance_kg_m2: f64,
}

impl ReactionWheelParams {
    /// A balanced, frictionless wheel with the given geometry and limits (the remaining fields
    /// take their configuration defaults).
    #[allow(clippy::too_many_arguments)]
    pub fn balanced(
        name: &str,
        spin_axis_b: Vector3<f64>,
        r_wb_b_m: Vector3<f64>,
        mass_kg: f64,
        j_s_kg_m2: f64,
        j_t_kg_m2: f64,
        omega_rad_s: f64,
        max_torque_nm: f64,
        max_speed_rad_s: f64,
    ) -> Self {
        Self {
            name: name.to_string(),
            spin_axis_b,
            r_wb_b_m,
            mass_kg,
            j_s_kg_m2,
            j_t_kg_m2,
            omega_rad_s,
            max_torque_nm,
            max_speed_rad_s,
            viscous_friction_nm_s_rad: 0.0,
            coulomb_friction_nm: 0.0,
            coulomb_band_rad_s: DEFAULT_COULOMB_BAND_RAD_S,
            static_imbalance_kg_m: 0.0,
            dynamic_imbalance_kg_m2: 0.0,
        }
    }

    /// Whether the wheel has a static or dynamic imbalance (then it also integrates its angle
    /// and applies the jitter of (W6)–(W7)).
    pub fn imbalanced(&self) -> bool {
        self.static_imbalance_kg_m > 0.0 || self.dynamic_imbalance_kg_m2 > 0.0
    }

    /// Validates the wheel (`path` is e.g. `reaction_wheels[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_unit_axis(path, "spin_axis_b", &self.spin_axis_b)?;
        check_finite(path, "r_wb_b_m", self.r_wb_b_m.as_slice())?;
        check_positive(path, "mass_kg", self.mass_kg)?;
        check_positive(path, "j_s_kg_m2", self.j_s_kg_m2)?;
        check_positive(path, "j_t_kg_m2", self.j_t_kg_m2)?;
        // The rotor's principal moments about W are (J_s, J_t, J_t).
        check_principal_moments(
            path,
            "j_s_kg_m2",
            &[self.j_s_kg_m2, self.j_t_kg_m2, self.j_t_kg_m2],
        )?;
        check_positive(path, "max_torque_nm", self.max_torque_nm)?;
        check_positive(path, "max_speed_rad_s", self.max_speed_rad_s)?;
        check_finite(path, "omega_rad_s", &[self.omega_rad_s])?;
        if self.omega_rad_s.abs() > self.max_speed_rad_s {
            return Err(ParamError::Exceeds {
                field: join(path, "omega_rad_s"),
                value: self.omega_rad_s,
                limit_field: "max_speed_rad_s",
                limit: self.max_speed_rad_s,
            });
        }
        check_non_negative(
            path,
            "viscous_friction_nm_s_rad",
            self.viscous_friction_nm_s_rad,
        )?;
        check_non_negative(path, "coulomb_friction_nm", self.coulomb_friction_nm)?;
        check_positive(path, "coulomb_band_rad_s", self.coulomb_band_rad_s)?;
        check_non_negative(path, "static_imbalance_kg_m", self.static_imbalance_kg_m)?;
        check_non_negative(
            path,
            "dynamic_imbalance_kg_m2",
            self.dynamic_imbalance_kg_m2,
        )
    }
}

/// [rad/s] default `coulomb_band_rad_s`.
pub const DEFAULT_COULOMB_BAND_RAD_S: f64 = 0.05;
