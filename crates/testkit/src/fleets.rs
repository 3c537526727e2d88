//! Fleet files the tests fly, written once.

/// The LEO scenario (every environment model on, `update_hz = 10`) as the chief, and a deputy
/// 100 m behind it along-track and 20 m below: a fleet file whose spacecraft files are
/// relative to `scenarios/` (read it with `FleetConfig::from_toml_str_in(LEO_PAIR, scenarios)`).
pub const LEO_PAIR: &str =
    "[[vehicles]]\nid = \"chief\"\nspacecraft_file = \"leo_environment.toml\"\n\
    participants = [1]\n\n[[vehicles]]\nid = \"deputy\"\nspacecraft_file = \
    \"leo_environment.toml\"\nparticipants = [2]\n[vehicles.relative]\nchief = \"chief\"\n\
    hill_position_m = [-20.0, -100.0, 0.0]\nhill_velocity_m_s = [0.0, 0.0, 0.01]\n";
