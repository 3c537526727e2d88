//! The environment message (`flexdyn/<sc>/tlm/env`, `EnvironmentMsg`) of a real server: it
//! arrives at `[environment] telemetry_rate_hz` (every 10th frame at 100 Hz), after the state of
//! its tick, and every field agrees with an independent computation at the published state:
//! - B in N with the IGRF-14 chain rebuilt here (epoch → Earth rotation → r in E → IGRF → N), and
//!   B in B with the published attitude;
//! - the Sun direction with the analytic ephemeris at the tick's TT, from the published position;
//! - the gravity-gradient torque and force with the closed forms (GG2, GG3 of
//!   `dynamics/dynamic_effectors/gravity_gradient`) on the rigid hub's inertia about its centre
//!   of mass, moved to B (τ_B = τ_C + c × F);
//! - the residual dipole's torque as m × B_B with B_B from the message;
//! - drag and solar pressure as those effectors evaluated directly at the published state with a
//!   sample filled afresh by an environment model built here;
//! - TAI with the time message of the same tick.
//!
//! The umbra check uses the simulation directly: the spacecraft placed behind the Earth on the
//! anti-Sun line reads shadow factor 0 and eclipse UMBRA, on the Sun side 1 and SUNLIT.

use crate::server_support;

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use flexdyn_dynamics::dynamic_effectors::{
    aero_drag::AeroDrag, gravity_gradient, solar_pressure::SolarPressure,
};
use flexdyn_dynamics::{DynamicEffector, StageState, Wrench};
use flexdyn_environment::earth_rotation::EarthRotation;
use flexdyn_environment::ephemeris::sun_position_n_m;
use flexdyn_environment::facets::{FacetModel, SOLAR_IRRADIANCE_1AU_W_M2};
use flexdyn_environment::magnetic::Igrf;
use flexdyn_environment::model::EnvironmentModel;
use flexdyn_environment::prefetch::Request;
use flexdyn_environment::EnvironmentSample;
use flexdyn_kernel::attitude::mrp_to_dcm;
use flexdyn_proto::{
    decode_environment, decode_state, decode_time, eclipse, environment_flags, EnvironmentMsg,
    Mode, StateMsg, TimeMsg, Topics,
};
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use nalgebra::{Matrix3, Vector3};
use server_support::{
    connecting_session, listening_session, wait_for_subscriber, wait_until, ServerHandle,
};
use zenoh::Wait;

const MU_M3_S2: f64 = 3.986_004_418e14;

/// `scenarios/leo_environment.toml` (every environment model on, `telemetry_rate_hz = 10`) with
/// a rigid hub (no panels, no sensors), so the vehicle's mass properties are known here.
fn rigid_leo() -> SimConfig {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/leo_environment.toml"
    );
    let leo = std::fs::read_to_string(path).unwrap();
    let world = &leo[..leo.find("[hub]").unwrap()];
    let text = format!(
        "panel_pairs = []\n{world}\n[hub]\nmass_kg = 750.0\n\
         inertia_bc_b_kg_m2 = [[900.0, 10.0, -5.0], [10.0, 800.0, 3.0], [-5.0, 3.0, 600.0]]\n\
         r_bcb_b_m = [0.02, -0.01, 0.3]\n"
    );
    SimConfig::from_toml_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

#[derive(Default)]
struct Seen {
    /// Keys in arrival order, with their header tick.
    order: Vec<(String, u64)>,
    states: BTreeMap<u64, StateMsg>,
    times: BTreeMap<u64, TimeMsg>,
    envs: Vec<EnvironmentMsg>,
}

fn run(cfg: SimConfig, duration_s: f64) -> Seen {
    let settings = ServerSettings {
        mode: Mode::RealTime,
        duration_ns: Some((duration_s * 1e9) as u64),
        speed: 2.0,
        status_hz: 5.0,
        ..ServerSettings::default()
    };
    let topics = Topics::new(&settings.sc_id).unwrap();
    // The subscriber is declared before the run starts: a 1 s run at speed 2 lasts 0.5 s, and a
    // subscriber that joined after the server had started missed every message but the last
    // (CI: "first environment message at tick 100").
    let (server_session, port) = listening_session();
    let session = connecting_session(port);
    let seen: Arc<Mutex<Seen>> = Arc::default();
    let s = seen.clone();
    let (env_key, state_key, time_key) = (
        topics.environment(),
        topics.state().to_owned(),
        topics.time(),
    );
    let _sub = session
        .declare_subscriber(topics.telemetry_wildcard())
        .callback(move |sample| {
            let key = sample.key_expr().as_str().to_owned();
            let bytes = sample.payload().to_bytes();
            let mut s = s.lock().unwrap();
            let tick = if key == env_key {
                let m = decode_environment(&bytes).expect("an EnvironmentMsg");
                s.envs.push(m);
                m.header.tick
            } else if key == state_key {
                let m = decode_state(&bytes).expect("a StateMsg");
                let tick = m.header.tick;
                s.states.insert(tick, m);
                tick
            } else if key == time_key {
                let m = decode_time(&bytes).expect("a TimeMsg");
                s.times.insert(m.header.tick, m);
                m.header.tick
            } else {
                return;
            };
            s.order.push((key, tick));
        })
        .wait()
        .unwrap();
    wait_for_subscriber(&server_session, &topics.environment());
    let mut server = ServerHandle::start_with_session(server_session, settings, cfg);
    let report = server.join(Duration::from_secs(60));
    server.stop();
    report.expect("the run ends normally");
    wait_until(Duration::from_secs(2), || false);
    let out = std::mem::take(&mut *seen.lock().unwrap());
    out
}

fn v(a: [f64; 3]) -> Vector3<f64> {
    Vector3::from(a)
}

/// `|a − b| ≤ rel · |b|` (or `abs` for a zero `b`), with a message naming `what`.
fn close(a: Vector3<f64>, b: Vector3<f64>, rel: f64, what: &str) {
    let tol = (rel * b.norm()).max(1e-300);
    assert!((a - b).norm() <= tol, "{what}: {a:?} vs {b:?}");
}

#[test]
fn environment_message_at_its_rate_agrees_with_independent_models() {
    let cfg = rigid_leo();
    let env_cfg = cfg.environment.clone().unwrap();
    assert_eq!(env_cfg.telemetry_every_frames, Some(10), "10 Hz at 100 Hz");
    let seen = run(cfg.clone(), 1.0);
    let frame_ns = cfg.frame_ns;

    // The rate: ticks 0, 10, …, 100 (1 s at 100 Hz), seq counting the messages. Real time
    // drops under congestion, and the subscriber may join after tick 0 on a loaded machine:
    // every message from the first one on, none between.
    let ticks: Vec<u64> = seen.envs.iter().map(|m| m.header.tick).collect();
    let first = *ticks.first().expect("environment messages");
    assert!(first <= 10, "first environment message at tick {first}");
    assert_eq!(ticks, (first..=100).step_by(10).collect::<Vec<_>>());
    for m in &seen.envs {
        assert_eq!(m.header.seq, m.header.tick / 10);
        assert_eq!(m.header.sim_time_ns, m.header.tick * frame_ns);
    }
    // Published after the state of its tick.
    for m in &seen.envs {
        let k = m.header.tick;
        let pos = |suffix: &str| {
            seen.order
                .iter()
                .position(|(key, t)| *t == k && key.ends_with(suffix))
                .unwrap_or_else(|| panic!("no {suffix} at tick {k}"))
        };
        assert!(pos("/tlm/state") < pos("/tlm/env"), "tick {k}");
    }

    let epoch = cfg.epoch.as_ref().unwrap();
    let igrf = Igrf::igrf14(13).unwrap();
    let rotation = EarthRotation::new(epoch.earth_orientation());
    let model = EnvironmentModel::new(&env_cfg, epoch).unwrap();
    let facets = FacetModel::new(env_cfg.facets.clone()).unwrap();
    let residual_m_b_am2 = env_cfg.residual_dipole_m_b_am2.unwrap();
    let (mass_kg, c_b, inertia_c) = (
        cfg.hub.mass_kg,
        cfg.hub.r_bcb_b_m,
        cfg.hub.inertia_bc_b_kg_m2,
    );
    let mut saw_torque = [false; 4];
    let mut checked = 0;
    for m in &seen.envs {
        let k = m.header.tick;
        let t = m.header.sim_time_ns;
        let st = &seen.states[&k];
        let r_n = v(st.r_bn_n_m);
        let v_n = v(st.v_bn_n_m_s);
        let dcm_bn = mrp_to_dcm(&v(st.sigma_bn));
        // Where the models were evaluated: at the state itself for the first update (t = 0),
        // else at the position predicted from the state of the update before, 10 ticks earlier
        // (`environment::prefetch::Request::predicted`). Without that state (the subscriber
        // joined late), this message is skipped.
        let r_model_n = if k == 0 {
            r_n
        } else {
            match seen.states.get(&(k - 10)) {
                Some(p) => {
                    let t0 = (k - 10) * frame_ns;
                    Request::predicted(t0, &v(p.r_bn_n_m), &v(p.v_bn_n_m_s), t).r_bn_n_m
                }
                None => continue,
            }
        };
        // A rigid hub: the prediction is the state to ½|J2|Δ² ≤ 1.2e-4 m.
        assert!((r_model_n - r_n).norm() < 1.2e-4, "tick {k}");
        checked += 1;
        assert_eq!(
            m.flags,
            environment_flags::EPOCH_VALID
                | environment_flags::MAGNETIC
                | environment_flags::SUN
                | environment_flags::MOON
                | environment_flags::SHADOW
                | environment_flags::ATMOSPHERE
        );
        assert_eq!(m.tai_ns_1958, seen.times[&k].tai_ns_1958, "tick {k} TAI");

        // B: the IGRF chain at the published position and time.
        let times = epoch.times(t);
        let earth = rotation.at(&times);
        let year = epoch.utc_calendar(t).decimal_year();
        let b_n = earth.dcm_ne() * igrf.field_ecef_t(year, &earth.r_e(&r_model_n));
        close(v(m.b_n_t), b_n, 1e-12, "B in N");
        close(v(m.b_b_t), dcm_bn * v(m.b_n_t), 1e-14, "B in B");
        let b_ut = b_n.norm() * 1e6;
        assert!((18.0..54.0).contains(&b_ut), "|B| = {b_ut} µT at 500 km");

        // The Sun direction from the published position.
        let sun_n = (sun_position_n_m(times.tt_centuries_j2000()) - r_model_n).normalize();
        close(v(m.sun_n), sun_n, 1e-14, "Sun in N");
        close(v(m.sun_b), dcm_bn * sun_n, 1e-14, "Sun in B");
        assert!((v(m.moon_n).norm() - 1.0).abs() < 1e-14);
        assert_eq!(m.eclipse, eclipse::of_shadow_factor(m.shadow_factor));
        assert!(m.density_kg_m3 > 1e-14 && m.density_kg_m3 < 1e-11, "500 km");

        // Gravity gradient: closed forms on the rigid hub about its centre of mass C, then at B.
        let r_cn_b = dcm_bn * r_n + c_b;
        let f_gg = gravity_gradient::force_b_newton(MU_M3_S2, &r_cn_b, &inertia_c);
        let tau_gg =
            gravity_gradient::torque_c_b_nm(MU_M3_S2, &r_cn_b, &inertia_c) + c_b.cross(&f_gg);
        close(v(m.gravity_gradient.torque_b_nm), tau_gg, 1e-9, "GG torque");
        close(v(m.gravity_gradient.force_b_newton), f_gg, 1e-9, "GG force");

        // Residual dipole: m × B_B, no force.
        close(
            v(m.residual_dipole.torque_b_nm),
            residual_m_b_am2.cross(&v(m.b_b_t)),
            1e-14,
            "dipole torque",
        );
        assert_eq!(m.residual_dipole.force_b_newton, [0.0; 3]);

        // Drag and solar pressure: the effectors at the published state, in a sample filled
        // afresh here (every message's tick is an update instant of the 10 Hz sample).
        let mut sample = EnvironmentSample::NONE;
        model.fill(t, &r_model_n, &v_n, &mut sample);
        let stage = StageState {
            t_step_ns: t,
            dt_stage_s: 0.0,
            r_bn_n_m: r_n,
            v_bn_n_m_s: v_n,
            sigma_bn: v(st.sigma_bn),
            dcm_bn,
            omega_bn_b_rad_s: v(st.omega_bn_b_rad_s),
            mass_kg,
            r_cb_b_m: c_b,
            r_cn_n_m: r_n + dcm_bn.transpose() * c_b,
            inertia_pnt_b_b_kg_m2: inertia_c
                + (Matrix3::from_diagonal_element(c_b.norm_squared()) - c_b * c_b.transpose())
                    * mass_kg,
        };
        let direct = |e: &mut dyn DynamicEffector| {
            let mut w = Wrench::ZERO;
            e.add_force_torque(&stage, &sample, &mut w);
            w
        };
        let drag = direct(&mut AeroDrag {
            facets: facets.clone(),
        });
        let srp = direct(&mut SolarPressure::new(
            facets.clone(),
            SOLAR_IRRADIANCE_1AU_W_M2,
        ));
        close(
            v(m.drag.torque_b_nm),
            drag.torque_b_nm,
            1e-12,
            "drag torque",
        );
        close(
            v(m.drag.force_b_newton),
            drag.force_b_newton,
            1e-12,
            "drag force",
        );
        close(
            v(m.solar_pressure.torque_b_nm),
            srp.torque_b_nm,
            1e-12,
            "SRP torque",
        );
        close(
            v(m.solar_pressure.force_b_newton),
            srp.force_b_newton,
            1e-12,
            "SRP force",
        );
        for (i, w) in [
            m.gravity_gradient,
            m.drag,
            m.solar_pressure,
            m.residual_dipole,
        ]
        .iter()
        .enumerate()
        {
            saw_torque[i] |= v(w.torque_b_nm).norm() > 0.0;
        }
    }
    // Every source acted at some point (none of the checks above passed on zeros alone) — SRP
    // only if the run was in sunlight.
    assert!(
        checked >= 9,
        "only {checked} messages had the state of the update before"
    );
    let sunlit = seen.envs.iter().any(|m| m.shadow_factor > 0.0);
    assert_eq!(saw_torque, [true, true, sunlit, true]);
}

/// Behind the Earth on the anti-Sun line the shadow factor is 0 (umbra), on the Sun side 1,
/// and the eclipse state says so; the solar pressure is zero in umbra.
#[test]
fn umbra_and_sunlight_at_placed_positions() {
    let cfg = rigid_leo();
    let mut sim = Simulation::new(&cfg).unwrap();
    // Step to the 10 Hz sample's next update instant, so the record refills at the new position.
    sim.step_n(100);
    let epoch = cfg.epoch.as_ref().unwrap();
    let t = sim.t_sim_ns();
    let sun_hat = sun_position_n_m(epoch.times(t).tt_centuries_j2000()).normalize();
    let mut read = |r_n: Vector3<f64>| {
        let mut x = sim.spacecraft().state().clone();
        x.r_bn_n = r_n;
        sim.spacecraft_mut().set_state(&x).unwrap();
        let mut m = EnvironmentMsg::default();
        sim.environment_into(&mut m);
        m
    };
    let deep = read(-sun_hat * 6_878_000.0);
    assert_eq!((deep.shadow_factor, deep.eclipse), (0.0, eclipse::UMBRA));
    assert_eq!(deep.solar_pressure.force_b_newton, [0.0; 3]);
    let lit = read(sun_hat * 6_878_000.0);
    assert_eq!((lit.shadow_factor, lit.eclipse), (1.0, eclipse::SUNLIT));
    assert!(v(lit.solar_pressure.force_b_newton).norm() > 0.0);
}

/// A rate that is not the frame rate over a whole number, and a non-positive one, are refused
/// naming `environment.telemetry_rate_hz`.
#[test]
fn telemetry_rate_errors_name_the_field() {
    let text = rigid_leo().source_toml.clone();
    for (rate, problem) in [("30.0", "whole number"), ("-1.0", "")] {
        let bad = text.replace(
            "telemetry_rate_hz = 10.0",
            &format!("telemetry_rate_hz = {rate}"),
        );
        assert_ne!(bad, text);
        let e = SimConfig::from_toml_str(&bad).unwrap_err().to_string();
        assert!(
            e.contains("environment.telemetry_rate_hz") && e.contains(problem),
            "{e}"
        );
    }
}

/// `simulate` writes the environment record's fields as `env_*` columns when
/// `telemetry_rate_hz` is set (none without it), and each row's values agree with that row's
/// state: B_B = [BN(σ)] B_N, the dipole torque is m × B_B, the Sun direction is a unit vector,
/// and the eclipse state is the shadow factor's.
#[test]
fn simulate_writes_consistent_environment_columns() {
    let cfg = rigid_leo();
    let mut out = Vec::new();
    flexdyn::commands::simulate::simulate_to(&cfg, 1.0, 0.1, &mut out, "test").unwrap();
    let text = String::from_utf8(out).unwrap();
    let mut lines = text.lines().skip_while(|l| l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 11);
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let vec3 = |row: &[f64], base: &str| {
        Vector3::new(
            row[col(&format!("{base}_1"))],
            row[col(&format!("{base}_2"))],
            row[col(&format!("{base}_3"))],
        )
    };
    let m_b_am2 = cfg
        .environment
        .as_ref()
        .unwrap()
        .residual_dipole_m_b_am2
        .unwrap();
    for row in &rows {
        let dcm_bn = mrp_to_dcm(&vec3(row, "sigma_bn"));
        let b_n = vec3(row, "env_b_n_t");
        let b_b = vec3(row, "env_b_b_t");
        assert!(b_n.norm() > 1e-5, "a field at 500 km");
        close(b_b, dcm_bn * b_n, 1e-14, "CSV B in B");
        close(
            vec3(row, "env_residual_dipole_torque_b_nm"),
            m_b_am2.cross(&b_b),
            1e-14,
            "CSV dipole torque",
        );
        assert!((vec3(row, "env_sun_n").norm() - 1.0).abs() < 1e-14);
        let nu = row[col("env_shadow_factor")];
        assert_eq!(
            row[col("env_eclipse")],
            f64::from(eclipse::of_shadow_factor(nu))
        );
        assert!(vec3(row, "env_gravity_gradient_torque_b_nm").norm() > 0.0);
        assert!(row[col("env_density_kg_m3")] > 0.0);
    }
    // Without the setting: no environment columns.
    let plain =
        SimConfig::from_toml_str(&cfg.source_toml.replace("telemetry_rate_hz = 10.0", "")).unwrap();
    let mut out = Vec::new();
    flexdyn::commands::simulate::simulate_to(&plain, 0.1, 0.1, &mut out, "test").unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(
        !text.contains("env_"),
        "no env_ columns without telemetry_rate_hz"
    );
}
