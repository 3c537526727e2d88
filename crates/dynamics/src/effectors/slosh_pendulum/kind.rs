//! The spherical slosh pendulum's entry in the kind registry ([`crate::kinds::KINDS`]): its
//! `[[slosh_pendulums]]` section, its telemetry names, and how a configured pendulum is checked
//! and built (the macro `slosh_component` of `crate::slosh_tank`, shared with the particle).

crate::slosh_tank::slosh_component!(
    /// The pendulum slosh kind.
    super::SloshPendulumEntry => SloshPendulum,
    section "slosh_pendulums",
    noun "slosh pendulum"
);
