//! The environment of a run, built once from the configuration's `[environment]` table
//! ([`schema`]), and the [`EnvironmentModel`] that fills an [`EnvironmentSample`] from the
//! simulation time and the hub's position and velocity.
//!
//! One update runs:
//! 1. the shared, position-independent part that the models on need ([`part::Needs`]): the
//!    epoch's time scales at `t_sim_ns` ([`crate::epoch`]), the Earth's orientation N → E
//!    ([`crate::earth_rotation`]), the Sun's and the Moon's geocentric positions
//!    ([`crate::ephemeris`]), shared by a world's vehicles ([`crate::common`]); then B's
//!    position in the Earth-fixed frame;
//! 2. every registered model that is on ([`part`]; the registry is in `crate::lib`), each
//!    filling its fields of the sample from those inputs: the magnetic field
//!    ([`crate::magnetic`]), the Sun and the Moon relative to B ([`crate::ephemeris`]), the
//!    shadow factor ([`crate::shadow`]), the density and the wind ([`crate::atmosphere`]), the
//!    Earth's visible cap for albedo ([`crate::albedo`]).
//!
//! [`EnvironmentModel::fill`] allocates nothing, locks nothing and returns no `Result`: every
//! parameter was checked when the model was built. [`EnvironmentModel::update_if_due`] runs it at
//! the configured rate and holds the sample between updates (zero-order hold: see
//! docs/models/world-environment.md for the error that costs). Each update after the first is evaluated for the
//! position predicted from the update before, so that [`EnvironmentModel::offload`] can move the
//! evaluation to a worker thread without changing a bit ([`super::prefetch`]).

pub mod constants;
pub mod part;
pub mod schema;

use std::sync::{Arc, OnceLock};

use nalgebra::Vector3;

use super::cannonball::Cannonball;
use super::common::{Common, CommonCache, Parts};
use super::earth_rotation::{EarthOrientation, EarthOrientationModel};
use super::ephemeris::{moon_position_n_m, sun_position_n_m};
use super::epoch::SimEpoch;
use super::facets::Facet;
use super::magnetic::MagneticError;
use super::prefetch::{Prefetcher, Request};
use super::{BuiltModels, EnvironmentSample, ModelSettings};
use part::At;

pub use super::atmosphere::AtmosphereSetting;
pub use super::magnetic::MagneticSetting;

/// The validated `[environment]` table.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentSettings {
    /// \[ns\] interval between sample updates (a whole number of RK4 steps).
    pub update_ns: u64,
    /// \[Hz\] the update rate as configured.
    pub update_hz: f64,
    /// \[Hz\] `telemetry_rate_hz`: the rate of the environment message (`tlm/env`) and of
    /// `simulate`'s environment columns; `None` (the default): neither.
    pub telemetry_rate_hz: Option<f64>,
    /// `telemetry_rate_hz` as a whole number of frames (set by the configuration, which knows
    /// the frame rate).
    pub telemetry_every_frames: Option<u64>,
    /// Every registered model's settings (`crate::lib`'s registry): the magnetic field, the
    /// Sun and the Moon, the shadow, the atmosphere, the albedo.
    pub models: ModelSettings,
    /// The model of the Earth's orientation, `[E N]` (IAU 2006/2000B by default).
    pub earth_rotation: EarthOrientationModel,
    /// The vehicle's flat plates (`[[environment.facets]]`), B frame.
    pub facets: Vec<Facet>,
    /// Dynamic effector: gravity-gradient torque.
    pub gravity_gradient: bool,
    /// Dynamic effector: drag on the facets.
    pub drag: bool,
    /// Dynamic effector: solar radiation pressure, on the facets or on a cannonball.
    pub solar_pressure: bool,
    /// `None`: the facets (the default); `Some`: a cannonball.
    pub cannonball: Option<Cannonball>,
    /// \[W/m²\] total solar irradiance at 1 AU (default
    /// [`crate::facets::SOLAR_IRRADIANCE_1AU_W_M2`]).
    pub solar_irradiance_1au_w_m2: f64,
    /// Dynamic effector: a residual dipole \[A·m²\], B components.
    pub residual_dipole_m_b_am2: Option<Vector3<f64>>,
}

impl EnvironmentSettings {
    /// Whether any model needs the epoch (everything but the gravity gradient and the facets).
    pub fn needs_epoch(&self) -> bool {
        self.dated_model().is_some()
    }

    /// The key (`magnetic`, `sun`, …) of the first registered model that is on and needs the
    /// epoch, for the error without one.
    pub fn dated_model(&self) -> Option<&'static str> {
        self.models.needs_epoch()
    }
}

/// \[m\] how far the actual position at an update may be from the predicted one before the
/// prediction counts as stale (the state was set from outside, e.g. a test placing the
/// spacecraft) and the update is evaluated at the actual state instead. The prediction's own
/// error is ½·|a_p|·Δ² ([`super::prefetch`]): 2e-4 m at 10 Hz in LEO, 10 m only at Δ ≈ 30 s.
/// Either way the choice depends only on the states, so the run stays deterministic.
pub const STALE_PREDICTION_M: f64 = 10.0;

/// The models proper, shared with the prefetch worker ([`super::prefetch`]).
#[derive(Debug)]
struct Models {
    epoch: SimEpoch,
    rotation: EarthOrientation,
    /// Every registered model, built.
    models: BuiltModels,
    /// The world's memo of the position-independent parts, when the vehicle is one of several
    /// ([`EnvironmentModel::share_common`]); set once, before any update.
    common: OnceLock<Arc<CommonCache>>,
}

/// The environment models of a run, built once; fills samples without allocating.
///
/// Update schedule: the first update (at the first call of [`Self::update_if_due`]) evaluates
/// the models at the actual state; every later one at the instant it comes into force, for the
/// position predicted from the state of the update before ([`Request::predicted`]), which lets a
/// worker thread evaluate it ahead of time ([`Self::offload`]) with bit-identical results.
#[derive(Debug)]
pub struct EnvironmentModel {
    models: Arc<Models>,
    update_ns: u64,
    /// \[ns\] the step of the simulation time grid: an update due at `t` happens at the first
    /// multiple of it at or after `t`.
    step_ns: u64,
    /// \[ns\] time of the next due update (`None`: none yet).
    next_update_ns: Option<u64>,
    sample: EnvironmentSample,
    /// What the next update evaluates, when it falls on the step grid as predicted.
    next: Option<Request>,
    /// The worker that evaluates `next` ahead of time ([`Self::offload`]).
    prefetch: Option<Prefetcher>,
    /// The update [`Self::sample_from`] evaluated ahead of its instant, for
    /// [`Self::update_if_due`] to take at the same instant and state instead of evaluating it
    /// a second time.
    memo: Option<Memo>,
    /// Updates evaluated by this model (by the models here or taken from the worker), not
    /// counting those taken from the memo.
    evaluated: u64,
}

/// An evaluated update and the inputs it was evaluated for: the instant and B's position and
/// velocity, bit for bit. The fourth input, the request predicted at the update before
/// (`EnvironmentModel::next`), is the same while the memo lives: every change of it clears the
/// memo.
#[derive(Debug, Clone, Copy)]
struct Memo {
    t_sim_ns: u64,
    r_bn_n_m: [u64; 3],
    v_bn_n_m_s: [u64; 3],
    sample: EnvironmentSample,
}

impl Memo {
    fn bits(v: &Vector3<f64>) -> [u64; 3] {
        [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
    }

    fn holds(&self, t_sim_ns: u64, r_bn_n_m: &Vector3<f64>, v_bn_n_m_s: &Vector3<f64>) -> bool {
        self.t_sim_ns == t_sim_ns
            && self.r_bn_n_m == Self::bits(r_bn_n_m)
            && self.v_bn_n_m_s == Self::bits(v_bn_n_m_s)
    }
}

impl Clone for EnvironmentModel {
    /// A copy of the models and the schedule, without the worker thread (its results are the
    /// same without it).
    fn clone(&self) -> Self {
        Self {
            models: self.models.clone(),
            update_ns: self.update_ns,
            step_ns: self.step_ns,
            next_update_ns: self.next_update_ns,
            sample: self.sample,
            next: self.next,
            prefetch: None,
            memo: self.memo,
            evaluated: self.evaluated,
        }
    }
}

/// A model that cannot be built for this epoch.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EnvironmentBuildError {
    /// The magnetic model refuses the degree or the epoch's date.
    #[error(transparent)]
    Magnetic(#[from] MagneticError),
    /// The space weather is out of range.
    #[error(transparent)]
    Atmosphere(#[from] super::atmosphere::AtmosphereError),
}

/// Which environment models are on ([`EnvironmentModel::models_on`]), by the names the
/// models give themselves (`"magnetic"`, `"sun"`, `"moon"`, `"shadow"`, `"atmosphere"`,
/// `"albedo"`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ModelsOn {
    names: [&'static str; MAX_MODELS_ON],
    len: usize,
}

/// The most model names [`ModelsOn`] holds.
const MAX_MODELS_ON: usize = 16;

impl ModelsOn {
    /// Marks `name` as on (a name past `MAX_MODELS_ON` is dropped; the models registered
    /// today give six names).
    pub fn set(&mut self, name: &'static str) {
        if self.len < MAX_MODELS_ON && !self.is_on(name) {
            self.names[self.len] = name;
            self.len += 1;
        }
    }

    /// Whether the model `name` is on.
    pub fn is_on(&self, name: &str) -> bool {
        self.names[..self.len].contains(&name)
    }
}

impl EnvironmentModel {
    /// Builds the models of `settings` for `epoch`. Fails if IGRF-14 does not cover the epoch
    /// (1900–2030) or the degree, or if the space weather is out of range.
    pub fn new(
        settings: &EnvironmentSettings,
        epoch: &SimEpoch,
    ) -> Result<Self, EnvironmentBuildError> {
        Ok(Self {
            models: Arc::new(Models {
                epoch: epoch.clone(),
                rotation: EarthOrientation::new(settings.earth_rotation, epoch.earth_orientation()),
                models: BuiltModels::new(settings, epoch)?,
                common: OnceLock::new(),
            }),
            update_ns: settings.update_ns.max(1),
            step_ns: 1,
            next_update_ns: None,
            sample: EnvironmentSample::NONE,
            next: None,
            prefetch: None,
            memo: None,
            evaluated: 0,
        })
    }

    /// The same models on a simulation stepping by `step_ns`: updates then happen at multiples
    /// of it, which is where the next update's request is predicted for.
    pub fn on_step_grid(mut self, step_ns: u64) -> Self {
        self.step_ns = step_ns.max(1);
        self
    }

    /// Starts a worker thread that evaluates each update ahead of time, so the models no longer
    /// run on the caller's (physics) thread; the samples are bit-identical with or without it
    /// ([`super::prefetch`]). Call it before stepping; an error (the thread could not be
    /// spawned) leaves the updates on the caller's thread.
    pub fn offload(&mut self) -> std::io::Result<()> {
        let models = self.models.clone();
        let prefetch = Prefetcher::spawn(move |req, out| {
            models.fill(req.t_sim_ns, &req.r_bn_n_m, &req.v_bn_n_m_s, out)
        })?;
        if let Some(req) = &self.next {
            prefetch.post(req);
        }
        self.prefetch = Some(prefetch);
        Ok(())
    }

    /// Shares `cache` with the other vehicles of a world: the Earth's orientation, the Sun and
    /// the Moon at an update instant are evaluated by the first vehicle that needs them and read
    /// by the others ([`super::common`]; the samples are the same bits either way). Returns
    /// false, changing nothing, if a cache was already shared.
    pub fn share_common(&self, cache: Arc<CommonCache>) -> bool {
        self.models.common.set(cache).is_ok()
    }

    /// Whether a worker evaluates the updates ([`Self::offload`]).
    pub fn is_offloaded(&self) -> bool {
        self.prefetch.is_some()
    }

    /// How many samples (updates and telemetry reads) came from the worker's answers, not from
    /// the caller's own evaluation (0 without a worker).
    pub fn prefetched_samples(&self) -> u64 {
        self.prefetch.as_ref().map_or(0, Prefetcher::answers_taken)
    }

    /// How many updates were evaluated (here or by the worker) rather than taken from an
    /// evaluation [`Self::sample_from`] made ahead of them: one per update instant.
    pub fn updates_evaluated(&self) -> u64 {
        self.evaluated
    }

    /// Whether the worker has answered the request posted at the last update, so the next
    /// update will take its answer (false without a worker). Tests and benchmarks use it to wait
    /// for the worker deterministically; the stepping path never waits.
    pub fn prefetch_answer_ready(&self) -> bool {
        self.prefetch.as_ref().is_some_and(Prefetcher::answer_ready)
    }

    /// The epoch.
    pub fn epoch(&self) -> &SimEpoch {
        &self.models.epoch
    }

    /// The numeric parameters of the built models, by configuration path
    /// (`environment.f107_sfu`, `environment.f107a_sfu`, `environment.ap` with NRLMSISE-00; the
    /// `environment.exponential_*` band of an exponential atmosphere given one), for a
    /// campaign's read-back. Not on the stepping path.
    pub fn parameters(&self, out: &mut Vec<(String, f64)>) {
        self.models.models.parameters(out);
    }

    /// The sample last filled by [`Self::update_if_due`].
    pub fn sample(&self) -> &EnvironmentSample {
        &self.sample
    }

    /// Fills `out` at `t_sim_ns` for the hub point B at `r_bn_n_m` moving at `v_bn_n_m_s` (N).
    /// Allocation-free, lock-free, no `Result`.
    pub fn fill(
        &self,
        t_sim_ns: u64,
        r_bn_n_m: &Vector3<f64>,
        v_bn_n_m_s: &Vector3<f64>,
        out: &mut EnvironmentSample,
    ) {
        self.models.fill(t_sim_ns, r_bn_n_m, v_bn_n_m_s, out);
    }

    /// The sample in force from `t_sim_ns` on, without touching the update schedule: the one
    /// [`Self::update_if_due`] would hold after a call at `t_sim_ns` (evaluated if an update is
    /// due then, else the held one). For telemetry at an instant where the next step's update
    /// has not run yet. An update evaluated here is kept, and the update at the same instant
    /// and state takes it instead of evaluating the models again (the same bits: the same
    /// function of the same inputs). Allocation-free.
    pub fn sample_from(
        &mut self,
        t_sim_ns: u64,
        r_bn_n_m: &Vector3<f64>,
        v_bn_n_m_s: &Vector3<f64>,
    ) -> EnvironmentSample {
        if self.next_update_ns.is_some_and(|next| t_sim_ns < next) {
            return self.sample;
        }
        if let Some(sample) = self.memo_of(t_sim_ns, r_bn_n_m, v_bn_n_m_s) {
            return sample;
        }
        let sample = self.evaluate_counted(t_sim_ns, r_bn_n_m, v_bn_n_m_s);
        self.memo = Some(Memo {
            t_sim_ns,
            r_bn_n_m: Memo::bits(r_bn_n_m),
            v_bn_n_m_s: Memo::bits(v_bn_n_m_s),
            sample,
        });
        sample
    }

    /// Which models are on.
    pub fn models_on(&self) -> ModelsOn {
        let mut on = ModelsOn::default();
        self.models.models.models_on(&mut on);
        on
    }

    /// Lists the schedule and the held sample for a checkpoint: the next update time, the
    /// sample held until then and the request the next update evaluates. Restored into an
    /// offloaded model, the request is posted to the worker again (its answer is the same bits
    /// as an evaluation here). The models themselves are configuration. Not on the stepping
    /// path.
    pub fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        use flexdyn_kernel::archive::Archived;
        a.section("environment", |a| {
            a.put(&mut self.next_update_ns);
            self.sample.archive(a);
            let mut has_next = self.next.is_some();
            a.put(&mut has_next);
            if has_next {
                let mut req = self.next.unwrap_or(Request {
                    t_sim_ns: 0,
                    r_bn_n_m: Vector3::zeros(),
                    v_bn_n_m_s: Vector3::zeros(),
                });
                a.put(&mut req.t_sim_ns);
                a.put(&mut req.r_bn_n_m);
                a.put(&mut req.v_bn_n_m_s);
                self.next = Some(req);
            } else {
                self.next = None;
            }
            if !a.is_saving() && !a.failed() {
                self.memo = None;
                if let (Some(p), Some(req)) = (&self.prefetch, &self.next) {
                    p.post(req);
                }
            }
        });
    }

    /// Refills the held sample when `t_sim_ns` has reached the next update time (the first call
    /// always updates), and returns it then; `None` while the held sample still stands.
    pub fn update_if_due(
        &mut self,
        t_sim_ns: u64,
        r_bn_n_m: &Vector3<f64>,
        v_bn_n_m_s: &Vector3<f64>,
    ) -> Option<&EnvironmentSample> {
        if self.next_update_ns.is_some_and(|next| t_sim_ns < next) {
            return None;
        }
        self.sample = match self.memo_of(t_sim_ns, r_bn_n_m, v_bn_n_m_s) {
            Some(sample) => sample,
            None => self.evaluate_counted(t_sim_ns, r_bn_n_m, v_bn_n_m_s),
        };
        // `next` changes below: a memo of this update is spent.
        self.memo = None;
        let due_ns = t_sim_ns.saturating_add(self.update_ns);
        self.next_update_ns = Some(due_ns);
        // The next update happens at the first step boundary at or after `due_ns`.
        let at_ns = due_ns.div_ceil(self.step_ns).saturating_mul(self.step_ns);
        let req = Request::predicted(t_sim_ns, r_bn_n_m, v_bn_n_m_s, at_ns);
        if let Some(p) = &self.prefetch {
            p.post(&req);
        }
        self.next = Some(req);
        Some(&self.sample)
    }

    /// The memo, if it holds the update at `t_sim_ns` for this state.
    fn memo_of(
        &self,
        t_sim_ns: u64,
        r_bn_n_m: &Vector3<f64>,
        v_bn_n_m_s: &Vector3<f64>,
    ) -> Option<EnvironmentSample> {
        self.memo
            .filter(|m| m.holds(t_sim_ns, r_bn_n_m, v_bn_n_m_s))
            .map(|m| m.sample)
    }

    /// [`Self::evaluate_update`], counted in [`Self::updates_evaluated`].
    fn evaluate_counted(
        &mut self,
        t_sim_ns: u64,
        r_bn_n_m: &Vector3<f64>,
        v_bn_n_m_s: &Vector3<f64>,
    ) -> EnvironmentSample {
        self.evaluated += 1;
        self.evaluate_update(t_sim_ns, r_bn_n_m, v_bn_n_m_s)
    }

    /// The sample of an update at `t_sim_ns`: the predicted request's (from the worker if it
    /// has answered, else evaluated here: the same bits), or, for the first update, one off the
    /// predicted instant and one whose state is more than [`STALE_PREDICTION_M`] from the
    /// prediction (a state set from outside), the models at the actual state.
    fn evaluate_update(
        &self,
        t_sim_ns: u64,
        r_bn_n_m: &Vector3<f64>,
        v_bn_n_m_s: &Vector3<f64>,
    ) -> EnvironmentSample {
        let mut s = EnvironmentSample::NONE;
        match &self.next {
            Some(req)
                if req.t_sim_ns == t_sim_ns
                    && (req.r_bn_n_m - r_bn_n_m).norm_squared()
                        <= STALE_PREDICTION_M * STALE_PREDICTION_M =>
            {
                match self.prefetch.as_ref().and_then(|p| p.answer(req)) {
                    Some(answer) => s = answer,
                    None => self.fill(req.t_sim_ns, &req.r_bn_n_m, &req.v_bn_n_m_s, &mut s),
                }
            }
            _ => self.fill(t_sim_ns, r_bn_n_m, v_bn_n_m_s, &mut s),
        }
        s
    }
}

impl Models {
    /// Fills `out` at `t_sim_ns` for the hub point B at `r_bn_n_m` moving at `v_bn_n_m_s` (N).
    /// Allocation-free, lock-free, no `Result`.
    fn fill(
        &self,
        t_sim_ns: u64,
        r_bn_n_m: &Vector3<f64>,
        _v_bn_n_m_s: &Vector3<f64>,
        out: &mut EnvironmentSample,
    ) {
        *out = EnvironmentSample::NONE;
        out.t_sim_ns = t_sim_ns;
        let needs = self.models.needs();
        // The Earth's orientation for the models that work in the Earth-fixed frame (the field,
        // a geodetic altitude, the co-rotating wind). The IAU chain (precession-nutation and
        // sidereal time, ~1.5 µs) is position-independent and shared with the Sun and the Moon
        // ([`super::common`]); a uniform rotation is evaluated here.
        let parts = Parts {
            earth: needs.frame && self.rotation.is_dated(),
            sun: needs.sun_ephemeris,
            moon: needs.moon_ephemeris,
        };
        let common = match self.common.get() {
            Some(cache) => {
                cache.get_or_evaluate(t_sim_ns, parts, || self.common_at(t_sim_ns, parts))
            }
            None => self.common_at(t_sim_ns, parts),
        };
        let earth = match &self.rotation {
            EarthOrientation::Uniform(u) if needs.frame => u.at(t_sim_ns),
            _ => common.earth,
        };
        let at = At {
            t_sim_ns,
            r_bn_n_m,
            epoch: &self.epoch,
            earth: &earth,
            r_e_m: if needs.frame {
                earth.r_e(r_bn_n_m)
            } else {
                Vector3::zeros()
            },
            // The Sun is an input of the models that need sunlight (the shadow, the albedo).
            r_sun_n_m: self
                .models
                .ephemeris
                .as_ref()
                .and_then(|e| e.sun_n_m(&common.r_sun_n_m)),
            r_moon_n_m: common.r_moon_n_m,
        };
        self.models.fill(&at, out);
    }

    /// The position-independent `parts` at `t_sim_ns`: what a world's vehicles share
    /// ([`super::common`]).
    fn common_at(&self, t_sim_ns: u64, parts: Parts) -> Common {
        let times = self.epoch.times(t_sim_ns);
        let t_tt_jc = times.tt_centuries_j2000();
        let mut c = Common::zero();
        if parts.earth {
            c.earth = self.rotation.at(&times, t_sim_ns);
        }
        if parts.sun {
            c.r_sun_n_m = sun_position_n_m(t_tt_jc);
        }
        if parts.moon {
            c.r_moon_n_m = moon_position_n_m(t_tt_jc);
        }
        c
    }
}
