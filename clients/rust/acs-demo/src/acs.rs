//! Flight-code-side building blocks of `flexdyn-acs-demo`: a reaction-wheel MRP feedback law
//! and a star-tracker attitude estimate propagated with the gyro between updates. They take the
//! spacecraft's geometry from the configuration the server serves
//! ([`flexdyn_proto::client::vehicle::VehicleConfig`]; flight code would have it in its own tables),
//! the attitude kernels from `flexdyn_proto::attitude` and the messages from `flexdyn-proto`.

use anyhow::{bail, Context as _};
use flexdyn_proto::attitude::{dcm_to_mrp, mrp_rate, mrp_switch, quat_to_dcm};
use flexdyn_proto::client::vehicle::VehicleConfig;
use flexdyn_proto::{effector_kind, EffectorInput, StarTrackerMsg, StateMsg};
use nalgebra::{DMatrix, Matrix3, Vector3, Vector4};

/// A row-major 3×3 array of the configuration as a matrix.
pub fn mat3(rows: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| rows[r][c])
}

/// The spacecraft's inertia about B with the wings at rest (θ = 0) and every wheel rotor: the
/// flight code's mass-property table. Panels as rigid bodies at their rest positions
/// (r_Sc1/B = r_H1/B − d1 ĥ1, r_Sc2/B = r_H1/B − (l1 + d2) ĥ1), rotors with J_s ĝĝᵀ +
/// J_t (I − ĝĝᵀ), all by the parallel-axis theorem.
pub fn inertia_about_b(cfg: &VehicleConfig) -> anyhow::Result<Matrix3<f64>> {
    let shift = |m: f64, r: &Vector3<f64>| {
        (Matrix3::from_diagonal_element(r.norm_squared()) - r * r.transpose()) * m
    };
    let h = &cfg.hub;
    let r_bcb = Vector3::from(h.r_bcb_b_m);
    let mut i = mat3(&h.inertia_bc_b_kg_m2) + shift(h.mass_kg, &r_bcb);
    for p in &cfg.panel_pairs {
        let dcm_h1b = mat3(&p.dcm_h1b);
        let h1 = dcm_h1b.row(0).transpose();
        let r_h1b = Vector3::from(p.r_h1b_b_m);
        let l1_m = p
            .panel1
            .l_m
            .with_context(|| format!("panel pair `{}`: panel1 has no l_m", p.name))?;
        // At θ = 0 the panel frames are [H1 B] (θ_H2S1 turns panel 2 about ĥ2; ignored here).
        let dcm_bs = dcm_h1b.transpose();
        for (panel, r) in [
            (&p.panel1, r_h1b - h1 * p.panel1.d_m),
            (&p.panel2, r_h1b - h1 * (l1_m + p.panel2.d_m)),
        ] {
            let i_s = Matrix3::from_diagonal(&Vector3::from(panel.inertia_s_kg_m2));
            i += dcm_bs * i_s * dcm_bs.transpose() + shift(panel.mass_kg, &r);
        }
    }
    for w in &cfg.reaction_wheels {
        let g = Vector3::from(w.spin_axis_b).normalize();
        let ggt = g * g.transpose();
        i += ggt * w.j_s_kg_m2
            + (Matrix3::identity() - ggt) * w.j_t_kg_m2
            + shift(w.mass_kg, &Vector3::from(w.r_wb_b_m));
    }
    Ok(i)
}

/// The wheel array as flight code sees it: each wheel's effector index on the wire, its spin
/// axis and spin inertia, and the minimum-norm torque distribution \[G_s\]⁺ = \[G_s\]ᵀ(\[G_s\]\[G_s\]ᵀ)⁻¹.
#[derive(Debug, Clone)]
pub struct WheelArray {
    /// Index of each wheel in `StateMsg::effectors` (after the panel pairs).
    pub effector_index: Vec<u32>,
    /// ĝ_s,j in B.
    pub spin_axis_b: Vec<Vector3<f64>>,
    /// J_s,j [kg·m²].
    pub j_s_kg_m2: Vec<f64>,
    pinv: DMatrix<f64>,
}

impl WheelArray {
    /// The wheels of `cfg`; an error if it has none or they do not span three axes.
    pub fn from_config(cfg: &VehicleConfig) -> anyhow::Result<Self> {
        if cfg.reaction_wheels.is_empty() {
            bail!("the configuration has no [[reaction_wheels]] (needed by --actuator wheels)");
        }
        let n = cfg.reaction_wheels.len();
        let axes: Vec<Vector3<f64>> = cfg
            .reaction_wheels
            .iter()
            .map(|w| Vector3::from(w.spin_axis_b).normalize())
            .collect();
        let first = cfg.first_wheel_index();
        let mut array = Self {
            effector_index: (0..n as u32).map(|j| first + j).collect(),
            spin_axis_b: axes,
            j_s_kg_m2: cfg.reaction_wheels.iter().map(|w| w.j_s_kg_m2).collect(),
            pinv: DMatrix::zeros(n, 3),
        };
        array.set_allocation(&vec![false; n])?;
        Ok(array)
    }

    /// Sets the allocation [G_s']⁺ = [G_s']ᵀ([G_s'][G_s']ᵀ)⁻¹ of the wheels not `excluded`:
    /// [G_s'] is [G_s] with the excluded wheels' columns zero, so they get u = 0.
    pub(crate) fn set_allocation(&mut self, excluded: &[bool]) -> anyhow::Result<()> {
        let axes = &self.spin_axis_b;
        let g = DMatrix::from_fn(3, axes.len(), |r, c| {
            if excluded.get(c).copied().unwrap_or(false) {
                0.0
            } else {
                axes[c][r]
            }
        });
        let ggt = &g * g.transpose();
        // Rank 3: the smallest eigenvalue of the (symmetric) [G][G]ᵀ is not round-off.
        let eig = nalgebra::SymmetricEigen::new(Matrix3::from_fn(|r, c| ggt[(r, c)])).eigenvalues;
        let ggt_inv = ggt
            .try_inverse()
            .filter(|m| m.iter().all(|x| x.is_finite()) && eig.min() > 1e-9 * eig.max())
            .context("the wheel spin axes do not span three axes: no torque about some axis")?;
        self.pinv = g.transpose() * ggt_inv;
        Ok(())
    }

    /// Wheel speeds Ω_j [rad/s] from a state message (its wheel telemetry).
    pub fn speeds(&self, state: &StateMsg) -> anyhow::Result<Vec<f64>> {
        self.effector_index
            .iter()
            .map(|&i| match state.effectors.get(i as usize) {
                Some(e) if e.kind == effector_kind::REACTION_WHEEL && !e.states.is_empty() => {
                    Ok(e.states[0])
                }
                _ => bail!(
                    "StateMsg effector {i} is not a reaction wheel, though the served \
                     configuration says so"
                ),
            })
            .collect()
    }

    /// Motor torques u = −\[G_s\]⁺ L that give the hub the torque L (the hub receives −Σ ĝ_j u_j).
    pub fn motor_torques(&self, torque_b_nm: &Vector3<f64>) -> Vec<f64> {
        let l = nalgebra::DVector::from_column_slice(torque_b_nm.as_slice());
        (&self.pinv * l).iter().map(|u| -u).collect()
    }

    /// The inputs of an `Actuators` command for motor torques `u`.
    pub fn inputs(&self, u: &[f64]) -> Vec<EffectorInput> {
        self.effector_index
            .iter()
            .zip(u)
            .map(|(&effector_index, &v)| EffectorInput {
                effector_index,
                values: vec![v],
            })
            .collect()
    }

    /// Wheel momentum about B: Σ ĝ_j J_s,j (ĝ_jᵀ ω + Ω_j).
    pub fn momentum_b(&self, omega_bn_b: &Vector3<f64>, speeds: &[f64]) -> Vector3<f64> {
        self.spin_axis_b
            .iter()
            .zip(&self.j_s_kg_m2)
            .zip(speeds)
            .map(|((g, js), om)| g * (js * (g.dot(omega_bn_b) + om)))
            .sum()
    }
}

/// The body torque the wheel law asks for (Schaub & Junkins, *Analytical Mechanics of Space
/// Systems*, ch. 8, MRP feedback with reaction wheels):
/// L = −K σ_BR − P ω + ω × (\[I\] ω + \[G_s\] h_s), with h_s,j = J_s,j (ĝ_jᵀ ω + Ω_j). The last term
/// cancels the gyroscopic coupling of the body and wheel momenta, so with −\[G_s\] u = L the
/// closed loop is \[I\] ω̇ = −K σ − P ω as for the wrench controller.
pub fn wheel_control_torque(
    k_nm: f64,
    p_nms: f64,
    sigma_br: &Vector3<f64>,
    omega_bn_b: &Vector3<f64>,
    inertia_b: &Matrix3<f64>,
    wheel_momentum_b: &Vector3<f64>,
) -> Vector3<f64> {
    -sigma_br * k_nm - omega_bn_b * p_nms
        + omega_bn_b.cross(&(inertia_b * omega_bn_b + wheel_momentum_b))
}

/// σ_BN from a star tracker: \[BN\] = \[CB\]ᵀ [C̃N], between updates propagated with the gyro rate,
/// σ̇ = ¼ [B(σ)] ω (Schaub & Junkins §3.7), one Euler step per frame, shadow set switched.
#[derive(Debug, Clone)]
pub struct StarTrackerAttitude {
    /// The tracker's mounting \[CB\].
    pub dcm_cb: Matrix3<f64>,
    /// It updates on ticks that are multiples of this.
    pub every_frames: u64,
    estimate: Option<Vector3<f64>>,
}

impl StarTrackerAttitude {
    /// The tracker `name` of `cfg`.
    pub fn from_config(cfg: &VehicleConfig, name: &str) -> anyhow::Result<Self> {
        let st = cfg.star_tracker(name)?;
        Ok(Self {
            dcm_cb: mat3(&st.dcm_cb),
            every_frames: cfg.star_tracker_period_frames(st)?,
            estimate: None,
        })
    }

    /// Whether a measurement is due at `tick`.
    pub fn due(&self, tick: u64) -> bool {
        tick.is_multiple_of(self.every_frames)
    }

    /// The estimate after this frame: a valid measurement replaces it; otherwise it is
    /// propagated over `dt_s` with `omega_bn_b`. `None` until the first valid measurement.
    pub fn update(
        &mut self,
        measurement: Option<&StarTrackerMsg>,
        omega_bn_b: &Vector3<f64>,
        dt_s: f64,
    ) -> Option<Vector3<f64>> {
        match measurement {
            Some(m) if m.valid => {
                let dcm_cn = quat_to_dcm(&Vector4::from(m.q_cn));
                self.estimate = Some(dcm_to_mrp(&(self.dcm_cb.transpose() * dcm_cn)));
            }
            _ => {
                if let Some(s) = &mut self.estimate {
                    *s += mrp_rate(s, omega_bn_b) * dt_s;
                    mrp_switch(s);
                }
            }
        }
        self.estimate
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn_proto::attitude::{mrp_to_dcm, tilde};

    fn cfg() -> VehicleConfig {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../../scenarios/wheels_star_tracker.toml");
        VehicleConfig::from_toml(&std::fs::read_to_string(path).unwrap()).unwrap()
    }

    /// −[G_s] u reproduces the requested torque (the pyramid spans 3 axes), with the minimum
    /// norm: u is in the row space of [G_s].
    #[test]
    fn torque_distribution_reproduces_the_request() {
        let w = WheelArray::from_config(&cfg()).unwrap();
        assert_eq!(w.effector_index, [2, 3, 4, 5]);
        let l = Vector3::new(0.05, -0.02, 0.03);
        let u = w.motor_torques(&l);
        let back: Vector3<f64> = w.spin_axis_b.iter().zip(&u).map(|(g, u)| -g * *u).sum();
        assert!((back - l).norm() < 1e-15, "{back} vs {l}");
        // Minimum norm: adding a null-space vector n (G n = 0) only lengthens u.
        let n = [1.0, -1.0, 1.0, -1.0];
        let gn: Vector3<f64> = w.spin_axis_b.iter().zip(n).map(|(g, x)| g * x).sum();
        assert!(gn.norm() < 1e-15, "the pyramid's null vector");
        assert!(u.iter().zip(n).map(|(a, b)| a * b).sum::<f64>().abs() < 1e-15);
    }

    #[test]
    fn star_tracker_attitude_inverts_the_mounting_and_propagates() {
        let c = cfg();
        let mut est = StarTrackerAttitude::from_config(&c, "st1").unwrap();
        assert_eq!(est.every_frames, 10);
        let sigma_bn = Vector3::new(0.1, -0.2, 0.05);
        let dcm_cn = est.dcm_cb * mrp_to_dcm(&sigma_bn);
        let q = flexdyn_proto::attitude::dcm_to_quat(&dcm_cn);
        let msg = StarTrackerMsg {
            q_cn: q.into(),
            valid: true,
            ..StarTrackerMsg::default()
        };
        let w = Vector3::new(0.01, 0.0, -0.02);
        let got = est.update(Some(&msg), &w, 0.01).unwrap();
        assert!((got - sigma_bn).norm() < 1e-14, "{got} vs {sigma_bn}");
        // Invalid: propagated, σ̇ = ¼ B(σ) ω.
        let invalid = StarTrackerMsg {
            valid: false,
            ..msg
        };
        let next = est.update(Some(&invalid), &w, 0.01).unwrap();
        let s2 = sigma_bn.norm_squared();
        let b = Matrix3::identity() * (1.0 - s2)
            + tilde(&sigma_bn) * 2.0
            + sigma_bn * sigma_bn.transpose() * 2.0;
        assert!((next - (sigma_bn + b * w * 0.0025)).norm() < 1e-15);
        assert!(StarTrackerAttitude::from_config(&c, "nope").is_err());
    }
}
