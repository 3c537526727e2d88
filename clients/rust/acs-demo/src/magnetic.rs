//! Magnetic attitude control laws: B-dot detumbling and cross-product momentum unloading, and
//! the allocation of a body dipole to the magnetorquer rods.
//!
//! - **B-dot** (Stickler & Alfriend, "Elementary magnetic attitude control system", J.
//!   Spacecraft 13(5), 1976): m = −k Ḃ_B, Ḃ_B from two magnetometer samples. In a field fixed in
//!   N, Ḃ_B = −ω × B_B, so m = k ω × B and the torque τ = m × B = k [B (ω·B) − ω |B|²] removes
//!   rotational energy at the rate ω·τ = −k |ω × B|² ≤ 0: it damps every rate component
//!   across the field.
//! - **Cross-product unloading** (Camillo & Markley, "Orbit-averaged behavior of magnetic
//!   control laws for momentum unloading", JGC 3(6), 1980; Sidi, *Spacecraft Dynamics and
//!   Control*, §7.5): to apply τ_d = −k (h_w − h_ref) with rods, command
//!   m = (B × τ_d) / |B|², which gives τ = m × B = τ_d − B (τ_d·B)/|B|², the part of τ_d across
//!   the field (the along-field part cannot be made; over an orbit the field turns, so every
//!   axis is unloaded). The attitude controller keeps pointing, so the wheels absorb the
//!   torque and their momentum falls.

use anyhow::{bail, Context as _};
use flexdyn_proto::client::vehicle::VehicleConfig;
use flexdyn_proto::EffectorInput;
use nalgebra::{DMatrix, DVector, Vector3};

/// The rods as flight code sees them: effector indices, axes, limits, and the minimum-norm
/// allocation \[A\]⁺ = \[A\]ᵀ(\[A\]\[A\]ᵀ)⁻¹ of a body dipole to rod dipoles.
#[derive(Debug, Clone)]
pub struct RodArray {
    /// Index of each rod in `StateMsg::effectors` and `Actuators` commands.
    pub effector_index: Vec<u32>,
    /// Each rod's axis in B.
    pub axis_b: Vec<Vector3<f64>>,
    /// \[A·m²\] each rod's largest dipole.
    pub max_dipole_am2: Vec<f64>,
    pinv: DMatrix<f64>,
}

impl RodArray {
    /// The rods of `cfg`; an error if there are none or they do not span three axes.
    pub fn from_config(cfg: &VehicleConfig) -> anyhow::Result<Self> {
        if cfg.magnetorquers.is_empty() {
            bail!("the configuration has no [[magnetorquers]]");
        }
        let axis_b: Vec<Vector3<f64>> = cfg
            .magnetorquers
            .iter()
            .map(|m| Vector3::from(m.axis_b).normalize())
            .collect();
        let n = axis_b.len();
        let a = DMatrix::from_fn(3, n, |r, c| axis_b[c][r]);
        let aat_inv = (&a * a.transpose())
            .try_inverse()
            .filter(|m| m.iter().all(|x| x.is_finite()))
            .context("the magnetorquer axes do not span three axes")?;
        let first = cfg.first_magnetorquer_index();
        Ok(Self {
            effector_index: (0..n as u32).map(|j| first + j).collect(),
            axis_b,
            max_dipole_am2: cfg.magnetorquers.iter().map(|m| m.max_dipole_am2).collect(),
            pinv: a.transpose() * aat_inv,
        })
    }

    /// Rod dipoles that make the body dipole `m_b_am2`, scaled down as a whole (direction kept)
    /// so that no rod exceeds its limit.
    pub fn dipoles(&self, m_b_am2: &Vector3<f64>) -> Vec<f64> {
        let mu = &self.pinv * DVector::from_column_slice(m_b_am2.as_slice());
        let over = mu
            .iter()
            .zip(&self.max_dipole_am2)
            .fold(1.0_f64, |s, (m, max)| s.max(m.abs() / max));
        mu.iter().map(|m| m / over).collect()
    }

    /// Rod dipoles from the minimum-norm allocation of `m_b_am2`, each clipped to its own limit
    /// on its own (the direction may change). For B-dot with rods along the body axes the
    /// allocation is m's components, and a clip that keeps each sign keeps every
    /// m_j (ω × B)_j ≥ 0: the law stays dissipative, with more torque than [`Self::dipoles`].
    pub fn dipoles_clipped(&self, m_b_am2: &Vector3<f64>) -> Vec<f64> {
        let mu = &self.pinv * DVector::from_column_slice(m_b_am2.as_slice());
        mu.iter()
            .zip(&self.max_dipole_am2)
            .map(|(m, max)| m.clamp(-max, *max))
            .collect()
    }

    /// The body dipole the rods make with dipoles `mu`.
    pub fn body_dipole(&self, mu: &[f64]) -> Vector3<f64> {
        self.axis_b.iter().zip(mu).map(|(a, m)| a * *m).sum()
    }

    /// The inputs of an `Actuators` command for rod dipoles `mu`.
    pub fn inputs(&self, mu: &[f64]) -> Vec<EffectorInput> {
        self.effector_index
            .iter()
            .zip(mu)
            .map(|(&effector_index, &v)| EffectorInput {
                effector_index,
                values: vec![v],
            })
            .collect()
    }
}

/// B-dot with a rate estimate from consecutive magnetometer samples.
#[derive(Debug, Clone)]
pub struct Bdot {
    /// \[A·m²·s/T\] gain k of m = −k Ḃ.
    pub gain: f64,
    last: Option<(u64, Vector3<f64>)>,
}

impl Bdot {
    /// A B-dot law with gain `gain` (> 0).
    pub fn new(gain: f64) -> Self {
        Self { gain, last: None }
    }

    /// The commanded body dipole after a field sample `b_b_t` \[T\] at `t_ns`: zero until a
    /// second sample gives Ḃ, and when no time has passed.
    pub fn dipole_b_am2(&mut self, t_ns: u64, b_b_t: &Vector3<f64>) -> Vector3<f64> {
        let m = match self.last {
            Some((t0, b0)) if t_ns > t0 => {
                let b_dot = (b_b_t - b0) / ((t_ns - t0) as f64 * 1e-9);
                -b_dot * self.gain
            }
            _ => Vector3::zeros(),
        };
        self.last = Some((t_ns, *b_b_t));
        m
    }
}

/// The gyro-aided B-dot dipole m = k_ω (ω × B)/|B|², all in B: its torque m × B = −k_ω ω_⊥,
/// the rate across the field damped with the gain k_ω \[N·m·s\] (`crate::sequence`'s docs:
/// why the gyro and not a finite difference of B). Zero in a zero field.
pub fn gyro_bdot_dipole_b_am2(
    gain_nms: f64,
    omega_bn_b_rad_s: &Vector3<f64>,
    b_b_t: &Vector3<f64>,
) -> Vector3<f64> {
    let b2 = b_b_t.norm_squared();
    if b2 == 0.0 {
        return Vector3::zeros();
    }
    omega_bn_b_rad_s.cross(b_b_t) * (gain_nms / b2)
}

/// The rod dipole for the cross-product unloading law: m = (B × τ_d)/|B|² with
/// τ_d = −k (h_w − h_ref), all in B. Zero in a zero field.
pub fn unloading_dipole_b_am2(
    gain_per_s: f64,
    h_wheels_b_nms: &Vector3<f64>,
    h_ref_b_nms: &Vector3<f64>,
    b_b_t: &Vector3<f64>,
) -> Vector3<f64> {
    let b2 = b_b_t.norm_squared();
    if b2 == 0.0 {
        return Vector3::zeros();
    }
    let tau_d = -(h_wheels_b_nms - h_ref_b_nms) * gain_per_s;
    b_b_t.cross(&tau_d) / b2
}

#[cfg(test)]
mod tests {
    use super::*;

    /// B-dot in a field fixed in N: over a short interval the finite difference gives
    /// Ḃ ≈ −ω × B, and the torque m × B takes energy out at ω·τ = −k|ω × B|² (module docs).
    #[test]
    fn bdot_damps_the_rate_across_the_field() {
        let omega = Vector3::new(0.03, -0.02, 0.05);
        let b0 = Vector3::new(2.0e-5, -1.0e-5, 3.0e-5);
        let dt = 1e-4;
        // B in B after dt of rotation at ω (first order: B(t) = B0 − ω × B0 t).
        let b1 = b0 - omega.cross(&b0) * dt;
        let mut law = Bdot::new(1e5);
        assert_eq!(law.dipole_b_am2(0, &b0), Vector3::zeros());
        let m = law.dipole_b_am2((dt * 1e9) as u64, &b1);
        let expected = omega.cross(&b0) * 1e5;
        assert!(
            (m - expected).norm() < 1e-9 * expected.norm(),
            "{m:?} vs {expected:?}"
        );
        let tau = m.cross(&b1);
        let rate = omega.dot(&tau);
        let closed = -1e5 * omega.cross(&b1).norm_squared();
        assert!(rate < 0.0);
        assert!(
            (rate - closed).abs() < 1e-6 * closed.abs(),
            "{rate} vs {closed}"
        );
    }

    /// (ω × B) × B = B (ω·B) − ω |B|², so m × B = k [(ω·b̂) b̂ − ω] = −k ω_⊥: the torque damps
    /// exactly the rate across the field and leaves the rate along it.
    #[test]
    fn gyro_bdot_torque_is_minus_the_gain_times_the_rate_across_the_field() {
        let omega = Vector3::new(0.03, -0.02, 0.05);
        let b = Vector3::new(2.0e-5, -1.0e-5, 3.0e-5);
        let k = 4.9;
        let tau = gyro_bdot_dipole_b_am2(k, &omega, &b).cross(&b);
        let across = omega - b * (omega.dot(&b) / b.norm_squared());
        assert!(
            (tau + across * k).norm() < 1e-15,
            "{tau:?} vs {:?}",
            -across * k
        );
        // A rate along the field gets no torque.
        assert!(gyro_bdot_dipole_b_am2(k, &(b * 1e3), &b).norm() < 1e-9);
        assert_eq!(
            gyro_bdot_dipole_b_am2(k, &omega, &Vector3::zeros()),
            Vector3::zeros()
        );
    }

    /// The unloading torque is −k (h − h_ref) across the field: (B × τ_d)/|B|² × B = τ_d⊥.
    #[test]
    fn unloading_torque_is_the_demand_across_the_field() {
        let h = Vector3::new(3.0, -1.0, 2.0);
        let b = Vector3::new(1.0e-5, 2.0e-5, -2.0e-5);
        let k = 0.01;
        let m = unloading_dipole_b_am2(k, &h, &Vector3::zeros(), &b);
        let tau = m.cross(&b);
        let tau_d = -h * k;
        let across = tau_d - b * (tau_d.dot(&b) / b.norm_squared());
        assert!((tau - across).norm() < 1e-15, "{tau:?} vs {across:?}");
        // It always takes momentum out: τ·h ≤ 0.
        assert!(tau.dot(&h) < 0.0);
        assert_eq!(
            unloading_dipole_b_am2(k, &h, &Vector3::zeros(), &Vector3::zeros()),
            Vector3::zeros()
        );
    }

    fn rods(axes: &[[f64; 3]], max: f64) -> RodArray {
        let toml = format!(
            "[simulation]\nframe_hz = 10.0\n[hub]\nmass_kg = 1.0\ninertia_bc_b_kg_m2 = \
             [[1.0,0.0,0.0],[0.0,1.0,0.0],[0.0,0.0,1.0]]\nr_bcb_b_m = [0.0,0.0,0.0]\n{}",
            axes.iter()
                .enumerate()
                .map(|(i, a)| format!(
                    "[[magnetorquers]]\nname = \"m{i}\"\naxis_b = {a:?}\nr_mb_b_m = [0.0, 0.0, 0.0]\n\
                     max_dipole_am2 = {max:?}\n"
                ))
                .collect::<String>()
        );
        RodArray::from_config(&VehicleConfig::from_toml(&toml).unwrap()).unwrap()
    }

    #[test]
    fn rods_make_the_body_dipole_and_saturate_as_a_whole() {
        let r = rods(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.6, 0.8]], 100.0);
        let m = Vector3::new(30.0, -20.0, 40.0);
        let mu = r.dipoles(&m);
        assert!((r.body_dipole(&mu) - m).norm() < 1e-12);
        // Too large: scaled down to the limit, direction kept.
        let big = m * 100.0;
        let mu = r.dipoles(&big);
        let made = r.body_dipole(&mu);
        assert!(mu.iter().map(|x| x.abs()).fold(0.0, f64::max) <= 100.0 + 1e-9);
        assert!(made.normalize().dot(&big.normalize()) > 1.0 - 1e-12);
        assert_eq!(r.inputs(&mu)[2].effector_index, 2);
        // Clipped rod by rod: the small component is kept, the others stop at the limit.
        let ortho = rods(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], 100.0);
        let mu = ortho.dipoles_clipped(&Vector3::new(500.0, -50.0, -300.0));
        assert_eq!(mu, [100.0, -50.0, -100.0]);
        // Two rods cannot make every dipole.
        let cfg = "[simulation]\nframe_hz = 10.0\n[hub]\nmass_kg = 1.0\ninertia_bc_b_kg_m2 = \
                   [[1.0,0.0,0.0],[0.0,1.0,0.0],[0.0,0.0,1.0]]\nr_bcb_b_m = [0.0,0.0,0.0]\n\
                   [[magnetorquers]]\nname = \"a\"\naxis_b = [1.0, 0.0, 0.0]\n\
                   r_mb_b_m = [0.0, 0.0, 0.0]\nmax_dipole_am2 = 1.0\n";
        assert!(RodArray::from_config(&VehicleConfig::from_toml(cfg).unwrap()).is_err());
    }
}
