//! The linear slosh particle's entry in the kind registry ([`crate::kinds::KINDS`]): its
//! `[[slosh_linear]]` section, its telemetry names, and how a configured particle is checked and
//! built (the macro `slosh_component` of `crate::slosh_tank`, shared with the pendulum).

crate::slosh_tank::slosh_component!(
    /// The linear slosh kind.
    super::SloshLinearEntry => SloshLinear,
    section "slosh_linear",
    noun "linear slosh particle"
);
