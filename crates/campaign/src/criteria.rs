//! `[[criteria]]` of a campaign file: what each run is judged on, read and checked against the
//! base configuration (a flight-code stream, mode, event or value must be declared there, a
//! fault must be one of its `[[faults]]`), so a misspelt name is an error before any run.
//!
//! ```toml
//! [[criteria]]                    # the truth, state by state
//! name = "pointing"
//! quantity = "sigma_br"           # sigma_br | sigma_bn | omega | theta
//! statistic = "final"             # final | max | settling_time
//! below = 0.01
//!
//! [[criteria]]                    # the flight code's own telemetry (issue 37)
//! name = "detection_latency"
//! quantity = "fsw_event_latency"  # fsw_mode_entry | fsw_mode_time | fsw_event_time
//! stream = "acs"                  #   | fsw_event_latency | fsw_value
//! event = "wheel-failure"
//! fault = "faults[1]"
//! below = 1.0
//! ```
//!
//! Over a fleet a deputy is judged on `range`, `station_error` (with `station_h_m`) or
//! `chief_pointing` (with `axis_b`). The book: docs/guides/campaigns.md, "Criteria".

use std::path::Path;

use super::fleet::FleetBase;
use super::spec::{invalid_at, CampaignError};
use flexdyn_kernel::numfmt::Num;
use flexdyn_kernel::schema::reader::TableReader;
use flexdyn_kernel::schema::SchemaError;
use flexdyn_vehicle::config::{FswStreamDecl, FswValueType, SimConfig, SourceMap};

/// What a criterion measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// |σ_BR|, the attitude error to the campaign's `sigma_rn` (MRP, –).
    SigmaBr,
    /// |σ_BN| (–).
    SigmaBn,
    /// |ω_BN| (rad/s).
    Omega,
    /// The largest |θ1|, |θ2| over every panel pair (rad).
    Theta,
    /// A fleet deputy's range to its chief (m), from the RelativeStateMsg the server publishes.
    Range,
    /// A fleet deputy's station-keeping error (m): |r_dc_h − station_h_m|, its offset from the
    /// chief in the chief's Hill frame (RelativeStateMsg) against the target station.
    StationError,
    /// A fleet deputy's pointing at its chief (rad): the angle between its body axis `axis_b`
    /// and the direction from its centre of mass to the chief's.
    ChiefPointing,
    /// \[s\] the time of the flight code's first sample in `mode`.
    FswModeEntry,
    /// \[s\] the time the flight code spent in `mode` (each sample's mode holds until the next
    /// sample that names one, the last until the run's end).
    FswModeTime,
    /// \[s\] the time of the flight code's first `event`.
    FswEventTime,
    /// \[s\] from the first activation of `fault` to the flight code's first `event` at or after
    /// it (detection latency).
    FswEventLatency,
    /// A value the flight code published (an element, or a vector's length), sample by sample.
    FswValue,
}

impl Quantity {
    /// The name a campaign file gives it.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::SigmaBr => "sigma_br",
            Quantity::SigmaBn => "sigma_bn",
            Quantity::Omega => "omega",
            Quantity::Theta => "theta",
            Quantity::Range => "range",
            Quantity::StationError => "station_error",
            Quantity::ChiefPointing => "chief_pointing",
            Quantity::FswModeEntry => "fsw_mode_entry",
            Quantity::FswModeTime => "fsw_mode_time",
            Quantity::FswEventTime => "fsw_event_time",
            Quantity::FswEventLatency => "fsw_event_latency",
            Quantity::FswValue => "fsw_value",
        }
    }

    const ALL: [Quantity; 12] = [
        Quantity::SigmaBr,
        Quantity::SigmaBn,
        Quantity::Omega,
        Quantity::Theta,
        Quantity::Range,
        Quantity::StationError,
        Quantity::ChiefPointing,
        Quantity::FswModeEntry,
        Quantity::FswModeTime,
        Quantity::FswEventTime,
        Quantity::FswEventLatency,
        Quantity::FswValue,
    ];

    /// Read from the deputy's RelativeStateMsg stream (a fleet deputy's quantities).
    pub fn is_relative(self) -> bool {
        matches!(
            self,
            Quantity::Range | Quantity::StationError | Quantity::ChiefPointing
        )
    }

    /// Read from the flight code's recorded telemetry.
    pub fn is_fsw(self) -> bool {
        matches!(
            self,
            Quantity::FswModeEntry
                | Quantity::FswModeTime
                | Quantity::FswEventTime
                | Quantity::FswEventLatency
                | Quantity::FswValue
        )
    }

    /// One number per run (a time), not a series a statistic reduces.
    pub fn is_once(self) -> bool {
        self.is_fsw() && self != Quantity::FswValue
    }
}

/// How a criterion reduces the quantity over time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Statistic {
    /// The value at the last state.
    Final,
    /// The maximum over the states at or after `after_s`.
    Max,
    /// The time (s) after which the quantity stays below `threshold` to the end; the run's
    /// duration + 1 frame if it never settles.
    SettlingTime {
        /// The settling band.
        threshold: f64,
    },
    /// The quantity is one number per run already (the `fsw_` times): no `statistic` is given.
    Once,
}

/// What a flight-code criterion reads: a declared stream and one of its modes, events or values.
#[derive(Clone, Debug, PartialEq)]
pub struct FswRef {
    /// The stream's declaration, from the base configuration.
    pub decl: FswStreamDecl,
    /// The mode, event or value.
    pub target: FswTarget,
}

/// The mode, event or value of a [`FswRef`].
#[derive(Clone, Debug, PartialEq)]
pub enum FswTarget {
    /// A mode's index.
    Mode(u32),
    /// An event's index; with `fault`, the index of the `[[faults]]` entry whose activation
    /// starts the latency.
    Event {
        /// The event's index.
        index: u16,
        /// `faults[k]`: k.
        fault: Option<usize>,
    },
    /// A value: its index among the declared values, and one element (`name[k]`) or, for
    /// `None`, every element (one element's value itself; several: the vector's length).
    Value {
        /// The value's index in `decl.values`.
        index: usize,
        /// The element, if one is named.
        element: Option<usize>,
    },
}

/// One `[[criteria]]` entry: passes when the statistic is below `below`.
#[derive(Clone, Debug, PartialEq)]
pub struct Criterion {
    /// Unique name (a column of `summary.csv`).
    pub name: String,
    /// The quantity.
    pub quantity: Quantity,
    /// The reduction.
    pub statistic: Statistic,
    /// \[s\] the window starts here (for `max`; default 0).
    pub after_s: f64,
    /// Pass if the statistic is strictly below this.
    pub below: f64,
    /// The vehicle whose states it judges (a fleet campaign's; `None` otherwise).
    pub vehicle: Option<String>,
    /// What an `fsw_` quantity reads.
    pub fsw: Option<FswRef>,
    /// \[m\] `station_error`'s target station, chief's Hill frame components.
    pub station_h_m: Option<[f64; 3]>,
    /// `chief_pointing`'s body axis (unit length), B components.
    pub axis_b: Option<[f64; 3]>,
}

impl Criterion {
    /// A criterion on a quantity of the states, with none of the other quantities' fields.
    pub fn on_states(
        name: &str,
        quantity: Quantity,
        statistic: Statistic,
        after_s: f64,
        below: f64,
    ) -> Self {
        Criterion {
            name: name.to_owned(),
            quantity,
            statistic,
            after_s,
            below,
            vehicle: None,
            fsw: None,
            station_h_m: None,
            axis_b: None,
        }
    }

    /// The unit of the criterion's value (its figures' axis): seconds for a time, else the
    /// quantity's (`–` for an MRP norm; a flight-code value's declared unit).
    pub fn unit(&self) -> String {
        match (self.statistic, self.quantity) {
            (Statistic::SettlingTime { .. }, _) => "s".into(),
            (_, q) if q.is_once() => "s".into(),
            (_, Quantity::Omega) => "rad/s".into(),
            (_, Quantity::Theta | Quantity::ChiefPointing) => "rad".into(),
            (_, Quantity::Range | Quantity::StationError) => "m".into(),
            (_, Quantity::FswValue) => match &self.fsw {
                Some(FswRef {
                    decl,
                    target: FswTarget::Value { index, .. },
                }) => decl.values[*index].unit.clone(),
                _ => String::new(),
            },
            _ => "–".into(),
        }
    }
}

/// Keys every `[[criteria]]` entry may have.
const COMMON_KEYS: [&str; 7] = [
    "name",
    "quantity",
    "statistic",
    "after_s",
    "below",
    "threshold",
    "vehicle",
];

/// Keys of some quantities only (each quantity's own are in `read_one`).
const QUANTITY_KEYS: [&str; 7] = [
    "stream",
    "mode",
    "event",
    "value",
    "fault",
    "station_h_m",
    "axis_b",
];

/// Keys of a `[[criteria]]` entry.
pub(crate) fn criterion_keys() -> Vec<&'static str> {
    COMMON_KEYS.iter().chain(&QUANTITY_KEYS).copied().collect()
}

/// Reads a `[[criteria]]` entry's `vehicle` (its table and index).
pub(crate) type VehicleOf<'f> =
    dyn Fn(&TableReader<'_, '_>, usize) -> Result<Option<String>, CampaignError> + 'f;

/// What a criterion is read against.
pub(crate) struct Context<'a> {
    /// The campaign file's text and path (errors name it).
    pub source: &'a str,
    /// The campaign file.
    pub path: &'a Path,
    /// The fleet, over a fleet.
    pub fleet: Option<&'a FleetBase>,
    /// The base configuration, with one spacecraft.
    pub base: Option<&'a SimConfig>,
    /// \[s\] each run's duration.
    pub duration_s: f64,
}

impl Context<'_> {
    fn invalid(&self, field: &str, problem: String) -> CampaignError {
        invalid_at(self.source, self.path, field, problem)
    }

    fn schema(&self, source: SchemaError) -> CampaignError {
        CampaignError::Schema {
            path: self.path.to_owned(),
            source,
        }
    }

    /// The configuration of the vehicle a criterion judges (the base, with one spacecraft).
    fn config(&self, vehicle: Option<&str>) -> Option<&SimConfig> {
        match (self.fleet, vehicle) {
            (Some(f), Some(id)) => f
                .config
                .vehicles
                .iter()
                .find(|v| v.id == id)
                .map(|v| &v.cfg),
            _ => self.base,
        }
    }

    /// Where the configuration of `vehicle` comes from, for an error message.
    fn config_name(&self, vehicle: Option<&str>) -> String {
        match (self.fleet, vehicle) {
            (Some(f), Some(id)) => format!("vehicle {id:?} of {}", f.path.display()),
            _ => "the base configuration".into(),
        }
    }
}

/// Reads the `[[criteria]]` tables of a campaign; `vehicle_of` reads an entry's `vehicle`
/// (required over a fleet, refused otherwise).
pub(crate) fn read(
    tables: &[TableReader<'_, '_>],
    cx: &Context<'_>,
    vehicle_of: &VehicleOf<'_>,
) -> Result<Vec<Criterion>, CampaignError> {
    let mut criteria: Vec<Criterion> = Vec::new();
    for (i, t) in tables.iter().enumerate() {
        let c = read_one(t, i, cx, vehicle_of)?;
        if criteria.iter().any(|k| k.name == c.name) {
            return Err(cx.invalid(
                &format!("criteria[{i}].name"),
                format!("{:?} is used twice", c.name),
            ));
        }
        criteria.push(c);
    }
    Ok(criteria)
}

fn read_one(
    t: &TableReader<'_, '_>,
    i: usize,
    cx: &Context<'_>,
    vehicle_of: &VehicleOf<'_>,
) -> Result<Criterion, CampaignError> {
    let field = |k: &str| format!("criteria[{i}].{k}");
    let schema = |e| cx.schema(e);
    let name = t.string("name").map_err(schema)?;
    if name.is_empty() || name.contains([',', '"', '\n']) {
        return Err(cx.invalid(
            &field("name"),
            "must be non-empty, without commas, quotes or newlines".into(),
        ));
    }
    let vehicle = vehicle_of(t, i)?;
    let written = t.string("quantity").map_err(schema)?;
    let quantity = Quantity::ALL
        .into_iter()
        .find(|q| q.name() == written)
        .ok_or_else(|| {
            cx.invalid(
                &field("quantity"),
                format!(
                    "{written:?} is not one of {}",
                    Quantity::ALL
                        .iter()
                        .map(|q| format!("{:?}", q.name()))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )
        })?;
    // Each quantity's own keys; any other is refused rather than ignored.
    let own: &[&str] = match quantity {
        Quantity::StationError => &["station_h_m"],
        Quantity::ChiefPointing => &["axis_b"],
        Quantity::FswModeEntry | Quantity::FswModeTime => &["stream", "mode"],
        Quantity::FswEventTime => &["stream", "event"],
        Quantity::FswEventLatency => &["stream", "event", "fault"],
        Quantity::FswValue => &["stream", "value"],
        _ => &[],
    };
    for k in QUANTITY_KEYS {
        if t.get(k).is_some() && !own.contains(&k) {
            return Err(cx.invalid(&field(k), format!("does not apply to quantity {written:?}")));
        }
    }
    if quantity.is_relative() {
        // A deputy's quantities: only a vehicle given relative to a chief has them.
        let deputy = cx
            .fleet
            .zip(vehicle.as_deref())
            .and_then(|(f, id)| f.vehicle(id))
            .is_some_and(|v| v.chief.is_some());
        if !deputy {
            return Err(cx.invalid(
                &field("quantity"),
                format!(
                    "{written} is a fleet deputy's quantity relative to its chief, and {} has no \
                     chief ([vehicles.relative] in the fleet file)",
                    vehicle
                        .as_ref()
                        .map_or("a single spacecraft".to_owned(), |v| format!("{v:?}"))
                ),
            ));
        }
    }
    let station_h_m = match quantity {
        Quantity::StationError => Some(t.floats::<3>("station_h_m").map_err(schema)?),
        _ => None,
    };
    let axis_b = match quantity {
        Quantity::ChiefPointing => {
            let a = t.floats::<3>("axis_b").map_err(schema)?;
            let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            if n <= 1e-9 || !n.is_finite() {
                return Err(cx.invalid(
                    &field("axis_b"),
                    "must be a direction (a nonzero vector, B components)".into(),
                ));
            }
            Some([a[0] / n, a[1] / n, a[2] / n])
        }
        _ => None,
    };
    let fsw = if quantity.is_fsw() {
        Some(read_fsw(t, i, cx, quantity, vehicle.as_deref())?)
    } else {
        None
    };

    let stat = match t.get("statistic") {
        Some(_) => Some(t.string("statistic").map_err(schema)?),
        None => None,
    };
    let threshold = t.opt_f64("threshold").map_err(schema)?;
    let statistic = match (quantity.is_once(), stat.as_deref(), threshold) {
        (true, None, None) => Statistic::Once,
        (true, Some(_), _) => {
            return Err(cx.invalid(
                &field("statistic"),
                format!("does not apply to quantity {written:?}: it is one time per run already"),
            ))
        }
        (true, None, Some(_)) => {
            return Err(cx.invalid(
                &field("threshold"),
                format!("does not apply to quantity {written:?}"),
            ))
        }
        (false, None, _) => {
            return Err(CampaignError::Invalid {
                path: cx.path.to_owned(),
                field: field("statistic"),
                problem: format!(
                    "missing: quantity {written:?} needs one of \"final\", \"max\", \
                     \"settling_time\""
                ),
                at: SourceMap::locate(cx.source, &field("quantity")),
            })
        }
        (false, Some("final"), None) => Statistic::Final,
        (false, Some("max"), None) => Statistic::Max,
        (false, Some("settling_time"), Some(threshold)) if threshold > 0.0 => {
            Statistic::SettlingTime { threshold }
        }
        (false, Some("settling_time"), _) => {
            return Err(cx.invalid(
                &field("threshold"),
                "settling_time needs a threshold > 0".into(),
            ))
        }
        (false, Some(s @ ("final" | "max")), Some(_)) => {
            return Err(cx.invalid(
                &field("threshold"),
                format!("does not apply to statistic {s:?}"),
            ))
        }
        (false, Some(other), _) => {
            return Err(cx.invalid(
                &field("statistic"),
                format!("{other:?} is not one of \"final\", \"max\", \"settling_time\""),
            ))
        }
    };
    let after_s = t.opt_f64("after_s").map_err(schema)?;
    if after_s.is_some() && statistic != Statistic::Max {
        // Only `max` has a window; elsewhere the key would be silently ignored.
        return Err(cx.invalid(
            &field("after_s"),
            match stat.as_deref() {
                Some(st) => {
                    format!("does not apply to statistic {st:?} (only \"max\" has a window)")
                }
                None => format!(
                    "does not apply to quantity {written:?} (only statistic \"max\" has a window)"
                ),
            },
        ));
    }
    let after_s = after_s.unwrap_or(0.0);
    if !(0.0..=cx.duration_s).contains(&after_s) {
        return Err(cx.invalid(
            &field("after_s"),
            format!(
                "must be within 0..=duration_s ({}), got {}",
                Num(cx.duration_s),
                Num(after_s)
            ),
        ));
    }
    let below = t.f64("below").map_err(schema)?;
    // A signed flight-code value (an f64 or i64 element, not a vector's length) may be judged
    // against any bound; every other quantity is a magnitude or a time (≥ 0), and a criterion
    // passes when its statistic is strictly below `below`.
    let signed = !matches!(statistic, Statistic::SettlingTime { .. })
        && fsw.as_ref().is_some_and(|f| match f.target {
            FswTarget::Value { index, element } => {
                let v = &f.decl.values[index];
                v.ty != FswValueType::Bool && (element.is_some() || v.len == 1)
            }
            _ => false,
        });
    if below <= 0.0 && !signed {
        return Err(cx.invalid(
            &field("below"),
            format!(
                "must be > 0, got {}: this quantity is ≥ 0, so the criterion could never pass",
                Num(below)
            ),
        ));
    }
    Ok(Criterion {
        name,
        quantity,
        statistic,
        after_s,
        below,
        vehicle,
        fsw,
        station_h_m,
        axis_b,
    })
}

/// The stream and the mode, event or value an `fsw_` criterion names, checked against the
/// configuration's `[[fsw_streams]]` (and `[[faults]]` for a latency).
fn read_fsw(
    t: &TableReader<'_, '_>,
    i: usize,
    cx: &Context<'_>,
    quantity: Quantity,
    vehicle: Option<&str>,
) -> Result<FswRef, CampaignError> {
    let field = |k: &str| format!("criteria[{i}].{k}");
    let schema = |e| cx.schema(e);
    let cfg = cx.config(vehicle).ok_or_else(|| {
        cx.invalid(
            &field("vehicle"),
            "names no vehicle of the fleet whose configuration declares its stream".into(),
        )
    })?;
    let whose = cx.config_name(vehicle);
    let stream = t.string("stream").map_err(schema)?;
    let decl = cfg
        .fsw_streams
        .iter()
        .find(|d| d.name == stream)
        .cloned()
        .ok_or_else(|| {
            let declared: Vec<&str> = cfg.fsw_streams.iter().map(|d| d.name.as_str()).collect();
            cx.invalid(
                &field("stream"),
                if declared.is_empty() {
                    format!(
                        "{stream:?} is not declared: {whose} has no [[fsw_streams]] (the flight \
                         code's telemetry must be declared there to be recorded)"
                    )
                } else {
                    format!(
                        "{stream:?} is not a stream {whose} declares (its [[fsw_streams]]: {})",
                        declared.join(", ")
                    )
                },
            )
        })?;
    let listed = |names: Vec<&str>| {
        if names.is_empty() {
            "none".to_owned()
        } else {
            names.join(", ")
        }
    };
    let target = match quantity {
        Quantity::FswModeEntry | Quantity::FswModeTime => {
            let mode = t.string("mode").map_err(schema)?;
            let index = decl.mode_index(&mode).ok_or_else(|| {
                cx.invalid(
                    &field("mode"),
                    format!(
                        "{mode:?} is not a mode of stream {stream:?} (its modes: {})",
                        listed(decl.modes.iter().map(String::as_str).collect())
                    ),
                )
            })?;
            FswTarget::Mode(index)
        }
        Quantity::FswEventTime | Quantity::FswEventLatency => {
            let event = t.string("event").map_err(schema)?;
            let index = decl.event_index(&event).ok_or_else(|| {
                cx.invalid(
                    &field("event"),
                    format!(
                        "{event:?} is not an event of stream {stream:?} (its events: {})",
                        listed(decl.events.iter().map(|e| e.name.as_str()).collect())
                    ),
                )
            })?;
            let fault = if quantity == Quantity::FswEventLatency {
                let written = t.string("fault").map_err(schema)?;
                let k = written
                    .strip_prefix("faults[")
                    .and_then(|r| r.strip_suffix(']'))
                    .and_then(|k| k.parse::<usize>().ok())
                    .ok_or_else(|| {
                        cx.invalid(
                            &field("fault"),
                            format!("{written:?} is not of the form \"faults[k]\""),
                        )
                    })?;
                if k >= cfg.faults.len() {
                    return Err(cx.invalid(
                        &field("fault"),
                        format!(
                            "{written:?}: {whose} has {} [[faults]] entr{}",
                            cfg.faults.len(),
                            if cfg.faults.len() == 1 { "y" } else { "ies" }
                        ),
                    ));
                }
                Some(k)
            } else {
                None
            };
            FswTarget::Event { index, fault }
        }
        _ => {
            let written = t.string("value").map_err(schema)?;
            let (name, element) = match written.split_once('[') {
                Some((n, rest)) => {
                    let k = rest
                        .strip_suffix(']')
                        .and_then(|k| k.parse::<usize>().ok())
                        .ok_or_else(|| {
                            cx.invalid(
                                &field("value"),
                                format!("{written:?}: an element is written name[k]"),
                            )
                        })?;
                    (n, Some(k))
                }
                None => (written.as_str(), None),
            };
            let index = decl
                .values
                .iter()
                .position(|v| v.name == name)
                .ok_or_else(|| {
                    cx.invalid(
                        &field("value"),
                        format!(
                            "{name:?} is not a value of stream {stream:?} (its values: {})",
                            listed(decl.values.iter().map(|v| v.name.as_str()).collect())
                        ),
                    )
                })?;
            let len = decl.values[index].len;
            if let Some(k) = element.filter(|k| *k >= len) {
                return Err(cx.invalid(
                    &field("value"),
                    format!("{written:?}: element {k} of a value of {len}"),
                ));
            }
            FswTarget::Value { index, element }
        }
    };
    Ok(FswRef { decl, target })
}
