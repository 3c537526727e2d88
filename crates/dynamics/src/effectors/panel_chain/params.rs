//! Parameters of an N-link hinged panel chain: plain data, validated here with errors that name
//! the configuration path (`panel_chains[0].panels[2].mass_kg`).

use nalgebra::{Matrix3, Vector3};

use flexdyn_kernel::validate::{
    check_dcm, check_finite, check_non_negative, check_positive, check_principal_moments, join,
    ParamError,
};

use super::MAX_LINKS;

/// One rigid panel (link) of a chain, with its hinge to the previous body and its initial state.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainPanelParams {
    /// \[kg\] panel mass m_k.
    pub mass_kg: f64,
    /// \[kg·m²\] principal inertia about the panel centre of mass, in its S_k frame:
    /// (I_sk1, I_sk2, I_sk3); ŝ_k2 is the common hinge axis.
    pub inertia_s_kg_m2: Vector3<f64>,
    /// \[m\] d_k: distance from the panel's hinge H_k to its centre of mass, along −ŝ_k1.
    pub d_m: f64,
    /// \[m\] l_k: distance from the panel's hinge H_k to the next hinge H_k+1, along −ŝ_k1.
    /// Required on every panel but the last, where it only bounds `d_m` (0 when not given).
    pub l_m: f64,
    /// \[N·m/rad\] k_k: torsional stiffness of hinge k.
    pub k_nm_rad: f64,
    /// \[N·m·s/rad\] c_k: torsional damping of hinge k.
    pub c_nm_s_rad: f64,
    /// \[rad\] θ_Hk: fixed rotation about the hinge axis of hinge k's frame relative to the
    /// previous panel's frame S_k−1 (relative to H1 for panel 1): [H_k S_k−1] = M2(θ_Hk), as the
    /// pair's `theta_h2s1_rad`. π folds panel k back over panel k − 1.
    pub theta_h_rad: f64,
    /// \[N·m\] u_k: the hinge motor torque at start-up, on panel k about +ê (panel k − 1, or the
    /// hub, takes the reaction). Flight code commands it as input k.
    pub motor_torque_nm: f64,
    /// \[rad\] θ_k at t = 0: panel k's deflection relative to panel k − 1 (to H1 for panel 1).
    pub theta_rad: f64,
    /// \[rad/s\] θ̇_k at t = 0.
    pub theta_dot_rad_s: f64,
}

/// A chain of N ≥ 1 rigid panels hinged in series: panel 1 to the hub at H1, panel k + 1 to the
/// tip of panel k at H_k+1 = H_k − l_k ŝ_k1. Every hinge axis is ê = ĥ12, the second row of
/// `dcm_h1b`.
#[derive(Debug, Clone, PartialEq)]
pub struct PanelChainParams {
    /// Name used in logs, messages and telemetry (unique among the chains).
    pub name: String,
    /// \[m\] hinge 1 location H1 relative to B, in B components.
    pub r_h1b_b_m: Vector3<f64>,
    /// DCM [H1 B]: maps B components to hinge-1 frame components (rows ĥ11, ĥ12, ĥ13 in B).
    pub dcm_h1b: Matrix3<f64>,
    /// The panels, from the hub outwards (1 ≤ N ≤ [`MAX_LINKS`]).
    pub panels: Vec<ChainPanelParams>,
}

impl ChainPanelParams {
    /// Validates one panel (`path` is e.g. `panel_chains[0].panels[2]`); `last` says whether
    /// it is the outermost one (whose `l_m` may be 0).
    pub fn validate(&self, path: &str, last: bool) -> Result<(), ParamError> {
        check_positive(path, "mass_kg", self.mass_kg)?;
        check_finite(path, "inertia_s_kg_m2", self.inertia_s_kg_m2.as_slice())?;
        let i = &self.inertia_s_kg_m2;
        check_principal_moments(path, "inertia_s_kg_m2", &[i.x, i.y, i.z])?;
        check_positive(path, "d_m", self.d_m)?;
        if last {
            check_non_negative(path, "l_m", self.l_m)?;
        } else {
            check_positive(path, "l_m", self.l_m)?;
        }
        if (!last || self.l_m > 0.0) && self.d_m > self.l_m {
            return Err(ParamError::DExceedsLength {
                field: join(path, "d_m"),
                d_m: self.d_m,
                l_m: self.l_m,
            });
        }
        check_non_negative(path, "k_nm_rad", self.k_nm_rad)?;
        check_non_negative(path, "c_nm_s_rad", self.c_nm_s_rad)?;
        check_finite(path, "theta_h_rad", &[self.theta_h_rad])?;
        check_finite(path, "motor_torque_nm", &[self.motor_torque_nm])?;
        check_finite(path, "theta_rad", &[self.theta_rad])?;
        check_finite(path, "theta_dot_rad_s", &[self.theta_dot_rad_s])
    }
}

impl PanelChainParams {
    /// Validates the chain (`path` is e.g. `panel_chains[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_finite(path, "r_h1b_b_m", self.r_h1b_b_m.as_slice())?;
        check_dcm(path, "dcm_h1b", &self.dcm_h1b)?;
        let n = self.panels.len();
        if n == 0 || n > MAX_LINKS {
            return Err(ParamError::Invalid {
                field: join(path, "panels"),
                problem: format!("has {n} panels; a chain has 1 to {MAX_LINKS}"),
            });
        }
        let panels = join(path, "panels");
        for (k, p) in self.panels.iter().enumerate() {
            p.validate(&format!("{panels}[{k}]"), k + 1 == n)?;
        }
        Ok(())
    }
}

impl PanelChainParams {
    /// The two-panel chain of a dual-hinged pair and its initial state: the same bodies, hinges
    /// and motor torques (the pair's `theta_h2s1_rad` is panel 2's `theta_h_rad`).
    pub fn from_pair(
        pair: &crate::effectors::panel_pair::PanelPairParams,
        initial: &crate::effectors::panel_pair::PanelPairInitial,
    ) -> Self {
        let panel = |p: &crate::effectors::panel_pair::PanelParams,
                     l_m: f64,
                     theta_h_rad: f64,
                     motor_torque_nm: f64,
                     theta_rad: f64,
                     theta_dot_rad_s: f64| ChainPanelParams {
            mass_kg: p.mass_kg,
            inertia_s_kg_m2: p.inertia_s_kg_m2,
            d_m: p.d_m,
            l_m,
            k_nm_rad: p.k_nm_rad,
            c_nm_s_rad: p.c_nm_s_rad,
            theta_h_rad,
            motor_torque_nm,
            theta_rad,
            theta_dot_rad_s,
        };
        Self {
            name: pair.name.clone(),
            r_h1b_b_m: pair.r_h1b_b_m,
            dcm_h1b: pair.dcm_h1b,
            panels: vec![
                panel(
                    &pair.panel1,
                    pair.l1_m,
                    0.0,
                    pair.motor_torque_nm[0],
                    initial.theta1_rad,
                    initial.theta1_dot_rad_s,
                ),
                panel(
                    &pair.panel2,
                    0.0,
                    pair.theta_h2s1_rad,
                    pair.motor_torque_nm[1],
                    initial.theta2_rad,
                    initial.theta2_dot_rad_s,
                ),
            ],
        }
    }
}
