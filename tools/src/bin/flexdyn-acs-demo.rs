//! `flexdyn-acs-demo`: a demo attitude controller for the flexdyn server — and the template to
//! copy when you attach your own flight code.
//!
//! # What it does
//! Every time the server publishes the spacecraft state (`flexdyn/<sc>/tlm/state`, one
//! [`StateMsg`](flexdyn_proto::StateMsg) per frame) this program computes the MRP proportional-derivative control torque
//!
//! ```text
//!     L = −K σ_BR − P ω_BR            (Schaub & Junkins, Analytical Mechanics of Space
//!                                      Systems, ch. 8: MRP feedback control)
//! ```
//!
//! and publishes it as a [`CommandMsg`] on `flexdyn/<sc>/cmd/<sender-id>`, stamped with the tick of
//! the state it answers. σ_BR is the MRP attitude error of the body B relative to the target
//! frame R (given as σ_RN with ω_RN = 0, so ω_BR = ω_BN).
//!
//! # Real time and lockstep: one loop
//! The loop is the same in both server modes:
//! - **real time**: the server never waits; it applies the latest command it has (typically the
//!   answer to the previous frame) and flags commands that get too old;
//! - **lockstep**: the server waits for our answer to tick k before stepping to k+1, so the run
//!   is bit-for-bit reproducible. Two rules make that work, both followed below:
//!   1. answer **every** state, stamped with **its** tick (send `CommandKind::NoCommand` if you
//!      have nothing to command);
//!   2. subscribe to the state topic **before** declaring the liveliness token
//!      `flexdyn/<sc>/participant/<sender-id>`: the server starts at tick 0 only once it sees
//!      the token.
//!
//! # Tuning (linearised closed loop, per principal axis with inertia I)
//! With σ̇ ≈ ω/4 for small errors, I ω̇ = −Kσ − Pω gives σ̈ + (P/I) σ̇ + (K/4I) σ = 0:
//! ω_n = √(K/(4I)), ζ = P/√(K I), decay rate ζ ω_n = P/(2I), 2 % settling ≈ 8 I / P.
//! The defaults (K = 100 N·m, P = 300 N·m·s) suit the reference spacecraft
//! (I ≈ 1100…1800 kg·m² about the centre of mass): ζ ≈ 0.7…0.9, settling ≈ 30…50 s.
//!
//! # Rate feedback from the gyro
//! Flight code reads rate gyros, not truth, so by default the rate comes from an IMU the server
//! publishes on `flexdyn/<sc>/tlm/imu/<name>` ([`ImuMsg`], one per frame, stamped with the same
//! tick as the state and published just before it): ω_B = [PB]ᵀ ω_P, with [PB] the IMU's
//! mounting (`--imu-dcm-pb`, as in the server's `[[imus]]`). `--rate-source`:
//! - `gyro`: use the IMU `--imu NAME` (an error if it never publishes; a later missed sample
//!   holds the previous rate, and is counted and logged);
//! - `auto` (default): `gyro` if `--imu NAME` is given, otherwise the state message's truth
//!   rate (said in the log). It never guesses an IMU: the mounting [PB] of an IMU it picked by
//!   itself would be unknown, and a wrong mounting rotates the rate feedback (on a rotated IMU
//!   that spins the craft up instead of damping it);
//! - `truth`: the state message's ω_BN.
//!
//! # Reaction wheels and the star tracker
//! With `--config` (the server's scenario: the flight code's copy of the geometry):
//! - `--actuator wheels` turns the torque into reaction-wheel motor torques: the law adds the
//!   wheel-momentum gyroscopic term, L = −Kσ − Pω + ω × ([I]ω + [G_s]h_s), and u = −[G_s]⁺L is
//!   sent as one `CommandKind::Actuators` per tick ([`flexdyn_tools::acs`]);
//! - `--attitude-source star-tracker --star-tracker NAME` takes σ_BN from that tracker's
//!   q_CN through its mounting [CB], propagated with the rate feedback between its updates; until
//!   its first valid sample the answer is `NoCommand`.
//!
//! With `--rate-source gyro --imu NAME` as well, the loop uses no truth at all.
//!
//! # Copying this file
//! Keep `main`'s order (session → subscribers → publisher → token → loop). Replace
//! [`GyroFeedback`] by your rate source and [`Controller::torque_b_nm`] by your control law.
//! Everything on the wire comes from the `flexdyn-proto` crate (see `proto/README.md` for C and
//! Python byte layouts).

use std::time::Duration;

use anyhow::{bail, Context as _};
use clap::Parser;
use flexdyn::numfmt::Rounded;
use flexdyn_proto::{
    decode_imu, decode_star_tracker, decode_state, encode_into, CommandMsg, Header, ImuMsg,
};
use flexdyn_tools::CommonArgs;
use nalgebra::Vector3;
use zenoh::handlers::{RingChannel, RingChannelHandler};
use zenoh::qos::CongestionControl;
use zenoh::sample::Sample;
use zenoh::Wait;

/// Demo MRP PD attitude controller: subscribes to flexdyn state, publishes torque commands.
#[derive(Debug, Parser)]
#[command(name = "flexdyn-acs-demo", version)]
struct Args {
    #[command(flatten)]
    common: CommonArgs,
    /// Our sender id (must be in the server's `participants`).
    #[arg(long, default_value_t = 1)]
    sender_id: u32,
    /// Attitude gain K [N·m per unit MRP].
    #[arg(long, default_value_t = 100.0, allow_negative_numbers = true)]
    k_nm: f64,
    /// Rate gain P [N·m·s/rad].
    #[arg(long, default_value_t = 300.0, allow_negative_numbers = true)]
    p_nms: f64,
    /// Target attitude σ_RN (MRP, three comma-separated numbers); ω_RN = 0.
    #[arg(long, value_name = "X,Y,Z", value_delimiter = ',', default_values_t = [0.0, 0.0, 0.0],
          allow_hyphen_values = true)]
    sigma_rn: Vec<f64>,
    /// Log a progress line every this many seconds of simulation time (0: never).
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    log_every_s: f64,
    /// Exit after this many seconds without a state: exit 0 if states were received (the run
    /// ended), exit 1 if none ever came (no server). Default: run until SIGINT/SIGTERM.
    #[arg(long, allow_negative_numbers = true)]
    idle_exit_s: Option<f64>,
    /// Where the rate feedback comes from. `gyro`: the IMU named by --imu, mounted as
    /// --imu-dcm-pb (an error if it never publishes; a missed sample holds the previous rate).
    /// `truth`: the state message's ω_BN. `auto`: `gyro` if --imu is given, else `truth`
    /// (logged); it never guesses an IMU, since its mounting would be unknown.
    #[arg(long, value_enum, default_value_t = RateSource::Auto)]
    rate_source: RateSource,
    /// The IMU whose gyro feeds the rate loop (its `[[imus]] name` in the server config).
    #[arg(long)]
    imu: Option<String>,
    /// That IMU's mounting [PB] (maps B to platform P), nine comma-separated numbers, row-major.
    #[arg(long, value_name = "9 NUMBERS", value_delimiter = ',', allow_hyphen_values = true,
          default_values_t = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0])]
    imu_dcm_pb: Vec<f64>,
    /// Longest wait [s] for the IMU's first sample before giving up (error); later samples are
    /// waited for at most 50 ms, then the previous rate is held. The same limits apply to the
    /// star tracker.
    #[arg(long, default_value_t = 5.0, allow_negative_numbers = true)]
    imu_timeout_s: f64,
    /// The server's scenario file: the flight code's copy of the spacecraft's geometry (wheel
    /// axes and inertias, star-tracker and IMU mountings, mass properties). Needed by
    /// `--actuator wheels` and `--attitude-source star-tracker`; with `--imu`, the IMU's
    /// mounting is taken from it.
    #[arg(long, value_name = "FILE")]
    config: Option<std::path::PathBuf>,
    /// What to command: `wrench` (a body torque) or `wheels` (reaction-wheel motor torques
    /// through an `Actuators` command, with wheel-momentum gyroscopic compensation).
    #[arg(long, value_enum, default_value_t = Actuator::Wrench)]
    actuator: Actuator,
    /// Where the attitude comes from: `truth` (the state message's σ_BN) or `star-tracker`
    /// (the tracker named by --star-tracker, propagated with the rate feedback between its
    /// updates; no command until its first valid measurement).
    #[arg(long, value_enum, default_value_t = AttitudeSource::Truth)]
    attitude_source: AttitudeSource,
    /// The star tracker feeding the attitude (its `[[star_trackers]] name`).
    #[arg(long)]
    star_tracker: Option<String>,
}

/// What the controller commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum Actuator {
    /// A body torque (`CommandKind::Wrench`).
    Wrench,
    /// Reaction-wheel motor torques (`CommandKind::Actuators`).
    Wheels,
}

/// Where the attitude comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum AttitudeSource {
    /// The state message's σ_BN.
    Truth,
    /// A star tracker's q_CN, mounted as in --config.
    StarTracker,
}

/// Rate feedback source.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum RateSource {
    /// The IMU named by `--imu` if given, else (with a log line) the truth rate. Never an IMU
    /// whose mounting was not given.
    Auto,
    /// The IMU named by `--imu`.
    Gyro,
    /// The truth rate in the state message.
    Truth,
}

// ---------------------------------------------------------------------------------------------
// MRP kinematics (Schaub & Junkins §3.7; conventions as in proto/README.md: σ_BN is the MRP
// set of B relative to N, |σ| ≤ 1 after shadow switching).

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The shadow set −σ/|σ|², which describes the same attitude.
fn mrp_shadow(s: [f64; 3]) -> [f64; 3] {
    let n2 = dot(s, s);
    [-s[0] / n2, -s[1] / n2, -s[2] / n2]
}

/// σ_BR from σ_BN and σ_RN (MRP subtraction, Schaub & Junkins §3.7, MRP composition):
///
/// σ_BR = [(1 − |σ_RN|²) σ_BN − (1 − |σ_BN|²) σ_RN + 2 σ_BN × σ_RN]
///        / [1 + |σ_RN|² |σ_BN|² + 2 σ_RN · σ_BN]
///
/// The denominator vanishes when the two attitudes are 360° apart in this MRP pair; then σ_BN's
/// shadow set is used instead. The result is switched to its shadow set if |σ_BR| > 1.
pub fn mrp_subtract(sigma_bn: [f64; 3], sigma_rn: [f64; 3]) -> [f64; 3] {
    let eval = |b: [f64; 3], r: [f64; 3]| {
        let (b2, r2) = (dot(b, b), dot(r, r));
        let den = 1.0 + r2 * b2 + 2.0 * dot(r, b);
        let c = cross(b, r);
        let num = [
            (1.0 - r2) * b[0] - (1.0 - b2) * r[0] + 2.0 * c[0],
            (1.0 - r2) * b[1] - (1.0 - b2) * r[1] + 2.0 * c[1],
            (1.0 - r2) * b[2] - (1.0 - b2) * r[2] + 2.0 * c[2],
        ];
        (num, den)
    };
    let (mut num, mut den) = eval(sigma_bn, sigma_rn);
    if den.abs() < 0.1 && dot(sigma_bn, sigma_bn) > 0.0 {
        (num, den) = eval(mrp_shadow(sigma_bn), sigma_rn);
    }
    let s = [num[0] / den, num[1] / den, num[2] / den];
    if dot(s, s) > 1.0 {
        mrp_shadow(s)
    } else {
        s
    }
}

// ---------------------------------------------------------------------------------------------
// The controller.

/// The gyro rate feedback: pairs each state with the `ImuMsg` of the same tick from the IMU
/// named by `--imu`, and rotates its rate to B, ω_B = [PB]ᵀ ω_P, with the mounting
/// `--imu-dcm-pb`. A missed sample holds the previous rate (counted and logged); only an IMU
/// that never publishes is an error.
struct GyroFeedback {
    /// The IMU followed (`--imu`).
    name: String,
    /// Its topic, for messages.
    key: String,
    /// [PB], row-major.
    dcm_pb: [[f64; 3]; 3],
    /// Latest sample not yet used, with its tick (a sample can arrive before its state).
    pending: Option<(u64, ImuMsg)>,
    /// The last rate used, held over a missed sample.
    last_rate_b: Option<[f64; 3]>,
    /// Samples missed so far.
    missed: u64,
}

impl GyroFeedback {
    /// ω_BN in B from a platform-frame gyro rate: [PB]ᵀ ω_P.
    fn rate_b(&self, omega_p: [f64; 3]) -> [f64; 3] {
        let c = &self.dcm_pb;
        [
            c[0][0] * omega_p[0] + c[1][0] * omega_p[1] + c[2][0] * omega_p[2],
            c[0][1] * omega_p[0] + c[1][1] * omega_p[1] + c[2][1] * omega_p[2],
            c[0][2] * omega_p[0] + c[1][2] * omega_p[1] + c[2][2] * omega_p[2],
        ]
    }

    /// Waits (at most `timeout`) for the sample of `tick`; see [`message_for_tick`].
    fn sample_for(
        &mut self,
        tick: u64,
        imus: &RingChannelHandler<Sample>,
        timeout: Duration,
    ) -> anyhow::Result<Option<[f64; 3]>> {
        let msg = message_for_tick(&mut self.pending, tick, imus, timeout, |b| {
            decode_imu(b).map(|m| (m.header.tick, m))
        })?;
        Ok(msg.map(|m| self.rate_b(m.omega_p_rad_s)))
    }

    /// The rate for `tick`: its sample, else the previous rate held (the first miss and every
    /// 100th are logged), else an error if the IMU never published within `first_timeout`.
    fn rate_for(
        &mut self,
        tick: u64,
        imus: &RingChannelHandler<Sample>,
        first_timeout: Duration,
    ) -> anyhow::Result<[f64; 3]> {
        // The sample is published just before its state, so once the IMU has been heard a short
        // wait suffices; the first one may take as long as the server's start.
        let wait = match self.last_rate_b {
            None => first_timeout,
            Some(_) => first_timeout.min(Duration::from_millis(50)),
        };
        match (self.sample_for(tick, imus, wait)?, self.last_rate_b) {
            (Some(w), _) => {
                self.last_rate_b = Some(w);
                Ok(w)
            }
            (None, Some(prev)) => {
                self.missed += 1;
                if self.missed == 1 || self.missed.is_multiple_of(100) {
                    tracing::warn!(
                        imu = %self.key,
                        tick,
                        missed = self.missed,
                        "no gyro sample for this tick; holding the previous rate"
                    );
                }
                Ok(prev)
            }
            (None, None) => bail!(
                "no gyro sample on {} for tick {tick} within {} s: does the server's \
                 configuration have an [[imus]] entry named `{}`? (or use --rate-source truth)",
                self.key,
                Rounded(first_timeout.as_secs_f64(), 3),
                self.name
            ),
        }
    }
}

/// Waits (at most `timeout`) on `rx` for the message stamped `tick`, decoded by `decode` into
/// (tick, message). Older messages are skipped, undecodable ones logged and skipped; a later
/// tick's message is kept in `pending` for its own turn. `Ok(None)`: it did not arrive in time.
fn message_for_tick<M>(
    pending: &mut Option<(u64, M)>,
    tick: u64,
    rx: &RingChannelHandler<Sample>,
    timeout: Duration,
    decode: impl Fn(&[u8]) -> Result<(u64, M), flexdyn_proto::DecodeError>,
) -> anyhow::Result<Option<M>> {
    if let Some((t, m)) = pending.take() {
        if t == tick {
            return Ok(Some(m));
        }
        if t > tick {
            *pending = Some((t, m));
            return Ok(None);
        }
    }
    let deadline = std::time::Instant::now() + timeout;
    loop {
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        let Some(sample) = rx.recv_timeout(left).map_err(|e| anyhow::anyhow!("{e}"))? else {
            return Ok(None);
        };
        let Ok((t, msg)) = decode(&sample.payload().to_bytes()) else {
            tracing::warn!(key = %sample.key_expr(), "ignoring an undecodable message");
            continue;
        };
        if t < tick {
            continue;
        }
        if t > tick {
            *pending = Some((t, msg));
            return Ok(None);
        }
        return Ok(Some(msg));
    }
}

/// MRP PD attitude controller, L = −K σ_BR − P ω_BR, with a fixed target (ω_RN = 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controller {
    /// K [N·m per unit MRP].
    pub k_nm: f64,
    /// P [N·m·s/rad].
    pub p_nms: f64,
    /// Target attitude σ_RN.
    pub sigma_rn: [f64; 3],
}

impl Controller {
    /// The attitude error σ_BR.
    pub fn sigma_br(&self, sigma_bn: [f64; 3]) -> [f64; 3] {
        mrp_subtract(sigma_bn, self.sigma_rn)
    }

    /// Control torque about B, B components [N·m], from the attitude σ_BN and the rate ω_BN
    /// [rad/s, B components]. With ω_RN = 0, ω_BR = ω_BN.
    pub fn torque_b_nm(&self, sigma_bn: [f64; 3], omega_bn_b_rad_s: [f64; 3]) -> [f64; 3] {
        let sigma_br = self.sigma_br(sigma_bn);
        let omega_br = omega_bn_b_rad_s;
        [
            -self.k_nm * sigma_br[0] - self.p_nms * omega_br[0],
            -self.k_nm * sigma_br[1] - self.p_nms * omega_br[1],
            -self.k_nm * sigma_br[2] - self.p_nms * omega_br[2],
        ]
    }
}

/// A 3×3 DCM from nine row-major numbers, checked proper orthonormal within 1e-9.
fn parse_dcm(v: &[f64]) -> anyhow::Result<[[f64; 3]; 3]> {
    if v.len() != 9 || v.iter().any(|x| !x.is_finite()) {
        return Err(flexdyn_tools::usage(
            "--imu-dcm-pb takes nine finite comma-separated numbers (row-major [PB])",
        ));
    }
    let c = [[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]];
    for i in 0..3 {
        for j in 0..3 {
            let d = dot(c[i], c[j]) - if i == j { 1.0 } else { 0.0 };
            if d.abs() > 1e-9 {
                return Err(flexdyn_tools::usage(format!(
                    "--imu-dcm-pb is not orthonormal within 1e-9 (rows {i}, {j}: {d:e})"
                )));
            }
        }
    }
    if (dot(cross(c[0], c[1]), c[2]) - 1.0).abs() > 1e-9 {
        bail!("--imu-dcm-pb is a reflection (determinant -1), not a rotation");
    }
    Ok(c)
}

fn main() -> std::process::ExitCode {
    let args = match flexdyn_tools::parse_args::<Args>() {
        Ok(a) => a,
        Err(code) => return code,
    };
    flexdyn_tools::init_tracing();
    flexdyn_tools::exit_with(run(args))
}

fn run(args: Args) -> anyhow::Result<()> {
    let topics = args.common.topics()?;
    if args.sigma_rn.len() != 3 {
        return Err(flexdyn_tools::usage(
            "--sigma-rn takes three comma-separated numbers, e.g. 0.1,0.2,-0.1",
        ));
    }
    let controller = Controller {
        k_nm: args.k_nm,
        p_nms: args.p_nms,
        sigma_rn: [args.sigma_rn[0], args.sigma_rn[1], args.sigma_rn[2]],
    };
    if !(controller.k_nm.is_finite() && controller.p_nms.is_finite())
        || controller.sigma_rn.iter().any(|x| !x.is_finite())
    {
        return Err(flexdyn_tools::usage("gains and target must be finite"));
    }
    let mut dcm_pb = parse_dcm(&args.imu_dcm_pb)?;
    // The flight code's copy of the spacecraft: needed for wheels and the star tracker.
    let cfg = match &args.config {
        Some(path) => Some(
            flexdyn::config::SimConfig::from_file(path)
                .map_err(|e| anyhow::anyhow!("--config: {e}"))?,
        ),
        None => None,
    };
    let needs = |what: &str| {
        flexdyn_tools::usage(format!(
            "{what} needs --config FILE (the server's scenario, for the spacecraft's geometry)"
        ))
    };
    let wheels = match (args.actuator, &cfg) {
        (Actuator::Wrench, _) => None,
        (Actuator::Wheels, None) => return Err(needs("--actuator wheels")),
        (Actuator::Wheels, Some(c)) => Some((
            flexdyn_tools::acs::WheelArray::from_config(c)?,
            flexdyn_tools::acs::inertia_about_b(c),
        )),
    };
    let mut tracker =
        match (args.attitude_source, &cfg, &args.star_tracker) {
            (AttitudeSource::Truth, _, _) => None,
            (AttitudeSource::StarTracker, None, _) => {
                return Err(needs("--attitude-source star-tracker"))
            }
            (AttitudeSource::StarTracker, Some(_), None) => return Err(flexdyn_tools::usage(
                "--attitude-source star-tracker needs --star-tracker NAME (its [[star_trackers]] \
                 name)",
            )),
            (AttitudeSource::StarTracker, Some(c), Some(name)) => Some((
                flexdyn_tools::acs::StarTrackerAttitude::from_config(c, name)?,
                name.clone(),
            )),
        };
    let frame_s = cfg.as_ref().map_or(0.01, |c| c.frame_ns as f64 * 1e-9);
    if let (Some(c), Some(name)) = (&cfg, &args.imu) {
        let imu = c.imus.iter().find(|i| &i.name == name).ok_or_else(|| {
            anyhow::anyhow!("--imu {name}: the --config file has no [[imus]] entry of that name")
        })?;
        dcm_pb = std::array::from_fn(|i| std::array::from_fn(|j| imu.dcm_pb[(i, j)]));
    }
    if args.rate_source == RateSource::Gyro && args.imu.is_none() {
        return Err(flexdyn_tools::usage(
            "--rate-source gyro needs --imu NAME (the [[imus]] name in the server config)",
        ));
    }
    if !(args.imu_timeout_s.is_finite() && args.imu_timeout_s > 0.0) {
        return Err(flexdyn_tools::usage(
            "--imu-timeout-s must be a positive number of seconds",
        ));
    }
    let imu_timeout = Duration::from_secs_f64(args.imu_timeout_s);

    // 1. Session: peer, connects to the server (tcp/127.0.0.1:7447 unless --connect says
    //    otherwise), multicast scouting off.
    let session = args.common.open_session()?;

    // 2. Subscribe to the state. A small ring buffer: in real time, if we ever fall behind,
    //    we skip to the newest states instead of queueing stale ones; in lockstep at most one
    //    state is outstanding, so nothing is ever dropped.
    let states = session
        .declare_subscriber(topics.state())
        .with(RingChannel::new(8))
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot subscribe to {}: {e}", topics.state()))?;

    // 2b. The gyro: the named IMU's topic (`auto` without --imu uses the truth rate).
    let gyro_imu = match (args.rate_source, &args.imu) {
        (RateSource::Truth, _) => None,
        (_, Some(name)) => Some(name.clone()),
        (RateSource::Auto, None) => {
            tracing::info!(
                "--rate-source auto without --imu: rate feedback uses the truth rate from the \
                 state message (name an IMU and its mounting with --imu and --imu-dcm-pb to \
                 close the loop on its gyro)"
            );
            None
        }
        (RateSource::Gyro, None) => unreachable!("checked above"),
    };
    let (imus, mut gyro) = match gyro_imu {
        None => (None, None),
        Some(name) => {
            let key = topics.imu(&name)?;
            let sub = session
                .declare_subscriber(&key)
                .with(RingChannel::new(64))
                .wait()
                .map_err(|e| anyhow::anyhow!("cannot subscribe to {key}: {e}"))?;
            tracing::info!(imu = %key, "rate feedback from this IMU's gyro");
            let g = GyroFeedback {
                name,
                key: key.to_string(),
                dcm_pb,
                pending: None,
                last_rate_b: None,
                missed: 0,
            };
            (Some(sub), Some(g))
        }
    };

    // 2c. The star tracker's topic.
    let st_sub = match &tracker {
        None => None,
        Some((_, name)) => {
            let key = topics.star_tracker(name)?;
            tracing::info!(star_tracker = %key, "attitude from this star tracker");
            Some(
                session
                    .declare_subscriber(&key)
                    .with(RingChannel::new(64))
                    .wait()
                    .map_err(|e| anyhow::anyhow!("cannot subscribe to {key}: {e}"))?,
            )
        }
    };
    let mut st_pending = None;
    let mut st_heard = false;

    // 3. The command publisher. Block (never drop) and express (no batching: lowest latency).
    let cmd_key = topics.cmd(args.sender_id);
    let commands = session
        .declare_publisher(cmd_key.clone())
        .congestion_control(CongestionControl::Block)
        .express(true)
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot declare {cmd_key}: {e}"))?;

    // 4. Announce ourselves to a lockstep server (harmless in real time). Declared after the
    //    subscriber, so the server cannot publish tick 0 before we can receive it.
    let _token = session
        .liveliness()
        .declare_token(topics.participant(args.sender_id))
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot declare the liveliness token: {e}"))?;
    tracing::info!(
        sender_id = args.sender_id,
        k_nm = controller.k_nm,
        p_nms = controller.p_nms,
        sigma_rn = ?controller.sigma_rn,
        state = topics.state(),
        commands = cmd_key,
        "flexdyn-acs-demo running"
    );

    // 5. The loop: one command per state received, until SIGINT/SIGTERM or --idle-exit-s.
    let stop = flexdyn_tools::stop_on_signals()?;
    let idle = args.idle_exit_s.map(Duration::from_secs_f64);
    let log_every_ns = (args.log_every_s.max(0.0) * 1e9) as u64;
    let mut next_log_ns = 0u64;
    let mut seq = 0u64;
    let mut buf = Vec::with_capacity(128);
    let mut states_received = 0u64;
    let mut last_state_at = std::time::Instant::now();
    loop {
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            tracing::info!(states_received, "stop signal: closing the session");
            break;
        }
        if let Some(d) = idle {
            if last_state_at.elapsed() >= d {
                if states_received == 0 {
                    bail!(
                        "no state received on {} within {} s (--idle-exit-s): no server, or it \
                         is not reachable at the --connect endpoint",
                        topics.state(),
                        Rounded(d.as_secs_f64(), 3)
                    );
                }
                tracing::info!(
                    states_received,
                    "no state for {} s; exiting",
                    Rounded(d.as_secs_f64(), 3)
                );
                break;
            }
        }
        // Wake at least every 100 ms to notice a signal or the idle limit.
        let Some(sample) = states
            .recv_timeout(Duration::from_millis(100))
            .map_err(|e| anyhow::anyhow!("{e}"))?
        else {
            continue;
        };
        let state = match decode_state(&sample.payload().to_bytes()) {
            Ok(s) => s,
            Err(e) => {
                tracing::warn!(error = %e, "ignoring an undecodable state");
                continue;
            }
        };
        states_received += 1;
        last_state_at = std::time::Instant::now();

        // The rate feedback: the gyro sample of this tick (see the module docs), or truth.
        let h = state.header;
        let rate_b = match (&mut gyro, &imus) {
            (Some(g), Some(sub)) => g.rate_for(h.tick, sub, imu_timeout)?,
            _ => state.omega_bn_b_rad_s,
        };

        // The attitude: truth, or the star tracker's (propagated with the rate between updates).
        let sigma_bn = match (&mut tracker, &st_sub) {
            (Some((est, name)), Some(sub)) => {
                let meas = if est.due(h.tick) {
                    let wait = if st_heard {
                        imu_timeout.min(Duration::from_millis(50))
                    } else {
                        imu_timeout
                    };
                    let m = message_for_tick(&mut st_pending, h.tick, sub, wait, |b| {
                        decode_star_tracker(b).map(|m| (m.header.tick, m))
                    })?;
                    if m.is_none() && !st_heard {
                        bail!(
                            "no sample from star tracker `{name}` for tick {}: does the server's \
                             configuration have it?",
                            h.tick
                        );
                    }
                    st_heard |= m.is_some();
                    m
                } else {
                    None
                };
                est.update(meas.as_ref(), &Vector3::from(rate_b), frame_s)
                    .map(|s| [s.x, s.y, s.z])
            }
            _ => Some(state.sigma_bn),
        };

        // Answer with the state's spacecraft id, tick and sim time; our own sequence number.
        let header = Header::new(h.spacecraft_id, h.tick, h.sim_time_ns, seq);
        let (cmd, torque_b_nm) = match (sigma_bn, &wheels) {
            // No attitude yet (the star tracker has not given a valid one): answer the tick.
            (None, _) => (CommandMsg::no_command(header, args.sender_id), [0.0; 3]),
            (Some(sigma_bn), None) => {
                let t = controller.torque_b_nm(sigma_bn, rate_b);
                (CommandMsg::wrench(header, args.sender_id, t, [0.0; 3]), t)
            }
            (Some(sigma_bn), Some((array, inertia))) => {
                let speeds = array.speeds(&state)?;
                let omega = Vector3::from(rate_b);
                let l = flexdyn_tools::acs::wheel_control_torque(
                    controller.k_nm,
                    controller.p_nms,
                    &Vector3::from(controller.sigma_br(sigma_bn)),
                    &omega,
                    inertia,
                    &array.momentum_b(&omega, &speeds),
                );
                let u = array.motor_torques(&l);
                let cmd = CommandMsg::actuators(
                    header,
                    args.sender_id,
                    [0.0; 3],
                    [0.0; 3],
                    array.inputs(&u),
                );
                (cmd, [l.x, l.y, l.z])
            }
        };
        encode_into(&cmd, &mut buf);
        commands
            .put(buf.as_slice())
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot publish the command: {e}"))
            .context("publishing")?;
        seq += 1;

        if log_every_ns > 0 && h.sim_time_ns >= next_log_ns {
            let e = controller.sigma_br(state.sigma_bn);
            tracing::info!(
                tick = h.tick,
                t_s = h.sim_time_ns as f64 / 1e9,
                sigma_br_norm = dot(e, e).sqrt(),
                omega_norm_rad_s = dot(state.omega_bn_b_rad_s, state.omega_bn_b_rad_s).sqrt(),
                torque_b_nm = ?torque_b_nm,
                "control"
            );
            next_log_ns = h.sim_time_ns.saturating_add(log_every_ns);
        }
    }
    // Undeclare the token first (a lockstep server sees us leave), then close the session.
    drop(_token);
    drop(commands);
    drop(imus);
    drop(st_sub);
    drop(states);
    session
        .close()
        .wait()
        .map_err(|e| anyhow::anyhow!("closing the Zenoh session: {e}"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn::attitude::mrp_error;
    use nalgebra::Vector3;

    fn close(a: [f64; 3], b: Vector3<f64>, tol: f64) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < tol)
    }

    /// Validated against a second algorithm: flexdyn's DCM-based [BR] = [BN][RN]ᵀ.
    #[test]
    fn validate_mrp_subtract_against_dcm() {
        let sets = [
            [0.0, 0.0, 0.0],
            [0.1, 0.2, -0.1],
            [-0.5, 0.3, 0.7],
            [0.9, -0.1, 0.2],
            [0.05, -0.6, 0.55],
        ];
        for b in sets {
            for r in sets {
                let got = mrp_subtract(b, r);
                let want = mrp_error(&Vector3::from(b), &Vector3::from(r));
                assert!(
                    close(got, want, 1e-12),
                    "b={b:?} r={r:?}: {got:?} vs {want:?}"
                );
            }
        }
        // 360° apart in this MRP pair: the denominator vanishes, the shadow set saves it.
        let b = [0.6, 0.0, 0.0];
        let r = mrp_shadow([0.6, 0.0, 0.0]);
        let got = mrp_subtract(b, r);
        assert!(got.iter().all(|x| x.is_finite()));
        assert!(close(got, Vector3::zeros(), 1e-12), "{got:?}");
    }

    #[test]
    fn pd_law_signs() {
        let c = Controller {
            k_nm: 2.0,
            p_nms: 3.0,
            sigma_rn: [0.0; 3],
        };
        assert_eq!(
            c.torque_b_nm([0.1, 0.0, 0.0], [0.0, 0.0, 0.0]),
            [-0.2, 0.0, 0.0]
        );
        assert_eq!(c.torque_b_nm([0.0; 3], [0.0, 1.0, 0.0]), [0.0, -3.0, 0.0]);
    }
}
