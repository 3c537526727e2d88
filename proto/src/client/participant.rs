//! A lockstep participant's side of the wire: its command publisher on
//! `flexdyn/<sc>/cmd/<id>` and its liveliness token on `flexdyn/<sc>/participant/<id>`.
//!
//! The publisher blocks (never drops a command) and is express (no batching: lowest latency).
//! The token is what a lockstep server waits for before tick 0 (harmless in real time), so
//! declare the telemetry subscriber first: the server cannot then publish tick 0 before the
//! participant can receive it. Dropping a [`Participant`] undeclares the token first (a
//! lockstep server sees the participant leave), then the publisher.

use std::fmt;

use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Publisher;
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait as _};

use crate::{encode_into, CommandMsg, Topics};

/// A declared lockstep participant: its liveliness token and its command publisher.
pub struct Participant {
    // Fields drop in this order: the token before the publisher.
    _token: LivelinessToken,
    publisher: Publisher<'static>,
    key: String,
}

/// What could not be declared.
#[derive(Debug)]
pub enum ParticipantError {
    /// The command publisher on the key.
    Publisher(String, zenoh::Error),
    /// The liveliness token.
    Token(zenoh::Error),
}

impl fmt::Display for ParticipantError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Publisher(key, e) => write!(f, "cannot declare {key}: {e}"),
            Self::Token(e) => write!(f, "cannot declare the liveliness token: {e}"),
        }
    }
}

impl std::error::Error for ParticipantError {}

impl Participant {
    /// Declares the command publisher of `sender_id` on `topics`' vehicle, then its liveliness
    /// token.
    pub fn declare(
        session: &Session,
        topics: &Topics,
        sender_id: u32,
    ) -> Result<Self, ParticipantError> {
        let key = topics.cmd(sender_id);
        let declared = super::transport::declared_key(session, key.clone())
            .map_err(|e| ParticipantError::Publisher(key.clone(), e))?;
        let publisher = session
            .declare_publisher(declared)
            .congestion_control(CongestionControl::Block)
            .express(true)
            .wait()
            .map_err(|e| ParticipantError::Publisher(key.clone(), e))?;
        let token = session
            .liveliness()
            .declare_token(topics.participant(sender_id))
            .wait()
            .map_err(ParticipantError::Token)?;
        Ok(Self {
            _token: token,
            publisher,
            key,
        })
    }

    /// The key the commands go to (`flexdyn/<sc>/cmd/<id>`).
    pub fn key(&self) -> &str {
        &self.key
    }

    /// Encodes `cmd` into `buf` (cleared first) and publishes it.
    pub fn send(&self, cmd: &CommandMsg, buf: &mut Vec<u8>) -> zenoh::Result<()> {
        encode_into(cmd, buf);
        self.publisher.put(buf.as_slice()).wait()
    }
}
