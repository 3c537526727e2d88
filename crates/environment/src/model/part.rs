//! The contract of one environment model, and the registry that lists them.
//!
//! Each model that fills part of the [`EnvironmentSample`] (the magnetic field, the Sun and the
//! Moon, the shadow, the atmosphere, the Earth's albedo) is a type implementing
//! [`EnvironmentPart`] in its own folder: its keys of `[environment]` and how they are read, its
//! settings, how it is built for an epoch, what of the shared update it needs (the Earth-fixed
//! frame, the Sun's or the Moon's ephemeris), how it fills its fields of a sample, and how those
//! fields travel through the prefetch slot and a checkpoint. `crate::lib` registers each with one
//! line of `environment_models!`, and the model ([`super`]), the schema ([`super::schema`]),
//! the prefetch slot ([`crate::prefetch`]) and the sample's archive ([`crate::sample`]) loop over
//! that list.
//!
//! The list expands, at compile time, into one field per model in [`crate::ModelSettings`] and in
//! the built models, and into one call per model in each loop: the update calls every model
//! through its concrete type, with no `dyn` dispatch and no allocation. The registry's order is
//! the order of the sample's words in the prefetch slot and in a checkpoint (a change of order
//! changes the checkpoint's layout), the order in which the models read their keys (a model may
//! look at the settings of those before it) and the order in which the update fills them (which
//! changes no bit: each reads only the shared inputs [`At`]).

use nalgebra::Vector3;

use super::{EnvironmentBuildError, EnvironmentSettings, ModelsOn};
use crate::earth_rotation::EarthFrame;
use crate::epoch::SimEpoch;
use crate::{EnvironmentSample, ModelSettings};
use flexdyn_kernel::archive::Archive;
use flexdyn_kernel::schema::{SchemaError, TableReader};

/// What of the shared, position-independent part of an update a model needs
/// ([`crate::common`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Needs {
    /// The Earth-fixed frame at the instant, and B's position in it ([`At::earth`],
    /// [`At::r_e_m`]).
    pub frame: bool,
    /// The Sun's ephemeris.
    pub sun_ephemeris: bool,
    /// The Moon's ephemeris.
    pub moon_ephemeris: bool,
}

impl Needs {
    /// Both needs.
    pub fn or(self, other: Needs) -> Needs {
        Needs {
            frame: self.frame || other.frame,
            sun_ephemeris: self.sun_ephemeris || other.sun_ephemeris,
            moon_ephemeris: self.moon_ephemeris || other.moon_ephemeris,
        }
    }
}

/// The inputs every model of one update reads: the instant, B's position and what the update
/// shares between the models.
#[derive(Debug, Clone, Copy)]
pub struct At<'a> {
    /// \[ns\] simulation time of the sample.
    pub t_sim_ns: u64,
    /// \[m\] position of the hub point B, N components.
    pub r_bn_n_m: &'a Vector3<f64>,
    /// The epoch (for the models that need the date).
    pub epoch: &'a SimEpoch,
    /// The Earth-fixed frame at `t_sim_ns` (meaningful when some model [`Needs::frame`]).
    pub earth: &'a EarthFrame,
    /// \[m\] B's position in the Earth-fixed frame (zero unless some model [`Needs::frame`]).
    pub r_e_m: Vector3<f64>,
    /// \[m\] the Sun's geocentric position, N components (the ephemeris or a fixed Sun); `None`
    /// when the Sun is off.
    pub r_sun_n_m: Option<Vector3<f64>>,
    /// \[m\] the Moon's geocentric position, N components (zero unless the Moon is on).
    pub r_moon_n_m: Vector3<f64>,
}

/// One environment model (module docs): implemented by the built model, in its own folder.
pub trait EnvironmentPart: Sized + std::fmt::Debug + Send + Sync + 'static {
    /// Its settings as read from `[environment]`; the default is "off".
    type Settings: std::fmt::Debug + Clone + PartialEq + Default;
    /// Its keys of `[environment]`.
    const KEYS: &'static [&'static str];
    /// The most words its fields of the sample take ([`Self::to_words`]).
    const WORDS: usize;
    /// What it names as a user of `solar_irradiance_1au_w_m2` in the error for that key given
    /// unused (`albedo = "lambertian"`), if it uses it at all.
    const IRRADIANCE_USER: Option<&'static str> = None;

    /// Reads its keys of `[environment]`; `before` holds the settings of the models registered
    /// before it (the rest are at their defaults). Errors name the key.
    fn read(t: &TableReader<'_, '_>, before: &ModelSettings)
        -> Result<Self::Settings, SchemaError>;

    /// The key that switches it on, if it is on and needs the date (an `[epoch]`).
    fn needs_epoch(_settings: &Self::Settings) -> Option<&'static str> {
        None
    }

    /// Whether it is on and reads `solar_irradiance_1au_w_m2` ([`Self::IRRADIANCE_USER`]).
    fn uses_irradiance(_settings: &Self::Settings) -> bool {
        false
    }

    /// The model for `epoch`, or `None` when it is off. `all` is the whole `[environment]`
    /// (a model may read a shared constant, or another model's: the albedo's sphere is the
    /// shadow's).
    fn build(
        settings: &Self::Settings,
        all: &EnvironmentSettings,
        epoch: &SimEpoch,
    ) -> Result<Option<Self>, EnvironmentBuildError>;

    /// What of the shared update it needs.
    fn needs(&self) -> Needs {
        Needs::default()
    }

    /// Fills its fields of `out` (which holds [`EnvironmentSample::NONE`]'s values for them).
    /// Allocation-free, lock-free, no `Result`.
    fn fill(&self, at: &At<'_>, out: &mut EnvironmentSample);

    /// Marks the models it is as on ([`ModelsOn::set`]), for the environment message's flags.
    fn models_on(&self, on: &mut ModelsOn);

    /// Its numeric parameters by configuration path, for a campaign's read-back.
    fn parameters(&self, _out: &mut Vec<(String, f64)>) {}

    /// Writes its fields of `s` into the front of `w` (at least [`Self::WORDS`] long); returns
    /// how many words it used (the prefetch slot moves only those).
    fn to_words(s: &EnvironmentSample, w: &mut [u64]) -> usize;

    /// Reads its fields of `s` from the front of `w`, as [`Self::to_words`] wrote them;
    /// returns how many words it read.
    fn from_words(w: &[u64], s: &mut EnvironmentSample) -> usize;

    /// Lists its fields of `s` for a checkpoint, in a fixed order.
    fn archive(s: &mut EnvironmentSample, a: &mut Archive<'_>);
}

/// The f64 in `w[i]`.
pub(crate) fn f(w: &[u64], i: usize) -> f64 {
    f64::from_bits(w[i])
}

/// The vector in `w[i..i + 3]`.
pub(crate) fn v3(w: &[u64], i: usize) -> Vector3<f64> {
    Vector3::new(f(w, i), f(w, i + 1), f(w, i + 2))
}

/// Writes `v` into `w[i..i + 3]`.
pub(crate) fn put_v3(w: &mut [u64], i: usize, v: &Vector3<f64>) {
    w[i] = v.x.to_bits();
    w[i + 1] = v.y.to_bits();
    w[i + 2] = v.z.to_bits();
}

/// The registry of environment models (module docs): one line per model,
/// `name: path::to::Part,` where `Part` implements [`EnvironmentPart`]. Expands into
/// [`crate::ModelSettings`] (one field per model, its settings), the built models, the keys of
/// every model, and the loops of the update, the schema, the prefetch slot and the archive.
macro_rules! environment_models {
    ($($(#[$doc:meta])* $name:ident: $part:ty,)+) => {
        /// The settings of every registered environment model (`crate::lib`'s registry), one
        /// field per model, each its model's `EnvironmentPart::Settings`.
        #[derive(Debug, Clone, PartialEq, Default)]
        pub struct ModelSettings {
            $($(#[$doc])* pub $name: <$part as $crate::model::part::EnvironmentPart>::Settings,)+
        }

        /// Every registered model, built (`None`: off).
        #[derive(Debug)]
        pub(crate) struct BuiltModels {
            $($name: Option<$part>,)+
        }

        /// The keys of `[environment]` of every registered model, in registry order.
        pub(crate) const MODEL_KEYS: &[&[&str]] =
            &[$(<$part as $crate::model::part::EnvironmentPart>::KEYS,)+];

        /// The most words a sample takes in the prefetch slot: its time, then every model's.
        pub(crate) const SAMPLE_WORDS: usize =
            1 $(+ <$part as $crate::model::part::EnvironmentPart>::WORDS)+;

        impl ModelSettings {
            /// Reads every model's keys, in registry order.
            pub(crate) fn read(
                t: &flexdyn_kernel::schema::TableReader<'_, '_>,
            ) -> Result<Self, flexdyn_kernel::schema::SchemaError> {
                let mut s = Self::default();
                $(s.$name =
                    <$part as $crate::model::part::EnvironmentPart>::read(t, &s)?;)+
                Ok(s)
            }

            /// The key of the first model that needs the date, if any.
            pub(crate) fn needs_epoch(&self) -> Option<&'static str> {
                None $(.or_else(|| {
                    <$part as $crate::model::part::EnvironmentPart>::needs_epoch(&self.$name)
                }))+
            }

            /// Whether some model reads `solar_irradiance_1au_w_m2`, and the switches of those
            /// that can.
            pub(crate) fn irradiance_users(&self) -> (bool, Vec<&'static str>) {
                let used = false $(|| <$part as $crate::model::part::EnvironmentPart>
                    ::uses_irradiance(&self.$name))+;
                let users = [$(<$part as $crate::model::part::EnvironmentPart>
                    ::IRRADIANCE_USER,)+];
                (used, users.into_iter().flatten().collect())
            }
        }

        impl BuiltModels {
            /// Builds every model of `all` for `epoch`.
            pub(crate) fn new(
                all: &$crate::model::EnvironmentSettings,
                epoch: &$crate::epoch::SimEpoch,
            ) -> Result<Self, $crate::model::EnvironmentBuildError> {
                Ok(Self {
                    $($name: <$part as $crate::model::part::EnvironmentPart>::build(
                        &all.models.$name, all, epoch,
                    )?,)+
                })
            }

            /// What the models that are on need of the shared update.
            pub(crate) fn needs(&self) -> $crate::model::part::Needs {
                let n = $crate::model::part::Needs::default();
                $(let n = match &self.$name {
                    Some(m) => n.or($crate::model::part::EnvironmentPart::needs(m)),
                    None => n,
                };)+
                n
            }

            /// Every model that is on fills its fields of `out`.
            #[inline]
            pub(crate) fn fill(
                &self,
                at: &$crate::model::part::At<'_>,
                out: &mut $crate::EnvironmentSample,
            ) {
                $(if let Some(m) = &self.$name {
                    $crate::model::part::EnvironmentPart::fill(m, at, out);
                })+
            }

            /// Which models are on.
            pub(crate) fn models_on(&self, on: &mut $crate::model::ModelsOn) {
                $(if let Some(m) = &self.$name {
                    $crate::model::part::EnvironmentPart::models_on(m, on);
                })+
            }

            /// The built models' parameters.
            pub(crate) fn parameters(&self, out: &mut Vec<(String, f64)>) {
                $(if let Some(m) = &self.$name {
                    $crate::model::part::EnvironmentPart::parameters(m, out);
                })+
            }
        }

        /// Writes `s` into `w` (the time, then every model's fields); returns the words used.
        pub(crate) fn sample_to_words(s: &$crate::EnvironmentSample, w: &mut [u64]) -> usize {
            w[0] = s.t_sim_ns;
            let mut n = 1;
            $(n += <$part as $crate::model::part::EnvironmentPart>::to_words(s, &mut w[n..]);)+
            n
        }

        /// The sample [`sample_to_words`] wrote into `w`.
        pub(crate) fn sample_from_words(w: &[u64]) -> $crate::EnvironmentSample {
            let mut s = $crate::EnvironmentSample::NONE;
            s.t_sim_ns = w[0];
            let mut n = 1;
            $(n += <$part as $crate::model::part::EnvironmentPart>::from_words(&w[n..], &mut s);)+
            let _ = n;
            s
        }

        /// Lists every model's fields of `s` for a checkpoint, in registry order.
        pub(crate) fn archive_models(
            s: &mut $crate::EnvironmentSample,
            a: &mut flexdyn_kernel::archive::Archive<'_>,
        ) {
            $(<$part as $crate::model::part::EnvironmentPart>::archive(s, a);)+
        }
    };
}

pub(crate) use environment_models;
