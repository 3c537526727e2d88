//! Fixed-step explicit Runge–Kutta methods for [`Spacecraft::step`](super::Spacecraft::step),
//! each a Butcher tableau in its own file and one line of [`METHODS`].
//!
//! A method is chosen in the configuration by `[simulation] integrator` (the name of one of
//! [`METHODS`]); RK4 is the default. The step is a whole number of nanoseconds whatever the
//! method, so a frame stays a whole number of steps; the MRP shadow switch happens after each
//! full step. Every state effector and dynamic effector sees the stage times `c_i h`.
//!
//! No symplectic or energy-preserving scheme is offered: see the book section
//! "Choosing the integrator" for why (damping, motor and friction torques, the MRP switch and the
//! back-substituted, non-separable equations of motion).

use std::ops::{Add, Mul};

use nalgebra::Vector3;

mod dopri8;
mod rk4;

pub use dopri8::RK8;
pub use rk4::RK4;

/// The registered methods; the configuration accepts their names. One line per method.
pub const METHODS: &[&ButcherTableau] = &[
    &rk4::RK4,    // "rk4": classical RK4, the default (listed first)
    &dopri8::RK8, // "rk8": Prince & Dormand RK8(7)13M, eighth-order weights
];

/// The most stages any registered method has (the size of the stack buffers that gather one
/// quantity's stage values).
pub const MAX_STAGES: usize = 13;

/// How a method combines its stage derivatives into the step's increment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Combine {
    /// The classical RK4 weights (1, 2, 2, 1)/6 written as `(k1 + (k2 + k3)·2 + k4)·(h/6)`: the
    /// exact floating-point expression flexdyn has always used, so RK4 runs stay bit-identical.
    ClassicRk4,
    /// `(Σ b_i k_i)·h` over the non-zero weights, in stage order.
    Weighted,
}

/// An explicit Runge–Kutta method: y₁ = y₀ + h Σ b_i k_i, k_i = f(t₀ + c_i h, y₀ + h Σ_j a_ij k_j).
#[derive(Debug, PartialEq)]
pub struct ButcherTableau {
    /// The name `[simulation] integrator` takes.
    pub name: &'static str,
    /// Classical order of the weights used.
    pub order: u32,
    /// Nodes c_i (c_1 = 0).
    pub c: &'static [f64],
    /// Rows of the strictly lower-triangular matrix: row i holds a_i1 … a_i,i−1 (row 0 empty).
    pub a: &'static [&'static [f64]],
    /// Weights b_i.
    pub b: &'static [f64],
    /// How the weights are applied.
    pub combine: Combine,
    /// Where the coefficients come from.
    pub source: &'static str,
}

impl ButcherTableau {
    /// Number of stages (derivative evaluations per step).
    pub fn stages(&self) -> usize {
        self.b.len()
    }

    /// The step increment h Σ b_i k_i for one quantity whose stage values `k(i)` returns.
    #[inline(always)]
    pub fn combine<T>(&self, k: impl Fn(usize) -> T, h: f64) -> T
    where
        T: Copy + Add<Output = T> + Mul<f64, Output = T>,
    {
        match self.combine {
            Combine::ClassicRk4 => super::stage_hook::rk4_combine(k(0), k(1), k(2), k(3), h),
            Combine::Weighted => {
                let mut acc: Option<T> = None;
                for (i, &b) in self.b.iter().enumerate() {
                    if b != 0.0 {
                        let term = k(i) * b;
                        acc = Some(match acc {
                            None => term,
                            Some(s) => s + term,
                        });
                    }
                }
                acc.unwrap_or_else(|| k(0) * 0.0) * h
            }
        }
    }

    /// The step increment h Σ b_i k_i of a vector quantity from its stage values `k` (one per
    /// stage, in order). For RK4 it is `(k1 + (k2 + k3)·2 + k4)·(h/6)`, bit for bit.
    #[inline(always)]
    pub fn combine_vec3(&self, k: &[Vector3<f64>], h: f64) -> Vector3<f64> {
        self.combine(|i| k[i], h)
    }
}

/// The method named `name`, if registered.
pub fn by_name(name: &str) -> Option<&'static ButcherTableau> {
    METHODS.iter().copied().find(|m| m.name == name)
}

/// The registered names, quoted and joined for an error message (`"rk4" or "rk8"`).
pub fn names_for_message() -> String {
    let quoted: Vec<String> = METHODS.iter().map(|m| format!("\"{}\"", m.name)).collect();
    match quoted.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests;
