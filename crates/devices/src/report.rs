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
pub fn text(devices: &[DeviceReport], commands_sent: u64) -> String {
    let mut s = format!("gateway: {commands_sent} commands sent\n");
    for d in devices {
        let _ = writeln!(s, "device {} ({}):", d.name, d.endpoint);
        for (k, v) in counters(d) {
            let _ = writeln!(s, "  {k} = {v}");
        }
    }
    s
}

/// The same as TOML: a table per device.
pub fn toml(devices: &[DeviceReport], commands_sent: u64) -> String {
    let mut s = format!("commands_sent = {commands_sent}\n");
    for d in devices {
        let _ = writeln!(s, "\n[device.{}]\nendpoint = {}", quote(&d.name), quote(&d.endpoint));
        for (k, v) in counters(d) {
            let _ = writeln!(s, "{k} = {v}");
        }
    }
    s
}

/// Every counter of a device, by name.
fn counters(d: &DeviceReport) -> Vec<(String, u64)> {
    let mut c: Vec<(String, u64)> = d
        .engine
        .named()
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
    c.push(("line_frames_sent".into(), d.line.frames_sent));
    c.push(("line_bytes_sent".into(), d.line.bytes_sent));
    c.push(("line_frames_unheard".into(), d.line.frames_unheard));
    c.push(("line_frames_dropped_full".into(), d.line.frames_dropped_full));
    c.push(("late_ticks".into(), d.late_ticks));
    c.push(("missing_inputs".into(), d.missing_inputs));
    c
}
