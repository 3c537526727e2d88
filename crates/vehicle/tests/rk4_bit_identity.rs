//! The default integrator (RK4) after the integrator choice of issue 24 steps every shipped
//! scenario bit for bit as the hand-written RK4 before it did.
//!
//! The golden value was first produced by this test's body on commit 535783c (the last commit
//! with the hand-written RK4 in `Spacecraft::step`), then on the generic Butcher-tableau step:
//! both gave the same hash, which then also covered the IMU Δv integrals kept in the state. The
//! sensor seam moved those out of the state (into the IMU, fed by the step's stage hook), so the
//! hash now covers the state alone and was re-derived on the merge of both changes; the state's
//! bits did not change there: `tests/cli/regress_sensor_outputs.rs` (CSV hashes of whole `simulate`
//! runs, state and sensor columns, pinned on 535783c) and the lockstep hashes of
//! `tools/tests/e2e_lockstep.rs` pass on it. Any change to RK4's floating-point expressions (stage sums, the
//! `(k1 + (k2 + k3)·2 + k4)·(h/6)` combination, the order of the effector passes) changes it.
//! A deliberate change to the dynamics changes it too: then re-derive it on the new code and say
//! so in the commit.

use std::path::Path;

use flexdyn_vehicle::config::SimConfig;

/// FNV-1a over the bit patterns of the end states.
const GOLDEN: u64 = 0x5837_430a_797b_b59b;

#[test]
fn rk4_steps_match_the_hand_written_rk4_bit_for_bit() {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut mix = |x: f64| {
        hash ^= x.to_bits();
        hash = hash.wrapping_mul(0x0100_0000_01b3);
    };
    for file in [
        "reference.toml",
        "imu_tactical.toml",
        "leo_environment.toml",
        "wheel_slew.toml",
        "wheels_star_tracker.toml",
        "eight_pairs.toml",
        "j2_orbit.toml",
        "damped_wing.toml",
    ] {
        let path = Path::new(crate::REPO).join("scenarios").join(file);
        let cfg = SimConfig::from_file(&path).expect("shipped scenario");
        assert_eq!(cfg.integrator.name, "rk4", "{file}: the default");
        let mut sc = cfg.build_spacecraft().expect("builds");
        // Every effector input non-zero, so motors and wheel torques are in the sum.
        let u: Vec<f64> = (0..sc.effector_input_len())
            .map(|i| 0.01 * (i as f64 + 1.0))
            .collect();
        sc.set_effector_inputs(&u).expect("inputs in range");
        for _ in 0..3000 {
            sc.step();
        }
        let s = sc.state();
        for v in [s.r_bn_n, s.v_bn_n, s.sigma_bn, s.omega_bn_b] {
            v.iter().copied().for_each(&mut mix);
        }
        s.effectors.iter().copied().for_each(&mut mix);
    }
    assert_eq!(hash, GOLDEN, "RK4 is no longer bit-identical: {hash:#018x}");
}
