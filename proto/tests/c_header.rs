//! The C header `proto/c/include/flexdyn_proto.h` against the Rust codec.
//!
//! Each test compiles a C program with the system C compiler (`$CC`, else `cc`) using
//! `-std=c99 -Wall -Wextra -Werror -pedantic` and runs it:
//! - `c_codec_matches_the_golden_vectors`: `proto/c/tests/test_golden.c` encodes every golden
//!   message from its table values and decodes the golden files (`proto/golden/`) back;
//! - `c_and_rust_decoders_agree_on_100000_buffers`: `proto/c/tests/fuzz_decode.c` and the Rust
//!   decoders see the same 100,000 seeded buffers (valid messages of every type, mutated,
//!   truncated, extended, random with a valid version, oversized) through all six decoders;
//!   they must agree on accept/reject, on the reason (and its numbers or field), and on every
//!   decoded field bit for bit. Every buffer the C side decodes it also re-encodes, and that must
//!   be the input again (C encode → Rust decode of random valid messages; the Rust encode → C
//!   decode direction is the valid messages in the stream).

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use flexdyn_proto::{
    decode_command, decode_header, decode_imu, decode_star_tracker, decode_state, decode_status,
    encode, CommandKind, CommandMsg, DecodeError, EffectorInput, EffectorState, Header, ImuMsg,
    Mode, RejectCounters, RunState, StalePolicy, StarTrackerMsg, StateMsg, StatusMsg,
    MAX_MESSAGE_BYTES,
};
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

fn proto_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Compiles `proto/c/tests/<name>.c` into the test's temporary directory.
fn compile(name: &str) -> PathBuf {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".to_string());
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let src = proto_dir().join(format!("c/tests/{name}.c"));
    let result = Command::new(&cc)
        .args([
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-O2",
            "-I",
        ])
        .arg(proto_dir().join("c/include"))
        .arg(&src)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap_or_else(|e| {
            panic!(
                "no C compiler: running `{cc}` failed ({e}). Install one (Debian: `apt install \
                 gcc`) or set CC to its path; the C header checks need it"
            )
        });
    assert!(
        result.status.success(),
        "{cc} failed on {}:\n{}",
        src.display(),
        String::from_utf8_lossy(&result.stderr)
    );
    out
}

#[test]
fn c_codec_matches_the_golden_vectors() {
    let exe = compile("test_golden");
    let out = Command::new(&exe)
        .arg(proto_dir().join("golden"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    eprintln!("{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "test_golden failed");
    assert!(text.contains("all C golden checks passed"));
}

// ---------------------------------------------------------------------------------------------
// Canonical lines, as fuzz_decode.c prints them.

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

fn tag(m: Mode) -> u64 {
    match m {
        Mode::RealTime => 0,
        Mode::Lockstep => 1,
        Mode::Batch => 2,
    }
}

fn status_line(m: &StatusMsg) -> String {
    let run = match m.run_state {
        RunState::Starting => 0,
        RunState::Running => 1,
        RunState::Stopping => 2,
        RunState::Finished => 3,
        RunState::Failed => 4,
        RunState::Stopped => 5,
    };
    let policy = match m.command.stale_policy {
        StalePolicy::Hold => 0,
        StalePolicy::Zero => 1,
    };
    let r = &m.rejected;
    let mut l = Line::new();
    l.h(&m.header)
        .u(tag(m.mode))
        .u(run)
        .u(m.timing.lateness_p50_ns)
        .u(m.timing.lateness_p99_ns)
        .u(m.timing.lateness_max_ns)
        .u(m.timing.overrun_count)
        .u(m.timing.frames_skipped)
        .u(m.command.last_command_tick)
        .u(m.command.command_age_ns)
        .u(m.command.command_stale.into())
        .u(policy)
        .u(r.malformed)
        .u(r.bad_version)
        .u(r.non_finite)
        .u(r.wrong_spacecraft)
        .u(r.stale_tick)
        .u(r.unknown_sender)
        .u(r.bad_effector_input)
        .u(m.commands_dropped)
        .u(m.wall_time_unix_ns);
    l.0
}

/// The six Rust verdicts for one buffer, in fuzz_decode.c's order, and the buffer's encoding if
/// any decoder accepted it (what the C side must re-encode).
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
        line(decode_command(b), command_line),
        line(decode_status(b), status_line),
        line(decode_header(b), |h| {
            let mut l = Line::new();
            l.h(h);
            l.0
        }),
    ]
}

// ---------------------------------------------------------------------------------------------
// Seeded buffers.

struct Gen(ChaCha8Rng);

impl Gen {
    fn u64(&mut self) -> u64 {
        self.0.next_u64()
    }
    fn below(&mut self, n: u64) -> u64 {
        self.u64() % n
    }
    /// Mostly ordinary numbers, sometimes any bit pattern (NaN, ±inf, subnormals, −0.0).
    fn f64(&mut self) -> f64 {
        match self.below(8) {
            0 => f64::from_bits(self.u64()),
            1 => [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -0.0][self.below(4) as usize],
            _ => (self.u64() >> 11) as f64 / (1u64 << 40) as f64 - 4096.0,
        }
    }
    fn finite(&mut self) -> f64 {
        let x = self.f64();
        if x.is_finite() {
            x
        } else {
            1.5
        }
    }
    fn v<const N: usize>(&mut self) -> [f64; N] {
        std::array::from_fn(|_| self.f64())
    }
    fn header(&mut self) -> Header {
        Header::new(self.u64() as u32, self.u64(), self.u64(), self.u64())
    }
    fn values(&mut self, finite: bool) -> Vec<f64> {
        (0..self.below(9))
            .map(|_| if finite { self.finite() } else { self.f64() })
            .collect()
    }

    fn message(&mut self) -> Vec<u8> {
        match self.below(5) {
            0 => {
                let effectors = (0..self.below(6))
                    .map(|_| EffectorState {
                        kind: self.u64() as u16,
                        flags: self.u64() as u32,
                        states: self.values(false),
                        outputs: self.values(false),
                    })
                    .collect();
                let mut m = StateMsg {
                    header: self.header(),
                    sigma_bn: self.v(),
                    q_bn: self.v(),
                    omega_bn_b_rad_s: self.v(),
                    omega_dot_bn_b_rad_s2: self.v(),
                    r_bn_n_m: self.v(),
                    v_bn_n_m_s: self.v(),
                    nongrav_accel_bn_n_m_s2: self.v(),
                    command_flags: self.u64() as u8,
                    effectors,
                    ..StateMsg::default()
                };
                m.conserved.orb_energy_j = self.f64();
                m.conserved.rot_ang_mom_c_n = self.v();
                m.wrench_applied.force_b_newton = self.v();
                encode(&m)
            }
            1 => encode(&ImuMsg {
                header: self.header(),
                omega_p_rad_s: self.v(),
                accel_p_m_s2: self.v(),
                dtheta_p_rad: self.v(),
                dv_p_m_s: self.v(),
                saturation_flags: self.u64() as u8,
            }),
            2 => encode(&StarTrackerMsg {
                header: self.header(),
                q_cn: self.v(),
                valid: self.below(2) == 1,
                status_flags: self.u64() as u8,
            }),
            3 => {
                // Mostly finite (accepted), sometimes with a non-finite number (NonFinite).
                let finite = self.below(4) != 0;
                let v3 = |g: &mut Self| -> [f64; 3] {
                    std::array::from_fn(|_| if finite { g.finite() } else { g.f64() })
                };
                let (t, f) = (v3(self), v3(self));
                let kind = match self.below(3) {
                    0 => CommandKind::Wrench {
                        torque_b_nm: t,
                        force_b_newton: f,
                    },
                    1 => CommandKind::NoCommand,
                    _ => CommandKind::Actuators {
                        torque_b_nm: t,
                        force_b_newton: f,
                        inputs: (0..self.below(5))
                            .map(|_| EffectorInput {
                                effector_index: self.u64() as u32,
                                values: self.values(finite),
                            })
                            .collect(),
                    },
                };
                encode(&CommandMsg {
                    header: self.header(),
                    sender_id: self.u64() as u32,
                    kind,
                })
            }
            _ => {
                let mut m = StatusMsg {
                    header: self.header(),
                    commands_dropped: self.u64(),
                    wall_time_unix_ns: self.u64(),
                    rejected: RejectCounters {
                        malformed: self.u64(),
                        bad_effector_input: self.u64(),
                        ..RejectCounters::default()
                    },
                    ..StatusMsg::default()
                };
                m.mode = [Mode::RealTime, Mode::Lockstep, Mode::Batch][self.below(3) as usize];
                m.command.command_stale = self.below(2) == 1;
                m.command.last_command_tick = self.u64();
                encode(&m)
            }
        }
    }

    /// A buffer: a valid message, edited, cut, extended, random, or oversized.
    fn buffer(&mut self) -> Vec<u8> {
        let mut b = self.message();
        match self.below(10) {
            0..=2 => {}
            3..=5 => {
                for _ in 0..=self.below(8) {
                    let at = self.below(b.len() as u64) as usize;
                    b[at] = self.u64() as u8;
                }
            }
            6 => {
                let cut = self.below(b.len() as u64) as usize;
                b.truncate(cut);
            }
            7 => {
                for _ in 0..=self.below(16) {
                    b.push(self.u64() as u8);
                }
            }
            8 => {
                // Random bytes behind a valid version.
                let n = self.below(600) as usize;
                b = flexdyn_proto::PROTOCOL_VERSION.to_le_bytes().to_vec();
                b.extend((0..n).map(|_| self.u64() as u8));
            }
            _ => {
                if self.below(20) == 0 {
                    b = vec![3u8; MAX_MESSAGE_BYTES + 1 + self.below(8) as usize];
                } else {
                    // A count field rewritten with a large value.
                    let at = [319usize, 86, 327 + 6][self.below(3) as usize];
                    if b.len() >= at + 8 {
                        let v = [1025u64, 9, u64::MAX, 1u64 << 40][self.below(4) as usize];
                        b[at..at + 8].copy_from_slice(&v.to_le_bytes());
                    }
                }
            }
        }
        b
    }
}

#[test]
fn c_and_rust_decoders_agree_on_100000_buffers() {
    const N: usize = 100_000;
    let exe = compile("fuzz_decode");
    let mut g = Gen(ChaCha8Rng::seed_from_u64(0xC0DEC));
    let buffers: Vec<Vec<u8>> = (0..N).map(|_| g.buffer()).collect();
    let mut input = Vec::new();
    for b in &buffers {
        input.extend_from_slice(&(b.len() as u32).to_le_bytes());
        input.extend_from_slice(b);
    }
    let mut child = Command::new(&exe)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap().unwrap();
    assert!(out.status.success(), "fuzz_decode failed");
    let text = String::from_utf8(out.stdout).unwrap();
    let mut c_lines = text.lines();
    let (mut accepted, mut rejected) = (0usize, 0usize);
    let mut reasons = std::collections::BTreeMap::<String, usize>::new();
    for (i, b) in buffers.iter().enumerate() {
        for (decoder, want) in [
            "state",
            "imu",
            "star_tracker",
            "command",
            "status",
            "header",
        ]
        .iter()
        .zip(rust_lines(b))
        {
            let got = c_lines.next().unwrap_or("<missing>");
            assert_eq!(
                got,
                want,
                "buffer {i} ({} bytes), {decoder} decoder: C and Rust disagree",
                b.len()
            );
            if want.starts_with('O') {
                accepted += 1;
            } else {
                rejected += 1;
                let reason = want.split_whitespace().nth(1).unwrap_or("").to_string();
                *reasons.entry(reason).or_default() += 1;
            }
        }
    }
    assert!(c_lines.next().is_none(), "extra C output");
    eprintln!(
        "{N} buffers x 6 decoders: {accepted} accepted, {rejected} rejected, by reason {reasons:?}"
    );
    // The stream exercises every outcome.
    for r in [
        "Length",
        "TrailingBytes",
        "TooLarge",
        "UnknownVersion",
        "NonFinite",
        "Malformed",
    ] {
        assert!(reasons.get(r).copied().unwrap_or(0) > 0, "no {r} case");
    }
    assert!(accepted > 10_000);
}
