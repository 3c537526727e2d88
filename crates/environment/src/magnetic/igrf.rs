//! The International Geomagnetic Reference Field, 14th generation, to a chosen degree.
//!
//! The main field is the gradient of a scalar potential (Alken et al., *Earth, Planets and Space*
//! 77, 2025, eq. 1; Langel, "The main field", in *Geomagnetism* vol. 1, 1987, §4.1):
//!
//! V(r, θ, φ, t) = a Σₙ (a/r)ⁿ⁺¹ Σₘ [gₙᵐ(t) cos mφ + hₙᵐ(t) sin mφ] Pₙᵐ(cos θ),
//!
//! with a = 6371.2 km, θ the geocentric colatitude, φ the east longitude, Pₙᵐ the Schmidt
//! semi-normalised associated Legendre functions and B = −∇V:
//!
//! - B_r = Σₙ (n+1) (a/r)ⁿ⁺² Σₘ (g cos mφ + h sin mφ) Pₙᵐ,
//! - B_θ = −Σₙ (a/r)ⁿ⁺² Σₘ (g cos mφ + h sin mφ) dPₙᵐ/dθ,
//! - B_φ = (1/sin θ) Σₙ (a/r)ⁿ⁺² Σₘ m (g sin mφ − h cos mφ) Pₙᵐ.
//!
//! The Schmidt functions and their θ-derivatives come from the standard recursions (Langel 1987,
//! §4.1; the same as the IAGA program `igrf14syn`): P₁¹ = sin θ,
//! Pₙⁿ = √((2n−1)/(2n)) sin θ Pₙ₋₁ⁿ⁻¹ (n ≥ 2), and for m < n
//! Pₙᵐ = [(2n−1) cos θ Pₙ₋₁ᵐ − √((n−1)²−m²) Pₙ₋₂ᵐ] / √(n²−m²).
//!
//! The coefficients of a date are the linear interpolation between the two bracketing epochs of
//! the shipped file (five-year steps; the last column, 2030.0, is the 2025 field plus its
//! predictive secular variation), which is the IGRF definition. The model covers 1900.0–2030.0;
//! [`Igrf::check_date`] reports a date outside it as [`MagneticError::DateOutsideModel`], and
//! the evaluation itself clamps the date to the span so it can never fail on the hot path.
//!
//! Checked against the IGRF-14 test values of the IAGA reference program (12 positions and dates,
//! 1900–2030) to 0.01 nT in `crates/environment/tests/magnetic.rs`.

use nalgebra::Vector3;

use super::MagneticError;

/// The highest degree of IGRF-14 (and of every IGRF since the 11th generation).
pub const IGRF_MAX_DEGREE: usize = 13;
const N: usize = IGRF_MAX_DEGREE + 1;

/// \[m\] the IGRF reference radius a (the Earth's mean radius of the model).
pub const IGRF_REFERENCE_RADIUS_M: f64 = 6_371_200.0;

/// The IGRF-14 coefficient file, shipped in the repository (see `README.md` beside it).
pub const IGRF14_SHC: &str = include_str!("IGRF14.SHC");

/// Schmidt semi-normalised Gauss coefficients of one date, up to `degree`, indexed `[n][m]`
/// (entries above the degree are zero). Fixed-size and `Copy`: evaluating it allocates nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussCoefficients {
    /// [-] the highest degree n used, 1..=13.
    pub degree: usize,
    /// \[nT\] gₙᵐ, `g_nt[n][m]`.
    pub g_nt: [[f64; N]; N],
    /// \[nT\] hₙᵐ, `h_nt[n][m]` (hₙ⁰ = 0).
    pub h_nt: [[f64; N]; N],
}

/// The field at a point in geocentric spherical components \[nT\]: radial (outward), along the
/// colatitude (southward) and along the longitude (eastward). The geocentric north-east-down
/// components are (−`b_theta`, `b_phi`, −`b_r`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphericalField {
    /// \[nT\] B_r, outward.
    pub b_r_nt: f64,
    /// \[nT\] B_θ, toward increasing colatitude (south).
    pub b_theta_nt: f64,
    /// \[nT\] B_φ, east.
    pub b_phi_nt: f64,
}

impl GaussCoefficients {
    fn zero(degree: usize) -> Self {
        GaussCoefficients {
            degree,
            g_nt: [[0.0; N]; N],
            h_nt: [[0.0; N]; N],
        }
    }

    /// The field at geocentric radius `radius_m` \[m\], colatitude `colat_rad` and east longitude
    /// `lon_rad` (the synthesis of the module docs). Allocation-free and panic-free; on the polar
    /// axis the limit is taken (sin θ is held at 1e-300, where every m ≥ 1 term is exact).
    pub fn field_spherical_nt(
        &self,
        radius_m: f64,
        colat_rad: f64,
        lon_rad: f64,
    ) -> SphericalField {
        let degree = self.degree.min(IGRF_MAX_DEGREE);
        let (st, ct) = colat_rad.sin_cos();
        let st = st.max(1e-300);
        // Schmidt Pₙᵐ(cos θ) and dPₙᵐ/dθ, by the recursions of the module docs.
        let mut p = [[0.0; N]; N];
        let mut dp = [[0.0; N]; N];
        p[0][0] = 1.0;
        for n in 1..=degree {
            let nf = n as f64;
            if n == 1 {
                p[1][1] = st;
                dp[1][1] = ct;
            } else {
                let k = ((2.0 * nf - 1.0) / (2.0 * nf)).sqrt();
                p[n][n] = k * st * p[n - 1][n - 1];
                dp[n][n] = k * (st * dp[n - 1][n - 1] + ct * p[n - 1][n - 1]);
            }
            for m in 0..n {
                let mf = m as f64;
                let denom = (nf * nf - mf * mf).sqrt();
                let a = (2.0 * nf - 1.0) / denom;
                let b = ((nf - 1.0) * (nf - 1.0) - mf * mf).max(0.0).sqrt() / denom;
                let (p2, dp2) = if n >= 2 {
                    (p[n - 2][m], dp[n - 2][m])
                } else {
                    (0.0, 0.0)
                };
                p[n][m] = a * ct * p[n - 1][m] - b * p2;
                dp[n][m] = a * (ct * dp[n - 1][m] - st * p[n - 1][m]) - b * dp2;
            }
        }
        // cos mφ and sin mφ by the angle-addition recursion.
        let (sp, cp) = lon_rad.sin_cos();
        let mut cos_m = [0.0; N];
        let mut sin_m = [0.0; N];
        cos_m[0] = 1.0;
        for m in 1..=degree {
            cos_m[m] = cos_m[m - 1] * cp - sin_m[m - 1] * sp;
            sin_m[m] = sin_m[m - 1] * cp + cos_m[m - 1] * sp;
        }
        let ratio = IGRF_REFERENCE_RADIUS_M / radius_m;
        let mut ratio_pow = ratio * ratio;
        let (mut b_r, mut b_theta, mut b_phi) = (0.0, 0.0, 0.0);
        for n in 1..=degree {
            // (a/r)^(n+2)
            ratio_pow *= ratio;
            let (mut sum_r, mut sum_theta, mut sum_phi) = (0.0, 0.0, 0.0);
            for m in 0..=n {
                let (g, h) = (self.g_nt[n][m], self.h_nt[n][m]);
                let gh = g * cos_m[m] + h * sin_m[m];
                sum_r += gh * p[n][m];
                sum_theta += gh * dp[n][m];
                sum_phi += m as f64 * (g * sin_m[m] - h * cos_m[m]) * p[n][m];
            }
            b_r += (n as f64 + 1.0) * ratio_pow * sum_r;
            b_theta -= ratio_pow * sum_theta;
            b_phi += ratio_pow * sum_phi;
        }
        SphericalField {
            b_r_nt: b_r,
            b_theta_nt: b_theta,
            b_phi_nt: b_phi / st,
        }
    }

    /// \[T\] the field in Earth-fixed components at `r_ecef_m` \[m\]. Allocation-free and
    /// panic-free; at the Earth's centre it returns zero.
    pub fn field_ecef_t(&self, r_ecef_m: &Vector3<f64>) -> Vector3<f64> {
        let radius_m = r_ecef_m.norm();
        if radius_m == 0.0 {
            return Vector3::zeros();
        }
        let rho = r_ecef_m.x.hypot(r_ecef_m.y);
        let colat = rho.atan2(r_ecef_m.z);
        let lon = r_ecef_m.y.atan2(r_ecef_m.x);
        let f = self.field_spherical_nt(radius_m, colat, lon);
        let (st, ct) = colat.sin_cos();
        let (sp, cp) = lon.sin_cos();
        // B = B_r r̂ + B_θ θ̂ + B_φ φ̂ with r̂ = (sθcφ, sθsφ, cθ), θ̂ = (cθcφ, cθsφ, −sθ),
        // φ̂ = (−sφ, cφ, 0).
        let b_nt = Vector3::new(
            f.b_r_nt * st * cp + f.b_theta_nt * ct * cp - f.b_phi_nt * sp,
            f.b_r_nt * st * sp + f.b_theta_nt * ct * sp + f.b_phi_nt * cp,
            f.b_r_nt * ct - f.b_theta_nt * st,
        );
        b_nt * 1e-9
    }
}

/// An IGRF generation: its coefficients at every epoch, and the degree it is evaluated to.
#[derive(Debug, Clone)]
pub struct Igrf {
    epochs_year: Vec<f64>,
    models: Vec<GaussCoefficients>,
    degree: usize,
}

impl Igrf {
    /// IGRF-14 from the shipped coefficient file, evaluated to `degree` (1..=13; 1 is the
    /// centred tilted dipole, 13 the full model).
    pub fn igrf14(degree: usize) -> Result<Igrf, MagneticError> {
        Igrf::from_shc(IGRF14_SHC, degree)
    }

    /// An IGRF generation from the text of its SHC coefficient file (the format of the IAGA
    /// V-MOD releases), evaluated to `degree`.
    pub fn from_shc(text: &str, degree: usize) -> Result<Igrf, MagneticError> {
        let (epochs_year, models) = parse_shc(text)?;
        let max = models.iter().map(|m| m.degree).max().unwrap_or(0);
        if degree == 0 || degree > max {
            return Err(MagneticError::DegreeOutOfRange { degree, max });
        }
        Ok(Igrf {
            epochs_year,
            models,
            degree,
        })
    }

    /// The degree the field is evaluated to.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// \[yr\] the first and last epochs of the model (1900.0 and 2030.0 for IGRF-14).
    pub fn validity_years(&self) -> (f64, f64) {
        (
            self.epochs_year[0],
            self.epochs_year[self.epochs_year.len() - 1],
        )
    }

    /// `Ok` when `decimal_year` lies within the model's span; otherwise the error to report.
    /// Call it when a run is set up (for its first and last dates), not per step.
    pub fn check_date(&self, decimal_year: f64) -> Result<(), MagneticError> {
        let (first_year, last_year) = self.validity_years();
        if (first_year..=last_year).contains(&decimal_year) {
            Ok(())
        } else {
            Err(MagneticError::DateOutsideModel {
                decimal_year,
                first_year,
                last_year,
            })
        }
    }

    /// The coefficients at `decimal_year`, linearly interpolated between the bracketing epochs
    /// and truncated to the model's degree. A date outside the span is clamped to it (check it
    /// with [`Igrf::check_date`] first). Allocation-free and panic-free.
    pub fn coefficients_at(&self, decimal_year: f64) -> GaussCoefficients {
        let (first_year, last_year) = self.validity_years();
        let year = decimal_year.clamp(first_year, last_year);
        let last = self.epochs_year.len() - 1;
        let i = self
            .epochs_year
            .partition_point(|&t| t <= year)
            .saturating_sub(1)
            .min(last - 1);
        let (t0, t1) = (self.epochs_year[i], self.epochs_year[i + 1]);
        let w = (year - t0) / (t1 - t0);
        let (a, b) = (&self.models[i], &self.models[i + 1]);
        let mut out = GaussCoefficients::zero(self.degree);
        for n in 1..=self.degree {
            for m in 0..=n {
                out.g_nt[n][m] = a.g_nt[n][m] + w * (b.g_nt[n][m] - a.g_nt[n][m]);
                out.h_nt[n][m] = a.h_nt[n][m] + w * (b.h_nt[n][m] - a.h_nt[n][m]);
            }
        }
        out
    }

    /// \[T\] the field in Earth-fixed components at `r_ecef_m` \[m\] on `decimal_year`
    /// ([`Igrf::coefficients_at`] then [`GaussCoefficients::field_ecef_t`]). When the field is
    /// sampled often within a short span, keep the coefficients and call the latter: they change
    /// by at most 0.004 nT per hour (the largest secular variation, 35 nT/yr).
    pub fn field_ecef_t(&self, decimal_year: f64, r_ecef_m: &Vector3<f64>) -> Vector3<f64> {
        self.coefficients_at(decimal_year).field_ecef_t(r_ecef_m)
    }
}

/// Parses an SHC file: comment lines (`#`), a header `n_min n_max n_epochs order steps first
/// last`, the epochs, then one row per coefficient, `n m value…`; m < 0 or the second row of an
/// (n, m > 0) pair is hₙ^|m|.
fn parse_shc(text: &str) -> Result<(Vec<f64>, Vec<GaussCoefficients>), MagneticError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let bad = |line: usize, problem: String| MagneticError::CoefficientFile { line, problem };
    let numbers = |line: usize, text: &str| -> Result<Vec<f64>, MagneticError> {
        text.split_whitespace()
            .map(|w| {
                w.parse::<f64>()
                    .map_err(|_| bad(line, format!("`{w}` is not a number")))
            })
            .collect()
    };
    let (line, header) = lines
        .next()
        .ok_or_else(|| bad(0, "no header line".into()))?;
    let header = numbers(line, header)?;
    if header.len() < 3 {
        return Err(bad(
            line,
            "the header needs n_min, n_max and the epoch count".into(),
        ));
    }
    let (n_min, n_max, n_epochs) = (header[0], header[1], header[2]);
    if n_min != 1.0 || !(1.0..=IGRF_MAX_DEGREE as f64).contains(&n_max) || n_epochs < 2.0 {
        return Err(bad(
            line,
            format!("header n_min {n_min}, n_max {n_max}, {n_epochs} epochs: want 1, 1..=13, >= 2"),
        ));
    }
    let (n_max, n_epochs) = (n_max as usize, n_epochs as usize);
    let (line, epochs) = lines
        .next()
        .ok_or_else(|| bad(0, "no line of epochs".into()))?;
    let epochs_year = numbers(line, epochs)?;
    if epochs_year.len() != n_epochs
        || epochs_year.windows(2).any(|w| w[1] <= w[0])
        || epochs_year.iter().any(|t| !t.is_finite())
    {
        return Err(bad(
            line,
            format!("want {n_epochs} increasing epochs, found {epochs_year:?}"),
        ));
    }
    let mut models = vec![GaussCoefficients::zero(n_max); n_epochs];
    let mut seen_g = [[false; N]; N];
    let mut seen_h = [[false; N]; N];
    let mut rows = 0;
    for (line, text) in lines {
        let values = numbers(line, text)?;
        if values.len() != n_epochs + 2 {
            return Err(bad(
                line,
                format!(
                    "want n, m and {n_epochs} values, found {} numbers",
                    values.len()
                ),
            ));
        }
        let (n, m) = (values[0], values[1]);
        if n.fract() != 0.0 || m.fract() != 0.0 || n < 1.0 || n > n_max as f64 || m.abs() > n {
            return Err(bad(line, format!("no coefficient (n, m) = ({n}, {m})")));
        }
        let (n, m_abs) = (n as usize, m.abs() as usize);
        let is_h = m < 0.0 || (m > 0.0 && seen_g[n][m_abs]);
        let seen = if is_h { &mut seen_h } else { &mut seen_g };
        if seen[n][m_abs] {
            return Err(bad(line, format!("({n}, {m}) appears twice")));
        }
        seen[n][m_abs] = true;
        for (model, value) in models.iter_mut().zip(&values[2..]) {
            if is_h {
                model.h_nt[n][m_abs] = *value;
            } else {
                model.g_nt[n][m_abs] = *value;
            }
        }
        rows += 1;
    }
    // Σ_{n=1}^{n_max} (2n + 1) = n_max (n_max + 2) coefficients.
    if rows != n_max * (n_max + 2) {
        return Err(bad(
            0,
            format!(
                "want {} coefficient rows, found {rows}",
                n_max * (n_max + 2)
            ),
        ));
    }
    Ok((epochs_year, models))
}
