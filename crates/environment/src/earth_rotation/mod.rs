//! The rotation from the inertial frame N (GCRF) to the Earth-fixed frame E (ITRF), and the
//! Earth's angular velocity.
//!
//! # Model (equinox based, IERS Conventions (2010) §5.5–5.6, IAU 2006/2000B)
//!
//! `[E N] = W · R3(GAST) · R1(−ε_A−Δε) · R3(−ψ̄−Δψ) · R1(φ̄) · R3(γ̄)`, i.e. `r_e = dcm_en · r_n`:
//!
//! - **Frame bias and precession**: the Fukushima–Williams angles γ̄, φ̄, ψ̄ of the IAU 2006
//!   precession, referred to the GCRS so that the frame bias is included (Hilton et al. 2006,
//!   Celest. Mech. Dyn. Astron. 94, 351; Capitaine & Wallace 2006, A&A 450, 855; IERS
//!   Conventions (2010) §5.6.4), and the IAU 2006 mean obliquity ε_A (Hilton et al. 2006).
//! - **Nutation** Δψ, Δε: IAU 2000B, 77 luni-solar terms plus fixed planetary offsets
//!   (McCarthy & Luzum 2003, [`nutation_2000b`]).
//! - **Sidereal time**: GAST = GMST + EE, with the IAU 2006 GMST as the Earth rotation angle
//!   plus a polynomial in TT (IERS Conventions (2010) Eq. (5.32); ERA Eq. (5.15)) and the
//!   equation of the equinoxes EE = Δψ cos ε_A + 2640.96 µas sin Ω + 63.52 µas sin 2Ω (the two
//!   leading complementary terms of IERS Conventions (2010) Table 5.2e; Capitaine et al. 2003).
//! - **Polar motion** `W = R1(−y_p) · R2(−x_p)` (IERS Conventions (2010) Eq. (5.3), transposed to
//!   TIRS → ITRS), from the configured x_p, y_p (zero by default); the TIO locator s′
//!   (−47 µas per century) is neglected.
//!
//! `R1, R2, R3` are the IERS passive rotations, e.g. `R3(θ) = [[c, s, 0], [−s, c, 0], [0, 0, 1]]`.
//!
//! # Error bound (rotation angle of the computed `[E N]` from the IERS 2010 one)
//! - Model, with the Earth orientation parameters given: ≤ 1.7 mas (8.2 nrad; 6 cm at 7,000 km)
//!   over 1995–2050: IAU 2000B vs 2000A ≤ 1.001 mas (McCarthy & Luzum 2003, as SOFA measures it
//!   for 1995–2050), + 0.042 mas for the 31 omitted complementary terms of EE (the sum of their
//!   amplitudes), + 0.06 mas for the IAU 2006 adjustments of the nutation and s′ (both ∝ t, at
//!   2100), + 0.5 mas for the unmodelled free-core nutation and CIP offsets dX, dY (which
//!   Bulletin A reports, ≲ 0.3 mas). Outside 1995–2050 the 2000B fit is "usually better than
//!   1 mas" (SOFA) to 2100.
//! - UT1 − UTC not configured: + up to 0.9 s of Earth rotation, 13.5″ (65 µrad: 0.46 km at
//!   7,000 km, about the pole) — by far the largest term; configure `ut1_minus_utc_s` to remove
//!   it. Over a run, UT1 − TAI drifts by ≤ 3 ms per day (45 mas per day).
//! - Polar motion not configured: + up to |(x_p, y_p)| ≈ 0.6″ (3 µrad: 20 m at 7,000 km).
//!
//! `crates/environment/tests/earth_rotation.rs` checks each piece against the IAU SOFA validation
//! values and the whole chain against Vallado's worked example (Vallado, Fundamentals of
//! Astrodynamics and Applications, 4th ed., Example 3-14; Vallado et al. 2006, AIAA 2006-6753,
//! Appendix C).
//!
//! # Cost and update rate
//! [`CelestialPole::at`] (precession + 77-term nutation) is the expensive part; it changes
//! slowly (the pole moves less than 10 µas per second), so it may be held for seconds and only
//! the sidereal rotation re-evaluated ([`EarthRotation::at_with_pole`]). The `time_rotation`
//! bench prints both costs.

mod nutation_2000b;
pub mod schema;
mod uniform;

pub use uniform::UniformRotation;

use nalgebra::{Matrix3, Vector3};

use super::epoch::{EarthOrientationParams, EpochTimes, NS_PER_DAY};

const TAU: f64 = std::f64::consts::TAU;
/// Radians per arcsecond.
const AS2R: f64 = std::f64::consts::PI / 648_000.0;
/// Arcseconds in a full turn.
const TURN_AS: f64 = 1_296_000.0;

/// \[rad/s\] the Earth's rotation rate relative to the GCRF: the rate of the Earth rotation
/// angle, 2π · 1.00273781191135448 per UT1 day (IERS Conventions (2010) Eq. (5.15)). The
/// conventional WGS 84 value 7.292115e-5 rad/s agrees to 2e-8 relative.
#[expect(clippy::excessive_precision, reason = "the IERS digits, as published")]
pub const OMEGA_EARTH_RAD_S: f64 = TAU * 1.002_737_811_911_354_48 / 86_400.0;

// The IERS passive rotations R1, R2, R3 are the attitude kernels' principal-axis rotations
// M1, M2, M3 (the same matrices: `R3(θ) = [[c, s, 0], [−s, c, 0], [0, 0, 1]]`).
pub use flexdyn_kernel::attitude::{m1 as r1, m2 as r2, m3 as r3};

/// `x` reduced to [0, 2π).
fn wrap_2pi(x: f64) -> f64 {
    x.rem_euclid(TAU)
}

/// The UT1 day count split exactly: (whole days, fraction of day) since J2000.0 UT1.
fn ut1_days_split(ut1_ns_j2000: i64) -> (f64, f64) {
    let days = ut1_ns_j2000.div_euclid(NS_PER_DAY);
    let frac = ut1_ns_j2000.rem_euclid(NS_PER_DAY) as f64 / NS_PER_DAY as f64;
    (days as f64, frac)
}

/// \[rad\] the Earth rotation angle θ = 2π (0.7790572732640 + 1.00273781191135448 D_U), D_U =
/// JD_UT1 − 2451545.0 (IERS Conventions (2010) Eq. (5.15)); evaluated as
/// 2π (frac(D_U) + 0.7790572732640 + 0.00273781191135448 D_U) to keep the precision of the
/// fraction of day.
pub fn earth_rotation_angle_rad(ut1_ns_j2000: i64) -> f64 {
    let (days, frac) = ut1_days_split(ut1_ns_j2000);
    let du = days + frac;
    wrap_2pi(TAU * (frac + 0.779_057_273_264_0 + 0.002_737_811_911_354_48 * du))
}

/// \[rad\] Greenwich mean sidereal time, IAU 2006: ERA(UT1) + 0.014506″ + 4612.156534″ t +
/// 1.3915817″ t² − 0.00000044″ t³ − 0.000029956″ t⁴ − 0.0000000368″ t⁵, t in Julian centuries
/// TT since J2000.0 (IERS Conventions (2010) Eq. (5.32); Capitaine et al. 2005).
pub fn gmst06_rad(ut1_ns_j2000: i64, tt_centuries: f64) -> f64 {
    let t = tt_centuries;
    let poly_as = 0.014_506
        + (4_612.156_534
            + (1.391_581_7 + (-0.000_000_44 + (-0.000_029_956 + -0.000_000_036_8 * t) * t) * t)
                * t)
            * t;
    wrap_2pi(earth_rotation_angle_rad(ut1_ns_j2000) + poly_as * AS2R)
}

/// \[rad\] Greenwich mean sidereal time, IAU 1982 (Aoki et al. 1982, A&A 105, 359):
/// GMST = 24110.54841 s + 8640184.812866 s T_U + 0.093104 s T_U² − 6.2e-6 s T_U³ + UT1 of day,
/// T_U in Julian centuries UT1 since J2000.0 — the sidereal time that defines SGP4's TEME
/// (Vallado et al. 2006, AIAA 2006-6753).
pub fn gmst82_rad(ut1_ns_j2000: i64) -> f64 {
    let (days, frac) = ut1_days_split(ut1_ns_j2000);
    let tu = (days + frac) / 36_525.0;
    // Seconds of UT1 since 0h: the day count starts at noon.
    let ut1_of_day_s = (frac + 0.5).fract() * 86_400.0;
    let gmst_s =
        24_110.548_41 + (8_640_184.812_866 + (0.093_104 - 6.2e-6 * tu) * tu) * tu + ut1_of_day_s;
    wrap_2pi(gmst_s * (TAU / 86_400.0))
}

/// The Fukushima–Williams precession angles (frame bias included) and the mean obliquity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FwAngles {
    /// \[rad\] γ̄: GCRS-referred ecliptic node angle.
    pub gamma_bar_rad: f64,
    /// \[rad\] φ̄: obliquity of the ecliptic of date on the GCRS equator.
    pub phi_bar_rad: f64,
    /// \[rad\] ψ̄: precession in longitude along the ecliptic of date.
    pub psi_bar_rad: f64,
    /// \[rad\] ε_A: mean obliquity of date.
    pub eps_a_rad: f64,
}

/// \[rad\] the IAU 2006 mean obliquity ε_A = 84381.406″ − 46.836769″ t − 0.0001831″ t² +
/// 0.00200340″ t³ − 0.000000576″ t⁴ − 0.0000000434″ t⁵ (Hilton et al. 2006; IERS Conventions
/// (2010) Eq. (5.40)), t in Julian centuries TT.
pub fn mean_obliquity06_rad(tt_centuries: f64) -> f64 {
    let t = tt_centuries;
    (84_381.406
        + (-46.836_769
            + (-0.000_183_1 + (0.002_003_40 + (-0.000_000_576 + -0.000_000_043_4 * t) * t) * t)
                * t)
            * t)
        * AS2R
}

/// The IAU 2006 Fukushima–Williams angles at `tt_centuries` (Hilton et al. 2006, Table; IERS
/// Conventions (2010) §5.6.4), GCRS-referred.
pub fn precession_fw06(tt_centuries: f64) -> FwAngles {
    let t = tt_centuries;
    let gamma_bar = -0.052_928
        + (10.556_378
            + (0.493_204_4 + (-0.000_312_38 + (-0.000_002_788 + 0.000_000_026_0 * t) * t) * t) * t)
            * t;
    let phi_bar = 84_381.412_819
        + (-46.811_016
            + (0.051_126_8 + (0.000_532_89 + (-0.000_000_440 + -0.000_000_017_6 * t) * t) * t) * t)
            * t;
    let psi_bar = -0.041_775
        + (5_038.481_484
            + (1.558_417_5 + (-0.000_185_22 + (-0.000_026_452 + -0.000_000_014_8 * t) * t) * t)
                * t)
            * t;
    FwAngles {
        gamma_bar_rad: gamma_bar * AS2R,
        phi_bar_rad: phi_bar * AS2R,
        psi_bar_rad: psi_bar * AS2R,
        eps_a_rad: mean_obliquity06_rad(t),
    }
}

/// The nutation angles and the Moon's node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nutation {
    /// \[rad\] nutation in longitude Δψ.
    pub dpsi_rad: f64,
    /// \[rad\] nutation in obliquity Δε.
    pub deps_rad: f64,
    /// \[rad\] mean longitude of the Moon's ascending node Ω (an argument of EE).
    pub moon_node_rad: f64,
}

/// IAU 2000B nutation at `tt_centuries` (McCarthy & Luzum 2003): the 77-term luni-solar series
/// with the Delaunay arguments of Simon et al. (1994, A&A 282, 663) as IAU 2000B takes them
/// (linear in t), plus the fixed planetary offsets Δψ −0.135 mas, Δε +0.388 mas.
pub fn nutation_2000b(tt_centuries: f64) -> Nutation {
    let t = tt_centuries;
    let arg = |a0: f64, a1: f64| (a0 + a1 * t).rem_euclid(TURN_AS) * AS2R;
    // Delaunay arguments l, l', F, D, Ω [rad].
    let fa = [
        arg(485_868.249_036, 1_717_915_923.217_8),
        arg(1_287_104.793_05, 129_596_581.048_1),
        arg(335_779.526_232, 1_739_527_262.847_8),
        arg(1_072_260.703_69, 1_602_961_601.209_0),
        arg(450_160.398_036, -6_962_890.543_1),
    ];
    let (mut dp, mut de) = (0.0, 0.0);
    // Smallest terms first, to sum with the least rounding.
    for (m, c) in nutation_2000b::TERMS_2000B.iter().rev() {
        let a = f64::from(m[0]) * fa[0]
            + f64::from(m[1]) * fa[1]
            + f64::from(m[2]) * fa[2]
            + f64::from(m[3]) * fa[3]
            + f64::from(m[4]) * fa[4];
        let (s, co) = a.sin_cos();
        dp += (c[0] + c[1] * t) * s + c[2] * co;
        de += (c[3] + c[4] * t) * co + c[5] * s;
    }
    // 0.1 µas → rad; planetary offsets in mas.
    let u2r = AS2R * 1e-7;
    Nutation {
        dpsi_rad: dp * u2r - 0.135e-3 * AS2R,
        deps_rad: de * u2r + 0.388e-3 * AS2R,
        moon_node_rad: fa[4],
    }
}

/// \[rad\] the equation of the equinoxes EE = Δψ cos ε_A + 2640.96 µas sin Ω + 63.52 µas sin 2Ω
/// (IERS Conventions (2010) Table 5.2e: the two leading complementary terms; the 31 others sum
/// to less than 42 µas).
pub fn equation_of_equinoxes_rad(nut: &Nutation, eps_a_rad: f64) -> f64 {
    let om = nut.moon_node_rad;
    nut.dpsi_rad * eps_a_rad.cos() + (2_640.96e-6 * om.sin() + 63.52e-6 * (2.0 * om).sin()) * AS2R
}

/// The matrix of Fukushima–Williams angles, `R1(−ε) · R3(−ψ) · R1(φ) · R3(γ)` (Capitaine &
/// Wallace 2006): with the precession angles alone it is the bias–precession matrix; with
/// ψ = ψ̄ + Δψ and ε = ε_A + Δε it is the bias–precession–nutation matrix `[TOD N]` (N to the
/// true equator and equinox of date).
pub fn fw_matrix(gamma_rad: f64, phi_rad: f64, psi_rad: f64, eps_rad: f64) -> Matrix3<f64> {
    r1(-eps_rad) * r3(-psi_rad) * r1(phi_rad) * r3(gamma_rad)
}

/// The polar-motion matrix TIRS → ITRS, `R1(−y_p) · R2(−x_p)` (the transpose of IERS
/// Conventions (2010) Eq. (5.3)'s W with s′ = 0).
pub fn polar_motion_dcm(x_p_rad: f64, y_p_rad: f64) -> Matrix3<f64> {
    r1(-y_p_rad) * r2(-x_p_rad)
}

/// The celestial pole of date: the bias–precession–nutation matrix and the equation of the
/// equinoxes. Slow: evaluate it at a low rate and hold it (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CelestialPole {
    /// `[TOD N]`: maps N (GCRF) components to the true equator and equinox of date.
    pub dcm_tod_n: Matrix3<f64>,
    /// \[rad\] equation of the equinoxes.
    pub eqeq_rad: f64,
    /// \[Julian centuries TT\] the time it was evaluated at.
    pub tt_centuries: f64,
}

impl CelestialPole {
    /// The pole at `tt_centuries` (Julian centuries TT since J2000.0).
    pub fn at(tt_centuries: f64) -> Self {
        let fw = precession_fw06(tt_centuries);
        let nut = nutation_2000b(tt_centuries);
        Self {
            dcm_tod_n: fw_matrix(
                fw.gamma_bar_rad,
                fw.phi_bar_rad,
                fw.psi_bar_rad + nut.dpsi_rad,
                fw.eps_a_rad + nut.deps_rad,
            ),
            eqeq_rad: equation_of_equinoxes_rad(&nut, fw.eps_a_rad),
            tt_centuries,
        }
    }

    /// \[rad\] GAST at `times` with this pole's equation of the equinoxes.
    pub fn gast_rad(&self, times: &EpochTimes) -> f64 {
        wrap_2pi(gmst06_rad(times.ut1_ns_j2000, times.tt_centuries_j2000()) + self.eqeq_rad)
    }

    /// \[unit\] the celestial intermediate pole (the Earth's rotation axis) in N.
    pub fn cip_n(&self) -> Vector3<f64> {
        self.dcm_tod_n.row(2).transpose()
    }
}

/// The Earth-fixed frame at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EarthFrame {
    /// `[E N]`: maps N (GCRF) components to E (ITRF) components, `r_e = dcm_en · r_n`.
    pub dcm_en: Matrix3<f64>,
    /// \[rad/s\] ω_E/N, the Earth's angular velocity relative to N, in N components (along the
    /// celestial intermediate pole, magnitude [`OMEGA_EARTH_RAD_S`]). The co-rotating
    /// atmosphere moves at `omega_en_n_rad_s × r_n` in N.
    pub omega_en_n_rad_s: Vector3<f64>,
    /// \[rad\] Greenwich apparent sidereal time.
    pub gast_rad: f64,
}

impl EarthFrame {
    /// `[N E]`, the transpose of [`Self::dcm_en`].
    pub fn dcm_ne(&self) -> Matrix3<f64> {
        self.dcm_en.transpose()
    }
    /// \[m\] a position in E from one in N.
    pub fn r_e(&self, r_n: &Vector3<f64>) -> Vector3<f64> {
        self.dcm_en * r_n
    }
    /// \[m/s\] the velocity relative to E, in E, of a point at `r_n` moving at `v_n` in N:
    /// `dcm_en · (v_n − ω_E/N × r_n)` (the transport theorem).
    pub fn v_e(&self, r_n: &Vector3<f64>, v_n: &Vector3<f64>) -> Vector3<f64> {
        self.dcm_en * (v_n - self.omega_en_n_rad_s.cross(r_n))
    }
    /// \[m\] a position in N from one in E.
    pub fn r_n(&self, r_e: &Vector3<f64>) -> Vector3<f64> {
        self.dcm_en.tr_mul(r_e)
    }
    /// \[m/s\] the inertial velocity in N of a point at `r_e` moving at `v_e` relative to E.
    pub fn v_n(&self, r_e: &Vector3<f64>, v_e: &Vector3<f64>) -> Vector3<f64> {
        let r_n = self.r_n(r_e);
        self.dcm_en.tr_mul(v_e) + self.omega_en_n_rad_s.cross(&r_n)
    }
}

/// The Earth's rotation for a run: the polar motion of its epoch, held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EarthRotation {
    /// `[E TIRS]`: polar motion (identity when x_p = y_p = 0).
    dcm_e_tirs: Matrix3<f64>,
}

impl EarthRotation {
    /// From the Earth orientation parameters of the epoch (UT1 − UTC is already in
    /// [`EpochTimes::ut1_ns_j2000`]).
    pub fn new(eop: &EarthOrientationParams) -> Self {
        Self {
            dcm_e_tirs: polar_motion_dcm(eop.polar_motion_x_rad, eop.polar_motion_y_rad),
        }
    }

    /// The Earth-fixed frame at `times`, evaluating the celestial pole too. Allocation-free.
    pub fn at(&self, times: &EpochTimes) -> EarthFrame {
        self.at_with_pole(&CelestialPole::at(times.tt_centuries_j2000()), times)
    }

    /// The Earth-fixed frame at `times` with a pole evaluated earlier (the fast path: one
    /// sidereal time and two 3×3 products). Allocation-free.
    pub fn at_with_pole(&self, pole: &CelestialPole, times: &EpochTimes) -> EarthFrame {
        let gast = pole.gast_rad(times);
        EarthFrame {
            dcm_en: self.dcm_e_tirs * r3(gast) * pole.dcm_tod_n,
            omega_en_n_rad_s: pole.cip_n() * OMEGA_EARTH_RAD_S,
            gast_rad: gast,
        }
    }
}

/// Which model gives `[E N]` (`environment.earth_rotation`): the IAU 2006/2000B chain of this
/// module (the default), or a [`UniformRotation`] about N's third axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EarthOrientationModel {
    /// [`EarthRotation`]: IAU 2006 precession, IAU 2000B nutation, sidereal time, polar motion.
    Iau2006,
    /// A uniform rotation at a given rate from a given angle.
    Uniform(UniformRotation),
}

/// The Earth's orientation for a run, built: what the environment and the GPS receiver both
/// rotate with, so that they agree to the bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EarthOrientation {
    /// The IAU chain with the epoch's polar motion.
    Iau2006(EarthRotation),
    /// A uniform rotation (the date never enters).
    Uniform(UniformRotation),
}

impl EarthOrientation {
    /// `model` for a run whose epoch has the orientation parameters `eop`.
    pub fn new(model: EarthOrientationModel, eop: &EarthOrientationParams) -> Self {
        match model {
            EarthOrientationModel::Iau2006 => Self::Iau2006(EarthRotation::new(eop)),
            EarthOrientationModel::Uniform(u) => Self::Uniform(u),
        }
    }

    /// Whether the frame depends on the date's time scales (the IAU chain) or only on the
    /// simulation time (a uniform rotation).
    pub fn is_dated(&self) -> bool {
        matches!(self, Self::Iau2006(_))
    }

    /// The Earth-fixed frame at `t_sim_ns`, whose time scales are `times`. Allocation-free.
    pub fn at(&self, times: &EpochTimes, t_sim_ns: u64) -> EarthFrame {
        match self {
            Self::Iau2006(r) => r.at(times),
            Self::Uniform(u) => u.at(t_sim_ns),
        }
    }
}

/// `[N TEME]`: maps SGP4's TEME components (true equator, mean equinox of date) to N.
///
/// TEME is defined by SGP4's use of the IAU 1982 GMST: the pseudo-Earth-fixed frame (TIRS,
/// polar motion excluded) is `R3(GMST82) · TEME`. So `[N TEME] = ([TIRS N])ᵀ · R3(GMST82)` with
/// `[TIRS N] = R3(GAST) · [TOD N]` from this module — the route through the pseudo-Earth-fixed
/// frame that Vallado et al. (2006, AIAA 2006-6753, §"Coordinate systems") recommend over the
/// ambiguous TEME → TOD equation of the equinoxes. UT1 enters both sidereal times at the same
/// rate to 1e-7, so an error in UT1 − UTC cancels (0.9 s of it moves `[N TEME]` by 6e-12 rad). Error: the bound of [`EarthRotation`]'s model (1.7 mas)
/// plus the ambiguity of the TEME definition itself, up to the 2.7 mas of the equation of the
/// equinoxes' complementary terms (whether SGP4's producers apply them is undocumented):
/// ≤ 4.4 mas (0.15 m at 7,000 km), far below the error of the element sets themselves (a
/// kilometre or so at epoch).
pub fn dcm_n_teme(pole: &CelestialPole, times: &EpochTimes) -> Matrix3<f64> {
    let dcm_tirs_n = r3(pole.gast_rad(times)) * pole.dcm_tod_n;
    dcm_tirs_n.tr_mul(&r3(gmst82_rad(times.ut1_ns_j2000)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_are_passive() {
        // R3(90°) maps the x axis to −y components (the frame turns, the vector stays).
        let v = r3(std::f64::consts::FRAC_PI_2) * Vector3::x();
        assert!((v - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-15);
        let v = r1(std::f64::consts::FRAC_PI_2) * Vector3::y();
        assert!((v - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-15);
        let v = r2(std::f64::consts::FRAC_PI_2) * Vector3::z();
        assert!((v - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-15);
    }

    #[test]
    fn omega_matches_wgs84_nominal() {
        assert!((OMEGA_EARTH_RAD_S / 7.292_115e-5 - 1.0).abs() < 3e-8);
    }
}
