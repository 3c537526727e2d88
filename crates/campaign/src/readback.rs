//! The read-back: every numeric parameter of the model as **built** (not as written), by
//! configuration path, so a campaign proves each dispersion reached the model (`result.json`'s
//! `applied`). [`readback`] reads one spacecraft; [`fleet_readback`] every vehicle of a fleet,
//! each key prefixed with the vehicle's id (`deputy.hub.mass_kg`), and each deputy's initial
//! Hill-frame offset from its chief (`deputy.relative.hill_position_m[1]`), recomputed from the
//! two built spacecraft.

use std::collections::BTreeMap;

use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::world::relative::com_state_n;
use flexdyn_vehicle::world::{relative_state_hill, FleetConfig};

/// Every numeric parameter of the model built from `cfg`, by configuration path: the hub, the
/// initial state (`initial.sigma_bn[i]`, `initial.omega_bn_b_rad_s[i]`, `initial.r_bn_n_m[i]`,
/// `initial.v_bn_n_m_s[i]`), each effector's [`flexdyn_dynamics::StateEffector::parameters`]
/// under its kind's section (`panel_pairs[k].`, `reaction_wheels[k].`: [`flexdyn_dynamics::kinds`]), each dynamic effector's
/// [`flexdyn_dynamics::DynamicEffector::parameters`] (facets, residual dipole), the environment
/// models' (space weather), the epoch's `epoch.offset_s` and each scheduled fault's window
/// (`faults[k].start_s`, `duration_s`, `period_s`).
pub fn readback(
    cfg: &SimConfig,
) -> Result<BTreeMap<String, f64>, flexdyn_vehicle::config::ConfigError> {
    let sc = cfg.build_spacecraft()?;
    let mut out = BTreeMap::new();
    let hub = sc.hub();
    out.insert("hub.mass_kg".to_owned(), hub.mass_kg);
    for i in 0..3 {
        out.insert(format!("hub.r_bcb_b_m[{i}]"), hub.r_bcb_b_m[i]);
        for j in 0..3 {
            out.insert(
                format!("hub.inertia_bc_b_kg_m2[{i}][{j}]"),
                hub.inertia_bc_b_kg_m2[(i, j)],
            );
        }
    }
    let x = sc.state();
    for i in 0..3 {
        out.insert(format!("initial.sigma_bn[{i}]"), x.sigma_bn[i]);
        out.insert(format!("initial.omega_bn_b_rad_s[{i}]"), x.omega_bn_b[i]);
        out.insert(format!("initial.r_bn_n_m[{i}]"), x.r_bn_n[i]);
        out.insert(format!("initial.v_bn_n_m_s[{i}]"), x.v_bn_n[i]);
    }
    let mut per_kind: BTreeMap<&str, usize> = BTreeMap::new();
    let mut params = Vec::new();
    for (e, range) in sc.effectors().iter().zip(sc.effector_ranges()) {
        let section =
            flexdyn_dynamics::kinds::by_name(e.kind().name).map_or(e.kind().name, |k| k.section);
        let k = per_kind.entry(section).or_insert(0);
        params.clear();
        e.parameters(&x.effectors[range.clone()], &mut params);
        for (key, v) in &params {
            out.insert(format!("{section}[{k}].{key}"), *v);
        }
        *k += 1;
    }
    // The sensors as built, each kind's entries counted in file order.
    let bank = cfg.frame_sensor_bank(x)?;
    let mut per_array: BTreeMap<&str, usize> = BTreeMap::new();
    for s in bank.sensors() {
        let section = s.kind().config_array;
        let k = per_array.entry(section).or_insert(0);
        params.clear();
        s.parameters(&mut params);
        for (key, v) in &params {
            out.insert(format!("{section}[{k}].{key}"), *v);
        }
        *k += 1;
    }
    let mut params = Vec::new();
    for d in sc.dynamic_effectors() {
        d.parameters(&mut params);
    }
    if let Some(epoch) = &cfg.epoch {
        params.push(("epoch.offset_s".to_owned(), epoch.offset_s()));
    }
    if let Some(env) = cfg.environment_model()? {
        env.parameters(&mut params);
    }
    out.extend(params);
    // Each scheduled fault's window as resolved (a random fault's start is its drawn failure
    // time, not a parameter: its `mtbf_s` and seed are).
    for (k, f) in cfg.faults.iter().enumerate() {
        if f.source != flexdyn_proto::FaultSource::Config {
            continue;
        }
        let w = &f.window;
        for (field, ns) in
            FAULT_WINDOW_FIELDS
                .iter()
                .zip([Some(w.start_ns), w.duration_ns, w.period_ns])
        {
            if let Some(ns) = ns {
                out.insert(format!("faults[{k}].{field}"), ns as f64 * 1e-9);
            }
        }
    }
    Ok(out)
}

/// The fields of a fault's window (`faults[k].<field>`), in seconds, which the configuration
/// takes only in whole nanoseconds: what [`readback`] reads back of a scheduled fault, what a
/// campaign rounds a draw of to the nanosecond, and all a forked campaign may disperse.
pub const FAULT_WINDOW_FIELDS: [&str; 3] = ["start_s", "duration_s", "period_s"];

/// `x` \[s\] to the nearest whole nanosecond, `None` if it is not a time (not finite, < 0,
/// beyond `u64` nanoseconds): the configuration's own conversion
/// ([`flexdyn_kernel::schema::checks::round_ns`]) of the rounded value.
pub fn nearest_ns(x: f64) -> Option<u64> {
    flexdyn_kernel::schema::checks::round_ns((x * 1e9).round())
}

/// Every vehicle's [`readback`], keys prefixed with `<id>.`, and for each vehicle given relative
/// to a chief its initial offset in the chief's Hill frame as the two built spacecraft have it:
/// `<id>.relative.hill_position_m[i]` and `<id>.relative.hill_velocity_m_s[i]`, from their
/// centres of mass ([`com_state_n`]) through [`relative_state_hill`]. That is an independent
/// reader of what [`flexdyn_vehicle::world::fleet`] wrote into the deputy's initial state: the offset
/// goes to N and comes back, so it equals the dispersed value to the rounding of positions of
/// about 7e6 m (≈ 1e-9 m), not bit for bit. An error names the vehicle.
pub fn fleet_readback(fleet: &FleetConfig) -> Result<BTreeMap<String, f64>, String> {
    let mut out = BTreeMap::new();
    let mut built = Vec::with_capacity(fleet.vehicles.len());
    for v in &fleet.vehicles {
        let named = |e: flexdyn_vehicle::config::ConfigError| format!("vehicle {:?}: {e}", v.id);
        for (k, x) in readback(&v.cfg).map_err(named)? {
            out.insert(format!("{}.{k}", v.id), x);
        }
        built.push(v.cfg.build_spacecraft().map_err(named)?);
    }
    for (d, v) in fleet.vehicles.iter().enumerate() {
        let Some(c) = v.chief else { continue };
        let (r_c, v_c) = com_state_n(&built[c]);
        let (r_d, v_d) = com_state_n(&built[d]);
        let rel = relative_state_hill(&r_c, &v_c, &r_d, &v_d).ok_or_else(|| {
            format!(
                "vehicle {:?}: its chief {:?} has no Hill frame",
                v.id, fleet.vehicles[c].id
            )
        })?;
        for i in 0..3 {
            out.insert(
                format!("{}.relative.hill_position_m[{i}]", v.id),
                rel.r_dc_h_m[i],
            );
            out.insert(
                format!("{}.relative.hill_velocity_m_s[{i}]", v.id),
                rel.v_dc_h_m_s[i],
            );
        }
    }
    Ok(out)
}
