//! Classical (Keplerian) orbital elements ↔ position and velocity in N.
//!
//! The elements are osculating two-body elements referred to N: the reference plane is N's
//! x–y plane (the GCRF equator) and the node is measured from N's x axis. With J2 (or any
//! perturbation) in the dynamics, they describe the initial state only; the orbit then evolves
//! under flexdyn's gravity.
//!
//! - Elements → r/v: the perifocal (PQW) state rotated by `[N PQW] = R3(−Ω) R1(−i) R3(−ω)`
//!   (Vallado, Fundamentals of Astrodynamics and Applications, 4th ed., Algorithm 10 COE2RV,
//!   Eqs. (2-110)–(2-112); Curtis, Orbital Mechanics for Engineering Students, Algorithm 4.5).
//! - A mean anomaly is converted through Kepler's equation M = E − e sin E (Vallado Eq. (2-4)),
//!   solved by [`eccentric_anomaly_rad`]: Newton–Raphson safeguarded by bisection on the bracket
//!   M ≤ E ≤ M + e (for 0 ≤ M ≤ π), so it converges for every 0 ≤ e < 1, even e → 1 with
//!   M → 0 where Newton alone overshoots.
//! - r/v → elements (for checks and reports): Vallado Algorithm 9 RV2COE, with atan2 forms.
//!   Where an angle is undefined the convention is stated on [`rv_to_elements`].
//!
//! Only closed orbits (0 ≤ e < 1) are accepted.

use nalgebra::{Matrix3, Vector3};

use crate::earth_rotation::{r1, r3};

const TAU: f64 = std::f64::consts::TAU;
const PI: f64 = std::f64::consts::PI;

/// Where on the orbit the state is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Anomaly {
    /// \[rad\] true anomaly ν.
    TrueRad(f64),
    /// \[rad\] mean anomaly M.
    MeanRad(f64),
}

/// Classical elements of a closed orbit, referred to N.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeplerianElements {
    /// \[m\] semi-major axis a > 0.
    pub semi_major_axis_m: f64,
    /// \[-\] eccentricity, 0 ≤ e < 1.
    pub eccentricity: f64,
    /// \[rad\] inclination i of the orbit plane to N's x–y plane, 0 ≤ i ≤ π.
    pub inclination_rad: f64,
    /// \[rad\] right ascension of the ascending node Ω, from N's x axis.
    pub raan_rad: f64,
    /// \[rad\] argument of perigee ω, from the ascending node.
    pub arg_perigee_rad: f64,
    /// The anomaly.
    pub anomaly: Anomaly,
}

/// A bad set of elements; names the configuration field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct ElementsError {
    /// Field path.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl KeplerianElements {
    /// Checks the ranges; `prefix` is the configuration path of the table (`orbit`), and
    /// `names` the keys used there for (a, e, i, Ω, ω, anomaly).
    pub fn validate(&self, prefix: &str, names: [&str; 6]) -> Result<(), ElementsError> {
        let field = |k: &str| {
            if prefix.is_empty() {
                k.to_string()
            } else {
                format!("{prefix}.{k}")
            }
        };
        let err = |k: &str, message: String| {
            Err(ElementsError {
                field: field(k),
                message,
            })
        };
        let anomaly = match self.anomaly {
            Anomaly::TrueRad(v) | Anomaly::MeanRad(v) => v,
        };
        for (k, v) in names.iter().zip([
            self.semi_major_axis_m,
            self.eccentricity,
            self.inclination_rad,
            self.raan_rad,
            self.arg_perigee_rad,
            anomaly,
        ]) {
            if !v.is_finite() {
                return err(k, "must be finite (got NaN or Inf)".to_string());
            }
        }
        if self.semi_major_axis_m <= 0.0 {
            return err(
                names[0],
                format!(
                    "the semi-major axis must be > 0 (got {} m; only closed orbits are accepted)",
                    self.semi_major_axis_m
                ),
            );
        }
        if !(0.0..1.0).contains(&self.eccentricity) {
            return err(
                names[1],
                format!(
                    "must be in [0, 1) (got {}; only closed orbits are accepted)",
                    self.eccentricity
                ),
            );
        }
        if !(0.0..=PI).contains(&self.inclination_rad) {
            return err(
                names[2],
                format!(
                    "must be in [0°, 180°] (got {}°)",
                    self.inclination_rad.to_degrees()
                ),
            );
        }
        Ok(())
    }

    /// \[rad\] the true anomaly (solving Kepler's equation for a mean anomaly).
    pub fn true_anomaly_rad(&self) -> f64 {
        match self.anomaly {
            Anomaly::TrueRad(nu) => nu,
            Anomaly::MeanRad(m) => true_of_eccentric_rad(
                eccentric_anomaly_rad(m, self.eccentricity),
                self.eccentricity,
            ),
        }
    }

    /// `[N PQW]`: maps perifocal components (P to perigee, W along the orbit normal) to N.
    pub fn dcm_n_pqw(&self) -> Matrix3<f64> {
        // [PQW N] = R3(ω) R1(i) R3(Ω) (Vallado Eq. (2-112) is its transpose).
        (r3(self.arg_perigee_rad) * r1(self.inclination_rad) * r3(self.raan_rad)).transpose()
    }

    /// \[m, m/s\] position and velocity in N for gravitational parameter `mu_m3_s2`
    /// (call [`Self::validate`] first; out-of-range elements give non-finite results, no panic).
    pub fn to_rv_n(&self, mu_m3_s2: f64) -> (Vector3<f64>, Vector3<f64>) {
        let e = self.eccentricity;
        let p = self.semi_major_axis_m * (1.0 - e * e);
        let nu = self.true_anomaly_rad();
        let (s, c) = nu.sin_cos();
        let r = p / (1.0 + e * c);
        let r_pqw = Vector3::new(r * c, r * s, 0.0);
        let k = (mu_m3_s2 / p).sqrt();
        let v_pqw = Vector3::new(-k * s, k * (e + c), 0.0);
        let dcm = self.dcm_n_pqw();
        (dcm * r_pqw, dcm * v_pqw)
    }
}

/// \[rad\] the eccentric anomaly E solving Kepler's equation M = E − e sin E, for 0 ≤ e < 1
/// and any finite M; E has the same whole turns as M. Newton–Raphson on the bracket
/// M ≤ E ≤ M + e (after reducing M to [0, π] by symmetry), with a bisection whenever a step
/// would leave it, to |ΔE| ≤ 4 ulp: it always converges (at most ~60 steps at e → 1, typically
/// 3–5).
pub fn eccentric_anomaly_rad(mean_anomaly_rad: f64, e: f64) -> f64 {
    // Reduce M to (−π, π] and then to [0, π] by symmetry (E(−M) = −E(M)).
    let turns = ((mean_anomaly_rad + PI) / TAU).floor();
    let m_red = mean_anomaly_rad - turns * TAU;
    let (sign, m) = if m_red < 0.0 {
        (-1.0, -m_red)
    } else {
        (1.0, m_red)
    };
    let (mut lo, mut hi) = (m, (m + e).min(PI));
    // Starter (Danby 1987, M + 0.85 e), clamped to the bracket.
    let mut x = (m + 0.85 * e).clamp(lo, hi);
    for _ in 0..200 {
        let (s, c) = x.sin_cos();
        let f = x - e * s - m;
        if f == 0.0 {
            break;
        }
        if f > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let fp = 1.0 - e * c;
        let mut next = x - f / fp;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - x).abs() <= 4.0 * f64::EPSILON * x.abs().max(1.0) || hi - lo <= f64::EPSILON * hi
        {
            x = next;
            break;
        }
        x = next;
    }
    sign * x + turns * TAU
}

/// \[rad\] the true anomaly of eccentric anomaly `ecc_anomaly_rad` (Vallado Eq. (2-9), half-angle
/// form), in the same turn.
pub fn true_of_eccentric_rad(ecc_anomaly_rad: f64, e: f64) -> f64 {
    let half = 0.5 * ecc_anomaly_rad;
    let turns = ((ecc_anomaly_rad + PI) / TAU).floor();
    let nu = 2.0 * ((1.0 + e).sqrt() * half.sin()).atan2((1.0 - e).sqrt() * half.cos());
    // atan2 gives (−2π, 2π]; bring it into E's turn.
    let nu_red = nu - ((nu + PI) / TAU).floor() * TAU;
    nu_red + turns * TAU
}

/// \[rad\] the mean anomaly of true anomaly `nu_rad` (inverse of the above, Vallado Eq. (2-9)).
pub fn mean_of_true_rad(nu_rad: f64, e: f64) -> f64 {
    let half = 0.5 * nu_rad;
    let ecc = 2.0 * ((1.0 - e).sqrt() * half.sin()).atan2((1.0 + e).sqrt() * half.cos());
    ecc - e * ecc.sin()
}

/// Elements of the orbit through `r_n_m` with velocity `v_n_m_s` (Vallado Algorithm 9),
/// anomaly as true anomaly, angles in [0, 2π). Conventions where the classical angles are
/// undefined (tolerance 1e-11 on e and on sin i):
/// - circular orbit: ω = 0, so ν is the argument of latitude (from the node);
/// - equatorial orbit: Ω = 0, so ω is measured from N's x axis (longitude of perigee);
/// - both: Ω = ω = 0, ν is the true longitude.
///
/// A state that is not a closed orbit returns e ≥ 1 (and a negative or infinite a).
pub fn rv_to_elements(
    r_n_m: &Vector3<f64>,
    v_n_m_s: &Vector3<f64>,
    mu_m3_s2: f64,
) -> KeplerianElements {
    let r = r_n_m.norm();
    let v2 = v_n_m_s.norm_squared();
    let h = r_n_m.cross(v_n_m_s);
    let h_hat = h / h.norm();
    let e_vec = ((v2 - mu_m3_s2 / r) * r_n_m - r_n_m.dot(v_n_m_s) * v_n_m_s) / mu_m3_s2;
    let e = e_vec.norm();
    let a = 1.0 / (2.0 / r - v2 / mu_m3_s2);
    let inc = h_hat.z.clamp(-1.0, 1.0).acos();
    let node = Vector3::z().cross(&h_hat);
    let tol = 1e-11;
    let wrap = |x: f64| x.rem_euclid(TAU);
    let equatorial = node.norm() < tol;
    let n_hat = if equatorial {
        // Retrograde equatorial orbits measure from x too; the sign of h decides the sense.
        Vector3::x()
    } else {
        node / node.norm()
    };
    let raan = if equatorial {
        0.0
    } else {
        n_hat.y.atan2(n_hat.x)
    };
    // Angle from `a` to `b` about h_hat.
    let angle = |a: &Vector3<f64>, b: &Vector3<f64>| h_hat.dot(&a.cross(b)).atan2(a.dot(b));
    let (argp, nu) = if e < tol {
        (0.0, angle(&n_hat, r_n_m))
    } else {
        (angle(&n_hat, &e_vec), angle(&e_vec, r_n_m))
    };
    KeplerianElements {
        semi_major_axis_m: a,
        eccentricity: e,
        inclination_rad: inc,
        raan_rad: wrap(raan),
        arg_perigee_rad: wrap(argp),
        anomaly: Anomaly::TrueRad(wrap(nu)),
    }
}
