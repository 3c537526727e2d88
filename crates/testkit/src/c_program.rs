//! C programs the tests and benchmarks build from source with the system compiler (`$CC`,
//! default `cc`), as strictly as a user's CI would: C99, every warning an error.

use std::path::Path;
use std::process::Command;

/// Compiles `source` into `exe` with `cc -std=c99 -O2 -Wall -Wextra -Werror -pedantic`, linking
/// `libs` (e.g. `-lm`); panics with the compiler's output if it fails.
pub fn compile_c99(source: &Path, exe: &Path, libs: &[&str]) {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(&cc)
        .args([
            "-std=c99",
            "-O2",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-o",
        ])
        .arg(exe)
        .arg(source)
        .args(libs)
        .output()
        .unwrap_or_else(|e| panic!("no C compiler ({cc}: {e}): install gcc or set CC"));
    assert!(
        out.status.success(),
        "{cc} failed on {}:\n{}",
        source.display(),
        String::from_utf8_lossy(&out.stderr)
    );
}
