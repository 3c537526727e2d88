//! The N-link panel chains (`[[panel_chains]]`) in the 3D scene, drawn as the pairs are: each
//! panel a box in its own frame, and the frames placed at the hinge angles of each StateMsg.
//!
//! # Frames (`crates/dynamics/src/effectors/panel_chain/mod.rs`, (C1)–(C2))
//! - `<chain>/panel1`: origin at hinge H1 (r_H1B in B), axes S1 with
//!   [S1 B] = M2(θ1) M2(θ_H1) [H1 B] = M2(θ1 + θ_H1) [H1 B] (rotations about the same axis add).
//! - `<chain>/panel<k>`, k ≥ 2: parent `<chain>/panel<k−1>`, origin at hinge
//!   H_k = H_k−1 − l_k−1 ŝ_k−1,1 (S_k−1 components (−l_k−1, 0, 0)), axes S_k with
//!   [S_k S_k−1] = M2(θ_k + θ_Hk).
//!
//! For N = 2 these are the pair's two frames (`theta_h2s1_rad` is panel 2's θ_H), so a chain
//! converted from a pair is drawn where the pair is.
//!
//! The angles come from the chain's StateMsg entry (`effector_kind::PANEL_CHAIN`, states
//! `[θ1, θ̇1, θ2, θ̇2, …]` in the wire table, `proto/schema/messages.toml`): θ_k is state
//! 2(k − 1).

use nalgebra::{Matrix3, Vector3};
use serde_json::Value;

use super::{cube_entity, panel_box, transform, Cuboid, PANEL_RGBA};
use flexdyn_dynamics::effectors::panel_chain::PanelChainParams;
use flexdyn_kernel::attitude::{dcm_to_quat, m2};
use flexdyn_proto::EffectorState;

/// One panel of a chain: its hinge's fixed angle, the distance to the next hinge and its box.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainLink {
    /// \[rad\] θ_Hk, the fixed angle of hinge k about ê relative to the previous panel.
    pub theta_h_rad: f64,
    /// \[m\] l_k, hinge k to hinge k + 1 along −ŝ_k1 (0 on the last panel).
    pub l_m: f64,
    /// The panel's box in its S_k frame.
    pub panel: Cuboid,
}

/// One chain's fixed geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainGeometry {
    /// The chain's configured name (frame ids `<name>/panel<k>`, k from 1).
    pub name: String,
    /// \[m\] hinge 1 relative to B, B components.
    pub r_h1b_b_m: Vector3<f64>,
    /// [H1 B].
    pub dcm_h1b: Matrix3<f64>,
    /// The panels, from the hub outwards.
    pub links: Vec<ChainLink>,
}

impl ChainGeometry {
    /// The geometry of a configured chain: each panel's box as a pair's panel is sized
    /// ([`panel_box`]; a chain panel has no `width_m`/`thickness_m`).
    pub fn new(p: &PanelChainParams) -> Self {
        Self {
            name: p.name.clone(),
            r_h1b_b_m: p.r_h1b_b_m,
            dcm_h1b: p.dcm_h1b,
            links: p
                .panels
                .iter()
                .map(|l| ChainLink {
                    theta_h_rad: l.theta_h_rad,
                    l_m: l.l_m,
                    panel: panel_box(l.mass_kg, &l.inertia_s_kg_m2, l.d_m, None, None),
                })
                .collect(),
        }
    }

    /// The frame id of panel `k` (0-based) under `prefix`.
    pub fn frame(&self, prefix: &str, k: usize) -> String {
        format!("{prefix}{}/panel{}", self.name, k + 1)
    }

    /// The transforms B → panel 1 → … → panel N at the hinge angles of `entry` (the chain's
    /// StateMsg entry), or none when the entry carries fewer angles than the chain has panels.
    pub fn transforms(&self, t_ns: u64, prefix: &str, entry: &EffectorState) -> Vec<Value> {
        if entry.states.len() < 2 * self.links.len() {
            return Vec::new();
        }
        let b = format!("{prefix}{}", super::FRAME_B);
        let mut out = Vec::with_capacity(self.links.len());
        for (k, link) in self.links.iter().enumerate() {
            let phi = entry.states[2 * k] + link.theta_h_rad;
            let child = self.frame(prefix, k);
            out.push(if k == 0 {
                transform(
                    t_ns,
                    &b,
                    &child,
                    &self.r_h1b_b_m,
                    &dcm_to_quat(&(m2(phi) * self.dcm_h1b)),
                )
            } else {
                transform(
                    t_ns,
                    &self.frame(prefix, k - 1),
                    &child,
                    &Vector3::new(-self.links[k - 1].l_m, 0.0, 0.0),
                    &dcm_to_quat(&m2(phi)),
                )
            });
        }
        out
    }

    /// One box entity per panel, in the panel's frame, coloured as the pairs' panels.
    pub fn entities(&self, prefix: &str, t_ns: u64) -> Vec<Value> {
        (0..self.links.len())
            .map(|k| {
                let frame = self.frame(prefix, k);
                cube_entity(t_ns, &frame, &frame, &self.links[k].panel, PANEL_RGBA)
            })
            .collect()
    }
}
