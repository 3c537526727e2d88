//! Publishing each fleet deputy's [`flexdyn_proto::RelativeStateMsg`] on
//! `flexdyn/<deputy>/tlm/rel/<chief>`, every frame, right after the deputy's frame (its StateMsg
//! and what follows it), from the thread that publishes the frames. The message itself is
//! filled with the frames ([`super::world::WorldStepper::fill`]); here it is only encoded into
//! a buffer sized once and put, with the deputy's congestion control (real time: `Drop`, so the
//! put never waits for the network).

use std::sync::atomic::Ordering;

use flexdyn_proto::client::transport::declared_key;
use flexdyn_proto::{encode_into, Mode, Topics, RELATIVE_STATE_LEN};
use zenoh::pubsub::Publisher;
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait};

use super::error::{ServerError, SettingsError};
use super::publish::Recording;
use super::shared::Shared;
use super::world::RelativePair;

/// The publisher of one (chief, deputy) pair, with its encode buffer.
pub struct RelativePublisher {
    publisher: Publisher<'static>,
    buf: Vec<u8>,
    /// Its key, for the recorder.
    key: std::sync::Arc<str>,
}

impl RelativePublisher {
    /// Declares `flexdyn/<deputy>/tlm/rel/<chief>` as the deputy's telemetry is declared
    /// ([`super::setup::Endpoints::declare`]).
    pub async fn declare(
        session: &Session,
        mode: Mode,
        deputy: &Topics,
        chief_id: &str,
    ) -> Result<Self, ServerError> {
        let key = deputy
            .relative_state(chief_id)
            .map_err(|e| SettingsError::Invalid {
                name: "relative.chief".into(),
                problem: e.to_string(),
            })?;
        let congestion = if mode == Mode::RealTime {
            CongestionControl::Drop
        } else {
            CongestionControl::Block
        };
        // Declared, so its samples go by a cached route (`transport::declared_key`).
        let declared = declared_key(session, key.clone())
            .map_err(|e| ServerError::zenoh("declare the relative-state publisher", e))?;
        let publisher = session
            .declare_publisher(declared)
            .congestion_control(congestion)
            .express(mode != Mode::Batch)
            .await
            .map_err(|e| ServerError::zenoh("declare the relative-state publisher", e))?;
        Ok(Self {
            publisher,
            buf: Vec::with_capacity(RELATIVE_STATE_LEN),
            key: key.into(),
        })
    }

    /// Encodes and puts `pair`'s message with the frame-boundary stamp as its attachment
    /// (queued for `rec` too); a failed put is counted in the deputy's `publish_errors`.
    pub fn publish(
        &mut self,
        pair: &RelativePair,
        stamp_ns: u64,
        deputy: &Shared,
        rec: Option<&Recording>,
    ) {
        encode_into(&pair.msg, &mut self.buf);
        if let Err(e) = self
            .publisher
            .put(self.buf.as_slice())
            .attachment(stamp_ns.to_le_bytes())
            .wait()
        {
            let n = deputy.publish_errors.fetch_add(1, Ordering::Relaxed) + 1;
            if n.is_power_of_two() {
                tracing::warn!(error = %e, errors = n, "cannot publish a relative state");
            }
        }
        if let Some(r) = rec {
            r.submit(&self.key, &self.buf, Some(stamp_ns));
        }
    }
}

/// Vehicle `deputy`'s relative states, right after its frame: every pair of `pairs` whose
/// deputy it is, each with its publisher (`publishers[j]` is `pairs[j]`'s), counted in the
/// deputy's `shared` and queued for its `rec`.
pub fn publish_deputy(
    deputy: usize,
    pairs: &[RelativePair],
    publishers: &mut [RelativePublisher],
    stamp_ns: u64,
    shared: &Shared,
    rec: Option<&Recording>,
) {
    for (pair, rp) in pairs.iter().zip(publishers) {
        if pair.deputy == deputy {
            rp.publish(pair, stamp_ns, shared, rec);
        }
    }
}
