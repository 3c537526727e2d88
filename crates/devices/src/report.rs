//! What the gateway tells its user: where each driver finds its device, and at the end what
//! each device did (frames out and in, malformed input by reason, late ticks), as text and as
//! TOML for a test or a script to read.

use std::fmt::Write as _;
use std::path::Path;

use crate::gateway::DeviceReport;

/// Writes `name = "where"` lines, one per device, as a TOML table `[endpoints]`.
pub fn write_endpoints(path: &Path, endpoints: &[(String, String)]) -> std::io::Result<()> {
    let mut s = String::from("[endpoints]\n");
    for (name, at) in endpoints {
        let _ = writeln!(s, "{} = {}", quote(name), quote(at));
    }
    std::fs::write(path, s)
}

/// A TOML basic string.
fn quote(s: &str) -> String {
    let mut q = String::with_capacity(s.len() + 2);
    q.push('"');
    for c in s.chars() {
        match c {
            '"' => q.push_str("\\\""),
            '\\' => q.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(q, "\\u{:04X}", c as u32);
            }
            c => q.push(c),
        }
    }
    q.push('"');
    q
}

/// One line per device and counter, for people.
pub fn text(devices: &[DeviceReport], commands_sent: u64, ticks_without_time: u64) -> String {
    let mut s = format!(
        "gateway: {commands_sent} commands sent, {ticks_without_time} ticks without their time message\n"
    );
    for d in devices {
        let _ = writeln!(s, "device {} ({}):", d.name, d.endpoint);
        for (k, v) in counters(d) {
            let _ = writeln!(s, "  {k} = {v}");
        }
    }
    s
}

/// The same as TOML: a table per device.
pub fn toml(devices: &[DeviceReport], commands_sent: u64, ticks_without_time: u64) -> String {
    let mut s =
        format!("commands_sent = {commands_sent}\nticks_without_time = {ticks_without_time}\n");
    for d in devices {
        let _ = writeln!(
            s,
            "\n[device.{}]\nendpoint = {}",
            quote(&d.name),
            quote(&d.endpoint)
        );
        for (k, v) in counters(d) {
            let _ = writeln!(s, "{k} = {v}");
        }
    }
    s
}

/// Every counter of a device, by name: frames in by message (`in_<message>`), the framing's
/// and the engine's rejections by reason (`rejected_<reason>`), the line's fate of each frame.
fn counters(d: &DeviceReport) -> Vec<(String, u64)> {
    let e = &d.engine;
    let f = &e.framing;
    let mut c: Vec<(String, u64)> = vec![("frames_out".into(), e.frames_out)];
    c.extend(
        d.messages
            .iter()
            .zip(&e.frames_in)
            .map(|(m, n)| (format!("in_{m}"), *n)),
    );
    for (k, v) in [
        ("framed", f.frames),
        ("garbage_bytes", f.garbage_bytes),
        ("rejected_checksum", f.bad_checksum),
        ("rejected_length_field", f.bad_length),
        ("rejected_oversize", f.oversize),
        ("rejected_escape", f.bad_escape),
        ("rejected_encoding", f.bad_encoding),
        ("rejected_aborted", f.aborted),
        ("rejected_unknown_id", e.unknown_id),
        ("rejected_not_an_input", e.unknown_request),
        ("rejected_payload_length", e.bad_length),
        ("rejected_constant", e.bad_constant),
        ("rejected_non_finite", e.bad_value),
        ("rejected_total", e.rejected_frames()),
        ("clamped", e.clamped),
        ("unsendable", e.unsendable),
        ("line_frames_sent", d.line.frames_sent),
        ("line_bytes_sent", d.line.bytes_sent),
        ("line_frames_unheard", d.line.frames_unheard),
        ("line_frames_dropped_full", d.line.frames_dropped_full),
        ("late_ticks", d.late_ticks),
        ("missing_inputs", d.missing_inputs),
        ("late_outputs", d.late_outputs),
    ] {
        c.push((k.to_owned(), v));
    }
    c.extend(d.link.iter().map(|(k, v)| ((*k).to_owned(), *v)));
    c
}
