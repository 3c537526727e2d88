//! A magnetorquer rod: a commanded magnetic dipole along a body-fixed axis, torqued by the
//! planet's field.
//!
//! τ = m × B (Griffiths, *Introduction to Electrodynamics*, 4th ed., eq. 6.1), with
//! m = μ â, μ the commanded dipole clipped to ±`max_dipole_am2`, â the rod's axis in B, and
//! B_B = \[BN\] B_N from the held [`EnvironmentSample`] rotated by each stage's attitude. The field
//! is uniform over the vehicle, so a rod exerts no force. This is the law of Basilisk's
//! `MtbEffector` as well; there the rods are grouped in one module, here each rod is one entry
//! of the effector list with one input, so a failed rod, a fault or a dispersion names it.
//!
//! The rod is an ideal current source: the dipole follows the command within the frame (no
//! coil inductance, no hysteresis of the core, no residual magnetisation once off). Its own
//! field at a magnetometer (the disturbance flight code must cope with) is the field of a
//! point dipole at `r_mb_b_m` (Griffiths eq. 5.89); the magnetometer folder reads it from
//! [`Magnetorquer::dipole_b_am2`] and [`MagnetorquerParams::r_mb_b_m`].

pub mod kind;
pub mod schema;

use nalgebra::Vector3;

use crate::dynamic_effector::{DynamicEffector, StageState};
use crate::effector::EffectorKind;
use crate::params::Wrench;
use flexdyn_environment::magnetic::dipole_torque_b_nm;
use flexdyn_environment::EnvironmentSample;
use flexdyn_kernel::validate::{
    check_at_most, check_finite, check_positive, check_unit_axis, ParamError, MAX_DIPOLE_AM2,
};

/// Wire tag, configuration section and CSV prefix.
pub const KIND: EffectorKind = EffectorKind {
    name: "magnetorquer",
    wire_tag: flexdyn_proto::effector_kind::MAGNETORQUER,
    column_prefix: "mtq",
};

/// The one input: the commanded dipole along the axis.
pub const INPUT_NAMES: [&str; 1] = ["dipole_am2"];
/// The one output: the dipole applied, after saturation.
pub const OUTPUT_NAMES: [&str; 1] = ["dipole_am2"];

/// Flag bit 0: the command exceeded `max_dipole_am2` and was clipped.
pub const SATURATED: u32 = flexdyn_proto::magnetorquer_flags::SATURATED;

/// One rod (`[[magnetorquers]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct MagnetorquerParams {
    /// Name used in logs, messages and telemetry.
    pub name: String,
    /// The rod's axis â in B components (a unit vector within [`flexdyn_kernel::validate::UNIT_AXIS_TOL`]); a positive
    /// dipole points along it.
    pub axis_b: Vector3<f64>,
    /// \[m\] the rod's centre M relative to B, B components (where its own field comes from).
    pub r_mb_b_m: Vector3<f64>,
    /// \[A·m²\] the largest dipole magnitude the rod can make.
    pub max_dipole_am2: f64,
}

impl MagnetorquerParams {
    /// Validates the rod (`path` is e.g. `magnetorquers[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_unit_axis(path, "axis_b", &self.axis_b)?;
        check_finite(path, "r_mb_b_m", self.r_mb_b_m.as_slice())?;
        check_positive(path, "max_dipole_am2", self.max_dipole_am2)?;
        check_at_most(
            path,
            "max_dipole_am2",
            self.max_dipole_am2,
            MAX_DIPOLE_AM2,
            "the largest dipole flexdyn accepts, in A·m²; flown rods make a few hundred",
        )
    }
}

/// A built rod: its parameters, its configuration path and the dipole it makes now.
#[derive(Debug, Clone)]
pub struct Magnetorquer {
    params: MagnetorquerParams,
    path: String,
    /// \[A·m²\] the applied dipole (the command clipped to ±max).
    dipole_am2: f64,
    saturated: bool,
}

impl Magnetorquer {
    /// Builds a rod after validating it; `path` (`magnetorquers[0]`) names its fields in errors
    /// and in [`DynamicEffector::parameters`].
    pub fn new(params: MagnetorquerParams, path: &str) -> Result<Self, ParamError> {
        params.validate(path)?;
        Ok(Self {
            params,
            path: path.to_string(),
            dipole_am2: 0.0,
            saturated: false,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &MagnetorquerParams {
        &self.params
    }

    /// \[A·m²\] the dipole the rod makes now, B components.
    pub fn dipole_b_am2(&self) -> Vector3<f64> {
        self.params.axis_b * self.dipole_am2
    }
}

impl DynamicEffector for Magnetorquer {
    fn name(&self) -> &str {
        &self.params.name
    }

    fn add_force_torque(&mut self, stage: &StageState, env: &EnvironmentSample, sum: &mut Wrench) {
        if self.dipole_am2 == 0.0 {
            // An idle rod's m × B is ±0 in each component: it adds nothing (as for a shut
            // thruster, only an exactly −0 sum would differ, by its sign).
            return;
        }
        let b_b_t = stage.dcm_bn * env.b_field_n_t;
        sum.torque_b_nm += dipole_torque_b_nm(&self.dipole_b_am2(), &b_b_t);
    }

    fn magnetic_dipole_b(&self) -> Option<(Vector3<f64>, Vector3<f64>)> {
        Some((self.params.r_mb_b_m, self.dipole_b_am2()))
    }

    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        let p = &self.params;
        for i in 0..3 {
            out.push((format!("{}.axis_b[{i}]", self.path), p.axis_b[i]));
        }
        for i in 0..3 {
            out.push((format!("{}.r_mb_b_m[{i}]", self.path), p.r_mb_b_m[i]));
        }
        out.push((format!("{}.max_dipole_am2", self.path), p.max_dipole_am2));
    }

    fn listed_kind(&self) -> Option<EffectorKind> {
        Some(KIND)
    }

    fn input_names(&self) -> &'static [&'static str] {
        &INPUT_NAMES
    }

    fn set_inputs(&mut self, u: &[f64]) {
        let max = self.params.max_dipole_am2;
        self.saturated = u[0].abs() > max;
        self.dipole_am2 = u[0].clamp(-max, max);
    }

    fn output_names(&self) -> &'static [&'static str] {
        &OUTPUT_NAMES
    }

    fn outputs(&self, out: &mut [f64]) -> u32 {
        out[0] = self.dipole_am2;
        if self.saturated {
            SATURATED
        } else {
            0
        }
    }

    /// The held dipole and its saturation flag.
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        let Self {
            params: _,
            path: _,
            dipole_am2,
            saturated,
        } = self;
        a.put(dipole_am2);
        a.put(saturated);
    }
}

#[cfg(test)]
mod tests;
