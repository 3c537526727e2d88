//! Two-line element sets, parsed by the `sgp4` crate (`Elements::from_tle`: fixed columns,
//! checksums, Alpha-5 catalogue numbers). A text may hold several sets, each two lines
//! (`1 …`, `2 …`) optionally preceded by a name line (3LE; Space-Track's `0 NAME` form too).

use super::{ElementFormat, MeanElements};
use crate::epoch::parse::calendar_of_ordinal;
use crate::epoch::CalendarTime;

/// Whether `text` looks like TLEs (a line starting `1 ` followed by one starting `2 `).
pub(crate) fn looks_like(text: &str) -> bool {
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    while let Some(l) = lines.next() {
        if l.starts_with("1 ") {
            return lines.next().is_some_and(|n| n.starts_with("2 "));
        }
    }
    false
}

/// The element sets of a TLE text.
pub(crate) fn read(text: &str) -> Result<Vec<MeanElements>, String> {
    let lines: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end()))
        .filter(|(_, l)| !l.trim().is_empty())
        .collect();
    let mut out = Vec::new();
    let mut k = 0;
    while k < lines.len() {
        let (n0, l0) = lines[k];
        let (name, first) = if l0.starts_with("1 ") {
            (None, k)
        } else {
            let name = l0.strip_prefix("0 ").unwrap_or(l0).trim().to_string();
            (Some(name), k + 1)
        };
        let Some(&(n1, l1)) = lines.get(first) else {
            return Err(format!("line {n0}: a name line with no TLE after it"));
        };
        let Some(&(n2, l2)) = lines.get(first + 1) else {
            return Err(format!("line {n1}: TLE line 1 with no line 2 after it"));
        };
        if !l1.starts_with("1 ") {
            return Err(format!(
                "line {n1}: expected TLE line 1 (starting `1 `), got {l1:?}"
            ));
        }
        if !l2.starts_with("2 ") {
            return Err(format!(
                "line {n2}: expected TLE line 2 (starting `2 `), got {l2:?}"
            ));
        }
        for (n, l) in [(n1, l1), (n2, l2)] {
            if l.len() != 69 {
                return Err(format!(
                    "line {n}: a TLE line has 69 characters, this one {}",
                    l.len()
                ));
            }
        }
        // Early sets (Spacetrack Report #3's own examples) leave the ephemeris-type column 63
        // blank; blank means 0 and weighs 0 in the checksum, as the crate's `0` does.
        let mut l1 = l1.as_bytes().to_vec();
        if l1[62] == b' ' {
            l1[62] = b'0';
        }
        let el = sgp4::Elements::from_tle(name, &l1, l2.as_bytes())
            .map_err(|e| format!("lines {n1}–{n2}: {e} (columns are 0-based)"))?;
        let epoch_utc = exact_epoch(&l1).map_err(|m| format!("line {n1}: epoch: {m}"))?;
        out.push(from_crate(&el, epoch_utc));
        k = first + 2;
    }
    if out.is_empty() {
        return Err("no TLE found".to_string());
    }
    Ok(out)
}

/// The epoch of line 1 (columns 19–32, `YYDDD.DDDDDDDD`, UTC; years 57–99 are 19xx) to the
/// nanosecond: the 8 decimals of a day are whole multiples of 864 µs, so the decimal text is
/// converted with integers (the crate's `f64` day loses a nanosecond or so).
fn exact_epoch(l1: &[u8]) -> Result<CalendarTime, String> {
    let text = std::str::from_utf8(&l1[18..32]).map_err(|e| e.to_string())?;
    let yy: i32 = text[..2].trim().parse().map_err(|_| format!("{text:?}"))?;
    let year = if yy < 57 { 2000 + yy } else { 1900 + yy };
    let day = text[2..].trim();
    let (doy, frac) = day.split_once('.').unwrap_or((day, ""));
    let doy: u16 = doy.trim().parse().map_err(|_| format!("{text:?}"))?;
    if frac.len() > 11 || !frac.bytes().all(|c| c.is_ascii_digit()) {
        return Err(format!("{text:?}"));
    }
    // 86 400 s = 864 × 10¹¹ ns: k decimals of a day are 864 × 10^(11 − k) ns each.
    let digits: u64 = if frac.is_empty() {
        0
    } else {
        frac.parse().map_err(|_| format!("{text:?}"))?
    };
    let ns = digits * 864 * 10u64.pow(11 - frac.len() as u32);
    calendar_of_ordinal(year, doy, ns)
}

/// Our element set from the crate's, with the exact epoch.
fn from_crate(el: &sgp4::Elements, epoch_utc: CalendarTime) -> MeanElements {
    MeanElements {
        object_name: el.object_name.clone(),
        object_id: el.international_designator.clone(),
        norad_cat_id: Some(el.norad_id),
        epoch_utc,
        mean_motion_rev_per_day: el.mean_motion,
        eccentricity: el.eccentricity,
        inclination_deg: el.inclination,
        raan_deg: el.right_ascension,
        arg_perigee_deg: el.argument_of_perigee,
        mean_anomaly_deg: el.mean_anomaly,
        bstar_per_earth_radius: el.drag_term,
        mean_motion_dot_rev_per_day2: el.mean_motion_dot,
        mean_motion_ddot_rev_per_day3: el.mean_motion_ddot,
        format: ElementFormat::Tle,
    }
}
