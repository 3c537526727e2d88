//! The classical fourth-order Runge–Kutta method (Kutta 1901; Butcher, "Numerical Methods for
//! Ordinary Differential Equations", 3rd ed., Wiley 2016, Sec. 235, tableau (235a)).

use super::{ButcherTableau, Combine};

/// Classical RK4: c = (0, ½, ½, 1), b = (1, 2, 2, 1)/6. The default method.
pub static RK4: ButcherTableau = ButcherTableau {
    name: "rk4",
    order: 4,
    c: &[0.0, 0.5, 0.5, 1.0],
    a: &[&[], &[0.5], &[0.0, 0.5], &[0.0, 0.0, 1.0]],
    b: &[1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
    combine: Combine::ClassicRk4,
    source: "Butcher (2016), Numerical Methods for ODEs, tableau (235a)",
};
