//! The per-stage hook of the integrator: how a model that integrates a quantity of its own
//! alongside the dynamics (an IMU's Δv, `flexdyn_sensors::imu`) sees every stage of a step
//! without living in the integrated [`State`], and the one RK4 combination of stage values that
//! the state update and the hooks share, so both give the same bits.
//!
//! [`Spacecraft::step_with`](super::Spacecraft::step_with) hands each stage's evaluation (the
//! stage state and its [`HubOutputs`]) to [`StageHook::stage`], then closes the step with
//! [`StageHook::end_step`], passing the integrator's [`StageCombine`]. A hook keeps at most
//! [`MAX_STAGES`] stage values; it does not know how many stages the integrator has nor how it
//! weighs them.

use std::ops::{Add, Mul};

use nalgebra::Vector3;

use super::integrator::{ButcherTableau, RK4};
use super::spacecraft::{HubOutputs, State};

/// The most stages any integrator hands a hook in one step (RK4 uses 4, RK8 13).
pub use super::integrator::MAX_STAGES;

/// The classical RK4 combination of the stage derivatives k1…k4 over a step of `h_s` seconds
/// (Butcher 2008, Eq. 235i): Δx = (k1 + 2 (k2 + k3) + k4) · h/6, in exactly this operation
/// order, so every quantity integrated with it — the state, an IMU's Δv — rounds alike.
#[inline(always)]
pub fn rk4_combine<T>(k1: T, k2: T, k3: T, k4: T, h_s: f64) -> T
where
    T: Add<Output = T> + Mul<f64, Output = T>,
{
    (k1 + (k2 + k3) * 2.0 + k4) * (h_s / 6.0)
}

/// How the integrator turns the stage values of one step into the step's increment: its
/// method's weights ([`ButcherTableau::combine_vec3`], [`rk4_combine`] for RK4), the same
/// arithmetic as the state's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageCombine {
    method: &'static ButcherTableau,
    /// \[s\] the step.
    h_s: f64,
}

impl StageCombine {
    /// The combination of `method` over a step of `h_s` seconds.
    pub fn new(method: &'static ButcherTableau, h_s: f64) -> Self {
        Self { method, h_s }
    }

    /// Classical RK4 over a step of `h_s` seconds.
    pub fn rk4(h_s: f64) -> Self {
        Self::new(&RK4, h_s)
    }

    /// Number of stages a step has (the values [`Self::vec3`] reads).
    pub fn n_stages(&self) -> usize {
        self.method.stages()
    }

    /// The increment over the step of a quantity whose derivative at stage `s` is `k[s]`; zero
    /// if `k` holds fewer than [`Self::n_stages`] values.
    #[inline]
    pub fn vec3(&self, k: &[Vector3<f64>]) -> Vector3<f64> {
        match k.get(..self.n_stages()) {
            Some(k) => self.method.combine_vec3(k, self.h_s),
            None => Vector3::zeros(),
        }
    }
}

/// What sees every stage of a step (see the module docs). Called on the stepping path: an
/// implementation allocates nothing, locks nothing and cannot fail.
pub trait StageHook {
    /// Stage `stage` (0-based, < [`MAX_STAGES`]) of the current step was evaluated at state
    /// `x`, giving the hub accelerations `hub`.
    fn stage(&mut self, stage: usize, x: &State, hub: &HubOutputs);

    /// The step is complete: combine the stage values with `combine`.
    fn end_step(&mut self, combine: &StageCombine);
}

/// No hook (plain [`Spacecraft::step`](super::Spacecraft::step)).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoHook;

impl StageHook for NoHook {
    #[inline(always)]
    fn stage(&mut self, _: usize, _: &State, _: &HubOutputs) {}

    #[inline(always)]
    fn end_step(&mut self, _: &StageCombine) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The RK4 combination integrates a cubic exactly (order 4): ∫₀ʰ t³ dt = h⁴/4, with the
    /// stage derivatives of ẋ = t³ at t = 0, h/2, h/2, h.
    #[test]
    fn rk4_combination_integrates_a_cubic_exactly() {
        let h = 0.5_f64;
        let f = |t: f64| t * t * t;
        let dx = rk4_combine(f(0.0), f(h / 2.0), f(h / 2.0), f(h), h);
        assert!((dx - h.powi(4) / 4.0).abs() < 1e-15, "{dx}");
        let k = [Vector3::new(1.0, 2.0, 3.0); MAX_STAGES];
        // A constant derivative gives k·h.
        assert!((StageCombine::rk4(h).vec3(&k) - Vector3::new(0.5, 1.0, 1.5)).amax() < 1e-15);
        assert_eq!(StageCombine::rk4(h).vec3(&k[..3]), Vector3::zeros());
    }
}
