//! The structs of `proto/c/include/flexdyn_proto.h`, field for field (`#[repr(C)]`, same types,
//! same order), and the conversions from and to the Rust messages. The C test
//! (`tests/c_client.rs`, `struct_layouts_agree`) decodes the golden messages once with the
//! header's own decoders and once through these conversions and compares every field, and
//! compares each struct's size.
//!
//! The fields are those of the C header, documented there (names, frames and units).
#![allow(missing_docs)]

use flexdyn_proto::{
    CommandStatus, EffectorInput, EffectorState, FrameTiming, Header, ImuMsg, Mode, RejectCounters,
    RunState, StalePolicy, StarTrackerMsg, StateMsg, StatusMsg, SysTime, TimeMsg,
    MAX_EFFECTOR_VALUES,
};

use crate::error::{Code, Error};

/// `fd_header`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FdHeader {
    pub protocol_version: u16,
    pub spacecraft_id: u32,
    pub tick: u64,
    pub sim_time_ns: u64,
    pub seq: u64,
}

/// `fd_effector_state`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FdEffectorState {
    pub kind: u16,
    pub flags: u32,
    pub n_states: u64,
    pub states: [f64; MAX_EFFECTOR_VALUES],
    pub n_outputs: u64,
    pub outputs: [f64; MAX_EFFECTOR_VALUES],
}

/// `fd_state_msg`: `effectors` points to the caller's `effectors_capacity` entries.
#[repr(C)]
#[derive(Debug)]
pub struct FdStateMsg {
    pub header: FdHeader,
    pub sigma_bn: [f64; 3],
    pub q_bn: [f64; 4],
    pub omega_bn_b_rad_s: [f64; 3],
    pub omega_dot_bn_b_rad_s2: [f64; 3],
    pub r_bn_n_m: [f64; 3],
    pub v_bn_n_m_s: [f64; 3],
    pub nongrav_accel_bn_n_m_s2: [f64; 3],
    pub orb_energy_j: f64,
    pub rot_energy_j: f64,
    pub orb_ang_mom_n: [f64; 3],
    pub rot_ang_mom_c_n: [f64; 3],
    pub torque_b_nm: [f64; 3],
    pub force_b_newton: [f64; 3],
    pub command_flags: u8,
    pub n_effectors: u64,
    pub effectors: *mut FdEffectorState,
    pub effectors_capacity: usize,
}

/// `fd_imu_msg`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FdImuMsg {
    pub header: FdHeader,
    pub omega_p_rad_s: [f64; 3],
    pub accel_p_m_s2: [f64; 3],
    pub dtheta_p_rad: [f64; 3],
    pub dv_p_m_s: [f64; 3],
    pub saturation_flags: u8,
}

/// `fd_star_tracker_msg`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FdStarTrackerMsg {
    pub header: FdHeader,
    pub q_cn: [f64; 4],
    pub valid: u8,
    pub status_flags: u8,
}

/// `fd_effector_input`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FdEffectorInput {
    pub effector_index: u32,
    pub n_values: u64,
    pub values: [f64; MAX_EFFECTOR_VALUES],
}

/// `fd_status_msg`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FdStatusMsg {
    pub header: FdHeader,
    pub mode: u32,
    pub run_state: u32,
    pub lateness_p50_ns: u64,
    pub lateness_p99_ns: u64,
    pub lateness_max_ns: u64,
    pub overrun_count: u64,
    pub frames_skipped: u64,
    pub last_command_tick: u64,
    pub command_age_ns: u64,
    pub command_stale: u8,
    pub stale_policy: u32,
    pub rejected_malformed: u64,
    pub rejected_bad_version: u64,
    pub rejected_non_finite: u64,
    pub rejected_wrong_spacecraft: u64,
    pub rejected_stale_tick: u64,
    pub rejected_unknown_sender: u64,
    pub rejected_bad_effector_input: u64,
    pub rejected_wrong_identity: u64,
    pub rejected_operator_refused: u64,
    pub rejected_fault_refused: u64,
    pub rejected_fsw_refused: u64,
    pub commands_dropped: u64,
    pub wall_time_unix_ns: u64,
    pub faults_active: u64,
    pub faults_active_bits: [u64; 4],
}

/// `fd_sys_time`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FdSysTime {
    pub seconds: u32,
    pub subseconds: u32,
}

/// `fd_time_msg`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FdTimeMsg {
    pub header: FdHeader,
    pub run_state: u32,
    pub mode: u32,
    pub flags: u8,
    pub frame_ns: u64,
    pub speed: f64,
    pub tai_ns_1958: u64,
    pub utc_year: u16,
    pub utc_month: u8,
    pub utc_day: u8,
    pub utc_hour: u8,
    pub utc_minute: u8,
    pub utc_second: u8,
    pub utc_nanosecond: u32,
    pub tai_minus_utc_s: i32,
    pub gps_week: u32,
    pub gps_ns_of_week: u64,
    pub met_ns: u64,
    pub cuc_tai: [u8; 8],
    pub tone_met: FdSysTime,
    pub tone_tai: FdSysTime,
}

impl From<SysTime> for FdSysTime {
    fn from(t: SysTime) -> Self {
        Self {
            seconds: t.seconds,
            subseconds: t.subseconds,
        }
    }
}

impl From<&TimeMsg> for FdTimeMsg {
    fn from(m: &TimeMsg) -> Self {
        Self {
            header: (&m.header).into(),
            run_state: m.run_state.tag(),
            mode: m.mode.tag(),
            flags: m.flags,
            frame_ns: m.frame_ns,
            speed: m.speed,
            tai_ns_1958: m.tai_ns_1958,
            utc_year: m.utc.year,
            utc_month: m.utc.month,
            utc_day: m.utc.day,
            utc_hour: m.utc.hour,
            utc_minute: m.utc.minute,
            utc_second: m.utc.second,
            utc_nanosecond: m.utc.nanosecond,
            tai_minus_utc_s: m.tai_minus_utc_s,
            gps_week: m.gps_week,
            gps_ns_of_week: m.gps_ns_of_week,
            met_ns: m.met_ns,
            cuc_tai: m.cuc_tai,
            tone_met: m.tone_met.into(),
            tone_tai: m.tone_tai.into(),
        }
    }
}

impl From<&Header> for FdHeader {
    fn from(h: &Header) -> Self {
        Self {
            protocol_version: h.protocol_version,
            spacecraft_id: h.spacecraft_id,
            tick: h.tick,
            sim_time_ns: h.sim_time_ns,
            seq: h.seq,
        }
    }
}

/// `n` copied into a fixed C array of [`MAX_EFFECTOR_VALUES`] (the Rust decoder has bounded it).
fn values(v: &[f64]) -> (u64, [f64; MAX_EFFECTOR_VALUES]) {
    let mut out = [0.0; MAX_EFFECTOR_VALUES];
    let n = v.len().min(MAX_EFFECTOR_VALUES);
    out[..n].copy_from_slice(&v[..n]);
    (n as u64, out)
}

impl From<&EffectorState> for FdEffectorState {
    fn from(e: &EffectorState) -> Self {
        let (n_states, states) = values(&e.states);
        let (n_outputs, outputs) = values(&e.outputs);
        Self {
            kind: e.kind,
            flags: e.flags,
            n_states,
            states,
            n_outputs,
            outputs,
        }
    }
}

/// Fills `out` from `m`: the effectors into `effectors` (the caller's array, its capacity).
/// Too small an array is [`Code::Capacity`] and writes nothing (as `fd_decode_state`).
pub fn fill_state(
    m: &StateMsg,
    out: &mut FdStateMsg,
    effectors: &mut [FdEffectorState],
) -> Result<(), Error> {
    if m.effectors.len() > effectors.len() {
        return Err(Error::new(
            Code::Capacity,
            format!(
                "the state of tick {} has {} effectors, the array holds {}",
                m.header.tick,
                m.effectors.len(),
                effectors.len()
            ),
        ));
    }
    out.header = (&m.header).into();
    out.sigma_bn = m.sigma_bn;
    out.q_bn = m.q_bn;
    out.omega_bn_b_rad_s = m.omega_bn_b_rad_s;
    out.omega_dot_bn_b_rad_s2 = m.omega_dot_bn_b_rad_s2;
    out.r_bn_n_m = m.r_bn_n_m;
    out.v_bn_n_m_s = m.v_bn_n_m_s;
    out.nongrav_accel_bn_n_m_s2 = m.nongrav_accel_bn_n_m_s2;
    out.orb_energy_j = m.conserved.orb_energy_j;
    out.rot_energy_j = m.conserved.rot_energy_j;
    out.orb_ang_mom_n = m.conserved.orb_ang_mom_n;
    out.rot_ang_mom_c_n = m.conserved.rot_ang_mom_c_n;
    out.torque_b_nm = m.wrench_applied.torque_b_nm;
    out.force_b_newton = m.wrench_applied.force_b_newton;
    out.command_flags = m.command_flags;
    out.n_effectors = m.effectors.len() as u64;
    for (slot, e) in effectors.iter_mut().zip(&m.effectors) {
        *slot = e.into();
    }
    Ok(())
}

impl From<&ImuMsg> for FdImuMsg {
    fn from(m: &ImuMsg) -> Self {
        Self {
            header: (&m.header).into(),
            omega_p_rad_s: m.omega_p_rad_s,
            accel_p_m_s2: m.accel_p_m_s2,
            dtheta_p_rad: m.dtheta_p_rad,
            dv_p_m_s: m.dv_p_m_s,
            saturation_flags: m.saturation_flags,
        }
    }
}

impl From<&StarTrackerMsg> for FdStarTrackerMsg {
    fn from(m: &StarTrackerMsg) -> Self {
        Self {
            header: (&m.header).into(),
            q_cn: m.q_cn,
            valid: u8::from(m.valid),
            status_flags: m.status_flags,
        }
    }
}

impl From<&StatusMsg> for FdStatusMsg {
    fn from(m: &StatusMsg) -> Self {
        let StatusMsg {
            header,
            mode,
            run_state,
            timing,
            command,
            rejected,
            commands_dropped,
            wall_time_unix_ns,
            faults_active,
            faults_active_bits,
        } = m;
        let FrameTiming {
            lateness_p50_ns,
            lateness_p99_ns,
            lateness_max_ns,
            overrun_count,
            frames_skipped,
        } = *timing;
        let CommandStatus {
            last_command_tick,
            command_age_ns,
            command_stale,
            stale_policy,
        } = *command;
        let RejectCounters {
            malformed,
            bad_version,
            non_finite,
            wrong_spacecraft,
            stale_tick,
            unknown_sender,
            bad_effector_input,
            wrong_identity,
            operator_refused,
            fault_refused,
            fsw_refused,
        } = *rejected;
        Self {
            header: header.into(),
            mode: Mode::tag(*mode),
            run_state: RunState::tag(*run_state),
            lateness_p50_ns,
            lateness_p99_ns,
            lateness_max_ns,
            overrun_count,
            frames_skipped,
            last_command_tick,
            command_age_ns,
            command_stale: u8::from(command_stale),
            stale_policy: StalePolicy::tag(stale_policy),
            rejected_malformed: malformed,
            rejected_bad_version: bad_version,
            rejected_non_finite: non_finite,
            rejected_wrong_spacecraft: wrong_spacecraft,
            rejected_stale_tick: stale_tick,
            rejected_unknown_sender: unknown_sender,
            rejected_bad_effector_input: bad_effector_input,
            rejected_wrong_identity: wrong_identity,
            rejected_operator_refused: operator_refused,
            rejected_fault_refused: fault_refused,
            rejected_fsw_refused: fsw_refused,
            commands_dropped: *commands_dropped,
            wall_time_unix_ns: *wall_time_unix_ns,
            faults_active: *faults_active,
            faults_active_bits: *faults_active_bits,
        }
    }
}

/// The Rust input of one C `fd_effector_input`; its value count must be at most
/// [`MAX_EFFECTOR_VALUES`] and every value finite (the server rejects anything else).
pub fn effector_input(index: usize, c: &FdEffectorInput) -> Result<EffectorInput, Error> {
    let n = usize::try_from(c.n_values)
        .ok()
        .filter(|n| *n <= MAX_EFFECTOR_VALUES)
        .ok_or_else(|| {
            Error::new(
                Code::Argument,
                format!(
                    "inputs[{index}].n_values = {} exceeds {MAX_EFFECTOR_VALUES}",
                    c.n_values
                ),
            )
        })?;
    let values = &c.values[..n];
    if let Some(j) = values.iter().position(|v| !v.is_finite()) {
        return Err(Error::new(
            Code::Argument,
            format!("inputs[{index}].values[{j}] = {} is not finite", values[j]),
        ));
    }
    Ok(EffectorInput {
        effector_index: c.effector_index,
        values: values.to_vec(),
    })
}

/// Checks that a wrench is finite (`what` names it in the error).
pub fn finite3(what: &str, v: &[f64; 3]) -> Result<(), Error> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::new(
            Code::Argument,
            format!("{what}[{i}] = {} is not finite", v[i]),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_tags_and_counters_land_in_their_fields() {
        let m = StatusMsg {
            mode: Mode::Lockstep,
            run_state: RunState::Stopped,
            rejected: RejectCounters {
                stale_tick: 7,
                wrong_identity: 9,
                ..RejectCounters::default()
            },
            command: CommandStatus {
                command_stale: true,
                stale_policy: StalePolicy::Zero,
                ..CommandStatus::default()
            },
            ..StatusMsg::default()
        };
        let c = FdStatusMsg::from(&m);
        assert_eq!((c.mode, c.run_state, c.stale_policy), (1, 5, 1));
        assert_eq!((c.rejected_stale_tick, c.rejected_wrong_identity), (7, 9));
        assert_eq!(c.command_stale, 1);
    }

    #[test]
    fn a_state_with_more_effectors_than_the_array_writes_nothing() {
        let m = StateMsg {
            effectors: vec![EffectorState::default(); 3],
            ..StateMsg::default()
        };
        let mut out = FdStateMsg {
            header: FdHeader::default(),
            sigma_bn: [5.0; 3],
            q_bn: [0.0; 4],
            omega_bn_b_rad_s: [0.0; 3],
            omega_dot_bn_b_rad_s2: [0.0; 3],
            r_bn_n_m: [0.0; 3],
            v_bn_n_m_s: [0.0; 3],
            nongrav_accel_bn_n_m_s2: [0.0; 3],
            orb_energy_j: 0.0,
            rot_energy_j: 0.0,
            orb_ang_mom_n: [0.0; 3],
            rot_ang_mom_c_n: [0.0; 3],
            torque_b_nm: [0.0; 3],
            force_b_newton: [0.0; 3],
            command_flags: 0,
            n_effectors: 0,
            effectors: std::ptr::null_mut(),
            effectors_capacity: 0,
        };
        let mut two = [FdEffectorState::default(); 2];
        let e = fill_state(&m, &mut out, &mut two).unwrap_err();
        assert_eq!(e.code, Code::Capacity);
        assert_eq!(out.sigma_bn, [5.0; 3], "nothing written");
        let mut three = [FdEffectorState::default(); 3];
        fill_state(&m, &mut out, &mut three).unwrap();
        assert_eq!((out.n_effectors, out.sigma_bn), (3, [0.0; 3]));
    }

    #[test]
    fn bad_effector_inputs_are_named() {
        let mut c = FdEffectorInput {
            effector_index: 4,
            n_values: 9,
            ..FdEffectorInput::default()
        };
        let e = effector_input(2, &c).unwrap_err();
        assert_eq!(e.message, "inputs[2].n_values = 9 exceeds 8");
        c.n_values = 2;
        c.values[1] = f64::NAN;
        let e = effector_input(0, &c).unwrap_err();
        assert_eq!(e.message, "inputs[0].values[1] = NaN is not finite");
        c.values[1] = 0.25;
        let r = effector_input(0, &c).unwrap();
        assert_eq!((r.effector_index, r.values), (4, vec![0.0, 0.25]));
    }
}
