//! The tools' test support: the end-to-end harness every suite shares
//! ([`flexdyn_testkit_server`]: an in-process server, loopback sessions, a recording lockstep
//! participant, child processes), and the ping-pong yardstick run against this package's own
//! `flexdyn-pingpong` binary.

// Each suite uses a different subset.
#[allow(unused_imports)]
pub use flexdyn_testkit_server::*;

/// Round-trip times of `count` StateMsg-sized pings after `warmup` ones, against a
/// `flexdyn-pingpong pong` child ([`flexdyn_tools::pingpong::round_trips`]).
#[allow(dead_code)]
pub fn pingpong_rtts(warmup: usize, count: usize, recv_loop: bool) -> Vec<std::time::Duration> {
    let pong = std::path::Path::new(env!("CARGO_BIN_EXE_flexdyn-pingpong"));
    flexdyn_tools::pingpong::round_trips(pong, warmup, count, recv_loop).expect("ping-pong")
}

/// Run `run`'s `result.json` in the campaign output `dir`.
#[allow(dead_code)]
pub fn campaign_result(dir: &std::path::Path, run: u32) -> flexdyn_campaign::execute::RunResult {
    let p = dir.join(format!("run-{run:04}/result.json"));
    serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap()
}

/// `flexdyn campaign run FILE --output OUT --jobs 2 --base-port 0` (each run records with
/// `record`), then `summarize`: (the run's exit code, the summary's text), both printed.
#[allow(dead_code)]
pub fn campaign_run_and_summarize(
    file: &std::path::Path,
    out: &std::path::Path,
    record: bool,
) -> (u8, String) {
    use flexdyn_campaign::{main as campaign, CampaignCommand};
    let report = campaign(&CampaignCommand::Run {
        file: file.to_owned(),
        output: out.to_owned(),
        jobs: Some(2),
        index: None,
        record,
        base_port: 0,
        without_random_faults: false,
    })
    .unwrap();
    eprintln!("{}", report.text);
    let summary = campaign(&CampaignCommand::Summarize {
        dir: out.to_owned(),
        slurm_array: None,
    })
    .unwrap();
    eprintln!("{}", summary.text);
    (report.exit_code, summary.text)
}

/// The demo's arguments for flying on its sensors and wheels: the star tracker `st1` for the
/// attitude, the gyro of the IMU `imu` for the rate, the reaction wheels as actuators.
#[allow(dead_code)]
pub fn on_sensors<'c>(
    cmd: &'c mut std::process::Command,
    imu: &str,
) -> &'c mut std::process::Command {
    cmd.args(["--actuator", "wheels", "--attitude-source", "star-tracker"])
        .args([
            "--star-tracker",
            "st1",
            "--rate-source",
            "gyro",
            "--imu",
            imu,
        ])
}
