//! Unit conversions against their published definitions, and the `time.…` sources against
//! the tick's clock.

use std::path::Path;

use super::{tick_time, tracker_frame};
use flexdyn_gateway::device::units::{factor_from_si, UnitMismatch};
use flexdyn_gateway::device::{Catalog, DeviceSet};

#[test]
fn validate_unit_factors_against_their_definitions() {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    // SI Brochure Table 8: 1″ = π/648 000 rad, so a radian is 206 264.806 247 09…″.
    assert!(close(
        factor_from_si("rad", "arcsec").unwrap(),
        206_264.806_247_096_36
    ));
    assert!(close(
        factor_from_si("rad", "deg").unwrap(),
        57.295_779_513_082_32
    ));
    // 1 rpm = 2π/60 rad/s.
    assert!(close(
        factor_from_si("rad/s", "rpm").unwrap(),
        9.549_296_585_513_72
    ));
    assert!(close(
        factor_from_si("rad/s", "deg/s").unwrap(),
        57.295_779_513_082_32
    ));
    // 1 G = 1e-4 T; nT and µT by their prefixes.
    assert!(close(factor_from_si("T", "gauss").unwrap(), 1e4));
    assert!(close(factor_from_si("T", "nT").unwrap(), 1e9));
    assert!(close(factor_from_si("T", "µT").unwrap(), 1e6));
    assert!(close(factor_from_si("m", "km").unwrap(), 1e-3));
    assert!(close(factor_from_si("m/s", "km/s").unwrap(), 1e-3));
    assert!(close(factor_from_si("N m", "mN·m").unwrap(), 1e3));
    assert!(close(factor_from_si("A m^2", "A·m²").unwrap(), 1.0));
    assert!(close(factor_from_si("s", "us").unwrap(), 1e6));
    assert!(close(factor_from_si("s", "ns").unwrap(), 1e9));
    // g₀ = 9.806 65 m/s² (3rd CGPM, 1901).
    assert!(close(
        factor_from_si("m/s^2", "g0").unwrap(),
        1.0 / 9.806_65
    ));
    assert_eq!(factor_from_si("T", "deg"), Err(UnitMismatch::Incompatible));
    assert_eq!(factor_from_si("T", "furlong"), Err(UnitMismatch::Unknown));
    // An SI unit outside the table is only itself.
    assert_eq!(factor_from_si("kg", "kg"), Ok(1.0));
    assert_eq!(factor_from_si("kg", "g0"), Err(UnitMismatch::Incompatible));
}

#[test]
fn time_sources_carry_the_ticks_clock() {
    let catalog = Catalog::new(super::FRAME_NS);
    let fields = [
        ("u32", "time.tick", "1"),
        ("u16", "time.gps_week", "1"),
        ("u32", "time.gps_seconds_of_week", "ms"),
        ("u16", "time.utc.year", "1"),
        ("u8", "time.utc.month", "1"),
        ("u8", "time.utc.day", "1"),
        ("u8", "time.utc.hour", "1"),
        ("u8", "time.utc.minute", "1"),
        ("u8", "time.utc.second", "1"),
        ("u32", "time.utc.nanosecond", "ns"),
        ("u32", "time.met_s", "ms"),
        ("u64", "time.tai_s", "s"),
    ];
    let mut d = String::from(
        "[framing]\nkind = \"sync_length\"\nsync = [0xEB, 0x90]\n\
         length = { offset = 2, size = 1, counts = \"payload\" }\n\
         checksum = \"CRC-16/CCITT-FALSE\"\n[id]\ntype = \"u8\"\n\
         [[message]]\nname = \"req\"\ndirection = \"in\"\nid = 1\nresponse = \"t\"\n\
         [[message]]\nname = \"t\"\ndirection = \"out\"\nid = 2\n",
    );
    for (ty, source, unit) in fields {
        d.push_str(&format!(
            "[[message.field]]\ntype = \"{ty}\"\nsource = \"{source}\"\nunit = \"{unit}\"\n"
        ));
    }
    let list =
        "[[device]]\nname = \"clock\"\ndescription = \"c.toml\"\nendpoint = { pty = \"/tmp/c\" }\n";
    let mut set = DeviceSet::from_str(list, Path::new("l.toml"), |_| Ok(d.clone()), &catalog)
        .unwrap_or_else(|e| panic!("{e}"));
    let device = &mut set.devices[0];
    let now = tick_time(1234);
    let mut out = Vec::new();
    device.take_bytes(&tracker_frame(&[0x01]), &now, &[], &mut [], &mut out);
    // Expected from the clock's integer fields, big-endian, whole units (tick 1234 at 100 Hz
    // is 12.34 s: UTC 12:00:12.34, GPS 129 618 s + 12.34 s of the week).
    let mut p = vec![0x02];
    p.extend_from_slice(&1234u32.to_be_bytes());
    p.extend_from_slice(&2447u16.to_be_bytes());
    p.extend_from_slice(&(129_618_000u32 + 12_340).to_be_bytes());
    p.extend_from_slice(&2026u16.to_be_bytes());
    p.extend_from_slice(&[11, 30, 12, 0, 12]);
    p.extend_from_slice(&340_000_000u32.to_be_bytes());
    p.extend_from_slice(&12_340u32.to_be_bytes());
    p.extend_from_slice(&2_000_000_012u64.to_be_bytes());
    assert_eq!(out, tracker_frame(&p));
    assert_eq!(device.counters().clamped, 0);
}
