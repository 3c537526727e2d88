//! `[[effector_input_schedule]]`: effector inputs (wheel motor torques) as a function of time,
//! by effector name, so `simulate` can drive the wheels with no flight code.
//!
//! - validation, like the wrench schedule's: the name exists and takes inputs, the input count
//!   is the kind's, times are whole steps and strictly increasing per effector, values finite;
//!   every error names the field and its line;
//! - physics: the rest-to-rest slew of `scenarios/wheel_slew.toml` against its closed form
//!   (momentum exchange between a rigid hub and one wheel on its principal axis);
//! - the flight code's inputs add to the scheduled ones.

use std::path::Path;

use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

fn slew_text() -> String {
    std::fs::read_to_string(Path::new(crate::REPO).join("scenarios/wheel_slew.toml")).unwrap()
}

/// The slew scenario without its schedule, plus `rows`.
fn with_rows(rows: &str) -> String {
    let text = slew_text();
    let cut = text.find("# Each row sets").unwrap();
    format!("{}{rows}", &text[..cut])
}

fn row(t_s: &str, effector: &str, inputs: &str) -> String {
    format!(
        "[[effector_input_schedule]]\nt_s = {t_s}\neffector = \"{effector}\"\ninputs = {inputs}\n"
    )
}

#[track_caller]
fn rejected(text: &str, field: &str, problem: &str) {
    let e = SimConfig::from_toml_str(text).expect_err("must be rejected");
    let msg = e.to_string();
    assert!(msg.starts_with(&format!("{field}: ")), "{msg}");
    assert!(msg.contains(problem), "{msg}");
    assert!(msg.contains("(line "), "no position: {msg}");
}

#[test]
fn rows_are_read_by_effector_name_and_sorted_by_time() {
    let text = with_rows(&format!(
        "{}{}{}",
        row("0.5", "rw1", "[0.1]"),
        row("0.75", "rw1", "[0.0]"),
        row("0.002", "rw1", "[-0.05]")
    ));
    // Out of order across rows of the same effector is an error (0.002 after 0.75) ...
    rejected(
        &text,
        "effector_input_schedule[2].t_s",
        "t_s must be strictly increasing",
    );
    // ... while rows of different effectors interleave freely, and come out sorted by time.
    let two_wheels = with_rows(&format!(
        "[[reaction_wheels]]\nname = \"rw2\"\nspin_axis_b = [1.0, 0.0, 0.0]\nr_wb_b_m = [0.0, 0.0, 0.0]\n\
         mass_kg = 5.0\nj_s_kg_m2 = 0.05\nj_t_kg_m2 = 0.03\nmax_torque_nm = 0.25\nmax_speed_rad_s = 600.0\n{}{}{}",
        row("0.5", "rw1", "[0.1]"),
        row("0.1", "rw2", "[0.2]"),
        row("0.7", "rw1", "[0.0]"),
    ));
    let cfg = SimConfig::from_toml_str(&two_wheels).unwrap();
    let got: Vec<(u64, usize, Vec<f64>)> = cfg
        .effector_input_schedule
        .iter()
        .map(|s| (s.t_start_ns, s.effector_index, s.inputs.clone()))
        .collect();
    assert_eq!(
        got,
        [
            (100_000_000, 1, vec![0.2]),
            (500_000_000, 0, vec![0.1]),
            (700_000_000, 0, vec![0.0]),
        ]
    );
}

#[test]
fn bad_rows_name_the_field() {
    rejected(
        &with_rows(&row("0.0", "rw9", "[0.1]")),
        "effector_input_schedule[0].effector",
        "no effector is named `rw9` (effectors that take inputs: `rw1`)",
    );
    rejected(
        &with_rows(&row("0.0", "rw1", "[0.1, 0.2]")),
        "effector_input_schedule[0].inputs",
        "expected 1 value (motor_torque_nm) for the reaction wheel `rw1`, got 2",
    );
    rejected(
        &with_rows(&row("0.0", "rw1", "[]")),
        "effector_input_schedule[0].inputs",
        "got 0",
    );
    rejected(
        &with_rows(&row("0.0005", "rw1", "[0.1]")),
        "effector_input_schedule[0].t_s",
        "not a whole number of steps",
    );
    rejected(
        &with_rows(&row("-1.0", "rw1", "[0.1]")),
        "effector_input_schedule[0].t_s",
        "-1",
    );
    rejected(
        &with_rows(&format!(
            "{}{}",
            row("1.0", "rw1", "[0.1]"),
            row("1.0", "rw1", "[0.2]")
        )),
        "effector_input_schedule[1].t_s",
        "not after the previous row's (1 s)",
    );
    rejected(
        &with_rows(&row("0.0", "rw1", "[nan]")),
        "effector_input_schedule[0].inputs[0]",
        "finite",
    );
    rejected(
        &with_rows(&row("0.0", "rw1", "0.1")),
        "effector_input_schedule[0].inputs",
        "expected an array of numbers",
    );
    rejected(
        &with_rows(&row("0.0", "rw1", "[0.1]").replace("effector =", "efector =")),
        "effector_input_schedule[0].efector",
        "unknown key",
    );
    // A panel pair is an effector but takes no inputs.
    let reference = flexdyn_vehicle::config::DEFAULT_CONFIG_TOML;
    rejected(
        &format!("{reference}\n{}", row("0.0", "wing_px", "[0.1]")),
        "effector_input_schedule[0].effector",
        "the panel pair `wing_px` takes no inputs",
    );
}

/// The rest-to-rest slew of `scenarios/wheel_slew.toml` (its header derives the numbers):
/// +u on the wheel for T, −u for T, on a rigid hub with the wheel on its z principal axis at
/// the CoM. The hub takes −u, so I_zz ω̇ = ∓u: ω(T) = −uT/I_zz, then back to 0 at 2T, and
/// φ(2T) = −uT²/I_zz about z, i.e. σ_BN = (0, 0, tan(φ/4)). The rotor obeys
/// J_s (ω + Ω)˙ = ±u: Ω(T) = uT/J_s + uT/I_zz, Ω(2T) = 0. H_C stays 0.
#[test]
fn validate_a_scheduled_wheel_slew_against_its_closed_form() {
    let cfg = SimConfig::from_toml_str(&slew_text()).unwrap();
    let (u, t, i_zz, j_s) = (0.2, 30.0, 400.0, 0.05);
    let mut sim = Simulation::new(&cfg).unwrap();
    let wheel = |sim: &Simulation| sim.spacecraft().state().effectors[0];
    sim.step_n(30_000);
    let s = sim.spacecraft().state();
    let (omega_t, big_omega_t) = (s.omega_bn_b.z, wheel(&sim));
    let omega_expected = -u * t / i_zz;
    let big_omega_expected = u * t / j_s + u * t / i_zz;
    eprintln!("t = T: ω_z {omega_t} (closed form {omega_expected}), Ω {big_omega_t} ({big_omega_expected})");
    assert!((omega_t - omega_expected).abs() <= 1e-12 * omega_expected.abs());
    assert!((big_omega_t - big_omega_expected).abs() <= 1e-12 * big_omega_expected);
    let h_scale = j_s * big_omega_expected;
    sim.step_n(30_000);
    let s = sim.spacecraft().state();
    let phi = -u * t * t / i_zz;
    let sigma_expected = (phi / 4.0).tan();
    eprintln!(
        "t = 2T: σ_3 {} (closed form {sigma_expected}), ω {:?}, Ω {}",
        s.sigma_bn.z,
        s.omega_bn_b,
        wheel(&sim)
    );
    assert!((s.sigma_bn.z - sigma_expected).abs() <= 1e-9 * sigma_expected.abs());
    assert!(s.sigma_bn.x.abs() < 1e-15 && s.sigma_bn.y.abs() < 1e-15);
    assert!(s.omega_bn_b.norm() <= 1e-12 * omega_expected.abs());
    assert!(wheel(&sim).abs() <= 1e-12 * big_omega_expected);
    let h = sim.spacecraft().conserved().rot_ang_mom_c_n;
    assert!(h.norm() <= 1e-12 * h_scale, "H_C = {h:?}");
    // After 60 s nothing drives the wheel: everything stays at rest.
    sim.step_n(1_000);
    assert!(wheel(&sim).abs() <= 1e-12 * big_omega_expected);
}

#[test]
fn commanded_inputs_add_to_the_scheduled_ones() {
    let cfg = SimConfig::from_toml_str(&slew_text()).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    assert_eq!(sim.scheduled_effector_inputs(), [0.2]);
    // 0.2 scheduled + 0.03 commanded over one step: the rotor's absolute rate gains
    // (u_s + u_c) h / J_s exactly (the hub starts at rest, so ω + Ω = Ω + ω).
    sim.set_effector_inputs(&[0.03]).unwrap();
    sim.step();
    let s = sim.spacecraft().state();
    let absolute = s.effectors[0] + s.omega_bn_b.z;
    let expected = (0.2 + 0.03) * 1e-3 / 0.05;
    assert!(
        (absolute - expected).abs() <= 1e-15,
        "{absolute} vs {expected}"
    );
    // The schedule's next row replaces the scheduled part; the command still adds.
    sim.step_n(29_999);
    assert_eq!(sim.scheduled_effector_inputs(), [0.2]);
    sim.step();
    assert_eq!(sim.t_sim_ns(), 30_001_000_000);
    assert_eq!(sim.scheduled_effector_inputs(), [-0.2]);
    assert_eq!(sim.effector_inputs(), [0.03]);
}
