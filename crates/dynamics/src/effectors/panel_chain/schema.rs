//! The `[[panel_chains]]` schema: one chain of hinged panels, its panels as an array of tables
//! (`[[panel_chains.panels]]`), each with its initial hinge state.
//!
//! Keys are checked by the shared reader ([`flexdyn_kernel::schema`]); values are validated by
//! [`super::PanelChainParams::validate`], whose errors name the same TOML paths
//! (`panel_chains[0].panels[2].mass_kg`).

use super::{ChainPanelParams, PanelChainParams};
use flexdyn_kernel::schema::{mat3, vec3, SchemaError, TableReader};

/// The keys of one `[[panel_chains]]` entry (all required).
pub(crate) const KEYS: [&str; 4] = ["name", "r_h1b_b_m", "dcm_h1b", "panels"];

/// The keys of one panel: `mass_kg`, `inertia_s_kg_m2`, `d_m`, `k_nm_rad`, `c_nm_s_rad` are
/// required, `l_m` too except on the last panel; `theta_h_rad`, `motor_torque_nm`, `theta_rad`
/// and `theta_dot_rad_s` default to 0.
pub(crate) const PANEL_KEYS: [&str; 10] = [
    "mass_kg",
    "inertia_s_kg_m2",
    "d_m",
    "l_m",
    "k_nm_rad",
    "c_nm_s_rad",
    "theta_h_rad",
    "motor_torque_nm",
    "theta_rad",
    "theta_dot_rad_s",
];

/// Reads one entry (shape only; [`PanelChainParams::validate`] checks the values).
pub(crate) fn read(t: &TableReader<'_, '_>) -> Result<PanelChainParams, SchemaError> {
    let tables = t.req_tables("panels", &PANEL_KEYS)?;
    let n = tables.len();
    let panels = tables
        .iter()
        .enumerate()
        .map(|(k, p)| {
            Ok(ChainPanelParams {
                mass_kg: p.f64("mass_kg")?,
                inertia_s_kg_m2: vec3(&p.floats("inertia_s_kg_m2")?),
                d_m: p.f64("d_m")?,
                l_m: if k + 1 == n {
                    p.opt_f64("l_m")?.unwrap_or(0.0)
                } else {
                    p.f64("l_m")?
                },
                k_nm_rad: p.f64("k_nm_rad")?,
                c_nm_s_rad: p.f64("c_nm_s_rad")?,
                theta_h_rad: p.opt_f64("theta_h_rad")?.unwrap_or(0.0),
                motor_torque_nm: p.opt_f64("motor_torque_nm")?.unwrap_or(0.0),
                theta_rad: p.opt_f64("theta_rad")?.unwrap_or(0.0),
                theta_dot_rad_s: p.opt_f64("theta_dot_rad_s")?.unwrap_or(0.0),
            })
        })
        .collect::<Result<Vec<_>, SchemaError>>()?;
    Ok(PanelChainParams {
        name: t.string("name")?,
        r_h1b_b_m: vec3(&t.floats("r_h1b_b_m")?),
        dcm_h1b: mat3(&t.mat3("dcm_h1b")?),
        panels,
    })
}
