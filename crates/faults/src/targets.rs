//! Load-time resolution of `[[faults]]`: each target must name a sensor (and optionally one of
//! its channels) or an actuator that exists, the mode must be one the kind states it takes, the
//! mode's parameters must be exactly its own and in range, and the window must be whole
//! nanoseconds. Every error names the entry's field; nothing is silently ignored. A command
//! link (`links.<sender id>`) must be one of the file's `server.participants` (default `[1]`);
//! the server checks again against its final participants (command-line overrides included).
//! The configuration (`flexdyn_vehicle::config`) calls [`resolve_one`] for each entry with the vehicle it
//! built.

use super::modes::{FaultMode, LINK_MODES, MODES, SENSOR_MODES, VALUE_MODES};
use super::schema::RawFault;
use super::window::FaultWindow;
use super::{FaultSpec, Port, MAX_AXES};
use flexdyn_dynamics::Spacecraft;
use flexdyn_kernel::schema::checks::whole_ns;
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::source_map::SourceMap;
use flexdyn_sensors::{SensorBank, KINDS as SENSOR_KINDS};

/// Resolves entry `index` (`r`) against the sensors `bank` and the spacecraft `sc`; a command
/// link must be one of `participants` (any, if `None`).
pub fn resolve_one(
    index: usize,
    r: &RawFault,
    bank: &SensorBank,
    sc: &Spacecraft,
    participants: Option<&[u32]>,
    map: &SourceMap,
) -> Result<FaultSpec, ConfigError> {
    let field = |key: &str| format!("{}.{key}", r.path);
    let bad = |key: &str, problem: String| map.invalid(&field(key), problem);

    // The mode and its parameters.
    let Some(&(mode_name, mode_keys)) = MODES.iter().find(|(n, _)| *n == r.mode) else {
        let names: Vec<&str> = MODES.iter().map(|(n, _)| *n).collect();
        return Err(bad(
            "mode",
            format!(
                "unknown mode \"{}\" (expected one of {})",
                r.mode,
                names.join(", ")
            ),
        ));
    };
    for (key, _) in &r.params {
        if !mode_keys.contains(key) {
            return Err(bad(
                key,
                format!(
                    "not a parameter of mode \"{mode_name}\" (it takes {})",
                    takes(mode_keys)
                ),
            ));
        }
    }
    if let Some(key) = mode_keys
        .iter()
        .find(|k| !r.params.iter().any(|(p, _)| p == *k))
    {
        return Err(bad(key, format!("missing: mode \"{mode_name}\" needs it")));
    }
    let value = |key: &str| {
        r.params
            .iter()
            .find(|(k, _)| *k == key)
            .map_or(0.0, |p| p.1)
    };
    let mode = FaultMode::from_name(mode_name, value)
        .ok_or_else(|| bad("mode", format!("unknown mode \"{mode_name}\"")))?;
    if let Some((key, problem)) = mode.check() {
        return Err(bad(key, format!("{problem} (got {})", value(key))));
    }

    // The window.
    let ns = |key: &str, s: f64| {
        whole_ns(s).ok_or_else(|| {
            bad(
                key,
                format!("{s} s is not a non-negative whole number of nanoseconds"),
            )
        })
    };
    let seed = r.seed.unwrap_or(index as u64);
    let mut start_ns = ns("start_s", r.start_s)?;
    if let Some(mtbf_s) = r.mtbf_s {
        if !(mtbf_s > 0.0 && mtbf_s.is_finite()) {
            return Err(bad(
                "mtbf_s",
                format!("must be finite and > 0 (got {mtbf_s})"),
            ));
        }
        start_ns = start_ns.saturating_add(failure_delay_ns(mtbf_s, seed));
    }
    let duration_ns = r.duration_s.map(|s| ns("duration_s", s)).transpose()?;
    let period_ns = r.period_s.map(|s| ns("period_s", s)).transpose()?;
    if duration_ns == Some(0) {
        return Err(bad("duration_s", "must be > 0".into()));
    }
    if let Some(p) = period_ns {
        match duration_ns {
            None => {
                return Err(bad(
                    "period_s",
                    "a repeating fault needs duration_s (each activation's length)".into(),
                ))
            }
            Some(d) if d >= p => {
                return Err(bad(
                    "period_s",
                    format!("must be longer than duration_s ({p} ns ≤ {d} ns)"),
                ))
            }
            _ => {}
        }
    }
    let window = FaultWindow {
        start_ns,
        duration_ns,
        period_ns,
    };

    // The target.
    let parts: Vec<&str> = r.target.split('.').collect();
    let (port, axis_count) =
        if let Some(kind) = SENSOR_KINDS.iter().find(|k| k.config_array == parts[0]) {
            let Some((sensor, s)) = parts.get(1).and_then(|name| {
                bank.sensors()
                    .iter()
                    .enumerate()
                    .find(|(_, s)| std::ptr::eq(s.kind(), *kind) && s.name() == *name)
            }) else {
                return Err(bad(
                    "target",
                    format!(
                        "\"{}\": no {} named \"{}\" in [[{}]]",
                        r.target,
                        kind.noun,
                        parts.get(1).copied().unwrap_or(""),
                        kind.config_array
                    ),
                ));
            };
            let channels = s.fault_channels();
            let channel = match parts.get(2) {
                None => None,
                Some(c) => Some(channels.iter().position(|n| n == c).ok_or_else(|| {
                    bad(
                        "target",
                        format!(
                            "\"{}\": {} has no channel \"{c}\" (its channels: {})",
                            r.target,
                            kind.a_noun,
                            takes(channels)
                        ),
                    )
                })?),
            };
            if parts.len() > 3 {
                return Err(bad(
                    "target",
                    format!("\"{}\": expected <section>.<name>[.<channel>]", r.target),
                ));
            }
            if !SENSOR_MODES.contains(&mode_name)
                || (mode == FaultMode::ValidityOff && !s.has_validity())
                || (VALUE_MODES.contains(&mode_name) && channels.is_empty())
            {
                return Err(not_applicable(
                    &bad,
                    mode_name,
                    kind.a_noun,
                    &kind_sensor_modes(s.as_ref()),
                ));
            }
            // The axes a value mode may select: the shortest selected channel's.
            let axis_count = match channel {
                Some(c) => s.fault_axes(c),
                None => (0..channels.len())
                    .map(|c| s.fault_axes(c))
                    .min()
                    .unwrap_or(0),
            };
            (Port::Sensor { sensor, channel }, axis_count)
        } else if let Some(kind) = flexdyn_dynamics::kinds::KINDS
            .iter()
            .find(|k| k.section == parts[0])
        {
            let name = parts.get(1).copied().unwrap_or("");
            let Some((effector, _)) = sc
                .effector_entries()
                .enumerate()
                .find(|(_, e)| e.kind == kind.effector && e.name == name)
            else {
                return Err(bad(
                    "target",
                    format!(
                        "\"{}\": no {} named \"{name}\" in [[{}]]",
                        r.target, kind.noun, kind.section
                    ),
                ));
            };
            if parts.len() > 2 {
                return Err(bad(
                    "target",
                    format!("\"{}\": an actuator target is <section>.<name>", r.target),
                ));
            }
            if !kind.fault_modes.contains(&mode_name) {
                return Err(not_applicable(&bad, mode_name, kind.noun, kind.fault_modes));
            }
            (Port::Actuator { effector }, 0)
        } else if parts[0] == super::link::SECTION {
            let name = parts.get(1).copied().unwrap_or("");
            let Some(sender_id) = super::link::sender_of(name).filter(|_| parts.len() == 2) else {
                return Err(bad(
                    "target",
                    format!(
                        "\"{}\": a command-link target is links.<sender id> (a participant's id, \
                         as server.participants lists it)",
                        r.target
                    ),
                ));
            };
            if let Some(ids) = participants.filter(|ids| !ids.contains(&sender_id)) {
                return Err(bad(
                    "target",
                    format!(
                        "\"{}\": participant {sender_id} is not in server.participants {ids:?}",
                        r.target
                    ),
                ));
            }
            if !LINK_MODES.contains(&mode_name) {
                return Err(not_applicable(
                    &bad,
                    mode_name,
                    "a command link",
                    LINK_MODES,
                ));
            }
            (Port::Link { sender_id }, 0)
        } else {
            let mut sections: Vec<&str> = SENSOR_KINDS.iter().map(|k| k.config_array).collect();
            sections.extend(
                flexdyn_dynamics::kinds::KINDS
                    .iter()
                    .filter(|k| !k.fault_modes.is_empty())
                    .map(|k| k.section),
            );
            sections.push(super::link::SECTION);
            return Err(bad(
                "target",
                format!(
                    "\"{}\": unknown section \"{}\" (expected one of {})",
                    r.target,
                    parts[0],
                    sections.join(", ")
                ),
            ));
        };

    // The axes.
    let mut axes = 0u32;
    if let Some(list) = &r.axes {
        if axis_count == 0 || !VALUE_MODES.contains(&mode_name) {
            return Err(bad(
                "axes",
                format!(
                    "mode \"{mode_name}\" on \"{}\" has no axes to select",
                    r.target
                ),
            ));
        }
        for (k, &a) in list.iter().enumerate() {
            if a.fract() != 0.0 || a < 1.0 || a > axis_count as f64 {
                return Err(bad(
                    &format!("axes[{k}]"),
                    format!("must be an integer from 1 to {axis_count} (got {a})"),
                ));
            }
            axes |= 1 << (a as u32 - 1);
        }
    }
    debug_assert!(axis_count <= MAX_AXES);
    Ok(FaultSpec {
        target: r.target.clone(),
        mode,
        window,
        axes,
        seed,
        port,
        source: if r.mtbf_s.is_some() {
            flexdyn_proto::FaultSource::Random
        } else {
            flexdyn_proto::FaultSource::Config
        },
    })
}

/// \[ns\] the time to failure of a component with mean time between failures `mtbf_s` \[s\]
/// (a constant failure rate λ = 1/MTBF, so the time to the first failure is exponential): the
/// inverse of its CDF, t = −MTBF · ln(1 − u), at u the first uniform of
/// [`NormalRng`](flexdyn_sensors::rng::NormalRng) seeded with `seed ⊕ 0x6d74_6266` (a stream of
/// its own, so `noise` and `spikes` keep theirs), with the portable `ln`: bit-identical for a
/// seed on every platform. Beyond u64 nanoseconds it saturates (never, in practice).
pub fn failure_delay_ns(mtbf_s: f64, seed: u64) -> u64 {
    let u = flexdyn_sensors::rng::NormalRng::new(seed ^ 0x6d74_6266).uniform01();
    let t_s = -mtbf_s * flexdyn_sensors::rng::ln_portable(1.0 - u);
    // `as` saturates; t_s ≥ 0 since 1 − u ∈ (0, 1].
    (t_s * 1e9).round() as u64
}

/// `a, b` or `nothing`.
fn takes(keys: &[&str]) -> String {
    if keys.is_empty() {
        "nothing".into()
    } else {
        keys.join(", ")
    }
}

/// The sensor modes `s` takes.
fn kind_sensor_modes(s: &dyn flexdyn_sensors::Sensor) -> Vec<&'static str> {
    SENSOR_MODES
        .iter()
        .copied()
        .filter(|m| {
            (*m != "validity_off" || s.has_validity())
                && (!VALUE_MODES.contains(m) || !s.fault_channels().is_empty())
        })
        .collect()
}

fn not_applicable(
    bad: &impl Fn(&str, String) -> ConfigError,
    mode: &str,
    noun: &str,
    modes: &[&str],
) -> ConfigError {
    bad(
        "mode",
        format!(
            "mode \"{mode}\" does not apply to {noun} (it takes {})",
            takes(modes)
        ),
    )
}
