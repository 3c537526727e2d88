//! `flexdyn-acs-demo`: a demo attitude controller for the flexdyn server — and the template to
//! copy when you attach your own flight code. It depends on `flexdyn-proto` alone: the wire,
//! plus its `client` feature (the Zenoh rules, the served configuration, complete ticks) and
//! its `attitude` feature (the MRP kernels), never on the simulator.
//!
//! # What it does
//! Every tick the server publishes the spacecraft state (`flexdyn/<sc>/tlm/state`, one
//! [`StateMsg`](flexdyn_proto::StateMsg) per frame) and its sensor samples. This program
//! computes the MRP proportional-derivative control torque
//!
//! ```text
//!     L = −K σ_BR − P ω_BR            (Schaub & Junkins, Analytical Mechanics of Space
//!                                      Systems, ch. 8: MRP feedback control)
//! ```
//!
//! and publishes it as a [`CommandMsg`] on `flexdyn/<sc>/cmd/<sender-id>`, stamped with the tick
//! of the state it answers. σ_BR is the MRP attitude error of the body B relative to the target
//! frame R (given as σ_RN with ω_RN = 0, so ω_BR = ω_BN).
//!
//! # Real time and lockstep: one loop
//! The loop is the same in both server modes:
//! - **real time**: the server never waits; it applies the latest command it has (typically the
//!   answer to the previous frame) and flags commands that get too old;
//! - **lockstep**: the server waits for our answer to tick k before stepping to k+1, so the run
//!   is bit-for-bit reproducible. Three rules make that work, all followed below:
//!   1. answer **every** state, stamped with **its** tick (send `CommandKind::NoCommand` if you
//!      have nothing to command);
//!   2. subscribe to the telemetry **before** declaring the liveliness token
//!      `flexdyn/<sc>/participant/<sender-id>`: the server starts at tick 0 only once it sees
//!      the token;
//!   3. answer tick k from the state **and every sensor sample due at tick k**, assembled in
//!      publication order, and which samples are due from the server's configuration
//!      queryable ([`TickReceiver`]: a callback subscriber per key, each run on the thread that
//!      reads the link). Subscribers that each queue their samples for a thread of their own
//!      can see a state before its own tick's IMU sample, and a run then depends on thread
//!      timing.
//!
//! # The end of the run
//! The demo stops as soon as the server's last status says the run `finished`, `stopped` or
//! `failed` ([`RunEnd`]), after the frames still queued: exit 0, or 1 if the run failed.
//!
//! # Tuning (linearised closed loop, per principal axis with inertia I)
//! With σ̇ ≈ ω/4 for small errors, I ω̇ = −Kσ − Pω gives σ̈ + (P/I) σ̇ + (K/4I) σ = 0:
//! ω_n = √(K/(4I)), ζ = P/√(K I), decay rate ζ ω_n = P/(2I), 2 % settling ≈ 8 I / P.
//! The defaults (K = 100 N·m, P = 300 N·m·s) suit the reference spacecraft
//! (I ≈ 1100…1800 kg·m² about the centre of mass): ζ ≈ 0.7…0.9, settling ≈ 30…50 s.
//!
//! # The spacecraft's geometry
//! At start the demo asks the server's `flexdyn/<sc>/config` queryable what it runs
//! ([`Vehicle`]): the IMU mountings, the wheels and the star trackers with their rates. Real
//! flight code has these in its own tables; the demo reads them so that it fits any scenario.
//!
//! # Rate feedback from the gyro
//! Flight code reads rate gyros, not truth, so by default the rate comes from an IMU the server
//! publishes on `flexdyn/<sc>/tlm/imu/<name>` (`ImuMsg`, one per frame, stamped with the same
//! tick as the state): ω_B = [PB]ᵀ ω_P, with [PB] the IMU's mounting from the configuration
//! (or `--imu-dcm-pb`). `--rate-source`:
//! - `gyro`: use the IMU `--imu NAME` (a sample lost in real time holds the previous rate,
//!   counted and logged);
//! - `auto` (default): `gyro` if `--imu NAME` is given, otherwise the state message's truth
//!   rate (said in the log). It never picks an IMU by itself;
//! - `truth`: the state message's ω_BN.
//!
//! # Reaction wheels and the star tracker
//! - `--actuator wheels` turns the torque into reaction-wheel motor torques: the law adds the
//!   wheel-momentum gyroscopic term, L = −Kσ − Pω + ω × ([I]ω + [G_s]h_s), and u = −[G_s]⁺L is
//!   sent as one `CommandKind::Actuators` per tick ([`flexdyn_acs_demo::acs`]);
//! - `--attitude-source star-tracker --star-tracker NAME` takes σ_BN from that tracker's
//!   q_CN through its mounting [CB], propagated with the rate feedback between its updates; until
//!   its first valid sample the answer is `NoCommand`.
//!
//! With `--rate-source gyro --imu NAME` as well, the loop uses no truth at all.
//!
//! # Fault detection, isolation and recovery
//! `--fdir` (with the wheels, the star tracker and `--imu`) watches every IMU's gyro (a frozen
//! output; consistency with the star tracker over `--fdir-window-s`) and every wheel (its speed
//! against its command), moves the rate feedback off a failed gyro (to another IMU, or to the
//! tracker's rate) and drops a failed wheel from the allocation
//! ([`flexdyn_acs_demo::fdir`], which derives each threshold). Every detection and
//! reconfiguration is a line on standard output (`fdir-detect`, `fdir-rate-source`,
//! `fdir-wheels`), the largest statistics one at the end (`fdir-summary`).
//!
//! # Copying this package
//! Keep `run`'s order (session → configuration → telemetry subscriber → publisher → token →
//! loop). Replace [`GyroFeedback`] by your rate source and [`Controller::torque_b_nm`] by your
//! control law. The answer to a tick is [`Flight::answer`]; [`Flight`] is the flight code's
//! state, answering on the Zenoh thread that completes each tick (`--answer-on zenoh-thread`)
//! or on the main thread (`main-thread`), and [`Flight::start`] answers the ticks that came
//! before the command publisher was declared. Everything on the wire comes from the
//! `flexdyn-proto` crate (see `proto/README.md` for C and Python byte layouts).

use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use anyhow::{bail, Context as _};
use clap::Parser;
use flexdyn_acs_demo::acs::WheelArray;
use flexdyn_acs_demo::acs::{inertia_about_b, mat3, wheel_control_torque, StarTrackerAttitude};
use flexdyn_acs_demo::fdir::{Event, GyroFdir, WheelFdir};
use flexdyn_acs_demo::modes::{Mode, ModeSettings};
use flexdyn_acs_demo::sequence::{AcsSequence, Gains, SequenceSetup};
use flexdyn_acs_demo::telemetry::{ControllerTick, Telemetry};
use flexdyn_proto::attitude::mrp_error;
use flexdyn_proto::client::cli::{exit_with, stop_on_signals, usage, CommonArgs};
use flexdyn_proto::client::lockstep::{SensorSchedule, Tick, TickHandler, TickReceiver};
use flexdyn_proto::client::participant::Participant;
use flexdyn_proto::client::run_end::RunEnd;
use flexdyn_proto::client::vehicle::{Vehicle, VehicleConfig};
use flexdyn_proto::{CommandMsg, Header, Topics};
use nalgebra::{Matrix3, Vector3};
use zenoh::{Session, Wait};

/// Demo MRP PD attitude controller: subscribes to flexdyn telemetry, publishes commands.
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
    /// Exit after this many seconds without a state: exit 0 if states were received, exit 1 if
    /// none ever came (no server). It also bounds the wait for the server's configuration at
    /// start. The demo stops without it when the server says the run ended; this bounds the wait
    /// for a server that dies without saying so. Default: wait until the run ends or
    /// SIGINT/SIGTERM.
    #[arg(long, allow_negative_numbers = true)]
    idle_exit_s: Option<f64>,
    /// Where the rate feedback comes from. `gyro`: the IMU named by --imu. `truth`: the state
    /// message's ω_BN. `auto`: `gyro` if --imu is given, else `truth` (logged); it never picks
    /// an IMU by itself.
    #[arg(long, value_enum, default_value_t = RateSource::Auto)]
    rate_source: RateSource,
    /// The IMU whose gyro feeds the rate loop (its `[[imus]] name` in the server config).
    #[arg(long)]
    imu: Option<String>,
    /// That IMU's mounting [PB] (maps B to platform P), nine comma-separated numbers,
    /// row-major. Default: the mounting in the server's configuration.
    #[arg(
        long,
        value_name = "9 NUMBERS",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    imu_dcm_pb: Option<Vec<f64>>,
    /// Longest wait [s] for a tick's sensor samples once its state is in; then the tick is
    /// answered without them (a lost sample: held rate, propagated attitude; logged). In
    /// lockstep no sample is lost.
    #[arg(
        long,
        visible_alias = "imu-timeout-s",
        default_value_t = 5.0,
        allow_negative_numbers = true
    )]
    sensor_timeout_s: f64,
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
    /// Run the whole ACS sequence instead of the single controller: detumble (B-dot on
    /// --magnetometer and the rods), sun acquisition (--css, the gyro --imu and the wheels),
    /// fine pointing (--star-tracker, the gyro and the wheels) and momentum management (the
    /// rods unload the wheels while fine pointing continues). Each transition is printed on
    /// standard output as `mode-transition tick=… t_s=… from=… to=…`.
    #[arg(long)]
    mode_manager: bool,
    /// The magnetometer of the mode manager (its `[[magnetometers]] name`).
    #[arg(long)]
    magnetometer: Option<String>,
    /// The coarse-sun-sensor array of the mode manager (its `[[coarse_sun_sensors]] name`).
    #[arg(long)]
    css: Option<String>,
    /// The solar-panel normal in B that sun acquisition turns onto the Sun.
    #[arg(long, value_name = "X,Y,Z", value_delimiter = ',', default_values_t = [0.0, 0.0, 1.0],
          allow_hyphen_values = true)]
    panel_normal_b: Vec<f64>,
    /// Mode manager: seconds of momentum management (default: one 95-minute orbit; the
    /// cross-product law needs the field to turn to reach every axis).
    #[arg(long, default_value_t = 5700.0, allow_negative_numbers = true)]
    unload_s: f64,
    /// Fault detection, isolation and recovery (`flexdyn_acs_demo::fdir`): every IMU's gyro is
    /// checked against the star tracker and a failed one is replaced by a healthy IMU (or by
    /// star-tracker-derived rates); every wheel's speed is checked against its command and a
    /// failed wheel is dropped from the allocation. Needs `--actuator wheels
    /// --attitude-source star-tracker --star-tracker NAME --imu NAME` (the first rate source).
    /// Detections and reconfigurations are printed on standard output (`fdir-detect …`,
    /// `fdir-rate-source …`, `fdir-wheels …`), the largest statistics at the end
    /// (`fdir-summary …`).
    #[arg(long)]
    fdir: bool,
    /// The flight code's own telemetry stream (`flexdyn/<sc>/fsw/<name>`): its mode, events,
    /// attitude estimate and target, and values, published every tick when the served
    /// configuration declares a `[[fsw_streams]]` of this name
    /// (`flexdyn_acs_demo::telemetry`); off otherwise.
    #[arg(long, default_value = "acs")]
    fsw_stream: String,
    /// The gyro monitor's window W [s] (rounded to whole star-tracker periods).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    fdir_window_s: f64,
    /// Which thread answers a tick. `zenoh-thread`: the Zenoh thread that delivered its last
    /// sample (no thread wake-up between the state and the command, as in a Zenoh ping-pong);
    /// in real time, a tick answered slower than a frame holds up the telemetry behind it and
    /// the server drops samples. `main-thread`: the main thread, which the Zenoh thread wakes
    /// per tick; up to 256 complete ticks wait for it, and in real time it loses whole old
    /// ticks when it falls behind.
    #[arg(long, value_enum, default_value_t = AnswerOn::ZenohThread)]
    answer_on: AnswerOn,
}

/// Which thread answers a tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum AnswerOn {
    /// The Zenoh thread that completed the tick.
    ZenohThread,
    /// The main thread.
    MainThread,
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
    /// A star tracker's q_CN, mounted as the configuration says.
    StarTracker,
}

/// Rate feedback source.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum RateSource {
    /// The IMU named by `--imu` if given, else (with a log line) the truth rate.
    Auto,
    /// The IMU named by `--imu`.
    Gyro,
    /// The truth rate in the state message.
    Truth,
}

// ---------------------------------------------------------------------------------------------
// The controller.

/// MRP PD attitude controller, L = −K σ_BR − P ω_BR, with a fixed target (ω_RN = 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controller {
    /// K [N·m per unit MRP].
    pub k_nm: f64,
    /// P [N·m·s/rad].
    pub p_nms: f64,
    /// Target attitude σ_RN.
    pub sigma_rn: Vector3<f64>,
}

impl Controller {
    /// The attitude error σ_BR ([BR] = [BN][RN]ᵀ, |σ_BR| ≤ 1).
    pub fn sigma_br(&self, sigma_bn: &Vector3<f64>) -> Vector3<f64> {
        mrp_error(sigma_bn, &self.sigma_rn)
    }

    /// Control torque about B, B components [N·m], from the attitude σ_BN and the rate ω_BN
    /// [rad/s, B components]. With ω_RN = 0, ω_BR = ω_BN.
    pub fn torque_b_nm(
        &self,
        sigma_bn: &Vector3<f64>,
        omega_bn_b_rad_s: &Vector3<f64>,
    ) -> Vector3<f64> {
        -self.sigma_br(sigma_bn) * self.k_nm - omega_bn_b_rad_s * self.p_nms
    }
}

/// The gyro rate feedback: the IMU `--imu`'s sample of each tick rotated to B,
/// ω_B = [PB]ᵀ ω_P. A sample lost in real time holds the previous rate (counted and logged).
struct GyroFeedback {
    /// The IMU followed (`--imu`), and its index in the tick's samples.
    name: String,
    index: usize,
    /// [PB].
    dcm_pb: Matrix3<f64>,
    /// The last rate used, held over a lost sample.
    last_rate_b: Option<Vector3<f64>>,
    /// Samples lost so far.
    missed: u64,
}

impl GyroFeedback {
    /// The rate for a tick whose sample of this IMU is `sample` (`None`: lost).
    fn rate_for(
        &mut self,
        tick: u64,
        sample: Option<&flexdyn_proto::ImuMsg>,
    ) -> anyhow::Result<Vector3<f64>> {
        if let Some(m) = sample {
            let w = self.dcm_pb.transpose() * Vector3::from(m.omega_p_rad_s);
            self.last_rate_b = Some(w);
            return Ok(w);
        }
        self.missed += 1;
        if self.missed == 1 || self.missed.is_multiple_of(100) {
            tracing::warn!(imu = %self.name, tick, missed = self.missed,
                "no gyro sample for this tick; holding the previous rate");
        }
        self.last_rate_b.with_context(|| {
            format!(
                "no sample from the IMU `{}` for tick {tick}, and none before",
                self.name
            )
        })
    }
}

/// A 3×3 DCM from nine row-major numbers, checked proper orthonormal within 1e-9.
fn parse_dcm(v: &[f64]) -> anyhow::Result<Matrix3<f64>> {
    if v.len() != 9 || v.iter().any(|x| !x.is_finite()) {
        return Err(usage(
            "--imu-dcm-pb takes nine finite comma-separated numbers (row-major [PB])",
        ));
    }
    let c = Matrix3::from_row_slice(v);
    let residual = c * c.transpose() - Matrix3::identity();
    if let Some((k, d)) = residual.iter().enumerate().find(|(_, d)| d.abs() > 1e-9) {
        // `iter` is column-major: element k is at row k % 3, column k / 3.
        return Err(usage(format!(
            "--imu-dcm-pb is not orthonormal within 1e-9 (rows {}, {}: {d:e})",
            k % 3,
            k / 3
        )));
    }
    if (c.determinant() - 1.0).abs() > 1e-9 {
        bail!("--imu-dcm-pb is a reflection (determinant -1), not a rotation");
    }
    Ok(c)
}

fn main() -> std::process::ExitCode {
    let args = match flexdyn_proto::client::logging::parse_args::<Args>() {
        Ok(a) => a,
        Err(code) => return code,
    };
    flexdyn_proto::client::logging::init_tracing();
    exit_with(run(args))
}

/// Checks the options that need no server.
fn check(args: &Args) -> anyhow::Result<Controller> {
    if args.sigma_rn.len() != 3 {
        return Err(usage(
            "--sigma-rn takes three comma-separated numbers, e.g. 0.1,0.2,-0.1",
        ));
    }
    let controller = Controller {
        k_nm: args.k_nm,
        p_nms: args.p_nms,
        sigma_rn: Vector3::new(args.sigma_rn[0], args.sigma_rn[1], args.sigma_rn[2]),
    };
    if !(controller.k_nm.is_finite() && controller.p_nms.is_finite())
        || controller.sigma_rn.iter().any(|x| !x.is_finite())
    {
        return Err(usage("gains and target must be finite"));
    }
    if let Some(v) = &args.imu_dcm_pb {
        parse_dcm(v)?;
    }
    if args.rate_source == RateSource::Gyro && args.imu.is_none() {
        return Err(usage(
            "--rate-source gyro needs --imu NAME (the [[imus]] name in the server config)",
        ));
    }
    if args.attitude_source == AttitudeSource::StarTracker && args.star_tracker.is_none() {
        return Err(usage(
            "--attitude-source star-tracker needs --star-tracker NAME (its [[star_trackers]] \
             name)",
        ));
    }
    if !(args.sensor_timeout_s.is_finite() && args.sensor_timeout_s > 0.0) {
        return Err(usage(
            "--sensor-timeout-s must be a positive number of seconds",
        ));
    }
    if let Some(s) = args.idle_exit_s {
        if !(s.is_finite() && s > 0.0) {
            return Err(usage("--idle-exit-s must be a positive number of seconds"));
        }
    }
    if args.fdir {
        if args.mode_manager
            || args.actuator != Actuator::Wheels
            || args.attitude_source != AttitudeSource::StarTracker
            || args.imu.is_none()
            || args.rate_source == RateSource::Truth
        {
            return Err(usage(
                "--fdir needs --actuator wheels --attitude-source star-tracker --star-tracker \
                 NAME --imu NAME (not --rate-source truth, not --mode-manager)",
            ));
        }
        if !(args.fdir_window_s.is_finite() && args.fdir_window_s > 0.0) {
            return Err(usage(
                "--fdir-window-s must be a positive number of seconds",
            ));
        }
    }
    if args.mode_manager {
        for (flag, given) in [
            ("--imu", args.imu.is_some()),
            ("--star-tracker", args.star_tracker.is_some()),
            ("--magnetometer", args.magnetometer.is_some()),
            ("--css", args.css.is_some()),
        ] {
            if !given {
                return Err(usage(format!(
                    "--mode-manager needs {flag} NAME (its name in the server config)"
                )));
            }
        }
        if args.panel_normal_b.len() != 3
            || !args.panel_normal_b.iter().all(|x| x.is_finite())
            || args.panel_normal_b.iter().all(|x| *x == 0.0)
        {
            return Err(usage(
                "--panel-normal-b takes three finite comma-separated numbers, not all zero",
            ));
        }
        if !(args.unload_s.is_finite() && args.unload_s > 0.0) {
            return Err(usage("--unload-s must be a positive number of seconds"));
        }
    }
    Ok(controller)
}

/// The ACS sequence of `--mode-manager` (checked by `check`).
fn sequence(
    args: &Args,
    cfg: &VehicleConfig,
    schedule: &SensorSchedule,
) -> anyhow::Result<Option<AcsSequence>> {
    if !args.mode_manager {
        return Ok(None);
    }
    let name = |o: &Option<String>| o.clone().unwrap_or_default();
    let p = &args.panel_normal_b;
    let setup = SequenceSetup {
        imu: name(&args.imu),
        star_tracker: name(&args.star_tracker),
        magnetometer: name(&args.magnetometer),
        coarse_sun_sensor: name(&args.css),
        panel_normal_b: Vector3::new(p[0], p[1], p[2]),
        target_sigma_rn: None,
        // 10 σ of the scenario's 0.005 detector noise.
        css_threshold: 0.05,
        modes: ModeSettings {
            unload_duration_ns: (args.unload_s * 1e9).round() as u64,
            ..ModeSettings::default()
        },
        gains: Gains::default(),
    };
    tracing::info!(?setup, "ACS mode manager");
    Ok(Some(AcsSequence::new(cfg, schedule, setup)?))
}

/// The estimates behind a tick's decisions as `key=value` words: the gyro rate, the Sun's
/// angle from the panel normal (coarse sun sensors; `none` in eclipse), the pointing error
/// (star tracker; `none` before a target), the wheel momentum.
fn sequence_estimates(out: &flexdyn_acs_demo::sequence::Output) -> String {
    let o = &out.observation;
    let deg = |a: Option<f64>| a.map_or("none".to_owned(), |a| a.to_degrees().to_string());
    format!(
        "rate_deg_s={} sun_angle_deg={} pointing_error_deg={} wheel_momentum_nms={}",
        o.omega_bn_b_rad_s.norm().to_degrees(),
        deg(o.sun_angle_rad),
        deg(o.pointing_error_rad),
        out.wheel_momentum_b_nms.norm()
    )
}

/// Prints what a tick of the sequence changed (stdout, one line each: the record of the run).
fn print_sequence_events(out: &flexdyn_acs_demo::sequence::Output) {
    if let Some(t) = &out.transition {
        println!(
            "mode-transition tick={} t_s={} from={} to={} {}",
            t.tick,
            t.t_ns as f64 * 1e-9,
            t.from.name(),
            t.to.name(),
            sequence_estimates(out)
        );
        tracing::info!(
            tick = t.tick,
            from = t.from.name(),
            to = t.to.name(),
            "mode transition"
        );
    }
    if let Some(s) = &out.new_target_sigma_rn {
        println!("fine-pointing-target sigma_rn={},{},{}", s[0], s[1], s[2]);
    }
}

/// The time in each mode and the last tick's estimates, printed when the run ends.
fn print_sequence_summary(
    seq: &AcsSequence,
    last: Option<&flexdyn_acs_demo::sequence::Output>,
    t_end_ns: u64,
) {
    let times = seq.modes().time_in_modes_ns(0, t_end_ns);
    for (mode, t) in Mode::ALL.iter().zip(times) {
        println!("time-in-mode mode={} s={}", mode.name(), t as f64 * 1e-9);
    }
    if let Some(out) = last {
        println!(
            "final tick={} t_s={} mode={} {}",
            out.observation.tick,
            out.observation.t_ns as f64 * 1e-9,
            out.mode.name(),
            sequence_estimates(out)
        );
    }
}

/// The FDIR of `--fdir`: the gyro and wheel monitors, and the events of the current tick.
struct Fdir {
    gyro: GyroFdir,
    wheels: WheelFdir,
    events: Vec<Event>,
}

/// Prints (stdout, one line each) and logs what the FDIR did at this tick, and forgets it.
fn print_fdir_events(tick: u64, t_ns: u64, events: &mut Vec<Event>) {
    let t_s = t_ns as f64 * 1e-9;
    for e in events.drain(..) {
        match e {
            Event::Detected {
                what,
                test,
                unit,
                statistic,
                threshold,
            } => {
                println!(
                    "fdir-detect tick={tick} t_s={t_s} what={what} unit={unit} test={test} \
                     statistic={statistic} threshold={threshold}"
                );
                tracing::warn!(tick, what, unit, statistic, "FDIR: failure detected");
            }
            Event::RateSource { source } => {
                println!("fdir-rate-source tick={tick} t_s={t_s} source={source}");
                tracing::warn!(tick, source, "FDIR: rate feedback reconfigured");
            }
            Event::Wheels { active } => {
                let active = active.join(",");
                println!("fdir-wheels tick={tick} t_s={t_s} active={active}");
                tracing::warn!(tick, active, "FDIR: wheel allocation reconfigured");
            }
        }
    }
}

/// The largest test statistic of each monitored unit (1 is the threshold), printed when the
/// run ends: the margins a healthy run kept.
fn print_fdir_summary(f: &Fdir) {
    let list = |names: Vec<&str>, s: &[f64]| -> String {
        names
            .iter()
            .zip(s)
            .map(|(n, s)| format!("{n}:{s}"))
            .collect::<Vec<_>>()
            .join(",")
    };
    let wheel_names = f.wheels.names().iter().map(String::as_str).collect();
    println!(
        "fdir-summary gyro_max_statistic={} wheel_max_statistic={}",
        list(f.gyro.names(), &f.gyro.max_statistic),
        list(wheel_names, &f.wheels.max_statistic)
    );
}

/// The served configuration, asked until the server answers, a stop signal, or `idle` passes.
fn wait_for_vehicle(
    session: &Session,
    topics: &Topics,
    idle: Option<Duration>,
    stop: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<Option<Vehicle>> {
    let started = Instant::now();
    loop {
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            return Ok(None);
        }
        match Vehicle::query(session, topics, Duration::from_millis(500)) {
            Ok(v) => return Ok(Some(v)),
            Err(flexdyn_proto::client::vehicle::VehicleError::NoAnswer { key, .. }) => {
                if let Some(d) = idle.filter(|d| started.elapsed() >= *d) {
                    bail!(
                        "no answer on {key} within {} s (--idle-exit-s): no server, or it is not \
                         reachable at the --connect endpoint",
                        d.as_secs_f64()
                    );
                }
            }
            Err(e) => return Err(e.into()),
        }
    }
}

/// The gyro feedback the options ask for, with the mounting from the configuration.
fn gyro(
    args: &Args,
    cfg: &VehicleConfig,
    schedule: &SensorSchedule,
) -> anyhow::Result<Option<GyroFeedback>> {
    let name = match (args.rate_source, &args.imu) {
        (RateSource::Truth, _) => return Ok(None),
        (_, Some(name)) => name.clone(),
        (RateSource::Auto, None) => {
            tracing::info!(
                "--rate-source auto without --imu: rate feedback uses the truth rate from the \
                 state message (name an IMU with --imu to close the loop on its gyro)"
            );
            return Ok(None);
        }
        (RateSource::Gyro, None) => unreachable!("checked in `check`"),
    };
    let imu = cfg
        .imu(&name)
        .map_err(|e| anyhow::anyhow!("--imu {name}: {e}"))?;
    let dcm_pb = match &args.imu_dcm_pb {
        Some(v) => parse_dcm(v)?,
        None => mat3(&imu.dcm_pb),
    };
    let index = schedule
        .imus()
        .position(|n| n == name)
        .context("the IMU is in the configuration but not in its schedule")?;
    tracing::info!(imu = %name, "rate feedback from this IMU's gyro");
    Ok(Some(GyroFeedback {
        name,
        index,
        dcm_pb,
        last_rate_b: None,
        missed: 0,
    }))
}

fn run(args: Args) -> anyhow::Result<()> {
    let topics = args.common.topics()?;
    let controller = check(&args)?;
    let idle = args.idle_exit_s.map(Duration::from_secs_f64);
    let stop = stop_on_signals()?;

    // 1. Session: peer, connects to the server (tcp/127.0.0.1:7447 unless --connect says
    //    otherwise), multicast scouting off.
    let session = args.common.open_session()?;

    // 2. What the server runs: the geometry, and which sensor samples each tick carries.
    let Some(vehicle) = wait_for_vehicle(&session, &topics, idle, &stop)? else {
        tracing::info!("stop signal before the server answered: closing the session");
        return close(session);
    };
    let cfg = vehicle.config()?;
    // Its controller and mode manager run on the tick's own time (`sim_time_ns`), never on the
    // time service's UTC or GPS time: it does not subscribe to the time message.
    let schedule = SensorSchedule::from_config(&cfg)?.without_time();
    let telemetry = Telemetry::declare(&session, &topics, &vehicle, &args.fsw_stream)?;
    let frame_s = (1e9 / cfg.simulation.frame_hz).round() * 1e-9;
    let gyro = gyro(&args, &cfg, &schedule)?;
    let wheels = match args.actuator {
        Actuator::Wrench => None,
        Actuator::Wheels => Some((WheelArray::from_config(&cfg)?, inertia_about_b(&cfg)?)),
    };
    let sequence = sequence(&args, &cfg, &schedule)?;
    let tracker = match (args.attitude_source, &args.star_tracker) {
        (AttitudeSource::StarTracker, Some(name)) => {
            let est = StarTrackerAttitude::from_config(&cfg, name)?;
            let index = schedule
                .star_trackers()
                .position(|(n, _)| n == name)
                .context("the star tracker is in the configuration but not in its schedule")?;
            tracing::info!(star_tracker = %name, "attitude from this star tracker");
            Some((est, index))
        }
        _ => None,
    };

    let fdir = match (args.fdir, &args.imu, &args.star_tracker) {
        (true, Some(imu), Some(st)) => Some(Fdir {
            gyro: GyroFdir::new(&cfg, &schedule, imu, st, args.fdir_window_s)?,
            wheels: WheelFdir::new(&cfg)?,
            events: Vec::new(),
        }),
        _ => None,
    };
    if let Some(f) = &fdir {
        tracing::info!(
            window_s = f.gyro.window_s(),
            gyros = ?f.gyro.names(),
            wheels = ?f.wheels.names(),
            "FDIR on"
        );
    }

    // 3. The end of the run (the server's last status), then the telemetry: a callback
    //    subscriber on each key a tick is assembled from, into complete ticks. Declared before the token, so the
    //    server cannot publish tick 0 before we can receive it. `--answer-on zenoh-thread`
    //    answers each tick on the Zenoh thread that completed it; `main-thread` queues at most
    //    256 complete ticks for this thread (in real time, if it ever falls behind, the oldest
    //    go: `ticks.lost`).
    let run_end = RunEnd::declare(&session, &topics)
        .map_err(|e| anyhow::anyhow!("cannot subscribe to {}: {e}", topics.status()))?;
    let flight = Arc::new(Mutex::new(Flight {
        sender_id: args.sender_id,
        controller,
        frame_s,
        log_every_ns: (args.log_every_s.max(0.0) * 1e9) as u64,
        next_log_ns: 0,
        sequence,
        last_sequence_output: None,
        telemetry,
        gyro,
        tracker,
        wheels,
        fdir,
        participant: None,
        pending: Vec::new(),
        buf: Vec::with_capacity(128),
        seq: 0,
        states_received: 0,
        last_state_at: Instant::now(),
        last_t_ns: 0,
        failed: None,
    }));
    let sensor_timeout = Duration::from_secs_f64(args.sensor_timeout_s);
    let declared = match args.answer_on {
        AnswerOn::ZenohThread => TickReceiver::declare_with_handler(
            &session,
            &topics,
            schedule,
            sensor_timeout,
            flight.clone(),
        ),
        AnswerOn::MainThread => {
            TickReceiver::declare(&session, &topics, schedule, 256, sensor_timeout)
        }
    };
    let mut ticks = declared.map_err(|e| {
        anyhow::anyhow!(
            "cannot subscribe to the tick's telemetry under {}: {e}",
            topics.telemetry_wildcard()
        )
    })?;

    // 4. The command publisher, Block (never drop) and express (no batching: lowest latency),
    // 5. then the liveliness token that announces us to a lockstep server (harmless in real
    //    time). A tick that completed before the publisher was in place is answered now.
    let participant = Participant::declare(&session, &topics, args.sender_id)?;
    tracing::info!(
        sender_id = args.sender_id,
        k_nm = controller.k_nm,
        p_nms = controller.p_nms,
        sigma_rn = ?controller.sigma_rn.as_slice(),
        telemetry = ?ticks.schedule().keys(&topics),
        commands = participant.key(),
        answer_on = ?args.answer_on,
        "flexdyn-acs-demo running"
    );
    lock(&flight).start(participant);

    // 6. The loop: one command per tick, until the server ends the run, SIGINT/SIGTERM or
    //    --idle-exit-s.
    let mut ended = None;
    loop {
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            let states_received = lock(&flight).states_received;
            tracing::info!(states_received, "stop signal: closing the session");
            break;
        }
        let (states_before, last_state_at, failed) = {
            let f = lock(&flight);
            (f.states_received, f.last_state_at, f.failed.is_some())
        };
        if failed {
            break; // the error is returned below, after the token goes
        }
        if let Some(d) = idle {
            if last_state_at.elapsed() >= d {
                if states_before == 0 {
                    bail!(
                        "no state received on {} within {} s (--idle-exit-s): the server \
                         answered but published nothing",
                        topics.state(),
                        d.as_secs_f64()
                    );
                }
                tracing::info!(
                    states_received = states_before,
                    "no state for {} s; exiting",
                    d.as_secs_f64()
                );
                break;
            }
        }
        // Wake every 20 ms to notice the end of the run, a signal or the idle limit. Once the
        // server has said the run ended, every frame it published is on its way: answer what
        // still comes, then stop after a slice in which nothing did.
        if let Some(tick) = ticks
            .recv_timeout(Duration::from_millis(20))
            .map_err(|e| anyhow::anyhow!("{e}"))?
        {
            lock(&flight).on_tick(tick);
            continue;
        }
        if lock(&flight).states_received != states_before {
            continue;
        }
        if let Some(end) = run_end.ended() {
            tracing::info!(
                states_received = states_before,
                tick = end.tick,
                after_ms = end.heard_at.elapsed().as_secs_f64() * 1e3,
                "the server reports the run {}: exiting",
                end.word()
            );
            ended = Some(end);
            break;
        }
    }
    // Undeclare the token first (a lockstep server sees us leave), then the subscribers, then
    // close the session. The flight code's error, if any, is the run's.
    let participant = {
        let mut f = lock(&flight);
        if let Some(e) = f.failed.take() {
            drop(f.participant.take());
            return Err(e);
        }
        if let Some(fsw) = &f.sequence {
            print_sequence_summary(fsw, f.last_sequence_output.as_ref(), f.last_t_ns);
        }
        if let Some(fdir) = &f.fdir {
            print_fdir_summary(fdir);
        }
        f.participant.take()
    };
    drop(participant);
    drop(ticks);
    drop(run_end);
    close(session)?;
    flexdyn_proto::client::run_end::outcome(ended)
}

/// The flight code of one run: what it answers each tick with, and what it has seen. It runs
/// on the Zenoh thread that completed the tick (`--answer-on zenoh-thread`) or on the main
/// thread (`main-thread`), one tick at a time behind its mutex.
struct Flight {
    sender_id: u32,
    controller: Controller,
    /// [s] the frame period (the star tracker's propagation step).
    frame_s: f64,
    log_every_ns: u64,
    next_log_ns: u64,
    sequence: Option<AcsSequence>,
    last_sequence_output: Option<flexdyn_acs_demo::sequence::Output>,
    telemetry: Option<Telemetry>,
    gyro: Option<GyroFeedback>,
    tracker: Option<(StarTrackerAttitude, usize)>,
    wheels: Option<(WheelArray, Matrix3<f64>)>,
    fdir: Option<Fdir>,
    /// The command publisher and the liveliness token, once declared ([`Self::start`]).
    participant: Option<Participant>,
    /// Ticks that completed before the participant was declared, answered by [`Self::start`].
    pending: Vec<Tick>,
    buf: Vec<u8>,
    seq: u64,
    states_received: u64,
    last_state_at: Instant,
    last_t_ns: u64,
    /// The first error or panic; the run stops on it and later ticks go unanswered.
    failed: Option<anyhow::Error>,
}

/// The flight code, locked (a panic while it was held leaves it usable).
fn lock(flight: &Mutex<Flight>) -> MutexGuard<'_, Flight> {
    flight.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Flight {
    /// Takes the declared participant and answers the ticks that waited for it.
    fn start(&mut self, participant: Participant) {
        self.participant = Some(participant);
        for tick in std::mem::take(&mut self.pending) {
            self.on_tick(tick);
        }
    }

    /// Answers one tick: the flight code's telemetry of the tick, then its command.
    fn answer(&mut self, tick: &Tick) -> anyhow::Result<()> {
        self.states_received += 1;
        self.last_state_at = Instant::now();
        let state = &tick.state;
        let h = state.header;

        // The rate feedback: this tick's gyro sample, or truth.
        self.last_t_ns = h.sim_time_ns;

        // The whole ACS sequence: its own sensors, modes and actuators.
        if let Some(fsw) = &mut self.sequence {
            let out = fsw.step(tick)?;
            print_sequence_events(&out);
            let out = self.last_sequence_output.insert(out);
            // The flight code's telemetry of this tick goes out before its answer.
            if let Some(t) = &mut self.telemetry {
                t.sequence(h.tick, h.sim_time_ns, out)?;
            }
            let header = Header::new(h.spacecraft_id, h.tick, h.sim_time_ns, self.seq);
            let inputs = std::mem::take(&mut out.inputs);
            let cmd = CommandMsg::actuators(header, self.sender_id, [0.0; 3], [0.0; 3], inputs);
            self.participant
                .as_ref()
                .context("no command publisher yet")?
                .send(&cmd, &mut self.buf)
                .map_err(|e| anyhow::anyhow!("cannot publish the command: {e}"))?;
            self.seq += 1;
            if self.log_every_ns > 0 && h.sim_time_ns >= self.next_log_ns {
                tracing::info!(
                    tick = h.tick,
                    t_s = h.sim_time_ns as f64 / 1e9,
                    mode = out.mode.name(),
                    omega_deg_s = Vector3::from(state.omega_bn_b_rad_s).norm().to_degrees(),
                    wheel_momentum_nms = out.wheel_momentum_b_nms.norm(),
                    "sequence"
                );
                self.next_log_ns = h.sim_time_ns.saturating_add(self.log_every_ns);
            }
            return Ok(());
        }

        let rate_b = match (&mut self.fdir, &mut self.gyro) {
            (Some(f), _) => f
                .gyro
                .update(tick, &mut f.events)
                .with_context(|| format!("no gyro rate for tick {} (no sample yet)", h.tick))?,
            (None, Some(g)) => g.rate_for(h.tick, tick.imus[g.index].as_ref())?,
            (None, None) => Vector3::from(state.omega_bn_b_rad_s),
        };
        // The attitude: truth, or the star tracker's (propagated with the rate between updates).
        let sigma_bn = match &mut self.tracker {
            Some((est, index)) => {
                est.update(tick.star_trackers[*index].as_ref(), &rate_b, self.frame_s)
            }
            None => Some(Vector3::from(state.sigma_bn)),
        };

        // Answer with the state's spacecraft id, tick and sim time; our own sequence number.
        let header = Header::new(h.spacecraft_id, h.tick, h.sim_time_ns, self.seq);
        let mut wheel_momentum_b_nms = Vector3::zeros();
        let controller = self.controller;
        let (cmd, torque_b_nm) = match (sigma_bn, &mut self.wheels) {
            // No attitude yet (the star tracker has not given a valid one): answer the tick.
            (None, _) => {
                if let Some(f) = &mut self.fdir {
                    f.wheels.uncommanded();
                }
                (
                    CommandMsg::no_command(header, self.sender_id),
                    Vector3::zeros(),
                )
            }
            (Some(sigma_bn), None) => {
                let t = controller.torque_b_nm(&sigma_bn, &rate_b);
                (
                    CommandMsg::wrench(header, self.sender_id, t.into(), [0.0; 3]),
                    t,
                )
            }
            (Some(sigma_bn), Some((array, inertia))) => {
                let speeds = array.speeds(state)?;
                if let Some(f) = &mut self.fdir {
                    if f.wheels.check(&speeds, &mut f.events).is_some() {
                        *array = array.without(&f.wheels.failed_list())?;
                        f.events.push(Event::Wheels {
                            active: f.wheels.active_names(),
                        });
                    }
                }
                wheel_momentum_b_nms = array.momentum_b(&rate_b, &speeds);
                let l = wheel_control_torque(
                    controller.k_nm,
                    controller.p_nms,
                    &controller.sigma_br(&sigma_bn),
                    &rate_b,
                    inertia,
                    &wheel_momentum_b_nms,
                );
                let u = array.motor_torques(&l);
                if let Some(f) = &mut self.fdir {
                    f.wheels.commanded(&speeds, &u);
                }
                let cmd = CommandMsg::actuators(
                    header,
                    self.sender_id,
                    [0.0; 3],
                    [0.0; 3],
                    array.inputs(&u),
                );
                (cmd, l)
            }
        };
        // The flight code's telemetry of this tick goes out before its answer.
        if let Some(t) = &mut self.telemetry {
            let c = ControllerTick {
                sigma_bn,
                sigma_rn: controller.sigma_rn,
                rate_b_rad_s: rate_b,
                wheel_momentum_b_nms,
                fdir_events: self.fdir.as_ref().map_or(&[], |f| f.events.as_slice()),
            };
            t.controller(h.tick, h.sim_time_ns, &c)?;
        }
        self.participant
            .as_ref()
            .context("no command publisher yet")?
            .send(&cmd, &mut self.buf)
            .map_err(|e| anyhow::anyhow!("cannot publish the command: {e}"))
            .context("publishing")?;
        self.seq += 1;
        if let Some(f) = &mut self.fdir {
            print_fdir_events(h.tick, h.sim_time_ns, &mut f.events);
        }

        if self.log_every_ns > 0 && h.sim_time_ns >= self.next_log_ns {
            tracing::info!(
                tick = h.tick,
                t_s = h.sim_time_ns as f64 / 1e9,
                sigma_br_norm = controller.sigma_br(&Vector3::from(state.sigma_bn)).norm(),
                omega_norm_rad_s = Vector3::from(state.omega_bn_b_rad_s).norm(),
                torque_b_nm = ?torque_b_nm.as_slice(),
                "control"
            );
            self.next_log_ns = h.sim_time_ns.saturating_add(self.log_every_ns);
        }
        Ok(())
    }
}

impl TickHandler for Flight {
    fn on_tick(&mut self, tick: Tick) {
        if self.failed.is_some() {
            return;
        }
        if self.participant.is_none() {
            self.pending.push(tick);
            return;
        }
        // A panic would otherwise unwind into Zenoh's receiving task and end it, leaving the
        // main thread waiting: it becomes the run's error instead.
        let answered =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| self.answer(&tick)));
        match answered {
            Ok(Ok(())) => {}
            Ok(Err(e)) => self.failed = Some(e),
            Err(panic) => {
                let what = panic
                    .downcast_ref::<&str>()
                    .map(|s| (*s).to_owned())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "a panic".to_owned());
                self.failed = Some(anyhow::anyhow!(
                    "the flight code panicked at tick {}: {what}",
                    tick.tick()
                ));
            }
        }
    }
}

fn close(session: Session) -> anyhow::Result<()> {
    session
        .close()
        .wait()
        .map_err(|e| anyhow::anyhow!("closing the Zenoh session: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pd_law_signs() {
        let c = Controller {
            k_nm: 2.0,
            p_nms: 3.0,
            sigma_rn: Vector3::zeros(),
        };
        let t = c.torque_b_nm(&Vector3::new(0.1, 0.0, 0.0), &Vector3::zeros());
        assert!((t - Vector3::new(-0.2, 0.0, 0.0)).norm() < 1e-15, "{t}");
        let t = c.torque_b_nm(&Vector3::zeros(), &Vector3::new(0.0, 1.0, 0.0));
        assert_eq!(t, Vector3::new(0.0, -3.0, 0.0));
    }

    #[test]
    fn the_mounting_must_be_a_rotation() {
        assert!(parse_dcm(&[0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0]).is_ok());
        let e = parse_dcm(&[-1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 2.0]).unwrap_err();
        assert!(e.to_string().contains("rows 2, 2"), "{e}");
        let e = parse_dcm(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0]).unwrap_err();
        assert!(e.to_string().contains("reflection"), "{e}");
    }
}
