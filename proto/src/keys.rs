//! Zenoh key expressions. Every key is `flexdyn/<sc-id>/<suffix>`, where
//! `<sc-id>` is the string spacecraft id (1..=[`MAX_ID_LEN`] chars of
//! `[A-Za-z0-9_-]`); the numeric id in [`crate::Header::spacecraft_id`] names
//! the same vehicle.

use crate::KeyError;

/// First chunk of every key.
pub const KEY_ROOT: &str = "flexdyn";
/// Suffix of the state topic.
pub const STATE_SUFFIX: &str = "tlm/state";
/// Suffix of the time-service topic ([`crate::TimeMsg`], one per frame, before the frame's
/// sensor samples and state). Protocol version 5.
pub const TIME_SUFFIX: &str = "tlm/time";
/// Suffix of the environment topic ([`crate::EnvironmentMsg`], at the configured rate).
pub const ENVIRONMENT_SUFFIX: &str = "tlm/env";
/// Prefix of the IMU topics; the IMU name follows after a `/`.
pub const IMU_PREFIX: &str = "tlm/imu";
/// Prefix of the star-tracker topics; the tracker name follows after a `/`.
pub const STAR_TRACKER_PREFIX: &str = "tlm/st";
/// Prefix of the magnetometer topics; the magnetometer name follows after a `/`.
pub const MAGNETOMETER_PREFIX: &str = "tlm/mag";
/// Prefix of the coarse-sun-sensor array topics; the array name follows after a `/`.
pub const CSS_PREFIX: &str = "tlm/css";
/// Prefix of the fine-sun-sensor topics; the sensor name follows after a `/`.
pub const FSS_PREFIX: &str = "tlm/fss";
/// Prefix of the GPS receiver topics; the receiver name follows after a `/`.
pub const GPS_PREFIX: &str = "tlm/gps";
/// Prefix of a fleet deputy's relative-state topic ([`crate::RelativeStateMsg`]); the chief's
/// string id follows after a `/` (`flexdyn/<deputy>/tlm/rel/<chief>`). Protocol version 9.
pub const RELATIVE_STATE_PREFIX: &str = "tlm/rel";
/// Prefix of the flight code's telemetry topics ([`crate::FswMsg`]); the stream's name follows
/// after a `/` (`flexdyn/<sc>/fsw/<name>`). Protocol version 10.
pub const FSW_PREFIX: &str = "fsw";
/// Prefix of the command topics; the sender's decimal `sender_id` follows after a `/`
/// (`flexdyn/<sc>/cmd/<sender_id>`, every [`crate::CommandKind`]). One key per sender, so a
/// Zenoh access-control list can reserve each participant's key for its authenticated subject.
/// Protocol version 4; versions ≤ 3 used the single key `flexdyn/<sc>/cmd/wrench`.
pub const CMD_PREFIX: &str = "cmd";
/// Suffix of the operator-command topic ([`crate::OperatorMsg`]: pause, resume, run N ticks).
/// Protocol version 6.
pub const OPERATOR_SUFFIX: &str = "operator";
/// Suffix of the fault-event topic ([`crate::FaultEventMsg`]). Protocol version 8.
pub const FAULT_EVENT_SUFFIX: &str = "tlm/fault";
/// Suffix of the live fault-command topic ([`crate::FaultCommandMsg`]). Protocol version 8.
pub const FAULT_SUFFIX: &str = "fault";
/// Suffix of the status topic.
pub const STATUS_SUFFIX: &str = "status";
/// Suffix of the server's configuration queryable (a `get` returns a UTF-8 JSON description
/// of the vehicle: its configuration TOML and the server settings). Not a bincode message.
pub const CONFIG_SUFFIX: &str = "config";
/// Prefix of the lockstep-participant liveliness tokens; the decimal sender id
/// follows after a `/` (`flexdyn/<sc>/participant/<sender_id>`).
pub const PARTICIPANT_PREFIX: &str = "participant";
/// Longest accepted spacecraft id or IMU name (bytes).
pub const MAX_ID_LEN: usize = 64;

fn validate(what: &'static str, id: &str) -> Result<(), KeyError> {
    if id.is_empty() {
        return Err(KeyError::Empty { what });
    }
    if let Some((index, ch)) = id
        .char_indices()
        .find(|&(_, c)| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'))
    {
        return Err(KeyError::InvalidChar { what, ch, index });
    }
    if id.len() > MAX_ID_LEN {
        return Err(KeyError::TooLong {
            what,
            len: id.len(),
            max: MAX_ID_LEN,
        });
    }
    Ok(())
}

/// Check a spacecraft id.
pub fn validate_sc_id(sc: &str) -> Result<(), KeyError> {
    validate("spacecraft id", sc)
}

/// Check an IMU name.
pub fn validate_imu_name(name: &str) -> Result<(), KeyError> {
    validate("imu name", name)
}

/// `flexdyn/<sc>/tlm/state`
pub fn state_key(sc: &str) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    Ok(format!("{KEY_ROOT}/{sc}/{STATE_SUFFIX}"))
}

/// `flexdyn/<sc>/tlm/imu/<name>`
pub fn imu_key(sc: &str, name: &str) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    validate_imu_name(name)?;
    Ok(format!("{KEY_ROOT}/{sc}/{IMU_PREFIX}/{name}"))
}

/// `flexdyn/<sc>/tlm/imu/*` — subscribe to every IMU of a spacecraft.
pub fn imu_wildcard_key(sc: &str) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    Ok(format!("{KEY_ROOT}/{sc}/{IMU_PREFIX}/*"))
}

/// Check a star-tracker name.
pub fn validate_star_tracker_name(name: &str) -> Result<(), KeyError> {
    validate("star tracker name", name)
}

/// `flexdyn/<sc>/tlm/st/<name>`
pub fn star_tracker_key(sc: &str, name: &str) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    validate_star_tracker_name(name)?;
    Ok(format!("{KEY_ROOT}/{sc}/{STAR_TRACKER_PREFIX}/{name}"))
}

/// `flexdyn/<sc>/tlm/st/*` — subscribe to every star tracker of a spacecraft.
pub fn star_tracker_wildcard_key(sc: &str) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    Ok(format!("{KEY_ROOT}/{sc}/{STAR_TRACKER_PREFIX}/*"))
}

/// Check a sensor name (the last chunk of a sensor key).
pub fn validate_sensor_name(name: &str) -> Result<(), KeyError> {
    validate("sensor name", name)
}

/// `flexdyn/<sc>/<prefix>/<name>`: the key of sensor `name` of a kind whose topics start with
/// `prefix` (e.g. [`MAGNETOMETER_PREFIX`]).
pub fn sensor_key(sc: &str, prefix: &str, name: &str) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    validate_sensor_name(name)?;
    Ok(format!("{KEY_ROOT}/{sc}/{prefix}/{name}"))
}

/// `flexdyn/<deputy>/tlm/rel/<chief>`: deputy `deputy`'s state relative to vehicle `chief`
/// ([`crate::RelativeStateMsg`], protocol 9).
pub fn relative_state_key(deputy: &str, chief: &str) -> Result<String, KeyError> {
    validate_sc_id(deputy)?;
    validate_sc_id(chief)?;
    Ok(format!(
        "{KEY_ROOT}/{deputy}/{RELATIVE_STATE_PREFIX}/{chief}"
    ))
}

/// `flexdyn/<sc>/fsw/<stream>`: where flight code publishes its telemetry stream `stream`
/// ([`crate::FswMsg`], protocol 10).
pub fn fsw_key(sc: &str, stream: &str) -> Result<String, KeyError> {
    sensor_key(sc, FSW_PREFIX, stream)
}

/// `flexdyn/<sc>/fsw/*`: every telemetry stream of the flight code of `sc`.
pub fn fsw_wildcard_key(sc: &str) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    Ok(format!("{KEY_ROOT}/{sc}/{FSW_PREFIX}/*"))
}

/// `flexdyn/<sc>/cmd/<sender_id>`: where participant `sender_id` publishes its commands.
pub fn cmd_key(sc: &str, sender_id: u32) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    Ok(format!("{KEY_ROOT}/{sc}/{CMD_PREFIX}/{sender_id}"))
}

/// `flexdyn/<sc>/cmd/*` — every sender's command key (what the server subscribes to).
pub fn cmd_wildcard_key(sc: &str) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    Ok(format!("{KEY_ROOT}/{sc}/{CMD_PREFIX}/*"))
}

/// The canonical decimal u32 after `prefix/` in `key`: no sign, no leading zero (so one sender
/// has exactly one key), `None` otherwise.
fn decimal_after(key: &str, sc: &str, prefix: &str) -> Option<u32> {
    let rest = key
        .strip_prefix(KEY_ROOT)?
        .strip_prefix('/')?
        .strip_prefix(sc)?
        .strip_prefix('/')?
        .strip_prefix(prefix)?
        .strip_prefix('/')?;
    if rest.is_empty()
        || !rest.bytes().all(|b| b.is_ascii_digit())
        || (rest.len() > 1 && rest.starts_with('0'))
    {
        return None;
    }
    rest.parse().ok()
}

/// `flexdyn/<sc>/status`
pub fn status_key(sc: &str) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    Ok(format!("{KEY_ROOT}/{sc}/{STATUS_SUFFIX}"))
}

/// `flexdyn/<sc>/operator`: where an operator publishes [`crate::OperatorMsg`]s.
pub fn operator_key(sc: &str) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    Ok(format!("{KEY_ROOT}/{sc}/{OPERATOR_SUFFIX}"))
}

/// `flexdyn/<sc>/participant/<sender_id>`: the Zenoh liveliness token a lockstep
/// participant declares once it is subscribed to the state topic, so the server
/// knows it is present before publishing tick 0.
pub fn participant_key(sc: &str, sender_id: u32) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    Ok(format!("{KEY_ROOT}/{sc}/{PARTICIPANT_PREFIX}/{sender_id}"))
}

/// `flexdyn/<sc>/participant/*` — every participant token of a spacecraft.
pub fn participant_wildcard_key(sc: &str) -> Result<String, KeyError> {
    validate_sc_id(sc)?;
    Ok(format!("{KEY_ROOT}/{sc}/{PARTICIPANT_PREFIX}/*"))
}

/// Which telemetry topic a key of a spacecraft is (see [`Topics::telemetry`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Telemetry<'a> {
    /// `flexdyn/<sc>/tlm/state`: a [`crate::StateMsg`].
    State,
    /// `flexdyn/<sc>/tlm/time`: a [`crate::TimeMsg`].
    Time,
    /// `flexdyn/<sc>/tlm/env`: an [`crate::EnvironmentMsg`].
    Environment,
    /// `flexdyn/<sc>/tlm/imu/<name>`: an [`crate::ImuMsg`] of the IMU `name`.
    Imu(&'a str),
    /// `flexdyn/<sc>/tlm/st/<name>`: a [`crate::StarTrackerMsg`] of the tracker `name`.
    StarTracker(&'a str),
    /// `flexdyn/<sc>/tlm/mag/<name>`: a [`crate::MagnetometerMsg`] of the magnetometer `name`.
    Magnetometer(&'a str),
    /// `flexdyn/<sc>/tlm/css/<name>`: a [`crate::CssMsg`] of the coarse-sun-sensor array
    /// `name`.
    Css(&'a str),
    /// `flexdyn/<sc>/tlm/fss/<name>`: an [`crate::FssMsg`] of the fine sun sensor `name`.
    Fss(&'a str),
    /// `flexdyn/<sc>/tlm/gps/<name>`: a [`crate::GpsMsg`] of the GPS receiver `name`.
    Gps(&'a str),
    /// `flexdyn/<sc>/tlm/rel/<chief>`: a [`crate::RelativeStateMsg`] of this vehicle relative
    /// to vehicle `chief` (protocol 9).
    Relative(&'a str),
}

/// All keys of one spacecraft, validated once.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Topics {
    sc_id: String,
    state: String,
    cmd_wildcard: String,
    status: String,
}

impl Topics {
    /// Validate `sc` and build its keys.
    pub fn new(sc: &str) -> Result<Self, KeyError> {
        Ok(Self {
            sc_id: sc.to_owned(),
            state: state_key(sc)?,
            cmd_wildcard: cmd_wildcard_key(sc)?,
            status: status_key(sc)?,
        })
    }

    /// The string spacecraft id.
    pub fn sc_id(&self) -> &str {
        &self.sc_id
    }

    /// `flexdyn/<sc>/tlm/state`
    pub fn state(&self) -> &str {
        &self.state
    }

    /// `flexdyn/<sc>/cmd/<sender_id>`: participant `sender_id`'s command key.
    pub fn cmd(&self, sender_id: u32) -> String {
        format!("{KEY_ROOT}/{}/{CMD_PREFIX}/{sender_id}", self.sc_id)
    }

    /// `flexdyn/<sc>/cmd/*`: every sender's command key.
    pub fn cmd_wildcard(&self) -> &str {
        &self.cmd_wildcard
    }

    /// The sender id of a command key of this spacecraft (`flexdyn/<sc>/cmd/<decimal u32>`,
    /// canonical: no leading zero), `None` for any other key.
    pub fn cmd_sender(&self, key: &str) -> Option<u32> {
        decimal_after(key, &self.sc_id, CMD_PREFIX)
    }

    /// `flexdyn/<sc>/status`
    pub fn status(&self) -> &str {
        &self.status
    }

    /// `flexdyn/<sc>/operator` (operator commands).
    pub fn operator(&self) -> String {
        format!("{KEY_ROOT}/{}/{OPERATOR_SUFFIX}", self.sc_id)
    }

    /// `flexdyn/<sc>/fault` (live fault commands).
    pub fn fault(&self) -> String {
        format!("{KEY_ROOT}/{}/{FAULT_SUFFIX}", self.sc_id)
    }

    /// `flexdyn/<sc>/tlm/fault` (fault activations and clearances).
    pub fn fault_events(&self) -> String {
        format!("{KEY_ROOT}/{}/{FAULT_EVENT_SUFFIX}", self.sc_id)
    }

    /// `flexdyn/<sc>/tlm/time`
    pub fn time(&self) -> String {
        format!("{KEY_ROOT}/{}/{TIME_SUFFIX}", self.sc_id)
    }

    /// `flexdyn/<sc>/tlm/env`
    pub fn environment(&self) -> String {
        format!("{KEY_ROOT}/{}/{ENVIRONMENT_SUFFIX}", self.sc_id)
    }

    /// `flexdyn/<sc>/tlm/rel/<chief>` (this vehicle's state relative to vehicle `chief`).
    pub fn relative_state(&self, chief: &str) -> Result<String, KeyError> {
        relative_state_key(&self.sc_id, chief)
    }

    /// `flexdyn/<sc>/tlm/imu/<name>`
    pub fn imu(&self, name: &str) -> Result<String, KeyError> {
        imu_key(&self.sc_id, name)
    }

    /// `flexdyn/<sc>/tlm/st/<name>`
    pub fn star_tracker(&self, name: &str) -> Result<String, KeyError> {
        star_tracker_key(&self.sc_id, name)
    }

    /// `flexdyn/<sc>/<prefix>/<name>` (see [`sensor_key`]).
    pub fn sensor(&self, prefix: &str, name: &str) -> Result<String, KeyError> {
        sensor_key(&self.sc_id, prefix, name)
    }

    /// `flexdyn/<sc>/config` (the server's configuration queryable).
    pub fn config(&self) -> String {
        format!("{KEY_ROOT}/{}/{CONFIG_SUFFIX}", self.sc_id)
    }

    /// `flexdyn/<sc>/tlm/**`: the state and every sensor topic. One subscriber on it receives
    /// a tick's samples in the order the server published them (its sensor samples, then its
    /// state); separate subscribers may be delivered on separate threads, where a state can
    /// overtake a sensor sample of its own tick (proto/README.md, "Lockstep protocol").
    pub fn telemetry_wildcard(&self) -> String {
        format!("{KEY_ROOT}/{}/tlm/**", self.sc_id)
    }

    /// Which telemetry topic of this spacecraft `key` is, `None` for any other key (another
    /// spacecraft, a command or status key, an unknown `tlm/` topic, an invalid name).
    pub fn telemetry<'k>(&self, key: &'k str) -> Option<Telemetry<'k>> {
        let rest = key
            .strip_prefix(KEY_ROOT)?
            .strip_prefix('/')?
            .strip_prefix(self.sc_id.as_str())?
            .strip_prefix('/')?;
        if rest == STATE_SUFFIX {
            return Some(Telemetry::State);
        }
        if rest == TIME_SUFFIX {
            return Some(Telemetry::Time);
        }
        if rest == ENVIRONMENT_SUFFIX {
            return Some(Telemetry::Environment);
        }
        let named = |prefix: &str| {
            rest.strip_prefix(prefix)?
                .strip_prefix('/')
                .filter(|name| validate("sensor name", name).is_ok())
        };
        named(IMU_PREFIX)
            .map(Telemetry::Imu)
            .or_else(|| named(STAR_TRACKER_PREFIX).map(Telemetry::StarTracker))
            .or_else(|| named(MAGNETOMETER_PREFIX).map(Telemetry::Magnetometer))
            .or_else(|| named(CSS_PREFIX).map(Telemetry::Css))
            .or_else(|| named(FSS_PREFIX).map(Telemetry::Fss))
            .or_else(|| named(GPS_PREFIX).map(Telemetry::Gps))
            .or_else(|| named(RELATIVE_STATE_PREFIX).map(Telemetry::Relative))
    }

    /// `flexdyn/<sc>/tlm/imu/*`
    pub fn imu_wildcard(&self) -> String {
        format!("{KEY_ROOT}/{}/{IMU_PREFIX}/*", self.sc_id)
    }

    /// `flexdyn/<sc>/participant/<sender_id>` (liveliness token of a lockstep participant).
    pub fn participant(&self, sender_id: u32) -> String {
        format!("{KEY_ROOT}/{}/{PARTICIPANT_PREFIX}/{sender_id}", self.sc_id)
    }

    /// `flexdyn/<sc>/participant/*`
    pub fn participant_wildcard(&self) -> String {
        format!("{KEY_ROOT}/{}/{PARTICIPANT_PREFIX}/*", self.sc_id)
    }

    /// The sender id of a participant token key of this spacecraft
    /// (`flexdyn/<sc>/participant/<decimal u32>`), `None` for any other key.
    pub fn participant_id(&self, key: &str) -> Option<u32> {
        decimal_after(key, &self.sc_id, PARTICIPANT_PREFIX)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys() {
        assert_eq!(state_key("sc-1").unwrap(), "flexdyn/sc-1/tlm/state");
        assert_eq!(
            imu_key("sc-1", "imu_A").unwrap(),
            "flexdyn/sc-1/tlm/imu/imu_A"
        );
        assert_eq!(cmd_key("SC_2", 7).unwrap(), "flexdyn/SC_2/cmd/7");
        assert_eq!(cmd_wildcard_key("SC_2").unwrap(), "flexdyn/SC_2/cmd/*");
        assert_eq!(status_key("x").unwrap(), "flexdyn/x/status");
        assert_eq!(imu_wildcard_key("x").unwrap(), "flexdyn/x/tlm/imu/*");
        assert_eq!(
            star_tracker_key("sc-1", "st_A").unwrap(),
            "flexdyn/sc-1/tlm/st/st_A"
        );
        assert_eq!(
            star_tracker_wildcard_key("x").unwrap(),
            "flexdyn/x/tlm/st/*"
        );
        assert!(star_tracker_key("sc", "a*").is_err());
        let t = Topics::new("sc-1").unwrap();
        assert_eq!(t.sc_id(), "sc-1");
        assert_eq!(t.state(), "flexdyn/sc-1/tlm/state");
        assert_eq!(t.cmd(1), "flexdyn/sc-1/cmd/1");
        assert_eq!(t.cmd(0), cmd_key("sc-1", 0).unwrap());
        assert_eq!(t.cmd_wildcard(), "flexdyn/sc-1/cmd/*");
        assert_eq!(t.cmd_sender("flexdyn/sc-1/cmd/1"), Some(1));
        assert_eq!(t.cmd_sender("flexdyn/sc-1/cmd/0"), Some(0));
        assert_eq!(t.cmd_sender(&t.cmd(u32::MAX)), Some(u32::MAX));
        for bad in [
            "flexdyn/sc-1/cmd/wrench",
            "flexdyn/sc-1/cmd/01",
            "flexdyn/sc-1/cmd/",
            "flexdyn/sc-1/cmd/4294967296",
            "flexdyn/sc-2/cmd/1",
            "flexdyn/sc-1/participant/1",
        ] {
            assert_eq!(t.cmd_sender(bad), None, "{bad}");
        }
        assert_eq!(t.status(), "flexdyn/sc-1/status");
        assert_eq!(t.operator(), "flexdyn/sc-1/operator");
        assert_eq!(operator_key("sc-1").unwrap(), t.operator());
        assert!(operator_key("a/b").is_err());
        assert_eq!(t.cmd_sender(&t.operator()), None);
        assert_eq!(t.telemetry(&t.operator()), None);
        assert_eq!(t.imu("g").unwrap(), "flexdyn/sc-1/tlm/imu/g");
        assert_eq!(t.imu_wildcard(), "flexdyn/sc-1/tlm/imu/*");
        assert_eq!(t.telemetry_wildcard(), "flexdyn/sc-1/tlm/**");
        assert_eq!(t.telemetry(t.state()), Some(Telemetry::State));
        assert_eq!(t.time(), "flexdyn/sc-1/tlm/time");
        assert_eq!(t.telemetry(&t.time()), Some(Telemetry::Time));
        assert_eq!(t.telemetry("flexdyn/sc-1/tlm/time/x"), None);
        assert_eq!(t.environment(), "flexdyn/sc-1/tlm/env");
        assert_eq!(t.telemetry(&t.environment()), Some(Telemetry::Environment));
        assert_eq!(
            t.telemetry(&t.imu("hub").unwrap()),
            Some(Telemetry::Imu("hub"))
        );
        assert_eq!(
            t.telemetry(&t.star_tracker("st1").unwrap()),
            Some(Telemetry::StarTracker("st1"))
        );
        assert_eq!(
            t.telemetry(&t.sensor(MAGNETOMETER_PREFIX, "mag1").unwrap()),
            Some(Telemetry::Magnetometer("mag1"))
        );
        assert_eq!(
            t.telemetry("flexdyn/sc-1/tlm/css/css"),
            Some(Telemetry::Css("css"))
        );
        assert_eq!(
            t.telemetry("flexdyn/sc-1/tlm/fss/fss"),
            Some(Telemetry::Fss("fss"))
        );
        assert_eq!(
            t.telemetry("flexdyn/sc-1/tlm/gps/g"),
            Some(Telemetry::Gps("g"))
        );
        assert_eq!(
            t.telemetry(&t.relative_state("chief").unwrap()),
            Some(Telemetry::Relative("chief"))
        );
        assert_eq!(
            relative_state_key("dep", "chief").unwrap(),
            "flexdyn/dep/tlm/rel/chief"
        );
        assert!(relative_state_key("dep", "a/b").is_err());
        for other in [
            "flexdyn/sc-2/tlm/state",
            "flexdyn/sc-1/tlm/state/x",
            "flexdyn/sc-1/tlm/imu",
            "flexdyn/sc-1/tlm/imu/",
            "flexdyn/sc-1/tlm/imu/a/b",
            "flexdyn/sc-1/tlm/gps/a/b",
            "flexdyn/sc-1/tlm/xyz/g",
            "flexdyn/sc-1/tlm/rel/a/b",
            "flexdyn/sc-1/status",
            "flexdyn/sc-1/cmd/1",
            "flexdyn/sc-10/tlm/state",
        ] {
            assert_eq!(t.telemetry(other), None, "{other}");
        }
        assert_eq!(t.participant(7), "flexdyn/sc-1/participant/7");
        assert_eq!(participant_key("sc-1", 7).unwrap(), t.participant(7));
        assert_eq!(t.participant_wildcard(), "flexdyn/sc-1/participant/*");
        assert_eq!(
            participant_wildcard_key("sc-1").unwrap(),
            t.participant_wildcard()
        );
        assert_eq!(t.participant_id("flexdyn/sc-1/participant/7"), Some(7));
        assert_eq!(
            t.participant_id("flexdyn/sc-1/participant/4294967295"),
            Some(u32::MAX)
        );
        for bad in [
            "flexdyn/sc-1/participant/",
            "flexdyn/sc-1/participant/x",
            "flexdyn/sc-1/participant/+7",
            "flexdyn/sc-1/participant/07",
            "flexdyn/sc-1/participant/4294967296",
            "flexdyn/sc-2/participant/7",
            "flexdyn/sc-1/tlm/state",
        ] {
            assert_eq!(t.participant_id(bad), None, "{bad}");
        }
    }

    #[test]
    fn rejects_bad_ids() {
        assert_eq!(
            state_key(""),
            Err(KeyError::Empty {
                what: "spacecraft id"
            })
        );
        for bad in ["a/b", "a*", "$x", "a b", "é", "a?", "a#"] {
            assert!(
                matches!(state_key(bad), Err(KeyError::InvalidChar { .. })),
                "{bad}"
            );
        }
        assert_eq!(
            state_key("ab/c"),
            Err(KeyError::InvalidChar {
                what: "spacecraft id",
                ch: '/',
                index: 2
            })
        );
        assert_eq!(imu_key("sc", ""), Err(KeyError::Empty { what: "imu name" }));
        assert!(matches!(
            imu_key("sc", "a/b"),
            Err(KeyError::InvalidChar {
                what: "imu name",
                ..
            })
        ));
        let long = "a".repeat(MAX_ID_LEN + 1);
        assert!(matches!(
            Topics::new(&long),
            Err(KeyError::TooLong {
                len: 65,
                max: 64,
                ..
            })
        ));
        assert!(Topics::new(&"a".repeat(MAX_ID_LEN)).is_ok());
    }
}
