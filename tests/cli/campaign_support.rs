//! What the campaign tests share: the `flexdyn` binary run as a CI job runs it
//! ([`flexdyn`], for `campaign_cli.rs`, `campaign_faults.rs`, `campaign_fork.rs`), and the
//! statistical checks of the planning tests (`campaign_plan.rs`, `campaign_fleet_plan.rs`): a
//! sample's mean and variance against the distribution it was drawn from, within 4 standard
//! errors.

use std::process::Output;

/// Runs the `flexdyn` binary with `args` (warnings and errors logged only) to completion.
pub fn flexdyn(args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(args)
        .env("RUST_LOG", "warn")
        .output()
        .expect("runs the flexdyn binary")
}

pub fn stats(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0);
    (m, v)
}

/// |mean − μ| < 4 σ/√n and the sample variance within 4 standard errors of σ² (for a normal,
/// se(s²) = σ²√(2/(n−1)); for a uniform, Var(s²) ≈ (μ4 − σ⁴)/n with μ4 = (b−a)⁴/80).
pub fn check(name: &str, x: &[f64], mu: f64, var: f64, var_se: f64) {
    let n = x.len() as f64;
    let (m, v) = stats(x);
    eprintln!("{name}: n {n}, mean {m:.6e} (want {mu:.6e}), var {v:.6e} (want {var:.6e})");
    assert!(
        (m - mu).abs() < 4.0 * (var / n).sqrt(),
        "{name}: mean {m} vs {mu}"
    );
    assert!(
        (v - var).abs() < 4.0 * var_se,
        "{name}: variance {v} vs {var}"
    );
}

/// [`check`] for draws of N(μ, σ): se(s²) = σ²√(2/(n−1)).
pub fn check_normal(name: &str, x: &[f64], mu: f64, sigma: f64) {
    let var = sigma * sigma;
    check(
        name,
        x,
        mu,
        var,
        var * (2.0 / (x.len() as f64 - 1.0)).sqrt(),
    );
}

/// Every draw in [a, b), and [`check`] for U(a, b): σ² = (b−a)²/12, μ4 = (b−a)⁴/80.
pub fn check_uniform(name: &str, x: &[f64], a: f64, b: f64) {
    assert!(
        x.iter().all(|v| (a..b).contains(v)),
        "{name}: a draw outside [{a}, {b})"
    );
    let var = (b - a).powi(2) / 12.0;
    let mu4 = (b - a).powi(4) / 80.0;
    let n = x.len() as f64;
    check(name, x, 0.5 * (a + b), var, ((mu4 - var * var) / n).sqrt());
}
