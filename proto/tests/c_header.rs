//! The C header `proto/c/include/flexdyn_proto.h` against the Rust codec.
//!
//! Each test compiles a C program with the system C compiler (`$CC`, else `cc`) using
//! `-std=c99 -Wall -Wextra -Werror -pedantic` and runs it:
//! - `c_codec_matches_the_golden_vectors`: `proto/c/tests/test_golden.c` encodes every golden
//!   message from its table values and decodes the golden files (`proto/golden/`) back;
//! - `c_and_rust_decoders_agree_on_100000_buffers`: `proto/c/tests/fuzz_decode.c` and the Rust
//!   decoders see the same 100,000 seeded buffers (valid messages of every type, mutated,
//!   truncated, extended, random with a valid version, oversized) through all thirteen decoders;
//!   (`flexdyn-decode-verdicts`, the canonical verdict printer the Python SDK's fuzz test uses
//!   too); they must agree on accept/reject, on the reason (and its numbers or field), and on every
//!   decoded field bit for bit. Every buffer the C side decodes it also re-encodes, and that must
//!   be the input again (C encode → Rust decode of random valid messages; the Rust encode → C
//!   decode direction is the valid messages in the stream).
//! - `c_header_is_clean_as_cpp_under_strict_lints`: the header alone, as C++ (`$CXX`, else
//!   `g++`; and `clang++` too when it is installed) under `-Wold-style-cast
//!   -Wzero-as-null-pointer-constant -Wuseless-cast -Wconversion -Wsign-conversion`, and as C99
//!   under `-Wconversion -Wsign-conversion`, all with `-Werror`;
//! - `c_docs_name_the_current_protocol_version`: the header's and the C README's opening lines
//!   name `PROTOCOL_VERSION`.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use flexdyn_proto::{
    encode, AppliedWrench, CommandKind, CommandMsg, CssMsg, EffectorInput, EffectorState,
    EnvironmentMsg, FssMsg, Header, ImuMsg, MagnetometerMsg, Mode, OperatorAction, OperatorMsg,
    RejectCounters, RunState, StarTrackerMsg, StateMsg, StatusMsg, TimeMsg, MAX_MESSAGE_BYTES,
};
use flexdyn_proto::{FaultAction, FaultCommandMsg, FaultEventMsg, FaultSource, FaultTarget};
// The GPS receiver (protocol 7): generator arm 11, the thirteenth decoder.
use flexdyn_proto::GpsMsg;
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

fn proto_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Compiles `proto/c/tests/<name>.c` into the test's temporary directory.
fn compile(name: &str) -> PathBuf {
    compile_file(&format!("tests/{name}.c"), name)
}

/// Compiles `proto/c/<rel>` into the test's temporary directory as `name`.
fn compile_file(rel: &str, name: &str) -> PathBuf {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".to_string());
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let src = proto_dir().join("c").join(rel);
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

/// A translation unit that includes only the header, valid as C and as C++. From C++11 on it
/// defines `NULL` as a plain `0`, as some C++ libraries do (the standard allows it): g++'s own
/// `NULL` is `__null`, which its `-Wzero-as-null-pointer-constant` does not flag, while clang++
/// flags every `NULL` whatever its definition. With this, g++ finds each null-pointer `0` too.
const HEADER_ONLY_TU: &str = r#"#include <stddef.h>
#include <stdint.h>
#include <string.h>
#if defined(__cplusplus) && __cplusplus >= 201103L
#undef NULL
#define NULL 0
#endif
#include "flexdyn_proto.h"
int main(void) { return 0; }
"#;

/// Syntax-checks [`HEADER_ONLY_TU`] with `compiler` as `language` (`c` or `c++`) and `flags`;
/// the compiler's complaints on failure.
fn check_header_only(compiler: &str, language: &str, flags: &[&str]) -> Result<(), String> {
    let tu = Path::new(env!("CARGO_TARGET_TMPDIR")).join("header_only.txt");
    std::fs::write(&tu, HEADER_ONLY_TU).unwrap();
    let out = Command::new(compiler)
        .args(["-x", language, "-fsyntax-only", "-Werror"])
        .args(flags)
        .arg("-I")
        .arg(proto_dir().join("c/include"))
        .arg(&tu)
        .output()
        .map_err(|e| format!("cannot run `{compiler}`: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "{compiler} -x {language} {}:\n{}",
            flags.join(" "),
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

/// Whether `compiler --version` runs, and whether it is clang.
fn probe(compiler: &str) -> Option<bool> {
    let out = Command::new(compiler).arg("--version").output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).contains("clang"))
}

/// C++ flight code includes the header under the lints MISRA-minded teams build with. Before
/// the header wrote `static_cast` and `nullptr` in C++, clang++ gave 38 `-Wold-style-cast` and
/// 15 `-Wzero-as-null-pointer-constant` warnings and g++ 14 `-Wuseless-cast` ones. (g++ does
/// not apply `-Wold-style-cast` inside an `extern "C"` block, which is why the header has none:
/// its functions are all `static inline`.) C99 stays clean as well.
#[test]
fn c_header_is_clean_as_cpp_under_strict_lints() {
    const COMMON: &[&str] = &[
        "-Wall",
        "-Wextra",
        "-pedantic",
        "-Wconversion",
        "-Wsign-conversion",
        "-Wshadow",
        "-Wcast-qual",
    ];
    const CXX_LINTS: &[&str] = &["-Wold-style-cast", "-Wzero-as-null-pointer-constant"];
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".to_string());
    let cxx = std::env::var("CXX").unwrap_or_else(|_| "g++".to_string());
    let mut compilers = vec![(
        cxx.clone(),
        probe(&cxx).unwrap_or_else(|| {
            panic!(
                "no C++ compiler: `{cxx} --version` failed. Install g++ (Debian: `apt install \
                 g++`) or set CXX; the C header's C++ check needs it"
            )
        }),
    )];
    // clang++ when present (its -Wzero-as-null-pointer-constant also flags `__null`).
    if !cxx.contains("clang") {
        if let Some(is_clang) = probe("clang++") {
            compilers.push(("clang++".to_string(), is_clang));
        }
    }
    let mut failures = Vec::new();
    let c99: Vec<&str> = ["-std=c99"].iter().chain(COMMON).copied().collect();
    failures.extend(check_header_only(&cc, "c", &c99).err());
    for (compiler, is_clang) in &compilers {
        for std in ["-std=c++98", "-std=c++11", "-std=c++17"] {
            let mut flags: Vec<&str> = vec![std];
            flags.extend(COMMON);
            flags.extend(CXX_LINTS);
            if !is_clang {
                flags.push("-Wuseless-cast");
            }
            failures.extend(check_header_only(compiler, "c++", &flags).err());
        }
    }
    let names: Vec<&str> = compilers.iter().map(|(c, _)| c.as_str()).collect();
    eprintln!("C++ compilers checked: {names:?}, C compiler: {cc}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The opening lines of the header and of its README name the protocol version they implement.
#[test]
fn c_docs_name_the_current_protocol_version() {
    let want = format!("version {}", flexdyn_proto::PROTOCOL_VERSION);
    for (file, lines) in [("c/include/flexdyn_proto.h", 3), ("c/README.md", 4)] {
        let text = std::fs::read_to_string(proto_dir().join(file)).unwrap();
        let head: Vec<&str> = text.lines().take(lines).collect();
        let head = head.join(" ");
        assert!(
            head.contains(&want),
            "{file} opens with {head:?}, which does not say {want:?}"
        );
    }
    let header = std::fs::read_to_string(proto_dir().join("c/include/flexdyn_proto.h")).unwrap();
    assert!(header.contains(&format!(
        "#define FD_PROTOCOL_VERSION {}u",
        flexdyn_proto::PROTOCOL_VERSION
    )));
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

/// The C example control law (`proto/c/examples/pd_controller.c`) answers the golden StateMsg
/// with the Wrench command L = −K σ − P ω (K = 100, P = 300) for its tick, which the Rust
/// decoder accepts.
#[test]
fn c_pd_controller_example_answers_a_state() {
    let exe = compile_file("examples/pd_controller.c", "pd_controller");
    let golden = proto_dir().join("golden/state.bin");
    let out = Command::new(&exe).arg(&golden).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let state = flexdyn_proto::decode_state(&std::fs::read(&golden).unwrap()).unwrap();
    let cmd = flexdyn_proto::decode_command(&out.stdout).expect("a valid CommandMsg");
    assert_eq!(cmd.header.tick, state.header.tick);
    assert_eq!(cmd.header.spacecraft_id, state.header.spacecraft_id);
    assert_eq!(cmd.sender_id, 1);
    let want: [f64; 3] =
        std::array::from_fn(|i| -100.0 * state.sigma_bn[i] - 300.0 * state.omega_bn_b_rad_s[i]);
    assert_eq!(
        cmd.kind,
        CommandKind::Wrench {
            torque_b_nm: want,
            force_b_newton: [0.0; 3]
        }
    );
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

    fn wrench(&mut self) -> AppliedWrench {
        AppliedWrench {
            torque_b_nm: self.v(),
            force_b_newton: self.v(),
        }
    }

    fn message(&mut self) -> Vec<u8> {
        match self.below(16) {
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
            6 => {
                let mut m = TimeMsg {
                    header: self.header(),
                    run_state: RunState::from_tag(self.below(7) as u32).unwrap_or_default(),
                    mode: [Mode::RealTime, Mode::Lockstep, Mode::Batch][self.below(3) as usize],
                    flags: self.u64() as u8,
                    frame_ns: self.u64(),
                    speed: self.f64(),
                    tai_ns_1958: self.u64(),
                    tai_minus_utc_s: self.u64() as i32,
                    gps_week: self.u64() as u32,
                    gps_ns_of_week: self.u64(),
                    met_ns: self.u64(),
                    cuc_tai: self.u64().to_le_bytes(),
                    ..TimeMsg::default()
                };
                m.utc.year = self.u64() as u16;
                m.utc.second = self.u64() as u8;
                m.utc.nanosecond = self.u64() as u32;
                m.tone_met.subseconds = self.u64() as u32;
                m.tone_tai.seconds = self.u64() as u32;
                encode(&m)
            }
            7 => encode(&OperatorMsg::new(
                self.header(),
                [
                    OperatorAction::Pause,
                    OperatorAction::Resume,
                    OperatorAction::RunTicks,
                    OperatorAction::Checkpoint,
                ][self.below(4) as usize],
                self.u64(),
            )),
            5 => encode(&MagnetometerMsg {
                header: self.header(),
                b_s_t: self.v(),
                saturation_flags: self.u64() as u8,
            }),
            // Counts up to 17: the last is above the maximum (Malformed).
            8 => encode(&CssMsg {
                header: self.header(),
                detector_count: self.below(18) as u8,
                readings: self.v(),
            }),
            9 => encode(&FssMsg {
                header: self.header(),
                alpha_rad: self.f64(),
                beta_rad: self.f64(),
                flags: self.u64() as u8,
            }),
            10 => encode(&EnvironmentMsg {
                header: self.header(),
                tai_ns_1958: self.u64(),
                flags: self.u64() as u8,
                eclipse: self.u64() as u8,
                b_n_t: self.v(),
                b_b_t: self.v(),
                sun_n: self.v(),
                sun_b: self.v(),
                moon_n: self.v(),
                shadow_factor: self.f64(),
                density_kg_m3: self.f64(),
                gravity_gradient: self.wrench(),
                drag: self.wrench(),
                solar_pressure: self.wrench(),
                residual_dipole: self.wrench(),
                albedo_nadir_w_m2: self.f64(),
            }),
            11 => encode(&GpsMsg {
                header: self.header(),
                valid_sim_time_ns: self.u64(),
                gps_week: self.u64() as u32,
                gps_seconds_of_week: self.f64(),
                r_be_e_m: self.v(),
                v_be_e_m_s: self.v(),
                r_bn_n_m: self.v(),
                v_bn_n_m_s: self.v(),
                flags: self.u64() as u8,
            }),
            // Protocol 8: fault events (any tag and bool byte: edits make them malformed) and
            // fault commands (sometimes a non-finite parameter).
            12 => encode(&FaultEventMsg {
                header: self.header(),
                fault_index: self.u64() as u32,
                source: [FaultSource::Config, FaultSource::Live, FaultSource::Random]
                    [self.below(3) as usize],
                mode: self.below(18) as u32,
                active: self.below(2) == 1,
                edge_ns: self.u64(),
                axes: self.u64() as u32,
                params: self.v(),
                target: FaultTarget(std::array::from_fn(|_| self.u64() as u8)),
            }),
            // Protocol 10: the flight code's telemetry: event counts up to 9 (the last above the
            // maximum) and 0..12 value words, or 257 (above the maximum).
            15 => {
                let finite = self.below(4) != 0;
                let q = |s: &mut Self| -> f64 {
                    if finite {
                        s.finite()
                    } else {
                        s.f64()
                    }
                };
                let q_est_bn = [q(self), q(self), q(self), q(self)];
                let q_target_rn = [q(self), q(self), q(self), q(self)];
                let att_var_b_rad2 = [q(self), q(self), q(self)];
                let n = if self.below(8) == 0 {
                    257
                } else {
                    self.below(12)
                };
                encode(&flexdyn_proto::FswMsg {
                    header: self.header(),
                    flags: self.u64() as u8,
                    mode: self.u64() as u32,
                    q_est_bn,
                    q_target_rn,
                    att_var_b_rad2,
                    event_count: self.below(10) as u8,
                    events: std::array::from_fn(|_| self.u64() as u16),
                    values: (0..n).map(|_| self.u64()).collect(),
                })
            }
            // Protocol 9: a fleet deputy's relative state (fixed length, plain numbers).
            14 => encode(&flexdyn_proto::RelativeStateMsg {
                header: self.header(),
                chief_spacecraft_id: self.u64() as u32,
                deputy_spacecraft_id: self.u64() as u32,
                r_dc_h_m: self.v(),
                v_dc_h_m_s: self.v(),
                range_m: self.f64(),
                range_rate_m_s: self.f64(),
            }),
            13 => encode(&FaultCommandMsg {
                header: self.header(),
                action: [FaultAction::Inject, FaultAction::Clear][self.below(2) as usize],
                at_tick: self.u64(),
                fault_index: self.u64() as u32,
                mode: self.below(18) as u32,
                params: if self.below(4) == 0 {
                    self.v()
                } else {
                    [self.finite(), self.finite()]
                },
                axes: self.u64() as u32,
                duration_ns: self.u64(),
                seed: self.u64(),
                target: FaultTarget::new("imus.hub.gyro").unwrap_or_default(),
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
                        wrong_identity: self.u64(),
                        operator_refused: self.u64(),
                        fault_refused: self.u64(),
                        fsw_refused: self.u64(),
                        ..RejectCounters::default()
                    },
                    faults_active: self.u64(),
                    faults_active_bits: [self.u64(), 0, self.u64(), 1],
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
                    let at = [319usize, 86, 327 + 6, 140][self.below(4) as usize];
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

/// The Rust decoders' verdicts (`flexdyn-decode-verdicts`) on `records`.
fn rust_verdicts(records: &[u8]) -> String {
    let mut child = Command::new(env!("CARGO_BIN_EXE_flexdyn-decode-verdicts"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let input = records.to_vec();
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap().unwrap();
    assert!(out.status.success(), "flexdyn-decode-verdicts failed");
    String::from_utf8(out.stdout).unwrap()
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
    let records = input.clone();
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
    let rust = rust_verdicts(&records);
    let mut rust_lines = rust.lines();
    let mut c_lines = text.lines();
    let (mut accepted, mut rejected) = (0usize, 0usize);
    let mut reasons = std::collections::BTreeMap::<String, usize>::new();
    for (i, b) in buffers.iter().enumerate() {
        for decoder in [
            "state",
            "imu",
            "star_tracker",
            "magnetometer",
            "css",
            "fss",
            "environment",
            "command",
            "status",
            "time",
            "operator",
            "header",
            "gps",
            "fault_event",
            "fault_command",
            "relative_state",
            "fsw",
        ] {
            let want = rust_lines.next().expect("a Rust verdict per decoder");
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
        "{N} buffers x 17 decoders: {accepted} accepted, {rejected} rejected, by reason {reasons:?}"
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
