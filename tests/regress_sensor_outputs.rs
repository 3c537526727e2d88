//! Regression goldens for the sensor outputs: the sha256 of the `flexdyn simulate` CSV (state,
//! IMU and star-tracker columns) of the two sensor scenarios, at three log intervals (the frame,
//! finer than a frame, coarser than a frame), so a refactor of the sensor seam, the IMU's Δv
//! integration or the stepping order that changes one bit of any output fails here.
//!
//! Provenance: minted by `flexdyn simulate --config scenarios/<name>.toml --duration-s 20
//! --log-every-s <interval> | sha256sum` at main 535783c (before the sensor seam of issue 20),
//! x86_64 Linux. To re-mint after an intended change of the outputs, run that command (or this
//! test, which prints the hashes) and replace the constants, saying why in the commit. A mismatch
//! on another platform can come from its libm (`atan2`, `acos`, `tan`), not from flexdyn.

use std::path::Path;

use flexdyn::cli::simulate_to;
use flexdyn::config::SimConfig;
use sha2::{Digest, Sha256};

/// (scenario, log interval \[s\], sha256 of the CSV).
const GOLDEN: [(&str, f64, &str); 6] = [
    (
        "imu_tactical",
        0.01,
        "f68b4d22dfa2997c6c1cf6b498569a8918f168b3d168cf9372a1927a1db61a29",
    ),
    (
        "imu_tactical",
        0.003,
        "6337c1b723498598b93a8cbb3557e9450ed6417fbc6cc1b88e41fcbf41116239",
    ),
    (
        "imu_tactical",
        0.05,
        "75b25b80bbd5af7e4452d6d649c227747f7d3c188b84a71fd33d99209c65ae52",
    ),
    (
        "wheels_star_tracker",
        0.01,
        "7b0be2a7348b24c891200c47f2cf54a3ef953322a173fc7f11fcb8e888de1585",
    ),
    (
        "wheels_star_tracker",
        0.003,
        "ee6953271f60360672c151837ac864476359ff71e99762b72432ab12747f21c3",
    ),
    (
        "wheels_star_tracker",
        0.05,
        "d79471c39a7a959a879384b022a1ff02fac4cfd3d18206b37aa305e1cd541b4f",
    ),
];

#[test]
fn regress_sensor_scenarios_simulate_csv_sha256() {
    let mut mismatches = Vec::new();
    for (scenario, log_every_s, want) in GOLDEN {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenarios/{scenario}.toml"));
        let cfg = SimConfig::from_file(&path).unwrap();
        let mut csv = Vec::new();
        simulate_to(&cfg, 20.0, log_every_s, &mut csv, "buffer").unwrap();
        let got: String = Sha256::digest(&csv)
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        println!(
            "{scenario} --log-every-s {log_every_s}: {} bytes, sha256 {got}",
            csv.len()
        );
        if got != want {
            mismatches.push(format!(
                "{scenario} at {log_every_s} s: {got}, golden {want}"
            ));
        }
    }
    assert!(mismatches.is_empty(), "{mismatches:#?}");
}
