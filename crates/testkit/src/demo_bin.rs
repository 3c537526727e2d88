//! Where the demo flight code `flexdyn-acs-demo` is, for the tests and benchmarks that run it.
//!
//! It is its own package (`clients/rust/acs-demo`, so that it does not link the simulator),
//! and Cargo gives a test the path of its own package's binaries only. Its binary sits in the
//! same target directory as this test's: `cargo test --workspace` (or `cargo build --release
//! -p flexdyn-acs-demo`) builds it. A missing binary, or one older than the sources it is
//! built from, stops the test with that instruction instead of running an old controller.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// The newest modification time of the files below `dir` (none: `UNIX_EPOCH`).
fn newest(dir: &Path) -> SystemTime {
    let mut t = SystemTime::UNIX_EPOCH;
    let Ok(entries) = std::fs::read_dir(dir) else {
        return t;
    };
    for e in entries.flatten() {
        let path = e.path();
        let m = if path.is_dir() {
            newest(&path)
        } else {
            e.metadata()
                .and_then(|m| m.modified())
                .unwrap_or(SystemTime::UNIX_EPOCH)
        };
        t = t.max(m);
    }
    t
}

/// The path of `flexdyn-acs-demo`, checked present and built after its sources.
pub fn acs_demo() -> String {
    demo_bin("flexdyn-acs-demo")
}

/// The path of `flexdyn-formation-demo` (the same package), checked like [`acs_demo`].
pub fn formation_demo() -> String {
    demo_bin("flexdyn-formation-demo")
}

/// The path of the acs-demo package's binary `name`, checked present and built after its
/// sources.
fn demo_bin(name: &str) -> String {
    let exe = std::env::current_exe().expect("the test's path");
    // <target>/<profile>/deps/<test>: the binaries are in <target>/<profile>.
    let bin: PathBuf = exe
        .parent()
        .and_then(Path::parent)
        .expect("the profile directory")
        .join(name);
    let build = "build it with `cargo build --release -p flexdyn-acs-demo` (`cargo test \
                 --workspace --release` does)";
    let built = std::fs::metadata(&bin)
        .and_then(|m| m.modified())
        .unwrap_or_else(|_| panic!("{} is missing: {build}", bin.display()));
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for sources in ["clients/rust/acs-demo/src", "proto/src"] {
        let dir = root.join(sources);
        assert!(
            newest(&dir) <= built,
            "{} is older than {}: {build}",
            bin.display(),
            dir.display()
        );
    }
    bin.to_string_lossy().into_owned()
}
