//! Reading flexdyn recordings back: the raw channels' samples in file order, tolerant of a file
//! cut short by a crash (everything up to the last complete record is returned, and the cut is
//! reported).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::error::SinkError;
use super::mcap_file::RAW_ENCODING;

/// One recorded raw sample.
#[derive(Clone, Debug, PartialEq)]
pub struct RawSample {
    /// Its Zenoh key (the channel topic).
    pub key: String,
    /// \[ns\] log time: the message's simulation time.
    pub log_time_ns: u64,
    /// \[ns since the Unix epoch\] publish time: the sample's wall-clock stamp.
    pub publish_time_ns: u64,
    /// The exact wire payload.
    pub payload: Vec<u8>,
}

/// A recording's raw samples and metadata.
#[derive(Clone, Debug, Default)]
pub struct Recording {
    /// Raw samples in file order.
    pub samples: Vec<RawSample>,
    /// Metadata records by name (`flexdyn`, `flexdyn/<sc-id>`, `flexdyn.recorder`).
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// Why reading stopped early (a truncated or damaged file), if it did.
    pub truncated: Option<String>,
}

fn input(path: &Path, problem: impl Into<String>) -> SinkError {
    SinkError::Input {
        path: PathBuf::from(path),
        problem: problem.into(),
    }
}

impl Recording {
    /// The vehicles the recording describes (its `flexdyn/<sc-id>` metadata records).
    pub fn vehicles(&self) -> Vec<super::mcap_file::VehicleInfo> {
        self.metadata
            .iter()
            .filter(|(name, _)| name.starts_with("flexdyn/"))
            .filter_map(|(_, meta)| super::mcap_file::VehicleInfo::from_metadata(meta))
            .collect()
    }
}

/// Reads `path`'s raw flexdyn channels (and its metadata) in file order.
pub fn read_recording(path: &Path) -> Result<Recording, SinkError> {
    let bytes = std::fs::read(path).map_err(|e| input(path, format!("cannot read: {e}")))?;
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(input(path, "not an MCAP file (no MCAP magic at the start)"));
    }
    let mut rec = Recording::default();
    let mut channels: BTreeMap<u16, (String, bool)> = BTreeMap::new();
    // Chunks unpacked; a missing end magic (a crash) is not an error by itself: reading stops
    // at the first incomplete record instead.
    let reader = mcap::read::ChunkFlattener::new_with_options(
        &bytes,
        mcap::read::Options::IgnoreEndMagic.into(),
    )
    .map_err(|e| input(path, format!("cannot read the MCAP header: {e}")))?;
    for record in reader {
        match record {
            Ok(mcap::records::Record::Channel(c)) => {
                channels.insert(c.id, (c.topic.clone(), c.message_encoding == RAW_ENCODING));
            }
            Ok(mcap::records::Record::Message { header, data }) => {
                if let Some((topic, true)) = channels.get(&header.channel_id) {
                    rec.samples.push(RawSample {
                        key: topic.clone(),
                        log_time_ns: header.log_time,
                        publish_time_ns: header.publish_time,
                        payload: data.into_owned(),
                    });
                }
            }
            Ok(mcap::records::Record::Metadata(m)) => {
                rec.metadata.insert(m.name.clone(), m.metadata.clone());
            }
            Ok(_) => {}
            Err(e) => {
                rec.truncated = Some(e.to_string());
                break;
            }
        }
    }
    Ok(rec)
}
