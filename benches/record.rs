//! Recorder throughput: how fast [`McapSink`] turns a real telemetry stream into an MCAP file
//! (raw + decoded JSON + frame transforms, zstd chunks), against the named peer measured in the
//! same run: the `mcap` crate's own writer storing the same payloads raw only, with the same
//! chunking and compression (the floor any recorder of this format pays).
//!
//! The stream is 20 000 frames of the wheel scenario (`scenarios/wheels_star_tracker.toml`:
//! two panel pairs, four wheels, an IMU and a star tracker), encoded once up front: per frame a
//! StateMsg and an ImuMsg, a StarTrackerMsg every 10th frame and a StatusMsg every 100th.
//! Prints the median over rounds of messages/s, payload MB/s and file size for both writers.
//! Then the same stream with the flight code's telemetry (issue 37): one FswMsg per frame on
//! `flexdyn/sc1/fsw/acs` (a mode, an estimate, a target, variances and 7 value words; an event
//! every 100th frame), declared in the configuration so the recorder writes its decoded channel
//! too, against the stream without it in the same rounds.
//!
//! `cargo bench --bench record`; environment `FLEXDYN_BENCH_RECORD_ROUNDS` (default 7).

use flexdyn_testkit::median;
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;
use std::time::Instant;

use flexdyn_proto::{encode, fsw_flags, FswMsg, Header, StatusMsg};
use flexdyn_sinks::mcap_file::{
    McapSink, RecordingInfo, VehicleInfo, CHUNK_SIZE_BYTES, RAW_ENCODING,
};
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

const FRAMES: u64 = 20_000;

/// The telemetry stream of the flight code in the recording with telemetry.
const FSW_STREAM: &str = "
[[fsw_streams]]
name = \"acs\"
modes = [\"detumble\", \"pointing\"]
events = [{ name = \"target-chosen\" }]
values = [
  { name = \"rate_b_rad_s\", type = \"f64\", len = 3, unit = \"rad/s\" },
  { name = \"wheel_momentum_b_nms\", type = \"f64\", len = 3, unit = \"N·m·s\" },
  { name = \"fdir_flags\", type = \"i64\" },
]
";

/// The flight code's sample of `header`'s tick: what `flexdyn-acs-demo` publishes.
fn fsw_sample(header: Header, q_bn: [f64; 4]) -> Vec<u8> {
    let tick = header.tick;
    let mut m = FswMsg {
        header,
        flags: fsw_flags::MODE | fsw_flags::ESTIMATE | fsw_flags::TARGET | fsw_flags::COVARIANCE,
        mode: u32::from(tick >= 1000),
        q_est_bn: q_bn,
        q_target_rn: [1.0, 0.0, 0.0, 0.0],
        att_var_b_rad2: [1e-10, 1e-10, 4e-10],
        values: [1e-3, -2e-3, 5e-4, 1.5, 0.3, -0.7]
            .iter()
            .map(|x: &f64| x.to_bits())
            .chain([0])
            .collect(),
        ..FswMsg::default()
    };
    if tick.is_multiple_of(100) {
        m.event_count = 1;
    }
    encode(&m)
}

fn stream(cfg: &SimConfig, with_fsw: bool) -> Vec<(String, Vec<u8>, u64)> {
    let mut sim = Simulation::new(cfg).expect("scenario");
    let mut out = Vec::new();
    let mut state = sim.blank_state();
    let mut imu = Vec::new();
    let mut st = Vec::new();
    for tick in 0..FRAMES {
        if tick > 0 {
            sim.step_frame();
        }
        sim.state_into(&mut state);
        let stamp = 1_700_000_000_000_000_000 + tick * cfg.frame_ns;
        let header = Header::new(1, tick, tick * cfg.frame_ns, tick);
        state.header = header;
        out.push(("flexdyn/sc1/tlm/state".to_owned(), encode(&state), stamp));
        if with_fsw {
            out.push((
                "flexdyn/sc1/fsw/acs".to_owned(),
                fsw_sample(header, state.q_bn),
                stamp,
            ));
        }
        sim.imu_samples_into(&mut imu);
        for (s, name) in imu.iter().zip(sim.imu_names()) {
            out.push((
                format!("flexdyn/sc1/tlm/imu/{name}"),
                encode(&s.to_msg(header)),
                stamp,
            ));
        }
        sim.star_tracker_samples_into(tick, &mut st);
        for (i, s) in &st {
            let name = sim.star_trackers()[*i].name();
            out.push((
                format!("flexdyn/sc1/tlm/st/{name}"),
                encode(&s.to_msg(header)),
                stamp,
            ));
        }
        if tick % 100 == 0 {
            let status = StatusMsg {
                header,
                wall_time_unix_ns: stamp,
                ..StatusMsg::default()
            };
            out.push(("flexdyn/sc1/status".to_owned(), encode(&status), stamp));
        }
    }
    out
}

fn flexdyn_sink(path: &Path, info: &VehicleInfo, msgs: &[(String, Vec<u8>, u64)]) -> u64 {
    let mut sink = McapSink::create(
        path,
        &RecordingInfo {
            recorder: "bench".into(),
            command_line: String::new(),
        },
    )
    .unwrap();
    sink.describe_vehicle(info).unwrap();
    for (key, payload, stamp) in msgs {
        sink.write(key, payload, Some(*stamp), *stamp).unwrap();
    }
    sink.finish().unwrap().mcap_messages
}

fn raw_mcap(path: &Path, msgs: &[(String, Vec<u8>, u64)]) -> u64 {
    let file = std::fs::File::create(path).unwrap();
    let mut w = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .chunk_size(Some(CHUNK_SIZE_BYTES))
        .create(BufWriter::new(file))
        .unwrap();
    let schema = w.add_schema("raw", "", b"").unwrap();
    let mut channels: BTreeMap<&str, u16> = BTreeMap::new();
    for (i, (key, payload, stamp)) in msgs.iter().enumerate() {
        let id = match channels.get(key.as_str()) {
            Some(id) => *id,
            None => {
                let id = w
                    .add_channel(schema, key, RAW_ENCODING, &BTreeMap::new())
                    .unwrap();
                channels.insert(key, id);
                id
            }
        };
        let header = mcap::records::MessageHeader {
            channel_id: id,
            sequence: i as u32,
            log_time: *stamp,
            publish_time: *stamp,
        };
        w.write_to_known_channel(&header, payload).unwrap();
    }
    w.finish().unwrap();
    msgs.len() as u64
}

/// Median seconds per run of the flexdyn sink and of the peer over `rounds`, with the files'
/// sizes and the flexdyn sink's MCAP message count.
fn measure(
    rounds: usize,
    info: &VehicleInfo,
    msgs: &[(String, Vec<u8>, u64)],
    dir: &Path,
) -> (f64, f64, u64, u64, u64) {
    let (mut ours, mut peer) = (Vec::new(), Vec::new());
    let (mut ours_size, mut peer_size, mut ours_msgs) = (0, 0, 0);
    for _ in 0..rounds {
        let a = dir.join("flexdyn.mcap");
        let t = Instant::now();
        ours_msgs = flexdyn_sink(&a, info, msgs);
        ours.push(t.elapsed().as_secs_f64());
        ours_size = std::fs::metadata(&a).unwrap().len();
        let b = dir.join("raw.mcap");
        let t = Instant::now();
        raw_mcap(&b, msgs);
        peer.push(t.elapsed().as_secs_f64());
        peer_size = std::fs::metadata(&b).unwrap().len();
    }
    (median(ours), median(peer), ours_size, peer_size, ours_msgs)
}

fn report(label: &str, msgs: &[(String, Vec<u8>, u64)], m: (f64, f64, u64, u64, u64)) -> f64 {
    let (a, b, ours_size, peer_size, ours_msgs) = m;
    let payload_bytes: usize = msgs.iter().map(|(_, p, _)| p.len()).sum();
    let n = msgs.len() as f64;
    let mb = payload_bytes as f64 / 1e6;
    println!("{label}: {} samples, {mb:.1} MB of payload", msgs.len());
    println!(
        "  flexdyn McapSink (raw + JSON + transforms): {:.0} samples/s, {:.1} MB/s of payload, \
         {:.3} s per run, {ours_msgs} MCAP messages, file {:.1} MB",
        n / a,
        mb / a,
        a,
        ours_size as f64 / 1e6
    );
    println!(
        "  peer: mcap::Writer raw only:                {:.0} samples/s, {:.1} MB/s of payload, \
         {:.3} s per run, file {:.1} MB",
        n / b,
        mb / b,
        b,
        peer_size as f64 / 1e6
    );
    println!(
        "  ratio flexdyn/peer time: {:.2}; headroom at 1 kHz: {:.0} frames/s of this stream",
        a / b,
        FRAMES as f64 / a
    );
    a
}

fn main() {
    let rounds: usize = std::env::var("FLEXDYN_BENCH_RECORD_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(7);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/wheels_star_tracker.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let cfg = SimConfig::from_toml_str(&text).unwrap();
    let info = |config_toml: String| VehicleInfo {
        sc_id: "sc1".into(),
        spacecraft_id: 1,
        config_toml,
        server_settings: String::new(),
        flexdyn_version: "bench".into(),
        git_commit: None,
        epoch_utc: None,
    };
    let with_text = format!("{text}{FSW_STREAM}");
    SimConfig::from_toml_str(&with_text).expect("the stream's declaration");
    println!("recorder throughput: {FRAMES} frames of the wheel scenario, {rounds} rounds, median");
    let dir = std::env::temp_dir().join(format!("flexdyn-bench-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let plain = stream(&cfg, false);
    let with = stream(&cfg, true);
    let a = report(
        "without the flight code's telemetry",
        &plain,
        measure(rounds, &info(text), &plain, &dir),
    );
    let b = report(
        "with the flight code's telemetry (one FswMsg per frame)",
        &with,
        measure(rounds, &info(with_text), &with, &dir),
    );
    let _ = std::fs::remove_dir_all(&dir);
    println!(
        "telemetry on: {:.2} x the time per run of the stream without it; still {:.0} frames/s, \
         {:.1} x a 1 kHz server",
        b / a,
        FRAMES as f64 / b,
        FRAMES as f64 / b / 1000.0
    );
}
