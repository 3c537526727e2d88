//! Message types. Field order here *is* the wire order (see the crate-level
//! "Layout" section and `proto/README.md` for byte offsets).
//!
//! Naming: `<quantity>_<frames>_<components>_<unit>`. `bn` is "body B relative to
//! inertial N"; a trailing `_b`/`_n`/`_p` names the frame the components are
//! expressed in (body, inertial, IMU platform); the unit closes the name.

use serde::{Deserialize, Serialize};

use crate::{FAULT_TARGET_LEN, MAX_CSS_DETECTORS, PROTOCOL_VERSION};

/// Common header, the first 30 bytes of every message.
///
/// | offset | size | field |
/// |---|---|---|
/// | 0 | 2 | `protocol_version` u16 |
/// | 2 | 4 | `spacecraft_id` u32 |
/// | 6 | 8 | `tick` u64 |
/// | 14 | 8 | `sim_time_ns` u64 |
/// | 22 | 8 | `seq` u64 |
///
/// All fields are deterministic (no wall clock).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Header {
    /// Wire protocol version, always [`PROTOCOL_VERSION`] when sent. Decoders check
    /// it (first two bytes, u16 LE) before anything else.
    pub protocol_version: u16,
    /// Numeric spacecraft id, configured alongside the string sc-id used in the
    /// key expression (`flexdyn/<sc-id>/…`). The two name the same vehicle; the
    /// numeric id lets a receiver check a message against its configuration
    /// without parsing the key.
    pub spacecraft_id: u32,
    /// Frame index `k`: the dynamics frame this message describes (state, IMU,
    /// status) or applies to (command).
    pub tick: u64,
    /// Simulation time of `tick` (ns since simulation epoch).
    pub sim_time_ns: u64,
    /// Publisher's sequence number for this topic, +1 per message, so a gap
    /// reveals a lost message.
    pub seq: u64,
}

impl Header {
    /// Header with the current [`PROTOCOL_VERSION`].
    pub fn new(spacecraft_id: u32, tick: u64, sim_time_ns: u64, seq: u64) -> Self {
        Self {
            protocol_version: PROTOCOL_VERSION,
            spacecraft_id,
            tick,
            sim_time_ns,
            seq,
        }
    }
}

impl Default for Header {
    /// Current [`PROTOCOL_VERSION`], everything else zero.
    fn default() -> Self {
        Self::new(0, 0, 0, 0)
    }
}

/// Wire tags of [`EffectorState::kind`]: which model an effector entry describes, and so what
/// its `states`, `outputs` and `flags` mean (`proto/README.md`, "Effector kinds").
pub mod effector_kind {
    /// A dual-hinged panel pair. States `[θ1 rad, θ̇1 rad/s, θ2 rad, θ̇2 rad/s]`; no outputs, no
    /// flags, no inputs.
    pub const PANEL_PAIR: u16 = 1;
    /// A reaction wheel. States `[Ω rad/s]` (balanced) or `[Ω rad/s, wheel angle rad]` (with
    /// imbalance); outputs `[applied motor torque N·m, friction torque N·m]`; flags
    /// [`super::wheel_flags`]; one input, the commanded motor torque (N·m).
    pub const REACTION_WHEEL: u16 = 2;
    /// A magnetorquer rod. No states; outputs `[applied dipole A·m²]`; flags
    /// [`super::magnetorquer_flags`]; one input, the commanded dipole (A·m²) along its axis.
    pub const MAGNETORQUER: u16 = 3;
    /// A thruster. No states; outputs `[thrust N, pulse count, propellant used kg, impulse N·s]`;
    /// flags [`super::thruster_flags`]; one input, the valve-open time per frame (s) or the duty
    /// cycle (0–1), as configured.
    pub const THRUSTER: u16 = 4;
}

/// Bits of [`EffectorState::flags`] for a [`effector_kind::MAGNETORQUER`] entry.
pub mod magnetorquer_flags {
    /// Bit 0: the commanded dipole exceeded `max_dipole_am2` and was clipped.
    pub const SATURATED: u32 = 1 << 0;
}

/// Bits of [`EffectorState::flags`] for a [`effector_kind::THRUSTER`] entry.
pub mod thruster_flags {
    /// Bit 0: the valve is open at this instant.
    pub const FIRING: u32 = 1 << 0;
    /// Bit 1: the commanded on-time is below `min_on_time_s`; the valve stays shut.
    pub const BELOW_MIN_ON_TIME: u32 = 1 << 1;
    /// Bit 2: the command was outside its range (on-time 0 … frame period, duty 0 … 1) and was
    /// clipped.
    pub const COMMAND_CLIPPED: u32 = 1 << 2;
}

/// Bits of [`EffectorState::flags`] for a [`effector_kind::REACTION_WHEEL`] entry.
pub mod wheel_flags {
    /// Bit 0: the commanded motor torque exceeded `max_torque_nm` and was clipped.
    pub const TORQUE_LIMITED: u32 = 1 << 0;
    /// Bit 1: the wheel is at `max_speed_rad_s` and the motor torque that would spin it faster
    /// was set to zero.
    pub const SPEED_LIMITED: u32 = 1 << 1;
}

/// One effector (appended body) in a [`StateMsg`], in the server's effector order (the
/// configuration's `panel_pairs`, then its `reaction_wheels`). On the wire: u16 LE `kind`,
/// u32 LE `flags`, u64 LE count + f64 `states`, u64 LE count + f64 `outputs`:
/// 22 + 8·(states + outputs) bytes.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EffectorState {
    /// Model tag, see [`effector_kind`]. Receivers skip kinds they do not know.
    pub kind: u16,
    /// Kind-specific status bits (e.g. [`wheel_flags`]); 0 for kinds without flags.
    pub flags: u32,
    /// The effector's integrated states, in the kind's documented order and units. At most
    /// [`crate::MAX_EFFECTOR_VALUES`].
    pub states: Vec<f64>,
    /// The effector's outputs (e.g. a wheel's applied torques), in the kind's documented order.
    /// At most [`crate::MAX_EFFECTOR_VALUES`].
    pub outputs: Vec<f64>,
}

/// Inputs for one effector in a [`CommandKind::Actuators`] command. On the wire: u32 LE
/// `effector_index`, u64 LE count, f64 `values`: 12 + 8·values bytes.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EffectorInput {
    /// Index of the effector in [`StateMsg::effectors`].
    pub effector_index: u32,
    /// Its inputs, as many as the kind takes (a reaction wheel: 1, the motor torque in N·m).
    /// At most [`crate::MAX_EFFECTOR_VALUES`].
    pub values: Vec<f64>,
}

/// Conserved quantities (for verification: constant when no external wrench
/// acts and the panels have no damping). 64 bytes on the wire.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Conserved {
    /// Total orbital energy (J).
    pub orb_energy_j: f64,
    /// Total rotational energy of hub + panels (J).
    pub rot_energy_j: f64,
    /// Orbital angular momentum about the inertial origin, N components (kg·m²/s).
    pub orb_ang_mom_n: [f64; 3],
    /// Rotational angular momentum about the system centre of mass C, N
    /// components (kg·m²/s).
    pub rot_ang_mom_c_n: [f64; 3],
}

/// External wrench held constant over a frame, body components about point B.
/// 48 bytes on the wire (torque first, like [`CommandKind::Wrench`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AppliedWrench {
    /// Torque about B, B components (N·m).
    pub torque_b_nm: [f64; 3],
    /// Force at B, B components (N).
    pub force_b_newton: [f64; 3],
}

/// Bits of [`StateMsg::command_flags`].
pub mod command_flags {
    /// Bit 0: the wrench held this frame comes from a command that is stale
    /// (not addressed to this tick, or older than the staleness limit).
    pub const STALE: u8 = 1 << 0;
    /// Bit 1: the stale-command policy ([`crate::StalePolicy::Zero`]) replaced the
    /// commanded wrench by zero for this frame.
    pub const ZEROED_BY_POLICY: u8 = 1 << 1;
    /// Bit 2: no command has been received since the run started; the wrench is zero.
    pub const NO_COMMAND_YET: u8 = 1 << 2;
    /// Bits 3..7 are reserved: senders write 0, receivers ignore them.
    pub const RESERVED_MASK: u8 = !(STALE | ZEROED_BY_POLICY | NO_COMMAND_YET);
}

/// Bits of [`StarTrackerMsg::status_flags`]: why a star tracker reports invalid.
pub mod star_tracker_flags {
    /// Bit 0: the boresight is within the configured exclusion angle of the Sun.
    pub const SUN_EXCLUSION: u8 = 1 << 0;
    /// Bit 1: |ω_B/N| exceeds the tracker's rate limit.
    pub const RATE_LIMIT: u8 = 1 << 1;
    /// Bit 2: the boresight is within the configured exclusion angle of the Earth's limb (its
    /// radius plus the configured atmosphere height), or on the Earth's disc.
    pub const EARTH_EXCLUSION: u8 = 1 << 2;
    /// Bit 3: the boresight is within the configured exclusion angle of the Moon's limb, or on
    /// its disc.
    pub const MOON_EXCLUSION: u8 = 1 << 3;
    /// Bits 4..7 are reserved: senders write 0, receivers ignore them.
    pub const RESERVED_MASK: u8 = !(SUN_EXCLUSION | RATE_LIMIT | EARTH_EXCLUSION | MOON_EXCLUSION);
}

/// Bits of [`ImuMsg::saturation_flags`].
pub mod saturation_flags {
    /// Bit 0: at least one gyro rate axis (`omega_p_rad_s`) hit its range limit.
    pub const GYRO_RATE: u8 = 1 << 0;
    /// Bit 1: at least one accelerometer axis (`accel_p_m_s2`) hit its range limit.
    pub const ACCEL: u8 = 1 << 1;
    /// Bit 2: at least one integrated-angle axis (`dtheta_p_rad`) saturated.
    pub const DTHETA: u8 = 1 << 2;
    /// Bit 3: at least one integrated-velocity axis (`dv_p_m_s`) saturated.
    pub const DV: u8 = 1 << 3;
    /// Bits 4..7 are reserved: senders write 0, receivers ignore them.
    pub const RESERVED_MASK: u8 = !(GYRO_RATE | ACCEL | DTHETA | DV);
}

/// Per-frame truth state, topic `flexdyn/<sc-id>/tlm/state`.
///
/// Deterministic: same scenario and command stream give the same bytes (no wall
/// clock). 327 bytes + each [`EffectorState`]; `effectors` is last on the wire so
/// every other field sits at a fixed offset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StateMsg {
    /// Common header; `tick` is the frame this state belongs to.
    pub header: Header,
    /// Attitude of B relative to N as modified Rodrigues parameters (shadow set
    /// switched so that |σ| ≤ 1).
    pub sigma_bn: [f64; 3],
    /// Same attitude as a unit quaternion, **scalar first**: `[q0, q1, q2, q3]`
    /// with `q0` the scalar part. It maps N to B, i.e. it corresponds to the DCM
    /// \[BN\] (`v_b = [BN] v_n`). Sign is chosen so that `q0 ≥ 0`.
    pub q_bn: [f64; 4],
    /// Angular velocity of B relative to N, B components (rad/s).
    pub omega_bn_b_rad_s: [f64; 3],
    /// Angular acceleration of B relative to N, B components (rad/s²).
    pub omega_dot_bn_b_rad_s2: [f64; 3],
    /// Position of point B relative to the inertial origin, N components (m).
    pub r_bn_n_m: [f64; 3],
    /// Inertial velocity of point B, N components (m/s).
    pub v_bn_n_m_s: [f64; 3],
    /// Non-gravitational acceleration of point B (what an ideal accelerometer at
    /// B senses), N components (m/s²).
    pub nongrav_accel_bn_n_m_s2: [f64; 3],
    /// Conserved quantities.
    pub conserved: Conserved,
    /// Commanded wrench (the flight-code commands summed in sender-id order, after
    /// the stale-command policy) held over the frame that ended at this tick; zero
    /// at tick 0. The configuration's scheduled disturbance wrench is not included.
    pub wrench_applied: AppliedWrench,
    /// Command bookkeeping bits, see [`command_flags`].
    pub command_flags: u8,
    /// Every effector's state, outputs and flags, in the server's effector order.
    /// On the wire: u64 LE count, then each [`EffectorState`]. At most
    /// [`crate::MAX_EFFECTORS`]; decoders reject larger counts.
    pub effectors: Vec<EffectorState>,
}

impl Default for StateMsg {
    /// Zero state with the identity attitude (`q_bn = [1, 0, 0, 0]`) and no effectors.
    fn default() -> Self {
        Self {
            header: Header::default(),
            sigma_bn: [0.0; 3],
            q_bn: [1.0, 0.0, 0.0, 0.0],
            omega_bn_b_rad_s: [0.0; 3],
            omega_dot_bn_b_rad_s2: [0.0; 3],
            r_bn_n_m: [0.0; 3],
            v_bn_n_m_s: [0.0; 3],
            nongrav_accel_bn_n_m_s2: [0.0; 3],
            conserved: Conserved::default(),
            wrench_applied: AppliedWrench::default(),
            command_flags: 0,
            effectors: Vec::new(),
        }
    }
}

/// IMU sample, topic `flexdyn/<sc-id>/tlm/imu/<name>`. 127 bytes.
///
/// All vectors are in the IMU platform frame P.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ImuMsg {
    /// Common header; `tick` is the frame at whose end the sample was taken.
    pub header: Header,
    /// Measured angular rate, P components (rad/s).
    pub omega_p_rad_s: [f64; 3],
    /// Measured specific force (non-gravitational acceleration), P components (m/s²).
    pub accel_p_m_s2: [f64; 3],
    /// Integrated angle over the sample interval, P components (rad).
    pub dtheta_p_rad: [f64; 3],
    /// Integrated velocity change over the sample interval, P components (m/s).
    pub dv_p_m_s: [f64; 3],
    /// Saturation bits, see [`saturation_flags`].
    pub saturation_flags: u8,
}

/// A star-tracker measurement, topic `flexdyn/<sc-id>/tlm/st/<name>`. 64 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StarTrackerMsg {
    /// Common header; `tick` is the frame at whose end the measurement was taken.
    pub header: Header,
    /// Measured attitude of the tracker's case frame C relative to N, unit quaternion,
    /// **scalar first**, `q0 ≥ 0`; it maps N components to C components. While `valid` is
    /// false it holds the last valid measurement (identity before the first).
    pub q_cn: [f64; 4],
    /// Whether `q_cn` is a fresh measurement (1 byte: 0 or 1; other values are malformed).
    pub valid: bool,
    /// Why the tracker is invalid, see [`star_tracker_flags`]; 0 when valid.
    pub status_flags: u8,
}

impl Default for StarTrackerMsg {
    /// Identity attitude, invalid, no flags.
    fn default() -> Self {
        Self {
            header: Header::default(),
            q_cn: [1.0, 0.0, 0.0, 0.0],
            valid: false,
            status_flags: 0,
        }
    }
}

/// Bits of [`MagnetometerMsg::saturation_flags`]: which axes hit the range limit.
pub mod magnetometer_flags {
    /// Bit 0: axis 1 of `b_s_t` was clipped to ± the range.
    pub const AXIS_1: u8 = 1 << 0;
    /// Bit 1: axis 2 was clipped.
    pub const AXIS_2: u8 = 1 << 1;
    /// Bit 2: axis 3 was clipped.
    pub const AXIS_3: u8 = 1 << 2;
    /// Bits 3..7 are reserved: senders write 0, receivers ignore them.
    pub const RESERVED_MASK: u8 = !(AXIS_1 | AXIS_2 | AXIS_3);
}

/// A three-axis magnetometer sample, topic `flexdyn/<sc-id>/tlm/mag/<name>`. 55 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MagnetometerMsg {
    /// Common header; `tick` is the frame at whose end the sample was taken.
    pub header: Header,
    /// Measured magnetic field, the sensor's frame S components (T).
    pub b_s_t: [f64; 3],
    /// Saturated axes, see [`magnetometer_flags`].
    pub saturation_flags: u8,
}

/// A coarse-sun-sensor array sample, topic `flexdyn/<sc-id>/tlm/css/<name>`: one reading per
/// cosine detector. 159 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CssMsg {
    /// Common header; `tick` is the frame at whose end the sample was taken.
    pub header: Header,
    /// How many detectors the array has (0..=[`MAX_CSS_DETECTORS`]; more is malformed): the
    /// first `detector_count` entries of `readings` are theirs, the rest are 0.
    pub detector_count: u8,
    /// Reading of each detector in configuration order, in the array's output unit (its
    /// `scale` at normal incidence in full sunlight; 0 outside the field of view and in umbra).
    pub readings: [f64; MAX_CSS_DETECTORS],
}

/// Bits of [`FssMsg::flags`].
pub mod fss_flags {
    /// Bit 0: the angles are a measurement (the Sun is in the field of view and lit, bits 1 and
    /// 2 both set); otherwise both angles are 0.
    pub const VALID: u8 = 1 << 0;
    /// Bit 1: the Sun direction is inside the field-of-view cone.
    pub const IN_FOV: u8 = 1 << 1;
    /// Bit 2: the shadow factor is at least the sensor's threshold (not in eclipse).
    pub const SUNLIT: u8 = 1 << 2;
    /// Bits 3..7 are reserved: senders write 0, receivers ignore them.
    pub const RESERVED_MASK: u8 = !(VALID | IN_FOV | SUNLIT);
}

/// A fine (two-axis) sun sensor sample, topic `flexdyn/<sc-id>/tlm/fss/<name>`. 47 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FssMsg {
    /// Common header; `tick` is the frame at whose end the sample was taken.
    pub header: Header,
    /// Sun angle in the sensor's 1–3 plane (rad): atan2(s₁, s₃) of the Sun direction s in the
    /// sensor frame F, boresight +3.
    pub alpha_rad: f64,
    /// Sun angle in the sensor's 2–3 plane (rad): atan2(s₂, s₃).
    pub beta_rad: f64,
    /// See [`fss_flags`].
    pub flags: u8,
}

/// Bits of [`GpsMsg::flags`].
pub mod gps_flags {
    /// Bit 0: the receiver has a fix; the time and the configured frames' fields are a
    /// measurement. Without it every number of the message is 0.
    pub const FIX: u8 = 1 << 0;
    /// Bit 1: the ECEF fields (`r_be_e_m`, `v_be_e_m_s`) are configured output.
    pub const ECEF: u8 = 1 << 1;
    /// Bit 2: the inertial fields (`r_bn_n_m`, `v_bn_n_m_s`) are configured output.
    pub const INERTIAL: u8 = 1 << 2;
    /// Bits 3..7 are reserved: senders write 0, receivers ignore them.
    pub const RESERVED_MASK: u8 = !(FIX | ECEF | INERTIAL);
}

/// A GPS receiver's navigation solution, topic `flexdyn/<sc-id>/tlm/gps/<name>`. 147 bytes.
/// The message published at `header.sim_time_ns` carries the measurement valid at
/// `valid_sim_time_ns` (earlier by the receiver's latency).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GpsMsg {
    /// Common header; `tick` is the frame at whose end the message is published.
    pub header: Header,
    /// \[ns\] simulation time at which the measurement is valid (publication − latency).
    pub valid_sim_time_ns: u64,
    /// GPS week of the measurement (since 1980-01-06, not modulo 1024); 0 without a fix.
    pub gps_week: u32,
    /// \[s\] GPS seconds of week of the measurement; 0 without a fix.
    pub gps_seconds_of_week: f64,
    /// \[m\] position of point B relative to the Earth's centre, ECEF (ITRF) components.
    pub r_be_e_m: [f64; 3],
    /// \[m/s\] velocity of B relative to the Earth-fixed frame, ECEF components.
    pub v_be_e_m_s: [f64; 3],
    /// \[m\] position of B in the inertial frame N.
    pub r_bn_n_m: [f64; 3],
    /// \[m/s\] inertial velocity of B, N components.
    pub v_bn_n_m_s: [f64; 3],
    /// See [`gps_flags`].
    pub flags: u8,
}

/// What a [`CommandMsg`] asks for. Wire: u32 LE variant index (0 = `Wrench`,
/// 1 = `NoCommand`, 2 = `Actuators`), then the variant's fields.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum CommandKind {
    /// Tag 0: hold this wrench, body components about B, over the frame
    /// starting at `header.tick`. 48 bytes follow the tag.
    Wrench {
        /// Torque about B, B components (N·m).
        torque_b_nm: [f64; 3],
        /// Force at B, B components (N).
        force_b_newton: [f64; 3],
    },
    /// Tag 1: explicit "no command this tick" (a lockstep participant's way to
    /// release the step without changing the wrench). Nothing follows the tag.
    NoCommand,
    /// Tag 2: hold this wrench **and** these effector inputs (e.g. reaction-wheel motor
    /// torques) over the frame starting at `header.tick`. Effectors not listed keep the
    /// sender's previous inputs. 48 bytes of wrench, then a u64 LE count and each
    /// [`EffectorInput`]. At most [`crate::MAX_EFFECTORS`] entries; an effector index may
    /// appear once. Added in protocol version 3.
    Actuators {
        /// Torque about B, B components (N·m).
        torque_b_nm: [f64; 3],
        /// Force at B, B components (N).
        force_b_newton: [f64; 3],
        /// Per-effector inputs.
        inputs: Vec<EffectorInput>,
    },
}

impl Default for CommandKind {
    /// [`CommandKind::NoCommand`].
    fn default() -> Self {
        Self::NoCommand
    }
}

/// Command from flight code, topic `flexdyn/<sc-id>/cmd/<sender_id>` (every kind of command uses
/// this one topic, so a lockstep participant's answer is one message).
/// 86 bytes (`Wrench`), 38 bytes (`NoCommand`) or 94 + Σ(12 + 8·values) bytes
/// (`Actuators`).
///
/// Decoding rejects NaN/infinite torque, force or input values with
/// [`crate::DecodeError::NonFinite`].
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CommandMsg {
    /// Common header: `tick` is the tick the command applies to (in lockstep the
    /// tick of the state it answers), `seq` the sender's own sequence number.
    pub header: Header,
    /// Numeric id of the sending participant, assigned in the server's
    /// configuration (fixed width instead of a name; 0 is a valid id).
    pub sender_id: u32,
    /// The command.
    pub kind: CommandKind,
}

impl CommandMsg {
    /// A `Wrench` command.
    pub fn wrench(
        header: Header,
        sender_id: u32,
        torque_b_nm: [f64; 3],
        force_b_newton: [f64; 3],
    ) -> Self {
        Self {
            header,
            sender_id,
            kind: CommandKind::Wrench {
                torque_b_nm,
                force_b_newton,
            },
        }
    }

    /// An `Actuators` command: a wrench and effector inputs.
    pub fn actuators(
        header: Header,
        sender_id: u32,
        torque_b_nm: [f64; 3],
        force_b_newton: [f64; 3],
        inputs: Vec<EffectorInput>,
    ) -> Self {
        Self {
            header,
            sender_id,
            kind: CommandKind::Actuators {
                torque_b_nm,
                force_b_newton,
                inputs,
            },
        }
    }

    /// A `NoCommand` command.
    pub fn no_command(header: Header, sender_id: u32) -> Self {
        Self {
            header,
            sender_id,
            kind: CommandKind::NoCommand,
        }
    }
}

/// How the server paces frames. Wire: u32 LE tag.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Mode {
    /// Tag 0: frames paced by the wall clock.
    #[default]
    RealTime,
    /// Tag 1: each step waits for every lockstep participant's command.
    Lockstep,
    /// Tag 2: as fast as possible, no waiting.
    Batch,
}

/// Server life cycle. Wire: u32 LE tag.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum RunState {
    /// Tag 0: initialising, not stepping yet.
    #[default]
    Starting,
    /// Tag 1: stepping.
    Running,
    /// Tag 2: shutdown requested, finishing the current frame.
    Stopping,
    /// Tag 3: ended normally (scenario end).
    Finished,
    /// Tag 4: ended on an error.
    Failed,
    /// Tag 5: ended on a stop request (SIGINT/SIGTERM or the library's shutdown future),
    /// after the last frame was published. Added in protocol version 2.
    Stopped,
    /// Tag 6: holding at a tick on an operator's request (pause in real time, the end of a
    /// "run N ticks" in lockstep): no time advances and no frame is published until the
    /// operator resumes. Added in protocol version 5.
    Paused,
}

impl Mode {
    /// The wire tag (the u32 LE variant index).
    pub const fn tag(self) -> u32 {
        self as u32
    }
}

impl RunState {
    /// The wire tag (the u32 LE variant index).
    pub const fn tag(self) -> u32 {
        self as u32
    }

    /// Whether the run is over: `Finished`, `Failed` or `Stopped` (the last status a server
    /// publishes; every client stops on it).
    pub const fn ended(self) -> bool {
        matches!(self, Self::Finished | Self::Failed | Self::Stopped)
    }

    /// The state of wire tag `tag`, `None` for an unknown tag.
    pub const fn from_tag(tag: u32) -> Option<Self> {
        match tag {
            0 => Some(Self::Starting),
            1 => Some(Self::Running),
            2 => Some(Self::Stopping),
            3 => Some(Self::Finished),
            4 => Some(Self::Failed),
            5 => Some(Self::Stopped),
            6 => Some(Self::Paused),
            _ => None,
        }
    }
}

/// What the server applies when the latest command is stale. Wire: u32 LE tag.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum StalePolicy {
    /// Tag 0: keep applying the last commanded wrench.
    #[default]
    Hold,
    /// Tag 1: apply zero wrench.
    Zero,
}

impl StalePolicy {
    /// The wire tag (the u32 LE variant index).
    pub const fn tag(self) -> u32 {
        self as u32
    }
}

/// Frame-timing statistics since the run started. 40 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FrameTiming {
    /// Median frame-start lateness versus the wall-clock schedule (ns; early
    /// starts count as 0).
    pub lateness_p50_ns: u64,
    /// 99th-percentile frame-start lateness (ns).
    pub lateness_p99_ns: u64,
    /// Largest frame-start lateness (ns).
    pub lateness_max_ns: u64,
    /// Frames whose computation did not finish within the frame period.
    pub overrun_count: u64,
    /// Frames dropped to catch up with the wall clock.
    pub frames_skipped: u64,
}

/// Command bookkeeping. 21 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CommandStatus {
    /// `header.tick` of the last accepted command, [`NO_COMMAND`] if none yet.
    pub last_command_tick: u64,
    /// Simulation time since the last accepted command was received (ns),
    /// [`NO_COMMAND`] if none yet.
    pub command_age_ns: u64,
    /// Whether the command in force is stale (1 byte: 0 or 1; other values are
    /// rejected as malformed).
    pub command_stale: bool,
    /// Policy applied while stale.
    pub stale_policy: StalePolicy,
}

/// Rejected-command counters by reason, cumulative since start. 64 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RejectCounters {
    /// Undecodable: wrong length, trailing bytes, oversize, bad enum tag or bool.
    pub malformed: u64,
    /// Unknown `protocol_version`.
    pub bad_version: u64,
    /// NaN or infinite torque/force.
    pub non_finite: u64,
    /// `header.spacecraft_id` not this server's.
    pub wrong_spacecraft: u64,
    /// `header.tick` already stepped past (or otherwise not acceptable).
    pub stale_tick: u64,
    /// `sender_id` not configured.
    pub unknown_sender: u64,
    /// An `Actuators` command naming an effector index that does not exist, an effector
    /// that takes no inputs, the wrong number of values for its kind, or the same index
    /// twice. Added in protocol version 3.
    pub bad_effector_input: u64,
    /// A command whose `sender_id` is not the one its key names: a participant publishes only
    /// on `flexdyn/<sc-id>/cmd/<its sender_id>`, and on a lab network the Zenoh access-control
    /// list lets only the participant's authenticated subject put there. Added in protocol
    /// version 4.
    pub wrong_identity: u64,
    /// An [`OperatorMsg`] the server would not apply: an action that does not fit the mode
    /// (anything in batch, `RunTicks` in real time), `RunTicks` with `ticks = 0`, `Resume` with
    /// nothing held or pending, `Pause` while already held or pending. Malformed, bad-version and
    /// wrong-spacecraft operator messages count under those reasons. Added in protocol
    /// version 6.
    pub operator_refused: u64,
    /// A [`FaultCommandMsg`] the server did not apply: an unknown target, a mode the target
    /// does not take, parameters out of range, a target that is not UTF-8, a tick already
    /// stepped past, a clear naming no fault, or no live-fault slot left. Malformed,
    /// bad-version and wrong-spacecraft fault commands count under those reasons. Added in
    /// protocol version 8.
    pub fault_refused: u64,
    /// A [`FswMsg`] the server did not record: an undeclared stream, a tick ahead of the server
    /// or not after the stream's last recorded one, a `sim_time_ns` other than its tick's, a mode or event the stream does not declare,
    /// a value count other than the declaration's, a bool other than 0/1, a NaN or infinite f64
    /// value, or COVARIANCE without ESTIMATE. Malformed, bad-version and wrong-spacecraft
    /// samples count here too (not under those reasons: telemetry is not a command). Added in
    /// protocol version 10.
    pub fsw_refused: u64,
}

impl RejectCounters {
    /// Count one decode failure under its reason: `UnknownVersion` →
    /// `bad_version`, `NonFinite` → `non_finite`, everything else → `malformed`.
    pub fn record(&mut self, err: &crate::DecodeError) {
        use crate::DecodeError as E;
        let c = match err {
            E::UnknownVersion { .. } => &mut self.bad_version,
            E::NonFinite { .. } => &mut self.non_finite,
            E::Length { .. } | E::TrailingBytes { .. } | E::TooLarge { .. } | E::Malformed(_) => {
                &mut self.malformed
            }
        };
        *c = c.saturating_add(1);
    }

    /// Sum of all counters (saturating).
    pub fn total(&self) -> u64 {
        [
            self.malformed,
            self.bad_version,
            self.non_finite,
            self.wrong_spacecraft,
            self.stale_tick,
            self.unknown_sender,
            self.bad_effector_input,
            self.wrong_identity,
            self.operator_refused,
            self.fault_refused,
            self.fsw_refused,
        ]
        .iter()
        .fold(0u64, |a, &b| a.saturating_add(b))
    }
}

/// Server health, topic `flexdyn/<sc-id>/status`. 243 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct StatusMsg {
    /// Common header; `tick` is the last frame stepped, `seq` counts status messages.
    pub header: Header,
    /// Pacing mode.
    pub mode: Mode,
    /// Life-cycle state.
    pub run_state: RunState,
    /// Frame timing statistics.
    pub timing: FrameTiming,
    /// Command bookkeeping.
    pub command: CommandStatus,
    /// Rejected commands by reason.
    pub rejected: RejectCounters,
    /// Valid commands dropped because the server's command queue was full
    /// (`server.command_queue`), cumulative since start. Added in protocol version 2.
    pub commands_dropped: u64,
    /// Wall-clock time of publication (ns since the Unix epoch). **Not
    /// deterministic**: the only wall-clock field in the protocol; ignore it when
    /// comparing runs.
    pub wall_time_unix_ns: u64,
    /// How many faults are active at `header.tick` (configured, random and live). Added in
    /// protocol version 8.
    pub faults_active: u64,
    /// Which: bit `i % 64` of word `i / 64` is set while fault index `i` (as in
    /// [`FaultEventMsg::fault_index`]) is active; indices from [`MAX_STATUS_FAULTS`] on are
    /// only counted in `faults_active`. Added in protocol version 8.
    pub faults_active_bits: [u64; 4],
}

/// Bits of [`TimeMsg::flags`].
pub mod time_flags {
    /// Bit 0: the configuration has an `[epoch]`, so the calendar fields (TAI, UTC, ΔAT, GPS,
    /// CUC, time at the tone in TAI) are set. Clear: every one of them is zero (the CUC
    /// octets too, P-field included), and only the simulation-time fields carry time.
    pub const EPOCH_VALID: u8 = 1 << 0;
    /// Bit 1: the 1 Hz tone. Set on the first frame at or after a whole second of the tone
    /// scale (TAI with an epoch, simulation time without): on tick `k` when
    /// `floor(T(k) / 1 s) > floor(T(k−1) / 1 s)`, and on tick 0 when `T(0)` is a whole second.
    /// `tone_*` then name that whole second.
    pub const TONE: u8 = 1 << 1;
    /// Bit 2: the instant lies inside an inserted leap second (UTC reads 23:59:60.x).
    pub const LEAP_SECOND: u8 = 1 << 2;
    /// Bits 3..7 are reserved: senders write 0, receivers ignore them.
    pub const RESERVED_MASK: u8 = !(EPOCH_VALID | TONE | LEAP_SECOND);
}

/// A UTC calendar reading. 11 bytes on the wire. All zero when the run has no `[epoch]`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct UtcTime {
    /// Year (e.g. 2016).
    pub year: u16,
    /// Month 1..=12.
    pub month: u8,
    /// Day of month 1..=31.
    pub day: u8,
    /// Hour 0..=23.
    pub hour: u8,
    /// Minute 0..=59.
    pub minute: u8,
    /// Second 0..=60 (60 only inside an inserted leap second).
    pub second: u8,
    /// Nanoseconds into the second, 0..=999,999,999.
    pub nanosecond: u32,
}

/// A time in the layout of cFE's `CFE_TIME_SysTime_t`: whole seconds and subseconds in units of
/// 2⁻³² s (`subseconds = floor(ns · 2³² / 10⁹)`). 8 bytes on the wire (little-endian here; a
/// cFS adapter copies the two u32 into its own struct).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SysTime {
    /// Whole seconds.
    pub seconds: u32,
    /// Fraction of a second in units of 2⁻³² s.
    pub subseconds: u32,
}

/// The time service, topic `flexdyn/<sc-id>/tlm/time`: one per frame, published **before**
/// that frame's sensor samples and state. 122 bytes. Added in protocol version 5.
///
/// Deterministic (no wall clock). Flight code that runs off it (a cFS tone adapter, an
/// F Prime rate-group driver) follows the simulation: its speed, its pauses and its steps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TimeMsg {
    /// Common header: `tick`, `sim_time_ns` (ns since the epoch, t = 0), and `seq` (= tick: one
    /// time message per published frame, so a pause leaves no gap).
    pub header: Header,
    /// Life cycle: `Running`, or `Paused` on the tick the server holds at (nothing follows
    /// until the operator resumes), `Stopping` on the last tick of a stop request.
    pub run_state: RunState,
    /// Pacing mode.
    pub mode: Mode,
    /// See [`time_flags`].
    pub flags: u8,
    /// \[ns\] the frame period (the one configuration value `simulation.frame_s`): tick `k` is
    /// at `k · frame_ns`.
    pub frame_ns: u64,
    /// Real time: wall-clock pacing factor (`--speed`, 1.0 = real time, 2.0 = twice as fast).
    /// Lockstep and batch are not paced by the wall clock: 0.0.
    pub speed: f64,
    /// \[ns\] TAI since 1958-01-01T00:00:00 TAI (the CCSDS Level 1 epoch); 0 without an epoch.
    pub tai_ns_1958: u64,
    /// UTC calendar reading (23:59:60.x inside a leap second); zero without an epoch.
    pub utc: UtcTime,
    /// \[s\] TAI − UTC, the leap-second count ΔAT (37 from 2017-01-01); 0 without an epoch.
    pub tai_minus_utc_s: i32,
    /// GPS week since 1980-01-06T00:00:00 UTC (full week number, not modulo 1024); 0 without
    /// an epoch.
    pub gps_week: u32,
    /// \[ns\] GPS time of week (since Sunday 00:00:00 GPS time); 0 without an epoch.
    pub gps_ns_of_week: u64,
    /// \[ns\] mission elapsed time: time since the epoch (simulation time zero, when the
    /// simulated vehicle's clock starts), equal to `header.sim_time_ns`.
    pub met_ns: u64,
    /// TAI of this tick as a CCSDS CUC: [`CUC_PFIELD_TAI_4_3`], 4 coarse octets (seconds since
    /// 1958) and 3 fine octets (2⁻²⁴ s, truncated), **big-endian** as CCSDS transmits them.
    /// All zero without an epoch.
    pub cuc_tai: [u8; 8],
    /// Mission elapsed time at the most recent tone (whole second of the tone scale ≤ this
    /// tick), in cFE `CFE_TIME_SysTime_t` form: what `CFE_TIME_ExternalMET` takes.
    pub tone_met: SysTime,
    /// TAI since 1958 at the most recent tone, `CFE_TIME_SysTime_t` form (subseconds 0: the
    /// tone is a whole TAI second); zero without an epoch.
    pub tone_tai: SysTime,
}

/// What an [`OperatorMsg`] asks for. Wire: u32 LE tag. Added in protocol version 6.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum OperatorAction {
    /// Tag 0: hold at the next tick. Real time: the next frame boundary; lockstep: the tick
    /// after the one published (as `RunTicks` with 1).
    #[default]
    Pause,
    /// Tag 1: release a hold (or a pending one) and run freely again.
    Resume,
    /// Tag 2 (lockstep only): step `ticks` more frames from the tick published (or held) now,
    /// then hold at that tick.
    RunTicks,
}

impl OperatorAction {
    /// The wire tag (the u32 LE variant index).
    pub const fn tag(self) -> u32 {
        self as u32
    }
}

/// An operator's command, topic `flexdyn/<sc-id>/operator`: pause, resume, or run N ticks and
/// hold. 42 bytes. Added in protocol version 6.
///
/// On a lab network the shipped access-control list lets only the operator's subject put on
/// this key (`scenarios/zenoh/secure-server.json5`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct OperatorMsg {
    /// Common header: `spacecraft_id` must be the server's; `tick` the newest tick the operator
    /// has seen (informational), `seq` the operator's own counter.
    pub header: Header,
    /// The action.
    pub action: OperatorAction,
    /// `RunTicks`: how many frames to step before holding (at least 1). Other actions: 0
    /// (ignored).
    pub ticks: u64,
}

impl OperatorMsg {
    /// An operator command with `action` and `ticks`.
    pub fn new(header: Header, action: OperatorAction, ticks: u64) -> Self {
        Self {
            header,
            action,
            ticks,
        }
    }
}

/// Bits of [`EnvironmentMsg::flags`]: which parts of the environment are modelled (a field
/// whose model is off carries its neutral value: zero field, zero direction, full sunlight,
/// vacuum, zero wrench).
pub mod environment_flags {
    /// Bit 0: the configuration has an `[epoch]`: `tai_ns_1958` is set.
    pub const EPOCH_VALID: u8 = 1 << 0;
    /// Bit 1: a magnetic-field model is on (`b_n_t`, `b_b_t`).
    pub const MAGNETIC: u8 = 1 << 1;
    /// Bit 2: the Sun ephemeris is on (`sun_n`, `sun_b`).
    pub const SUN: u8 = 1 << 2;
    /// Bit 3: the Moon ephemeris is on (`moon_n`).
    pub const MOON: u8 = 1 << 3;
    /// Bit 4: a shadow model is on (`shadow_factor`, `eclipse`).
    pub const SHADOW: u8 = 1 << 4;
    /// Bit 5: an atmosphere model is on (`density_kg_m3`).
    pub const ATMOSPHERE: u8 = 1 << 5;
    /// Bits 6..7 are reserved: senders write 0, receivers ignore them.
    pub const RESERVED_MASK: u8 = !(EPOCH_VALID | MAGNETIC | SUN | MOON | SHADOW | ATMOSPHERE);
}

/// Values of [`EnvironmentMsg::eclipse`], from the shadow factor ν.
pub mod eclipse {
    /// ν = 1: the whole solar disc is visible (also without a shadow model).
    pub const SUNLIT: u8 = 0;
    /// 0 < ν < 1: part of the disc is hidden.
    pub const PENUMBRA: u8 = 1;
    /// ν = 0: the disc is hidden.
    pub const UMBRA: u8 = 2;

    /// The eclipse state of a shadow factor ν ∈ [0, 1].
    pub fn of_shadow_factor(nu: f64) -> u8 {
        if nu >= 1.0 {
            SUNLIT
        } else if nu <= 0.0 {
            UMBRA
        } else {
            PENUMBRA
        }
    }
}

/// The environment at the spacecraft, truth for operators, recordings and tests: topic
/// `flexdyn/<sc-id>/tlm/env`, at `[environment] telemetry_rate_hz`. 368 bytes.
///
/// Every value refers to the instant of `header.tick` (the end of that frame): the held
/// environment sample the dynamic effectors read at that instant, and each source's force and
/// torque evaluated by that dynamic effector itself at the tick's state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EnvironmentMsg {
    /// Common header; `tick` is the frame the values refer to.
    pub header: Header,
    /// \[ns\] TAI since 1958-01-01T00:00:00 TAI of `header.tick` (as [`TimeMsg::tai_ns_1958`]);
    /// 0 without an epoch.
    pub tai_ns_1958: u64,
    /// See [`environment_flags`].
    pub flags: u8,
    /// See [`eclipse`].
    pub eclipse: u8,
    /// \[T\] the planet's magnetic field at the spacecraft, N components.
    pub b_n_t: [f64; 3],
    /// \[T\] the same field, B components.
    pub b_b_t: [f64; 3],
    /// Unit vector from the hub point B to the Sun, N components (zero without the Sun).
    pub sun_n: [f64; 3],
    /// The same direction, B components.
    pub sun_b: [f64; 3],
    /// Unit vector from B to the Moon, N components (zero without the Moon).
    pub moon_n: [f64; 3],
    /// \[-\] fraction of the solar disc visible (1 sunlit, 0 umbra).
    pub shadow_factor: f64,
    /// \[kg/m³\] atmospheric mass density at the spacecraft.
    pub density_kg_m3: f64,
    /// Gravity-gradient torque about B and force at B, B components.
    pub gravity_gradient: AppliedWrench,
    /// Aerodynamic drag on the facets.
    pub drag: AppliedWrench,
    /// Solar radiation pressure on the facets.
    pub solar_pressure: AppliedWrench,
    /// The residual dipole's torque in the field (its force is zero: a uniform field).
    pub residual_dipole: AppliedWrench,
}

/// The fault modes' names by code (the `mode` of [`FaultEventMsg`] and [`FaultCommandMsg`]):
/// `proto/README.md`, "Fault modes"; the names a configuration's `[[faults]]` use.
pub const FAULT_MODE_NAMES: [&str; 21] = [
    "stuck_current",
    "stuck_value",
    "bias_step",
    "bias_ramp",
    "scale",
    "noise",
    "spikes",
    "dropout",
    "validity_off",
    "friction_scale",
    "torque_limit",
    "seized",
    "command_ignored",
    "stuck_on",
    "stuck_off",
    "thrust_scale",
    "dead",
    "dipole_scale",
    "dropped",
    "delayed",
    "corrupted",
];

/// A fault's target as written in a configuration (`imus.hub.gyro`, `reaction_wheels.rw2`):
/// [`FAULT_TARGET_LEN`] bytes of UTF-8, padded with NUL bytes (no length prefix on the wire; in
/// JSON, a string).
/// Protocol version 8.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct FaultTarget(pub [u8; FAULT_TARGET_LEN]);

impl FaultTarget {
    /// `target` padded with NULs; `None` if longer than [`FAULT_TARGET_LEN`] bytes or holding a
    /// NUL.
    pub fn new(target: &str) -> Option<Self> {
        let b = target.as_bytes();
        if b.len() > FAULT_TARGET_LEN || b.contains(&0) {
            return None;
        }
        let mut out = [0u8; FAULT_TARGET_LEN];
        out[..b.len()].copy_from_slice(b);
        Some(Self(out))
    }

    /// The bytes up to the first NUL, as UTF-8 (`None` if they are not).
    pub fn as_str(&self) -> Option<&str> {
        let n = self
            .0
            .iter()
            .position(|&b| b == 0)
            .unwrap_or(FAULT_TARGET_LEN);
        std::str::from_utf8(&self.0[..n]).ok()
    }

    /// `target` truncated to [`FAULT_TARGET_LEN`] bytes at a character boundary (for an event
    /// whose target is longer; the fault index stays exact).
    pub fn truncated(target: &str) -> Self {
        let mut end = target.len().min(FAULT_TARGET_LEN);
        while !target.is_char_boundary(end) {
            end -= 1;
        }
        let mut out = [0u8; FAULT_TARGET_LEN];
        for (o, b) in out.iter_mut().zip(&target.as_bytes()[..end]) {
            *o = if *b == 0 { b'?' } else { *b };
        }
        Self(out)
    }
}

impl FaultTarget {
    /// The text rule of `proto/README.md` ("Decoder rules", step 4): the text ends at its first
    /// NUL byte and every byte after it is NUL, so one target has one encoding. Another byte in
    /// the padding is [`crate::DecodeError::Malformed`], naming `field`.
    pub fn check_padding(&self, field: &str) -> Result<(), crate::DecodeError> {
        let Some(end) = self.0.iter().position(|&b| b == 0) else {
            return Ok(());
        };
        match self.0[end..].iter().position(|&b| b != 0) {
            None => Ok(()),
            Some(i) => Err(crate::DecodeError::Malformed(format!(
                "{field}: byte {} is 0x{:02x}, after the text ended (NUL) at byte {end}; the \
                 padding must be NUL",
                end + i,
                self.0[end + i]
            ))),
        }
    }
}

impl Default for FaultTarget {
    fn default() -> Self {
        Self([0; FAULT_TARGET_LEN])
    }
}

impl std::fmt::Debug for FaultTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.as_str() {
            Some(s) => write!(f, "FaultTarget({s:?})"),
            None => write!(f, "FaultTarget(<not UTF-8>)"),
        }
    }
}

impl Serialize for FaultTarget {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeTuple;
        // JSON (recordings, viewers): the text, bytes that are not UTF-8 replaced.
        if s.is_human_readable() {
            let n = self
                .0
                .iter()
                .position(|&b| b == 0)
                .unwrap_or(FAULT_TARGET_LEN);
            return s.serialize_str(&String::from_utf8_lossy(&self.0[..n]));
        }
        // A tuple: the bytes in order, no length prefix (as `[u8; N]` for N ≤ 32).
        let mut t = s.serialize_tuple(FAULT_TARGET_LEN)?;
        for b in &self.0 {
            t.serialize_element(b)?;
        }
        t.end()
    }
}

impl<'de> Deserialize<'de> for FaultTarget {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Bytes;
        impl<'de> serde::de::Visitor<'de> for Bytes {
            type Value = FaultTarget;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{FAULT_TARGET_LEN} bytes")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut a: A,
            ) -> Result<Self::Value, A::Error> {
                let mut out = [0u8; FAULT_TARGET_LEN];
                for (i, o) in out.iter_mut().enumerate() {
                    *o = a
                        .next_element()?
                        .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?;
                }
                Ok(FaultTarget(out))
            }
        }
        if d.is_human_readable() {
            let text = String::deserialize(d)?;
            return FaultTarget::new(&text)
                .ok_or_else(|| serde::de::Error::custom("a fault target of at most 128 bytes"));
        }
        d.deserialize_tuple(FAULT_TARGET_LEN, Bytes)
    }
}

/// Where a fault came from. Wire: u32 LE tag. Protocol version 8.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum FaultSource {
    /// Tag 0: a `[[faults]]` entry of the configuration (a schedule).
    #[default]
    Config,
    /// Tag 1: a live [`FaultCommandMsg`].
    Live,
    /// Tag 2: a `[[faults]]` entry with `mtbf_s` (its start drawn from its seed).
    Random,
}

impl FaultSource {
    /// The wire tag (the u32 LE variant index).
    pub const fn tag(self) -> u32 {
        self as u32
    }
}

/// A fault's activation or clearance, topic `flexdyn/<sc-id>/tlm/fault`. 199 bytes. Protocol
/// version 8.
///
/// Published at the frame boundary where the server sees the change: `header.tick` is that
/// boundary (the first tick whose sensor samples and actuation carry the change), `header.seq`
/// counts fault events from 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FaultEventMsg {
    /// Common header.
    pub header: Header,
    /// The fault's index: its position in the configuration's `[[faults]]` (from 0), or, for a
    /// live fault, the number of configured faults plus the live fault's order of acceptance.
    pub fault_index: u32,
    /// Where it came from.
    pub source: FaultSource,
    /// Its mode: the index in the server's mode table (`proto/README.md`, "Fault modes").
    pub mode: u32,
    /// `true`: activated at this tick; `false`: cleared.
    pub active: bool,
    /// \[ns\] simulation time the activation began or the clearance took effect (≤
    /// `header.sim_time_ns`; earlier when the window's edge lies inside the frame).
    pub edge_ns: u64,
    /// Selected axes, bit `a` for 1-based axis `a + 1`; 0: every axis.
    pub axes: u32,
    /// The mode's parameters in the order of its table row (unused: 0).
    pub params: [f64; 2],
    /// Its target as written (truncated to [`FAULT_TARGET_LEN`] bytes).
    pub target: FaultTarget,
}

/// What a [`FaultCommandMsg`] asks for. Wire: u32 LE tag. Protocol version 8.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum FaultAction {
    /// Tag 0: inject the fault the message describes.
    #[default]
    Inject,
    /// Tag 1: clear fault `fault_index` (configured or live) for the rest of the run.
    Clear,
}

impl FaultAction {
    /// The wire tag (the u32 LE variant index).
    pub const fn tag(self) -> u32 {
        self as u32
    }
}

/// A live fault command, topic `flexdyn/<sc-id>/fault`: inject a fault, or clear one. 214
/// bytes. Protocol version 8.
///
/// On a lab network the shipped access-control list lets only the operator's subject put on
/// this key (`scenarios/zenoh/secure-server.json5`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FaultCommandMsg {
    /// Common header: `spacecraft_id` must be the server's; `tick` the newest tick the sender
    /// has seen (informational); `seq` the sender's counter.
    pub header: Header,
    /// Inject or clear.
    pub action: FaultAction,
    /// The frame boundary at which it takes effect; [`AT_NEXT_TICK`]: the next one.
    pub at_tick: u64,
    /// `Clear`: the fault to clear. `Inject`: 0 (ignored).
    pub fault_index: u32,
    /// `Inject`: the mode (index in the mode table).
    pub mode: u32,
    /// `Inject`: the mode's parameters in its table row's order (unused: 0).
    pub params: [f64; 2],
    /// `Inject`: selected axes, bit `a` for 1-based axis `a + 1`; 0: every axis.
    pub axes: u32,
    /// `Inject`: \[ns\] how long it lasts; 0: until cleared.
    pub duration_ns: u64,
    /// `Inject`: the seed of its generator (`noise`, `spikes`).
    pub seed: u64,
    /// `Inject`: the target, as in `[[faults]]` (`imus.hub.gyro`).
    pub target: FaultTarget,
}

/// A deputy's motion relative to its chief, topic `flexdyn/<deputy-id>/tlm/rel/<chief-id>`.
/// 102 bytes. Protocol version 9 (issue 22).
///
/// Published by a fleet server (`flexdyn run --fleet`) every frame for each vehicle whose fleet
/// entry has a `[vehicles.relative]` table naming a chief, after the deputy's StateMsg of the
/// same tick. Both vehicles are taken at that tick and at their system centres of mass C
/// (for a vehicle whose centre of mass is its hub point B, StateMsg's `r_bn_n_m`, `v_bn_n_m_s`).
/// H is the chief's Hill frame: x̂ along the chief's position, ẑ along its orbital angular
/// momentum r × v, ŷ = ẑ × x̂ (along-track); it turns at (|r × v| / |r|²) ẑ.
/// `header.spacecraft_id` is the deputy's; `header.seq` counts the messages from 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RelativeStateMsg {
    /// Common header: the deputy's `spacecraft_id`; `tick` and `sim_time_ns` of the two
    /// vehicles' states.
    pub header: Header,
    /// The chief's numeric id (its messages' `header.spacecraft_id`).
    pub chief_spacecraft_id: u32,
    /// The deputy's numeric id (as `header.spacecraft_id`).
    pub deputy_spacecraft_id: u32,
    /// \[m\] r_Cd/Cc: the deputy's centre of mass relative to the chief's, H components.
    pub r_dc_h_m: [f64; 3],
    /// \[m/s\] its rate of change seen in the rotating frame H, H components.
    pub v_dc_h_m_s: [f64; 3],
    /// \[m\] |r_Cd/Cc|.
    pub range_m: f64,
    /// \[m/s\] d|r_Cd/Cc|/dt (the same in every frame).
    pub range_rate_m_s: f64,
}

/// FswMsg `flags`: which of its optional fields are set (protocol 10).
pub mod fsw_flags {
    /// Bit 0: `mode` is the flight code's mode at `header.tick`.
    pub const MODE: u8 = 1 << 0;
    /// Bit 1: `q_est_bn` is the flight code's attitude estimate.
    pub const ESTIMATE: u8 = 1 << 1;
    /// Bit 2: `q_target_rn` is the attitude the flight code points at.
    pub const TARGET: u8 = 1 << 2;
    /// Bit 3: `att_var_b_rad2` holds the estimate's error variances (needs ESTIMATE).
    pub const COVARIANCE: u8 = 1 << 3;
    /// Bits 4..7 are reserved: senders write 0, receivers ignore them.
    pub const RESERVED_MASK: u8 = !(MODE | ESTIMATE | TARGET | COVARIANCE);
}

/// A sample of the flight code's own telemetry stream `<name>`, topic
/// `flexdyn/<sc-id>/fsw/<name>`. 148 bytes + 8 per value word. Protocol version 10 (issue 37).
///
/// The stream is declared in the spacecraft configuration's `[[fsw_streams]]`: its modes, its
/// events (each with a severity) and its values (each an f64, i64 or bool, with a length and a
/// unit). The server checks a sample against that declaration, records it beside the truth, and
/// applies nothing from it to the physics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FswMsg {
    /// Common header: `tick` is the tick the flight code answered (the newest it has seen),
    /// `sim_time_ns` that tick's time, `seq` the sender's counter on this stream.
    pub header: Header,
    /// Which optional fields are set ([`fsw_flags`]).
    pub flags: u8,
    /// [`fsw_flags::MODE`]: index in the stream's `modes`.
    pub mode: u32,
    /// [`fsw_flags::ESTIMATE`]: the estimated attitude of B relative to N, quaternion (maps
    /// N → B), scalar first.
    pub q_est_bn: [f64; 4],
    /// [`fsw_flags::TARGET`]: the reference attitude R the flight code points B at,
    /// quaternion (maps N → R), scalar first.
    pub q_target_rn: [f64; 4],
    /// [`fsw_flags::COVARIANCE`]: \[rad²\] the variances of the estimate's attitude error
    /// about the body axes (the diagonal of its covariance).
    pub att_var_b_rad2: [f64; 3],
    /// Events raised at `header.tick` (at most [`crate::MAX_FSW_EVENTS`]).
    pub event_count: u8,
    /// Event k's index in the stream's `events`, k < `event_count`; the rest 0.
    pub events: [u16; 8],
    /// One word per element of the stream's declared `values`, in declaration order: an f64 as
    /// its IEEE-754 bits ([`f64::to_bits`]), an i64 in two's complement (`as u64`), a bool 0 or
    /// 1 (at most [`crate::MAX_FSW_VALUES`]).
    pub values: Vec<u64>,
}

impl Default for FswMsg {
    fn default() -> Self {
        Self {
            header: Header::default(),
            flags: 0,
            mode: 0,
            q_est_bn: [1.0, 0.0, 0.0, 0.0],
            q_target_rn: [1.0, 0.0, 0.0, 0.0],
            att_var_b_rad2: [0.0; 3],
            event_count: 0,
            events: [0; 8],
            values: Vec::new(),
        }
    }
}

impl FswMsg {
    /// The events raised, as indices in the stream's `events` (at most `event_count`, bounded by
    /// the array).
    pub fn event_indices(&self) -> &[u16] {
        &self.events[..usize::from(self.event_count).min(self.events.len())]
    }
}
