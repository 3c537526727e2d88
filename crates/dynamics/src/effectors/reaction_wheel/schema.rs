//! The `[[reaction_wheels]]` schema. Keys are checked by the shared reader
//! ([`flexdyn_kernel::schema`]); values are validated by [`super::ReactionWheel::new`], whose errors name
//! the same TOML paths.

use super::params::DEFAULT_COULOMB_BAND_RAD_S;
use super::ReactionWheelParams;
use flexdyn_kernel::schema::{vec3, SchemaError, TableReader};

/// The keys of one `[[reaction_wheels]]` entry (the first eight are required).
pub const KEYS: [&str; 14] = [
    "name",
    "spin_axis_b",
    "r_wb_b_m",
    "mass_kg",
    "j_s_kg_m2",
    "j_t_kg_m2",
    "max_torque_nm",
    "max_speed_rad_s",
    "omega_rad_s",
    "viscous_friction_nm_s_rad",
    "coulomb_friction_nm",
    "coulomb_band_rad_s",
    "static_imbalance_kg_m",
    "dynamic_imbalance_kg_m2",
];

/// Reads one entry (shape only; [`ReactionWheelParams::validate`] checks the values).
pub fn read(t: &TableReader<'_, '_>) -> Result<ReactionWheelParams, SchemaError> {
    let v3 = |a: [f64; 3]| vec3(&a);
    let opt = |k: &str, default: f64| t.opt_f64(k).map(|v| v.unwrap_or(default));
    Ok(ReactionWheelParams {
        name: t.string("name")?,
        spin_axis_b: v3(t.floats("spin_axis_b")?),
        r_wb_b_m: v3(t.floats("r_wb_b_m")?),
        mass_kg: t.f64("mass_kg")?,
        j_s_kg_m2: t.f64("j_s_kg_m2")?,
        j_t_kg_m2: t.f64("j_t_kg_m2")?,
        max_torque_nm: t.f64("max_torque_nm")?,
        max_speed_rad_s: t.f64("max_speed_rad_s")?,
        omega_rad_s: opt("omega_rad_s", 0.0)?,
        viscous_friction_nm_s_rad: opt("viscous_friction_nm_s_rad", 0.0)?,
        coulomb_friction_nm: opt("coulomb_friction_nm", 0.0)?,
        coulomb_band_rad_s: opt("coulomb_band_rad_s", DEFAULT_COULOMB_BAND_RAD_S)?,
        static_imbalance_kg_m: opt("static_imbalance_kg_m", 0.0)?,
        dynamic_imbalance_kg_m2: opt("dynamic_imbalance_kg_m2", 0.0)?,
    })
}
