//! The device descriptions and engine: the shipped examples against bytes derived by hand,
//! the loader's refusals, malformed input counted and never applied, the speed loop's closed
//! form, chunking independence and encode → decode round trips.

mod examples;
mod loader;
mod malformed;
mod round_trip;
mod units_time;

use std::collections::HashMap;

use flexdyn_gateway::device::{Catalog, Device, DeviceSet, TickTime, Utc};

pub use crate::support::{shipped_list, FRAME_NS};

/// The shared catalog ([`crate::support::catalog`]) with the magnetorquer's dipole input.
pub fn catalog() -> Catalog {
    let mut c = crate::support::catalog();
    c.add_input("magnetorquer.mtq1.dipole_am2", "A m^2");
    c
}

/// The shipped devices, by name.
pub fn shipped(catalog: &Catalog) -> HashMap<String, Device> {
    let set = DeviceSet::load(&shipped_list(), catalog).unwrap_or_else(|e| panic!("{e}"));
    set.devices
        .into_iter()
        .map(|d| (d.name().to_owned(), d))
        .collect()
}

/// The catalog's values, all zero, with the named channels set.
pub fn values(catalog: &Catalog, set: &[(&str, f64)]) -> Vec<f64> {
    let mut v = vec![0.0; catalog.channel_count()];
    for (name, value) in set {
        let i = catalog
            .channel_index(name)
            .unwrap_or_else(|| panic!("no channel {name}"));
        v[i] = *value;
    }
    v
}

/// Tick `tick` of a 100 Hz run with an epoch: UTC 2026-11-30T12:00:00 at tick 0.
pub fn tick_time(tick: u64) -> TickTime {
    let sim_time_ns = tick * FRAME_NS;
    TickTime {
        tick,
        sim_time_ns,
        has_epoch: true,
        // 2 000 000 000 s after 1958 TAI, plus the tick's time.
        tai_ns_1958: 2_000_000_000_000_000_000 + sim_time_ns,
        utc: Utc {
            year: 2026,
            month: 11,
            day: 30,
            hour: 12,
            minute: 0,
            second: (sim_time_ns / 1_000_000_000) as u8,
            nanosecond: (sim_time_ns % 1_000_000_000) as u32,
        },
        gps_week: 2447,
        gps_ns_of_week: 129_618_000_000_000 + sim_time_ns,
        met_ns: sim_time_ns,
    }
}

/// CRC-16/CCITT-FALSE bit by bit, straight from the Rocksoft model (Williams 1993 §8: shift
/// left, XOR 0x1021 when the bit shifted out is 1; init 0xFFFF, no reflection, no final XOR).
/// An oracle independent of the crate's table-driven CRC.
pub fn crc16_ccitt_false(data: &[u8]) -> u16 {
    let mut crc = 0xFFFFu16;
    for &b in data {
        crc ^= u16::from(b) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

/// CRC-16/KERMIT bit by bit (reflected: shift right, XOR 0x8408, the reflected 0x1021; init 0).
pub fn crc16_kermit(data: &[u8]) -> u16 {
    let mut crc = 0u16;
    for &b in data {
        crc ^= u16::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0x8408
            } else {
                crc >> 1
            };
        }
    }
    crc
}

/// A SLIP frame of `content` by RFC 1055's rules: END, content with END → ESC ESC_END and
/// ESC → ESC ESC_ESC, END.
pub fn slip_frame(content: &[u8]) -> Vec<u8> {
    let mut f = vec![0xC0];
    for &b in content {
        match b {
            0xC0 => f.extend_from_slice(&[0xDB, 0xDC]),
            0xDB => f.extend_from_slice(&[0xDB, 0xDD]),
            _ => f.push(b),
        }
    }
    f.push(0xC0);
    f
}

/// A reaction-wheel frame: payload, CRC-16/KERMIT low octet first, SLIP.
pub fn wheel_frame(payload: &[u8]) -> Vec<u8> {
    let mut content = payload.to_vec();
    content.extend_from_slice(&crc16_kermit(payload).to_le_bytes());
    slip_frame(&content)
}

/// A star-tracker frame: EB 90, LEN, payload, CRC-16/CCITT-FALSE of all before, high first.
pub fn tracker_frame(payload: &[u8]) -> Vec<u8> {
    let mut f = vec![0xEB, 0x90, payload.len() as u8];
    f.extend_from_slice(payload);
    let crc = crc16_ccitt_false(&f);
    f.extend_from_slice(&crc.to_be_bytes());
    f
}

#[test]
fn the_bitwise_oracles_give_the_published_check_values() {
    // RevEng catalogue: CRC-16/IBM-3740 (CCITT-FALSE) check=0x29b1, CRC-16/KERMIT check=0x2189.
    assert_eq!(crc16_ccitt_false(b"123456789"), 0x29B1);
    assert_eq!(crc16_kermit(b"123456789"), 0x2189);
}

#[test]
fn devices_can_move_to_the_runtimes_threads() {
    fn send<T: Send + 'static>() {}
    send::<Device>();
    send::<DeviceSet>();
    send::<Catalog>();
}
