//! The `[[panel_pairs]]` schema: one dual-hinged panel pair and its initial hinge states.
//!
//! Keys are checked by the shared reader ([`flexdyn_kernel::schema`]); values are validated by
//! [`super::PanelPair::new`], whose errors name the same TOML paths.

use super::{PanelPairInitial, PanelPairParams, PanelParams};
use flexdyn_kernel::schema::{mat3, vec3, SchemaError, TableReader};

/// The keys of one `[[panel_pairs]]` entry.
pub const KEYS: [&str; 7] = [
    "name",
    "r_h1b_b_m",
    "dcm_h1b",
    "theta_h2s1_rad",
    "motor_torque_nm",
    "panel1",
    "panel2",
];

/// One `[[panel_pairs]]` entry as written (values checked by [`PanelPairParams::validate`]).
pub struct RawPanelPair {
    /// The pair's name (unique among the pairs: the configuration checks it).
    pub name: String,
    r_h1b_b_m: [f64; 3],
    dcm_h1b: [[f64; 3]; 3],
    theta_h2s1_rad: f64,
    motor_torque_nm: Option<[f64; 2]>,
    panel1: RawPanel,
    panel2: RawPanel,
}

/// Panel 1 has `l_m`; panel 2 does not (the reader enforces which keys each allows).
pub(crate) struct RawPanel {
    mass_kg: f64,
    inertia_s_kg_m2: [f64; 3],
    d_m: f64,
    l_m: Option<f64>,
    k_nm_rad: f64,
    c_nm_s_rad: f64,
    theta_rad: f64,
    theta_dot_rad_s: f64,
    width_m: Option<f64>,
    thickness_m: Option<f64>,
}

impl RawPanelPair {
    /// Reads one entry's shape.
    pub fn read(t: &TableReader<'_, '_>) -> Result<Self, SchemaError> {
        const PANEL2: [&str; 9] = [
            "mass_kg",
            "inertia_s_kg_m2",
            "d_m",
            "k_nm_rad",
            "c_nm_s_rad",
            "theta_rad",
            "theta_dot_rad_s",
            "width_m",
            "thickness_m",
        ];
        let panel1_keys: Vec<&str> = PANEL2.iter().copied().chain(["l_m"]).collect();
        let read_panel =
            |p: &TableReader<'_, '_>, has_length: bool| -> Result<RawPanel, SchemaError> {
                Ok(RawPanel {
                    mass_kg: p.f64("mass_kg")?,
                    inertia_s_kg_m2: p.floats("inertia_s_kg_m2")?,
                    d_m: p.f64("d_m")?,
                    l_m: if has_length {
                        Some(p.f64("l_m")?)
                    } else {
                        None
                    },
                    k_nm_rad: p.f64("k_nm_rad")?,
                    c_nm_s_rad: p.f64("c_nm_s_rad")?,
                    theta_rad: p.f64("theta_rad")?,
                    theta_dot_rad_s: p.f64("theta_dot_rad_s")?,
                    width_m: p.opt_f64("width_m")?,
                    thickness_m: p.opt_f64("thickness_m")?,
                })
            };
        Ok(RawPanelPair {
            name: t.string("name")?,
            r_h1b_b_m: t.floats("r_h1b_b_m")?,
            dcm_h1b: t.mat3("dcm_h1b")?,
            theta_h2s1_rad: t.f64("theta_h2s1_rad")?,
            motor_torque_nm: t.opt_floats("motor_torque_nm")?,
            panel1: read_panel(&t.table("panel1", &panel1_keys)?, true)?,
            panel2: read_panel(&t.table("panel2", &PANEL2)?, false)?,
        })
    }
}

impl RawPanelPair {
    /// The pair's parameters and initial hinge states, as written (not yet validated).
    pub fn into_params(self) -> (PanelPairParams, PanelPairInitial) {
        let p1 = &self.panel1;
        let p2 = &self.panel2;
        let params = PanelPairParams {
            name: self.name,
            r_h1b_b_m: vec3(&self.r_h1b_b_m),
            dcm_h1b: mat3(&self.dcm_h1b),
            theta_h2s1_rad: self.theta_h2s1_rad,
            l1_m: p1.l_m.unwrap_or_default(),
            panel1: PanelParams {
                mass_kg: p1.mass_kg,
                inertia_s_kg_m2: vec3(&p1.inertia_s_kg_m2),
                d_m: p1.d_m,
                k_nm_rad: p1.k_nm_rad,
                c_nm_s_rad: p1.c_nm_s_rad,
                width_m: p1.width_m,
                thickness_m: p1.thickness_m,
            },
            panel2: PanelParams {
                mass_kg: p2.mass_kg,
                inertia_s_kg_m2: vec3(&p2.inertia_s_kg_m2),
                d_m: p2.d_m,
                k_nm_rad: p2.k_nm_rad,
                c_nm_s_rad: p2.c_nm_s_rad,
                width_m: p2.width_m,
                thickness_m: p2.thickness_m,
            },
            motor_torque_nm: self.motor_torque_nm.unwrap_or([0.0, 0.0]),
        };
        let initial = PanelPairInitial {
            theta1_rad: p1.theta_rad,
            theta1_dot_rad_s: p1.theta_dot_rad_s,
            theta2_rad: p2.theta_rad,
            theta2_dot_rad_s: p2.theta_dot_rad_s,
        };
        (params, initial)
    }
}
