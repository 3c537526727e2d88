//! The vehicle a server runs, as its `flexdyn/<sc>/config` queryable describes it
//! (proto/README.md, "Topics"): the reply's JSON, and the parts of the configuration TOML that
//! flight code reads — the frame rate, the mass properties and mountings, the wheels and the
//! sensors with their rates. The TOML keys are the server's (docs/guides/configuration.md); every
//! other key is ignored, and the server has validated the file before serving it.

use std::time::{Duration, Instant};

use crate::Topics;
use serde::Deserialize;
use zenoh::{Session, Wait};

/// Why the vehicle description cannot be had.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum VehicleError {
    /// No server answered the query in time.
    #[error(
        "no answer on {key} within {timeout_s} s: is a flexdyn server running with this sc_id \
         at the --connect endpoint?"
    )]
    NoAnswer {
        /// The queryable's key.
        key: String,
        /// How long it was asked \[s\].
        timeout_s: f64,
    },
    /// Zenoh refused the query.
    #[error("cannot query {key}: {message}")]
    Zenoh {
        /// The queryable's key.
        key: String,
        /// Zenoh's message.
        message: String,
    },
    /// The reply is not a vehicle description.
    #[error("{key}: the reply is not a flexdyn vehicle description: {message}")]
    Reply {
        /// The queryable's key.
        key: String,
        /// What is wrong with it.
        message: String,
    },
    /// The configuration TOML lacks what flight code needs, or a value is unusable.
    #[error("the served configuration: {0}")]
    Config(String),
}

/// The reply of `flexdyn/<sc>/config`, the fields flight code uses.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct Vehicle {
    /// The string spacecraft id of the keys.
    pub sc_id: String,
    /// The numeric spacecraft id of the headers: stamp commands with it.
    pub spacecraft_id: u32,
    /// The configuration file, verbatim.
    pub config_toml: String,
}

impl Vehicle {
    /// Parses a reply's JSON.
    pub fn from_json(key: &str, text: &str) -> Result<Self, VehicleError> {
        serde_json::from_str(text).map_err(|e| VehicleError::Reply {
            key: key.to_owned(),
            message: e.to_string(),
        })
    }

    /// Asks the server of `topics` what it runs, again every 50 ms until it answers or
    /// `timeout` passes: the queryable is declared a moment after the server starts listening,
    /// and a client may start before the server.
    pub fn query(
        session: &Session,
        topics: &Topics,
        timeout: Duration,
    ) -> Result<Self, VehicleError> {
        let key = topics.config();
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let replies = session
                .get(&key)
                .timeout(left.clamp(Duration::from_millis(100), Duration::from_secs(2)))
                .wait()
                .map_err(|e| VehicleError::Zenoh {
                    key: key.clone(),
                    message: e.to_string(),
                })?;
            while let Ok(reply) = replies.recv() {
                if let Ok(sample) = reply.result() {
                    let text =
                        sample
                            .payload()
                            .try_to_string()
                            .map_err(|e| VehicleError::Reply {
                                key: key.clone(),
                                message: e.to_string(),
                            })?;
                    return Self::from_json(&key, &text);
                }
            }
            if Instant::now() >= deadline {
                return Err(VehicleError::NoAnswer {
                    key,
                    timeout_s: timeout.as_secs_f64(),
                });
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// The parts of the configuration flight code reads.
    pub fn config(&self) -> Result<VehicleConfig, VehicleError> {
        VehicleConfig::from_toml(&self.config_toml)
    }
}

/// What flight code reads of a configuration (the server's TOML keys and units).
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct VehicleConfig {
    /// `[simulation]`.
    pub simulation: Simulation,
    /// `[hub]`.
    pub hub: Hub,
    /// `[[panel_pairs]]`, in file order (effector indices 0, 1, …).
    #[serde(default)]
    pub panel_pairs: Vec<PanelPair>,
    /// `[[reaction_wheels]]`, in file order (effector indices after the panel pairs).
    #[serde(default)]
    pub reaction_wheels: Vec<ReactionWheel>,
    /// `[[panel_chains]]`, in file order (effector indices after the wheels).
    #[serde(default)]
    pub panel_chains: Vec<PanelChain>,
    /// `[[slosh_linear]]`, in file order (effector indices after the panel chains): kept as
    /// tables, for their count (flight code does not read slosh parameters).
    #[serde(default)]
    pub slosh_linear: Vec<toml::Table>,
    /// `[[slosh_pendulums]]`, in file order (effector indices after the linear slosh
    /// particles): kept as tables, for their count.
    #[serde(default)]
    pub slosh_pendulums: Vec<toml::Table>,
    /// `[[propellant_tanks]]`, in file order (effector indices after the slosh bodies): kept as
    /// tables, for their count (their telemetry is the propellant left; they take no input).
    #[serde(default)]
    pub propellant_tanks: Vec<toml::Table>,
    /// `[[magnetorquers]]`, in file order (effector indices after the propellant tanks).
    #[serde(default)]
    pub magnetorquers: Vec<Magnetorquer>,
    /// `[[thrusters]]`, in file order (effector indices after the magnetorquers).
    #[serde(default)]
    pub thrusters: Vec<Thruster>,
    /// `[[imus]]`, in file order.
    #[serde(default)]
    pub imus: Vec<Imu>,
    /// `[[star_trackers]]`, in file order.
    #[serde(default)]
    pub star_trackers: Vec<StarTracker>,
    /// `[[magnetometers]]`, in file order.
    #[serde(default)]
    pub magnetometers: Vec<Magnetometer>,
    /// `[[coarse_sun_sensors]]`, in file order.
    #[serde(default)]
    pub coarse_sun_sensors: Vec<CoarseSunSensor>,
    /// `[[fine_sun_sensors]]`, in file order.
    #[serde(default)]
    pub fine_sun_sensors: Vec<FineSunSensor>,
    /// `[[gps_receivers]]`, in file order.
    #[serde(default)]
    pub gps_receivers: Vec<GpsReceiver>,
    /// `[[faults]]`, in file order: fault index `i` of FaultEventMsg and StatusMsg is entry
    /// `i` (live faults follow them).
    #[serde(default)]
    pub faults: Vec<Fault>,
}

impl VehicleConfig {
    /// Parses a configuration's TOML.
    pub fn from_toml(text: &str) -> Result<Self, VehicleError> {
        let cfg: Self = toml::from_str(text).map_err(|e| VehicleError::Config(e.to_string()))?;
        if !(cfg.simulation.frame_hz.is_finite() && cfg.simulation.frame_hz > 0.0) {
            return Err(VehicleError::Config(format!(
                "simulation.frame_hz = {} is not a positive number",
                cfg.simulation.frame_hz
            )));
        }
        Ok(cfg)
    }

    /// The effector index of the first reaction wheel in `StateMsg::effectors` and in
    /// `Actuators` commands (after every panel pair).
    pub fn first_wheel_index(&self) -> u32 {
        self.panel_pairs.len() as u32
    }

    /// The effector index of the first panel chain (after every wheel).
    pub fn first_chain_index(&self) -> u32 {
        self.first_wheel_index() + self.reaction_wheels.len() as u32
    }

    /// The effector index of the first fuel-slosh body (after every panel chain): the linear
    /// particles, then the pendulums.
    pub fn first_slosh_index(&self) -> u32 {
        self.first_chain_index() + self.panel_chains.len() as u32
    }

    /// The effector index of the first propellant tank (after every fuel-slosh body).
    pub fn first_tank_index(&self) -> u32 {
        self.first_slosh_index() + (self.slosh_linear.len() + self.slosh_pendulums.len()) as u32
    }

    /// The effector index of the first magnetorquer (after every appended body: pairs, wheels,
    /// chains, slosh bodies, propellant tanks).
    pub fn first_magnetorquer_index(&self) -> u32 {
        self.first_tank_index() + self.propellant_tanks.len() as u32
    }

    /// The effector index of the first thruster (after every magnetorquer).
    pub fn first_thruster_index(&self) -> u32 {
        self.first_magnetorquer_index() + self.magnetorquers.len() as u32
    }

    /// The IMU `name`.
    pub fn imu(&self, name: &str) -> Result<&Imu, VehicleError> {
        find_named(&self.imus, "imus", name, |i| &i.name)
    }

    /// The star tracker `name`.
    pub fn star_tracker(&self, name: &str) -> Result<&StarTracker, VehicleError> {
        find_named(&self.star_trackers, "star_trackers", name, |s| &s.name)
    }

    /// The period of star tracker `st` in frames: round(`frame_hz` / `rate_hz`), as the server
    /// computes it (it accepts only rates that divide the frame rate).
    pub fn star_tracker_period_frames(&self, st: &StarTracker) -> Result<u64, VehicleError> {
        self.period_frames("star tracker", &st.name, st.rate_hz)
    }

    /// The magnetometer `name`.
    pub fn magnetometer(&self, name: &str) -> Result<&Magnetometer, VehicleError> {
        find_named(&self.magnetometers, "magnetometers", name, |m| &m.name)
    }

    /// The coarse-sun-sensor array `name`.
    pub fn coarse_sun_sensor(&self, name: &str) -> Result<&CoarseSunSensor, VehicleError> {
        find_named(&self.coarse_sun_sensors, "coarse_sun_sensors", name, |c| {
            &c.name
        })
    }

    /// The fine sun sensor `name`.
    pub fn fine_sun_sensor(&self, name: &str) -> Result<&FineSunSensor, VehicleError> {
        find_named(&self.fine_sun_sensors, "fine_sun_sensors", name, |f| {
            &f.name
        })
    }

    /// The GPS receiver `name`.
    pub fn gps_receiver(&self, name: &str) -> Result<&GpsReceiver, VehicleError> {
        find_named(&self.gps_receivers, "gps_receivers", name, |g| &g.name)
    }

    /// The latency of GPS receiver `gps` in frames: `latency_s` · `frame_hz`, which the server
    /// accepts only as a whole number.
    pub fn gps_latency_frames(&self, gps: &GpsReceiver) -> Result<u64, VehicleError> {
        let frames = gps.latency_s * self.simulation.frame_hz;
        if !(frames.is_finite() && frames >= 0.0 && (frames - frames.round()).abs() < 1e-9) {
            return Err(VehicleError::Config(format!(
                "GPS receiver `{}`: latency_s = {} is not a whole number of frames at {} Hz",
                gps.name, gps.latency_s, self.simulation.frame_hz
            )));
        }
        Ok(frames.round() as u64)
    }

    /// The period in frames of a sensor `what` `name` updating at `rate_hz`:
    /// round(`frame_hz` / `rate_hz`), as the server computes it (it accepts only rates that
    /// divide the frame rate).
    pub fn period_frames(&self, what: &str, name: &str, rate_hz: f64) -> Result<u64, VehicleError> {
        let ratio = self.simulation.frame_hz / rate_hz;
        if !(ratio.is_finite() && ratio.round() >= 1.0) {
            return Err(VehicleError::Config(format!(
                "{what} `{name}`: rate_hz = {rate_hz} does not divide the frame rate {} Hz",
                self.simulation.frame_hz
            )));
        }
        Ok(ratio.round() as u64)
    }
}

/// The entry of `list` (the `[[section]]` entries) whose name is `name`.
fn find_named<'a, T>(
    list: &'a [T],
    section: &str,
    name: &str,
    name_of: impl Fn(&T) -> &String,
) -> Result<&'a T, VehicleError> {
    list.iter().find(|e| name_of(e) == name).ok_or_else(|| {
        let names: Vec<&str> = list.iter().map(|e| name_of(e).as_str()).collect();
        VehicleError::Config(format!(
            "no [[{section}]] named `{name}` (it has: {names:?})"
        ))
    })
}

/// `[simulation]`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct Simulation {
    /// \[Hz\] frame (tick) rate.
    pub frame_hz: f64,
}

/// `[hub]`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct Hub {
    /// \[kg\]
    pub mass_kg: f64,
    /// \[kg·m²\] about the hub's centre of mass C_B, B components.
    pub inertia_bc_b_kg_m2: [[f64; 3]; 3],
    /// \[m\] hub centre of mass relative to B, B components.
    pub r_bcb_b_m: [f64; 3],
}

/// One `[[panel_pairs]]` entry (the mass properties flight code tabulates).
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct PanelPair {
    /// Its name.
    pub name: String,
    /// \[m\] hinge 1 relative to B, B components.
    pub r_h1b_b_m: [f64; 3],
    /// [H1 B], rows ĥ1, ĥ2, ĥ3 in B; at θ = 0 a panel extends along −ĥ1.
    pub dcm_h1b: [[f64; 3]; 3],
    /// The inboard panel (with its length `l_m`).
    pub panel1: Panel,
    /// The outboard panel.
    pub panel2: Panel,
}

/// A `[[panel_chains]]` entry: N hinged panels in series (inputs: one motor torque per hinge,
/// N·m, in `Actuators` commands).
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct PanelChain {
    /// Its name.
    pub name: String,
    /// \[m\] hinge 1 relative to B, B components.
    pub r_h1b_b_m: [f64; 3],
    /// [H1 B], rows ĥ1, ĥ2, ĥ3 in B; every hinge axis is ĥ2.
    pub dcm_h1b: [[f64; 3]; 3],
    /// The panels, from the hub outwards (each with `l_m`, optional on the last).
    pub panels: Vec<Panel>,
}

/// One panel of a pair or a chain.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct Panel {
    /// \[kg\]
    pub mass_kg: f64,
    /// \[kg·m²\] principal inertia about its centre of mass, panel frame.
    pub inertia_s_kg_m2: [f64; 3],
    /// \[m\] hinge to centre of mass.
    pub d_m: f64,
    /// \[m\] hinge to hinge (a pair's panel 1, a chain's panels but the last).
    #[serde(default)]
    pub l_m: Option<f64>,
}

/// One `[[reaction_wheels]]` entry.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct ReactionWheel {
    /// Its name.
    pub name: String,
    /// Spin axis ĝ_s in B (normalised by the server).
    pub spin_axis_b: [f64; 3],
    /// \[m\] rotor centre of mass relative to B, B components.
    pub r_wb_b_m: [f64; 3],
    /// \[kg\] rotor mass.
    pub mass_kg: f64,
    /// \[kg·m²\] spin inertia.
    pub j_s_kg_m2: f64,
    /// \[kg·m²\] transverse inertia.
    pub j_t_kg_m2: f64,
    /// \[N·m\] motor torque limit.
    pub max_torque_nm: f64,
    /// \[rad/s\] the speed beyond which the motor stops accelerating (infinite when absent).
    #[serde(default = "infinite")]
    pub max_speed_rad_s: f64,
    /// \[N·m·s/rad\] viscous bearing friction (0 when absent).
    #[serde(default)]
    pub viscous_friction_nm_s_rad: f64,
    /// \[N·m\] Coulomb bearing friction (0 when absent).
    #[serde(default)]
    pub coulomb_friction_nm: f64,
}

fn infinite() -> f64 {
    f64::INFINITY
}

/// One `[[magnetorquers]]` entry.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct Magnetorquer {
    /// Its name.
    pub name: String,
    /// The rod's axis â in B (a unit vector).
    pub axis_b: [f64; 3],
    /// \[m\] the rod's centre relative to B, B components.
    pub r_mb_b_m: [f64; 3],
    /// \[A·m²\] the largest dipole magnitude.
    pub max_dipole_am2: f64,
}

/// One `[[thrusters]]` entry.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct Thruster {
    /// Its name.
    pub name: String,
    /// \[m\] the nozzle point relative to B, B components.
    pub r_tb_b_m: [f64; 3],
    /// The direction the thrust pushes the vehicle, B components (a unit vector).
    pub force_axis_b: [f64; 3],
    /// \[N\] steady-state thrust.
    pub max_thrust_newton: f64,
    /// \[s\] the shortest on-time the valve executes (0 when absent).
    #[serde(default)]
    pub min_on_time_s: f64,
    /// `"on_time_s"` (absent) or `"duty_cycle"`: what its one input means.
    #[serde(default)]
    pub command: Option<String>,
    /// The `[[propellant_tanks]]` entry it draws from (absent: none; its thrust does not
    /// change the vehicle's mass).
    #[serde(default)]
    pub tank: Option<String>,
}

/// One `[[imus]]` entry.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct Imu {
    /// Its name (topic `flexdyn/<sc>/tlm/imu/<name>`).
    pub name: String,
    /// \[m\] sensor location relative to B, B components.
    pub r_sb_b_m: [f64; 3],
    /// \[PB\]: maps B components to the platform frame P.
    pub dcm_pb: [[f64; 3]; 3],
    /// `[imus.<name>.gyro]`: the gyro's error specification (an ideal gyro when absent).
    #[serde(default)]
    pub gyro: GyroSpec,
}

/// The error specification of a gyro triad (`[imus.gyro]`), the part flight code's fault
/// detection needs; absent keys are 0.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
pub struct GyroSpec {
    /// \[rad/s/√Hz\] angle random walk N.
    #[serde(default)]
    pub arw_rad_s_sqrt_hz: f64,
    /// \[rad/s\] the constant bias, P components.
    #[serde(default)]
    pub bias_rad_s: [f64; 3],
    /// \[rad/s\] the steady-state σ of the Gauss–Markov bias instability.
    #[serde(default)]
    pub bias_instability_sigma_rad_s: f64,
    /// \[rad/s\] the rate output's quantum (0: not quantised).
    #[serde(default)]
    pub lsb_rad_s: f64,
}

/// One `[[star_trackers]]` entry.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct StarTracker {
    /// Its name (topic `flexdyn/<sc>/tlm/st/<name>`).
    pub name: String,
    /// \[CB\]: maps B components to the case frame C.
    pub dcm_cb: [[f64; 3]; 3],
    /// \[Hz\] update rate (a whole divisor of the frame rate).
    pub rate_hz: f64,
    /// \[rad\] 1σ noise about the two axes across the boresight (0 when absent).
    #[serde(default)]
    pub sigma_cross_boresight_rad: f64,
    /// \[rad\] 1σ noise about the boresight (0 when absent).
    #[serde(default)]
    pub sigma_about_boresight_rad: f64,
    /// The boresight in C (+z_C when absent).
    #[serde(default = "plus_z")]
    pub boresight_c: [f64; 3],
}

fn plus_z() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

/// One `[[faults]]` entry: what it breaks and how (its window and parameters are the
/// server's business; FaultEventMsg reports them as they take effect).
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct Fault {
    /// The target as written (`imus.hub.gyro`, `reaction_wheels.rw2`, `links.1`).
    pub target: String,
    /// The mode's name (`bias_step`; `proto/README.md`, "Fault modes").
    pub mode: String,
}

/// One `[[magnetometers]]` entry.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct Magnetometer {
    /// Its name (topic `flexdyn/<sc>/tlm/mag/<name>`).
    pub name: String,
    /// \[SB\]: maps B components to the sensor frame S.
    pub dcm_sb: [[f64; 3]; 3],
    /// \[Hz\] update rate (a whole divisor of the frame rate).
    pub rate_hz: f64,
}

/// One `[[fine_sun_sensors]]` entry.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct FineSunSensor {
    /// Its name (topic `flexdyn/<sc>/tlm/fss/<name>`).
    pub name: String,
    /// \[FB\]: maps B components to the sensor frame F (boresight +z_F).
    pub dcm_fb: [[f64; 3]; 3],
    /// \[Hz\] update rate (a whole divisor of the frame rate).
    pub rate_hz: f64,
}

/// One `[[gps_receivers]]` entry.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct GpsReceiver {
    /// Its name (topic `flexdyn/<sc>/tlm/gps/<name>`).
    pub name: String,
    /// \[Hz\] solution rate (a whole divisor of the frame rate).
    pub rate_hz: f64,
    /// \[s\] from the instant a solution is valid to its publication (a whole number of
    /// frames; 0 by default, as the server reads it).
    #[serde(default)]
    pub latency_s: f64,
}

/// One `[[coarse_sun_sensors]]` entry (an array of cosine detectors).
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct CoarseSunSensor {
    /// Its name (topic `flexdyn/<sc>/tlm/css/<name>`).
    pub name: String,
    /// Each detector's normal in B, in reading order.
    pub normals_b: Vec<[f64; 3]>,
    /// \[Hz\] update rate (a whole divisor of the frame rate).
    pub rate_hz: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOML: &str = r#"
[simulation]
step_s = 0.001
frame_hz = 100.0
[hub]
mass_kg = 750
inertia_bc_b_kg_m2 = [[900.0, 0.0, 0.0], [0.0, 800.0, 0.0], [0.0, 0.0, 600.0]]
r_bcb_b_m = [0.0, 0.0, 1.0]
[[star_trackers]]
name = "st1"
dcm_cb = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]
rate_hz = 10.0
seed = 7
[[star_trackers]]
name = "slow"
dcm_cb = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
rate_hz = 3.0
[[magnetometers]]
name = "mag1"
dcm_sb = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
rate_hz = 50.0
seed = 31
[[coarse_sun_sensors]]
name = "css"
normals_b = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]]
rate_hz = 0.0
seed = 41
[[fine_sun_sensors]]
name = "fss"
dcm_fb = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
rate_hz = 20.0
[[gps_receivers]]
name = "gps1"
rate_hz = 1.0
latency_s = 0.2
[[gps_receivers]]
name = "late"
rate_hz = 1.0
latency_s = 0.125
"#;

    #[test]
    fn reads_the_reply_and_the_parts_flight_code_needs() {
        let json = serde_json::json!({
            "sc_id": "sc1", "spacecraft_id": 7, "config_toml": TOML,
            "server_settings": "mode=lockstep", "flexdyn_version": "0.1.0", "git_commit": null
        })
        .to_string();
        let v = Vehicle::from_json("flexdyn/sc1/config", &json).unwrap();
        assert_eq!((v.sc_id.as_str(), v.spacecraft_id), ("sc1", 7));
        let c = v.config().unwrap();
        // An integer where a float is expected, as the server's own reader accepts.
        assert_eq!(c.hub.mass_kg, 750.0);
        assert_eq!((c.first_wheel_index(), c.imus.len()), (0, 0));
        let st = c.star_tracker("st1").unwrap();
        assert_eq!(c.star_tracker_period_frames(st).unwrap(), 10);
        // 100 / 3 rounds to 33 frames (the server would refuse this rate; the rounding is its).
        let slow = c.star_tracker("slow").unwrap();
        assert_eq!(c.star_tracker_period_frames(slow).unwrap(), 33);
        let e = c.star_tracker("st9").unwrap_err().to_string();
        assert!(
            e.contains("no [[star_trackers]] named `st9`") && e.contains("\"slow\""),
            "{e}"
        );
        assert!(c.imu("hub").is_err());
        // The attitude sensors of the ACS sequence: their schedule and the array's normals.
        let mag = c.magnetometer("mag1").unwrap();
        assert_eq!(
            c.period_frames("magnetometer", "mag1", mag.rate_hz)
                .unwrap(),
            2
        );
        let css = c.coarse_sun_sensor("css").unwrap();
        assert_eq!(css.normals_b[1], [-1.0, 0.0, 0.0]);
        let e = c
            .period_frames("coarse sun sensor", "css", css.rate_hz)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("coarse sun sensor `css`: rate_hz = 0 does not divide"),
            "{e}"
        );
        let fss = c.fine_sun_sensor("fss").unwrap();
        assert_eq!(
            (
                fss.dcm_fb[1],
                c.period_frames("fine sun sensor", "fss", fss.rate_hz)
                    .unwrap()
            ),
            ([-1.0, 0.0, 0.0], 5)
        );
        // 0.2 s at 100 Hz is 20 frames; 0.125 s is 12.5, which the server refuses.
        let gps = c.gps_receiver("gps1").unwrap();
        assert_eq!(c.gps_latency_frames(gps).unwrap(), 20);
        let e = c
            .gps_latency_frames(c.gps_receiver("late").unwrap())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`late`: latency_s = 0.125 is not a whole number of frames"),
            "{e}"
        );
        let e = c.magnetometer("nope").unwrap_err().to_string();
        assert!(e.contains("no [[magnetometers]] named `nope`"), "{e}");
        let e = Vehicle::from_json("k", "{}").unwrap_err().to_string();
        assert!(
            e.starts_with("k: the reply is not a flexdyn vehicle description"),
            "{e}"
        );
        let e = VehicleConfig::from_toml("[simulation]\nframe_hz = 0.0\n").unwrap_err();
        assert!(
            e.to_string().contains("hub") || e.to_string().contains("frame_hz"),
            "{e}"
        );
    }
}
