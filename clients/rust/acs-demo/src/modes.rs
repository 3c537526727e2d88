//! The ACS mode manager: which control mode runs, from what the sensors say. Pure logic: it
//! takes one [`Observation`] per tick and returns the mode; no I/O, no clock of its own (time is
//! the tick's simulation time in nanoseconds), so a lockstep run is reproducible bit for bit.
//!
//! The sequence after separation (issue 20, §5):
//!
//! ```text
//!  Detumble ──|ω| < 0.1°/s──▶ SunAcquisition ──Sun ≤ 5° off the panel normal──▶ FinePointing
//!     ▲                         (waits in eclipse)                               │  ▲
//!     │                                                      pointing settled ──┘  │ unloading
//!     └── |ω| > 0.5°/s (from any other mode: the safe-mode fallback) ─ MomentumManagement ┘ done
//! ```
//!
//! - **Detumble**: B-dot on the magnetometer and the rods, until the gyro rate is below
//!   `detumble_exit_rate_rad_s`.
//! - **SunAcquisition**: coarse sun sensors, gyro and wheels, until the Sun is within
//!   `sun_exit_angle_rad` of the panel normal and the rate is still below the detumble exit
//!   rate. In eclipse the sensors see nothing: the exit condition cannot hold, so it waits (the
//!   law only damps the rate).
//! - **FinePointing**: star tracker, gyro and wheels to the target; once the pointing error has
//!   stayed below `fine_settled_error_rad`, momentum management starts (once per run).
//! - **MomentumManagement**: fine pointing continues while the rods unload the wheels, for
//!   `unload_duration_ns` (at least one orbit: the field must turn through every direction for
//!   the cross-product law to reach every axis), then back to FinePointing.
//!
//! **No chatter.** Every exit condition must hold *continuously* for `dwell_ns` (a noisy
//! sample that breaks it restarts the count), and the only way back (the fallback to
//! Detumble) needs a rate five times the detumble exit rate, also held for `dwell_ns`: a
//! hysteresis band of 0.1…0.5°/s in which no transition is possible either way. Every
//! transition is kept with its tick ([`ModeManager::transitions`]).

use nalgebra::Vector3;

/// The control modes, in sequence order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Mode {
    /// B-dot detumbling with the magnetorquers.
    Detumble,
    /// Turning the panel normal onto the Sun with the wheels.
    SunAcquisition,
    /// Star-tracker pointing with the wheels.
    FinePointing,
    /// Fine pointing while the magnetorquers unload the wheels.
    MomentumManagement,
}

impl Mode {
    /// Every mode, in sequence order.
    pub const ALL: [Mode; 4] = [
        Mode::Detumble,
        Mode::SunAcquisition,
        Mode::FinePointing,
        Mode::MomentumManagement,
    ];

    /// The mode's name in logs (kebab case).
    pub fn name(self) -> &'static str {
        match self {
            Mode::Detumble => "detumble",
            Mode::SunAcquisition => "sun-acquisition",
            Mode::FinePointing => "fine-pointing",
            Mode::MomentumManagement => "momentum-management",
        }
    }
}

/// Thresholds and times of the mode logic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeSettings {
    /// \[rad/s\] Detumble ends below this gyro rate (0.1°/s).
    pub detumble_exit_rate_rad_s: f64,
    /// \[rad/s\] above this rate any other mode falls back to Detumble (0.5°/s).
    pub fallback_rate_rad_s: f64,
    /// \[rad\] SunAcquisition ends with the Sun this close to the panel normal (5°).
    pub sun_exit_angle_rad: f64,
    /// \[rad\] FinePointing counts as settled (momentum management may start) below this
    /// pointing error.
    pub fine_settled_error_rad: f64,
    /// \[ns\] how long MomentumManagement unloads.
    pub unload_duration_ns: u64,
    /// \[ns\] how long an exit (or fallback) condition must hold without a break.
    pub dwell_ns: u64,
}

impl Default for ModeSettings {
    /// The issue's thresholds; 10 s of dwell (100 samples of a 10 Hz loop, against gyro noise of
    /// ~0.01°/s per sample in `scenarios/acs_full.toml`); 0.05° settled; one 95-minute orbit of
    /// unloading.
    fn default() -> Self {
        Self {
            detumble_exit_rate_rad_s: 0.1_f64.to_radians(),
            fallback_rate_rad_s: 0.5_f64.to_radians(),
            sun_exit_angle_rad: 5.0_f64.to_radians(),
            fine_settled_error_rad: 0.05_f64.to_radians(),
            unload_duration_ns: 5_700_000_000_000,
            dwell_ns: 10_000_000_000,
        }
    }
}

/// What the mode logic reads at one tick (estimates from the sensors, never truth).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observation {
    /// The tick.
    pub tick: u64,
    /// \[ns\] its simulation time.
    pub t_ns: u64,
    /// \[rad/s\] the gyro rate ω_BN, B components.
    pub omega_bn_b_rad_s: Vector3<f64>,
    /// \[rad\] the angle between the panel normal and the Sun (coarse sun sensors); `None` when
    /// no sensor sees the Sun (eclipse).
    pub sun_angle_rad: Option<f64>,
    /// \[rad\] the fine-pointing error (star tracker); `None` without an attitude yet.
    pub pointing_error_rad: Option<f64>,
}

/// One mode change.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Transition {
    /// The tick at which the new mode starts commanding.
    pub tick: u64,
    /// \[ns\] its simulation time.
    pub t_ns: u64,
    /// The mode left.
    pub from: Mode,
    /// The mode entered.
    pub to: Mode,
}

/// The mode state machine (see the module docs).
#[derive(Clone, Debug)]
pub struct ModeManager {
    settings: ModeSettings,
    mode: Mode,
    /// \[ns\] when the current mode started.
    entered_ns: u64,
    /// \[ns\] since when the current mode's exit condition has held.
    exit_since_ns: Option<u64>,
    /// \[ns\] since when the fallback condition has held.
    fallback_since_ns: Option<u64>,
    /// Whether a momentum-management pass has completed.
    unloaded: bool,
    transitions: Vec<Transition>,
}

impl ModeManager {
    /// Starts in Detumble (after separation) at `t_ns`.
    pub fn new(settings: ModeSettings, t_ns: u64) -> Self {
        Self {
            settings,
            mode: Mode::Detumble,
            entered_ns: t_ns,
            exit_since_ns: None,
            fallback_since_ns: None,
            unloaded: false,
            transitions: Vec::new(),
        }
    }

    /// The current mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Every transition so far, in order.
    pub fn transitions(&self) -> &[Transition] {
        &self.transitions
    }

    /// The settings.
    pub fn settings(&self) -> &ModeSettings {
        &self.settings
    }

    /// Whether `since` (the start of an unbroken run of a condition, updated here) has lasted
    /// the dwell at `t_ns`.
    fn held(since: &mut Option<u64>, holds: bool, t_ns: u64, dwell_ns: u64) -> bool {
        if !holds {
            *since = None;
            return false;
        }
        let start = *since.get_or_insert(t_ns);
        t_ns.saturating_sub(start) >= dwell_ns
    }

    /// Takes this tick's observation; returns the mode to command at this tick, and records a
    /// transition when it changed.
    pub fn update(&mut self, obs: &Observation) -> Mode {
        let s = self.settings;
        let rate = obs.omega_bn_b_rad_s.norm();
        let next = if self.mode != Mode::Detumble
            && Self::held(
                &mut self.fallback_since_ns,
                rate > s.fallback_rate_rad_s,
                obs.t_ns,
                s.dwell_ns,
            ) {
            Some(Mode::Detumble)
        } else {
            let (exit, to) = match self.mode {
                Mode::Detumble => (rate < s.detumble_exit_rate_rad_s, Mode::SunAcquisition),
                Mode::SunAcquisition => (
                    rate < s.detumble_exit_rate_rad_s
                        && obs.sun_angle_rad.is_some_and(|a| a <= s.sun_exit_angle_rad),
                    Mode::FinePointing,
                ),
                Mode::FinePointing => (
                    !self.unloaded
                        && obs
                            .pointing_error_rad
                            .is_some_and(|e| e < s.fine_settled_error_rad),
                    Mode::MomentumManagement,
                ),
                Mode::MomentumManagement => (
                    obs.t_ns.saturating_sub(self.entered_ns) >= s.unload_duration_ns,
                    Mode::FinePointing,
                ),
            };
            // Momentum management has a duration, not a condition to confirm.
            let dwell = if self.mode == Mode::MomentumManagement {
                0
            } else {
                s.dwell_ns
            };
            Self::held(&mut self.exit_since_ns, exit, obs.t_ns, dwell).then_some(to)
        };
        if let Some(to) = next {
            if self.mode == Mode::MomentumManagement {
                self.unloaded = true;
            }
            self.transitions.push(Transition {
                tick: obs.tick,
                t_ns: obs.t_ns,
                from: self.mode,
                to,
            });
            self.mode = to;
            self.entered_ns = obs.t_ns;
            self.exit_since_ns = None;
            self.fallback_since_ns = None;
        }
        self.mode
    }

    /// \[ns\] the time spent in each mode (in [`Mode::ALL`] order) from the start `t0_ns` to
    /// `t_end_ns`, from the transitions.
    pub fn time_in_modes_ns(&self, t0_ns: u64, t_end_ns: u64) -> [u64; 4] {
        let mut out = [0u64; 4];
        let mut mode = Mode::Detumble;
        let mut since = t0_ns;
        for tr in &self.transitions {
            out[mode as usize] += tr.t_ns.saturating_sub(since);
            mode = tr.to;
            since = tr.t_ns;
        }
        out[mode as usize] += t_end_ns.saturating_sub(since);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DWELL_NS: u64 = 10_000_000_000;
    const FRAME_NS: u64 = 100_000_000;

    fn settings() -> ModeSettings {
        ModeSettings {
            unload_duration_ns: 600_000_000_000,
            ..ModeSettings::default()
        }
    }

    fn obs(tick: u64, rate_deg_s: f64, sun_deg: Option<f64>, err_deg: Option<f64>) -> Observation {
        Observation {
            tick,
            t_ns: tick * FRAME_NS,
            omega_bn_b_rad_s: Vector3::new(0.0, 0.0, rate_deg_s.to_radians()),
            sun_angle_rad: sun_deg.map(f64::to_radians),
            pointing_error_rad: err_deg.map(f64::to_radians),
        }
    }

    /// Feeds `n` ticks of the same observation from `*tick` on; returns the modes.
    fn feed(
        m: &mut ModeManager,
        tick: &mut u64,
        n: u64,
        rate: f64,
        sun: Option<f64>,
        err: Option<f64>,
    ) -> Vec<Mode> {
        (0..n)
            .map(|_| {
                let mode = m.update(&obs(*tick, rate, sun, err));
                *tick += 1;
                mode
            })
            .collect()
    }

    /// The whole sequence, each exit after exactly the dwell (100 ticks of 0.1 s after the
    /// condition first holds), the eclipse wait, and the unloading pass with its duration.
    #[test]
    fn the_sequence_runs_in_order_with_dwell_and_eclipse_wait() {
        // The default dwell is the 100 ticks this test counts.
        assert_eq!(settings().dwell_ns, DWELL_NS);
        assert_eq!(DWELL_NS / FRAME_NS, 100);
        let mut m = ModeManager::new(settings(), 0);
        let mut t = 0;
        // Tumbling at 3°/s: stays.
        assert!(feed(&mut m, &mut t, 500, 3.0, None, None)
            .iter()
            .all(|&x| x == Mode::Detumble));
        // Below 0.1°/s from tick 500: the transition comes at tick 600 (10 s later).
        feed(&mut m, &mut t, 100, 0.09, None, None);
        assert_eq!(m.mode(), Mode::Detumble);
        feed(&mut m, &mut t, 1, 0.09, None, None);
        assert_eq!(m.mode(), Mode::SunAcquisition);
        assert_eq!(
            m.transitions()[0],
            Transition {
                tick: 600,
                t_ns: 600 * FRAME_NS,
                from: Mode::Detumble,
                to: Mode::SunAcquisition
            }
        );
        // Eclipse: no Sun, no exit however long it lasts.
        feed(&mut m, &mut t, 3000, 0.05, None, None);
        assert_eq!(m.mode(), Mode::SunAcquisition);
        // Sunlit but 20° off, then 4° off but still turning too fast (0.2°/s), then settled.
        feed(&mut m, &mut t, 300, 0.05, Some(20.0), None);
        feed(&mut m, &mut t, 300, 0.2, Some(4.0), None);
        assert_eq!(m.mode(), Mode::SunAcquisition);
        let start = t;
        feed(&mut m, &mut t, 101, 0.05, Some(4.0), None);
        assert_eq!(m.mode(), Mode::FinePointing);
        assert_eq!(m.transitions()[1].tick, start + 100);
        // Fine pointing: no attitude yet, then settling, then settled → unloading.
        feed(&mut m, &mut t, 50, 0.01, Some(1.0), None);
        feed(&mut m, &mut t, 200, 0.01, Some(1.0), Some(1.0));
        assert_eq!(m.mode(), Mode::FinePointing);
        feed(&mut m, &mut t, 101, 0.01, Some(1.0), Some(0.01));
        assert_eq!(m.mode(), Mode::MomentumManagement);
        let unload_start = m.transitions()[2].t_ns;
        // Unloading lasts its duration exactly, then fine pointing for good.
        feed(&mut m, &mut t, 5999, 0.01, Some(1.0), Some(0.01));
        assert_eq!(m.mode(), Mode::MomentumManagement);
        feed(&mut m, &mut t, 1, 0.01, Some(1.0), Some(0.01));
        assert_eq!(m.mode(), Mode::FinePointing);
        let back = m.transitions()[3];
        assert_eq!(back.t_ns - unload_start, settings().unload_duration_ns);
        feed(&mut m, &mut t, 5000, 0.01, Some(1.0), Some(0.01));
        assert_eq!(m.mode(), Mode::FinePointing, "one unloading pass per run");
        assert_eq!(m.transitions().len(), 4);
        // The time in each mode adds up to the run.
        let times = m.time_in_modes_ns(0, t * FRAME_NS);
        assert_eq!(times.iter().sum::<u64>(), t * FRAME_NS);
        assert_eq!(times[0], 600 * FRAME_NS);
        assert_eq!(times[3], settings().unload_duration_ns);
    }

    /// A rate that dithers around the exit threshold (noise) never holds for the dwell, so
    /// nothing happens; nor does a rate inside the hysteresis band ever send a mode back.
    #[test]
    fn noise_around_a_threshold_cannot_make_it_chatter() {
        let mut m = ModeManager::new(settings(), 0);
        let mut t = 0;
        for _ in 0..200 {
            // 99 ticks under, one over: the condition never holds 100 ticks in a row.
            feed(&mut m, &mut t, 99, 0.09, None, None);
            feed(&mut m, &mut t, 1, 0.11, None, None);
        }
        assert_eq!(m.mode(), Mode::Detumble);
        assert!(m.transitions().is_empty());
        feed(&mut m, &mut t, 101, 0.09, None, None);
        assert_eq!(m.mode(), Mode::SunAcquisition);
        // Inside the band (0.1…0.5°/s): neither exit nor fallback, however long.
        feed(&mut m, &mut t, 10_000, 0.4, Some(1.0), None);
        assert_eq!(m.mode(), Mode::SunAcquisition);
        // Short spikes above the fallback rate do not count either.
        for _ in 0..50 {
            feed(&mut m, &mut t, 90, 0.6, Some(1.0), None);
            feed(&mut m, &mut t, 10, 0.3, Some(1.0), None);
        }
        assert_eq!(m.mode(), Mode::SunAcquisition);
        assert_eq!(m.transitions().len(), 1);
    }

    /// A real tumble (above 0.5°/s for the dwell) sends any mode back to Detumble, which then
    /// runs the sequence again.
    #[test]
    fn a_tumble_falls_back_to_detumble() {
        let mut m = ModeManager::new(settings(), 0);
        let mut t = 0;
        feed(&mut m, &mut t, 101, 0.05, None, None);
        feed(&mut m, &mut t, 101, 0.05, Some(1.0), None);
        assert_eq!(m.mode(), Mode::FinePointing);
        feed(&mut m, &mut t, 100, 1.0, Some(1.0), Some(10.0));
        assert_eq!(m.mode(), Mode::FinePointing);
        feed(&mut m, &mut t, 1, 1.0, Some(1.0), Some(10.0));
        assert_eq!(m.mode(), Mode::Detumble);
        let last = m.transitions().last().unwrap();
        assert_eq!((last.from, last.to), (Mode::FinePointing, Mode::Detumble));
        feed(&mut m, &mut t, 101, 0.05, None, None);
        assert_eq!(m.mode(), Mode::SunAcquisition);
    }
}
