//! `flexdyn-decode-verdicts`: the Rust decoders' verdicts on a stream of buffers, in the
//! canonical text form the other codecs' differential tests compare against (the C driver
//! `proto/c/tests/fuzz_decode.c`, the Python package's `tests/test_proto_fuzz.py`).
//!
//! Input (stdin): records of a u32 LE length and that many bytes. Output (stdout): per record,
//! seventeen lines, one per decoder (state, imu, star tracker, magnetometer, css, fss,
//! environment, command, status, time, operator, header, gps, fault event, fault command,
//! relative state, fsw):
//! `E <reason> [numbers or field]` for an error (the `DecodeError` variant; `Length needed
//! actual`, `TrailingBytes expected actual`, `TooLarge actual`, `UnknownVersion found`,
//! `NonFinite field`, `Malformed`), or `O <fields>` for a decoded message: every field in wire
//! order, integers in lower-case hex, f64 as its bit pattern in hex.

use std::fmt::Write as _;
use std::io::{Read, Write};

use flexdyn_proto::{
    decode_command, decode_css, decode_environment, decode_fss, decode_header, decode_imu,
    decode_magnetometer, decode_operator, decode_star_tracker, decode_state, decode_status,
    decode_time, CommandKind, CommandMsg, DecodeError, EnvironmentMsg, Header, ImuMsg,
    MagnetometerMsg, OperatorMsg, StarTrackerMsg, StateMsg, StatusMsg, TimeMsg,
};
// The GPS receiver (protocol 7), the thirteenth decoder.
use flexdyn_proto::{decode_gps, GpsMsg};
// Fault injection (protocol 8), the fourteenth and fifteenth decoders.
use flexdyn_proto::{decode_fault_command, decode_fault_event, FaultCommandMsg, FaultEventMsg};
// A fleet deputy's relative state (protocol 9), the sixteenth decoder.
use flexdyn_proto::{decode_relative_state, RelativeStateMsg};
// The flight code's own telemetry (protocol 10), the seventeenth decoder.
use flexdyn_proto::{decode_fsw, FswMsg};

fn err_line(e: &DecodeError) -> String {
    match e {
        DecodeError::Length { needed, actual } => format!("E Length {needed} {actual}"),
        DecodeError::TrailingBytes { expected, actual } => {
            format!("E TrailingBytes {expected} {actual}")
        }
        DecodeError::TooLarge { actual, .. } => format!("E TooLarge {actual}"),
        DecodeError::UnknownVersion { found } => format!("E UnknownVersion {found}"),
        DecodeError::NonFinite { field } => format!("E NonFinite {field}"),
        DecodeError::Malformed(_) => "E Malformed".to_string(),
    }
}

struct Line(String);

impl Line {
    fn new() -> Self {
        Line("O".to_string())
    }
    fn u(&mut self, v: u64) -> &mut Self {
        let _ = write!(self.0, " {v:x}");
        self
    }
    fn f(&mut self, v: &[f64]) -> &mut Self {
        for x in v {
            let _ = write!(self.0, " {:x}", x.to_bits());
        }
        self
    }
    fn h(&mut self, h: &Header) -> &mut Self {
        self.u(h.protocol_version.into())
            .u(h.spacecraft_id.into())
            .u(h.tick)
            .u(h.sim_time_ns)
            .u(h.seq)
    }
}

fn state_line(m: &StateMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header)
        .f(&m.sigma_bn)
        .f(&m.q_bn)
        .f(&m.omega_bn_b_rad_s)
        .f(&m.omega_dot_bn_b_rad_s2)
        .f(&m.r_bn_n_m)
        .f(&m.v_bn_n_m_s)
        .f(&m.nongrav_accel_bn_n_m_s2)
        .f(&[m.conserved.orb_energy_j, m.conserved.rot_energy_j])
        .f(&m.conserved.orb_ang_mom_n)
        .f(&m.conserved.rot_ang_mom_c_n)
        .f(&m.wrench_applied.torque_b_nm)
        .f(&m.wrench_applied.force_b_newton)
        .u(m.command_flags.into())
        .u(m.effectors.len() as u64);
    for e in &m.effectors {
        l.u(e.kind.into())
            .u(e.flags.into())
            .u(e.states.len() as u64)
            .f(&e.states)
            .u(e.outputs.len() as u64)
            .f(&e.outputs);
    }
    l.0
}

fn imu_line(m: &ImuMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header)
        .f(&m.omega_p_rad_s)
        .f(&m.accel_p_m_s2)
        .f(&m.dtheta_p_rad)
        .f(&m.dv_p_m_s)
        .u(m.saturation_flags.into());
    l.0
}

fn star_tracker_line(m: &StarTrackerMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header)
        .f(&m.q_cn)
        .u(m.valid.into())
        .u(m.status_flags.into());
    l.0
}

fn magnetometer_line(m: &MagnetometerMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header).f(&m.b_s_t).u(m.saturation_flags.into());
    l.0
}

fn environment_line(m: &EnvironmentMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header)
        .u(m.tai_ns_1958)
        .u(m.flags.into())
        .u(m.eclipse.into())
        .f(&m.b_n_t)
        .f(&m.b_b_t)
        .f(&m.sun_n)
        .f(&m.sun_b)
        .f(&m.moon_n)
        .f(&[m.shadow_factor, m.density_kg_m3]);
    for w in [
        &m.gravity_gradient,
        &m.drag,
        &m.solar_pressure,
        &m.residual_dipole,
    ] {
        l.f(&w.torque_b_nm).f(&w.force_b_newton);
    }
    l.0
}

fn command_line(m: &CommandMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header).u(m.sender_id.into());
    match &m.kind {
        CommandKind::Wrench {
            torque_b_nm,
            force_b_newton,
        } => {
            l.u(0).f(torque_b_nm).f(force_b_newton);
        }
        CommandKind::NoCommand => {
            l.u(1);
        }
        CommandKind::Actuators {
            torque_b_nm,
            force_b_newton,
            inputs,
        } => {
            l.u(2)
                .f(torque_b_nm)
                .f(force_b_newton)
                .u(inputs.len() as u64);
            for i in inputs {
                l.u(i.effector_index.into())
                    .u(i.values.len() as u64)
                    .f(&i.values);
            }
        }
    }
    l.0
}

fn status_line(m: &StatusMsg) -> String {
    let r = &m.rejected;
    let mut l = Line::new();
    l.h(&m.header)
        .u(m.mode.tag().into())
        .u(m.run_state.tag().into())
        .u(m.timing.lateness_p50_ns)
        .u(m.timing.lateness_p99_ns)
        .u(m.timing.lateness_max_ns)
        .u(m.timing.overrun_count)
        .u(m.timing.frames_skipped)
        .u(m.command.last_command_tick)
        .u(m.command.command_age_ns)
        .u(m.command.command_stale.into())
        .u(m.command.stale_policy.tag().into())
        .u(r.malformed)
        .u(r.bad_version)
        .u(r.non_finite)
        .u(r.wrong_spacecraft)
        .u(r.stale_tick)
        .u(r.unknown_sender)
        .u(r.bad_effector_input)
        .u(r.wrong_identity)
        .u(r.operator_refused)
        .u(r.fault_refused)
        .u(r.fsw_refused)
        .u(m.commands_dropped)
        .u(m.wall_time_unix_ns)
        .u(m.faults_active);
    for w in m.faults_active_bits {
        l.u(w);
    }
    l.0
}

fn time_line(m: &TimeMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header)
        .u(m.run_state.tag().into())
        .u(m.mode.tag().into())
        .u(m.flags.into())
        .u(m.frame_ns)
        .f(&[m.speed])
        .u(m.tai_ns_1958)
        .u(m.utc.year.into())
        .u(m.utc.month.into())
        .u(m.utc.day.into())
        .u(m.utc.hour.into())
        .u(m.utc.minute.into())
        .u(m.utc.second.into())
        .u(m.utc.nanosecond.into())
        // The i32 as its two's-complement bit pattern.
        .u((m.tai_minus_utc_s as u32).into())
        .u(m.gps_week.into())
        .u(m.gps_ns_of_week)
        .u(m.met_ns);
    for b in m.cuc_tai {
        l.u(b.into());
    }
    l.u(m.tone_met.seconds.into())
        .u(m.tone_met.subseconds.into())
        .u(m.tone_tai.seconds.into())
        .u(m.tone_tai.subseconds.into());
    l.0
}

fn operator_line(m: &OperatorMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header).u(m.action.tag().into()).u(m.ticks);
    l.0
}

fn gps_line(m: &GpsMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header)
        .u(m.valid_sim_time_ns)
        .u(m.gps_week.into())
        .f(&[m.gps_seconds_of_week])
        .f(&m.r_be_e_m)
        .f(&m.v_be_e_m_s)
        .f(&m.r_bn_n_m)
        .f(&m.v_bn_n_m_s)
        .u(m.flags.into());
    l.0
}

fn fault_event_line(m: &FaultEventMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header)
        .u(m.fault_index.into())
        .u(m.source.tag().into())
        .u(m.mode.into())
        .u(m.active.into())
        .u(m.edge_ns)
        .u(m.axes.into())
        .f(&m.params);
    for b in m.target.0 {
        l.u(b.into());
    }
    l.0
}

fn fault_command_line(m: &FaultCommandMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header)
        .u(m.action.tag().into())
        .u(m.at_tick)
        .u(m.fault_index.into())
        .u(m.mode.into())
        .f(&m.params)
        .u(m.axes.into())
        .u(m.duration_ns)
        .u(m.seed);
    for b in m.target.0 {
        l.u(b.into());
    }
    l.0
}

fn relative_state_line(m: &RelativeStateMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header)
        .u(m.chief_spacecraft_id.into())
        .u(m.deputy_spacecraft_id.into())
        .f(&m.r_dc_h_m)
        .f(&m.v_dc_h_m_s)
        .f(&[m.range_m, m.range_rate_m_s]);
    l.0
}

fn fsw_line(m: &FswMsg) -> String {
    let mut l = Line::new();
    l.h(&m.header)
        .u(m.flags.into())
        .u(m.mode.into())
        .f(&m.q_est_bn)
        .f(&m.q_target_rn)
        .f(&m.att_var_b_rad2)
        .u(m.event_count.into());
    for e in m.events {
        l.u(e.into());
    }
    l.u(m.values.len() as u64);
    for &w in &m.values {
        l.u(w);
    }
    l.0
}

/// The seventeen verdicts for one buffer, in the order of the module docs.
fn rust_lines(b: &[u8]) -> Vec<String> {
    fn line<M>(r: Result<M, DecodeError>, f: impl Fn(&M) -> String) -> String {
        match r {
            Ok(m) => f(&m),
            Err(e) => err_line(&e),
        }
    }
    vec![
        line(decode_state(b), state_line),
        line(decode_imu(b), imu_line),
        line(decode_star_tracker(b), star_tracker_line),
        line(decode_magnetometer(b), magnetometer_line),
        line(decode_css(b), |m| {
            let mut l = Line::new();
            l.h(&m.header).u(m.detector_count.into()).f(&m.readings);
            l.0
        }),
        line(decode_fss(b), |m| {
            let mut l = Line::new();
            l.h(&m.header)
                .f(&[m.alpha_rad, m.beta_rad])
                .u(m.flags.into());
            l.0
        }),
        line(decode_environment(b), environment_line),
        line(decode_command(b), command_line),
        line(decode_status(b), status_line),
        line(decode_time(b), time_line),
        line(decode_operator(b), operator_line),
        line(decode_header(b), |h| {
            let mut l = Line::new();
            l.h(h);
            l.0
        }),
        line(decode_gps(b), gps_line),
        line(decode_fault_event(b), fault_event_line),
        line(decode_fault_command(b), fault_command_line),
        line(decode_relative_state(b), relative_state_line),
        line(decode_fsw(b), fsw_line),
    ]
}

fn main() -> std::process::ExitCode {
    let mut input = Vec::new();
    if let Err(e) = std::io::stdin().read_to_end(&mut input) {
        eprintln!("error: cannot read stdin: {e}");
        return std::process::ExitCode::FAILURE;
    }
    let mut out = String::new();
    let mut at = 0;
    while at < input.len() {
        let Some(len) = input
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
        else {
            eprintln!("error: truncated record length at byte {at}");
            return std::process::ExitCode::FAILURE;
        };
        let Some(buf) = input.get(at + 4..at + 4 + len) else {
            eprintln!("error: truncated record at byte {at}");
            return std::process::ExitCode::FAILURE;
        };
        for line in rust_lines(buf) {
            out.push_str(&line);
            out.push('\n');
        }
        at += 4 + len;
    }
    if let Err(e) = std::io::stdout().write_all(out.as_bytes()) {
        eprintln!("error: cannot write stdout: {e}");
        return std::process::ExitCode::FAILURE;
    }
    std::process::ExitCode::SUCCESS
}
