//! The `[[slosh_linear]]` schema. Keys are checked by the shared reader
//! ([`flexdyn_kernel::schema`]); values are validated by [`super::SloshLinear::new`] (and
//! [`crate::slosh_tank::CylindricalTank::validate`]), whose errors name the same TOML paths.
//!
//! An entry gives its sloshing mass, stiffness and rest point either directly (`mass_kg`,
//! `k_n_m`, `r_pb_b_m`) or through a `tank` table, whose fill level sets them
//! ([`crate::slosh_tank`], Eqs. T2–T4).

use super::params::{SloshLinearEntry, SloshLinearSource};
use crate::slosh_tank::read_tank;
use flexdyn_kernel::schema::{vec3, SchemaError, TableReader};

/// The keys of one `[[slosh_linear]]` entry.
pub const KEYS: [&str; 9] = [
    "name",
    "p_hat_b",
    "r_pb_b_m",
    "mass_kg",
    "k_n_m",
    "tank",
    "c_n_s_m",
    "rho_m",
    "rho_dot_m_s",
];

/// The keys a `tank` table replaces.
const DIRECT_KEYS: [&str; 3] = ["r_pb_b_m", "mass_kg", "k_n_m"];

/// Reads one entry (shape only; [`SloshLinearEntry::resolve`] checks the values).
pub fn read(t: &TableReader<'_, '_>) -> Result<SloshLinearEntry, SchemaError> {
    let opt = |k: &str| t.opt_f64(k).map(|v| v.unwrap_or(0.0));
    let source = match read_tank(t, true, &DIRECT_KEYS)? {
        Some((tank, settling_accel_m_s2)) => SloshLinearSource::Tank {
            tank,
            settling_accel_m_s2,
        },
        None => SloshLinearSource::Direct {
            r_pb_b_m: vec3(&t.floats("r_pb_b_m")?),
            mass_kg: t.f64("mass_kg")?,
            k_n_m: t.f64("k_n_m")?,
        },
    };
    Ok(SloshLinearEntry {
        name: t.string("name")?,
        p_hat_b: vec3(&t.floats("p_hat_b")?),
        source,
        c_n_s_m: opt("c_n_s_m")?,
        rho_m: opt("rho_m")?,
        rho_dot_m_s: opt("rho_dot_m_s")?,
    })
}
