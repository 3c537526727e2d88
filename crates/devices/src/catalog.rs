//! What a server's vehicle offers the devices: every sensor's sample fields as named channels
//! (the device descriptions' sources), every commandable actuator as a named input (their
//! destinations), and the copy of each complete tick into the flat arrays the device engine
//! reads, and of the inputs into a `CommandMsg`.
//!
//! The names, with their SI units (a description may ask for another unit of the same
//! dimension; the engine converts):
//!
//! | group | fields |
//! |---|---|
//! | `imu.<name>` | `omega_p_rad_s[0..2]` rad/s, `accel_p_m_s2[0..2]` m/s^2, `dtheta_p_rad[0..2]` rad, `dv_p_m_s[0..2]` m/s, `saturation_flags` |
//! | `star_tracker.<name>` | `q_cn[0..3]` (scalar first), `valid` (1/0), `status_flags` |
//! | `magnetometer.<name>` | `b_s_t[0..2]` T, `saturation_flags` |
//! | `css.<name>` | `readings[0..K-1]` (the array's output unit) |
//! | `fss.<name>` | `alpha_rad`, `beta_rad` rad, `valid` (1/0), `flags` |
//! | `gps.<name>` | `gps_week`, `gps_seconds_of_week` s, `r_be_e_m[0..2]` m, `v_be_e_m_s[0..2]` m/s, `r_bn_n_m[0..2]` m, `v_bn_n_m_s[0..2]` m/s, `valid` (1/0: a fix), `flags` |
//! | `wheel.<name>` | `speed_rad_s` rad/s, `torque_nm` N m (applied), fresh every tick |
//!
//! Inputs: `wheel.<name>.torque_nm` (N m, the motor torque), `magnetorquer.<name>.dipole_am2`
//! (A m^2).
//!
//! A sensor's channels hold its last sample between samples; `fresh` says which groups
//! published at the tick.

use flexdyn_gateway::device::Catalog;
use flexdyn_proto::client::lockstep::Tick;
use flexdyn_proto::client::vehicle::VehicleConfig;
use flexdyn_proto::{effector_kind, fss_flags, gps_flags, EffectorInput};

/// Where each group's channels start in the value array, by sensor kind, in configuration order.
#[derive(Clone, Debug)]
pub struct VehicleCatalog {
    catalog: Catalog,
    imus: Vec<(usize, usize)>,
    trackers: Vec<(usize, usize)>,
    magnetometers: Vec<(usize, usize)>,
    css: Vec<(usize, usize, usize)>,
    fss: Vec<(usize, usize)>,
    gps: Vec<(usize, usize)>,
    /// (group, first channel, effector index) of each wheel.
    wheels: Vec<(usize, usize, u32)>,
    /// The effector index of each input, in input order.
    input_effectors: Vec<u32>,
}

fn vector(prefix: &str, unit: &'static str, n: usize) -> Vec<(String, &'static str)> {
    (0..n).map(|i| (format!("{prefix}[{i}]"), unit)).collect()
}

impl VehicleCatalog {
    /// The channels and inputs of a served configuration.
    pub fn from_config(cfg: &VehicleConfig) -> Self {
        let frame_ns = (1e9 / cfg.simulation.frame_hz).round() as u64;
        let mut c = Self {
            catalog: Catalog::new(frame_ns),
            imus: Vec::new(),
            trackers: Vec::new(),
            magnetometers: Vec::new(),
            css: Vec::new(),
            fss: Vec::new(),
            gps: Vec::new(),
            wheels: Vec::new(),
            input_effectors: Vec::new(),
        };
        let add = |cat: &mut Catalog, group: String, fields: Vec<(String, &'static str)>| {
            let f: Vec<(&str, &str)> = fields.iter().map(|(n, u)| (n.as_str(), *u)).collect();
            let first = cat.channel_count();
            (cat.add_group(&group, &f), first)
        };
        for imu in &cfg.imus {
            let mut f = vector("omega_p_rad_s", "rad/s", 3);
            f.extend(vector("accel_p_m_s2", "m/s^2", 3));
            f.extend(vector("dtheta_p_rad", "rad", 3));
            f.extend(vector("dv_p_m_s", "m/s", 3));
            f.push(("saturation_flags".into(), "1"));
            let g = add(&mut c.catalog, format!("imu.{}", imu.name), f);
            c.imus.push(g);
        }
        for st in &cfg.star_trackers {
            let mut f = vector("q_cn", "1", 4);
            f.push(("valid".into(), "1"));
            f.push(("status_flags".into(), "1"));
            let g = add(&mut c.catalog, format!("star_tracker.{}", st.name), f);
            c.trackers.push(g);
        }
        for m in &cfg.magnetometers {
            let mut f = vector("b_s_t", "T", 3);
            f.push(("saturation_flags".into(), "1"));
            let g = add(&mut c.catalog, format!("magnetometer.{}", m.name), f);
            c.magnetometers.push(g);
        }
        for a in &cfg.coarse_sun_sensors {
            let k = a.normals_b.len().min(16);
            let (g, first) = add(
                &mut c.catalog,
                format!("css.{}", a.name),
                vector("readings", "1", k),
            );
            c.css.push((g, first, k));
        }
        for s in &cfg.fine_sun_sensors {
            let f = vec![
                ("alpha_rad".into(), "rad"),
                ("beta_rad".into(), "rad"),
                ("valid".into(), "1"),
                ("flags".into(), "1"),
            ];
            let g = add(&mut c.catalog, format!("fss.{}", s.name), f);
            c.fss.push(g);
        }
        for r in &cfg.gps_receivers {
            let mut f = vec![
                ("gps_week".to_owned(), "1"),
                ("gps_seconds_of_week".to_owned(), "s"),
            ];
            f.extend(vector("r_be_e_m", "m", 3));
            f.extend(vector("v_be_e_m_s", "m/s", 3));
            f.extend(vector("r_bn_n_m", "m", 3));
            f.extend(vector("v_bn_n_m_s", "m/s", 3));
            f.push(("valid".into(), "1"));
            f.push(("flags".into(), "1"));
            let g = add(&mut c.catalog, format!("gps.{}", r.name), f);
            c.gps.push(g);
        }
        let first_wheel = cfg.first_wheel_index();
        for (j, w) in cfg.reaction_wheels.iter().enumerate() {
            let f = vec![("speed_rad_s".into(), "rad/s"), ("torque_nm".into(), "N m")];
            let (g, first) = add(&mut c.catalog, format!("wheel.{}", w.name), f);
            c.wheels.push((g, first, first_wheel + j as u32));
        }
        for (j, w) in cfg.reaction_wheels.iter().enumerate() {
            c.catalog
                .add_input(&format!("wheel.{}.torque_nm", w.name), "N m");
            c.input_effectors.push(first_wheel + j as u32);
        }
        let first_rod = cfg.first_magnetorquer_index();
        for (j, m) in cfg.magnetorquers.iter().enumerate() {
            c.catalog
                .add_input(&format!("magnetorquer.{}.dipole_am2", m.name), "A m^2");
            c.input_effectors.push(first_rod + j as u32);
        }
        c
    }

    /// The names the device descriptions resolve against.
    pub fn catalog(&self) -> &Catalog {
        &self.catalog
    }

    /// Copies a complete tick into `values` (its channels) and `fresh` (its groups that
    /// published at the tick); channels of a sensor that did not publish keep their last value.
    pub fn fill(&self, tick: &Tick, values: &mut [f64], fresh: &mut [bool]) {
        fresh.fill(false);
        let mut put = |group: usize, first: usize, xs: &[f64]| {
            fresh[group] = true;
            values[first..first + xs.len()].copy_from_slice(xs);
        };
        for (&(g, first), m) in self.imus.iter().zip(&tick.imus) {
            if let Some(m) = m {
                let mut x = [0.0; 13];
                x[0..3].copy_from_slice(&m.omega_p_rad_s);
                x[3..6].copy_from_slice(&m.accel_p_m_s2);
                x[6..9].copy_from_slice(&m.dtheta_p_rad);
                x[9..12].copy_from_slice(&m.dv_p_m_s);
                x[12] = f64::from(m.saturation_flags);
                put(g, first, &x);
            }
        }
        for (&(g, first), m) in self.trackers.iter().zip(&tick.star_trackers) {
            if let Some(m) = m {
                let mut x = [0.0; 6];
                x[0..4].copy_from_slice(&m.q_cn);
                x[4] = f64::from(u8::from(m.valid));
                x[5] = f64::from(m.status_flags);
                put(g, first, &x);
            }
        }
        for (&(g, first), m) in self.magnetometers.iter().zip(&tick.magnetometers) {
            if let Some(m) = m {
                put(
                    g,
                    first,
                    &[
                        m.b_s_t[0],
                        m.b_s_t[1],
                        m.b_s_t[2],
                        f64::from(m.saturation_flags),
                    ],
                );
            }
        }
        for (&(g, first, k), m) in self.css.iter().zip(&tick.coarse_sun_sensors) {
            if let Some(m) = m {
                put(g, first, &m.readings[..k]);
            }
        }
        for (&(g, first), m) in self.fss.iter().zip(&tick.fine_sun_sensors) {
            if let Some(m) = m {
                let valid = m.flags & fss_flags::VALID != 0;
                put(
                    g,
                    first,
                    &[
                        m.alpha_rad,
                        m.beta_rad,
                        f64::from(u8::from(valid)),
                        f64::from(m.flags),
                    ],
                );
            }
        }
        for (&(g, first), m) in self.gps.iter().zip(&tick.gps_receivers) {
            if let Some(m) = m {
                let mut x = [0.0; 16];
                x[0] = f64::from(m.gps_week);
                x[1] = m.gps_seconds_of_week;
                x[2..5].copy_from_slice(&m.r_be_e_m);
                x[5..8].copy_from_slice(&m.v_be_e_m_s);
                x[8..11].copy_from_slice(&m.r_bn_n_m);
                x[11..14].copy_from_slice(&m.v_bn_n_m_s);
                x[14] = f64::from(u8::from(m.flags & gps_flags::FIX != 0));
                x[15] = f64::from(m.flags);
                put(g, first, &x);
            }
        }
        for &(g, first, e) in &self.wheels {
            if let Some(w) = tick
                .state
                .effectors
                .get(e as usize)
                .filter(|w| w.kind == effector_kind::REACTION_WHEEL && !w.states.is_empty())
            {
                let torque = w.outputs.first().copied().unwrap_or(0.0);
                put(g, first, &[w.states[0], torque]);
            }
        }
    }

    /// The effector inputs of a command from `inputs` (the catalog's input order).
    pub fn effector_inputs(&self, inputs: &[f64]) -> Vec<EffectorInput> {
        self.input_effectors
            .iter()
            .zip(inputs)
            .map(|(&effector_index, &v)| EffectorInput {
                effector_index,
                values: vec![v],
            })
            .collect()
    }
}
