//! The per-vehicle fault runtime: applies the configured faults at the sensor port (after the
//! bank samples) and at the actuator port (before the inputs reach the spacecraft). Built once;
//! every per-frame and per-step call allocates nothing, locks nothing and cannot fail.
//!
//! # Actuator modes, physically
//! Each transforms the effector's input (commanded + scheduled), then the model applies its own
//! limits as for any command:
//! - reaction wheel (input: motor torque u \[N·m\]):
//!   - `command_ignored`: u = 0;
//!   - `torque_limit`: u clipped to ±`fraction`·`max_torque_nm`;
//!   - `friction_scale` k: u + (k − 1) τ_f(Ω), τ_f the wheel's own friction law
//!     ([`ReactionWheel::friction_nm`]) at the speed Ω at the start of each step, held over the
//!     step: the bearing then drags with k τ_f. The extra drag passes the motor's torque clip;
//!   - `seized`: the bearing locks. Modelled as a brake, an internal torque between rotor and
//!     hub: u = −J_s Ω / h − τ_f(Ω) at the start of each step of length h, so that by (W3) of
//!     the wheel model Ω̇ ≈ −Ω/h and the rotor stops within a step (within the motor's torque
//!     limit, so a fast wheel stops in J_s |Ω| / `max_torque_nm`) and is then held at rest. The
//!     rotor's momentum goes to the hub through the reaction torque: the total angular momentum
//!     is conserved, as in a real seizure.
//! - thruster (input: on-time \[s\] or duty cycle): `stuck_on` = the whole frame (on-time = the
//!   frame period, duty = 1); `stuck_off` = 0; `thrust_scale` k: the input × k, so the impulse
//!   per frame scales by k (exactly for an ideal valve; the rise and tail-off lags apply to the
//!   shortened pulse as to any other);
//! - magnetorquer (input: dipole \[A·m²\]): `dead` = 0; `dipole_scale` k: the input × k (before the
//!   rod's ±`max_dipole_am2` clip).

use super::modes::{sensor_value, Draws, FaultMode};
use super::{FaultSpec, Port, MAX_AXES, MAX_CHANNELS};
use crate::config::{ConfigError, SimConfig};
use crate::dynamics::effectors::reaction_wheel::ReactionWheel;
use crate::dynamics::{Spacecraft, State};
use crate::sensors::rng::NormalRng;
use crate::sensors::SensorBank;

/// What an actuator fault needs of its effector.
#[derive(Debug, Clone)]
enum Actuator {
    /// A reaction wheel: its model (for its friction law and J_s), the index of Ω in the state's
    /// effector states, and \[s\] the step.
    Wheel {
        wheel: Box<ReactionWheel>,
        omega_index: usize,
        step_s: f64,
    },
    /// A thruster: its full-open input (the frame period in s, or duty 1).
    Thruster { full_open: f64 },
    /// A magnetorquer.
    Magnetorquer,
}

/// One configured fault and its state.
#[derive(Debug, Clone)]
struct Live {
    spec: FaultSpec,
    rng: NormalRng,
    /// The start \[ns\] of the activation in force at the last evaluation.
    on: Option<u64>,
    /// Healthy values at the activation's first sample (`stuck_current`).
    held: [[f64; MAX_AXES]; MAX_CHANNELS],
    held_set: bool,
    /// The actuator's offset in the flat input vector and what it needs.
    actuator: Option<(usize, Actuator)>,
}

/// The faults of one vehicle.
#[derive(Debug, Clone, Default)]
pub struct Faults {
    live: Vec<Live>,
    any_actuator: bool,
}

impl Faults {
    /// The faults of `cfg` (resolved at load) for the spacecraft `sc` built from it.
    pub fn new(cfg: &SimConfig, sc: &Spacecraft) -> Result<Self, ConfigError> {
        let mut live = Vec::with_capacity(cfg.faults.len());
        for spec in &cfg.faults {
            let actuator = match spec.port {
                // Applied by the server's command book (`super::link`).
                Port::Sensor { .. } | Port::Link { .. } => None,
                Port::Actuator { effector } => Some(actuator(cfg, sc, effector)?),
            };
            live.push(Live {
                rng: NormalRng::new(spec.seed),
                spec: spec.clone(),
                on: None,
                held: [[0.0; MAX_AXES]; MAX_CHANNELS],
                held_set: false,
                actuator,
            });
        }
        Ok(Self {
            any_actuator: live.iter().any(|l| l.actuator.is_some()),
            live,
        })
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.live.is_empty()
    }

    /// Whether some fault sits at an actuator (the inputs then go through
    /// [`Self::at_input_port`] at every step).
    pub fn has_actuator_faults(&self) -> bool {
        self.any_actuator
    }

    /// The configured faults, in configuration order.
    pub fn specs(&self) -> impl Iterator<Item = &FaultSpec> {
        self.live.iter().map(|l| &l.spec)
    }

    /// The sensor port at `t_ns`: transforms the outputs of the sensors the bank just sampled
    /// (faults in configuration order; channels, then axes in order), drops those in `dropout`
    /// from the sampled list and marks those in `validity_off` invalid.
    pub fn at_sensor_port(&mut self, t_ns: u64, bank: &mut SensorBank) {
        for l in &mut self.live {
            let Port::Sensor { sensor, channel } = l.spec.port else {
                continue;
            };
            let Some(on) = l.activation(t_ns) else {
                continue;
            };
            if !bank.sampled().contains(&sensor) {
                continue;
            }
            let t_on_s = (t_ns - on) as f64 * 1e-9;
            let mode = l.spec.mode;
            match mode {
                FaultMode::Dropout => bank.unsample(sensor),
                FaultMode::ValidityOff => bank.sensor_mut(sensor).force_invalid(),
                _ => {
                    let s = bank.sensor_mut(sensor);
                    let (first, end) = match channel {
                        Some(c) => (c, c + 1),
                        None => (0, s.fault_channels().len()),
                    };
                    for c in first..end.min(MAX_CHANNELS) {
                        for (a, v) in s.fault_channel(c).iter_mut().enumerate().take(MAX_AXES) {
                            if l.spec.axes != 0 && l.spec.axes & (1 << a) == 0 {
                                continue;
                            }
                            if !l.held_set {
                                l.held[c][a] = *v;
                            }
                            let d = Draws::take(&mode, &mut l.rng);
                            *v = sensor_value(&mode, *v, l.held[c][a], t_on_s, d);
                        }
                    }
                    l.held_set = true;
                }
            }
        }
    }

    /// The actuator port at `t_ns` with state `x`: transforms the flat inputs `u` (command +
    /// schedule, laid out by [`Spacecraft::effector_input_ranges`]) as the module docs say.
    #[inline]
    pub fn at_input_port(&mut self, t_ns: u64, x: &State, u: &mut [f64]) {
        for l in &mut self.live {
            if l.actuator.is_none() || l.activation(t_ns).is_none() {
                continue;
            }
            let Some((i, actuator)) = &l.actuator else {
                continue;
            };
            let Some(v) = u.get_mut(*i) else { continue };
            *v = actuator_input(&l.spec.mode, actuator, x, *v);
        }
    }
}

impl Live {
    /// The activation in force at `t_ns` (a new one forgets the held values).
    #[inline]
    fn activation(&mut self, t_ns: u64) -> Option<u64> {
        let on = self.spec.window.activation_at(t_ns);
        if on != self.on {
            self.on = on;
            self.held_set = false;
        }
        on
    }
}

/// The input of an actuator in `mode` given the healthy input `u` (module docs).
#[inline]
fn actuator_input(mode: &FaultMode, actuator: &Actuator, x: &State, u: f64) -> f64 {
    match (mode, actuator) {
        (
            FaultMode::FrictionScale { factor },
            Actuator::Wheel {
                wheel, omega_index, ..
            },
        ) => {
            let omega = x.effectors.get(*omega_index).copied().unwrap_or(0.0);
            u + (factor - 1.0) * wheel.friction_nm(omega)
        }
        (FaultMode::TorqueLimit { fraction }, Actuator::Wheel { wheel, .. }) => {
            let lim = fraction * wheel.params().max_torque_nm;
            u.clamp(-lim, lim)
        }
        (
            FaultMode::Seized,
            Actuator::Wheel {
                wheel,
                omega_index,
                step_s,
            },
        ) => {
            let omega = x.effectors.get(*omega_index).copied().unwrap_or(0.0);
            -wheel.params().j_s_kg_m2 * omega / step_s - wheel.friction_nm(omega)
        }
        (FaultMode::StuckOn, Actuator::Thruster { full_open }) => *full_open,
        (FaultMode::ThrustScale { factor }, Actuator::Thruster { .. })
        | (FaultMode::DipoleScale { factor }, Actuator::Magnetorquer) => u * factor,
        (FaultMode::CommandIgnored, _) | (FaultMode::StuckOff, _) | (FaultMode::Dead, _) => 0.0,
        _ => u,
    }
}

/// What a fault on effector `effector` needs (its kind was checked at load).
fn actuator(
    cfg: &SimConfig,
    sc: &Spacecraft,
    effector: usize,
) -> Result<(usize, Actuator), ConfigError> {
    use crate::dynamics::dynamic_effectors::{magnetorquer, thruster};
    use crate::dynamics::effectors::reaction_wheel;
    let input = sc.effector_input_ranges()[effector].start;
    let entry = sc
        .effector_entries()
        .nth(effector)
        .ok_or_else(|| ConfigError::Invalid {
            field: "faults".into(),
            problem: format!("no effector {effector}"),
            at: Default::default(),
        })?;
    let kind = entry.kind;
    let a = if kind == reaction_wheel::KIND {
        // Its index among the wheels (the configuration's order).
        let w = sc
            .effector_entries()
            .take(effector)
            .filter(|e| e.kind == reaction_wheel::KIND)
            .count();
        let path = format!("reaction_wheels[{w}]");
        Actuator::Wheel {
            wheel: Box::new(ReactionWheel::new(cfg.reaction_wheels[w].clone(), &path)?),
            omega_index: entry.state_range.start,
            step_s: sc.step_ns() as f64 * 1e-9,
        }
    } else if kind == thruster::KIND {
        Actuator::Thruster {
            full_open: if entry.input_names == thruster::ON_TIME_INPUT {
                cfg.frame_ns as f64 * 1e-9
            } else {
                1.0
            },
        }
    } else if kind == magnetorquer::KIND {
        Actuator::Magnetorquer
    } else {
        return Err(ConfigError::Invalid {
            field: "faults".into(),
            problem: format!("{} takes no faults", kind.name),
            at: Default::default(),
        });
    };
    Ok((input, a))
}
