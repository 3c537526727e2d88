//! Lockstep presence: the participants announce themselves with a liveliness token on
//! `flexdyn/<sc>/participant/<sender_id>`, and tick 0 waits until every configured participant's
//! token is there and the state publisher has a subscriber, so no participant misses it. A token
//! dropped during the run is logged with the tick.

use std::collections::BTreeSet;
use std::future::Future;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use flexdyn_proto::Topics;
use tokio::sync::Notify;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::sample::SampleKind;
use zenoh::Session;

use super::error::ServerError;
use super::settings::ServerSettings;
use super::shared::Shared;

/// Participants seen through their liveliness tokens, and a wake-up for the presence wait.
#[derive(Default)]
struct Seen {
    ids: Mutex<BTreeSet<u32>>,
    changed: Notify,
}

impl Seen {
    fn missing(&self, wanted: &[u32]) -> Vec<u32> {
        let ids = self.ids.lock().unwrap_or_else(|p| p.into_inner());
        wanted
            .iter()
            .copied()
            .filter(|id| !ids.contains(id))
            .collect()
    }
}

/// The participants' liveliness tokens, watched for the whole run.
pub(super) struct Presence {
    seen: Arc<Seen>,
    _subscriber: Subscriber<()>,
}

impl Presence {
    /// Subscribes to the participants' tokens (with history: tokens declared before the server
    /// started count too).
    pub(super) async fn declare(
        session: &Session,
        topics: &Topics,
        shared: Arc<Shared>,
    ) -> Result<Self, ServerError> {
        let seen = Arc::new(Seen::default());
        let (s, t) = (seen.clone(), topics.clone());
        let subscriber = session
            .liveliness()
            .declare_subscriber(topics.participant_wildcard())
            .history(true)
            .callback(move |sample| {
                let Some(id) = t.participant_id(sample.key_expr().as_str()) else {
                    return;
                };
                let mut ids = s.ids.lock().unwrap_or_else(|e| e.into_inner());
                match sample.kind() {
                    SampleKind::Put => {
                        if ids.insert(id) {
                            tracing::info!(participant = id, "lockstep participant present");
                        }
                    }
                    SampleKind::Delete => {
                        if ids.remove(&id) {
                            tracing::warn!(
                                participant = id,
                                tick = shared.tick.load(Ordering::Relaxed),
                                "lockstep participant left (liveliness token dropped)"
                            );
                        }
                    }
                }
                drop(ids);
                s.changed.notify_one();
            })
            .await
            .map_err(|e| ServerError::zenoh("declare the participant liveliness subscriber", e))?;
        Ok(Self {
            seen,
            _subscriber: subscriber,
        })
    }

    /// Waits until every participant's liveliness token is present and `state_pub` has a
    /// subscriber. `Ok(true)` to start, `Ok(false)` if `shutdown` completed first; an error
    /// after `presence_timeout` names the participants still missing.
    pub(super) async fn wait(
        &self,
        state_pub: &Publisher<'static>,
        settings: &ServerSettings,
        topics: &Topics,
        mut shutdown: std::pin::Pin<&mut impl Future<Output = ()>>,
    ) -> Result<bool, ServerError> {
        let presence = &self.seen;
        let waited_from = Instant::now();
        let give_up = tokio::time::Instant::now() + settings.presence_timeout;
        let p = presence.clone();
        let _matching = state_pub
            .matching_listener()
            .callback(move |_| p.changed.notify_one())
            .await
            .map_err(|e| ServerError::zenoh("declare a matching listener", e))?;
        tracing::info!(
            participants = ?settings.participants,
            key = topics.participant_wildcard(),
            "waiting for the lockstep participants"
        );
        loop {
            let missing = presence.missing(&settings.participants);
            let matching = state_pub
                .matching_status()
                .await
                .map_err(|e| ServerError::zenoh("query the state publisher's matching status", e))?
                .matching();
            if missing.is_empty() && matching {
                tracing::info!("every lockstep participant is present; starting at tick 0");
                return Ok(true);
            }
            tokio::select! {
                () = shutdown.as_mut() => {
                    tracing::info!("shutdown requested before tick 0");
                    return Ok(false);
                }
                r = tokio::time::timeout_at(give_up, presence.changed.notified()) => {
                    if r.is_err() {
                        return Err(ServerError::ParticipantsAbsent {
                            missing: if missing.is_empty() {
                                settings.participants.clone()
                            } else {
                                missing
                            },
                            sc_id: settings.sc_id.clone(),
                            waited_s: waited_from.elapsed().as_secs_f64(),
                        });
                    }
                }
            }
        }
    }
}
