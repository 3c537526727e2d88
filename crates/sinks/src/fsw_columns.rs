//! The flight code's telemetry by name: the columns `flexdyn export` adds to a FswMsg row when
//! the recording's configuration declares its stream (`[[fsw_streams]]`), after the wire
//! columns (which stay, exact: `mode`, `events_1..8`, `values_1..n` as the u64 words).
//!
//! - `mode_name`: the mode's declared name (empty when the sample sets no mode);
//! - `event_names`: the events raised, by name, `;`-separated (empty when none);
//! - `v_<element>`: each declared value element, typed as declared: an f64 as a number, an i64
//!   as its exact decimal text, a bool as 0 or 1 (`v_h_wheels_b_nms[0]`, `v_fdir_flags`).

use std::collections::HashMap;

use flexdyn_proto::{fsw_flags, FswMsg};
use flexdyn_vehicle::config::fsw::read_streams;
use flexdyn_vehicle::config::{FswStreamDecl, FswValueType};

use super::reader::Recording;
use super::table::Cell;

/// The declared streams of every vehicle of a recording, by key (`flexdyn/<sc>/fsw/<name>`).
pub fn declarations(rec: &Recording) -> HashMap<String, FswStreamDecl> {
    let mut out = HashMap::new();
    for v in rec.vehicles() {
        match read_streams(&v.config_toml) {
            Ok(streams) => {
                for decl in streams {
                    // The configuration validated the names: their keys are there.
                    if let Ok(key) = flexdyn_proto::fsw_key(&v.sc_id, &decl.name) {
                        out.insert(key, decl);
                    }
                }
            }
            Err(e) => tracing::warn!(
                sc_id = %v.sc_id,
                error = %e,
                "the recording's [[fsw_streams]] do not load: flight-code columns by wire only"
            ),
        }
    }
    out
}

/// The named cells of `msg` by its stream's declaration (module docs).
pub fn named_cells(decl: &FswStreamDecl, msg: &FswMsg) -> Vec<(String, Cell)> {
    let mut out = Vec::with_capacity(2 + decl.words());
    let mode = (msg.flags & fsw_flags::MODE != 0)
        .then(|| decl.modes.get(msg.mode as usize))
        .flatten()
        .cloned()
        .unwrap_or_default();
    out.push(("mode_name".to_owned(), Cell::Text(mode)));
    let events: Vec<&str> = msg
        .event_indices()
        .iter()
        .filter_map(|&e| decl.events.get(usize::from(e)).map(|e| e.name.as_str()))
        .collect();
    out.push(("event_names".to_owned(), Cell::Text(events.join(";"))));
    for v in &decl.values {
        let Some(words) = v.words_of(&msg.values) else {
            continue;
        };
        for (k, &w) in words.iter().enumerate() {
            let cell = match v.ty {
                FswValueType::F64 => Cell::Num(f64::from_bits(w)),
                FswValueType::I64 => Cell::Text((w as i64).to_string()),
                FswValueType::Bool => Cell::Int(w),
            };
            out.push((format!("v_{}", v.element_name(k)), cell));
        }
    }
    out
}
