//! The generated conversions of `ctypes.rs` on the cases that matter to C: enum tags and flattened
//! counters in their members, and an array of effectors too small for the state.

use flexdyn_proto::{
    CommandStatus, EffectorState, Mode, RejectCounters, RunState, StalePolicy, StateMsg, StatusMsg,
};

use crate::ctypes::{fill_state, FdEffectorState, FdHeader, FdStateMsg, FdStatusMsg};
use crate::error::Code;

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
