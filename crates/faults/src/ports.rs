//! The per-vehicle fault runtime: applies the configured faults at the sensor port (after the
//! bank samples) and at the actuator port (before the inputs reach the spacecraft). Built once;
//! every per-frame and per-step call allocates nothing, locks nothing and cannot fail.
//!
//! # Actuator modes, physically
//! Each transforms the effector's input (commanded + scheduled), then the model applies its own
//! limits as for any command:
//! - reaction wheel (input: motor torque u \[N·m\]):
//!   - `command_ignored`: u = 0;
//!   - `torque_limit`: u clipped to ±`fraction`·`max_torque_nm`;
//!   - `friction_scale` k: u + (k − 1) τ_f(Ω), τ_f the wheel's own friction law
//!     ([`ReactionWheel::friction_nm`]) at the speed Ω at the start of each step, held over the
//!     step: the bearing then drags with k τ_f. The extra drag passes the motor's torque clip;
//!   - `seized`: the bearing locks. Modelled as a brake, an internal torque between rotor and
//!     hub: u = −J_s Ω / h − τ_f(Ω) at the start of each step of length h, so that by (W3) of
//!     the wheel model Ω̇ ≈ −Ω/h and the rotor stops within a step (within the motor's torque
//!     limit, so a fast wheel stops in J_s |Ω| / `max_torque_nm`) and is then held at rest. The
//!     rotor's momentum goes to the hub through the reaction torque: the total angular momentum
//!     is conserved, as in a real seizure.
//! - thruster (input: on-time \[s\] or duty cycle): `stuck_on` = the whole frame (on-time = the
//!   frame period, duty = 1); `stuck_off` = 0; `thrust_scale` k: the input × k, so the impulse
//!   per frame scales by k (exactly for an ideal valve; the rise and tail-off lags apply to the
//!   shortened pulse as to any other);
//! - magnetorquer (input: dipole \[A·m²\]): `dead` = 0; `dipole_scale` k: the input × k (before the
//!   rod's ±`max_dipole_am2` clip).

use flexdyn_proto::{FaultEventMsg, FaultTarget, Header, AT_NEXT_TICK};

use super::modes::{sensor_value, Draws, FaultMode};
use super::{FaultSpec, Port, MAX_AXES, MAX_CHANNELS, MAX_LIVE_FAULTS};
use flexdyn_dynamics::effectors::reaction_wheel::{ReactionWheel, ReactionWheelParams};
use flexdyn_dynamics::{Spacecraft, State};
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_sensors::rng::NormalRng;
use flexdyn_sensors::SensorBank;

/// The vehicle a fault sits on: what an actuator fault needs of it.
#[derive(Debug, Clone, Copy)]
pub struct FaultHost<'a> {
    /// The spacecraft (its effector list and step).
    pub sc: &'a Spacecraft,
    /// \[ns\] the frame period (a thruster's full-open on-time, the fault events' boundaries).
    pub frame_ns: u64,
    /// The reaction wheels' parameters, in configuration order (a wheel fault's friction law
    /// and J_s).
    pub reaction_wheels: &'a [ReactionWheelParams],
}

/// What an actuator fault needs of its effector.
#[derive(Debug, Clone)]
enum Actuator {
    /// A reaction wheel: its model (for its friction law and J_s), the index of Ω in the state's
    /// effector states, and \[s\] the step.
    Wheel {
        wheel: Box<ReactionWheel>,
        omega_index: usize,
        step_s: f64,
    },
    /// A thruster: its full-open input (the frame period in s, or duty 1).
    Thruster { full_open: f64 },
    /// A magnetorquer.
    Magnetorquer,
}

/// One fault (configured or live) and its state.
#[derive(Debug, Clone)]
pub(super) struct Live {
    spec: FaultSpec,
    /// Its target as the wire carries it (built off the stepping path).
    target: FaultTarget,
    /// \[ns\] from here on it is cleared (a live `Clear`); `u64::MAX`: never.
    cleared_from_ns: u64,
    /// The activation in force at the last boundary noted ([`Faults::note_boundary`]).
    reported: Option<u64>,
    rng: NormalRng,
    /// The start \[ns\] of the activation in force at the last evaluation.
    on: Option<u64>,
    /// Healthy values at the activation's first sample (`stuck_current`).
    held: [[f64; MAX_AXES]; MAX_CHANNELS],
    held_set: bool,
    /// The actuator's offset in the flat input vector and what it needs.
    actuator: Option<(usize, Actuator)>,
}

/// A live fault request, checked and built off the stepping path ([`super::live`]), for
/// [`Faults::install`].
#[derive(Debug)]
pub struct LiveRequest {
    pub(super) kind: RequestKind,
    /// The boundary it applies at ([`AT_NEXT_TICK`]: the next one).
    pub(super) at_tick: u64,
}

#[derive(Debug)]
pub(super) enum RequestKind {
    Inject(Box<Live>),
    Clear(u32),
}

impl LiveRequest {
    /// The tick it applies at, given the boundary the next frame reaches, `next_tick`.
    pub fn applies_at(&self, next_tick: u64) -> u64 {
        if self.at_tick == AT_NEXT_TICK {
            next_tick
        } else {
            self.at_tick
        }
    }

    /// The fault a `Clear` names, `None` for an injection.
    pub fn clears(&self) -> Option<u32> {
        match self.kind {
            RequestKind::Clear(i) => Some(i),
            RequestKind::Inject(_) => None,
        }
    }
}

/// Why [`Faults::install`] refused a request (a code, so the physics thread can store it in an
/// atomic): index into [`INSTALL_REFUSALS`].
pub const REFUSED_LATE: u8 = 0;
/// See [`REFUSED_LATE`].
pub const REFUSED_NO_SLOT: u8 = 1;
/// See [`REFUSED_LATE`].
pub const REFUSED_NO_INDEX: u8 = 2;
/// The reasons of [`Faults::install`]'s refusals, by code.
pub const INSTALL_REFUSALS: [&str; 3] = [
    "its at_tick had already been stepped past when the server took it (lockstep: put it \
     before the answer to the tick before at_tick)",
    "no live-fault slot left (64 per run)",
    "a clear naming no fault (fault_index beyond the configured and live faults)",
];

/// A request's remains once installed: the injected fault's box (its contents moved into a
/// reserved slot), to be freed off the stepping path.
#[derive(Debug)]
pub struct Installed(#[allow(dead_code)] Option<Box<Live>>);

/// Fault events kept for the next frame that is filled: for one boundary, at most a clearance
/// and an activation per one-shot fault (the configured ones and every live slot), and for a
/// repeating fault the clearance of the activation reported last plus an activation and a
/// clearance for each activation that can begin within a frame (at most ⌊frame/period⌋ + 1).
fn event_capacity(live: &[Live], frame_ns: u64) -> usize {
    let configured: usize = live
        .iter()
        .map(|l| match l.spec.window.period_ns {
            Some(p) => 1 + 2 * (frame_ns / p.max(1) + 1) as usize,
            None => 2,
        })
        .sum();
    configured + 2 * MAX_LIVE_FAULTS
}

/// The faults of one vehicle.
#[derive(Debug, Clone, Default)]
pub struct Faults {
    live: Vec<Live>,
    any_actuator: bool,
    /// How many of `live` come from the configuration (the live ones follow).
    configured: usize,
    /// \[ns\] the frame period (live faults start at boundaries).
    frame_ns: u64,
    /// Activations and clearances noted and not yet taken ([`Self::take_events`]).
    events: Vec<FaultEventMsg>,
    /// Events dropped because `events` was full (frames whose telemetry was dropped).
    pub events_lost: u64,
    event_seq: u64,
    /// \[ns\] the boundary noted last (`None` before the first).
    last_boundary_ns: Option<u64>,
    active_count: u64,
    active_bits: [u64; 4],
}

impl Live {
    /// A configured fault's state, for a checkpoint (its spec, target and actuator are built
    /// from the configuration).
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        let Self {
            spec: _,
            target: _,
            cleared_from_ns,
            reported,
            rng,
            on,
            held,
            held_set,
            actuator: _,
        } = self;
        a.put(cleared_from_ns);
        a.put(reported);
        a.put(rng);
        a.put(on);
        for channel in held.iter_mut() {
            a.put(channel);
        }
        a.put(held_set);
    }

    /// After a restore at the boundary `at_ns` (`None`: before the first): a fault whose
    /// window opens after it has never been active in a run of this configuration, so it has
    /// drawn nothing and its generator is the one its own seed gives at t = 0. The checkpoint
    /// may hold the generator of another seed (a campaign's fork gives each run's random fault
    /// a seed of its own; the checkpoint was taken with the base's): its state is set to
    /// what a run of this configuration flown from t = 0 holds here. For a plain resume (the
    /// same seed) this is the state restored, unchanged.
    fn reseed_if_never_active(&mut self, at_ns: Option<u64>) {
        let opens_later = at_ns.is_none_or(|t| self.spec.window.start_ns > t);
        if opens_later && self.reported.is_none() && self.on.is_none() && !self.held_set {
            self.rng = NormalRng::new(self.spec.seed);
        }
    }

    /// A fault of `spec` on the vehicle `host`.
    pub(super) fn new(spec: FaultSpec, host: &FaultHost<'_>) -> Result<Self, ConfigError> {
        let actuator = match spec.port {
            // A link fault is applied by the server's command book (`super::link`).
            Port::Sensor { .. } | Port::Link { .. } => None,
            Port::Actuator { effector } => Some(actuator(host, effector)?),
        };
        Ok(Live {
            rng: NormalRng::new(spec.seed),
            target: FaultTarget::truncated(&spec.target),
            spec,
            cleared_from_ns: u64::MAX,
            reported: None,
            on: None,
            held: [[0.0; MAX_AXES]; MAX_CHANNELS],
            held_set: false,
            actuator,
        })
    }
}

impl Faults {
    /// The faults `specs` (resolved at load) on the vehicle `host`.
    pub fn new(specs: &[FaultSpec], host: &FaultHost<'_>) -> Result<Self, ConfigError> {
        let mut live = Vec::with_capacity(specs.len());
        for spec in specs {
            live.push(Live::new(spec.clone(), host)?);
        }
        Ok(Self {
            any_actuator: live.iter().any(|l| l.actuator.is_some()),
            configured: live.len(),
            frame_ns: host.frame_ns,
            live,
            ..Self::default()
        })
    }

    /// Reserves the live-fault slots ([`MAX_LIVE_FAULTS`]) and the event buffer, so that
    /// [`Self::install`] and [`Self::note_boundary`] never allocate (the server, at start).
    pub fn reserve_live(&mut self) {
        self.live.reserve_exact(MAX_LIVE_FAULTS);
        self.events = Vec::with_capacity(self.event_capacity());
    }

    /// Most events `Self::take_events` can hand out at once (size a frame's buffer with it).
    pub fn event_capacity(&self) -> usize {
        event_capacity(&self.live[..self.configured], self.frame_ns)
    }

    /// Installs a live request at the boundary the next frame reaches, `next_tick` (the fault
    /// is active from `at_tick`, the clearance takes effect there). Allocation- and lock-free:
    /// the fault moves into a reserved slot ([`Self::reserve_live`]) and its box is handed
    /// back to be freed elsewhere. Refused (with the reason's code, [`INSTALL_REFUSALS`]): a
    /// tick already stepped past, no slot left, a clear naming no fault.
    pub fn install(
        &mut self,
        req: LiveRequest,
        next_tick: u64,
    ) -> Result<Installed, (u8, Installed)> {
        let tick = req.applies_at(next_tick);
        let at_ns = tick.saturating_mul(self.frame_ns);
        match req.kind {
            RequestKind::Inject(b) => {
                if tick < next_tick {
                    return Err((REFUSED_LATE, Installed(Some(b))));
                }
                if self.live.len() >= self.configured + MAX_LIVE_FAULTS
                    || self.live.len() == self.live.capacity()
                {
                    return Err((REFUSED_NO_SLOT, Installed(Some(b))));
                }
                let mut b = b;
                let mut l = std::mem::replace(&mut *b, Live::placeholder());
                l.spec.window.start_ns = at_ns;
                self.any_actuator |= l.actuator.is_some();
                self.live.push(l);
                Ok(Installed(Some(b)))
            }
            RequestKind::Clear(i) => {
                if tick < next_tick {
                    return Err((REFUSED_LATE, Installed(None)));
                }
                let Some(l) = self.live.get_mut(i as usize) else {
                    return Err((REFUSED_NO_INDEX, Installed(None)));
                };
                l.cleared_from_ns = l.cleared_from_ns.min(at_ns);
                Ok(Installed(None))
            }
        }
    }

    /// Lists the faults' state for a checkpoint: each configured fault's activation, held
    /// values and generator, the events not yet taken and the counters. A fault injected live
    /// (by an operator command) is not yet part of a checkpoint: with one installed, a save
    /// fails with [`ArchiveError::Invalid`](flexdyn_kernel::archive::ArchiveError) naming the
    /// count (inject it from the configuration's `[[faults]]` instead). Not on the stepping path.
    pub fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        a.section("faults", |a| {
            let live = self.live.len() - self.configured;
            if live > 0 {
                a.invalid(
                    "faults injected live (a checkpoint cannot hold them yet)",
                    live as u64,
                );
                return;
            }
            a.expect_count("configured faults", self.configured);
            for l in &mut self.live[..self.configured] {
                l.archive(a);
            }
            let mut n = self.events.len();
            a.length("fault events not yet taken", &mut n, self.events.capacity());
            if a.failed() {
                return;
            }
            let mut bytes = Vec::new();
            let mut restored = Vec::with_capacity(n);
            for i in 0..n {
                bytes.clear();
                if let Some(e) = self.events.get(i) {
                    flexdyn_proto::encode_into(e, &mut bytes);
                }
                a.blob("a fault event", &mut bytes, flexdyn_proto::FAULT_EVENT_LEN);
                if !a.is_saving() && !a.failed() {
                    match flexdyn_proto::decode::<FaultEventMsg>(&bytes) {
                        Ok(e) => restored.push(e),
                        Err(_) => a.invalid("a fault event that does not decode", i as u64),
                    }
                }
            }
            if !a.is_saving() && !a.failed() {
                self.events.clear();
                self.events.extend(restored);
            }
            a.put(&mut self.events_lost);
            a.put(&mut self.event_seq);
            a.put(&mut self.last_boundary_ns);
            a.put(&mut self.active_count);
            a.put(&mut self.active_bits);
            if !a.is_saving() && !a.failed() {
                let at_ns = self.last_boundary_ns;
                for l in &mut self.live[..self.configured] {
                    l.reseed_if_never_active(at_ns);
                }
            }
        });
    }

    /// Notes each fault's state at the boundary of tick `k` (time `t_ns`): an event for every
    /// activation and clearance since the last boundary noted, in time order, and the active
    /// set. Every activation is reported, also one that began and ended between two boundaries
    /// (a window shorter than a frame, or a repeating fault's activations in between): its
    /// activation and its clearance come together, at the boundary after it. Allocation-free
    /// once [`Self::reserve_live`] has run (a full event buffer drops and counts).
    pub fn note_boundary(&mut self, k: u64, t_ns: u64) {
        let since = self.last_boundary_ns.replace(t_ns);
        self.active_count = 0;
        self.active_bits = [0; 4];
        for (i, l) in self.live.iter_mut().enumerate() {
            let now = l.state_at(t_ns);
            let mut emit = |active: bool, edge_ns: u64, l: &Live| {
                let ev = FaultEventMsg {
                    header: Header::new(0, k, t_ns, self.event_seq),
                    fault_index: i as u32,
                    source: l.spec.source,
                    mode: l.spec.mode.index() as u32,
                    active,
                    edge_ns,
                    axes: l.spec.axes,
                    params: l.spec.mode.params(),
                    target: l.target,
                };
                if self.events.len() < self.events.capacity() {
                    self.events.push(ev);
                    self.event_seq += 1;
                } else {
                    self.events_lost += 1;
                }
            };
            // The activation reported at the last boundary, if it has ended since.
            if let Some(prev) = l.reported.filter(|&prev| now != Some(prev)) {
                emit(false, l.end_of(prev, t_ns), l);
            }
            // An activation in force that began at or before the last boundary without being
            // reported there: the first boundary, or a live fault installed at the last one.
            let unreported = |s: u64| l.reported != Some(s) && since.is_none_or(|b| s <= b);
            if let Some(start) = now.filter(|&s| unreported(s)) {
                emit(true, start, l);
            }
            // Every activation that began since the last boundary (none at the first), and its
            // clearance if it has ended by now. A clearance stops the later ones.
            if let Some(b) = since {
                let cleared_from_ns = l.cleared_from_ns;
                for start in l.spec.window.starts_in(b, t_ns) {
                    if start >= cleared_from_ns {
                        break;
                    }
                    emit(true, start, l);
                    if now != Some(start) {
                        emit(false, l.end_of(start, t_ns), l);
                    }
                }
            }
            l.reported = now;
            if now.is_some() {
                self.active_count += 1;
                if let Some(w) = self.active_bits.get_mut(i / 64) {
                    *w |= 1 << (i % 64);
                }
            }
        }
    }

    /// Moves the events noted (oldest first) into `out` as far as its spare capacity goes,
    /// with `spacecraft_id` in their headers; the rest wait for the next call. Allocation-free.
    pub fn take_events_into(&mut self, spacecraft_id: u32, out: &mut Vec<FaultEventMsg>) {
        let n = self.events.len().min(out.capacity() - out.len());
        for mut e in self.events.drain(..n) {
            e.header.spacecraft_id = spacecraft_id;
            out.push(e);
        }
    }

    /// The faults active at the last boundary noted: their count and the bits of indices
    /// 0–255 (StatusMsg).
    pub fn active(&self) -> (u64, [u64; 4]) {
        (self.active_count, self.active_bits)
    }

    /// How many faults come from the configuration (live ones are indexed after them).
    pub fn configured(&self) -> usize {
        self.configured
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.live.is_empty()
    }

    /// Whether some fault sits at an actuator (the inputs then go through
    /// [`Self::at_input_port`] at every step).
    pub fn has_actuator_faults(&self) -> bool {
        self.any_actuator
    }

    /// The configured faults, in configuration order.
    pub fn specs(&self) -> impl Iterator<Item = &FaultSpec> {
        self.live.iter().map(|l| &l.spec)
    }

    /// The sensor port at `t_ns`: transforms the outputs of the sensors the bank just sampled
    /// (faults in configuration order; channels, then axes in order), drops those in `dropout`
    /// from the sampled list and marks those in `validity_off` invalid.
    pub fn at_sensor_port(&mut self, t_ns: u64, bank: &mut SensorBank) {
        for l in &mut self.live {
            let Port::Sensor { sensor, channel } = l.spec.port else {
                continue;
            };
            let Some(on) = l.activation(t_ns) else {
                continue;
            };
            if !bank.sampled().contains(&sensor) {
                continue;
            }
            let t_on_s = (t_ns - on) as f64 * 1e-9;
            let mode = l.spec.mode;
            match mode {
                FaultMode::Dropout => bank.unsample(sensor),
                FaultMode::ValidityOff => bank.sensor_mut(sensor).force_invalid(),
                _ => {
                    let s = bank.sensor_mut(sensor);
                    if mode == FaultMode::StuckCurrent && !l.held_set && !s.is_valid() {
                        // Nothing to hold yet (a GPS without a fix): published as it is.
                        continue;
                    }
                    let (first, end) = match channel {
                        Some(c) => (c, c + 1),
                        None => (0, s.fault_channels().len()),
                    };
                    for c in first..end.min(MAX_CHANNELS) {
                        for (a, v) in s.fault_channel(c).iter_mut().enumerate().take(MAX_AXES) {
                            if l.spec.axes != 0 && l.spec.axes & (1 << a) == 0 {
                                continue;
                            }
                            if !l.held_set {
                                l.held[c][a] = *v;
                            }
                            let d = Draws::take(&mode, &mut l.rng);
                            *v = sensor_value(&mode, *v, l.held[c][a], t_on_s, d);
                        }
                    }
                    l.held_set = true;
                }
            }
        }
    }

    /// The actuator port at `t_ns` with state `x`: transforms the flat inputs `u` (command +
    /// schedule, laid out by [`Spacecraft::effector_input_ranges`]) as the module docs say.
    #[inline]
    pub fn at_input_port(&mut self, t_ns: u64, x: &State, u: &mut [f64]) {
        for l in &mut self.live {
            if l.actuator.is_none() || l.activation(t_ns).is_none() {
                continue;
            }
            let Some((i, actuator)) = &l.actuator else {
                continue;
            };
            let Some(v) = u.get_mut(*i) else { continue };
            *v = actuator_input(&l.spec.mode, actuator, x, *v);
        }
    }
}

impl Live {
    /// An empty fault, left in a live request's box when its contents move into a slot.
    fn placeholder() -> Self {
        Live {
            spec: FaultSpec {
                target: String::new(),
                mode: FaultMode::Dropout,
                window: super::FaultWindow::from(u64::MAX),
                axes: 0,
                seed: 0,
                port: Port::Actuator { effector: 0 },
                source: flexdyn_proto::FaultSource::Live,
            },
            target: FaultTarget::default(),
            cleared_from_ns: 0,
            reported: None,
            rng: NormalRng::new(0),
            on: None,
            held: [[0.0; MAX_AXES]; MAX_CHANNELS],
            held_set: false,
            actuator: None,
        }
    }

    /// The activation in force at `t_ns` (its start), a clearance included; no side effects.
    #[inline]
    fn state_at(&self, t_ns: u64) -> Option<u64> {
        if t_ns >= self.cleared_from_ns {
            return None;
        }
        self.spec.window.activation_at(t_ns)
    }

    /// \[ns\] when the activation that began at `start_ns` ended, seen at `t_ns`: its
    /// duration's end or its clearance, whichever came first (at most `t_ns`).
    fn end_of(&self, start_ns: u64, t_ns: u64) -> u64 {
        let by_window = self
            .spec
            .window
            .duration_ns
            .map_or(u64::MAX, |d| start_ns.saturating_add(d));
        by_window.min(self.cleared_from_ns).min(t_ns)
    }

    /// The activation in force at `t_ns` (a new one forgets the held values).
    #[inline]
    fn activation(&mut self, t_ns: u64) -> Option<u64> {
        let on = self.state_at(t_ns);
        if on != self.on {
            self.on = on;
            self.held_set = false;
        }
        on
    }
}

/// The input of an actuator in `mode` given the healthy input `u` (module docs).
#[inline]
fn actuator_input(mode: &FaultMode, actuator: &Actuator, x: &State, u: f64) -> f64 {
    match (mode, actuator) {
        (
            FaultMode::FrictionScale { factor },
            Actuator::Wheel {
                wheel, omega_index, ..
            },
        ) => {
            let omega = x.effectors.get(*omega_index).copied().unwrap_or(0.0);
            u + (factor - 1.0) * wheel.friction_nm(omega)
        }
        (FaultMode::TorqueLimit { fraction }, Actuator::Wheel { wheel, .. }) => {
            let lim = fraction * wheel.params().max_torque_nm;
            u.clamp(-lim, lim)
        }
        (
            FaultMode::Seized,
            Actuator::Wheel {
                wheel,
                omega_index,
                step_s,
            },
        ) => {
            let omega = x.effectors.get(*omega_index).copied().unwrap_or(0.0);
            -wheel.params().j_s_kg_m2 * omega / step_s - wheel.friction_nm(omega)
        }
        (FaultMode::StuckOn, Actuator::Thruster { full_open }) => *full_open,
        (FaultMode::ThrustScale { factor }, Actuator::Thruster { .. })
        | (FaultMode::DipoleScale { factor }, Actuator::Magnetorquer) => u * factor,
        (FaultMode::CommandIgnored, _) | (FaultMode::StuckOff, _) | (FaultMode::Dead, _) => 0.0,
        _ => u,
    }
}

/// What a fault on effector `effector` needs (its kind was checked at load).
fn actuator(host: &FaultHost<'_>, effector: usize) -> Result<(usize, Actuator), ConfigError> {
    let sc = host.sc;
    use flexdyn_dynamics::dynamic_effectors::{magnetorquer, thruster};
    use flexdyn_dynamics::effectors::reaction_wheel;
    let input = sc.effector_input_ranges()[effector].start;
    let entry = sc
        .effector_entries()
        .nth(effector)
        .ok_or_else(|| ConfigError::Invalid {
            field: "faults".into(),
            problem: format!("no effector {effector}"),
            at: Default::default(),
        })?;
    let kind = entry.kind;
    let a = if kind == reaction_wheel::KIND {
        // Its index among the wheels (the configuration's order).
        let w = sc
            .effector_entries()
            .take(effector)
            .filter(|e| e.kind == reaction_wheel::KIND)
            .count();
        let path = format!("reaction_wheels[{w}]");
        Actuator::Wheel {
            wheel: Box::new(ReactionWheel::new(host.reaction_wheels[w].clone(), &path)?),
            omega_index: entry.state_range.start,
            step_s: sc.step_ns() as f64 * 1e-9,
        }
    } else if kind == thruster::KIND {
        Actuator::Thruster {
            full_open: if entry.input_names == thruster::ON_TIME_INPUT {
                host.frame_ns as f64 * 1e-9
            } else {
                1.0
            },
        }
    } else if kind == magnetorquer::KIND {
        Actuator::Magnetorquer
    } else {
        return Err(ConfigError::Invalid {
            field: "faults".into(),
            problem: format!("{} takes no faults", kind.name),
            at: Default::default(),
        });
    };
    Ok((input, a))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FaultWindow;

    /// A fault on sensor 0 with `window`, cleared from `cleared_from_ns`.
    fn fault(window: FaultWindow, cleared_from_ns: u64) -> Live {
        let mut l = Live::placeholder();
        l.spec.window = window;
        l.spec.port = Port::Sensor {
            sensor: 0,
            channel: None,
        };
        l.cleared_from_ns = cleared_from_ns;
        l
    }

    /// Every activation and clearance is reported at the first boundary at or after it, with
    /// its own edge, whatever the frame: checked against the edges found by looking at each
    /// fault every nanosecond.
    #[test]
    fn every_edge_is_reported_at_the_boundary_after_it() {
        let frame_ns = 10;
        let live = vec![
            // Begins and ends inside one frame.
            fault(
                FaultWindow {
                    start_ns: 12,
                    duration_ns: Some(3),
                    period_ns: None,
                },
                u64::MAX,
            ),
            // Repeats several times per frame.
            fault(
                FaultWindow {
                    start_ns: 1,
                    duration_ns: Some(1),
                    period_ns: Some(4),
                },
                u64::MAX,
            ),
            // Spans two boundaries.
            fault(
                FaultWindow {
                    start_ns: 5,
                    duration_ns: Some(20),
                    period_ns: None,
                },
                u64::MAX,
            ),
            // Repeats, and is cleared inside an activation at 23.
            fault(
                FaultWindow {
                    start_ns: 0,
                    duration_ns: Some(2),
                    period_ns: Some(3),
                },
                23,
            ),
            // Open from the first boundary on.
            fault(FaultWindow::from(0), u64::MAX),
        ];
        let mut faults = Faults {
            any_actuator: false,
            configured: live.len(),
            frame_ns,
            live,
            ..Faults::default()
        };
        faults.reserve_live();
        let end_tick = 5;
        // The oracle: each fault's edges, looked at every nanosecond, in the order the
        // boundaries report them (boundary, fault index, time).
        let mut want = Vec::new();
        for k in 0..=end_tick {
            let t = k * frame_ns;
            for (i, l) in faults.live.iter().enumerate() {
                if k == 0 {
                    if let Some(s) = l.state_at(0) {
                        want.push((k, i as u32, true, s));
                    }
                    continue;
                }
                for ns in t - frame_ns + 1..=t {
                    let (before, now) = (l.state_at(ns - 1), l.state_at(ns));
                    if before != now {
                        if before.is_some() {
                            want.push((k, i as u32, false, ns));
                        }
                        if let Some(s) = now {
                            want.push((k, i as u32, true, s));
                        }
                    }
                }
            }
        }
        let mut got = Vec::new();
        let mut out = Vec::with_capacity(faults.event_capacity());
        for k in 0..=end_tick {
            faults.note_boundary(k, k * frame_ns);
            faults.take_events_into(7, &mut out);
            for e in out.drain(..) {
                assert_eq!(e.header.tick, k);
                assert_eq!(e.header.spacecraft_id, 7);
                got.push((k, e.fault_index, e.active, e.edge_ns));
            }
        }
        assert_eq!(faults.events_lost, 0);
        assert_eq!(got, want);
        // The frame-long windows inside the frame are there: fault 0 at 12–15 and fault 1's
        // three activations of the first frame.
        assert!(got.contains(&(2, 0, true, 12)) && got.contains(&(2, 0, false, 15)));
        assert_eq!(got.iter().filter(|e| e.0 == 1 && e.1 == 1).count(), 6);
        // The active set at the last boundary (50 ns): only the open-ended fault 4.
        assert_eq!(faults.active(), (1, [1 << 4, 0, 0, 0]));
    }

    /// A checkpoint restored into a configuration whose faults have other seeds (a campaign's
    /// fork): a fault that opens after the checkpoint gets its own seed's generator, as a run
    /// of that configuration from t = 0 holds it; one that opened before keeps the
    /// checkpoint's generator (its draws are part of the flight); with the same seeds, a
    /// restore changes nothing.
    #[test]
    fn a_restored_fault_that_never_fired_draws_from_its_own_seed() {
        let faults_with = |seeds: [u64; 2]| {
            let mut live = vec![
                fault(FaultWindow::from(1_000), u64::MAX),
                fault(FaultWindow::from(100), u64::MAX),
            ];
            for (l, s) in live.iter_mut().zip(seeds) {
                l.spec.seed = s;
                l.rng = NormalRng::new(s);
            }
            let mut f = Faults {
                configured: live.len(),
                frame_ns: 100,
                live,
                ..Faults::default()
            };
            f.reserve_live();
            f
        };
        // The checkpoint's flight, to the boundary at 500 ns: fault 1 opened at 100 and drew.
        let mut saved = faults_with([1, 1]);
        for k in 0..=5 {
            saved.note_boundary(k, k * 100);
        }
        saved.live[1].on = Some(100);
        let drawn = saved.live[1].rng.next_u64();
        let mut bytes = Vec::new();
        let mut a = flexdyn_kernel::archive::Archive::saving(&mut bytes);
        saved.archive(&mut a);
        a.finish().unwrap();
        let restored = |seeds: [u64; 2]| {
            let mut f = faults_with(seeds);
            let mut a = flexdyn_kernel::archive::Archive::loading(&bytes);
            f.archive(&mut a);
            a.finish().unwrap();
            f
        };
        let next = |f: &mut Faults, i: usize| f.live[i].rng.next_u64();
        let checkpoint_next = saved.live[1].rng.clone().next_u64();
        assert_ne!(checkpoint_next, drawn);
        // Other seeds: fault 0 draws from its own; fault 1 continues the checkpoint's stream.
        let mut fork = restored([2, 2]);
        assert_eq!(next(&mut fork, 0), NormalRng::new(2).next_u64());
        assert_eq!(next(&mut fork, 1), checkpoint_next);
        // The same seeds: the state saved, both.
        let mut resumed = restored([1, 1]);
        assert_eq!(next(&mut resumed, 0), NormalRng::new(1).next_u64());
        assert_eq!(next(&mut resumed, 1), checkpoint_next);
    }
}
