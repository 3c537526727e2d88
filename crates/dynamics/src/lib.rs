//! Rigid hub + appended bodies (dual-hinged panel pairs, reaction wheels), by back-substitution.
//!
//! Every appended body is a [`StateEffector`] in its own folder under [`effectors`]; the hub
//! ([`spacecraft`]) only sees their summed mass properties and contributions. [`reference`](mod@reference)
//! builds the reference spacecraft in code and measures how well a run conserves energy and
//! angular momentum.
//!
//! The equations are those of Allard & Schaub, "Spacecraft Dynamical Model with Dual-Connected
//! Hinged Rigid Bodies" (citation in `docs/errata.md`), Sections III and V, with the two
//! numerical errata of `docs/errata.md` applied:
//! - **E1** (Eqs. 80/81/120/123b): the ω̇ coefficient of the panel-2 row is
//!   `I_s22 ŝ22ᵀ − m2 d2 ŝ23ᵀ[r̃_Sc2/B]` — see `panel_pair`;
//! - **E2** (Eq. 148): `[C] = m_sc[c̃] + [C_contr]` — see [`spacecraft`].
//!
//! # Notation legend
//! Names follow the paper in snake case, with frames, points and units in the name:
//! - `r_xy_f`: position of point X relative to point Y, in frame F components
//!   (`r_bn_n` = r_B/N in N; `r_sc1b_b` = r_Sc1/B in B; `r_h1b_b` = r_H1/B in B);
//! - `v_bn_n`: inertial velocity of B in N; `omega_bn_b`: ω_B/N in B; `omega_dot_bn_b`: ω̇_B/N in B;
//! - `sigma_bn`: MRP of B relative to N;
//! - `dcm_xy`: the DCM \[XY\] that maps Y components to X components (`v_x = dcm_xy * v_y`), so
//!   `dcm_bn` maps N to B and `dcm_h1b` maps B to H1;
//! - `r_prime_*`: body-frame (B-relative) time derivative (the paper's ′); `*_dot`: inertial;
//! - `s11`, `s12`, `s13` (`s21`, …): the panel-1 (panel-2) frame axes ŝ_i1,k (ŝ_i2,k) in B;
//! - units are SI unless the name says otherwise (`step_ns`, `t_sim_ns`);
//! - **suffix rule**: a single letter after a quantity names a frame or point, never a unit. So
//!   `_n` is always the inertial frame N (`orb_ang_mom_n`, `r_bn_n`), and units are spelled so
//!   they cannot be read as one: `_newton` for newtons (`force_b_newton`), `_nm` for newton-metres
//!   (`torque_b_nm`, `k_nm_rad`, `c_nm_s_rad`), `_m` metres, `_kg`, `_s`, `_rad`, `_j` joules.
//!
//! # Conventions
//! - [S1 B] = M2(θ1)[H1 B], [S2 B] = M2(θ2) M2(θ_H2S1) [S1 B], M2(a) = [[c,0,−s],\[0,1,0\],\[s,0,c\]];
//!   θ2 is measured relative to panel 1; both hinge axes are ŝ12 = ĥ12.
//! - A positive θ rotates the panel about +ŝ2 by the right-hand rule; the panel's centre of mass
//!   lies at −d ŝ1 from its hinge, so at θ = 0 the panel extends along −ĥ1.
//! - Gravity acts at the system centre of mass as a uniform field.
//!
//! # Layer
//! Above `flexdyn-kernel` and `flexdyn-environment` (the sample the dynamic effectors read). A
//! library user can depend on this crate alone (with the environment if wanted) and step a
//! spacecraft in their own program. It must never depend on the sensors, the faults, the vehicle's
//! configuration or anything above them, nor on any I/O stack (`zenoh`, `tokio`, `foxglove`,
//! `plotters`, `mcap`): `.ci/layers` (run by `.ci/run`) checks the dependency graph.

#![warn(missing_docs)]

pub mod component;
pub mod dynamic_effector;
pub mod dynamic_effectors;
pub mod effector;
pub mod effectors;
pub mod integrator;
pub mod kinds;
pub mod params;
pub mod reference;
pub mod slosh_tank;
pub mod spacecraft;
pub mod stage_hook;

pub use dynamic_effector::{DynamicEffector, EnvironmentSource, EnvironmentWrenches, StageState};
pub use effector::{
    BackSubContributions, EffectorKind, EffectorMassProps, EnergyMomentum, HubAccel, HubKinematics,
    StateEffector,
};
pub use effectors::panel_pair::{PanelPair, PanelPairInitial, PanelPairParams, PanelParams};
pub use effectors::reaction_wheel::{ReactionWheel, ReactionWheelParams};
pub use params::{GravityModel, HubParams, SensorPoint, Wrench, WrenchSegment};
pub use spacecraft::{
    gravity_accel_n, gravity_potential, specific_force_b, Conserved, EffectorEntry, HubInitial,
    HubOutputs, InitialTranslation, Spacecraft, State,
};

pub use flexdyn_kernel::validate::ParamError;
