//! The actuator sections of a configuration: `[[magnetorquers]]` and `[[thrusters]]`.
//!
//! Each kind's reader and validation live in its folder (`dynamics::dynamic_effectors::*`); this
//! file registers the sections, checks names for uniqueness within a kind, and gives the count
//! and the wire size of their state-record entries to the capacity check. An actuator is listed
//! after the appended bodies in the effector list (magnetorquers, then thrusters, each in file
//! order) and takes its inputs from `Actuators` commands by that index.

use std::collections::HashSet;

use flexdyn_proto::EFFECTOR_STATE_FIXED_LEN;

use crate::dynamics::dynamic_effectors::magnetorquer::{self, MagnetorquerParams};
use crate::dynamics::dynamic_effectors::thruster::{self, ThrusterParams};
use crate::schema::TableReader;

use super::{unique_name, ConfigError, SourceMap};

/// The root keys this file registers.
pub(super) const ROOT_KEYS: [&str; 2] = ["magnetorquers", "thrusters"];

/// The actuator sections, as read (shape checked, values not yet).
#[derive(Default)]
pub(super) struct RawActuators {
    magnetorquers: Vec<MagnetorquerParams>,
    thrusters: Vec<ThrusterParams>,
}

/// The actuators, validated.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Actuators {
    /// Magnetorquer rods (`[[magnetorquers]]`), in file order.
    pub magnetorquers: Vec<MagnetorquerParams>,
    /// Thrusters (`[[thrusters]]`), in file order.
    pub thrusters: Vec<ThrusterParams>,
}

impl RawActuators {
    /// Reads both sections (each optional).
    pub(super) fn read(root: &TableReader<'_, '_>) -> Result<Self, ConfigError> {
        let magnetorquers = root
            .tables(ROOT_KEYS[0], &magnetorquer::schema::KEYS)?
            .unwrap_or_default()
            .iter()
            .map(magnetorquer::schema::read)
            .collect::<Result<Vec<_>, _>>()?;
        let thrusters = root
            .tables(ROOT_KEYS[1], &thruster::schema::KEYS)?
            .unwrap_or_default()
            .iter()
            .map(thruster::schema::read)
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            magnetorquers,
            thrusters,
        })
    }

    /// Validates every actuator for frames of `frame_ns`; errors name the entry and the field.
    pub(super) fn resolve(self, map: &SourceMap, frame_ns: u64) -> Result<Actuators, ConfigError> {
        let mut names = HashSet::new();
        for (i, p) in self.magnetorquers.iter().enumerate() {
            let path = format!("{}[{i}]", ROOT_KEYS[0]);
            unique_name(map, &path, &p.name, &mut names, "magnetorquer")?;
            p.validate(&path).map_err(|e| map.param_error(e))?;
        }
        let mut names = HashSet::new();
        for (i, p) in self.thrusters.iter().enumerate() {
            let path = format!("{}[{i}]", ROOT_KEYS[1]);
            unique_name(map, &path, &p.name, &mut names, "thruster")?;
            p.validate(&path, frame_ns)
                .map_err(|e| map.param_error(e))?;
        }
        Ok(Actuators {
            magnetorquers: self.magnetorquers,
            thrusters: self.thrusters,
        })
    }
}

impl Actuators {
    /// Number of effector entries they add to the state record.
    pub fn len(&self) -> usize {
        self.magnetorquers.len() + self.thrusters.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// \[bytes\] their entries in the state record: the fixed part and 8 bytes per output (they
    /// have no states).
    pub(super) fn wire_bytes(&self) -> usize {
        let entry = |outputs: usize| EFFECTOR_STATE_FIXED_LEN + 8 * outputs;
        self.magnetorquers.len() * entry(magnetorquer::OUTPUT_NAMES.len())
            + self.thrusters.len() * entry(thruster::OUTPUT_NAMES.len())
    }
}
