//! The `[[slosh_pendulums]]` schema. Keys are checked by the shared reader
//! ([`flexdyn_kernel::schema`]); values are validated by [`super::SloshPendulum::new`] (and
//! [`crate::slosh_tank::CylindricalTank::validate`]), whose errors name the same TOML paths.
//!
//! An entry gives its pivot, hang axis, length and mass either directly (`r_pb_b_m`,
//! `hang_axis_b`, `l_m`, `mass_kg`) or through a `tank` table, whose fill level sets them
//! ([`crate::slosh_tank`], Eqs. T2, T3, T5).

use super::params::{SloshPendulumEntry, SloshPendulumSource};
use crate::slosh_tank::read_tank;
use flexdyn_kernel::schema::{vec3, SchemaError, TableReader};

/// The keys of one `[[slosh_pendulums]]` entry.
pub const KEYS: [&str; 11] = [
    "name",
    "r_pb_b_m",
    "hang_axis_b",
    "l_m",
    "mass_kg",
    "tank",
    "c_nm_s_rad",
    "phi_rad",
    "phi_dot_rad_s",
    "theta_rad",
    "theta_dot_rad_s",
];

/// The keys a `tank` table replaces.
const DIRECT_KEYS: [&str; 4] = ["r_pb_b_m", "hang_axis_b", "l_m", "mass_kg"];

/// Reads one entry (shape only; [`SloshPendulumEntry::resolve`] checks the values).
pub fn read(t: &TableReader<'_, '_>) -> Result<SloshPendulumEntry, SchemaError> {
    let opt = |k: &str| t.opt_f64(k).map(|v| v.unwrap_or(0.0));
    let source = match read_tank(t, false, &DIRECT_KEYS)? {
        Some((tank, _)) => SloshPendulumSource::Tank(tank),
        None => SloshPendulumSource::Direct {
            r_pb_b_m: vec3(&t.floats("r_pb_b_m")?),
            hang_axis_b: vec3(&t.floats("hang_axis_b")?),
            l_m: t.f64("l_m")?,
            mass_kg: t.f64("mass_kg")?,
        },
    };
    Ok(SloshPendulumEntry {
        name: t.string("name")?,
        source,
        c_nm_s_rad: opt("c_nm_s_rad")?,
        phi_rad: opt("phi_rad")?,
        phi_dot_rad_s: opt("phi_dot_rad_s")?,
        theta_rad: opt("theta_rad")?,
        theta_dot_rad_s: opt("theta_dot_rad_s")?,
    })
}
