//! Every refusal of the loader names the file, the key path and the problem.

use std::io;
use std::path::{Path, PathBuf};

use super::catalog;
use flexdyn_gateway::device::{DescriptionError, DeviceSet};

const LIST: &str = "/cfg/devices.toml";
const DESCRIPTION: &str = "/cfg/dev.toml";

/// A one-device list over `description`, with `endpoint` and the binds of the examples.
fn load_with(list: &str, description: &str) -> Result<DeviceSet, DescriptionError> {
    let description = description.to_owned();
    DeviceSet::from_str(
        list,
        Path::new(LIST),
        move |p: &Path| {
            if p == Path::new(DESCRIPTION) {
                Ok(description.clone())
            } else {
                Err(io::Error::new(io::ErrorKind::NotFound, "no such file"))
            }
        },
        &catalog(),
    )
}

fn one_device(endpoint: &str) -> String {
    format!(
        "[[device]]\nname = \"d1\"\ndescription = \"dev.toml\"\n\
         bind = {{ tracker = \"st1\", wheel = \"rw1\", mag = \"mag1\", gps = \"gps1\" }}\n\
         endpoint = {endpoint}\n"
    )
}

fn load(description: &str) -> Result<DeviceSet, DescriptionError> {
    load_with(&one_device("{ pty = \"/tmp/d1\" }"), description)
}

/// A valid star-tracker-like description whose out-message's field is `field`, and whose
/// framing and message keys can be replaced.
fn tracker(framing: &str, message_extra: &str, field: &str) -> String {
    format!(
        "[framing]\n{framing}\n[id]\ntype = \"u8\"\n\
         [[message]]\nname = \"q\"\ndirection = \"out\"\nid = 1\n{message_extra}\n\
         [[message.field]]\n{field}\n"
    )
}

const SYNC: &str = "kind = \"sync_length\"\nsync = [0xEB, 0x90]\n\
                    length = { offset = 2, size = 1, counts = \"payload\" }\n\
                    checksum = \"CRC-16/CCITT-FALSE\"";
const PERIODIC: &str = "every_s = 0.1";
const Q0: &str = "type = \"i32\"\nsource = \"star_tracker.{tracker}.q_cn[0]\"";

/// The error's file, key and problem (an `Invalid` is expected).
fn invalid(result: Result<DeviceSet, DescriptionError>) -> (PathBuf, String, String) {
    match result {
        Err(DescriptionError::Invalid { file, key, problem }) => (file, key, problem),
        Err(other) => panic!("expected an invalid value, got: {other}"),
        Ok(_) => panic!("expected an error, the description loaded"),
    }
}

#[test]
fn a_valid_description_loads() {
    let set = load(&tracker(SYNC, PERIODIC, Q0)).unwrap();
    assert_eq!(set.devices.len(), 1);
    assert_eq!(set.devices[0].message_names(), ["q"]);
}

#[test]
fn an_unknown_channel_is_named_with_the_channels_offered() {
    let field = "type = \"i32\"\nsource = \"star_tracker.{tracker}.q_xx\"";
    let (file, key, problem) = invalid(load(&tracker(SYNC, PERIODIC, field)));
    assert_eq!(file, Path::new(DESCRIPTION));
    assert_eq!(key, "message[0].field[0].source");
    assert!(
        problem.contains("unknown channel `star_tracker.st1.q_xx`"),
        "{problem}"
    );
    assert!(problem.contains("star_tracker.st1.q_cn[0]"), "{problem}");
}

#[test]
fn an_incompatible_or_unknown_unit_is_refused_naming_both() {
    let field = "type = \"i32\"\nunit = \"deg\"\nsource = \"magnetometer.{mag}.b_s_t[0]\"";
    let (_, key, problem) = invalid(load(&tracker(SYNC, PERIODIC, field)));
    assert_eq!(key, "message[0].field[0].unit");
    assert!(
        problem.contains("`deg`") && problem.contains("`T`"),
        "{problem}"
    );
    let field = "type = \"i32\"\nunit = \"furlong\"\nsource = \"magnetometer.{mag}.b_s_t[0]\"";
    let (_, _, problem) = invalid(load(&tracker(SYNC, PERIODIC, field)));
    assert!(
        problem.contains("unknown unit `furlong`") && problem.contains("nT"),
        "{problem}"
    );
}

#[test]
fn a_period_that_is_not_a_whole_number_of_frames_is_refused() {
    // 15 ms at a 10 ms frame.
    let (_, key, problem) = invalid(load(&tracker(SYNC, "every_s = 0.015", Q0)));
    assert_eq!(key, "message[0].every_s");
    assert!(
        problem.contains("not a whole number of frames"),
        "{problem}"
    );
    let (_, _, problem) = invalid(load(&tracker(SYNC, "every_s = 0.0", Q0)));
    assert!(problem.contains("positive"), "{problem}");
    // 0.1 s and 2 s are whole numbers of 10 ms frames.
    load(&tracker(SYNC, "every_s = 2.0", Q0)).unwrap();
}

#[test]
fn an_unknown_framing_lists_the_framings() {
    let (_, key, problem) = invalid(load(&tracker("kind = \"morse\"", PERIODIC, Q0)));
    assert_eq!(key, "framing.kind");
    assert!(
        problem.contains("`morse`") && problem.contains("cobs"),
        "{problem}"
    );
    let (_, _, problem) = invalid(load(&tracker("kind = \"lines\"", PERIODIC, Q0)));
    assert!(problem.contains("nmea0183"), "{problem}");
}

#[test]
fn an_unknown_checksum_lists_the_catalogue() {
    let framing = "kind = \"slip\"\nchecksum = \"CRC-17/NONE\"";
    let (_, key, problem) = invalid(load(&tracker(framing, PERIODIC, Q0)));
    assert_eq!(key, "framing.checksum");
    assert!(problem.contains("CRC-16/KERMIT"), "{problem}");
    // Named by its parameters instead: CRC-16/CCITT-FALSE's.
    let framing = "kind = \"slip\"\nchecksum = { width = 16, poly = 0x1021, init = 0xFFFF, \
                   refin = false, refout = false, xorout = 0 }";
    load(&tracker(framing, PERIODIC, Q0)).unwrap();
    let framing = "kind = \"slip\"\nchecksum = { width = 16, poly = 0x1020, init = 0xFFFF, \
                   refin = false, refout = false, xorout = 0 }";
    let (_, _, problem) = invalid(load(&tracker(framing, PERIODIC, Q0)));
    assert!(problem.contains("even"), "{problem}");
}

#[test]
fn a_lab_address_is_refused_unless_allowed() {
    let endpoint = "{ udp_local = \"192.168.1.5:4000\", udp_remote = \"127.0.0.1:4001\" }";
    let description = tracker(SYNC, PERIODIC, Q0);
    let (file, key, problem) = invalid(load_with(&one_device(endpoint), &description));
    assert_eq!(file, Path::new(LIST));
    assert_eq!(key, "device[0].endpoint.udp_local");
    assert!(
        problem.contains("`d1`") && problem.contains("192.168.1.5:4000"),
        "{problem}"
    );
    let allowed = format!("allow_lab_interfaces = true\n{}", one_device(endpoint));
    load_with(&allowed, &description).unwrap();
    // Two endpoints at once.
    let both = "{ pty = \"/tmp/x\", tcp_server = \"127.0.0.1:0\" }";
    let (_, key, _) = invalid(load_with(&one_device(both), &description));
    assert_eq!(key, "device[0].endpoint");
}

#[test]
fn an_unbound_parameter_names_the_binds() {
    let field = "type = \"i32\"\nsource = \"star_tracker.{camera}.q_cn[0]\"";
    let (_, key, problem) = invalid(load(&tracker(SYNC, PERIODIC, field)));
    assert_eq!(key, "message[0].field[0].source");
    assert!(
        problem.contains("`{camera}`") && problem.contains("tracker"),
        "{problem}"
    );
}

#[test]
fn unknown_keys_and_missing_files_name_the_file() {
    let err = load(&format!(
        "colour = \"red\"\n{}",
        tracker(SYNC, PERIODIC, Q0)
    ))
    .unwrap_err();
    assert!(matches!(err, DescriptionError::Syntax { .. }), "{err}");
    assert_eq!(err.file(), Path::new(DESCRIPTION));
    assert!(err.to_string().contains("colour"), "{err}");
    let list = one_device("{ pty = \"/tmp/d1\" }").replace("dev.toml", "missing.toml");
    let err = load_with(&list, "").unwrap_err();
    assert!(matches!(err, DescriptionError::Read { .. }), "{err}");
    assert_eq!(err.file(), Path::new("/cfg/missing.toml"));
}

#[test]
fn messages_that_cannot_work_are_refused() {
    // A response that is not an out-message.
    let d = format!(
        "{}\n[[message]]\nname = \"req\"\ndirection = \"in\"\nid = 2\nresponse = \"nothing\"\n",
        tracker(SYNC, PERIODIC, Q0)
    );
    let (_, key, problem) = invalid(load(&d));
    assert_eq!(key, "message[1].response");
    assert!(
        problem.contains("`nothing`") && problem.contains("[q]"),
        "{problem}"
    );
    // Two in-messages with one id (an in- and an out-message may share one: a reply may carry
    // its request's id).
    let d = format!(
        "{}\n[[message]]\nname = \"cmd\"\ndirection = \"in\"\nid = 1\n",
        tracker(SYNC, PERIODIC, Q0)
    );
    load(&d).unwrap();
    let d = format!("{d}\n[[message]]\nname = \"cmd2\"\ndirection = \"in\"\nid = 1\n");
    let (_, key, _) = invalid(load(&d));
    assert_eq!(key, "message[2].id");
    // An out-message that is never sent.
    let (_, key, problem) = invalid(load(&tracker(SYNC, "", Q0)));
    assert_eq!(key, "message[0]");
    assert!(problem.contains("never sent"), "{problem}");
    // An id that does not fit its field.
    let d = tracker(SYNC, PERIODIC, Q0).replace("id = 1", "id = 256");
    let (_, key, _) = invalid(load(&d));
    assert_eq!(key, "message[0].id");
    // A speed setpoint without a speed loop.
    let d = format!(
        "{}\n[[message]]\nname = \"cmd\"\ndirection = \"in\"\nid = 2\n\
         [[message.field]]\ntype = \"f32\"\ndest = \"speed_loop.setpoint\"\n",
        tracker(SYNC, PERIODIC, Q0)
    );
    let (_, key, _) = invalid(load(&d));
    assert_eq!(key, "message[1].field[0].dest");
    // An unknown input.
    let d = format!(
        "{}\n[[message]]\nname = \"cmd\"\ndirection = \"in\"\nid = 2\n\
         [[message.field]]\ntype = \"f32\"\ndest = \"wheel.rw9.torque_nm\"\n",
        tracker(SYNC, PERIODIC, Q0)
    );
    let (_, key, problem) = invalid(load(&d));
    assert_eq!(key, "message[1].field[0].dest");
    assert!(problem.contains("wheel.rw1.torque_nm"), "{problem}");
    // A length field that does not follow the sync.
    let framing = SYNC.replace("offset = 2", "offset = 3");
    let (_, key, _) = invalid(load(&tracker(&framing, PERIODIC, Q0)));
    assert_eq!(key, "framing.length.offset");
    // A counter in a float field.
    let (_, key, _) = invalid(load(&tracker(
        SYNC,
        PERIODIC,
        "type = \"f32\"\nsource = \"counter\"",
    )));
    assert_eq!(key, "message[0].field[0].type");
}

#[test]
fn the_device_list_refuses_duplicates() {
    let list = format!(
        "{}{}",
        one_device("{ pty = \"/tmp/a\" }"),
        one_device("{ pty = \"/tmp/b\" }")
    );
    let (_, key, _) = invalid(load_with(&list, &tracker(SYNC, PERIODIC, Q0)));
    assert_eq!(key, "device[1].name");
    let list = format!(
        "{}{}",
        one_device("{ pty = \"/tmp/a\" }"),
        one_device("{ pty = \"/tmp/a\" }").replace("\"d1\"", "\"d2\"")
    );
    let (_, key, problem) = invalid(load_with(&list, &tracker(SYNC, PERIODIC, Q0)));
    assert_eq!(key, "device[1].endpoint");
    assert!(problem.contains("`d1`"), "{problem}");
}

#[test]
fn the_nmea_protocol_checks_its_group_and_sentences() {
    let d = "protocol = \"nmea0183\"\ngps = \"gps.{gps}\"\n[[sentence]]\ntype = \"GSV\"\nevery_s = 1.0\n";
    let (_, key, problem) = invalid(load(d));
    assert_eq!(key, "sentence[0].type");
    assert!(problem.contains("GGA"), "{problem}");
    let d =
        "protocol = \"nmea0183\"\ngps = \"imu.hub\"\n[[sentence]]\ntype = \"GGA\"\nevery_s = 1.0\n";
    let (_, key, problem) = invalid(load(d));
    assert_eq!(key, "gps");
    assert!(problem.contains("no field `gps_week`"), "{problem}");
}
