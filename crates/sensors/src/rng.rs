//! The sensors' portable random numbers: standard normals by Marsaglia's polar method on
//! ChaCha8, with `ln`/`exp` written with IEEE-754 basic operations only, so a seed gives the same
//! noise bit for bit on every platform (see [`super::imu`]'s module docs for the method).

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

// ---------------------------------------------------------------------------------------------
// Portable elementary functions (IEEE-754 +, −, ×, ÷ only; Rust never contracts them to FMA).

/// ln 2 split so that `k * LN2_HI` is exact for |k| < 2¹¹ (fdlibm's constants).
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000); // 6.93147180369123816490e-01
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76); // 1.90821492927058770002e-10

/// Natural logarithm of a positive, finite `x`, bit-reproducible on every IEEE-754 platform
/// (within 2 ulp of the true value). x = m·2ᵉ with m ∈ [√½, √2); ln m = 2 atanh(f),
/// f = (m − 1)/(m + 1), |f| ≤ 0.172, summed to f²⁵ (truncation < 1e-19 relative).
pub fn ln_portable(x: f64) -> f64 {
    if x.is_nan() || x < 0.0 {
        return f64::NAN;
    }
    if x == 0.0 {
        return f64::NEG_INFINITY;
    }
    if x == f64::INFINITY {
        return x;
    }
    let (mut x, mut e) = (x, 0i64);
    if x < f64::MIN_POSITIVE {
        x *= 18_014_398_509_481_984.0; // 2^54, exact
        e = -54;
    }
    let [ln] = ln_normal_lanes([x], [e]);
    ln
}

/// [`ln_portable`] of `N` values side by side, each its result bit for bit. The scalar function
/// is one chain of dependent multiply-adds (about 130 cycles); with the lanes' chains
/// interleaved, the processor runs them at once. Any value outside the positive normal range
/// (zero, subnormal, negative, infinite, NaN) sends the whole call to the scalar function.
#[inline(always)]
pub(crate) fn ln_portable_lanes<const N: usize>(x: [f64; N]) -> [f64; N] {
    if x.iter()
        .any(|v| !(f64::MIN_POSITIVE..f64::INFINITY).contains(v))
    {
        return x.map(ln_portable);
    }
    ln_normal_lanes(x, [0; N])
}

/// ln(x_i · 2^e0_i) for positive normal x_i, lane by lane: [`ln_portable`]'s series, each lane
/// with the same IEEE-754 operations in the same order whatever `N` is.
#[inline(always)]
fn ln_normal_lanes<const N: usize>(x: [f64; N], e0: [i64; N]) -> [f64; N] {
    let mut f = [0.0; N];
    let mut ef = [0.0; N];
    for i in 0..N {
        let bits = x[i].to_bits();
        let mut e = e0[i] + ((bits >> 52) & 0x7ff) as i64 - 1023;
        let mut m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | (1023u64 << 52));
        if m > std::f64::consts::SQRT_2 {
            m *= 0.5;
            e += 1;
        }
        f[i] = (m - 1.0) / (m + 1.0);
        ef[i] = e as f64;
    }
    let f2 = f.map(|v| v * v);
    // 2 atanh f = 2 Σ f^(2k+1)/(2k+1), k = 0..12, Horner in f².
    let mut s = [2.0 / 25.0; N];
    for k in (0..12).rev() {
        let c = 2.0 / (2 * k + 1) as f64;
        for i in 0..N {
            s[i] = s[i] * f2[i] + c;
        }
    }
    let mut out = [0.0; N];
    for i in 0..N {
        out[i] = ef[i] * LN2_HI + (f[i] * s[i] + ef[i] * LN2_LO);
    }
    out
}

/// e^r − 1 for |r| ≤ ½ ln 2, by its Taylor series to r¹⁸ (truncation < 1e-22 relative).
fn expm1_reduced(r: f64) -> f64 {
    let mut s = 1.0 / 6_402_373_705_728_000.0; // 1/18!
    let mut fact = 6_402_373_705_728_000.0;
    for n in (1..18).rev() {
        fact /= (n + 1) as f64;
        s = s * r + 1.0 / fact;
    }
    // s = Σ_{n=1..18} r^(n−1)/n!
    s * r
}

/// e^x, bit-reproducible on every IEEE-754 platform (within 2 ulp). x = k ln 2 + r,
/// |r| ≤ ½ ln 2, e^x = 2ᵏ (1 + expm1(r)).
pub fn exp_portable(x: f64) -> f64 {
    if x.is_nan() {
        return x;
    }
    if x > 709.78 {
        return f64::INFINITY;
    }
    if x < -745.2 {
        return 0.0;
    }
    let k = (x * std::f64::consts::LOG2_E).round();
    let r = (x - k * LN2_HI) - k * LN2_LO;
    let y = 1.0 + expm1_reduced(r);
    scale_pow2(y, k as i64)
}

/// e^x − 1 without cancellation near 0, bit-reproducible (within 2 ulp).
pub fn expm1_portable(x: f64) -> f64 {
    if x.abs() <= 0.5 * std::f64::consts::LN_2 {
        expm1_reduced(x)
    } else {
        exp_portable(x) - 1.0
    }
}

/// y · 2ᵏ by exact power-of-two multiplications (handles subnormal results).
fn scale_pow2(mut y: f64, mut k: i64) -> f64 {
    while k > 1023 {
        y *= f64::from_bits(2046u64 << 52); // 2^1023
        k -= 1023;
    }
    while k < -1022 {
        y *= f64::from_bits(1u64 << 52); // 2^-1022
        k += 1022;
    }
    y * f64::from_bits(((k + 1023) as u64) << 52)
}

// ---------------------------------------------------------------------------------------------
// Random numbers.

/// Standard normal pairs by Marsaglia's polar method on ChaCha8 (see the module docs). Also the
/// campaign dispersions' generator.
#[derive(Debug, Clone)]
pub struct NormalRng {
    rng: ChaCha8Rng,
}

impl flexdyn_kernel::archive::Archived for NormalRng {
    /// The generator's key, stream and position in its stream (ChaCha8's seed, stream id and
    /// word position): restored, it continues the same sequence from the same word.
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        let mut seed = self.rng.get_seed();
        let mut stream = self.rng.get_stream();
        let mut word_pos = self.rng.get_word_pos();
        a.put(&mut seed);
        a.put(&mut stream);
        a.put(&mut word_pos);
        if !a.is_saving() && !a.failed() {
            let mut rng = ChaCha8Rng::from_seed(seed);
            rng.set_stream(stream);
            rng.set_word_pos(word_pos);
            self.rng = rng;
        }
    }
}

impl NormalRng {
    /// A generator seeded with `seed` (ChaCha8's `seed_from_u64`).
    pub fn new(seed: u64) -> Self {
        Self {
            rng: ChaCha8Rng::seed_from_u64(seed),
        }
    }

    /// Uniform on [0, 1) with 53 random bits.
    pub fn uniform01(&mut self) -> f64 {
        const TWO_POW_M53: f64 = 1.0 / 9_007_199_254_740_992.0;
        (self.rng.next_u64() >> 11) as f64 * TWO_POW_M53
    }

    /// One standard normal (the first of a pair; the second is discarded, so every call uses
    /// the same amount of the stream whatever came before).
    pub fn normal(&mut self) -> f64 {
        self.normal_pair().0
    }

    /// 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.rng.next_u64()
    }

    /// Uniform on [−1, 1) with 53 random bits.
    #[inline]
    fn uniform_pm1(&mut self) -> f64 {
        const TWO_POW_M52: f64 = 1.0 / 4_503_599_627_370_496.0;
        (self.rng.next_u64() >> 11) as f64 * TWO_POW_M52 - 1.0
    }

    /// The polar method's accepted point: (u, v) uniform in the unit disc without its centre,
    /// and s = u² + v².
    #[inline]
    fn polar_point(&mut self) -> (f64, f64, f64) {
        loop {
            let u = self.uniform_pm1();
            let v = self.uniform_pm1();
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                return (u, v, s);
            }
        }
    }

    /// Two independent standard normals.
    #[inline]
    pub fn normal_pair(&mut self) -> (f64, f64) {
        let [pair] = self.normal_pairs::<1>();
        pair
    }

    /// `N` pairs of standard normals: the same numbers, in the same order, as `N` calls of
    /// [`Self::normal_pair`]. The accepted points are drawn first, one after the other as the
    /// single calls draw them; then their logarithms are taken side by side
    /// ([`ln_portable_lanes`]), which is where the time goes.
    #[inline]
    pub fn normal_pairs<const N: usize>(&mut self) -> [(f64, f64); N] {
        let points: [(f64, f64, f64); N] = std::array::from_fn(|_| self.polar_point());
        let ln_s = ln_portable_lanes(points.map(|(_, _, s)| s));
        let mut out = [(0.0, 0.0); N];
        for (o, ((u, v, s), ln)) in out.iter_mut().zip(points.into_iter().zip(ln_s)) {
            let f = (-2.0 * ln / s).sqrt();
            *o = (u * f, v * f);
        }
        out
    }

    /// Fills `out` (even length) with standard normals: the same numbers as pair after pair of
    /// [`Self::normal_pair`], taken four pairs at a time.
    #[inline]
    pub(crate) fn fill(&mut self, out: &mut [f64]) {
        let mut quads = out.chunks_exact_mut(8);
        for quad in &mut quads {
            for (k, (a, b)) in self.normal_pairs::<4>().into_iter().enumerate() {
                quad[2 * k] = a;
                quad[2 * k + 1] = b;
            }
        }
        for pair in quads.into_remainder().chunks_exact_mut(2) {
            let (a, b) = self.normal_pair();
            pair[0] = a;
            pair[1] = b;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Inputs that reach every branch of `ln_portable`: both sides of the √2 mantissa split,
    /// exact powers of two, 1 and its neighbours, the ends of the normal range, the values the
    /// polar method passes (0 < s < 1), and the ones outside the normal range that send the
    /// lanes to the scalar function.
    fn ln_inputs() -> Vec<f64> {
        let sqrt2 = std::f64::consts::SQRT_2;
        let mut v = vec![
            1.0,
            f64::from_bits(1.0f64.to_bits() + 1),
            f64::from_bits(1.0f64.to_bits() - 1),
            sqrt2,
            f64::from_bits(sqrt2.to_bits() + 1),
            f64::from_bits(sqrt2.to_bits() - 1),
            0.5,
            2.0,
            f64::MIN_POSITIVE,
            f64::MAX,
            1e-300,
            0.999_999_999,
        ];
        let mut rng = NormalRng::new(3);
        for _ in 0..4000 {
            let (_, _, s) = rng.polar_point();
            v.push(s);
            v.push(rng.uniform01() * 1e6);
        }
        let mut x = 1e-300;
        while x < 1e300 {
            v.push(x);
            x *= 3.7;
        }
        v
    }

    #[test]
    fn ln_lanes_are_the_scalar_ln_bit_for_bit() {
        let v = ln_inputs();
        for w in v.chunks_exact(4) {
            let x = [w[0], w[1], w[2], w[3]];
            assert_eq!(
                ln_portable_lanes(x).map(f64::to_bits),
                x.map(|x| ln_portable(x).to_bits()),
                "{x:?}"
            );
        }
        // A lane outside the normal range: the whole call takes the scalar path.
        for odd in [0.0, 5e-324, -1.0, f64::INFINITY, f64::NAN] {
            let x = [0.25, odd, 0.75, 3.0];
            let got = ln_portable_lanes(x);
            for (g, x) in got.iter().zip(x) {
                let want = ln_portable(x);
                assert!(
                    g.to_bits() == want.to_bits() || (g.is_nan() && want.is_nan()),
                    "{x}"
                );
            }
        }
    }

    /// `normal_pairs` and `fill` are the same numbers as single `normal_pair` calls from the
    /// same stream, in the same order, and leave the stream at the same word.
    #[test]
    fn batched_normals_are_the_single_draws_bit_for_bit() {
        for seed in [1, 7, 31, 43] {
            let mut single = NormalRng::new(seed);
            let mut batched = single.clone();
            let mut filled = single.clone();
            let want: Vec<(f64, f64)> = (0..9).map(|_| single.normal_pair()).collect();
            let mut got = Vec::new();
            got.extend(batched.normal_pairs::<4>());
            got.extend(batched.normal_pairs::<2>());
            got.extend(batched.normal_pairs::<3>());
            let bits = |v: &[(f64, f64)]| -> Vec<(u64, u64)> {
                v.iter().map(|(a, b)| (a.to_bits(), b.to_bits())).collect()
            };
            assert_eq!(bits(&got), bits(&want), "seed {seed}");
            let mut z = [0.0; 18];
            filled.fill(&mut z);
            let pairs: Vec<(f64, f64)> = z.chunks_exact(2).map(|p| (p[0], p[1])).collect();
            assert_eq!(bits(&pairs), bits(&want), "seed {seed}");
            assert_eq!(batched.rng.get_word_pos(), single.rng.get_word_pos());
            assert_eq!(filled.rng.get_word_pos(), single.rng.get_word_pos());
        }
    }
}
