//! The `[[thrusters]]` schema. Keys are checked by the shared reader ([`flexdyn_kernel::schema`]);
//! values are validated by [`super::Thruster::new`], whose errors name the same TOML paths.

use super::{ThrusterCommand, ThrusterParams};
use flexdyn_kernel::schema::{vec3, SchemaError, TableReader};

/// The keys of one `[[thrusters]]` entry (the first five are required).
pub(crate) const KEYS: [&str; 10] = [
    "name",
    "r_tb_b_m",
    "force_axis_b",
    "max_thrust_newton",
    "isp_s",
    "min_on_time_s",
    "rise_time_constant_s",
    "tail_off_time_constant_s",
    "command",
    "tank",
];

/// Reads one entry (shape only; [`ThrusterParams::validate`] checks the values).
pub(crate) fn read(t: &TableReader<'_, '_>) -> Result<ThrusterParams, SchemaError> {
    let opt = |k: &str| t.opt_f64(k).map(|v| v.unwrap_or(0.0));
    let command = match t.opt_choice("command", &ThrusterCommand::NAMES)? {
        None | Some(0) => ThrusterCommand::OnTime,
        Some(_) => ThrusterCommand::DutyCycle,
    };
    Ok(ThrusterParams {
        name: t.string("name")?,
        r_tb_b_m: vec3(&t.floats("r_tb_b_m")?),
        force_axis_b: vec3(&t.floats("force_axis_b")?),
        max_thrust_newton: t.f64("max_thrust_newton")?,
        isp_s: t.f64("isp_s")?,
        min_on_time_s: opt("min_on_time_s")?,
        rise_time_constant_s: opt("rise_time_constant_s")?,
        tail_off_time_constant_s: opt("tail_off_time_constant_s")?,
        command,
        tank: t.get("tank").map(|_| t.string("tank")).transpose()?,
    })
}
