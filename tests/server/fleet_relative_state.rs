//! The fleet server's RelativeStateMsg (`flexdyn/<deputy>/tlm/rel/<chief>`, protocol 9), end to
//! end over Zenoh: `server::fleet::run` (what `flexdyn run --fleet` calls) in lockstep with one
//! in-process participant (sender 9, listed for both vehicles) that records every StateMsg and
//! answers `NoCommand`, and a subscriber on the deputy's relative-state key.
//!
//! - **Physics.** Each published relative state equals what `world::relative` computes from the
//!   two published StateMsgs of its tick, recomputed here independently: the vehicles are rigid
//!   hubs (no panels, no wheels) whose centre of mass sits at the configured `r_bcb_b_m` from
//!   B, so r_C = r_B + [NB] c_B and v_C = v_B + [NB] (ω × c_B) (transport theorem, c_B fixed in
//!   B), with σ_BN, ω_BN, r_BN, v_BN from the StateMsg. Both sides round differently only in
//!   the last bits of quantities of size |r| ≈ 7e6 m and |v| ≈ 7.5e3 m/s, so they agree to
//!   1e-9 of the relative state's own scale. Taking the hub points B instead (0.55 m away from
//!   C, tumbling) misses by far more, which the test also checks, so it can fail.
//! - **Determinism.** Two runs publish bit-identical relative-state streams, one per tick.

use crate::server_support;

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use flexdyn_campaign::execute::Observer;
use flexdyn_proto::{decode_relative_state, decode_state, Mode, StateMsg, Topics};
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::world::{relative_state_hill, FleetConfig};
use nalgebra::Vector3;
use server_support::{connecting_session, endpoint, FleetServerHandle};
use sha2::{Digest, Sha256};
use zenoh::Wait;

const MU_M3_S2: f64 = 3.986004415e14;
const R_CHIEF_M: f64 = 7.0e6;
/// 10 Hz frames for 20 s.
const TICKS: u64 = 200;
/// \[m\] the hub's centre of mass from B, in B (both vehicles).
const C_B_M: [f64; 3] = [0.1, -0.2, 0.5];

/// A rigid hub (no panels) on a circular orbit inclined 0.9 rad, at attitude `sigma`, tumbling
/// at `omega`.
fn spacecraft_toml(sigma: [f64; 3], omega: [f64; 3]) -> String {
    let v = (MU_M3_S2 / R_CHIEF_M).sqrt();
    let (s, c) = 0.9_f64.sin_cos();
    format!(
        "simulation = {{ step_s = 0.01, frame_hz = 10.0 }}\n\
         gravity = {{ model = \"point_mass\", mu_m3_s2 = {MU_M3_S2:e} }}\n\
         hub = {{ mass_kg = 500.0, inertia_bc_b_kg_m2 = [[300.0, 0.0, 0.0], [0.0, 250.0, 0.0], \
         [0.0, 0.0, 200.0]], r_bcb_b_m = [{:e}, {:e}, {:e}] }}\n\
         initial = {{ r_cn_n_m = [{R_CHIEF_M:e}, 0.0, 0.0], v_cn_n_m_s = [0.0, {:e}, {:e}], \
         sigma_bn = [{:e}, {:e}, {:e}], omega_bn_b_rad_s = [{:e}, {:e}, {:e}] }}\n\
         panel_pairs = []\n",
        C_B_M[0],
        C_B_M[1],
        C_B_M[2],
        v * c,
        v * s,
        sigma[0],
        sigma[1],
        sigma[2],
        omega[0],
        omega[1],
        omega[2],
    )
}

fn fleet() -> FleetConfig {
    let indent = |t: String| t.replace('\n', "\n    ");
    let text = format!(
        "[[vehicles]]\nid = \"chief\"\nparticipants = [9]\n[vehicles.spacecraft]\n    {}\n\
         [[vehicles]]\nid = \"deputy\"\nparticipants = [9]\n[vehicles.spacecraft]\n    {}\n\
         [vehicles.relative]\nchief = \"chief\"\n\
         hill_position_m = [10.0, -100.0, 5.0]\nhill_velocity_m_s = [0.01, 0.0, -0.02]\n",
        indent(spacecraft_toml([0.1, -0.2, 0.05], [0.02, -0.01, 0.03])),
        indent(spacecraft_toml([-0.3, 0.1, 0.2], [-0.03, 0.02, 0.01])),
    );
    FleetConfig::from_toml_str_in(&text, std::path::Path::new("."))
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
}

struct Run {
    chief: Vec<(u64, Vec<u8>)>,
    deputy: Vec<(u64, Vec<u8>)>,
    relative: Vec<(String, Vec<u8>)>,
}

/// (key, payload) of every relative-state sample, in arrival order.
type Samples = Arc<Mutex<Vec<(String, Vec<u8>)>>>;

fn sorted(r: &flexdyn_campaign::execute::Received) -> Vec<(u64, Vec<u8>)> {
    let mut s = r.lock().unwrap().clone();
    s.sort_by_key(|(t, _)| *t);
    s
}

fn run() -> Run {
    let settings = ServerSettings {
        mode: Mode::Lockstep,
        participant_timeout: Duration::from_secs(20),
        presence_timeout: Duration::from_secs(30),
        duration_ns: Some(TICKS * 100_000_000),
        ..ServerSettings::default()
    };
    let server = FleetServerHandle::start(settings, fleet());
    let port = server.port;
    // The relative-state subscriber, declared before the participant makes tick 0 go.
    let session = connecting_session(port);
    let relative: Samples = Arc::default();
    let rec = relative.clone();
    let _sub = session
        .declare_subscriber("flexdyn/deputy/tlm/rel/*")
        .callback(move |s| {
            rec.lock().unwrap().push((
                s.key_expr().as_str().to_owned(),
                s.payload().to_bytes().into_owned(),
            ));
        })
        .wait()
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let chief = Observer::start(&endpoint(port), &Topics::new("chief").unwrap(), 9).unwrap();
    let deputy = Observer::start(&endpoint(port), &Topics::new("deputy").unwrap(), 9).unwrap();
    let report = server
        .join(Duration::from_secs(120))
        .expect("the fleet run failed");
    assert_eq!(report.frames, TICKS);
    let give_up = Instant::now() + Duration::from_secs(10);
    while relative.lock().unwrap().len() < (TICKS + 1) as usize && Instant::now() < give_up {
        std::thread::sleep(Duration::from_millis(10));
    }
    let relative = relative.lock().unwrap().clone();
    Run {
        chief: sorted(&chief.states),
        deputy: sorted(&deputy.states),
        relative,
    }
}

/// r_C, v_C in N from a rigid hub's StateMsg (centre of mass fixed at `C_B_M` in B).
fn com_from_state(s: &StateMsg) -> (Vector3<f64>, Vector3<f64>) {
    let dcm_nb = flexdyn_kernel::attitude::mrp_to_dcm(&Vector3::from(s.sigma_bn)).transpose();
    let c_b = Vector3::from(C_B_M);
    let omega = Vector3::from(s.omega_bn_b_rad_s);
    (
        Vector3::from(s.r_bn_n_m) + dcm_nb * c_b,
        Vector3::from(s.v_bn_n_m_s) + dcm_nb * omega.cross(&c_b),
    )
}

fn digest(payloads: &[(String, Vec<u8>)]) -> String {
    let mut h = Sha256::new();
    for (_, p) in payloads {
        h.update(p);
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
fn the_relative_state_matches_the_published_states_and_repeats_bit_for_bit() {
    let a = run();
    assert_eq!(a.chief.len(), (TICKS + 1) as usize);
    assert_eq!(a.deputy.len(), (TICKS + 1) as usize);
    assert_eq!(
        a.relative.len(),
        (TICKS + 1) as usize,
        "one relative state per tick"
    );
    let n = (MU_M3_S2 / R_CHIEF_M.powi(3)).sqrt();
    let mut worst = 0.0_f64;
    let mut b_point_miss = f64::INFINITY;
    for (k, (key, payload)) in a.relative.iter().enumerate() {
        assert_eq!(key, "flexdyn/deputy/tlm/rel/chief");
        let m = decode_relative_state(payload).unwrap();
        let k = k as u64;
        // Published in tick order (one subscriber, one publisher): seq = tick = k.
        assert_eq!((m.header.tick, m.header.seq), (k, k));
        assert_eq!(
            (
                m.header.spacecraft_id,
                m.chief_spacecraft_id,
                m.deputy_spacecraft_id
            ),
            (2, 1, 2)
        );
        let c = decode_state(&a.chief[k as usize].1).unwrap();
        let d = decode_state(&a.deputy[k as usize].1).unwrap();
        assert_eq!((c.header.tick, d.header.tick), (k, k));
        assert_eq!(m.header.sim_time_ns, d.header.sim_time_ns);
        let (rc, vc) = com_from_state(&c);
        let (rd, vd) = com_from_state(&d);
        let want = relative_state_hill(&rc, &vc, &rd, &vd).unwrap();
        let r_scale = want.range_m;
        let v_scale = want.v_dc_h_m_s.norm() + n * want.range_m;
        let errs = [
            (Vector3::from(m.r_dc_h_m) - want.r_dc_h_m).norm() / r_scale,
            (Vector3::from(m.v_dc_h_m_s) - want.v_dc_h_m_s).norm() / v_scale,
            (m.range_m - want.range_m).abs() / r_scale,
            (m.range_rate_m_s - want.range_rate_m_s).abs() / v_scale,
        ];
        for e in errs {
            worst = worst.max(e);
        }
        // The hub points B are not the centres of mass (the two hubs point differently, so
        // their offsets do not cancel): that recomputation must miss.
        let at_b = relative_state_hill(
            &Vector3::from(c.r_bn_n_m),
            &Vector3::from(c.v_bn_n_m_s),
            &Vector3::from(d.r_bn_n_m),
            &Vector3::from(d.v_bn_n_m_s),
        )
        .unwrap();
        b_point_miss = b_point_miss.min((Vector3::from(m.r_dc_h_m) - at_b.r_dc_h_m).norm());
    }
    println!("largest relative difference to the recomputation: {worst:.3e}");
    println!("smallest miss of the hub-point recomputation: {b_point_miss:.3e} m");
    assert!(worst < 1e-9, "{worst:e}");
    assert!(b_point_miss > 1e-2, "{b_point_miss:e} m");
    // The deputy started at the Hill offset the fleet file gives (to the rounding of N ↔ H).
    let first = decode_relative_state(&a.relative[0].1).unwrap();
    assert!((Vector3::from(first.r_dc_h_m) - Vector3::new(10.0, -100.0, 5.0)).norm() < 1e-6);

    let b = run();
    assert_eq!(
        digest(&a.relative),
        digest(&b.relative),
        "the relative-state stream changed between two lockstep runs"
    );
    println!("relative-state stream sha256 {}", digest(&a.relative));
}
