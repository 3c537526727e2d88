//! The end of a run, as every client sees it: the server's last StatusMsg on
//! `flexdyn/<sc>/status` says `Finished`, `Stopped` or `Failed` ([`RunState::ended`];
//! `proto/README.md`, "StatusMsg"). The server publishes it once its last frame is out, in every
//! mode, so a client that hears it has heard every frame of the run and can stop at once instead
//! of waiting for telemetry that will not come.

use std::sync::{Arc, Mutex};
use std::time::Instant;

use zenoh::pubsub::Subscriber;
use zenoh::{Session, Wait as _};

use crate::keys::Topics;
use crate::{decode_status, RunState};

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ended {
    /// `Finished`, `Stopped` or `Failed`.
    pub run_state: RunState,
    /// The last tick the server stepped (the status header's tick).
    pub tick: u64,
    /// When this client heard it.
    pub heard_at: Instant,
}

impl Ended {
    /// `finished`, `stopped` or `failed`.
    pub fn word(&self) -> &'static str {
        match self.run_state {
            RunState::Finished => "finished",
            RunState::Stopped => "stopped",
            _ => "failed",
        }
    }
}

/// A subscriber on a vehicle's status that remembers the first end of run it hears.
pub struct RunEnd {
    seen: Arc<Mutex<Option<Ended>>>,
    last_status: Arc<Mutex<Option<Instant>>>,
    _subscriber: Subscriber<()>,
}

impl RunEnd {
    /// Subscribes to `topics`' status key. Declare it before the telemetry subscriber, so the
    /// end cannot be heard before the frames it follows are subscribed to.
    pub fn declare(session: &Session, topics: &Topics) -> zenoh::Result<Self> {
        let seen = Arc::new(Mutex::new(None));
        let last_status = Arc::new(Mutex::new(None));
        let slot = Arc::clone(&seen);
        let heard = Arc::clone(&last_status);
        let subscriber = session
            .declare_subscriber(topics.status())
            .callback(move |sample| {
                let Ok(status) = decode_status(&sample.payload().to_bytes()) else {
                    return;
                };
                *heard.lock().unwrap_or_else(|p| p.into_inner()) = Some(Instant::now());
                if !status.run_state.ended() {
                    return;
                }
                let mut seen = slot.lock().unwrap_or_else(|p| p.into_inner());
                seen.get_or_insert(Ended {
                    run_state: status.run_state,
                    tick: status.header.tick,
                    heard_at: Instant::now(),
                });
            })
            .wait()?;
        Ok(Self {
            seen,
            last_status,
            _subscriber: subscriber,
        })
    }

    /// When the last status message came: a server that still publishes its status (also
    /// while paused) is alive.
    pub fn last_heard(&self) -> Option<Instant> {
        *self.last_status.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// How the run ended, once the server said so.
    pub fn ended(&self) -> Option<Ended> {
        *self.seen.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// A client's exit after the run: an error naming the tick if the server said the run failed
/// (its log says why), else success (finished, stopped, or no end heard).
pub fn outcome(ended: Option<Ended>) -> anyhow::Result<()> {
    match ended {
        Some(end) if end.run_state == RunState::Failed => anyhow::bail!(
            "the server reports that the run failed at tick {} (its log says why)",
            end.tick
        ),
        _ => Ok(()),
    }
}
