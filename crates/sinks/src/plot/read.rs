//! `flexdyn plot`'s reading of a recording: streamed from the file (never all of it in memory),
//! with progress on stderr, keeping only the samples the figures draw from.
//!
//! [`crate::reader::read_recording`] reads the whole file into memory, then copies every raw
//! sample of every vehicle; `plot` draws one vehicle (and, with `--relative-to`, the chief's
//! states), so the samples of every other channel are left in the decompressed chunk here.

use std::collections::HashMap;
use std::io::{IsTerminal as _, Read as _, Write as _};
use std::path::Path;
use std::time::{Duration, Instant};

use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

use crate::error::SinkError;
use crate::mcap_file::RAW_ENCODING;
use crate::reader::{RawSample, Recording};
use crate::topics::{classify, TopicKind};

/// How often the reading progress is printed.
pub const PROGRESS_EVERY: Duration = Duration::from_secs(1);

fn input(path: &Path, problem: impl Into<String>) -> SinkError {
    SinkError::Input {
        path: path.to_owned(),
        problem: problem.into(),
    }
}

/// Progress on stderr: `plot: read 120/368 MB (33 %)` while reading a recording, then
/// `plot: decoded 400000/1040290 messages (38 %)`, at most every [`PROGRESS_EVERY`], rewriting
/// one line on a terminal and as plain lines otherwise (a CI log); nothing for a step done in
/// less than that.
pub struct ReadProgress {
    what: &'static str,
    unit: &'static str,
    scale: f64,
    total: u64,
    started: Instant,
    last: Instant,
    terminal: bool,
    printed: bool,
}

impl ReadProgress {
    /// Progress over a file of `total` bytes.
    pub fn new(total: u64) -> Self {
        Self::counting("read", "MB", 1e6, total)
    }

    /// Progress over `total` messages decoded.
    pub fn decoding(total: u64) -> Self {
        Self::counting("decoded", "messages", 1.0, total)
    }

    fn counting(what: &'static str, unit: &'static str, scale: f64, total: u64) -> Self {
        let now = Instant::now();
        ReadProgress {
            what,
            unit,
            scale,
            total,
            started: now,
            last: now,
            terminal: std::io::stderr().is_terminal(),
            printed: false,
        }
    }

    /// The progress line at `done`.
    pub fn line(&self, done: u64) -> String {
        format!(
            "plot: {} {:.0}/{:.0} {} ({:.0} %)",
            self.what,
            done as f64 / self.scale,
            self.total as f64 / self.scale,
            self.unit,
            100.0 * done as f64 / self.total.max(1) as f64
        )
    }

    /// `read` bytes read so far: prints the line when one is due.
    pub fn update(&mut self, read: u64) {
        let now = Instant::now();
        if now.duration_since(self.last) < PROGRESS_EVERY {
            return;
        }
        self.last = now;
        self.print(read);
    }

    fn print(&mut self, read: u64) {
        let line = self.line(read);
        let mut err = std::io::stderr().lock();
        let _ = if self.terminal {
            write!(err, "\r{line}")
        } else {
            writeln!(err, "{line}")
        };
        let _ = err.flush();
        self.printed = true;
    }

    /// Reading ended at `read` bytes: the last line, if any was printed, with the time taken.
    pub fn finish(&mut self, read: u64) {
        if !self.printed {
            return;
        }
        let line = self.line(read);
        let s = self.started.elapsed().as_secs_f64();
        let end = if self.terminal { "\r" } else { "" };
        eprintln!("{end}{line} in {s:.1} s");
    }
}

/// What to keep of a channel's samples.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Keep {
    All,
    None,
}

/// The raw samples of `path` that `plot` draws from: every flexdyn channel of vehicle `sc`
/// (the first vehicle with a sample when `None`) and the StateMsgs of `chief`, with the
/// file's metadata (what [`crate::reader::read_recording`] returns, less the other channels).
/// Returns the recording and the vehicle plotted (`None`: no flexdyn channel).
pub fn read_for_plot(
    path: &Path,
    sc: Option<&str>,
    chief: Option<&str>,
) -> Result<(Recording, Option<String>), SinkError> {
    let mut file =
        std::fs::File::open(path).map_err(|e| input(path, format!("cannot read: {e}")))?;
    let total = file.metadata().map(|m| m.len()).unwrap_or(0);
    let mut magic = [0u8; 8];
    let n = file
        .read(&mut magic)
        .map_err(|e| input(path, format!("cannot read: {e}")))?;
    if magic[..n] != mcap::MAGIC[..] {
        return Err(input(path, "not an MCAP file (no MCAP magic at the start)"));
    }
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_skip_start_magic(true)
            .with_skip_end_magic(true),
    );
    let mut progress = ReadProgress::new(total);
    let mut read = n as u64;
    let mut sc: Option<String> = sc.map(str::to_owned);
    let mut rec = Recording::default();
    // Channel id → (topic, raw encoding, what to keep once decided).
    let mut channels: HashMap<u16, (String, bool, Option<Keep>)> = HashMap::new();
    while let Some(event) = reader.next_event() {
        let event = match event {
            Ok(e) => e,
            Err(e) => {
                rec.truncated = Some(e.to_string());
                break;
            }
        };
        match event {
            LinearReadEvent::ReadRequest(need) => {
                let got = file
                    .read(reader.insert(need))
                    .map_err(|e| input(path, format!("cannot read: {e}")))?;
                reader.notify_read(got);
                read += got as u64;
                progress.update(read);
            }
            LinearReadEvent::Record { data, opcode } => match mcap::parse_record(opcode, data) {
                Ok(mcap::records::Record::Channel(c)) => {
                    let raw = c.message_encoding == RAW_ENCODING;
                    channels.insert(c.id, (c.topic, raw, None));
                }
                Ok(mcap::records::Record::Message { header, data }) => {
                    let Some((topic, true, keep)) = channels.get_mut(&header.channel_id) else {
                        continue;
                    };
                    let keep = *keep.get_or_insert_with(|| match classify(topic) {
                        None => Keep::None,
                        Some(t) => {
                            let sc = sc.get_or_insert_with(|| t.sc_id.to_owned());
                            if t.sc_id == sc.as_str()
                                || (Some(t.sc_id) == chief && t.kind == TopicKind::State)
                            {
                                Keep::All
                            } else {
                                Keep::None
                            }
                        }
                    });
                    if keep == Keep::All {
                        rec.samples.push(RawSample {
                            key: topic.clone(),
                            log_time_ns: header.log_time,
                            publish_time_ns: header.publish_time,
                            payload: data.into_owned(),
                        });
                    }
                }
                Ok(mcap::records::Record::Metadata(m)) => {
                    rec.metadata.insert(m.name, m.metadata);
                }
                Ok(_) => {}
                Err(e) => {
                    rec.truncated = Some(e.to_string());
                    break;
                }
            },
        }
    }
    progress.finish(read);
    Ok((rec, sc))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcap_file::{McapSink, RecordingInfo};
    use flexdyn_proto::{encode, Header, StateMsg, StatusMsg};

    /// Issue 36: the progress lines' wording, and only the plotted vehicle's channels (and the
    /// chief's states) are kept from a recording of three vehicles.
    #[test]
    fn keeps_the_plotted_vehicle_and_the_chiefs_states_and_says_how_far_it_got() {
        assert_eq!(
            ReadProgress::new(368_000_000).line(120_000_000),
            "plot: read 120/368 MB (33 %)"
        );
        assert_eq!(
            ReadProgress::decoding(1000).line(250),
            "plot: decoded 250/1000 messages (25 %)"
        );
        let path =
            std::env::temp_dir().join(format!("flexdyn-plot-read-{}.mcap", std::process::id()));
        let info = RecordingInfo {
            recorder: "plot::read tests".into(),
            command_line: String::new(),
        };
        let mut sink = McapSink::create(&path, &info).unwrap();
        for k in 0..10u64 {
            let t = k * 100_000_000;
            for id in ["a", "b", "c"] {
                let s = StateMsg {
                    header: Header::new(1, k, t, k),
                    ..StateMsg::default()
                };
                sink.write(&format!("flexdyn/{id}/tlm/state"), &encode(&s), None, t)
                    .unwrap();
                let st = StatusMsg {
                    header: Header::new(1, k, t, k),
                    ..StatusMsg::default()
                };
                sink.write(&format!("flexdyn/{id}/status"), &encode(&st), None, t)
                    .unwrap();
            }
        }
        sink.finish().unwrap();
        let (rec, sc) = read_for_plot(&path, None, Some("c")).unwrap();
        assert_eq!(sc.as_deref(), Some("a"));
        let mut keys: Vec<&str> = rec.samples.iter().map(|s| s.key.as_str()).collect();
        keys.dedup();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(
            keys,
            [
                "flexdyn/a/status",
                "flexdyn/a/tlm/state",
                "flexdyn/c/tlm/state"
            ]
        );
        assert_eq!(rec.samples.len(), 30);
        assert!(rec.truncated.is_none(), "{:?}", rec.truncated);
        let (rec, sc) = read_for_plot(&path, Some("b"), None).unwrap();
        assert_eq!(sc.as_deref(), Some("b"));
        assert!(rec.samples.iter().all(|s| s.key.starts_with("flexdyn/b/")));
        assert_eq!(rec.samples.len(), 20);
        let _ = std::fs::remove_file(&path);
    }
}
