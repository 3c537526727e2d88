//! Parameters of a dual-hinged panel pair: plain data, validated here with errors that name the
//! configuration path.

use nalgebra::{Matrix3, Vector3};

use flexdyn_kernel::validate::{
    check_dcm, check_finite, check_non_negative, check_positive, check_principal_moments, join,
    ParamError,
};

/// One rigid panel of a dual-hinged pair.
#[derive(Debug, Clone, PartialEq)]
pub struct PanelParams {
    /// \[kg\] panel mass.
    pub mass_kg: f64,
    /// [kg·m²] principal inertia about the panel centre of mass, in its S frame: (I_s1, I_s2, I_s3).
    pub inertia_s_kg_m2: Vector3<f64>,
    /// \[m\] distance from the panel's hinge to its centre of mass, along −ŝ1.
    pub d_m: f64,
    /// [N·m/rad] torsional stiffness of the panel's hinge.
    pub k_nm_rad: f64,
    /// [N·m·s/rad] torsional damping of the panel's hinge.
    pub c_nm_s_rad: f64,
    /// \[m\] the panel's width along its hinge axis ŝ2, if given: drawn (`flexdyn view`) instead
    /// of the width of the box with the panel's inertia. Not used by the dynamics.
    pub width_m: Option<f64>,
    /// \[m\] the panel's thickness along ŝ3, if given; drawn like `width_m`.
    pub thickness_m: Option<f64>,
}

/// A pair of dual-linked hinged panels: panel 1 hinged to the hub at H1, panel 2 hinged to the tip
/// of panel 1 at H2 (a distance `l1_m` from H1 along −ŝ11).
#[derive(Debug, Clone, PartialEq)]
pub struct PanelPairParams {
    /// Name used in logs and error messages.
    pub name: String,
    /// \[m\] hinge 1 location H1 relative to B, in B components.
    pub r_h1b_b_m: Vector3<f64>,
    /// DCM \[H1B\]: maps B components to hinge-1 frame H1 components (rows are ĥ1, ĥ2, ĥ3 in B).
    pub dcm_h1b: Matrix3<f64>,
    /// \[rad\] fixed rotation of the hinge-2 frame H2 about the (common) hinge axis ŝ12,
    /// relative to S1: [H2 S1] = M2(theta_h2s1). Non-zero models folded or undeployed wings.
    pub theta_h2s1_rad: f64,
    /// \[m\] length of panel 1 (hinge 1 to hinge 2).
    pub l1_m: f64,
    /// Panel 1 (inboard).
    pub panel1: PanelParams,
    /// Panel 2 (outboard).
    pub panel2: PanelParams,
    /// [N·m] constant motor torques at (hinge 1, hinge 2). Hinge 1's motor acts between the hub and
    /// panel 1, hinge 2's between panel 1 and panel 2; both are internal torques.
    pub motor_torque_nm: [f64; 2],
}

/// Initial state of one pair.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PanelPairInitial {
    /// \[rad\] θ1, panel 1 deflection about ŝ12 from H1.
    pub theta1_rad: f64,
    /// [rad/s] θ̇1.
    pub theta1_dot_rad_s: f64,
    /// \[rad\] θ2, panel 2 deflection relative to panel 1 (and H2).
    pub theta2_rad: f64,
    /// [rad/s] θ̇2.
    pub theta2_dot_rad_s: f64,
}

impl PanelParams {
    /// Validates one panel (`path` is e.g. `panel_pairs[0].panel1`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_positive(path, "mass_kg", self.mass_kg)?;
        check_finite(path, "inertia_s_kg_m2", self.inertia_s_kg_m2.as_slice())?;
        check_principal_moments(
            path,
            "inertia_s_kg_m2",
            &[
                self.inertia_s_kg_m2.x,
                self.inertia_s_kg_m2.y,
                self.inertia_s_kg_m2.z,
            ],
        )?;
        check_positive(path, "d_m", self.d_m)?;
        check_non_negative(path, "k_nm_rad", self.k_nm_rad)?;
        check_non_negative(path, "c_nm_s_rad", self.c_nm_s_rad)?;
        for (field, v) in [("width_m", self.width_m), ("thickness_m", self.thickness_m)] {
            if let Some(v) = v {
                check_positive(path, field, v)?;
            }
        }
        Ok(())
    }
}

impl PanelPairParams {
    /// Validates the pair (`path` is e.g. `panel_pairs[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_finite(path, "r_h1b_b_m", self.r_h1b_b_m.as_slice())?;
        check_dcm(path, "dcm_h1b", &self.dcm_h1b)?;
        check_finite(path, "theta_h2s1_rad", &[self.theta_h2s1_rad])?;
        check_finite(path, "motor_torque_nm", &self.motor_torque_nm)?;
        let p1 = join(path, "panel1");
        self.panel1.validate(&p1)?;
        self.panel2.validate(&join(path, "panel2"))?;
        check_positive(&p1, "l_m", self.l1_m)?;
        if self.panel1.d_m > self.l1_m {
            return Err(ParamError::DExceedsLength {
                field: join(&p1, "d_m"),
                d_m: self.panel1.d_m,
                l_m: self.l1_m,
            });
        }
        Ok(())
    }
}

impl PanelPairInitial {
    /// Validates the initial panel state (all finite).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        let p1 = join(path, "panel1");
        let p2 = join(path, "panel2");
        check_finite(&p1, "theta_rad", &[self.theta1_rad])?;
        check_finite(&p1, "theta_dot_rad_s", &[self.theta1_dot_rad_s])?;
        check_finite(&p2, "theta_rad", &[self.theta2_rad])?;
        check_finite(&p2, "theta_dot_rad_s", &[self.theta2_dot_rad_s])
    }
}
