//! Fleet mode with the tools every one-vehicle server has:
//!
//! - `flexdyn run --fleet F --record FILE` records every vehicle (each described by its
//!   configuration, each state stream whole) and the deputy's relative states in one MCAP file,
//!   and `flexdyn plot --relative-to` draws the recorded RelativeStateMsg from it;
//! - the operator's pause and resume (`flexdyn/<id>/operator`) hold and release the whole fleet,
//!   whichever vehicle's key they arrive on.

use crate::server_support;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use flexdyn_campaign::execute::Observer;
use flexdyn_proto::{
    decode_relative_state, decode_state, encode, Header, Mode, OperatorAction, OperatorMsg, Topics,
};
use flexdyn_server::ServerSettings;
use flexdyn_sinks::plot::{figures, PlotArgs};
use flexdyn_sinks::reader::read_recording;
use flexdyn_vehicle::world::FleetConfig;
use server_support::{connecting_session, endpoint, FleetServerHandle, ANY_PORT};
use zenoh::Wait;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Two reference spacecraft, the deputy 100 m behind the chief; sender 9 answers both.
fn fleet_text() -> String {
    let reference = root().join("scenarios/reference.toml");
    format!(
        "[[vehicles]]\nid = \"chief\"\nspacecraft_file = {reference:?}\nparticipants = [9]\n\
         [[vehicles]]\nid = \"deputy\"\nspacecraft_file = {reference:?}\nparticipants = [9]\n\
         [vehicles.relative]\nchief = \"chief\"\nhill_position_m = [0.0, -100.0, 0.0]\n"
    )
}

#[test]
fn a_fleet_run_records_every_vehicle_and_the_relative_states() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fleet_record");
    std::fs::create_dir_all(&dir).unwrap();
    let fleet = dir.join("pair.toml");
    std::fs::write(&fleet, fleet_text()).unwrap();
    let file = dir.join("pair.mcap");
    let _ = std::fs::remove_file(&file);
    // Batch: 2 s of 100 Hz frames, ticks 0..=200, no participant needed.
    let out = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args([
            "run",
            "--mode",
            "batch",
            "--duration-s",
            "2",
            "--listen",
            ANY_PORT,
        ])
        .arg("--fleet")
        .arg(&fleet)
        .arg("--record")
        .arg(&file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rec = read_recording(&file).unwrap();
    assert!(rec.truncated.is_none(), "{:?}", rec.truncated);
    let mut described: Vec<String> = rec.vehicles().into_iter().map(|v| v.sc_id).collect();
    described.sort();
    assert_eq!(described, ["chief", "deputy"]);
    for (sc, id) in [("chief", 1), ("deputy", 2)] {
        let key = format!("flexdyn/{sc}/tlm/state");
        let ticks: Vec<(u64, u32)> = rec
            .samples
            .iter()
            .filter(|s| s.key == key)
            .map(|s| decode_state(&s.payload).unwrap().header)
            .map(|h| (h.tick, h.spacecraft_id))
            .collect();
        assert_eq!(
            ticks,
            (0..=200).map(|t| (t, id)).collect::<Vec<_>>(),
            "{sc}"
        );
        assert!(
            rec.samples
                .iter()
                .any(|s| s.key == format!("flexdyn/{sc}/status")),
            "{sc}: no StatusMsg recorded"
        );
    }
    let rel: Vec<_> = rec
        .samples
        .iter()
        .filter(|s| s.key == "flexdyn/deputy/tlm/rel/chief")
        .map(|s| decode_relative_state(&s.payload).unwrap())
        .collect();
    assert_eq!(
        rel.iter().map(|m| m.header.tick).collect::<Vec<_>>(),
        (0..=200).collect::<Vec<_>>()
    );
    // The deputy started 100 m behind the chief (centres of mass; the reference spacecraft's
    // panels move its centre of mass by millimetres).
    assert!((rel[0].r_dc_h_m[1] + 100.0).abs() < 1e-6, "{:?}", rel[0]);

    // The relative-motion figure is the recorded message's, point for point.
    let (figs, _) = figures(&PlotArgs {
        input: file.clone(),
        output: PathBuf::new(),
        sc_id: Some("deputy".into()),
        sigma_rn: None,
        relative_to: Some("chief".into()),
    })
    .unwrap();
    let fig = figs
        .iter()
        .find(|f| f.name == "relative_motion.png")
        .expect("relative_motion.png");
    // The title says the figure is the recorded RelativeStateMsg's (the other source, two
    // StateMsgs' hub points, is titled "Hub point B relative to …").
    assert!(
        fig.title.starts_with("Centre of mass") && fig.title.ends_with("(recorded)"),
        "{}",
        fig.title
    );
    let along = &fig.panels[0].lines[1];
    assert_eq!(along.points.len(), rel.len());
    for (p, m) in along.points.iter().zip(&rel) {
        assert_eq!(p.1, m.r_dc_h_m[1]);
    }
}

/// Lockstep fleet, sender 9 answering both vehicles: a `Pause` on the deputy's operator key
/// holds both vehicles at one tick; a `Resume` on the chief's releases both, and the run ends
/// complete with nothing refused.
#[test]
fn an_operator_pause_holds_the_whole_fleet() {
    const TICKS: u64 = 20_000;
    let fleet = FleetConfig::from_toml_str_in(&fleet_text(), &root()).unwrap();
    let settings = ServerSettings {
        mode: Mode::Lockstep,
        participant_timeout: Duration::from_secs(20),
        presence_timeout: Duration::from_secs(30),
        duration_ns: Some(TICKS * 10_000_000),
        ..ServerSettings::default()
    };
    let server = FleetServerHandle::start(settings, fleet);
    let port = server.port;
    let chief = Observer::start(&endpoint(port), &Topics::new("chief").unwrap(), 9).unwrap();
    let deputy = Observer::start(&endpoint(port), &Topics::new("deputy").unwrap(), 9).unwrap();
    let last = |o: &Observer| o.states.lock().unwrap().iter().map(|(t, _)| *t).max();
    let wait_for = |o: &Observer, tick: u64| {
        let give_up = Instant::now() + Duration::from_secs(60);
        while last(o).is_none_or(|t| t < tick) {
            assert!(Instant::now() < give_up, "never reached tick {tick}");
            std::thread::sleep(Duration::from_millis(2));
        }
    };
    wait_for(&chief, 50);
    let op = connecting_session(port);
    let put = |sc: &str, id: u32, action: OperatorAction| {
        let msg = OperatorMsg::new(Header::new(id, 0, 0, 0), action, 0);
        op.put(Topics::new(sc).unwrap().operator(), encode(&msg))
            .wait()
            .unwrap();
    };
    put("deputy", 2, OperatorAction::Pause);
    // Held: neither vehicle advances, both at the same tick.
    std::thread::sleep(Duration::from_millis(500));
    let frozen = (last(&chief), last(&deputy));
    std::thread::sleep(Duration::from_millis(700));
    assert_eq!(frozen, (last(&chief), last(&deputy)), "a vehicle stepped");
    assert_eq!(frozen.0, frozen.1);
    let held_at = frozen.0.unwrap();
    assert!(
        held_at < TICKS,
        "held at {held_at}: the pause came too late"
    );
    put("chief", 1, OperatorAction::Resume);
    let report = server
        .join(Duration::from_secs(120))
        .expect("the fleet run failed");
    assert_eq!(report.frames, TICKS);
    for (id, r) in &report.vehicles {
        assert_eq!(r.last_tick, TICKS, "{id}");
        assert_eq!(r.rejected.total(), 0, "{id}: {r}");
    }
    for o in [&chief, &deputy] {
        let mut ticks: Vec<u64> = o.states.lock().unwrap().iter().map(|(t, _)| *t).collect();
        ticks.sort_unstable();
        assert_eq!(ticks, (0..=TICKS).collect::<Vec<_>>());
    }
    println!("held both vehicles at tick {held_at}");
}
