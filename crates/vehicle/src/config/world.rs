//! The world sections of a configuration: `[epoch]`, `[orbit]` and `[environment]`.
//!
//! Their readers live with their models (`environment::epoch::schema`,
//! `environment::orbit::schema`, `environment::model::schema`, which asks each registered
//! environment model for its keys); this file registers them and runs the checks that need the
//! rest of the file: `[orbit]` against `[initial]` and the gravity model, every dated model
//! against `[epoch]`, the magnetic model's span against the epoch, and the gravity gradient
//! against the gravity model. Without these sections nothing changes.

use std::path::Path;

use flexdyn_dynamics::GravityModel;
use flexdyn_environment::epoch::schema::{self as epoch_schema, RawEpoch};
use flexdyn_environment::epoch::SimEpoch;
use flexdyn_environment::geodetic::WGS84_A_M;
use flexdyn_environment::model::schema as env_schema;
use flexdyn_environment::model::{EnvironmentBuildError, EnvironmentModel, EnvironmentSettings};
use flexdyn_environment::orbit::schema::{self as orbit_schema, InitialOrbit, RawOrbit};
use flexdyn_kernel::schema::{SchemaError, TableReader};

use super::{ConfigError, SourceMap};

/// The root keys this file registers.
pub(super) const ROOT_KEYS: [&str; 3] = ["epoch", "orbit", "environment"];

/// The world sections as written.
pub(super) struct RawWorld {
    epoch: Option<RawEpoch>,
    orbit: Option<RawOrbit>,
    environment: Option<EnvironmentSettings>,
}

/// The world sections, resolved.
pub(super) struct World {
    pub epoch: Option<SimEpoch>,
    pub orbit: Option<InitialOrbit>,
    pub environment: Option<EnvironmentSettings>,
}

/// [`ConfigError::Invalid`] at `field`, or at its nearest enclosing table.
fn invalid_near(map: &SourceMap, field: &str, problem: String) -> ConfigError {
    ConfigError::Invalid {
        field: field.to_string(),
        problem,
        at: map.near(field),
    }
}

/// A reader error with its position looked up (the world readers leave it to the caller).
fn located(map: &SourceMap, e: SchemaError) -> ConfigError {
    let e = match e {
        SchemaError::UnknownKey { field, message, at } if at.0.is_none() => {
            let at = map.near(&field);
            SchemaError::UnknownKey { field, message, at }
        }
        SchemaError::MissingKey { field, at } if at.0.is_none() => {
            let at = map.near(&field);
            SchemaError::MissingKey { field, at }
        }
        SchemaError::InvalidValue { field, message, at } if at.0.is_none() => {
            let at = map.near(&field);
            SchemaError::InvalidValue { field, message, at }
        }
        other => other,
    };
    ConfigError::Schema(e)
}

impl RawWorld {
    /// Reads the three sections (each optional).
    pub(super) fn read(root: &TableReader<'_, '_>, map: &SourceMap) -> Result<Self, ConfigError> {
        let l = |e| located(map, e);
        let epoch = root
            .opt_table("epoch", &epoch_schema::KEYS)
            .map_err(l)?
            .map(|t| epoch_schema::read(&t))
            .transpose()
            .map_err(l)?;
        let orbit = root
            .opt_table("orbit", &orbit_schema::KEYS)
            .map_err(l)?
            .map(|t| orbit_schema::read(&t))
            .transpose()
            .map_err(l)?;
        let environment = root
            .opt_table("environment", &env_schema::KEYS)
            .map_err(l)?
            .map(|t| env_schema::read(&t))
            .transpose()
            .map_err(l)?;
        Ok(Self {
            epoch,
            orbit,
            environment,
        })
    }

    /// Whether `[orbit]` is given (then `[initial]` holds only the attitude).
    pub(super) fn has_orbit(&self) -> bool {
        self.orbit.is_some()
    }

    /// Resolves the sections against the gravity model; `base_dir` is the configuration file's
    /// folder (for `orbit.elements_file`).
    pub(super) fn resolve(
        self,
        gravity: &GravityModel,
        base_dir: &Path,
        map: &SourceMap,
    ) -> Result<World, ConfigError> {
        let epoch = match &self.epoch {
            None => None,
            Some(raw) => Some(raw.build().map_err(|e| {
                let msg = e.to_string();
                let (field, problem) = msg
                    .split_once(": ")
                    .map_or((raw.field.clone(), msg.clone()), |(f, p)| {
                        (f.to_string(), p.to_string())
                    });
                invalid_near(map, &field, problem)
            })?),
        };
        let needs_epoch = |what: &str, field: &str| {
            invalid_near(
                map,
                field,
                format!("{what} needs a date: add an [epoch] table (utc = \"…Z\" or tai = \"…\")"),
            )
        };
        let orbit = match (&self.orbit, &epoch) {
            (None, _) => None,
            (Some(_), None) => return Err(needs_epoch("an [orbit]", "orbit")),
            (Some(raw), Some(epoch)) => {
                let (mu_m3_s2, r_eq_m) = match *gravity {
                    GravityModel::None => {
                        return Err(invalid_near(
                            map,
                            "gravity.model",
                            "an [orbit] needs a central body: use gravity.model = \
                             \"point_mass\" or \"j2\""
                                .into(),
                        ))
                    }
                    GravityModel::PointMass { mu_m3_s2 } => (mu_m3_s2, WGS84_A_M),
                    GravityModel::J2 {
                        mu_m3_s2, r_eq_m, ..
                    } => (mu_m3_s2, r_eq_m),
                };
                Some(
                    raw.initial_state_n("orbit", epoch, mu_m3_s2, r_eq_m, base_dir)
                        .map_err(|e| {
                            let msg = e.to_string();
                            let (field, problem) = msg
                                .split_once(": ")
                                .map_or(("orbit".to_string(), msg.clone()), |(f, p)| {
                                    (f.to_string(), p.to_string())
                                });
                            invalid_near(map, &field, problem)
                        })?,
                )
            }
        };
        let environment = match self.environment {
            None => None,
            Some(env) => {
                if env.gravity_gradient && *gravity == GravityModel::None {
                    return Err(invalid_near(
                        map,
                        "environment.gravity_gradient",
                        "the gravity gradient needs a central body: use gravity.model = \
                         \"point_mass\" or \"j2\""
                            .into(),
                    ));
                }
                match &epoch {
                    None if env.needs_epoch() => {
                        let field = env.dated_model().unwrap_or("environment");
                        return Err(needs_epoch(
                            &format!("environment.{field}"),
                            &format!("environment.{field}"),
                        ));
                    }
                    None => {}
                    Some(epoch) => {
                        EnvironmentModel::new(&env, epoch).map_err(|e| match e {
                            EnvironmentBuildError::Magnetic(m) => invalid_near(
                                map,
                                &self
                                    .epoch
                                    .as_ref()
                                    .map_or("epoch".into(), |r| r.field.clone()),
                                format!("{m} (environment.magnetic)"),
                            ),
                            other => invalid_near(map, "environment", other.to_string()),
                        })?;
                    }
                }
                Some(env)
            }
        };
        Ok(World {
            epoch,
            orbit,
            environment,
        })
    }
}

/// Adds the dynamic effectors `env` switches on to `sc`, in a fixed order: gravity gradient,
/// drag, solar pressure, residual dipole. The settings were validated when read (facets, a
/// central body, the models each effector reads), so this cannot fail.
pub(super) fn add_dynamic_effectors(
    sc: &mut flexdyn_dynamics::Spacecraft,
    env: &EnvironmentSettings,
    gravity: &GravityModel,
) {
    use flexdyn_dynamics::dynamic_effectors::{
        aero_drag::AeroDrag, cannonball_srp::CannonballSrp, gravity_gradient::GravityGradient,
        residual_dipole::ResidualDipole, solar_pressure::SolarPressure,
    };
    use flexdyn_environment::facets::FacetModel;
    let facets = || FacetModel::new(env.facets.clone()).unwrap_or_default();
    if env.gravity_gradient {
        let mu_m3_s2 = match *gravity {
            GravityModel::PointMass { mu_m3_s2 } | GravityModel::J2 { mu_m3_s2, .. } => mu_m3_s2,
            GravityModel::None => 0.0,
        };
        sc.add_dynamic_effector(Box::new(GravityGradient { mu_m3_s2 }));
    }
    if env.drag {
        sc.add_dynamic_effector(Box::new(AeroDrag { facets: facets() }));
    }
    if env.solar_pressure {
        match env.cannonball {
            None => sc.add_dynamic_effector(Box::new(SolarPressure::new(
                facets(),
                env.solar_irradiance_1au_w_m2,
            ))),
            Some(ball) => sc.add_dynamic_effector(Box::new(CannonballSrp::new(
                ball,
                env.solar_irradiance_1au_w_m2,
            ))),
        };
    }
    if let Some(m_b_am2) = env.residual_dipole_m_b_am2 {
        sc.add_dynamic_effector(Box::new(ResidualDipole { m_b_am2 }));
    }
}
