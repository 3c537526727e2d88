//! `[[faults]]` against the vehicle this configuration builds: each entry is resolved by the
//! fault layer's [`flexdyn_faults::targets`] rules against the built spacecraft and sensor
//! bank, and a period shorter than the integration step is refused here. Live faults are checked
//! by the same rules through the [`LiveResolver`] this configuration builds.

use super::{ConfigError, SimConfig, SourceMap};
use flexdyn_dynamics::Spacecraft;
use flexdyn_faults::live::LiveResolver;
use flexdyn_faults::schema::RawFault;
use flexdyn_faults::targets::resolve_one;
use flexdyn_faults::FaultSpec;

/// Resolves every entry against `cfg`'s sensors and the spacecraft `sc` built from it.
pub(crate) fn resolve(
    raw: &[RawFault],
    cfg: &SimConfig,
    sc: &Spacecraft,
    map: &SourceMap,
) -> Result<Vec<FaultSpec>, ConfigError> {
    if raw.is_empty() {
        return Ok(Vec::new());
    }
    let bank = cfg.frame_sensor_bank(sc.state())?;
    let participants = file_participants(&cfg.server);
    raw.iter()
        .enumerate()
        .map(|(i, r)| {
            let spec = resolve_one(i, r, &bank, sc, participants.as_deref(), map)?;
            match spec.window.period_ns {
                // The stepping looks at a fault once per step: a shorter period would alias.
                Some(p) if p < cfg.step_ns => Err(map.invalid(
                    &format!("{}.period_s", r.path),
                    format!(
                        "must be at least the integration step ({} ns), got {p} ns: the \
                         stepping looks at a fault once per step",
                        cfg.step_ns
                    ),
                )),
                _ => Ok(spec),
            }
        })
        .collect()
}

/// `server.participants` as the file gives it (the server's default `[1]` when absent); `None`
/// if it is not a list of sender ids (the server's own schema reports that).
fn file_participants(server: &toml::Table) -> Option<Vec<u32>> {
    match server.get("participants") {
        None => Some(vec![1]),
        Some(toml::Value::Array(ids)) => ids
            .iter()
            .map(|v| v.as_integer().and_then(|i| u32::try_from(i).ok()))
            .collect(),
        Some(_) => None,
    }
}

impl SimConfig {
    /// The resolver of live faults (`flexdyn/<sc>/fault`) for this configuration's vehicle.
    pub fn live_fault_resolver(&self) -> Result<LiveResolver, ConfigError> {
        let sc = self.build_spacecraft()?;
        let bank = self.frame_sensor_bank(sc.state())?;
        Ok(LiveResolver::new(
            sc,
            bank,
            self.frame_ns,
            self.reaction_wheels.clone(),
        ))
    }
}
