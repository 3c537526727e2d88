//! Live faults: the callback of `flexdyn/<sc>/fault` ([`FaultCommandMsg`], protocol 8).
//!
//! The callback decodes the command, checks its spacecraft, and resolves the fault exactly as a
//! `[[faults]]` entry is resolved at load ([`LiveResolver`]): that may allocate, and it happens
//! here, on the Zenoh thread. The physics side only receives the ready-made request: through a
//! bounded channel it drains before stepping each frame (its box goes back through a recycle
//! channel, to be freed by the telemetry thread), or, in lockstep with `handoff = "direct"`,
//! straight into the `LockstepCore` under its lock (the core steps on this side anyway).
//!
//! In lockstep a fault for `at_tick` = k + 1 put before the answer to tick k, from the same
//! Zenoh session, is installed before frame k → k + 1 is stepped: Zenoh delivers one session's
//! samples in order on one thread, and this callback hands the request over before it returns.
//!
//! Refused commands count in `rejected.fault_refused` (the resolution's error, or the physics
//! side's [`flexdyn_faults::ports::INSTALL_REFUSALS`]) and are logged with the reason;
//! undecodable or wrong-spacecraft ones count like commands. Who may put on the key is Zenoh's
//! access-control list (the shipped `scenarios/zenoh/secure-server.json5` lets only user
//! `operator`).

use std::sync::mpsc::SyncSender;
use std::sync::{Arc, Mutex};

use flexdyn_proto::{decode_fault_command, FaultCommandMsg, Topics};
use zenoh::pubsub::Subscriber;
use zenoh::Session;

use super::error::ServerError;
use super::intake::record_arrival;
use super::lockstep::VehicleCore;
use super::reject_log::RejectLog;
use super::shared::Shared;
use flexdyn_faults::live::LiveResolver;
use flexdyn_faults::ports::{LiveRequest, INSTALL_REFUSALS};
use flexdyn_sinks::recorder::RecordTx;

/// Where a resolved live fault goes.
pub(super) enum FaultSink {
    /// The physics thread's bounded queue, drained before each frame is stepped.
    Queue(SyncSender<LiveRequest>),
    /// Lockstep with `handoff = "direct"`: the core, installed under its lock.
    Core(VehicleCore),
}

/// Subscribes the live-fault callback to `flexdyn/<sc>/fault`; dropping the subscriber stops it.
pub(super) async fn declare(
    session: &Session,
    topics: &Topics,
    resolver: LiveResolver,
    sink: FaultSink,
    shared: Arc<Shared>,
    spacecraft_id: u32,
    record: Option<RecordTx>,
) -> Result<Subscriber<()>, ServerError> {
    let log = Mutex::new(RejectLog::default());
    // The resolver holds a spacecraft and its sensors (not `Sync`); deliveries take turns.
    let resolver = Mutex::new(resolver);
    let callback = move |sample: zenoh::sample::Sample| {
        let bytes = sample.payload().to_bytes();
        record_arrival(record.as_ref(), &sample, &bytes);
        let warn = |reason: &'static str, detail: &dyn std::fmt::Display| {
            log.lock()
                .unwrap_or_else(|p| p.into_inner())
                .record(reason, None, 1, detail);
        };
        let cmd: FaultCommandMsg = match decode_fault_command(&bytes) {
            Ok(m) => m,
            Err(e) => {
                let reason = match e {
                    flexdyn_proto::DecodeError::UnknownVersion { .. } => "bad_version",
                    flexdyn_proto::DecodeError::NonFinite { .. } => "non_finite",
                    _ => "malformed",
                };
                warn(reason, &format_args!("fault command: {e}"));
                shared.reject_decode(&e);
                return;
            }
        };
        if cmd.header.spacecraft_id != spacecraft_id {
            warn(
                "wrong_spacecraft",
                &format_args!(
                    "fault command for spacecraft_id {}, not this server's {spacecraft_id}",
                    cmd.header.spacecraft_id
                ),
            );
            shared.reject_wrong_spacecraft();
            return;
        }
        let resolved = resolver
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .resolve(&cmd);
        let req = match resolved {
            Ok(r) => r,
            Err(why) => {
                warn(
                    "fault_refused",
                    &format_args!("fault command refused: {why}"),
                );
                shared.reject_fault();
                return;
            }
        };
        let what = describe(&cmd);
        match &sink {
            FaultSink::Queue(tx) => {
                if tx.try_send(req).is_err() {
                    warn(
                        "fault_refused",
                        &format_args!("fault command refused ({what}): the fault queue is full"),
                    );
                    shared.reject_fault();
                } else {
                    tracing::info!(at_tick = cmd.at_tick, "fault command queued: {what}");
                }
            }
            FaultSink::Core(core) => match core.install_fault(req) {
                Ok(()) => {
                    tracing::info!(at_tick = cmd.at_tick, "fault command applied: {what}")
                }
                Err(code) => {
                    warn(
                        "fault_refused",
                        &format_args!(
                            "fault command refused ({what}): {}",
                            INSTALL_REFUSALS.get(usize::from(code)).unwrap_or(&"")
                        ),
                    );
                    shared.reject_fault();
                }
            },
        }
    };
    session
        .declare_subscriber(topics.fault())
        .callback(callback)
        .await
        .map_err(|e| ServerError::zenoh("declare the fault-command subscriber", e))
}

/// `inject bias_step on imus.hub.gyro` / `clear fault 3`, for the log.
fn describe(cmd: &FaultCommandMsg) -> String {
    match cmd.action {
        flexdyn_proto::FaultAction::Clear => format!("clear fault {}", cmd.fault_index),
        flexdyn_proto::FaultAction::Inject => format!(
            "inject {} on {}",
            flexdyn_faults::modes::MODES
                .get(cmd.mode as usize)
                .map_or("?", |m| m.0),
            cmd.target.as_str().unwrap_or("?")
        ),
    }
}
