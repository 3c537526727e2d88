//! A rigid hub about a point mass, built from a configuration text: the vehicle of the
//! dynamic-effector tests (`crates/vehicle/tests/gravity_gradient.rs`, `crates/vehicle/tests/surface_forces.rs`).

use flexdyn_dynamics::Spacecraft;
use flexdyn_vehicle::config::SimConfig;

/// A rigid hub of 500 kg with principal inertia `inertia_kg_m2` about its centre of mass, that
/// centre `r_bcb_b_m` from B, under the point-mass gravity `mu_m3_s2`, stepped at `step_s`;
/// `initial` is the body of its `[initial]` table.
pub fn rigid_hub(
    mu_m3_s2: f64,
    inertia_kg_m2: [f64; 3],
    r_bcb_b_m: [f64; 3],
    initial: &str,
    step_s: f64,
) -> Spacecraft {
    let [i1, i2, i3] = inertia_kg_m2;
    let [c1, c2, c3] = r_bcb_b_m;
    let toml = format!(
        r#"
panel_pairs = []
[simulation]
step_s = {step_s}
frame_hz = 1.0
[gravity]
model = "point_mass"
mu_m3_s2 = {mu_m3_s2:?}
[hub]
mass_kg = 500.0
inertia_bc_b_kg_m2 = [[{i1:?}, 0.0, 0.0], [0.0, {i2:?}, 0.0], [0.0, 0.0, {i3:?}]]
r_bcb_b_m = [{c1:?}, {c2:?}, {c3:?}]
[initial]
{initial}
"#
    );
    SimConfig::from_toml_str(&toml)
        .unwrap()
        .build_spacecraft()
        .unwrap()
}
