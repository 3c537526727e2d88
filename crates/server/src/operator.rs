//! Operator control: the callback of `flexdyn/<sc>/operator` ([`OperatorMsg`], protocol 6) that
//! pauses and resumes a real-time run and, in lockstep, runs N ticks and then holds; and (protocol
//! 12) asks for a checkpoint at a tick ([`checkpoint_tick`]), which the checkpoint writer's
//! requested tick carries to whoever steps the frames ([`super::checkpoint`]).
//!
//! The callback only moves the run's **hold target** ([`Shared::hold_target`]): "hold at the
//! first frame boundary at or after tick h". Whoever steps the frames reads it once per frame
//! (one atomic load, so the stepping path stays lock- and allocation-free): the frame of a tick
//! it holds at goes out with its TimeMsg's run state `Paused`, and then nothing of the frame
//! stream until the target moves past that tick or is cleared (`physics`, `lockstep`). What each
//! action means in each mode is [`decide`], documented in `proto/README.md`, "OperatorMsg".
//!
//! Refused actions count in `rejected.operator_refused`; undecodable or wrong-spacecraft
//! operator messages count like commands (`malformed`, `bad_version`, `wrong_spacecraft`). Who
//! may put on the key is Zenoh's access-control list (the shipped
//! `scenarios/zenoh/secure-server.json5` lets only user `operator`).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use flexdyn_proto::{decode_operator, Mode, OperatorAction, OperatorMsg, Topics};
use zenoh::pubsub::Subscriber;
use zenoh::Session;

use super::error::ServerError;
use super::intake::record_arrival;
use super::lockstep::LockstepCore;
use super::reject_log::RejectLog;
use super::shared::Shared;
use flexdyn_sinks::recorder::RecordTx;

/// What the hold target becomes when an operator asks for `action` (with `ticks`), in `mode`,
/// with the hold target `target` and the frames published up to (or held at) tick `tick`; or
/// why the action is refused.
pub fn decide(
    mode: Mode,
    action: OperatorAction,
    ticks: u64,
    target: Option<u64>,
    tick: u64,
) -> Result<Option<u64>, &'static str> {
    use OperatorAction::{Checkpoint, Pause, Resume, RunTicks};
    match (mode, action) {
        (Mode::Batch, _) => Err("operator commands do not apply to a batch run"),
        (_, Pause) if target.is_some() => {
            Err("pause: the run is already held, or a hold is pending")
        }
        // Real time: hold at the next frame boundary, whichever it is.
        (Mode::RealTime, Pause) => Ok(Some(0)),
        // Lockstep: the tick after the one published, as `RunTicks` 1.
        (Mode::Lockstep, Pause) => Ok(Some(tick.saturating_add(1))),
        (_, Resume) if target.is_none() => Err("resume: nothing is held or pending"),
        (_, Resume) => Ok(None),
        (Mode::RealTime, RunTicks) => {
            Err("run_ticks applies to lockstep runs; pause and resume a real-time run")
        }
        (Mode::Lockstep, RunTicks) if ticks == 0 => Err("run_ticks with ticks = 0"),
        (Mode::Lockstep, RunTicks) => Ok(Some(tick.saturating_add(ticks))),
        // Not a hold: `checkpoint_tick` decides it.
        (_, Checkpoint) => Err("checkpoint requests do not move the hold target"),
    }
}

/// The tick an operator's checkpoint request (`ticks`; 0: the next boundary) saves at, with the
/// frames published up to tick `tick`; or why it is refused. `dir` says whether the server has
/// a `--checkpoint-dir`, `pending` whether a request waits already.
pub fn checkpoint_tick(
    mode: Mode,
    ticks: u64,
    dir: bool,
    pending: bool,
    tick: u64,
) -> Result<u64, &'static str> {
    match mode {
        Mode::Batch => Err("operator commands do not apply to a batch run"),
        _ if !dir => Err("checkpoint: this server has no --checkpoint-dir"),
        _ if pending => Err("checkpoint: another checkpoint request is pending"),
        _ if ticks == 0 => Ok(tick.saturating_add(1)),
        _ if ticks <= tick => Err("checkpoint: that tick is already published"),
        _ => Ok(ticks),
    }
}

/// Subscribes the operator callback to `flexdyn/<sc>/operator`; dropping the subscriber stops
/// it. `core` is the lockstep core when the commands' callback steps the frames (lockstep,
/// `handoff = "direct"`): a release steps the held frame there at once. Refusals count in
/// `shared`; the hold target (and the tick it is decided against) is `hold`'s: the vehicle's
/// own `shared` for one vehicle, one for the whole fleet in fleet mode (any vehicle's operator
/// key pauses, resumes or runs the fleet). `checkpoints` is the checkpoint writer's requested
/// tick when the server has a `--checkpoint-dir` (`None`: checkpoint requests are refused).
// Eight: the run's keys, counters, hold, mode and ids, the lockstep core and the recorder are
// each what one caller has and the other does not (one vehicle, or a fleet).
#[allow(clippy::too_many_arguments)]
pub(super) async fn declare(
    session: &Session,
    topics: &Topics,
    shared: Arc<Shared>,
    mode: Mode,
    spacecraft_id: u32,
    core: Option<Arc<Mutex<LockstepCore>>>,
    record: Option<RecordTx>,
    hold: Arc<Shared>,
    checkpoints: Option<Arc<AtomicU64>>,
) -> Result<Subscriber<()>, ServerError> {
    let log = Mutex::new(RejectLog::default());
    // Serialises decisions (read the target, write it back) between concurrent deliveries.
    let deciding = Mutex::new(());
    let callback = move |sample: zenoh::sample::Sample| {
        let bytes = sample.payload().to_bytes();
        record_arrival(record.as_ref(), &sample, &bytes);
        let warn = |reason: &'static str, detail: &dyn std::fmt::Display| {
            log.lock()
                .unwrap_or_else(|p| p.into_inner())
                .record(reason, None, 1, detail);
        };
        let msg: OperatorMsg = match decode_operator(&bytes) {
            Ok(m) => m,
            Err(e) => {
                let reason = match e {
                    flexdyn_proto::DecodeError::UnknownVersion { .. } => "bad_version",
                    _ => "malformed",
                };
                warn(reason, &format_args!("operator command: {e}"));
                shared.reject_decode(&e);
                return;
            }
        };
        if msg.header.spacecraft_id != spacecraft_id {
            warn(
                "wrong_spacecraft",
                &format_args!(
                    "operator command for spacecraft_id {}, not this server's {spacecraft_id}",
                    msg.header.spacecraft_id
                ),
            );
            shared.reject_wrong_spacecraft();
            return;
        }
        let _one_at_a_time = deciding.lock().unwrap_or_else(|p| p.into_inner());
        // With the core, decide under its lock: the tick it has published cannot move meanwhile.
        let mut core_guard = core
            .as_ref()
            .map(|c| c.lock().unwrap_or_else(|p| p.into_inner()));
        let tick = hold.tick.load(Ordering::Acquire);
        if msg.action == OperatorAction::Checkpoint {
            let requested = checkpoints.as_deref();
            let pending = requested.is_some_and(|r| r.load(Ordering::Acquire) != u64::MAX);
            match checkpoint_tick(mode, msg.ticks, requested.is_some(), pending, tick) {
                Ok(at) => {
                    if let Some(r) = requested {
                        r.store(at, Ordering::Release);
                    }
                    tracing::info!(tick, at, "operator checkpoint requested");
                }
                Err(why) => {
                    warn(
                        "operator_refused",
                        &format_args!("operator command Checkpoint refused: {why}"),
                    );
                    shared.reject_operator();
                }
            }
            return;
        }
        match decide(mode, msg.action, msg.ticks, hold.hold_target(), tick) {
            Ok(target) => {
                hold.set_hold_target(target);
                tracing::info!(
                    action = ?msg.action,
                    ticks = msg.ticks,
                    tick,
                    hold_at = ?target,
                    "operator command applied"
                );
                if let Some(core) = core_guard.as_mut() {
                    core.release_if_due();
                }
            }
            Err(why) => {
                warn(
                    "operator_refused",
                    &format_args!("operator command {:?} refused: {why}", msg.action),
                );
                shared.reject_operator();
            }
        }
    };
    session
        .declare_subscriber(topics.operator())
        .callback(callback)
        .await
        .map_err(|e| ServerError::zenoh("declare the operator subscriber", e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use OperatorAction::{Checkpoint, Pause, Resume, RunTicks};

    #[test]
    fn a_checkpoint_request_saves_at_a_tick_still_to_come() {
        // 0: the next boundary after the one published.
        assert_eq!(checkpoint_tick(Mode::Lockstep, 0, true, false, 41), Ok(42));
        assert_eq!(checkpoint_tick(Mode::RealTime, 0, true, false, 41), Ok(42));
        assert_eq!(checkpoint_tick(Mode::Lockstep, 50, true, false, 41), Ok(50));
        // A tick already published, a pending request, no directory, batch: refused.
        assert!(checkpoint_tick(Mode::Lockstep, 41, true, false, 41).is_err());
        assert!(checkpoint_tick(Mode::Lockstep, 50, true, true, 41).is_err());
        assert!(checkpoint_tick(Mode::Lockstep, 50, false, false, 41).is_err());
        assert!(checkpoint_tick(Mode::Batch, 50, true, false, 41).is_err());
    }

    #[test]
    fn each_action_moves_the_hold_target_as_documented() {
        // Real time: pause holds at the next boundary; resume clears; run_ticks is refused.
        assert_eq!(decide(Mode::RealTime, Pause, 0, None, 41), Ok(Some(0)));
        assert!(decide(Mode::RealTime, Pause, 0, Some(0), 41).is_err());
        assert_eq!(decide(Mode::RealTime, Resume, 0, Some(0), 41), Ok(None));
        assert!(decide(Mode::RealTime, Resume, 0, None, 41).is_err());
        assert!(decide(Mode::RealTime, RunTicks, 5, None, 41).is_err());
        // Lockstep: run_ticks counts from the tick published or held.
        assert_eq!(decide(Mode::Lockstep, RunTicks, 5, None, 0), Ok(Some(5)));
        assert_eq!(decide(Mode::Lockstep, RunTicks, 3, Some(5), 5), Ok(Some(8)));
        assert_eq!(decide(Mode::Lockstep, RunTicks, 3, Some(9), 5), Ok(Some(8)));
        assert!(decide(Mode::Lockstep, RunTicks, 0, None, 5).is_err());
        assert_eq!(
            decide(Mode::Lockstep, RunTicks, u64::MAX, None, 5),
            Ok(Some(u64::MAX))
        );
        assert_eq!(decide(Mode::Lockstep, Pause, 0, None, 7), Ok(Some(8)));
        assert!(decide(Mode::Lockstep, Pause, 0, Some(8), 7).is_err());
        assert_eq!(decide(Mode::Lockstep, Resume, 0, Some(8), 8), Ok(None));
        assert!(decide(Mode::Lockstep, Resume, 0, None, 8).is_err());
        // Checkpoint (protocol 12): never moves the hold target (`checkpoint_tick` decides it).
        assert!(decide(Mode::RealTime, Checkpoint, 0, None, 41).is_err());
        assert!(decide(Mode::Lockstep, Checkpoint, 50, Some(8), 7).is_err());
        // Batch: nothing applies.
        for a in [Pause, Resume, RunTicks, Checkpoint] {
            assert!(decide(Mode::Batch, a, 1, None, 0).is_err());
            assert!(decide(Mode::Batch, a, 1, Some(3), 0).is_err());
        }
    }
}
