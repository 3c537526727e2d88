//! The command callback: the Zenoh thread that delivers a `flexdyn/<sc>/cmd/*` sample decodes
//! and checks it (protocol, spacecraft, the key's sender, the participants, then the tick and the
//! effector inputs through the [`Gate`]), counts each rejection under its reason, records every
//! command that arrives, and delivers the valid ones: into the physics thread's bounded queue,
//! or (lockstep, `handoff = "direct"`) to the [`LockstepCore`], which may step the frame there.

use std::sync::mpsc::{SyncSender, TrySendError};
use std::sync::{Arc, Mutex};

use flexdyn_proto::client::transport::declared_key;
use flexdyn_proto::{decode_command, CommandMsg, Topics};
use zenoh::key_expr::KeyExpr;
use zenoh::pubsub::Subscriber;
use zenoh::Session;

use super::commands::{Gate, Offer};
use super::error::ServerError;
use super::lockstep::VehicleCore;
use super::reject_log::RejectLog;
use super::settings::ServerSettings;
use super::shared::Shared;
use super::stepper::count_offer;
use flexdyn_sinks::recorder::{RecordItem, RecordTx};

/// Where the command callback delivers a validated command.
pub(super) enum CommandSink {
    /// The physics thread's bounded queue, each command tagged with the index of the vehicle
    /// it arrived for (never blocks: a full queue drops and counts), behind that vehicle's
    /// [`Gate`].
    Queue {
        /// The vehicle's index in the world (0 for one spacecraft).
        vehicle: usize,
        /// The queue, behind this vehicle's [`Gate`].
        queue: Mutex<(SyncSender<(usize, CommandMsg)>, Gate)>,
    },
    /// Lockstep with `handoff = "direct"`: the core, stepped in this callback.
    Core(VehicleCore),
}

/// The command subscriber, and the participants' command keys declared to the session so
/// that Zenoh routes each command by a cached route
/// ([`flexdyn_proto::client::transport::declared_key`]). Dropping it stops the commands.
pub(super) struct Intake {
    _subscriber: Subscriber<()>,
    _keys: Vec<KeyExpr<'static>>,
}

/// Subscribes the command callback to `flexdyn/<sc>/cmd/*`, with the key of each of
/// `settings.participants` declared.
pub(super) async fn declare(
    session: &Session,
    topics: &Topics,
    sink: CommandSink,
    shared: Arc<Shared>,
    settings: &ServerSettings,
    record: Option<RecordTx>,
) -> Result<Intake, ServerError> {
    let mut keys = Vec::with_capacity(settings.participants.len());
    for p in &settings.participants {
        keys.push(
            declared_key(session, topics.cmd(*p))
                .map_err(|e| ServerError::zenoh("declare a participant's command key", e))?,
        );
    }
    let subscriber = session
        .declare_subscriber(topics.cmd_wildcard().to_owned())
        .callback(command_callback(
            sink,
            shared,
            topics.clone(),
            settings.spacecraft_id,
            settings.participants.clone(),
            record,
        ))
        .await
        .map_err(|e| ServerError::zenoh("declare the command subscriber", e))?;
    Ok(Intake {
        _subscriber: subscriber,
        _keys: keys,
    })
}

/// Queues a sample that arrived (a command, an operator command) for the `--record` file, as
/// it came, accepted or not.
pub(super) fn record_arrival(
    record: Option<&RecordTx>,
    sample: &zenoh::sample::Sample,
    bytes: &[u8],
) {
    if let Some(rec) = record {
        rec.submit(RecordItem {
            key: Arc::from(sample.key_expr().as_str()),
            payload: bytes.to_vec(),
            publish_time_ns: flexdyn_proto::client::transport::frame_stamp_ns(sample),
        });
    }
}

/// The zenoh callback for `flexdyn/<sc>/cmd/*`: decode and check (spacecraft, the key's
/// sender, the participants), count rejections, and deliver valid commands to `sink`.
fn command_callback(
    sink: CommandSink,
    shared: Arc<Shared>,
    topics: Topics,
    spacecraft_id: u32,
    participants: Vec<u32>,
    record: Option<RecordTx>,
) -> impl Fn(zenoh::sample::Sample) + Send + Sync + 'static {
    let log = Mutex::new(RejectLog::default());
    let warn = move |reason: &'static str, sender: Option<u32>, detail: &dyn std::fmt::Display| {
        log.lock()
            .unwrap_or_else(|p| p.into_inner())
            .record(reason, sender, 1, detail);
    };
    move |sample| {
        let bytes = sample.payload().to_bytes();
        let key = sample.key_expr().as_str();
        // Every command that arrives is recorded, accepted or not: the file shows what was sent.
        record_arrival(record.as_ref(), &sample, &bytes);
        let cmd = match decode_command(&bytes) {
            Ok(cmd) => cmd,
            Err(e) => {
                let reason = match e {
                    flexdyn_proto::DecodeError::UnknownVersion { .. } => "bad_version",
                    flexdyn_proto::DecodeError::NonFinite { .. } => "non_finite",
                    _ => "malformed",
                };
                // The sender id sits at bytes 30..34 once the header is there.
                let sender = bytes
                    .get(30..34)
                    .and_then(|b| b.try_into().ok())
                    .map(u32::from_le_bytes)
                    .filter(|_| reason == "non_finite");
                warn(reason, sender, &e);
                shared.reject_decode(&e);
                return;
            }
        };
        if cmd.header.spacecraft_id != spacecraft_id {
            warn(
                "wrong_spacecraft",
                Some(cmd.sender_id),
                &format_args!(
                    "header.spacecraft_id {} is not this server's {spacecraft_id}",
                    cmd.header.spacecraft_id
                ),
            );
            shared.reject_wrong_spacecraft();
            return;
        }
        if topics.cmd_sender(key) != Some(cmd.sender_id) {
            warn(
                "wrong_identity",
                Some(cmd.sender_id),
                &format_args!(
                    "sender_id {} arrived on `{key}`; participant {} publishes on `{}` only",
                    cmd.sender_id,
                    cmd.sender_id,
                    topics.cmd(cmd.sender_id)
                ),
            );
            shared.reject_wrong_identity();
            return;
        }
        if participants.binary_search(&cmd.sender_id).is_err() {
            warn(
                "unknown_sender",
                Some(cmd.sender_id),
                &format_args!(
                    "sender_id {} is not in server.participants {participants:?}",
                    cmd.sender_id
                ),
            );
            shared.reject_unknown_sender();
            return;
        }
        match &sink {
            CommandSink::Queue { vehicle, queue } => {
                let mut queue = queue.lock().unwrap_or_else(|p| p.into_inner());
                let (tx, gate) = &mut *queue;
                gated_send(gate, &shared, cmd, |cmd| {
                    match tx.try_send((*vehicle, cmd)) {
                        Ok(()) => Sent::Queued,
                        Err(TrySendError::Full(_)) => Sent::Full,
                        Err(TrySendError::Disconnected(_)) => Sent::RunOver,
                    }
                });
            }
            CommandSink::Core(core) => core.offer(&cmd),
        }
    }
}

/// What became of a command handed to the physics thread's queue.
enum Sent {
    /// Queued.
    Queued,
    /// The queue was full: dropped, and counted in `commands_dropped`.
    Full,
    /// The physics thread has ended (the run reached its duration or stopped): an answer to
    /// the last tick published, which nothing would step. Not a drop.
    RunOver,
}

/// Checks `cmd` against the published tick through `gate` and hands it to `send`, which never
/// blocks.
fn gated_send(
    gate: &mut Gate,
    shared: &Shared,
    cmd: CommandMsg,
    send: impl FnOnce(CommandMsg) -> Sent,
) {
    let published = shared.tick.load(std::sync::atomic::Ordering::Acquire);
    let offer = gate.check(&cmd, published);
    if offer != Offer::Accepted {
        count_offer(shared, offer, cmd.sender_id);
        return;
    }
    let (sender, tick) = (cmd.sender_id, cmd.header.tick);
    match send(cmd) {
        Sent::Queued => gate.queued(sender, tick),
        Sent::Full => {
            shared
                .commands_dropped
                .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        Sent::RunOver => {}
    }
}
