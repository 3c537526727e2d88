//! The `[[faults]]` schema: one entry per fault. Keys and types are checked here; the target,
//! the mode and its parameters by `super::targets::resolve`, against the built spacecraft and
//! sensors.
//!
//! ```toml
//! [[faults]]
//! target = "imus.hub.gyro"   # <section>.<name>[.<channel>], or links.<sender id>
//! mode = "bias_step"         # see faults::modes
//! value = 0.01               # the mode's parameters
//! start_s = 2.0              # default 0
//! duration_s = 1.0           # default: to the end of the run
//! period_s = 5.0             # default: once
//! axes = [1, 3]              # 1-based; default: every axis
//! seed = 7                   # noise, spikes and mtbf_s; default: the entry's index
//! mtbf_s = 3.6e6             # random: the first activation at start_s + an exponential draw
//! ```

use flexdyn_kernel::schema::{SchemaError, TableReader};

/// The keys of one `[[faults]]` entry (`target` and `mode` are required): the general ones,
/// then `PARAM_KEYS`.
pub const KEYS: [&str; 16] = {
    let general = [
        "target",
        "mode",
        "start_s",
        "duration_s",
        "period_s",
        "axes",
        "seed",
        "mtbf_s",
    ];
    let mut keys = [""; 16];
    let mut i = 0;
    while i < keys.len() {
        keys[i] = if i < general.len() {
            general[i]
        } else {
            PARAM_KEYS[i - general.len()]
        };
        i += 1;
    }
    keys
};

/// The parameter keys (a mode takes some of them: [`super::modes::MODES`]).
pub(crate) const PARAM_KEYS: [&str; 8] = [
    "value",
    "rate_per_s",
    "factor",
    "sigma",
    "probability",
    "amplitude",
    "fraction",
    "frames",
];

/// One entry as written.
#[derive(Debug, Clone)]
pub struct RawFault {
    /// Its TOML path (`faults[2]`).
    pub path: String,
    pub(crate) target: String,
    pub(crate) mode: String,
    pub(crate) start_s: f64,
    pub(crate) duration_s: Option<f64>,
    pub(crate) period_s: Option<f64>,
    pub(crate) axes: Option<Vec<f64>>,
    pub(crate) seed: Option<u64>,
    pub(crate) mtbf_s: Option<f64>,
    /// The parameter keys present, with their values, in [`PARAM_KEYS`] order.
    pub(crate) params: Vec<(&'static str, f64)>,
}

/// Reads one entry.
pub fn read(t: &TableReader<'_, '_>) -> Result<RawFault, SchemaError> {
    let field = t.field("target");
    let path = field.strip_suffix(".target").unwrap_or(&field).to_string();
    let mut params = Vec::new();
    for key in PARAM_KEYS {
        if let Some(v) = t.opt_f64(key)? {
            params.push((key, v));
        }
    }
    Ok(RawFault {
        path,
        target: t.string("target")?,
        mode: t.string("mode")?,
        start_s: t.opt_f64("start_s")?.unwrap_or(0.0),
        duration_s: t.opt_f64("duration_s")?,
        period_s: t.opt_f64("period_s")?,
        axes: match t.get("axes") {
            Some(_) => Some(t.float_list("axes")?),
            None => None,
        },
        seed: match t.get("seed") {
            Some(_) => Some(t.int_in("seed", 0, i64::MAX)? as u64),
            None => None,
        },
        mtbf_s: t.opt_f64("mtbf_s")?,
        params,
    })
}
