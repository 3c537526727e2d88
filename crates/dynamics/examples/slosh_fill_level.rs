//! Prints the first lateral slosh mode of an upright cylindrical tank (radius 0.4 m, hydrazine)
//! against its fill level, as CSV: the table behind `docs/figures/slosh_fill_level.png`
//! (`tools/peers/slosh_figures.py` plots it).
//!
//! ```sh
//! cargo run --release -p flexdyn-dynamics --example slosh_fill_level > fill.csv
//! ```

use flexdyn_dynamics::slosh_tank::CylindricalTank;
use nalgebra::Vector3;

fn main() {
    let radius_m = 0.4;
    println!("h_over_r,slosh_fraction,pendulum_length_over_r,slosh_height_over_h,hinge_height_over_h,omega_at_0p01_rad_s");
    for i in 1..=60 {
        let h_over_r = 0.05 * i as f64;
        let tank = CylindricalTank {
            radius_m,
            fill_height_m: h_over_r * radius_m,
            density_kg_m3: 1004.0,
            r_bottom_b_m: Vector3::zeros(),
            axis_b: Vector3::z(),
        };
        let m = tank.first_mode();
        let h = tank.fill_height_m;
        println!(
            "{h_over_r:.3},{:.6},{:.6},{:.6},{:.6},{:.6}",
            m.slosh_mass_kg / m.liquid_mass_kg,
            m.pendulum_length_m / radius_m,
            m.slosh_height_m / h,
            m.hinge_height_m / h,
            m.omega_rad_s(0.01),
        );
    }
}
