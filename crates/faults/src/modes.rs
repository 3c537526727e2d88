//! The fault modes and their transforms: what a fault does to the value at its port.
//!
//! Sensor modes transform each selected axis `x` of a sample's output channel (the healthy
//! value the sensor model produced) into the published value `y`; `t_on_s` is the time since the
//! fault's current activation began (\[s\]), `x_on` the healthy value at the first sample of
//! that activation that carries a measurement ([`flexdyn_sensors::Sensor::is_valid`]: a GPS
//! receiver's samples without a fix go out as measured until the first with one):
//!
//! | mode | parameters | y |
//! |---|---|---|
//! | `stuck_current` | — | `x_on` |
//! | `stuck_value` | `value` | `value` |
//! | `bias_step` | `value` | `x + value` |
//! | `bias_ramp` | `rate_per_s` | `x + rate_per_s · t_on_s` |
//! | `scale` | `factor` | `factor · x` |
//! | `noise` | `sigma` | `x + sigma · n`, n one standard normal |
//! | `spikes` | `probability`, `amplitude` | `x + s · amplitude` when u₁ < `probability`, else `x`; s = +1 if u₂ < ½ else −1 |
//! | `dropout` | — | no message is published |
//! | `validity_off` | — | the sample is marked invalid (kinds with a validity flag) |
//!
//! Random draws come from the fault's own generator ([`flexdyn_sensors::rng::NormalRng`] seeded
//! with the fault's `seed`), per sample, per selected axis in axis order: `noise` draws one
//! normal, `spikes` draws u₁ then u₂ (both every time, so the stream does not depend on the
//! outcome). Units are the channel's own (rad/s for a gyro, T for a magnetometer…).
//!
//! Actuator modes transform the effector's input (command + schedule) before it reaches the
//! model; the models themselves are untouched (see [`super::ports`] for the physics of each).
//!
//! Command-link modes act on a participant's commands where the server takes them in (see
//! [`super::link`]): `dropped` (never arrive), `delayed` by `frames` frames, `corrupted` (each
//! bit of the payload flipped with `probability`).

/// A fault mode with its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FaultMode {
    /// Sensor: held at the healthy value of the activation's first valid sample.
    StuckCurrent,
    /// Sensor: held at `value`.
    StuckValue {
        /// The value, in the channel's unit.
        value: f64,
    },
    /// Sensor: `value` added.
    BiasStep {
        /// The bias, in the channel's unit.
        value: f64,
    },
    /// Sensor: a bias growing at `rate_per_s` from the activation.
    BiasRamp {
        /// \[unit/s\] the bias rate.
        rate_per_s: f64,
    },
    /// Sensor: multiplied by `factor`.
    Scale {
        /// The scale factor.
        factor: f64,
    },
    /// Sensor: extra white Gaussian noise of standard deviation `sigma`.
    Noise {
        /// The standard deviation, in the channel's unit.
        sigma: f64,
    },
    /// Sensor: ±`amplitude` added with probability `probability` per sample and axis.
    Spikes {
        /// Per sample and axis, in [0, 1].
        probability: f64,
        /// The spike's size, in the channel's unit.
        amplitude: f64,
    },
    /// Sensor: nothing published.
    Dropout,
    /// Sensor: the validity flag forced off.
    ValidityOff,
    /// Reaction wheel: the bearing friction multiplied by `factor` (≥ 0).
    FrictionScale {
        /// The friction multiplier.
        factor: f64,
    },
    /// Reaction wheel: the motor torque limited to `fraction` of `max_torque_nm`.
    TorqueLimit {
        /// In [0, 1].
        fraction: f64,
    },
    /// Reaction wheel: the bearing seized (the rotor is braked to rest and held).
    Seized,
    /// Reaction wheel: the motor ignores its command (zero motor torque).
    CommandIgnored,
    /// Thruster: the valve stuck open (full on-time or duty cycle every frame).
    StuckOn,
    /// Thruster: the valve stuck closed.
    StuckOff,
    /// Thruster: the impulse per frame scaled by `factor` (≥ 0).
    ThrustScale {
        /// The scale factor.
        factor: f64,
    },
    /// Magnetorquer: no dipole.
    Dead,
    /// Magnetorquer: the commanded dipole scaled by `factor`.
    DipoleScale {
        /// The scale factor.
        factor: f64,
    },
    /// Command link: the participant's commands never arrive.
    Dropped,
    /// Command link: the participant's command applied at tick k is the one it sent for
    /// k − `frames`.
    Delayed {
        /// The delay \[frames\], a whole number in 1..=[`MAX_DELAY_FRAMES`].
        frames: f64,
    },
    /// Command link: each bit of each command's payload flipped with `probability` (the bit
    /// error rate), from the fault's seed and the tick.
    Corrupted {
        /// In [0, 1].
        probability: f64,
    },
}

/// The longest link delay \[frames\] (the delay line holds that many commands per participant).
pub const MAX_DELAY_FRAMES: f64 = 10_000.0;

/// Every mode's configuration name and its parameter keys, in the order of [`FaultMode`].
pub const MODES: &[(&str, &[&str])] = &[
    ("stuck_current", &[]),
    ("stuck_value", &["value"]),
    ("bias_step", &["value"]),
    ("bias_ramp", &["rate_per_s"]),
    ("scale", &["factor"]),
    ("noise", &["sigma"]),
    ("spikes", &["probability", "amplitude"]),
    ("dropout", &[]),
    ("validity_off", &[]),
    ("friction_scale", &["factor"]),
    ("torque_limit", &["fraction"]),
    ("seized", &[]),
    ("command_ignored", &[]),
    ("stuck_on", &[]),
    ("stuck_off", &[]),
    ("thrust_scale", &["factor"]),
    ("dead", &[]),
    ("dipole_scale", &["factor"]),
    ("dropped", &[]),
    ("delayed", &["frames"]),
    ("corrupted", &["probability"]),
];

/// The modes a command link (`links.<sender id>`) takes: the last three wire codes
/// (`dropped`, `delayed`, `corrupted`; the table is [`flexdyn_proto::FAULT_MODE_NAMES`], which
/// the tests below check [`MODES`] against).
pub const LINK_MODES: &[&str] = flexdyn_proto::FAULT_MODE_NAMES.split_at(18).1;

/// The modes every sensor kind takes (`validity_off` only where
/// [`flexdyn_sensors::Sensor::has_validity`]): the first nine wire codes, `stuck_current` …
/// `validity_off`.
pub const SENSOR_MODES: &[&str] = flexdyn_proto::FAULT_MODE_NAMES.split_at(9).0;

/// The sensor modes that transform values (all but `dropout` and `validity_off`, the first
/// seven of [`SENSOR_MODES`]): they need a channel with axes.
pub const VALUE_MODES: &[&str] = SENSOR_MODES.split_at(7).0;

impl FaultMode {
    /// The mode named `name` with its parameters from `param` (a parameter's value by key; the
    /// caller has checked that exactly the mode's keys are present). `None` for an unknown name.
    pub fn from_name(name: &str, param: impl Fn(&str) -> f64) -> Option<Self> {
        Some(match name {
            "stuck_current" => Self::StuckCurrent,
            "stuck_value" => Self::StuckValue {
                value: param("value"),
            },
            "bias_step" => Self::BiasStep {
                value: param("value"),
            },
            "bias_ramp" => Self::BiasRamp {
                rate_per_s: param("rate_per_s"),
            },
            "scale" => Self::Scale {
                factor: param("factor"),
            },
            "noise" => Self::Noise {
                sigma: param("sigma"),
            },
            "spikes" => Self::Spikes {
                probability: param("probability"),
                amplitude: param("amplitude"),
            },
            "dropout" => Self::Dropout,
            "validity_off" => Self::ValidityOff,
            "friction_scale" => Self::FrictionScale {
                factor: param("factor"),
            },
            "torque_limit" => Self::TorqueLimit {
                fraction: param("fraction"),
            },
            "seized" => Self::Seized,
            "command_ignored" => Self::CommandIgnored,
            "stuck_on" => Self::StuckOn,
            "stuck_off" => Self::StuckOff,
            "thrust_scale" => Self::ThrustScale {
                factor: param("factor"),
            },
            "dead" => Self::Dead,
            "dipole_scale" => Self::DipoleScale {
                factor: param("factor"),
            },
            "dropped" => Self::Dropped,
            "delayed" => Self::Delayed {
                frames: param("frames"),
            },
            "corrupted" => Self::Corrupted {
                probability: param("probability"),
            },
            _ => return None,
        })
    }

    /// Its configuration name.
    pub fn name(&self) -> &'static str {
        MODES[self.index()].0
    }

    /// Its index in [`MODES`] (also its wire code).
    pub fn index(&self) -> usize {
        match self {
            Self::StuckCurrent => 0,
            Self::StuckValue { .. } => 1,
            Self::BiasStep { .. } => 2,
            Self::BiasRamp { .. } => 3,
            Self::Scale { .. } => 4,
            Self::Noise { .. } => 5,
            Self::Spikes { .. } => 6,
            Self::Dropout => 7,
            Self::ValidityOff => 8,
            Self::FrictionScale { .. } => 9,
            Self::TorqueLimit { .. } => 10,
            Self::Seized => 11,
            Self::CommandIgnored => 12,
            Self::StuckOn => 13,
            Self::StuckOff => 14,
            Self::ThrustScale { .. } => 15,
            Self::Dead => 16,
            Self::DipoleScale { .. } => 17,
            Self::Dropped => 18,
            Self::Delayed { .. } => 19,
            Self::Corrupted { .. } => 20,
        }
    }

    /// Its parameters in the order of its [`MODES`] row, unused ones 0 (the wire's `params`).
    pub fn params(&self) -> [f64; 2] {
        match *self {
            Self::StuckValue { value } | Self::BiasStep { value } => [value, 0.0],
            Self::BiasRamp { rate_per_s } => [rate_per_s, 0.0],
            Self::Scale { factor }
            | Self::FrictionScale { factor }
            | Self::ThrustScale { factor }
            | Self::DipoleScale { factor } => [factor, 0.0],
            Self::Noise { sigma } => [sigma, 0.0],
            Self::Spikes {
                probability,
                amplitude,
            } => [probability, amplitude],
            Self::TorqueLimit { fraction } => [fraction, 0.0],
            Self::Delayed { frames } => [frames, 0.0],
            Self::Corrupted { probability } => [probability, 0.0],
            _ => [0.0, 0.0],
        }
    }

    /// The first parameter out of its range, as `(key, problem)`.
    pub fn check(&self) -> Option<(&'static str, &'static str)> {
        let nonneg = |v: f64| v >= 0.0;
        match *self {
            Self::Noise { sigma } if !nonneg(sigma) => Some(("sigma", "must be ≥ 0")),
            Self::Spikes { probability, .. } | Self::Corrupted { probability }
                if !(0.0..=1.0).contains(&probability) =>
            {
                Some(("probability", "must be in [0, 1]"))
            }
            Self::Delayed { frames }
                if !(frames.fract() == 0.0 && (1.0..=MAX_DELAY_FRAMES).contains(&frames)) =>
            {
                Some(("frames", "must be a whole number of frames from 1 to 10000"))
            }
            Self::FrictionScale { factor } | Self::ThrustScale { factor } if !nonneg(factor) => {
                Some(("factor", "must be ≥ 0"))
            }
            Self::TorqueLimit { fraction } if !(0.0..=1.0).contains(&fraction) => {
                Some(("fraction", "must be in [0, 1]"))
            }
            _ => None,
        }
    }
}

/// The random draws of one axis of one sample ([`sensor_value`]); zero for modes that draw none.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Draws {
    /// `noise`: one standard normal.
    pub normal: f64,
    /// `spikes`: u₁ (occurrence) and u₂ (sign), uniform on [0, 1).
    pub u1: f64,
    /// See `u1`.
    pub u2: f64,
}

impl Draws {
    /// The draws `mode` takes from `rng` for one axis, in the documented order.
    #[inline]
    pub fn take(mode: &FaultMode, rng: &mut flexdyn_sensors::rng::NormalRng) -> Self {
        match mode {
            FaultMode::Noise { .. } => Self {
                normal: rng.normal(),
                ..Self::default()
            },
            FaultMode::Spikes { .. } => {
                let u1 = rng.uniform01();
                Self {
                    u1,
                    u2: rng.uniform01(),
                    ..Self::default()
                }
            }
            _ => Self::default(),
        }
    }
}

/// The published value of one axis under a value mode (the table in the module docs): `x` the
/// healthy value, `x_on` the healthy value at the activation's first sample, `t_on_s` \[s\] the
/// time since the activation began, `d` the axis's draws. Other modes return `x`.
#[inline]
pub fn sensor_value(mode: &FaultMode, x: f64, x_on: f64, t_on_s: f64, d: Draws) -> f64 {
    match *mode {
        FaultMode::StuckCurrent => x_on,
        FaultMode::StuckValue { value } => value,
        FaultMode::BiasStep { value } => x + value,
        FaultMode::BiasRamp { rate_per_s } => x + rate_per_s * t_on_s,
        FaultMode::Scale { factor } => factor * x,
        FaultMode::Noise { sigma } => x + sigma * d.normal,
        FaultMode::Spikes {
            probability,
            amplitude,
        } => {
            if d.u1 < probability {
                x + if d.u2 < 0.5 { amplitude } else { -amplitude }
            } else {
                x
            }
        }
        _ => x,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_index_is_the_table_order() {
        for (i, (name, keys)) in MODES.iter().enumerate() {
            let m = FaultMode::from_name(name, |_| 0.5).unwrap();
            assert_eq!(m.index(), i);
            assert_eq!(m.name(), *name);
            assert!(keys.len() <= 2);
        }
        assert!(FaultMode::from_name("melted", |_| 0.0).is_none());
    }

    /// The clients' table of mode names by wire code (`flexdyn_proto::FAULT_MODE_NAMES`, which
    /// the monitor names faults with) is this one.
    #[test]
    fn the_clients_mode_names_are_the_table() {
        let names: Vec<&str> = MODES.iter().map(|(n, _)| *n).collect();
        assert_eq!(names, flexdyn_proto::FAULT_MODE_NAMES);
    }

    /// The sensor and link modes are slices of the wire table by position: these are the
    /// boundaries (issue 21's sensor modes, and the three link modes).
    #[test]
    fn the_sensor_and_link_modes_are_their_wire_codes() {
        let sensor = "stuck_current stuck_value bias_step bias_ramp scale noise spikes dropout \
                      validity_off";
        assert_eq!(SENSOR_MODES, sensor.split_whitespace().collect::<Vec<_>>());
        assert_eq!(LINK_MODES, ["dropped", "delayed", "corrupted"]);
        assert_eq!(VALUE_MODES, &SENSOR_MODES[..7]);
    }

    #[test]
    fn value_transforms_follow_the_table() {
        let d = Draws {
            normal: 2.0,
            u1: 0.1,
            u2: 0.7,
        };
        let v = |m| sensor_value(&m, 3.0, 1.5, 4.0, d);
        assert_eq!(v(FaultMode::StuckCurrent), 1.5);
        assert_eq!(v(FaultMode::StuckValue { value: -2.0 }), -2.0);
        assert_eq!(v(FaultMode::BiasStep { value: 0.25 }), 3.25);
        assert_eq!(v(FaultMode::BiasRamp { rate_per_s: 0.5 }), 5.0);
        assert_eq!(v(FaultMode::Scale { factor: 2.0 }), 6.0);
        assert_eq!(v(FaultMode::Noise { sigma: 0.5 }), 4.0);
        let spikes = |p| FaultMode::Spikes {
            probability: p,
            amplitude: 10.0,
        };
        // u1 = 0.1 < 0.2: a spike, u2 ≥ ½: negative.
        assert_eq!(v(spikes(0.2)), -7.0);
        assert_eq!(v(spikes(0.1)), 3.0);
        assert_eq!(v(FaultMode::Dropout), 3.0);
    }
}
