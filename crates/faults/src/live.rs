//! Live faults (`flexdyn/<sc>/fault`, [`FaultCommandMsg`]): each command is checked by the very
//! resolution a `[[faults]]` entry gets at load ([`super::targets`]: the target exists, its kind
//! takes the mode, the parameters are the mode's and in range, the axes exist), on the thread
//! that receives it, and the fault is built there ([`LiveResolver::resolve`]); the physics side
//! only moves the ready-made fault into a slot reserved at start
//! ([`super::Faults::install`]). A bad command is an error with the reason, never a no-op.

use flexdyn_proto::{FaultAction, FaultCommandMsg};

use super::modes::MODES;
use super::ports::{FaultHost, Live, LiveRequest, RequestKind};
use super::schema::RawFault;
use flexdyn_dynamics::effectors::reaction_wheel::ReactionWheelParams;
use flexdyn_dynamics::Spacecraft;
use flexdyn_kernel::schema::source_map::SourceMap;
use flexdyn_sensors::SensorBank;

/// What a live fault is checked against: the vehicle's spacecraft and its sensors (built once,
/// when the server starts), its frame period and its wheels' parameters.
pub struct LiveResolver {
    sc: Spacecraft,
    bank: SensorBank,
    frame_ns: u64,
    reaction_wheels: Vec<ReactionWheelParams>,
}

impl std::fmt::Debug for LiveResolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("LiveResolver")
    }
}

impl LiveResolver {
    /// A resolver for the vehicle with spacecraft `sc`, sensors `bank`, frame period
    /// `frame_ns` and wheels `reaction_wheels` (configuration order).
    pub fn new(
        sc: Spacecraft,
        bank: SensorBank,
        frame_ns: u64,
        reaction_wheels: Vec<ReactionWheelParams>,
    ) -> Self {
        Self {
            sc,
            bank,
            frame_ns,
            reaction_wheels,
        }
    }

    /// The request `cmd` asks for, or why it cannot be applied (the problem, naming the
    /// command's field as `fault.<field>`).
    pub fn resolve(&self, cmd: &FaultCommandMsg) -> Result<LiveRequest, String> {
        if cmd.action == FaultAction::Clear {
            return Ok(LiveRequest {
                kind: RequestKind::Clear(cmd.fault_index),
                at_tick: cmd.at_tick,
            });
        }
        let target = cmd
            .target
            .as_str()
            .ok_or("fault.target: not UTF-8")?
            .to_owned();
        let Some(&(mode, keys)) = MODES.get(cmd.mode as usize) else {
            return Err(format!(
                "fault.mode: unknown mode code {} (0 to {})",
                cmd.mode,
                MODES.len() - 1
            ));
        };
        if let Some((k, v)) = cmd
            .params
            .iter()
            .enumerate()
            .skip(keys.len())
            .find(|(_, v)| **v != 0.0)
        {
            return Err(format!(
                "fault.params[{k}]: mode \"{mode}\" takes {} parameter(s), got {v} here",
                keys.len()
            ));
        }
        let raw = RawFault {
            path: "fault".into(),
            target,
            mode: mode.into(),
            start_s: 0.0,
            duration_s: None,
            period_s: None,
            axes: (cmd.axes != 0).then(|| {
                (0..32)
                    .filter(|a| cmd.axes >> a & 1 == 1)
                    .map(|a| f64::from(a + 1))
                    .collect()
            }),
            seed: Some(cmd.seed),
            mtbf_s: None,
            params: keys.iter().copied().zip(cmd.params).collect(),
        };
        // Participants: none, so a command-link target is refused below (resolution accepts
        // any sender id when it has no list).
        let mut spec =
            super::targets::resolve_one(0, &raw, &self.bank, &self.sc, None, &SourceMap::empty())
                .map_err(|e| e.to_string())?;
        if let super::Port::Link { .. } = spec.port {
            // The command book builds its link faults at start; a live one would never apply.
            return Err(format!(
                "fault.target: \"{}\": a command-link fault is configured in [[faults]], not \
                 injected live",
                spec.target
            ));
        }
        spec.window.duration_ns = (cmd.duration_ns != 0).then_some(cmd.duration_ns);
        spec.source = flexdyn_proto::FaultSource::Live;
        let host = FaultHost {
            sc: &self.sc,
            frame_ns: self.frame_ns,
            reaction_wheels: &self.reaction_wheels,
        };
        let live = Live::new(spec, &host).map_err(|e| e.to_string())?;
        Ok(LiveRequest {
            kind: RequestKind::Inject(Box::new(live)),
            at_tick: cmd.at_tick,
        })
    }
}
