//! The star tracker's entry in the sensor registry ([`crate::KINDS`]): its key
//! (`flexdyn/<sc>/tlm/st/<name>`), its wire message ([`StarTrackerMsg`]), how it is built from
//! `[[star_trackers]]` and how `flexdyn plot` draws it.

use flexdyn_proto::keys::{Topics, STAR_TRACKER_PREFIX};
use flexdyn_proto::{decode_star_tracker, StarTrackerMsg};

use super::{schema, StarTracker, StarTrackerConfig};
use crate::params::{read_boxed, SensorConfigReader, SensorParams};
use crate::{json_of, PanelSpec, Sensor, SensorBuild, SensorKind};
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::plausible::Implausible;

/// The star-tracker kind.
pub static KIND: SensorKind = SensorKind {
    noun: "star tracker",
    a_noun: "a star tracker",
    config_array: "star_trackers",
    config: SensorConfigReader {
        keys: &schema::KEYS,
        read: |t| read_boxed(t, schema::read),
        error_terms: &[
            ("sigma_cross_boresight_rad", 1),
            ("sigma_about_boresight_rad", 1),
            ("bias_c_rad", 3),
        ],
    },
    key_prefix: STAR_TRACKER_PREFIX,
    column_prefix: "st",
    message_name: "StarTrackerMsg",
    key: Topics::star_tracker,
    build,
    decode: |b| decode_star_tracker(b).map(|m| json_of(m.header, &m)),
    default_json: || json_of(Default::default(), &StarTrackerMsg::default()).1,
    json_schema: crate::message_json_schema::<StarTrackerMsg>,
    plot: (
        "star_tracker.png",
        "Star trackers: measured attitude q_CN (scalar first) and validity",
        &[
            PanelSpec {
                y_label: "measured q_CN (–)",
                lines: &[
                    ("q_cn_0", "q0"),
                    ("q_cn_1", "q1"),
                    ("q_cn_2", "q2"),
                    ("q_cn_3", "q3"),
                ],
            },
            PanelSpec {
                y_label: "valid; flags (1 Sun, 2 rate, 4 Earth, 8 Moon)",
                lines: &[("valid", "valid (0/1)"), ("status_flags", "status flags")],
            },
        ],
    ),
};

/// One [`StarTracker`] per `[[star_trackers]]` entry (errors name `star_trackers[i]…`).
fn build(ctx: &SensorBuild<'_>, out: &mut Vec<Box<dyn Sensor>>) -> Result<(), ConfigError> {
    for (i, st) in ctx.sensors.of::<StarTrackerConfig>().enumerate() {
        let path = format!("star_trackers[{i}]");
        out.push(Box::new(StarTracker::new(st.clone(), &path)?));
    }
    Ok(())
}

impl SensorParams for StarTrackerConfig {
    fn sensor_kind() -> &'static SensorKind {
        &KIND
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn implausible(&self, path: &str, out: &mut Vec<Implausible>) {
        super::plausibility::check(self, path, out);
    }
}
