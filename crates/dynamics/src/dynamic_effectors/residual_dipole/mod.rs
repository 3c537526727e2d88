//! The torque of the spacecraft's residual magnetic dipole in the planet's field.
//!
//! τ = m × B (Griffiths, *Introduction to Electrodynamics*, 4th ed., eq. 6.1), with the
//! configured dipole m fixed in B and the field of the held [`EnvironmentSample`] rotated into
//! B by the stage's \[BN\]: B_B = \[BN\] B_N. The field is uniform over the vehicle, so there is no
//! force. A magnetorquer's commanded dipole obeys the same law; this effector is the part of the
//! vehicle's moment that nobody commands (currents in harnesses and solar arrays, magnetised
//! parts), typically 0.01–1 A·m² on a small satellite.
//!
//! Neglected: the field's change within an environment update (held), and any induced
//! (field-dependent) part of the dipole.

use nalgebra::Vector3;

use crate::dynamic_effector::{DynamicEffector, EnvironmentSource, StageState};
use crate::params::Wrench;
use flexdyn_environment::magnetic::dipole_torque_b_nm;
use flexdyn_environment::EnvironmentSample;

/// A constant magnetic dipole fixed in the body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualDipole {
    /// \[A·m²\] the dipole moment, B components.
    pub m_b_am2: Vector3<f64>,
}

impl DynamicEffector for ResidualDipole {
    fn name(&self) -> &str {
        "residual_dipole"
    }

    fn environment_source(&self) -> Option<EnvironmentSource> {
        Some(EnvironmentSource::ResidualDipole)
    }

    fn add_force_torque(&mut self, stage: &StageState, env: &EnvironmentSample, sum: &mut Wrench) {
        let b_b_t = stage.dcm_bn * env.b_field_n_t;
        sum.torque_b_nm += dipole_torque_b_nm(&self.m_b_am2, &b_b_t);
    }

    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        for i in 0..3 {
            out.push((
                format!("environment.residual_dipole_m_b_am2[{i}]"),
                self.m_b_am2[i],
            ));
        }
    }

    /// Nothing: its parameters are configuration (a held Sun is memoised from its inputs).
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
}
