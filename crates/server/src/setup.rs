//! Setup of a run, before any of its threads starts: the telemetry publishers, the
//! `flexdyn/<sc>/config` queryable that describes the vehicle, and the `--record` recorder.
//!
//! Real time publishes telemetry with congestion control "drop" (a full link queue drops the
//! sample instead of delaying the frame); lockstep and batch with "block", so no sample of the
//! deterministic stream is lost.

use std::sync::Arc;

use flexdyn_proto::client::transport::declared_key;
use flexdyn_proto::{Mode, Topics};
use zenoh::pubsub::Publisher;
use zenoh::qos::CongestionControl;
use zenoh::query::Queryable;
use zenoh::{Session, Wait};

use super::error::{ServerError, SettingsError};
use super::publish::FramePublisher;
use super::settings::ServerSettings;
use flexdyn_sinks::mcap_file::{flexdyn_version, git_commit, RecordingInfo, VehicleInfo};
use flexdyn_sinks::recorder::{RecordTx, Recorder};
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

/// Samples the `--record` queue holds before real time drops (lockstep waits instead).
pub const RECORD_QUEUE: usize = 65_536;

/// The run's telemetry publishers and the description of the vehicle it runs.
pub(super) struct Endpoints {
    /// `flexdyn/<sc>/tlm/state`, also in [`Self::frames`] (the lockstep presence wait asks it
    /// for subscribers).
    pub state_pub: Arc<Publisher<'static>>,
    /// `flexdyn/<sc>/status`.
    pub status_pub: Publisher<'static>,
    /// The per-frame publishers: state, IMUs, star trackers.
    pub frames: FramePublisher,
    /// What this server runs, for recordings and the configuration queryable.
    pub vehicle: VehicleInfo,
}

impl Endpoints {
    /// Declares the publishers of `sim`'s telemetry.
    pub(super) async fn declare(
        session: &Session,
        settings: &ServerSettings,
        cfg: &SimConfig,
        topics: &Topics,
        sim: &Simulation,
    ) -> Result<Self, ServerError> {
        // Real time drops telemetry under congestion rather than delaying the frame; lockstep
        // and batch block, so no sample of the deterministic stream is lost. Delivery is
        // reliable (Zenoh's default `Reliability::Reliable`, over TCP); its setter is unstable
        // in Zenoh 1.10.
        let congestion = if settings.mode == Mode::RealTime {
            CongestionControl::Drop
        } else {
            CongestionControl::Block
        };
        // A frame goes out as one batch: its time message and sensor samples wait in Zenoh's
        // batch and the state, published after them and express, sends it (Zenoh moves the
        // current batch, with everything queued before, to the link on an express message;
        // order is kept). One write per frame and subscriber instead of one per message: the
        // socket and wake-up cost per message is what bounds a fleet's tick rate on 2 cores.
        // The environment, fault-event and relative messages follow the state and stay express
        // (they are the frame's tail; nothing else would flush them). Batch mode batches all.
        let express = settings.mode != Mode::Batch;
        // Each key declared first, so Zenoh routes its samples by a cached route
        // (`flexdyn_proto::client::transport::declared_key`).
        let telemetry_pub = |key: String, what: &'static str, express: bool| async move {
            let key = declared_key(session, key).map_err(|e| ServerError::zenoh(what, e))?;
            session
                .declare_publisher(key)
                .congestion_control(congestion)
                .express(express)
                .await
                .map_err(|e| ServerError::zenoh(what, e))
        };
        let state_pub = telemetry_pub(
            topics.state().to_owned(),
            "declare the state publisher",
            express,
        )
        .await?;
        let status_key = declared_key(session, topics.status())
            .map_err(|e| ServerError::zenoh("declare the status publisher", e))?;
        let status_pub = session
            .declare_publisher(status_key)
            .congestion_control(congestion)
            .await
            .map_err(|e| ServerError::zenoh("declare the status publisher", e))?;

        // One publisher per sensor, in the bank's (publication) order.
        let sensors = sim.sensors().sensors();
        let mut sensor_pubs = Vec::with_capacity(sensors.len());
        for (i, s) in sensors.iter().enumerate() {
            let kind = s.kind();
            let key = (kind.key)(topics, s.name()).map_err(|e| {
                // Its index among its kind's configuration entries.
                let j = sensors[..i]
                    .iter()
                    .filter(|o| std::ptr::eq(o.kind(), kind))
                    .count();
                SettingsError::Invalid {
                    name: format!("{}[{j}].name", kind.config_array),
                    problem: e.to_string(),
                }
            })?;
            sensor_pubs.push((
                kind,
                telemetry_pub(key, "declare a sensor publisher", false).await?,
            ));
        }
        let time_pub = telemetry_pub(topics.time(), "declare the time publisher", false).await?;
        let state_pub = Arc::new(state_pub);
        let mut frames = FramePublisher::new(time_pub, state_pub.clone(), sensor_pubs);
        if sim.environment_every_frames().is_some() {
            frames.environment_pub = Some(
                telemetry_pub(
                    topics.environment(),
                    "declare the environment publisher",
                    express,
                )
                .await?,
            );
        }
        // Fault events: configured faults, and live ones may come at any time.
        frames.fault_pub = Some(
            telemetry_pub(
                topics.fault_events(),
                "declare the fault-event publisher",
                express,
            )
            .await?,
        );

        let vehicle = VehicleInfo {
            sc_id: settings.sc_id.clone(),
            spacecraft_id: settings.spacecraft_id,
            config_toml: cfg.source_toml.clone(),
            server_settings: settings.summary(),
            flexdyn_version: flexdyn_version().to_owned(),
            git_commit: git_commit().map(str::to_owned),
            epoch_utc: cfg.epoch.as_ref().map(|e| e.utc_iso()),
        };
        Ok(Self {
            state_pub,
            status_pub,
            frames,
            vehicle,
        })
    }
}

/// The `flexdyn/<sc>/config` queryable: answers with `vehicle` (JSON) for as long as it lives.
pub(super) async fn serve_config(
    session: &Session,
    topics: &Topics,
    vehicle: &VehicleInfo,
) -> Result<Queryable<()>, ServerError> {
    let vehicle_json = serde_json::to_string(vehicle)
        .map_err(|e| ServerError::Internal(format!("vehicle description: {e}")))?;
    session
        .declare_queryable(topics.config())
        .callback(move |query| {
            let key = query.key_expr().clone();
            if let Err(e) = query.reply(key, vehicle_json.clone()).wait() {
                tracing::debug!(error = %e, "cannot answer a configuration query");
            }
        })
        .await
        .map_err(|e| ServerError::zenoh("declare the configuration queryable", e))
}

/// `--record`: the recorder thread (with the vehicle's description already queued), fed by
/// whoever publishes the frames, the telemetry thread (status) and the command callback. Real
/// time drops (and counts) what it cannot keep up with; lockstep and batch wait for it.
pub(super) fn start_recorder(
    settings: &ServerSettings,
    vehicle: &VehicleInfo,
) -> Result<Option<(Recorder, RecordTx)>, ServerError> {
    let recorder = open_recorder(settings)?;
    if let Some((_, tx)) = &recorder {
        tx.describe_vehicle(vehicle.clone());
    }
    Ok(recorder)
}

/// The `--record` recorder thread with no vehicle described yet (fleet mode describes each
/// vehicle as its endpoints are declared).
pub(super) fn open_recorder(
    settings: &ServerSettings,
) -> Result<Option<(Recorder, RecordTx)>, ServerError> {
    let Some(path) = &settings.record else {
        return Ok(None);
    };
    let info = RecordingInfo {
        recorder: "flexdyn run --record".into(),
        command_line: std::env::args().collect::<Vec<_>>().join(" "),
    };
    let (recorder, tx) =
        Recorder::start(path, &info, RECORD_QUEUE, settings.mode != Mode::RealTime)?;
    tracing::info!(file = %path.display(), "recording to MCAP");
    Ok(Some((recorder, tx)))
}
