//! The `[[magnetorquers]]` schema. Keys are checked by the shared reader ([`flexdyn_kernel::schema`]);
//! values are validated by [`super::Magnetorquer::new`], whose errors name the same TOML paths.

use super::MagnetorquerParams;
use flexdyn_kernel::schema::{vec3, SchemaError, TableReader};

/// The keys of one `[[magnetorquers]]` entry (all required).
pub(crate) const KEYS: [&str; 4] = ["name", "axis_b", "r_mb_b_m", "max_dipole_am2"];

/// Reads one entry (shape only; [`MagnetorquerParams::validate`] checks the values).
pub(crate) fn read(t: &TableReader<'_, '_>) -> Result<MagnetorquerParams, SchemaError> {
    Ok(MagnetorquerParams {
        name: t.string("name")?,
        axis_b: vec3(&t.floats("axis_b")?),
        r_mb_b_m: vec3(&t.floats("r_mb_b_m")?),
        max_dipole_am2: t.f64("max_dipole_am2")?,
    })
}
