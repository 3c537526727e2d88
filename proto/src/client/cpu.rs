//! The processor check every flexdyn binary makes first ([`super::logging::parse_args`]).
//!
//! The workspace builds for x86-64-v3 on x86-64 (`.cargo/config.toml`), so its binaries use
//! AVX2, FMA and BMI2 instructions anywhere. On a processor without them the first such
//! instruction would kill the process with `SIGILL` ("illegal instruction") and no word of why.
//! [`missing_features`] compares the instruction-set extensions this build was compiled for
//! with those the running processor reports (`cpuid`), so the binary can stop with a message
//! that names them and says how to rebuild. On other architectures nothing is checked.

/// The instruction-set extensions this build was compiled to use that the running processor
/// lacks (empty when it has them all, and always on a non-x86-64 build).
pub fn missing_features() -> Vec<&'static str> {
    #[cfg(target_arch = "x86_64")]
    {
        macro_rules! missing {
            ($($feature:tt),* $(,)?) => {{
                let mut out: Vec<&'static str> = Vec::new();
                $(
                    if cfg!(target_feature = $feature)
                        && !std::arch::is_x86_feature_detected!($feature)
                    {
                        out.push($feature);
                    }
                )*
                out
            }};
        }
        // x86-64-v2 and v3 (`rustc --print cfg -C target-cpu=x86-64-v3`).
        missing!(
            "sse3",
            "ssse3",
            "sse4.1",
            "sse4.2",
            "popcnt",
            "cmpxchg16b",
            "avx",
            "avx2",
            "bmi1",
            "bmi2",
            "fma",
            "f16c",
            "lzcnt",
            "movbe",
            "xsave",
        )
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec::new()
    }
}

/// `Err` with the message a binary prints when the processor lacks an extension this build
/// uses ([`missing_features`]): the extensions, and the command that builds for this processor.
pub fn check() -> Result<(), String> {
    verdict(&missing_features())
}

/// [`check`]'s answer for the `missing` extensions.
fn verdict(missing: &[&str]) -> Result<(), String> {
    if missing.is_empty() {
        return Ok(());
    }
    Err(format!(
        "this processor lacks {}, which this build of flexdyn uses (it targets x86-64-v3, \
         .cargo/config.toml); rebuild for it with \
         RUSTFLAGS=\"-C target-cpu=native\" cargo build --release",
        missing.join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The machine that built the tests runs them, so it has every extension the build uses
    /// (x86-64-v3's under the workspace's `.cargo/config.toml`, none beyond x86-64 with
    /// `RUSTFLAGS="-C target-cpu=x86-64"`).
    #[test]
    fn the_build_machine_has_what_the_build_uses() {
        assert_eq!(missing_features(), Vec::<&str>::new());
        assert_eq!(check(), Ok(()));
    }

    /// What a processor without AVX2 and FMA is told: the missing extensions by name, the
    /// target of the build and the command that builds for this processor.
    #[test]
    fn a_missing_extension_is_named_with_the_rebuild_command() {
        let message = verdict(&["avx2", "fma"]).unwrap_err();
        assert!(
            message.starts_with("this processor lacks avx2, fma, "),
            "{message}"
        );
        assert!(message.contains("x86-64-v3"), "{message}");
        assert!(
            message.contains("RUSTFLAGS=\"-C target-cpu=native\" cargo build --release"),
            "{message}"
        );
        assert_eq!(verdict(&[]), Ok(()));
    }
}
