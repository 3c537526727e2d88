//! Regression goldens for the sensor outputs: the sha256 of the `flexdyn simulate` CSV (state,
//! IMU and star-tracker columns) of the two sensor scenarios, at three log intervals (the frame,
//! finer than a frame, coarser than a frame), so a refactor of the sensor seam, the IMU's Δv
//! integration or the stepping order that changes one bit of any output fails here.
//!
//! Provenance: minted by `flexdyn simulate --config scenarios/<name>.toml --duration-s 20
//! --log-every-s <interval> | sha256sum` at main 535783c (before the sensor seam of issue 20),
//! x86_64 Linux; re-minted for protocol version 5, whose only effect on these CSVs is the
//! `protocol_version` column: with that column written back as 4, every CSV hashes to the
//! 535783c value; and again for protocol version 6 (the sun sensors and operator control; both branches minted the same values), checked the same way (the
//! column written back as 5 gives the protocol-5 hashes); and again for protocol version 7 (the GPS
//! receiver, issue 20): every CSV with its `protocol_version` column written back as 6 hashes to
//! its protocol-6 value. To re-mint after an intended change of the outputs, run that command (or this
//! test, which prints the hashes) and replace the constants, saying why in the commit. A mismatch
//! on another platform can come from its libm (`atan2`, `acos`, `tan`), not from flexdyn.

use std::path::Path;

use flexdyn::commands::simulate::simulate_to;
use flexdyn_vehicle::config::SimConfig;
use sha2::{Digest, Sha256};

/// (scenario, log interval \[s\], sha256 of the CSV). Re-minted for protocol version 10 (the
/// flight code's telemetry, issue 37): with the CSV's `protocol_version` column set back to 9,
/// all six hash to their protocol-9 values (checked with `flexdyn simulate` and a rewrite of
/// that column). Re-minted for protocol version 9 (the
/// fleet's relative-state message, issue 22): with the CSV's `protocol_version` column set back
/// to 8, all six were checked to hash to their protocol-8 values. Re-minted for protocol
/// version 8 (fault
/// events, issue 21): with the CSV's `protocol_version` column set back to 7, two of them
/// (imu_tactical at 0.01 s, wheels_star_tracker at 0.05 s) were checked to hash to their
/// protocol-7 values. Re-minted for protocol version 7: the
/// CSV's `protocol_version` column reads 7; with it set back to 6 each CSV hashes to its
/// protocol-6 golden (and back to 5, 4, to the older ones), so no other value changed.
///
/// Protocol version 11 (Earth albedo on the coarse sun sensors and 32 effector values, issue 39
/// §4) is checked without a re-mint: the CSV's `protocol_version` column, the only place the
/// version enters these outputs, is written back to [`MINTED_PROTOCOL_VERSION`] before hashing
/// ([`with_minted_version`]), which is what each re-mint above checked by hand; every other
/// byte is hashed as written.
const GOLDEN: [(&str, f64, &str); 6] = [
    (
        "imu_tactical",
        0.01,
        "eed792b77ee40928434d826ee45b6960ce0d0af9bd5fc21a3f988d64286b597b",
    ),
    (
        "imu_tactical",
        0.003,
        "8ad8f85a079763e835670069c22da9d284c7fe45e564916ebb545047651ef63e",
    ),
    (
        "imu_tactical",
        0.05,
        "382c9c998926a376c4f75650dfcebcc891e433017af687b9fd61e86ef6755a9e",
    ),
    (
        "wheels_star_tracker",
        0.01,
        "f5a4df3148effb65603cf602c9f38f16bd29b2e09395f03a8736908625e8bb9d",
    ),
    (
        "wheels_star_tracker",
        0.003,
        "b0eb07161b2af23972df71ab962bd6fb8271c6f35bef6885e5cc6e07dca99b0a",
    ),
    (
        "wheels_star_tracker",
        0.05,
        "5317dcdbfe6f76c61ddec4ffb96bee09f8628067129bf3094b8ad4d0b6ffe21e",
    ),
];

/// The protocol version the goldens were minted at.
const MINTED_PROTOCOL_VERSION: u16 = 10;

/// The CSV with its `protocol_version` column (the current [`flexdyn_proto::PROTOCOL_VERSION`]
/// in every row, checked) written as [`MINTED_PROTOCOL_VERSION`]; every other byte as it is.
fn with_minted_version(csv: &[u8]) -> Vec<u8> {
    let text = std::str::from_utf8(csv).expect("the CSV is UTF-8");
    let mut lines = text.split_inclusive('\n');
    let header = lines.next().expect("a header row");
    let column = header
        .trim_end()
        .split(',')
        .position(|name| name == "protocol_version")
        .expect("a protocol_version column");
    let (now, minted) = (
        flexdyn_proto::PROTOCOL_VERSION.to_string(),
        MINTED_PROTOCOL_VERSION.to_string(),
    );
    let mut out = String::with_capacity(text.len());
    out.push_str(header);
    for line in lines {
        let (row, end) = line.split_at(line.trim_end_matches(['\r', '\n']).len());
        let fields: Vec<&str> = row
            .split(',')
            .enumerate()
            .map(|(i, field)| {
                if i == column {
                    assert_eq!(field, now, "protocol_version column");
                    minted.as_str()
                } else {
                    field
                }
            })
            .collect();
        out.push_str(&fields.join(","));
        out.push_str(end);
    }
    out.into_bytes()
}

#[test]
fn regress_sensor_scenarios_simulate_csv_sha256() {
    let mut mismatches = Vec::new();
    for (scenario, log_every_s, want) in GOLDEN {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenarios/{scenario}.toml"));
        let cfg = SimConfig::from_file(&path).unwrap();
        let mut csv = Vec::new();
        simulate_to(&cfg, 20.0, log_every_s, &mut csv, "buffer").unwrap();
        let got: String = Sha256::digest(with_minted_version(&csv))
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
