//! The `[[propellant_tanks]]` schema. Keys are checked by the shared reader
//! ([`flexdyn_kernel::schema`]); values are validated by [`super::PropellantTank::new`], whose
//! errors name the same TOML paths.
//!
//! `inertia_model` chooses how the propellant's inertia follows its mass (the module's (D6)):
//! `"constant_volume"` takes `radius_m`, `"constant_density"` takes `density_kg_m3`.

use super::{PropellantTankParams, TankInertiaModel};
use flexdyn_kernel::schema::{vec3, SchemaError, TableReader};

/// The keys of one `[[propellant_tanks]]` entry.
pub const KEYS: [&str; 6] = [
    "name",
    "r_tcb_b_m",
    "propellant_mass_kg",
    "inertia_model",
    "radius_m",
    "density_kg_m3",
];

/// Reads one entry (shape only; [`PropellantTankParams::validate`] checks the values).
pub fn read(t: &TableReader<'_, '_>) -> Result<PropellantTankParams, SchemaError> {
    let (inertia, other_key) = match t.opt_choice("inertia_model", &TankInertiaModel::NAMES)? {
        None | Some(0) => (
            TankInertiaModel::ConstantVolume {
                radius_m: t.f64("radius_m")?,
            },
            "density_kg_m3",
        ),
        Some(_) => (
            TankInertiaModel::ConstantDensity {
                density_kg_m3: t.f64("density_kg_m3")?,
            },
            "radius_m",
        ),
    };
    if t.get(other_key).is_some() {
        let model = match inertia {
            TankInertiaModel::ConstantVolume { .. } => TankInertiaModel::NAMES[0],
            TankInertiaModel::ConstantDensity { .. } => TankInertiaModel::NAMES[1],
        };
        return Err(t.refuse(
            other_key,
            format!(
                "a `{model}` tank does not take {other_key} (`constant_volume` takes radius_m, \
                 `constant_density` takes density_kg_m3)"
            ),
        ));
    }
    Ok(PropellantTankParams {
        name: t.string("name")?,
        r_tcb_b_m: vec3(&t.floats("r_tcb_b_m")?),
        propellant_mass_kg: t.f64("propellant_mass_kg")?,
        inertia,
    })
}
